"""Unit tests of reports/report.py's statistics and tables (run by ctest with /usr/bin/python3)."""
import json
import math
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "reports"))
import report  # noqa: E402


def trial(label, scene, seed, times, nodes, status="ok", metrics=None):
    return {"id": f"{label}/{scene}/s{seed}", "label": label, "algorithm": label, "scene": scene, "seed": seed,
            "sweep": {}, "status": status, "counts": {"nodes": nodes, "leaves": 0},
            "output_bytes": {"obj": 3 * nodes, "ply": nodes, "glb": nodes},
            "metrics": metrics or {"coverage": 0.5, "attached_fraction": 0.25, "penetration_samples": 0.0},
            "alloc": {"growth": {"bytes": 100 * nodes, "count": nodes}},
            "samples": [{"repetition": i, "status": status, "child_max_rss_bytes": 2 ** 20 * (10 + i),
                         "phases": {"growth": {"wall_s": t, "cpu_s": t}, "export": {"wall_s": 0.001, "cpu_s": 0.001}}}
                        for i, t in enumerate(times)] if status == "ok" else [{"repetition": 0, "status": status}]}


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
        self.assertEqual(a[:3], ["a", "wall", "2"])
        self.assertEqual(a[3], "16.0 ms [10.0 ms, 22.0 ms]")
        # A file written before the suite wrote summaries: the median, no interval.
        self.assertEqual(report.table_rows(cells)[0][3], "16.0 ms [no interval in this file]")
        self.assertEqual(a[6], "2000")
        self.assertEqual(a[7:], ["0.500", "0.250", "0.000", "-", "-"])  # no leaf metrics in these records
        self.assertEqual(b[3], "timeout")

    def test_latex_and_markdown(self):
        cells = [report.Cell(trial("ivy_luft", "wall", 1, [0.5, 0.6], 10))]
        pooled = {frozenset(["ivy_luft/wall/s1"]): {"n": 2, "median": 0.55, "lo": 0.5, "hi": 0.6, "exact": False}}
        rows = report.table_rows(cells, pooled)
        with tempfile.TemporaryDirectory() as d:
            report.write_latex(os.path.join(d, "t.tex"), rows, "50% of it")
            tex = open(os.path.join(d, "t.tex")).read()
            self.assertIn("\\toprule", tex)
            self.assertIn("ivy\\_luft & wall", tex)
            self.assertIn("50\\% of it", tex)
            self.assertIn("{[}$\\sim$", tex)  # '[~' escaped
            report.write_markdown(os.path.join(d, "t.md"), rows, "c")
            md = open(os.path.join(d, "t.md")).read().splitlines()
            self.assertEqual(md[0].count("|"), len(report.TABLE_HEAD) + 1)
            self.assertTrue(md[2].startswith("| ivy_luft | wall | 1 |"))

    def test_bad_results_are_clear_errors(self):
        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "r.json")
            open(p, "w").write("{\"trials\": [")
            with self.assertRaisesRegex(report.ReportError, "r.json: not valid JSON: line 1"):
                report.load_results(p)
            open(p, "w").write(json.dumps({"trials": []}))
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


if __name__ == "__main__":
    unittest.main()
