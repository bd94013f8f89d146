"""table.tex fits a page: compiled with pdflatex in a two-column article (run by ctest with /usr/bin/python3)."""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "reports"))
import paper_tables  # noqa: E402
import report  # noqa: E402
from report_test import trial  # noqa: E402

DOCUMENT = r"""\documentclass[twocolumn]{article}
\usepackage{booktabs}
\begin{document}
\input{table}
\end{document}
"""


def summary(times):
    s = sorted(times)
    return {"n": len(s), "median": s[len(s) // 2], "lo": s[0], "hi": s[-1], "exact": len(s) >= 6}


def suite_tables(entries, scenes, seeds=3):
    """table.tex of a suite of `entries` x `scenes` x `seeds`, with times over five orders of magnitude."""
    trials = []
    for i, label in enumerate(entries):
        for j, scene in enumerate(scenes):
            for seed in range(1, seeds + 1):
                base = 10.0 ** (-4 + (i + j) % 6) * (1 + 0.1 * seed)
                times = [base * (1 + 0.01 * k) for k in range(5)]
                verdict = ("not_applicable", ["nothing to climb"]) if (i + j) % 7 == 3 else ("valid",)
                t = trial(label, scene, seed, times, 1000 * (i + 1) * seed, verdict=verdict,
                          metrics={"coverage": 0.123, "attached_fraction": 1.0, "penetration_samples": 0.0,
                                   "leaf_overlap": None, "leaf_light_exposure": 0.5})
                t["summary"] = {"growth_s": summary(times)}
                t["output_bytes"]["glb"] = 3_500_000 * (i + 1)
                trials.append(t)
    cells = [report.Cell(t) for t in trials]
    # The suite's summaries over each row's valid seeds, as results.json holds them.
    pooled = {}
    for _, _, group in report.table_groups(cells):
        valid = [c for c in group if c.valid]
        if valid:
            pooled[frozenset(c.id() for c in valid)] = summary([x for c in valid for x in c.growth])
    rows = {(label, scene): report.row_numbers(group, pooled) for label, scene, group in report.table_groups(cells)}
    return rows, report.ordered(c.row for c in cells), report.ordered(c.scene for c in cells), report.table_notes(cells)


def compile_tex(tex):
    """(pdflatex's exit code, its log) for table.tex inside the two-column article."""
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "table.tex"), "w") as f:
            f.write(tex)
        with open(os.path.join(d, "doc.tex"), "w") as f:
            f.write(DOCUMENT)
        r = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "doc.tex"], cwd=d,
                           capture_output=True, text=True, timeout=120)
        with open(os.path.join(d, "doc.log"), errors="replace") as f:
            return r.returncode, f.read()


class Fits(unittest.TestCase):
    def write(self, entries, scenes, seeds=3):
        rows, labels, scene_names, notes = suite_tables(entries, scenes, seeds)
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "table.tex")
            paper_tables.write_tex(path, rows, labels, scene_names, report.QUALITY, notes)
            with open(path) as f:
                return f.read()

    def assert_fits(self, tex):
        self.assertIsNotNone(shutil.which("pdflatex"), "pdflatex is missing: scripts/install-deps installs it")
        code, log = compile_tex(tex)
        self.assertEqual(code, 0, log[-3000:])
        self.assertNotIn("Overfull \\hbox", log, re.findall(r"Overfull \\hbox.*", log)[:5])
        self.assertNotIn("Float too large", log)

    def test_the_standard_suites_shape_fits_a_two_column_article(self):
        entries = ["spacecol-cling", "spacecol-avoid", "lsystem-wrap", "lsystem-blossom", "ivy-luft", "ivy-blender",
                   "hadrich", "vines"]
        scenes = ["wall", "facade", "column", "corner", "pergola", "boulder", "trunk", "envelope",
                  "mesh:stanford-bunny", "mesh:spot"]
        tex = self.write(entries, scenes)
        self.assert_fits(tex)
        # Ten scenes do not fit one float: the tables are split, and each part says so.
        self.assertIn("(part 1 of", tex)
        # One unit per table: the time table names its unit once, its cells are numbers.
        time_tables = [t for t in tex.split("\\begin{table") if "\\caption{Growth time" in t]
        self.assertTrue(time_tables)
        for t in time_tables:
            body = t[t.index("\\midrule"):]
            self.assertNotRegex(body, r"\d (ms|s|us)\b")
        self.assertIn("\\caption{Growth time (ms)", tex)  # the median of the medians is under 1 s
        self.assertIn("not appl.", tex)
        self.assertIn("\\paragraph{Left out of comparisons (verdict not valid):}", tex)

    def test_many_entries_split_rows_and_long_names_still_fit(self):
        entries = [f"spacecol point_count={1000 * k} step=0.0{k}" for k in range(1, 46)]
        tex = self.write(entries, ["wall", "boulder"], seeds=1)
        self.assert_fits(tex)
        self.assertIn("(part 2 of 2)", tex)

    def test_one_scene_fits_a_column(self):
        tex = self.write(["a", "b"], ["wall"], seeds=2)
        self.assertIn("\\begin{table}[tbp]", tex)
        self.assertNotIn("\\begin{table*}", tex)
        self.assert_fits(tex)


class Numbers(unittest.TestCase):
    def test_significant_figures(self):
        self.assertEqual([paper_tables.sig(x) for x in (12345.6, 123.4, 12.34, 1.234, 0.1234, 0.001234, 0)],
                         ["12346", "123", "12.3", "1.23", "0.123", "0.00123", "0"])

    def test_units(self):
        self.assertEqual(paper_tables.time_unit([2e-5, 9e-4, 5e-4])[1:], ("us", 1e-6))
        self.assertEqual(paper_tables.time_unit([2e-5, 9.9, 0.5])[1:], ("ms", 1e-3))
        self.assertEqual(paper_tables.time_unit([0.1, 12.0, 3.0])[1:], ("s", 1.0))
        self.assertEqual(paper_tables.bytes_unit([5 * 2 ** 20, 50 * 2 ** 20])[1], "MiB")

    def test_a_time_cell_has_its_interval_only_over_two_trials_or_more(self):
        r = {"group": [1], "valid": [1], "failed": [], "time": {"n": 3, "median": 0.012, "lo": 0.011, "hi": 0.0135}}
        self.assertEqual(paper_tables.cell_text(r, "time", 1e-3), "12.0 [11.0, 13.5]")
        r["time"] = {"n": 1, "median": 0.012, "lo": 0.012, "hi": 0.012}
        self.assertEqual(paper_tables.cell_text(r, "time", 1e-3), "12.0")
        r["group"] = [1, 2]  # a seed left out
        self.assertEqual(paper_tables.cell_text(r, "time", 1e-3), "12.0$^\\dagger$")


if __name__ == "__main__":
    unittest.main()
