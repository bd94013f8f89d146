"""Unit tests of `make peers`' pure parts: the grammar scripts/peers writes for growbench from a case, the
ratio interval, and the report's "versus peers" table (run by ctest with /usr/bin/python3; no peer needed)."""
import importlib.machinery
import importlib.util
import json
import os
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "reports"))
import report  # noqa: E402

_loader = importlib.machinery.SourceFileLoader("peers", os.path.join(HERE, "..", "..", "scripts", "peers"))
_spec = importlib.util.spec_from_loader("peers", _loader)
peers = importlib.util.module_from_spec(_spec)
_loader.exec_module(peers)


def case(**kw):
    c = {"name": "c", "kind": "lsystem", "title": "t", "target": 5, "iterations": 3}
    c.update(kw)
    return c


class Grammar(unittest.TestCase):
    def test_string_rules(self):
        g = peers.growbench_grammar(case(axiom="F", rules={"F": "F[+F]F[-F]F"}))
        self.assertEqual(g.splitlines()[1:], ["premise: F", "generations: 3", "F = F[+F]F[-F]F"])

    def test_context_rule_and_tail(self):
        g = peers.growbench_grammar(case(axiom="b", axiom_tail=["a", 4], rules={"b<a": "b", "b": "a"}))
        self.assertEqual(g.splitlines()[1:], ["premise: baaaa", "generations: 3", "b < a = b", "b = a"])

    def test_parametric_rules(self):
        g = peers.growbench_grammar(case(axiom=[["A", 1, 10]],
                                         rules={"A(l,w)": [["!", "w"], ["["], ["A", "l*0.9", "w*0.707"], ["]"]]}))
        self.assertEqual(g.splitlines()[1:], ["premise: A(1,10)", "generations: 3", "A(l,w) = !(w)[A(l*0.9,w*0.707)]"])

    def test_the_committed_cases_make_grammars(self):
        with open(os.path.join(HERE, "..", "..", "bench", "peers", "cases.json")) as f:
            cases = json.load(f)["cases"]
        tree = next(c for c in cases if c["name"] == "abop-monopodial")
        self.assertIn("A(l,w) = !(w)F(l)[&(45)B(l*0.6,w*0.707)]/(137.5)A(l*0.9,w*0.707)",
                      peers.growbench_grammar(tree).splitlines())


class Ratio(unittest.TestCase):
    def test_identical_samples_give_a_point_interval(self):
        self.assertEqual(peers.ratio_interval([2.0] * 5, [0.5] * 5, seed=1), (4.0, 4.0))

    def test_interval_brackets_the_ratio_of_medians(self):
        lo, hi = peers.ratio_interval([1.0, 2.0, 3.0, 4.0, 5.0], [1.0] * 5, seed=1)
        self.assertLessEqual(lo, 3.0)
        self.assertGreaterEqual(hi, 3.0)
        self.assertGreaterEqual(lo, 1.0)
        self.assertLessEqual(hi, 5.0)


DOC = {"schema": "growbench-peers/1", "started": "2026-01-01T00:00:00+00:00", "repetitions": 5, "untimed_first_runs": 1,
       "interval": {"level": 0.95, "method": "bootstrap percentile of the ratio of medians, 4000 resamples"},
       "machine": {"cpu": "test cpu", "cores": 2}, "growbench": {"version": "abc1234"},
       "cases": [{"name": "ivy-cube", "kind": "ivy", "title": "ivy on a cube", "target": 50, "peer": "Blender 3.4.1",
                  "growbench_threads": 1, "peer_median_s": 3.0, "growbench_median_s": 0.075, "ratio": 40.0,
                  "ratio_low": 30.0, "ratio_high": 45.5, "cpu_ratio": 20.0, "peer_count": 60860, "growbench_count": 65911,
                  "count_unit": "nodes", "load_1min": [1.5, 2.5], "check": {"ok": True, "what": "node counts within 10%"}}]}


class Report(unittest.TestCase):
    def test_rows(self):
        self.assertEqual(report.peers_rows(DOC), [[
            "ivy on a cube", "Blender 3.4.1", "3.00 s", "75.0 ms (1 thr.)", "40.0x [30.0, 45.5]", ">= 50x not met",
            "20.0x", "60,860 nodes", "65,911 nodes", "ok: node counts within 10%"]])

    def test_whole_operator_row(self):
        doc = json.loads(json.dumps(DOC))
        doc["cases"][0]["whole"] = {"what": "whole vs growth + meshing", "peer_s": [9.0, 8.0, 10.0],
                                    "growbench_s": [1.0, 1.0, 1.0], "ratio": 9.0, "ratio_low": 8.0, "ratio_high": 10.0}
        rows = report.peers_rows(doc)
        self.assertEqual(rows[1], ["ivy on a cube: whole vs growth + meshing", "Blender 3.4.1", "9.00 s",
                                   "1.00 s (1 thr.)", "9.0x [8.0, 10.0]", "-", "-", "", "", ""])

    def test_page_alone(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "peers.json")
            with open(path, "w") as f:
                json.dump(DOC, f)
            self.assertEqual(report.main(["--peers", path, "--out", os.path.join(d, "r"), "--formats", "png"]), 0)
            page = open(os.path.join(d, "r", "index.html")).read()
            self.assertIn("<h2>Versus peers</h2>", page)
            self.assertIn("<td>40.0x [30.0, 45.5]</td>", page)
            self.assertIn("load during the runs 1.5 to 2.5. Each side ran 1 untimed time(s) before its timed", page)
            self.assertTrue(os.path.exists(os.path.join(d, "r", "fig-peers.png")))

    def test_not_a_peers_file(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "peers.json")
            with open(path, "w") as f:
                json.dump({"schema": "other"}, f)
            with self.assertRaisesRegex(report.ReportError, "not a peers file of scripts/peers"):
                report.load_peers(path)


if __name__ == "__main__":
    unittest.main()
