"""Every figure of the report is drawn at a paper width (3.5 in or 7 in) with no font under 7 pt at that width: the
PDFs themselves are read (page size from /MediaBox, font sizes from the text operators of their content streams).
Also the quality-against-cost (Pareto) front. Run by ctest with /usr/bin/python3."""
import math
import os
import re
import sys
import tempfile
import unittest
import zlib

sys.path.insert(0, os.path.dirname(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "reports"))
import report  # noqa: E402
from peers_test import DOC as PEERS  # noqa: E402
from report_test import document, trial  # noqa: E402

WIDTHS_PT = (72 * report.COLUMN_IN, 72 * report.PAGE_IN)


def pdf_width_and_fonts(path):
    """(page width in points, [every font size a text operator sets]) of a one-page PDF."""
    with open(path, "rb") as f:
        data = f.read()
    box = re.search(rb"/MediaBox\s*\[\s*([-\d.]+)\s+([-\d.]+)\s+([-\d.]+)\s+([-\d.]+)\s*\]", data)
    width = float(box.group(3)) - float(box.group(1))
    sizes = []
    for m in re.finditer(rb"stream\r?\n(.*?)endstream", data, re.S):
        raw = m.group(1)
        try:
            raw = zlib.decompress(raw)
        except zlib.error:
            pass
        sizes += [float(s) for s in re.findall(rb"/\w+\s+([\d.]+)\s+Tf\b", raw)]
    return width, sizes


def suite():
    """Three entries (one swept over four budgets) on two scenes, three seeds, leaves on one: every figure."""
    trials = []
    for scene in ("wall", "mesh:stanford-bunny"):
        for seed in (1, 2, 3):
            for label, budgets in (("spacecol-cling", [1000, 3000, 10000, 30000]), ("ivy-luft", [None]),
                                   ("lsystem-blossom", [None])):
                for b in budgets:
                    n = (b or 2000) * seed
                    t = trial(label, scene, seed, [1e-6 * n * (1 + 0.02 * k) for k in range(3)], n,
                              metrics={"coverage": min(1.0, 0.1 + n / 1e5), "attached_fraction": 0.9,
                                       "penetration_samples": 0.01, "leaf_overlap": 0.2 if "blossom" in label else None,
                                       "leaf_light_exposure": 0.6 if "blossom" in label else None})
                    if b:
                        t["sweep"] = {"point_count": b}
                        t["id"] = f"{label} point_count={b}/{scene}/s{seed}"
                    t["curve"] = {"step": [0, 1, 2, 3], "nodes": [1, n // 3, n // 2, n], "wall_s": [0, 0.1, 0.2, 0.4]}
                    t["output_bytes"]["glb_plain"] = 2 * n
                    trials.append(t)
    return document(trials)


class PaperSizes(unittest.TestCase):
    def test_every_figure_is_a_page_width_with_fonts_of_7pt_or_more(self):
        with tempfile.TemporaryDirectory() as d:
            doc = suite()
            figs = report.write_report(doc, os.path.join(d, "results.json"), d, ["png", "pdf"])
            report.peers_figure(PEERS, d, ["pdf"])
            names = [n for n, _ in figs] + ["fig-peers"]
            for want in ("fig-time-vs-size", "fig-memory-vs-size", "fig-file-size", "fig-seeds", "fig-quality",
                         "fig-growth-curves", "fig-sweep-point_count", "fig-pareto-wall",
                         "fig-pareto-mesh-stanford-bunny"):
                self.assertIn(want, names)
            for name in names:
                width, sizes = pdf_width_and_fonts(os.path.join(d, name + ".pdf"))
                self.assertTrue(any(math.isclose(width, w, abs_tol=0.5) for w in WIDTHS_PT), f"{name}: {width} pt wide")
                self.assertTrue(sizes, f"{name}: no text found")
                self.assertGreaterEqual(min(sizes), report.MIN_FONT_PT, f"{name}: a {min(sizes)} pt font")

    def test_the_reader_sees_a_small_font(self):
        # The check itself can fail: a figure with a 5 pt label is caught.
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        with tempfile.TemporaryDirectory() as d:
            fig = plt.figure(figsize=(report.PAGE_IN, 2))
            fig.text(0.5, 0.5, "tiny", fontsize=5)
            fig.savefig(os.path.join(d, "f.pdf"))
            plt.close(fig)
            width, sizes = pdf_width_and_fonts(os.path.join(d, "f.pdf"))
        self.assertAlmostEqual(width, 504.0)
        self.assertEqual(sizes, [5.0])


class Pareto(unittest.TestCase):
    def test_the_front_keeps_only_points_nothing_beats(self):
        pts = [(1.0, 0.2, "a"), (2.0, 0.5, "b"), (3.0, 0.4, "c"), (4.0, 0.9, "d"), (4.0, 0.7, "e"), (0.5, 0.2, "f")]
        self.assertEqual([p[2] for p in report.pareto_front(pts)], ["f", "b", "d"])
        # Less is better (penetration): the fastest, then only improvements.
        self.assertEqual([p[2] for p in report.pareto_front(pts, lower_is_better=True)], ["f"])
        self.assertEqual([p[2] for p in report.pareto_front([(1, 0.5, "x"), (2, 0.1, "y")], True)], ["x", "y"])

    def test_points_are_per_sweep_value_over_valid_seeds(self):
        cells = [report.Cell(t) for t in suite()["trials"]]
        pts = report.pareto_points([c for c in cells if c.valid], "wall", "coverage")
        self.assertEqual(len(pts["spacecol-cling"]), 4)  # one per point_count
        self.assertEqual(len(pts["ivy-luft"]), 1)
        # point_count 1000: seeds 1-3 have n = 1000, 2000, 3000; the medians over seeds.
        t, q, row = pts["spacecol-cling"][0]
        self.assertEqual(row, "spacecol-cling point_count=1000")
        self.assertAlmostEqual(t, 1e-6 * 2000 * 1.02)
        self.assertAlmostEqual(q, 0.1 + 2000 / 1e5)

    def test_an_unknown_metric_is_a_clear_error(self):
        with tempfile.TemporaryDirectory() as d:
            with self.assertRaisesRegex(report.ReportError, "--pareto-metric coverge: no cell of .* has it; its "
                                                            "metrics: attached_fraction, coverage"):
                report.write_report(suite(), os.path.join(d, "r.json"), d, ["png"], pareto_metric="coverge")


class Readable(unittest.TestCase):
    """What a reader of the figures must be able to tell apart or see whole."""

    def drawn(self, doc):
        """{figure name: the figure}, drawn (so that text has its extent) just before the report saves it."""
        figs, save = {}, report.Canvas.save

        def keep(canvas, fig, name, caption):
            fig.canvas.draw()
            figs[name] = (fig, [(a.get_title(), a.get_ylim(), a.get_legend()) for a in fig.axes],
                          fig.bbox.extents)
            save(canvas, fig, name, caption)
        report.Canvas.save = keep
        try:
            with tempfile.TemporaryDirectory() as d:
                report.write_report(doc, os.path.join(d, "results.json"), d, ["png"])
        finally:
            report.Canvas.save = save
        return figs

    def test_no_two_scenes_share_both_colour_and_marker(self):
        with tempfile.TemporaryDirectory() as d:
            canvas = report.Canvas([], d, [])
            for n in (8, 10, 11, 25, 100):
                canvas.scenes = [f"scene{i}" for i in range(n)]
                colour, marker = canvas.scene_styles()
                pairs = {(tuple(colour[s]), marker[s]) for s in canvas.scenes}
                self.assertEqual(len(pairs), n, f"{n} scenes")
                if n <= 10:
                    self.assertEqual(len({tuple(c) for c in colour.values()}), n, "up to ten: a colour each")

    def test_ten_scenes_legend_stays_inside_the_quality_figure(self):
        scenes = ["wall", "facade", "column", "corner", "pergola", "boulder", "trunk", "envelope",
                  "mesh:stanford-bunny", "mesh:spot"]
        doc = document([trial(label, scene, 1, [0.1], 1000) for label in ("a", "b") for scene in scenes])
        _, axes, (x0, y0, x1, y1) = self.drawn(doc)["fig-quality"]
        legends = [legend for _, _, legend in axes if legend is not None]
        self.assertEqual(len(legends), 1)
        box = legends[0].get_window_extent()
        self.assertTrue(box.x0 >= x0 - 1 and box.y0 >= y0 - 1 and box.x1 <= x1 + 1 and box.y1 <= y1 + 1,
                        f"legend {box.extents} outside the figure {(x0, y0, x1, y1)}")

    def test_a_growth_curve_that_rises_above_its_end_is_drawn_whole(self):
        t = trial("lsystem", "wall", 1, [0.1], 100)
        t["curve"] = {"step": [0, 1, 2, 3], "nodes": [1, 80, 250, 100], "wall_s": [0, 0.1, 0.2, 0.3]}
        _, axes, _ = self.drawn(document([t]))["fig-growth-curves"]
        top = [ylim[1] for title, ylim, _ in axes if title == "wall"]
        self.assertEqual(len(top), 1)
        self.assertGreaterEqual(top[0], 2.5, "the curve peaks at 2.5 times its final count")

    def test_a_log_axis_under_a_decade_has_several_labels(self):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        for lo, hi in ((35, 95), (0.12, 0.9), (3, 70)):
            fig, ax = plt.subplots()
            ax.set_yscale("log")
            ax.plot([1, 2], [lo, hi])
            ax.set_ylim(lo, hi)
            report.plain_log_ticks(ax)
            fig.canvas.draw()
            shown = [t.get_text() for t in ax.yaxis.get_ticklabels() + ax.yaxis.get_ticklabels(minor=True)
                     if t.get_text() and lo <= t.get_position()[1] <= hi]
            plt.close(fig)
            self.assertGreaterEqual(len(shown), 3, f"{lo}..{hi}: {shown}")


if __name__ == "__main__":
    unittest.main()
