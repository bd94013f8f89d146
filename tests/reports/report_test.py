"""Unit tests of reports/report.py's statistics and tables (run by ctest with /usr/bin/python3)."""
import base64
import gzip
import json
import math
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "reports"))
import report  # noqa: E402

MiB = 2 ** 20


def phase(t, rss):
    return {"wall_s": t, "cpu_s": t, "peak_rss_bytes": rss, "peak_rss_reset": True, "alloc_count": 1, "alloc_bytes": 1}


def trial(label, scene, seed, times, nodes, status="ok", metrics=None, verdict=None, summary=None):
    """A cell as results.json holds it: the whole process's peak (child_max_rss_bytes) 100 MiB and more, the growth
    phase's own peak 20 MiB and more, the query structure's 5 MiB and more; `verdict`: (status, reasons)."""
    t = {"id": f"{label}/{scene}/s{seed}", "label": label, "algorithm": label, "scene": scene, "seed": seed,
         "sweep": {}, "status": status, "counts": {"nodes": nodes, "leaves": 0},
         "output_bytes": {"obj": 3 * nodes, "ply": nodes, "glb": nodes},
         "metrics": metrics or {"coverage": 0.5, "attached_fraction": 0.25, "penetration_samples": 0.0},
         "alloc": {"growth": {"bytes": 100 * nodes, "count": nodes}},
         "curve": {"step": [0, 1], "nodes": [1, nodes]},
         "samples": [{"repetition": i, "status": status, "child_max_rss_bytes": MiB * (100 + i),
                      "phases": {"query_build": phase(0.002, MiB * (5 + i)), "growth": phase(t, MiB * (20 + i)),
                                 "export": phase(0.001, MiB * (30 + i))}}
                     for i, t in enumerate(times)] if status == "ok" else [{"repetition": 0, "status": status}]}
    if verdict:
        t["verdict"] = {"status": verdict[0]} | ({"reasons": list(verdict[1])} if len(verdict) > 1 else {})
    if summary:
        t["summary"] = {"growth_s": summary}
    return t


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def write(path, text):
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def col(row, name):
    return row[report.TABLE_HEAD.index(name)]


def document(trials, context=None, pooled=()):
    return {"kind": "growbench-results", "schema_version": 1, "repetitions": 1, "suite": {"name": "t"},
            "context": context or {"hardware_threads": 4, "cpu_model": "test"}, "trials": trials,
            "summary": {"growth_s_over_seeds": [{"cells": list(c), "growth_s": g} for c, g in pooled]}}


class Drawn:
    """Records what the figures draw: every Axes.plot, bar and errorbar call, with its axes (whose title names the
    figure or panel once drawing is done)."""

    def __enter__(self):
        import matplotlib
        matplotlib.use("Agg")
        from matplotlib.axes import Axes
        self.calls, self.saved = [], {}
        for name in ("plot", "bar", "errorbar"):
            original = getattr(Axes, name)
            self.saved[name] = original

            def wrapper(ax, *a, _original=original, _name=name, **k):
                self.calls.append((_name, ax, a, k))
                return _original(ax, *a, **k)
            setattr(Axes, name, wrapper)
        return self

    def __exit__(self, *exc):
        from matplotlib.axes import Axes
        for name, original in self.saved.items():
            setattr(Axes, name, original)

    def on(self, title, name):
        """(args, kwargs, axes) of each `name` call on the axes titled `title`."""
        return [(a, k, ax) for n, ax, a, k in self.calls if n == name and ax.get_title() == title]


TIME_VS_SIZE = "Growth time against output size"


class Statistics(unittest.TestCase):
    def test_median(self):
        self.assertEqual(report.median([3, 1, 2]), 2)
        self.assertEqual(report.median([4, 1, 3, 2]), 2.5)

    def test_exponent_of_an_exact_power_law(self):
        xs = [1e3, 1e4, 1e5, 1e6]
        b, ci, a = report.fit_exponent(xs, [3.0 * x ** 1.5 for x in xs])
        self.assertAlmostEqual(b, 1.5, places=9)
        self.assertAlmostEqual(math.exp(a), 3.0, places=6)
        self.assertAlmostEqual(ci[0], 1.5, places=6)
        self.assertAlmostEqual(ci[1], 1.5, places=6)

    def test_exponent_interval_from_t(self):
        # log-log points (0,0), (1,1), (2,3): slope 1.5, residuals 1/6, -1/3, 1/6: rss 1/6, se = sqrt(1/6 / 2),
        # t(1) = 12.706.
        e = math.e
        b, ci, _ = report.fit_exponent([1, e, e * e], [1, e, e ** 3])
        self.assertAlmostEqual(b, 1.5)
        half = 12.706 * math.sqrt((1 / 6) / 1 / 2)
        self.assertAlmostEqual(ci[0], 1.5 - half, places=6)
        self.assertAlmostEqual(ci[1], 1.5 + half, places=6)

    def test_no_exponent_over_nearly_equal_sizes(self):
        self.assertIsNone(report.fit_exponent([2000, 2003, 2001], [1.0, 2.0, 3.0]))
        self.assertIsNone(report.fit_exponent([1000], [1.0]))


class Tables(unittest.TestCase):
    def test_rows_pool_seeds_and_name_failures(self):
        cells = [report.Cell(t) for t in [
            trial("a", "wall", 1, [0.010, 0.012, 0.011], 1000),
            trial("a", "wall", 2, [0.020, 0.021, 0.022], 3000),
            trial("b", "wall", 1, [], 0, status="timeout"),
        ]]
        # The interval over both seeds' six samples is the suite's (harness/stats/stats.hpp): median
        # (0.012 + 0.020) / 2 = 16 ms, interval (x_(1), x_(6)) = [10 ms, 22 ms].
        pooled = {frozenset(["a/wall/s1", "a/wall/s2"]): {"n": 6, "median": 0.016, "lo": 0.010, "hi": 0.022, "exact": True}}
        rows = report.table_rows(cells, pooled)
        self.assertEqual(len(rows), 2)
        a, b = rows
        # The row says what it pools; unjudged cells (a file written before verdicts) count as valid, unmarked.
        self.assertEqual(a[:4], ["a", "wall", "2 seeds x 3 reps", "-"])
        self.assertEqual(col(a, report.GROWTH_HEAD), "16.0 ms CI [10.0 ms, 22.0 ms]")
        # A file written before the suite wrote summaries: the median, no interval.
        self.assertEqual(col(report.table_rows(cells)[0], report.GROWTH_HEAD), "16.0 ms [no interval in this file]")
        self.assertEqual(col(a, "nodes"), "2000")
        self.assertEqual(a[report.TABLE_HEAD.index("coverage"):],
                         ["0.500", "0.250", "0.000", "-", "-"])  # no leaf metrics in these records
        self.assertEqual(col(b, "trials pooled"), "none (1 failed: timeout)")
        self.assertEqual(col(b, report.GROWTH_HEAD), "timeout")

    def test_latex_and_markdown(self):
        cells = [report.Cell(trial("ivy_luft", "wall", 1, [0.5, 0.6], 10))]
        pooled = {frozenset(["ivy_luft/wall/s1"]): {"n": 2, "median": 0.55, "lo": 0.5, "hi": 0.6, "exact": False}}
        rows = report.table_rows(cells, pooled)
        with tempfile.TemporaryDirectory() as d:
            report.paper_tables.write_tex(os.path.join(d, "t.tex"), {("ivy_luft", "wall"): report.row_numbers(
                cells, pooled)}, ["ivy_luft"], ["wall"], report.QUALITY)
            tex = read(os.path.join(d, "t.tex"))
            self.assertIn("\\toprule", tex)
            self.assertIn("\\caption{Growth time (ms): the median", tex)
            self.assertIn("ivy\\_luft & 550 [500, 600] \\\\", tex)  # the unit in the caption, not the cell
            self.assertNotIn("Leaf overlap", tex)  # no cell records it: no table
            report.write_markdown(os.path.join(d, "t.md"), rows, "c")
            md = read(os.path.join(d, "t.md")).splitlines()
            self.assertEqual(md[0].count("|"), len(report.TABLE_HEAD) + 1)
            self.assertTrue(md[2].startswith("| ivy_luft | wall | 1 seed x 2 reps | - | 550.0 ms range \\[500.0 ms, "
                                             "600.0 ms\\] |"), md[2])
        # Free text from a suite is shown as written: no HTML element, markup or line break gets through.
        self.assertEqual(report.md_text("<script>x</script> | *a*\n`b`"),
                         "&lt;script&gt;x&lt;/script&gt; \\| \\*a\\* \\`b\\`")
        self.assertEqual(report.paper_tables.escape("$\\frac{$^\n\\end{table}<b>"),
                         "\\$\\textbackslash{}frac\\{\\$\\^{} \\textbackslash{}end\\{table\\}\\textless{}b\\textgreater{}")

    def test_bad_results_are_clear_errors(self):
        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "r.json")
            write(p, "{\"trials\": [")
            with self.assertRaisesRegex(report.ReportError, "r.json: not valid JSON: line 1"):
                report.load_results(p)
            write(p, json.dumps({"trials": []}))
            with self.assertRaisesRegex(report.ReportError, "not a growbench results file"):
                report.load_results(p)
            self.assertEqual(report.main([p, "--out", os.path.join(d, "out")]), 2)

    def test_results_are_checked_against_the_schema(self):
        schema = report.load_schema()
        self.assertEqual(report.schema_version(schema), 1)
        doc = {"kind": "growbench-results", "schema_version": 1, "trials": []}
        with self.assertRaisesRegex(report.ReportError, r"r.json: at the top level: '\w+' is a required property"):
            report.validate(doc, "r.json", schema)
        with self.assertRaisesRegex(report.ReportError, "r.json: schema_version 2; this report reads 1"):
            report.validate(dict(doc, schema_version=2), "r.json", schema)
        self.assertEqual(report.json_path(["trials", 3, "samples", 0, "phases", "growth", "wall_s"]),
                         "trials[3].samples[0].phases.growth.wall_s")

    def test_cells_read_the_suites_summary(self):
        t = trial("a", "wall", 1, [0.010, 0.030, 0.020], 1000)
        self.assertEqual(report.Cell(t).growth_median(), 0.020)  # no summary: computed
        t["summary"] = {"growth_s": {"n": 3, "median": 0.025, "lo": 0.010, "hi": 0.030, "exact": False}}
        self.assertEqual(report.Cell(t).growth_median(), 0.025)  # the suite's, as written


GROWTH = report.GROWTH_HEAD
FLAT = ("degenerate", ["flat", "stunted"])
NA = ("not_applicable", ["a climber with nothing to climb"])


def numbers(args):
    """Every number among a drawing call's positional arguments (its x and y data)."""
    import numpy as np
    out = []
    for a in args:
        try:
            out += list(np.asarray(a, dtype=float).ravel())
        except (TypeError, ValueError):
            pass
    return out


class Verdicts(unittest.TestCase):
    """Only valid (or unjudged) plants enter what compares cells; the others are marked and listed, never dropped."""

    def cells(self):
        return [report.Cell(t) for t in [
            trial("a", "wall", 1, [0.010, 0.011, 0.012], 1000, verdict=("valid",)),
            trial("a", "wall", 2, [0.020, 0.021, 0.022], 3000, verdict=("valid",)),
            # Far slower and larger: it would move the pooled median (to 20 ms) and the nodes (to 3000).
            trial("a", "wall", 3, [9.0, 9.1, 9.2], 50000, verdict=FLAT),
            trial("b", "wall", 1, [0.5], 10, verdict=NA),
            trial("b", "wall", 2, [0.6], 10, verdict=NA),
        ]]

    def test_a_degenerate_cell_is_left_out_of_the_pooled_row_and_marked(self):
        cells = self.cells()
        pooled = {frozenset(["a/wall/s1", "a/wall/s2"]): {"n": 6, "median": 0.016, "lo": 0.010, "hi": 0.022,
                                                          "exact": True}}
        a, b = report.table_rows(cells, pooled)
        self.assertEqual(col(a, "verdict"), "degenerate (1 of 3 seeds)")
        self.assertEqual(col(a, "trials pooled"), "2 seeds x 3 reps")
        self.assertEqual(col(a, GROWTH), "16.0 ms CI [10.0 ms, 22.0 ms]")  # the suite's summary of the valid seeds
        self.assertEqual(col(a, "nodes"), "2000")
        # Without the suite's summary, the median of the valid seeds' trials alone (with the third: 20.0 ms).
        self.assertEqual(col(report.table_rows(cells)[0], GROWTH), "16.0 ms [no interval in this file]")
        # A row whose plants are all not valid shows no numbers at all.
        self.assertEqual(b[:4], ["b", "wall", "none", "n/a (2 of 2 seeds)"])
        self.assertEqual(set(b[4:]), {"-"})
        # Both kinds in one row, and a valid one.
        mixed = [report.Cell(trial("c", "wall", i, [0.1], 10, verdict=v)) for i, v in
                 enumerate([("valid",), FLAT, NA], 1)]
        self.assertEqual(col(report.table_rows(mixed)[0], "verdict"), "degenerate (1 of 3 seeds), n/a (1 of 3 seeds)")
        self.assertEqual(col(report.table_rows(mixed[:1])[0], "verdict"), "valid")

    def test_cells_left_out_are_listed_with_their_reasons(self):
        cells = self.cells()
        notes = report.table_notes(cells)
        self.assertEqual(notes, ["Left out of comparisons (verdict not valid):",
                                 "a/wall/s3: degenerate: flat; stunted",
                                 "b/wall/s1: not applicable: a climber with nothing to climb",
                                 "b/wall/s2: not applicable: a climber with nothing to climb"])
        self.assertEqual(report.table_notes([report.Cell(trial("a", "wall", 1, [0.1], 10))]), [])  # unjudged
        rows = report.table_rows(cells)
        with tempfile.TemporaryDirectory() as d:
            report.write_markdown(os.path.join(d, "t.md"), rows, "caption", notes)
            md = read(os.path.join(d, "t.md"))
            self.assertIn("caption\n\nLeft out of comparisons (verdict not valid):\n\n- a/wall/s3: degenerate: flat; "
                          "stunted\n- b/wall/s1: not applicable", md)
            report.paper_tables.write_tex(os.path.join(d, "t.tex"), {(l, s): report.row_numbers(g) for l, s, g in
                                                                      report.table_groups(cells)}, ["a", "b"],
                                          ["wall"], report.QUALITY, notes)
            tex = read(os.path.join(d, "t.tex"))
            self.assertIn("a/wall/s3: degenerate: flat; stunted\\\\", tex)
            self.assertIn("b & not appl. \\\\", tex)
            self.assertLess(tex.rindex("\\end{tabular}"), tex.index("a/wall/s3: degenerate"))

    def test_figures_and_the_fit_leave_out_a_degenerate_cell(self):
        cells = [report.Cell(t) for t in [
            # An exact power law of exponent 1 over three valid sizes spanning 10x ...
            trial("a", "wall", 1, [1e-5 * 1000], 1000), trial("a", "wall", 2, [1e-5 * 3000], 3000),
            trial("a", "wall", 3, [1e-5 * 10000], 10000, verdict=("valid",)),
            # ... and a degenerate plant that would bend it, with numbers seen nowhere else.
            trial("a", "wall", 4, [7.77], 77777, verdict=FLAT,
                  metrics={"coverage": 0.777, "attached_fraction": 0.777, "penetration_samples": 0.777}),
            trial("b", "wall", 1, [0.001], 100), trial("b", "wall", 2, [0.01], 1000),  # two sizes: no fit
            trial("c", "wall", 1, [0.001], 1000), trial("c", "wall", 2, [0.002], 1200),
            trial("c", "wall", 3, [0.003], 1500),  # three sizes within 2x: no fit
        ]]
        with tempfile.TemporaryDirectory() as d, Drawn() as drawn:
            report.figures(cells, d, ["png"])
        points = [(a, k) for a, k, _ in drawn.on(TIME_VS_SIZE, "plot") if "label" in k]
        self.assertEqual([k["label"] for _, k in points],
                         ["a: 3 sizes, k = 1.00 [1.00, 1.00]", "b: 2 sizes, no fit", "c: 3 sizes within 2x, no fit"])
        self.assertEqual(sorted(points[0][0][0]), [1000, 3000, 10000])
        fits = [a for a, k, _ in drawn.on(TIME_VS_SIZE, "plot") if "label" not in k]
        self.assertEqual(len(fits), 1)  # a's only
        self.assertAlmostEqual(min(fits[0][0]), 1000)
        self.assertAlmostEqual(max(fits[0][0]), 10000)
        # The degenerate plant's size, time and metrics are drawn in no figure.
        for name, ax, args, _ in drawn.calls:
            for v in numbers(args):
                for bad in (77777, 7.77, 0.777):
                    self.assertFalse(math.isclose(v, bad, rel_tol=1e-9), f"{bad} drawn by {name} on {ax.get_title()!r}")

    def test_not_applicable_metrics_are_na_and_not_drawn(self):
        cells = [report.Cell(t) for t in [
            trial("a", "wall", 1, [0.1], 100, metrics={"coverage": 0.2, "leaf_overlap": 0.2}),
            trial("a", "wall", 2, [0.1], 100, metrics={"coverage": 0.4, "leaf_overlap": None}),
            trial("a", "wall", 3, [0.1], 100, metrics={"coverage": 0.9, "leaf_overlap": 0.4}),
            trial("a", "ground", 1, [0.1], 100, metrics={"coverage": None, "leaf_overlap": None}),
            trial("a", "ground", 2, [0.1], 100, metrics={"coverage": None, "leaf_overlap": None}),
        ]]
        wall, ground = report.table_rows(cells)
        self.assertEqual(col(wall, "leaf overlap"), "0.300")  # the median of 0.2 and 0.4, not of 0.2, 0, 0.4
        self.assertEqual(col(wall, "coverage"), "0.400")
        self.assertEqual(col(ground, "coverage"), "n/a")
        self.assertEqual(col(ground, "leaf overlap"), "n/a")
        self.assertEqual(col(ground, "attached"), "-")  # not in the record at all
        with tempfile.TemporaryDirectory() as d, Drawn() as drawn:
            report.figures(cells, d, ["png"])
        # One marker at the wall's median and a line over its seeds' range; nothing, not 0, for the ground.
        for title, med, spread in [("surface coverage", 0.4, (0.2, 0.9)), ("leaf overlap", 0.3, (0.2, 0.4))]:
            calls = drawn.on(title, "plot")
            points = [list(a[0]) for a, _, _ in calls if len(a[0]) == 1]
            lines = [tuple(a[0]) for a, _, _ in calls if len(a[0]) == 2]
            self.assertEqual(len(points), 1, title)
            self.assertAlmostEqual(points[0][0], med, msg=title)
            self.assertEqual(len(lines), 1, title)
            self.assertAlmostEqual(lines[0][0], spread[0], msg=title)
            self.assertAlmostEqual(lines[0][1], spread[1], msg=title)


class Intervals(unittest.TestCase):
    """Each interval says what it is: a CI, a range, or none for one trial."""

    def test_one_trial_prints_no_interval(self):
        cells = [report.Cell(trial("a", "wall", 1, [0.012], 1000))]
        one = {"n": 1, "median": 0.012, "lo": 0.012, "hi": 0.012, "exact": False}
        row = report.table_rows(cells, {frozenset(["a/wall/s1"]): one})[0]
        self.assertEqual(col(row, GROWTH), "12.0 ms (1 trial)")
        self.assertEqual(col(row, "trials pooled"), "1 seed x 1 rep")
        self.assertEqual(col(report.table_rows(cells)[0], GROWTH), "12.0 ms (1 trial)")  # without a summary too
        self.assertEqual(report.growth_time_text({"n": 3, "median": 0.012, "lo": 0.011, "hi": 0.013, "exact": False},
                                                 []), "12.0 ms range [11.0 ms, 13.0 ms]")
        self.assertNotIn("95% CI]", " ".join(report.TABLE_HEAD))
        self.assertIn("growth time (median; 95% CI or range)", report.TABLE_HEAD)
        # Seeds with different repetition counts: the trials and the seeds.
        mixed = [report.Cell(trial("a", "wall", 1, [0.1, 0.2], 10)), report.Cell(trial("a", "wall", 2, [0.1], 10))]
        self.assertEqual(col(report.table_rows(mixed)[0], "trials pooled"), "3 trials over 2 seeds")

    def test_bars_only_where_an_interval_exists(self):
        cells = [report.Cell(t) for t in [
            trial("a", "wall", 1, [0.01], 1000, summary={"n": 1, "median": 0.01, "lo": 0.01, "hi": 0.01, "exact": False}),
            trial("a", "wall", 2, [0.02, 0.03, 0.04], 2000,
                  summary={"n": 3, "median": 0.03, "lo": 0.02, "hi": 0.04, "exact": False}),
        ]]
        with tempfile.TemporaryDirectory() as d, Drawn() as drawn:
            report.figures(cells, d, ["png"])
        bars = drawn.on(TIME_VS_SIZE, "errorbar")
        self.assertEqual(len(bars), 1)
        args, kw, ax = bars[0]
        self.assertEqual(list(args[0]), [2000])  # not at the one-trial cell
        self.assertEqual([list(e) for e in kw["yerr"]], [[0.03 - 0.02], [0.04 - 0.03]])
        label = ax.get_ylabel().replace("\n", " ")
        self.assertIn("points: median over repetitions; bars: 95% CI (6+ repetitions) or range", label)
        self.assertNotIn("median and 95% interval", label)
        # One trial everywhere: the label claims no interval.
        with tempfile.TemporaryDirectory() as d, Drawn() as drawn:
            report.figures(cells[:1], d, ["png"])
        self.assertEqual(drawn.on(TIME_VS_SIZE, "errorbar"), [])
        ax = drawn.on(TIME_VS_SIZE, "plot")[0][2]
        self.assertEqual(ax.get_ylabel(), "growth wall time (s)\none trial per point (no interval)")

    def test_a_fit_needs_three_sizes_over_a_factor_of_two(self):
        self.assertEqual(report.scaling_fit([100, 1000, 100, 1000], [1, 10, 1, 10]), (2, None))
        self.assertEqual(report.scaling_fit([1000, 1500, 1900], [1, 2, 3]), (3, None))
        sizes, (b, ci, _) = report.scaling_fit([100, 1000, 10000], [1, 10, 100])
        self.assertEqual(sizes, 3)
        self.assertAlmostEqual(b, 1.0)
        self.assertEqual(report.scaling_legend("ivy", 2, None), "ivy: 2 sizes, no fit")
        self.assertEqual(report.scaling_legend("spacecol", 4, (1.123, (0.98, 1.251), 0.0)),
                         "spacecol: 4 sizes, k = 1.12 [0.98, 1.25]")


class Memory(unittest.TestCase):
    def test_the_memory_shown_is_the_growth_phases_own_peak(self):
        cells = [report.Cell(trial("a", "wall", 1, [0.01, 0.02, 0.03], 1000))]
        row = report.table_rows(cells)[0]
        self.assertEqual(col(row, "growth peak RSS"), "21.0 MiB")  # phases.growth: 20, 21, 22 MiB
        self.assertEqual(col(row, "query peak RSS"), "6.0 MiB")  # phases.query_build: 5, 6, 7 MiB
        self.assertNotIn("101.0 MiB", row)  # the whole process's peak (child_max_rss_bytes) is not the algorithm's
        self.assertNotIn("peak memory", report.TABLE_HEAD)
        t = trial("a", "wall", 1, [0.01], 1000)
        t["samples"][0]["phases"]["growth"]["peak_rss_reset"] = False  # the process's peak so far: marked
        self.assertEqual(col(report.table_rows([report.Cell(t)])[0], "growth peak RSS"), "20.0 MiB *")
        with tempfile.TemporaryDirectory() as d, Drawn() as drawn:
            report.figures(cells, d, ["png"])
        mem = [(a, ax) for n, ax, a, _ in drawn.calls
               if n == "plot" and ax.get_ylabel() == "growth peak RSS (MiB)\nmedian over repetitions"]
        self.assertEqual(len(mem), 1)
        self.assertEqual(list(mem[0][0][1]), [21.0])


class Page(unittest.TestCase):
    def write(self, doc):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "results.json")
            with open(path, "w") as f:
                json.dump(doc, f)
            report.write_report(doc, path, os.path.join(d, "out"), ["png"])
            page = read(os.path.join(d, "out", "index.html"))
            md = read(os.path.join(d, "out", "table.md"))
        return page, md

    def test_busy_machine_banner_and_plants_left_out(self):
        trials = [trial("a", "wall", 1, [0.01], 1000, verdict=("valid",)),
                  trial("a", "wall", 2, [0.02], 2000, verdict=FLAT),
                  trial("b", "ground", 1, [0.01], 100, verdict=NA)]
        busy = {"hardware_threads": 2, "cpu_model": "test", "load_average_start": [1.8, 1.2, 0.9],
                "load_average_end": [1.1, 1.0, 0.8], "cpu_mhz": 2450.0, "cpu_governor": "performance"}
        page, md = self.write(document(trials, busy))
        self.assertIn("<div class='banner' id='machine-banner'><p>The machine was busy when this run began (load 1.80 "
                      "over the last minute, on 2 hardware threads)", page)
        self.assertLess(page.index("machine-banner"), page.index("<h2>Context</h2>"))  # at the top
        self.assertIn("<tr><th>load average (1, 5, 15 min)</th><td>at the start 1.80, 1.20, 0.90; at the end 1.10, "
                      "1.00, 0.80</td></tr>", page)
        self.assertIn("<tr><th>CPU clock</th><td>2450 MHz, governor performance</td></tr>", page)
        section = page[page.index("<h2 id='left-out'>Plants left out of comparisons</h2>"):]
        self.assertIn("<li>a/wall/s2: degenerate: flat; stunted</li>", section)
        self.assertIn("<li>b/ground/s1: not applicable: a climber with nothing to climb</li>", section)
        self.assertIn("- a/wall/s2: degenerate: flat; stunted", md)
        self.assertIn("<td>degenerate (1 of 2 seeds)</td>", page)
        # A quiet machine (0.5 on 2 threads is a quarter, not more): no banner, nothing left out.
        quiet = dict(busy, load_average_start=[0.5, 0.4, 0.3])
        page, _ = self.write(document([trial("a", "wall", 1, [0.01], 1000, verdict=("valid",))], quiet))
        self.assertNotIn("machine-banner", page)
        self.assertNotIn("busy", page)
        self.assertIn("None: every plant that grew was judged valid.", page)
        # A file without the machine's state: no banner, no rows for it.
        page, _ = self.write(document([trial("a", "wall", 1, [0.01], 1000)]))
        self.assertNotIn("machine-banner", page)
        self.assertNotIn("load average", page)

    def test_the_context_names_each_plugin_with_its_build(self):
        ctx = {"hardware_threads": 2, "cpu_model": "test",
               "plugins": [{"name": "walker", "path": "/home/r/walker.so", "hash": "0123456789abcdef",
                            "abi_version": 1, "version": "1.2"}]}
        page, _ = self.write(document([trial("walker", "wall", 1, [0.01], 1000)], ctx))
        self.assertIn("<tr><th>plugin walker</th><td>/home/r/walker.so (version 1.2, ABI 1, xxh3 0123456789abcdef)"
                      "</td></tr>", page)
        page, _ = self.write(document([trial("a", "wall", 1, [0.01], 1000)], {"hardware_threads": 2}))
        self.assertNotIn("<th>plugin ", page)

    def test_a_results_file_names_only_its_own_renders(self):
        # Grids and a trial's render named outside the results folder (absolute, '..', a symlink out) are left
        # out, neither copied nor linked; the folder's own grid is copied. A label of TeX is drawn as text.
        with tempfile.TemporaryDirectory() as d:
            res = os.path.join(d, "res")
            os.makedirs(res)
            write(os.path.join(d, "secret.png"), "secret")
            write(os.path.join(res, "grid.png"), "grid")
            os.symlink(os.path.join(d, "secret.png"), os.path.join(res, "link.png"))
            t = trial("$\\frac{$", "wall", 1, [0.01], 1000)
            t["render"] = {"png": "../secret.png", "status": "ok"}
            doc = document([t, trial("b", "wall", 1, [0.02], 900)])
            doc["renders"] = {"grid": "../secret.png", "grid_per_scene": {
                "wall": "/etc/passwd", "ground": "link.png", "column": "grid.png", "rock": "trials"}}
            path = os.path.join(res, "results.json")
            with open(path, "w") as f:
                json.dump(doc, f)
            out = os.path.join(d, "out")
            report.write_report(doc, path, out, ["png"])
            self.assertEqual(os.listdir(os.path.join(out, "renders")), ["grid.png"])
            pages = [read(os.path.join(out, "index.html"))] + [
                read(os.path.join(out, "trials", f)) for f in os.listdir(os.path.join(out, "trials"))]
            for page in pages:
                self.assertNotIn("secret", page)
                self.assertNotIn("passwd", page)
                self.assertNotIn("link.png", page)
            self.assertTrue(os.path.exists(os.path.join(out, "fig-time-vs-size.png")))

    def test_a_trial_id_names_a_folder_under_trials_only(self):
        # A plant.glb outside the results folder, reached by a '..' id, is neither copied nor viewed; the
        # folder's own trial's plant is, gzipped, with its scene from the results' "scenes" map.
        with tempfile.TemporaryDirectory() as d:
            res = os.path.join(d, "res")
            os.makedirs(os.path.join(res, "trials", "b", "wall", "s1"))
            os.makedirs(os.path.join(res, "scenes"))
            os.makedirs(os.path.join(d, "outside"))
            write(os.path.join(d, "outside", "plant.glb"), "glTF-secret")
            write(os.path.join(res, "trials", "b", "wall", "s1", "plant.glb"), "glTF-own")
            write(os.path.join(res, "scenes", "wall-1234.glb"), "glTF-scene")
            bad = trial("a", "wall", 1, [0.01], 1000)
            bad["id"] = "../../outside"
            good = trial("b", "wall", 1, [0.02], 900)
            good["scene_hash"] = "1234"
            doc = document([bad, good])
            doc["scenes"] = {"1234": "scenes/wall-1234.glb"}
            path = os.path.join(res, "results.json")
            with open(path, "w") as f:
                json.dump(doc, f)
            out = os.path.join(d, "out")
            report.write_report(doc, path, out, ["png"])
            scripts = sorted(os.path.relpath(os.path.join(r, f), out) for r, _, fs in os.walk(out) for f in fs
                             if f.endswith(".glb.js"))
            self.assertEqual(scripts, ["scenes/wall-1234.glb.js", "trials/b_wall_s1/plant.glb.js"])
            text = read(os.path.join(out, "trials", "b_wall_s1", "plant.glb.js"))
            data = text.split('="', 1)[1].rsplit('";', 1)[0]
            self.assertEqual(gzip.decompress(base64.b64decode(data)), b"glTF-own")
            page = read(os.path.join(out, "trials", "b_wall_s1.html"))
            self.assertIn("data-scene='../scenes/wall-1234.glb.js'", page)
            self.assertIn("data-plant='b_wall_s1/plant.glb.js'", page)

    def test_noisy_repetitions_banner(self):
        steady, noisy = [0.010, 0.0101, 0.0102], [0.01, 0.02, 0.03]  # CV 1%, 50%
        cells = lambda k: [report.Cell(trial("a", "wall", i, noisy if i <= k else steady, 10)) for i in range(1, 5)]
        self.assertEqual(report.machine_warnings({"context": {}}, cells(1)), [])  # 1 of 4: a quarter, not more
        self.assertEqual(report.machine_warnings({"context": {}}, cells(2)),
                         ["The growth times of 2 of 4 cells with 2 or more repetitions varied by more than 10% over "
                          "repetitions (coefficient of variation): timings are noisy."])
        one = [report.Cell(trial("a", "wall", 1, [0.01], 10)), report.Cell(trial("a", "wall", 2, noisy, 10))]
        self.assertEqual(len(report.machine_warnings({"context": {}}, one)), 1)  # cells of one trial do not count
        page, _ = self.write(document([trial("a", "wall", i, noisy, 10) for i in (1, 2)]))
        self.assertIn("The growth times of 2 of 2 cells", page)

    def test_new_fields_are_the_schemas(self):
        # The fields read here, as harness/record/results.schema.json declares them (once it is generated with
        # the verdicts and the machine's state).
        defs = report.load_schema()["$defs"]
        if "verdict" not in defs or "load_average_start" not in defs["context"]["properties"]:
            self.skipTest("results.schema.json does not declare verdicts yet")
        self.assertEqual(set(defs["verdict"]["properties"]), {"status", "reasons"})
        self.assertEqual(set(defs["verdict"]["properties"]["status"]["enum"]), {"valid", "degenerate", "not_applicable"})
        self.assertEqual(set(report.VERDICT_SHORT), {"degenerate", "not_applicable"})
        self.assertIn("verdict", defs["cell"]["properties"])
        for k in ("load_average_start", "load_average_end", "cpu_mhz", "cpu_governor", "hardware_threads"):
            self.assertIn(k, defs["context"]["properties"])
        self.assertIn("peak_rss_bytes", defs["phase"]["properties"])


if __name__ == "__main__":
    unittest.main()
