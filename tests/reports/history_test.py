#!/usr/bin/python3
"""reports/history.py: change points on series with known steps, and (given the growbench binary) a
history built with `growbench history add` and plotted with `growbench history plot`.

usage: history_test.py [GROWBENCH WORKDIR]
"""
import json
import os
import random
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "reports"))
import history  # noqa: E402

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


rng = random.Random(3)
noisy = lambda c, n: [c * (1 + 0.005 * rng.uniform(-1, 1)) for _ in range(n)]

# A 10% step after six commits of 0.5% noise: found at index 6.
check(history.change_points(noisy(1.0, 6) + noisy(1.1, 6)) == [6], "a 10% step at commit 6")
# Noise alone: nothing.
check(history.change_points(noisy(1.0, 12)) == [], "no change point in noise")
# Two steps, up then back down.
check(history.change_points(noisy(1.0, 5) + noisy(1.2, 5) + noisy(1.0, 5)) == [5, 10], "up at 5, down at 10")
# Deterministic (instruction counts): a 2% rise at the newest commit counts; 0.5% does not.
check(history.change_points([1e9] * 7 + [1.02e9]) == [7], "a 2% step at the last commit")
check(history.change_points([1e9] * 7 + [1.005e9]) == [], "a 0.5% step is under --min-step")
check(history.change_points([5.0]) == [], "one commit")

if len(sys.argv) == 3:
    growbench, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    # Five commits of a two-cell suite; cell a's growth slows by 20% from commit c3 on.
    for i, commit in enumerate(["c0", "c1", "c2", "c3", "c4"]):
        res = {"kind": "growbench-results", "mode": "timing", "suite": {"name": "t"},
               "context": {"growbench_commit": commit, "commit_time": 1000 + i, "cpu_model": "Test CPU (R)",
                           "hardware_threads": 2, "date": f"2026-11-2{i}T00:00:00Z", "dirty": "false"},
               "trials": []}
        for cell, base in [("a/wall/s1", 0.010), ("b/wall/s1", 0.020)]:
            slow = 1.2 if cell == "a/wall/s1" and i >= 3 else 1.0
            samples = [{"status": "ok", "phases": {"growth": {"wall_s": base * slow * (1 + 0.003 * r), "cpu_s": base * slow,
                                                              "peak_rss_bytes": 1e6}}} for r in range(3)]
            res["trials"].append({"id": cell, "status": "ok", "geometry_hash": "h", "counts": {"nodes": 10},
                                  "samples": samples})
        path = os.path.join(work, f"r{i}.json")
        json.dump(res, open(path, "w"))
        out = subprocess.run([growbench, "history", "add", path, "--dir", os.path.join(work, "hist")],
                             capture_output=True, text=True)
        check(out.returncode == 0, f"history add {commit}: {out.stdout}{out.stderr}")
    files = sorted(os.listdir(os.path.join(work, "hist", "test_cpu_r_-2t", "t")))
    check(files == ["c0.json", "c1.json", "c2.json", "c3.json", "c4.json"], f"one file per commit: {files}")
    # The same commit again: a second run in the same file.
    subprocess.run([growbench, "history", "add", os.path.join(work, "r4.json"), "--dir", os.path.join(work, "hist")],
                   check=True, capture_output=True)
    c4 = json.load(open(os.path.join(work, "hist", "test_cpu_r_-2t", "t", "c4.json")))
    check(len(c4["runs"]) == 2, "a second run of a commit is appended")
    out = subprocess.run([growbench, "history", "plot", "--dir", os.path.join(work, "hist"), "--out",
                          os.path.join(work, "plot")], capture_output=True, text=True)
    check(out.returncode == 0, f"history plot: {out.stdout}{out.stderr}")
    cp = json.load(open(os.path.join(work, "plot", "change_points.json")))
    found = {(c["cell"], c["metric"], c["after"]) for g in cp["groups"] for c in g["change_points"]}
    check(("a/wall/s1", "growth_wall_s", "c3") in found, f"the slowdown at c3 is a change point: {found}")
    check(not any(c[0] == "b/wall/s1" for c in found), f"nothing changed in cell b: {found}")
    check(os.path.exists(os.path.join(work, "plot", "test_cpu_r_-2t", "t", "growth_wall_s.png")), "the figure")
    check(os.path.exists(os.path.join(work, "plot", "index.html")), "index.html")
    # The page's interactive plot, driven in headless chromium (tools/viewer/test-history.mjs).
    viewer = os.path.join(os.path.dirname(__file__), "..", "..", "tools", "viewer")
    out = subprocess.run(["node", os.path.join(viewer, "test-history.mjs"), os.path.join(work, "plot", "index.html"),
                          "a/wall/s1", "c3", "1.2"], capture_output=True, text=True)
    check(out.returncode == 0, f"the interactive history plot: {out.stdout}{out.stderr}")

    # Hostile history files (written by hand, not by history add): a machine and suite that would lead out
    # of --out, commits and a cell carrying HTML and TeX. Nothing is written outside --out, nothing is
    # injected into index.html, and matplotlib draws the TeX as text rather than failing on it.
    escape_to = os.path.join(work, "outside")
    hostile = os.path.join(work, "hostile", "m", "s")
    os.makedirs(hostile)
    for i, commit in enumerate(["<script>alert(1)</script>", "$\\frac{$", "<img src=x onerror=alert(2)>"]):
        doc = {"kind": "growbench-history", "schema_version": 1, "commit": commit, "commit_time": i,
               "machine": "../..", "suite": escape_to, "runs": [{"date": f"d{i}", "cells": {
                   "$x^{$/<b>/s1": {"growth_wall_s": 0.01 * (1 + i), "geometry_hash": f"h{i}"}}}]}
        json.dump(doc, open(os.path.join(hostile, f"c{i}.json"), "w"))
    plot = os.path.join(work, "hostile_out", "plot")
    out = subprocess.run([growbench, "history", "plot", "--dir", os.path.join(work, "hostile"), "--out", plot],
                         capture_output=True, text=True)
    check(out.returncode == 0, f"history plot of hostile names: {out.stdout}{out.stderr}")
    check(os.listdir(os.path.join(work, "hostile_out")) == ["plot"], "nothing beside --out")
    check(not os.path.exists(escape_to), "nothing at the absolute suite name")
    page = open(os.path.join(plot, "index.html"), encoding="utf-8").read()
    check("<script>alert" not in page and "<img src=x" not in page and "<b>" not in page,
          "no element injected into index.html")
    check("at &lt;img src=x onerror=alert(2)&gt;" in page, "the commit is shown, escaped")
    written = [os.path.relpath(os.path.join(d, f), plot) for d, _, fs in os.walk(plot) for f in fs]
    check(any(w.endswith("growth_wall_s.png") for w in written), f"the hostile group's figure: {written}")

print("history tests:", "FAILED" if failures else "OK")
sys.exit(1 if failures else 0)
