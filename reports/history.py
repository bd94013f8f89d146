#!/usr/bin/python3
"""growbench history plot: each metric of a history directory over commits, with change points.

A history directory (growbench history add / suite --history) holds MACHINE/SUITE/COMMIT.json, each
with the runs of one suite at one commit on one machine, reduced to per-cell medians. For every
machine and suite this draws, per metric, one line per cell (its value over the first commit's, on a
log scale), orders commits by commit time, and marks change points: commits where the series steps
to a new level. Writes METRIC.png/.pdf per machine and suite, change_points.json, and index.html.

Change points come from binary segmentation of the log values: a split is kept when it lowers the
squared error by more than 2 sigma^2 ln(n) (sigma: the noise, estimated robustly from successive
differences) and the levels on either side differ by at least --min-step (default 1%). Deterministic
series (instruction counts) have sigma 0, so any step of at least --min-step is a change point.
"""
import argparse
import glob
import html
import json
import math
import os
import re
import statistics
import sys
import time
import urllib.parse

import history_view

METRICS = [
    ("growth_wall_s", "growth wall time"),
    ("growth_cpu_s", "growth CPU time"),
    ("total_wall_s", "all phases, wall time"),
    ("growth_peak_rss_bytes", "growth peak RSS"),
    ("nodes", "nodes"),
]


def noise_sigma(y):
    """Robust noise level of a series: MAD of successive differences, scaled for one value."""
    if len(y) < 3:
        return 0.0
    d = [abs(b - a) for a, b in zip(y, y[1:])]
    return 1.4826 * statistics.median(d) / math.sqrt(2.0)


def sse(y, a, b):
    seg = y[a:b]
    m = sum(seg) / len(seg)
    return sum((v - m) ** 2 for v in seg)


def change_points(values, min_step=0.01):
    """Indices k where the series steps to a new level (k is the first index of the new level)."""
    y = [math.log(v) for v in values if v > 0]
    if len(y) != len(values) or len(y) < 2:
        return []
    n = len(y)
    sigma = noise_sigma(y)
    beta = 2.0 * sigma * sigma * math.log(n)
    found = []

    def split(a, b):
        if b - a < 2:
            return
        total = sse(y, a, b)
        best, best_k = 0.0, None
        for k in range(a + 1, b):
            gain = total - sse(y, a, k) - sse(y, k, b)
            if gain > best + 1e-15:
                best, best_k = gain, k
        if best_k is None or best <= beta:
            return
        left = sum(y[a:best_k]) / (best_k - a)
        right = sum(y[best_k:b]) / (b - best_k)
        if abs(right - left) < math.log(1.0 + min_step):
            return
        found.append(best_k)
        split(a, best_k)
        split(best_k, b)

    split(0, n)
    return sorted(found)


def safe_name(s):
    """A folder name for a machine or suite name a history file gives, as growbench's safe_name makes
    them: characters outside [A-Za-z0-9-_.=,] become '_', and so do leading dots ('..' would leave --out,
    '.x' would be hidden)."""
    s = re.sub(r"[^A-Za-z0-9._=,-]", "_", str(s))
    dots = len(s) - len(s.lstrip("."))
    return "_" * dots + s[dots:]


def fail(message):
    """Bad input: the message, and exit status 2 (growbench's contract; 1 would read as a regression)."""
    print(f"history: error: {message}", file=sys.stderr)
    sys.exit(2)


FILE_KEY = " file"  # where load() found a document (no history file has a key that starts with a space)


def load(dir_):
    groups = {}
    for path in sorted(glob.glob(os.path.join(dir_, "*", "*", "*.json"), include_hidden=True)):
        try:
            with open(path, encoding="utf-8") as f:
                doc = json.load(f)
        except (OSError, ValueError, RecursionError) as e:
            fail(f"{path}: not a history file ({e})")
        if not isinstance(doc, dict) or doc.get("kind") != "growbench-history":
            fail(f"{path}: not a history file (kind {doc.get('kind') if isinstance(doc, dict) else None!r})")
        if not isinstance(doc.get("runs"), list):
            fail(f"{path}: at runs: expected an array of runs")
        doc[FILE_KEY] = path
        groups.setdefault((doc.get("machine", ""), doc.get("suite", "")), []).append(doc)
    for docs in groups.values():
        docs.sort(key=lambda d: (d.get("commit_time") or 0, d["runs"][0].get("date", "") if d["runs"] else ""))
    return groups


def series(docs):
    """{(cell, metric): [value or None per commit]}, medians over each commit's runs."""
    out = {}
    for i, doc in enumerate(docs):
        per = {}
        for run in doc["runs"]:
            for cell, c in run["cells"].items():
                for m, _ in METRICS:
                    if isinstance(c.get(m), (int, float)):
                        per.setdefault((cell, m), []).append(float(c[m]))
                for phase, ir in (c.get("instructions") or {}).items():
                    per.setdefault((cell, "instructions." + phase), []).append(float(ir))
        for key, vals in per.items():
            out.setdefault(key, [None] * len(docs))[i] = statistics.median(vals)
    return out


def behaviour_changes(docs):
    """(cell, commit index) where the geometry hash differs from the previous commit's."""
    changes = []
    last = {}
    for i, doc in enumerate(docs):
        for run in doc["runs"][-1:]:
            for cell, c in run["cells"].items():
                h = c.get("geometry_hash")
                if h and cell in last and last[cell] != h:
                    changes.append((cell, i))
                if h:
                    last[cell] = h
    return changes


def commit_dates(docs):
    """Each commit's date: its commit time (UTC) when the history file has one, else its first run's date."""
    out = []
    for d in docs:
        t = d.get("commit_time")
        if isinstance(t, (int, float)) and not isinstance(t, bool) and 0 <= t < 2 ** 40:
            out.append(time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(t)))
        else:
            out.append(str(d["runs"][0].get("date", "")) if d["runs"] and isinstance(d["runs"][0], dict) else "")
    return out


def metric_words(metrics):
    words = dict(METRICS)
    return {m: words.get(m, f"instructions, {m.split('.', 1)[1]} phase" if m.startswith("instructions.") else m)
            for m in metrics}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir")
    ap.add_argument("--out", required=True)
    ap.add_argument("--min-step", type=float, default=0.01)
    a = ap.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    plt.rcParams["text.parse_math"] = False  # names and commits are data, never TeX

    groups = load(a.dir)
    if not groups:
        fail(f"{a.dir}: no history files (MACHINE/SUITE/COMMIT.json); add runs with growbench history add")
    os.makedirs(a.out, exist_ok=True)
    report = {"min_step": a.min_step, "groups": []}
    body = []
    for (machine, suite), docs in sorted(groups.items()):
        commits = [str(d.get("commit", "")) for d in docs]
        group = {"machine": machine, "suite": suite, "commits": commits, "change_points": [],
                 "behaviour_changes": [{"cell": c, "commit": commits[i]} for c, i in behaviour_changes(docs)]}
        sub = os.path.join(safe_name(machine), safe_name(suite))
        os.makedirs(os.path.join(a.out, sub), exist_ok=True)
        data = series(docs)
        metrics = sorted({m for _, m in data})
        marks = []  # (cell, metric, commit index) of each change point: commit names need not be unique
        figures = []
        for m in metrics:
            cells = sorted(c for c, mm in data if mm == m)
            fig, ax = plt.subplots(figsize=(8, 4.5))
            for cell in cells:
                vals = data[(cell, m)]
                idx = [i for i, v in enumerate(vals) if v is not None and v > 0]
                if not idx:
                    continue
                ys = [vals[i] for i in idx]
                rel = [v / ys[0] for v in ys]
                (line,) = ax.plot(idx, rel, marker="o", ms=3, lw=1, label=cell)
                for k in change_points(ys, a.min_step):
                    i0, i1 = idx[k - 1], idx[k]
                    ratio = statistics.median(ys[k:]) / statistics.median(ys[:k])
                    ax.plot([i1], [rel[k]], marker="D", ms=9, mfc="none", mec=line.get_color(), mew=2)
                    group["change_points"].append({"cell": cell, "metric": m, "before": commits[i0],
                                                   "after": commits[i1], "ratio": ratio})
                    marks.append((cell, m, i1))
            ax.set_yscale("log")
            plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
            ax.yaxis.set_major_formatter(plain)
            ax.yaxis.set_minor_formatter(plain)
            ax.set_xticks(range(len(commits)))
            ax.set_xticklabels([c[:8] for c in commits], rotation=60, fontsize=7)
            ax.set_ylabel(f"{m} / first commit's")
            ax.set_title(f"{m} on {machine} ({suite}); diamonds: change points")
            ax.grid(True, which="both", alpha=0.3)
            if len(cells) <= 20:
                ax.legend(fontsize=6, ncol=2)
            fig.tight_layout()
            name = m.replace("/", "_")
            for ext in ("png", "pdf"):
                fig.savefig(os.path.join(a.out, sub, f"{name}.{ext}"), dpi=110)
            plt.close(fig)
            figures.append((m, os.path.join(sub, f"{name}.png")))
        report["groups"].append(group)
        rows = "".join(
            f"<tr><td>{html.escape(c['cell'])}</td><td>{html.escape(c['metric'])}</td><td>{html.escape(c['before'])}</td>"
            f"<td>{html.escape(c['after'])}</td><td>{c['ratio']:.3f}</td></tr>" for c in group["change_points"])
        body.append(f"<h2>{html.escape(machine)} / {html.escape(suite)}: {len(commits)} commits</h2>")
        body.append("<table><tr><th>cell</th><th>metric</th><th>before</th><th>after</th><th>after/before</th></tr>"
                    f"{rows or '<tr><td colspan=5>no change points</td></tr>'}</table>")
        if group["behaviour_changes"]:
            body.append("<p>Behaviour changed (geometry hash): " + ", ".join(
                f"{html.escape(b['cell'])} at {html.escape(b['commit'])}" for b in group["behaviour_changes"]) + "</p>")
        # Links: each part of the path quoted, so that '#', '?' or '%' in a folder name stays a file name.
        files = ["./" + "/".join(urllib.parse.quote(part) for part in os.path.relpath(d[FILE_KEY], a.out).split(os.sep))
                 for d in docs]
        body.append(history_view.group_html(sub, commits, commit_dates(docs), files, data, marks,
                                            metric_words(metrics)))
        body.append("<details><summary>The same as static figures (PNG, with PDFs beside them)</summary>")
        for m, png in figures:
            body.append(f"<figure><img src='{html.escape(png)}' alt='{html.escape(m)}'><figcaption>{html.escape(m)}</figcaption></figure>")
        body.append("</details>")
    with open(os.path.join(a.out, "change_points.json"), "w") as f:
        json.dump(report, f, indent=1)
    with open(os.path.join(a.out, "index.html"), "w") as f:
        f.write("<!doctype html><meta charset='utf-8'><title>growbench history</title>"
                "<style>body{font-family:sans-serif;max-width:70em;margin:auto}table{border-collapse:collapse}"
                "td,th{border:1px solid #ccc;padding:2px 6px}img{max-width:100%}.note{color:#555}"
                f"{history_view.STYLE}</style>"
                f"<h1>growbench history</h1><p>Change points: a step of at least {100 * a.min_step:g}% that the noise "
                "does not explain (binary segmentation, see reports/history.py).</p>" + "".join(body) +
                f"<script>{history_view.SCRIPT}</script>")
    n = sum(len(g["change_points"]) for g in report["groups"])
    print(f"history: {len(groups)} machine/suite groups, {n} change points; wrote {a.out}/index.html")


if __name__ == "__main__":
    try:
        main()
    except OSError as e:  # the output directory cannot be made or written (a file in the way, a full disk)
        fail(f"{e.filename}: cannot write: {e.strerror}")
