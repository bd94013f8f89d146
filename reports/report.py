#!/usr/bin/python3
"""growbench report: figures, tables and an HTML page from one results file.

Reads only the results JSON that `growbench suite` writes (and the render images it names); never the
algorithms' code. Run with Debian's /usr/bin/python3, which sees python3-matplotlib and python3-numpy:

    /usr/bin/python3 reports/report.py out/demo/results.json --out out/demo/report

Writes into OUT: fig-*.png and fig-*.pdf, table.tex (booktabs), table.md, renders/ (copies of the
comparison grids), and index.html, which needs nothing from the network.

The file is checked against harness/record/results.schema.json first (python3-jsonschema), the
schema whose version the C++ writes: a renamed or mistyped field is an error naming the file and the
JSON path.

Statistics:
- growth times: the medians and distribution-free 95% intervals the suite wrote into results.json
  ("summary" of each cell, and "summary.growth_s_over_seeds" for the table's rows, whose seeds are
  pooled), computed by the same C++ as `growbench summary` (harness/stats/stats.hpp); a results file
  written before the suite wrote them shows medians without intervals;
- scaling exponents: least squares of log(time) on log(nodes) over an algorithm's cells (their median
  times), with a 95% interval from Student's t on the slope's standard error.
"""

import argparse
import html
import json
import math
import os
import re
import shutil
import sys

# The t quantiles t_{0.975, df} for df = 1..30 (beyond: 1.96).
T975 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
        2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042]

# The file-size figure's bars: output_bytes keys and their labels. glb_plain is the plain layout's size,
# which the trial computes beside the GLB it writes (docs/metrics.md).
FORMATS = [("obj", "OBJ"), ("ply", "PLY"), ("glb_plain", "GLB plain"), ("glb", "GLB as written")]
QUALITY = [("coverage", "surface coverage", "fraction"),
           ("attached_fraction", "attached nodes", "fraction"),
           ("penetration_samples", "penetration (segment samples inside)", "fraction"),
           ("self_intersection_fraction", "self-intersecting segments", "fraction"),
           ("leaf_overlap", "leaf overlap", "fraction"),
           ("leaf_light_exposure", "leaf light exposure (self-shadowed)", "fraction"),
           ("leaf_light_exposure_scene", "leaf light exposure (scene shade only)", "fraction")]
# The metrics' definitions and error bounds, rendered beside the report (docs/metrics.md).
METRICS_DOC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "metrics.md")
# The results file's schema, declared beside the C++ record that writes it.
SCHEMA_NAME = "harness/record/results.schema.json"
SCHEMA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", *SCHEMA_NAME.split("/"))


class ReportError(Exception):
    pass


# ---------------------------------------------------------------- statistics (no matplotlib needed)

def median(v):
    s = sorted(v)
    n = len(s)
    if n == 0:
        return float("nan")
    return s[n // 2] if n % 2 else 0.5 * (s[n // 2 - 1] + s[n // 2])


def t975(df):
    return T975[df - 1] if 1 <= df <= len(T975) else 1.96


def fit_exponent(xs, ys):
    """Least squares of log y on log x: (slope, (low, high) or None, intercept). None unless the sizes span
    at least a factor of 2 (an exponent fitted over nearly equal sizes says nothing)."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x > 0 and y > 0]
    n = len(pts)
    if n < 2 or max(p[0] for p in pts) - min(p[0] for p in pts) < math.log(2.0):
        return None
    mx = sum(p[0] for p in pts) / n
    my = sum(p[1] for p in pts) / n
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    if sxx <= 1e-12:
        return None
    b = sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx
    a = my - b * mx
    ci = None
    if n >= 3:
        rss = sum((p[1] - (a + b * p[0])) ** 2 for p in pts)
        se = math.sqrt(rss / (n - 2) / sxx)
        ci = (b - t975(n - 2) * se, b + t975(n - 2) * se)
    return b, ci, a


# ---------------------------------------------------------------- reading results

def load_schema():
    with open(SCHEMA) as f:
        return json.load(f)


def schema_version(schema):
    """The results schema_version this report reads: the one the schema (and so the C++) declares."""
    return schema["$defs"]["results"]["properties"]["schema_version"]["const"]


def json_path(parts):
    """trials[3].samples[0].phases: a path as the C++ reader names it."""
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out or "the top level"


def validate(doc, path, schema=None):
    """ReportError naming the file and the JSON path of the first place `doc` departs from the schema."""
    schema = schema or load_schema()
    try:
        import jsonschema
    except ImportError:
        raise ReportError("python3-jsonschema is not installed (scripts/install-deps installs it)")
    version = schema_version(schema)
    if doc.get("schema_version") != version:
        raise ReportError(f"{path}: schema_version {doc.get('schema_version')!r}; this report reads {version} ({SCHEMA_NAME})")
    error = jsonschema.exceptions.best_match(jsonschema.Draft202012Validator(schema).iter_errors(doc))
    if error is not None:
        raise ReportError(f"{path}: at {json_path(error.absolute_path)}: {error.message} (against {SCHEMA_NAME})")


def load_results(path):
    try:
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
    except OSError as e:
        raise ReportError(f"{path}: cannot open: {e.strerror}")
    except json.JSONDecodeError as e:
        raise ReportError(f"{path}: not valid JSON: line {e.lineno} column {e.colno}: {e.msg}")
    except UnicodeDecodeError as e:
        raise ReportError(f"{path}: not valid JSON: byte {e.start} is not UTF-8 ({e.reason})")
    except (ValueError, RecursionError) as e:  # a number beyond a float, nesting deeper than Python recurses
        raise ReportError(f"{path}: not valid JSON: {e}")
    if not isinstance(doc, dict) or doc.get("kind") != "growbench-results" or "trials" not in doc:
        raise ReportError(f"{path}: not a growbench results file (expected kind 'growbench-results' and trials)")
    validate(doc, path)
    return doc


def pooled_summaries(doc):
    """The suite's growth-time summaries over seeds, by the set of cells each pools."""
    return {frozenset(p["cells"]): p["growth_s"] for p in doc.get("summary", {}).get("growth_s_over_seeds", [])}


def row_label(t):
    label = t.get("label") or t.get("algorithm", "?")
    sweep = t.get("sweep") or {}
    if isinstance(sweep, dict) and sweep:
        label += " " + " ".join(f"{k}={v}" for k, v in sweep.items())
    return label


class Cell:
    """One trial cell (algorithm entry x scene x seed x sweep value) with its repetitions."""

    def __init__(self, t):
        self.t = t
        self.label = t.get("label") or t.get("algorithm", "?")
        self.row = row_label(t)
        self.scene = t.get("scene", "?")
        self.seed = t.get("seed", 0)
        self.status = t.get("status", "?")
        ok = [s for s in t.get("samples", []) if s.get("status") == "ok" and "phases" in s]
        self.growth = [s["phases"]["growth"]["wall_s"] for s in ok]
        self.growth_cpu = [s["phases"]["growth"]["cpu_s"] for s in ok]
        self.total = [sum(p["wall_s"] for p in s["phases"].values()) for s in ok]
        self.rss = [s.get("child_max_rss_bytes", 0) for s in ok]
        self.growth_rss = [s["phases"]["growth"].get("peak_rss_bytes", 0) for s in ok]
        counts = t.get("counts", {})
        self.nodes = counts.get("nodes", 0)
        self.leaves = counts.get("leaves", 0)
        self.bytes = t.get("output_bytes", {})
        self.metrics = t.get("metrics", {})
        alloc = t.get("alloc", {}).get("growth", {})
        self.alloc_bytes = alloc.get("bytes", 0)
        self.alloc_count = alloc.get("count", 0)
        self.ok = self.status == "ok" and len(self.growth) > 0
        # The suite's median and 95% interval of the growth time (None in files written before it did).
        self.growth_summary = t.get("summary", {}).get("growth_s")

    def growth_median(self):
        return self.growth_summary["median"] if self.growth_summary else median(self.growth)


def ordered(values):
    out = []
    for v in values:
        if v not in out:
            out.append(v)
    return out


# ---------------------------------------------------------------- formatting

def fmt_seconds(s):
    if s != s:
        return "-"
    if s < 1e-3:
        return f"{s * 1e6:.0f} us"
    if s < 1:
        return f"{s * 1e3:.1f} ms"
    return f"{s:.2f} s"


def fmt_bytes(b):
    if b is None or b != b:
        return "-"
    for unit, f in (("GiB", 2 ** 30), ("MiB", 2 ** 20), ("KiB", 2 ** 10)):
        if b >= f:
            return f"{b / f:.1f} {unit}"
    return f"{b:.0f} B"


def fmt_frac(x):
    return "-" if x is None else f"{x:.3f}"


def time_with_ci(summary, times):
    """'median [lo, hi]' from a summary the suite wrote ('~': the full range, under 6 samples); without one, the
    median of `times` alone."""
    if summary:
        lo, hi = summary["lo"], summary["hi"]
        return f"{fmt_seconds(summary['median'])} [{'' if summary['exact'] else '~'}{fmt_seconds(lo)}, {fmt_seconds(hi)}]"
    if not times:
        return "-"
    return f"{fmt_seconds(median(times))} [no interval in this file]"


# ---------------------------------------------------------------- tables

TABLE_HEAD = ["algorithm", "scene", "seeds", "growth time median [95% CI]", "peak memory", "GLB size", "nodes",
              "coverage", "attached", "penetration", "leaf overlap", "leaf light"]


def table_rows(cells, pooled=None):
    """One row per algorithm entry x scene (seeds pooled): repetition times of every seed together, with the
    interval the suite computed over them (`pooled`: pooled_summaries of the results file)."""
    pooled = pooled or {}
    rows = []
    for scene in ordered(c.scene for c in cells):
        for label in ordered(c.row for c in cells):
            group = [c for c in cells if c.scene == scene and c.row == label]
            if not group:
                continue
            good = [c for c in group if c.ok]
            bad = [c for c in group if not c.ok]
            if not good:
                rows.append([label, scene, str(len(group)), ", ".join(sorted({c.status for c in bad})), "-", "-", "-",
                             "-", "-", "-"])
                continue
            times = [x for c in good for x in c.growth]
            rss = median([x for c in good for x in c.rss])
            glb = median([c.bytes.get("glb", 0) for c in good])
            nodes = median([c.nodes for c in good])
            m = lambda k: median([c.metrics[k] for c in good if k in c.metrics]) if any(k in c.metrics for c in good) else None
            seeds = f"{len(good)}" + (f" ({len(bad)} failed: {', '.join(sorted({c.status for c in bad}))})" if bad else "")
            summary = pooled.get(frozenset(c.t.get("id") for c in good))
            rows.append([label, scene, seeds, time_with_ci(summary, times), fmt_bytes(rss), fmt_bytes(glb), f"{nodes:.0f}",
                         fmt_frac(m("coverage")), fmt_frac(m("attached_fraction")), fmt_frac(m("penetration_samples")),
                         fmt_frac(m("leaf_overlap")), fmt_frac(m("leaf_light_exposure"))])
    return rows


def latex_escape(s):
    return (s.replace("\\", "\\textbackslash{}").replace("&", "\\&").replace("%", "\\%").replace("_", "\\_")
            .replace("#", "\\#").replace("~", "$\\sim$").replace("[", "{[}").replace("]", "{]}"))


def write_latex(path, rows, caption):
    lines = ["% growbench report table; needs \\usepackage{booktabs}",
             "\\begin{table}[t]", "\\centering", "\\small",
             "\\begin{tabular}{ll" + "r" * (len(TABLE_HEAD) - 2) + "}", "\\toprule",
             " & ".join(latex_escape(h) for h in TABLE_HEAD) + " \\\\", "\\midrule"]
    prev_scene = None
    for r in rows:
        if prev_scene is not None and r[1] != prev_scene:
            lines.append("\\midrule")
        prev_scene = r[1]
        lines.append(" & ".join(latex_escape(x) for x in r) + " \\\\")
    lines += ["\\bottomrule", "\\end{tabular}", f"\\caption{{{latex_escape(caption)}}}", "\\end{table}", ""]
    with open(path, "w") as f:
        f.write("\n".join(lines))


def write_markdown(path, rows, caption):
    lines = ["| " + " | ".join(TABLE_HEAD) + " |", "|" + "|".join(["---"] * 2 + ["---:"] * (len(TABLE_HEAD) - 2)) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(x.replace("|", "\\|") for x in r) + " |")
    lines += ["", caption, ""]
    with open(path, "w") as f:
        f.write("\n".join(lines))


# ---------------------------------------------------------------- figures

def figures(cells, out, formats):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    plt.rcParams.update({"font.size": 9, "axes.grid": True, "grid.alpha": 0.3, "figure.dpi": 110,
                         "savefig.bbox": "tight", "pdf.fonttype": 42})
    labels = ordered(c.label for c in cells)
    colours = {l: plt.cm.tab10(i % 10) for i, l in enumerate(labels)}
    markers = "osD^v<>ph*"
    written = []

    def save(fig, name, caption):
        for ext in formats:
            fig.savefig(os.path.join(out, f"{name}.{ext}"), metadata={"CreationDate": None} if ext == "pdf" else None)
        plt.close(fig)
        written.append((name, caption))

    good = [c for c in cells if c.ok and c.nodes > 0]

    # 1. Growth time vs output size, log-log, with fitted exponents.
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for i, label in enumerate(labels):
        pts = [c for c in good if c.label == label]
        if not pts:
            continue
        x = np.array([c.nodes for c in pts], dtype=float)
        med = np.array([c.growth_median() for c in pts])
        # Bars: the suite's interval of each median (none in files written before it wrote them).
        lo = med - np.array([c.growth_summary["lo"] if c.growth_summary else m for c, m in zip(pts, med)])
        hi = np.array([c.growth_summary["hi"] if c.growth_summary else m for c, m in zip(pts, med)]) - med
        fit = fit_exponent(x, med)
        name = label
        if fit:
            b, ci, a = fit
            name += f": exponent {b:.2f}" + (f" [{ci[0]:.2f}, {ci[1]:.2f}]" if ci else " (2 sizes, no interval)")
            xs = np.geomspace(x.min(), x.max(), 20)
            ax.plot(xs, np.exp(a) * xs ** b, "-", color=colours[label], alpha=0.6, lw=1)
        else:
            name += ": sizes within 2x, no fit"
        ax.errorbar(x, med, yerr=[lo, hi], fmt=markers[i % len(markers)], color=colours[label], ms=4, capsize=2,
                    label=name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("plant nodes (output size)")
    ax.set_ylabel("growth wall time (s), median and 95% interval")
    ax.set_title("Growth time against output size")
    ax.legend(fontsize=7, loc="best")
    save(fig, "fig-time-vs-size", "Growth wall time against plant size, log-log: one point per cell (median over "
         "repetitions, bars: distribution-free 95% interval of the median), lines: least-squares fits with the "
         "exponent and its 95% interval in the legend. The fit spans every cell of an algorithm entry in this "
         "suite, so where cells differ in scene as well as size it mixes both; the scaling suite "
         "(bench/suites/scaling.json) varies only the size, on one scene.")

    # 2. Memory and allocations vs size.
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for i, label in enumerate(labels):
        pts = [c for c in good if c.label == label]
        if not pts:
            continue
        x = [c.nodes for c in pts]
        axes[0].plot(x, [median(c.rss) / 2 ** 20 for c in pts], markers[i % len(markers)], color=colours[label], ms=4,
                     label=label)
        axes[1].plot(x, [max(c.alloc_bytes, 1) / 2 ** 20 for c in pts], markers[i % len(markers)], color=colours[label],
                     ms=4, label=label)
    for a, t in zip(axes, ["peak resident memory of the trial process (MiB)", "bytes allocated during growth (MiB)"]):
        a.set_xscale("log")
        a.set_yscale("log")
        a.set_xlabel("plant nodes")
        a.set_ylabel(t)
    axes[0].legend(fontsize=7)
    fig.suptitle("Memory against output size")
    save(fig, "fig-memory-vs-size", "Peak resident memory (wait4's ru_maxrss of each trial's own process, median over "
         "repetitions) and bytes allocated in the growth phase (counted by a replaced operator new), against plant size.")

    # 3. Output file size per format.
    fig, ax = plt.subplots(figsize=(7, 4))
    width = 0.8 / len(FORMATS)
    for k, (fmt, fmt_label) in enumerate(FORMATS):
        meds, los, his = [], [], []
        for label in labels:
            v = [c.bytes.get(fmt, 0) / 2 ** 20 for c in good if c.label == label and fmt in c.bytes]
            m = median(v) if v else 0
            meds.append(m)
            los.append(m - (min(v) if v else 0))
            his.append((max(v) if v else 0) - m)
        ax.bar(np.arange(len(labels)) + (k - (len(FORMATS) - 1) / 2) * width, meds, width, yerr=[los, his], capsize=2,
               label=fmt_label)
    ax.set_xticks(np.arange(len(labels)))
    ax.set_xticklabels(labels, rotation=20, ha="right")
    ax.set_yscale("log")
    ax.set_ylabel("file size (MiB), median over cells, bars: range")
    ax.set_title("Output file size per format")
    ax.legend()
    save(fig, "fig-file-size", "Output file size per format (OBJ with MTL, binary PLY, binary glTF in the plain layout "
         "and as written: compact unless the run chose another `--glb` layout), median over every scene and seed of each "
         "algorithm entry; bars span the smallest to the largest. Runs recorded before the plain size was kept have "
         "no GLB plain bar.")

    # 4. Boxplots across seeds, per scene.
    scenes = ordered(c.scene for c in cells)
    ncol = min(3, len(scenes))
    nrow = math.ceil(len(scenes) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 3.2 * nrow), squeeze=False)
    for idx, scene in enumerate(scenes):
        a = axes[idx // ncol][idx % ncol]
        data, names = [], []
        for label in labels:
            v = [c.growth_median() for c in good if c.scene == scene and c.label == label]
            if v:
                data.append(v)
                names.append(label)
        if data:
            a.boxplot(data, showfliers=False)
            for j, v in enumerate(data):
                a.plot(np.full(len(v), j + 1.0), v, ".", color="k", ms=3, alpha=0.6)
            a.set_xticks(range(1, len(names) + 1))
            a.set_xticklabels(names, rotation=30, ha="right", fontsize=7)
            a.set_yscale("log")
        a.set_title(scene)
        a.set_ylabel("growth time (s)")
    for idx in range(len(scenes), nrow * ncol):
        axes[idx // ncol][idx % ncol].axis("off")
    fig.suptitle("Growth time across seeds (each point: one seed's median over repetitions)")
    fig.tight_layout()
    save(fig, "fig-seeds-boxplot", "Growth time across seeds for each algorithm entry and scene: boxes over the seeds' "
         "medians, points are the seeds.")

    # 5. Quality metrics side by side.
    qcols = (len(QUALITY) + 1) // 2
    fig, axes = plt.subplots(2, qcols, figsize=(4.3 * qcols, 7), squeeze=False)
    width = 0.8 / max(1, len(labels))
    for idx in range(len(QUALITY), 2 * qcols):
        axes[idx // qcols][idx % qcols].axis("off")
    for idx, (key, title, _) in enumerate(QUALITY):
        a = axes[idx // qcols][idx % qcols]
        for i, label in enumerate(labels):
            vals = []
            for scene in scenes:
                v = [c.metrics[key] for c in good if c.scene == scene and c.label == label and key in c.metrics]
                vals.append(median(v) if v else 0.0)
            a.bar(np.arange(len(scenes)) + (i - (len(labels) - 1) / 2) * width, vals, width, color=colours[label],
                  label=label)
        a.set_xticks(np.arange(len(scenes)))
        a.set_xticklabels(scenes, rotation=30, ha="right", fontsize=7)
        a.set_title(title)
        a.set_ylim(0, 1.05)
    if len(QUALITY) < 2 * qcols:  # the spare panel holds the legend, clear of the bars
        spare = axes[1][qcols - 1]
        spare.legend(*axes[0][0].get_legend_handles_labels(), loc="center", fontsize=9, frameon=False)
    else:
        axes[0][0].legend(fontsize=7)
    fig.suptitle("Quality metrics (median over seeds; the same definitions for every algorithm)")
    fig.tight_layout()
    save(fig, "fig-quality", "Quality metrics computed identically for every algorithm (harness/output/metrics.hpp): "
         "coverage of the climbable surface, fraction of nodes attached, penetration into solids, self-intersection, "
         "leaf overlap and leaf light exposure with and without the plant's own shade; median over seeds.")

    # 6. Growth curves: nodes against step, one panel per scene, the lowest seed.
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 3.0 * nrow), squeeze=False)
    for idx, scene in enumerate(scenes):
        a = axes[idx // ncol][idx % ncol]
        for label in labels:
            pts = sorted((c for c in good if c.scene == scene and c.label == label), key=lambda c: c.seed)
            curve = pts[0].t.get("curve") if pts else None
            if curve and curve.get("step"):
                a.plot(curve["step"], [max(n, 1) for n in curve["nodes"]], color=colours[label], label=label, lw=1.2)
        a.set_yscale("log")
        a.set_title(scene)
        a.set_xlabel("step")
        a.set_ylabel("nodes")
    for idx in range(len(scenes), nrow * ncol):
        axes[idx // ncol][idx % ncol].axis("off")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    save(fig, "fig-growth-curves", "Growth curves: plant nodes after each step (lowest seed of each cell).")
    sweep_figures(good, labels, colours, markers, plt, np, save)
    return written


def swept_numbers(cells):
    """The sweep keys whose values are numbers and take at least two values across these cells."""
    keys = ordered(k for c in cells for k in (c.t.get("sweep") or {}))
    out = []
    for k in keys:
        vals = {c.t["sweep"].get(k) for c in cells if k in (c.t.get("sweep") or {})}
        if len(vals) > 1 and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
            out.append(k)
    return out


def sweep_figures(good, labels, colours, markers, plt, np, save):
    """One figure per swept numeric parameter: growth time against it, one line per entry and scene (the
    seed's Figure 16 for the vines' resolution, and any other sweep)."""
    for key in swept_numbers(good):
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        spans = []
        scenes = ordered(c.scene for c in good)
        for i, label in enumerate(labels):
            for scene in ordered(c.scene for c in good if c.label == label):
                j = scenes.index(scene)  # the scene picks the marker and dash, the entry the colour
                # Per value: the lowest seed's cell (several seeds would zigzag one line).
                by_value = {}
                for c in good:
                    if c.label == label and c.scene == scene and key in (c.t.get("sweep") or {}):
                        v = float(c.t["sweep"][key])
                        if v not in by_value or c.seed < by_value[v].seed:
                            by_value[v] = c
                if len(by_value) < 2:
                    continue
                x = np.array(sorted(by_value))
                pts = [by_value[v] for v in x]
                med = np.array([c.growth_median() for c in pts])
                lo = med - np.array([c.growth_summary["lo"] if c.growth_summary else m for c, m in zip(pts, med)])
                hi = np.array([c.growth_summary["hi"] if c.growth_summary else m for c, m in zip(pts, med)]) - med
                ax.errorbar(x, med, yerr=[lo, hi], fmt=markers[j % len(markers)], ls=["-", "--", ":", "-."][j % 4],
                            color=colours[label], ms=4, capsize=2, lw=1, label=f"{label} on {scene}")
                spans.append(x.max() / max(x.min(), 1e-300))
        if not spans:
            plt.close(fig)
            continue
        if max(spans) >= 4:
            ax.set_xscale("log")
            ax.set_yscale("log")
        ax.set_xlabel(key)
        ax.set_ylabel("growth wall time (s), median and 95% interval")
        ax.set_title(f"Growth time against {key}")
        ax.legend(fontsize=7, loc="best")
        save(fig, f"fig-sweep-{re.sub(r'[^A-Za-z0-9_]+', '-', key)}",
             f"Growth wall time against the swept parameter {key}: one line per algorithm entry and scene (its lowest "
             f"seed), points are the median over repetitions, bars its distribution-free 95% interval.")


# ---------------------------------------------------------------- HTML

CSS = """
body { font-family: DejaVu Sans, sans-serif; margin: 2em auto; padding: 0 2em; max-width: 1400px; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; margin-top: 2em; }
table { border-collapse: collapse; font-size: 0.85em; }
th, td { padding: 3px 8px; border-bottom: 1px solid #ddd; text-align: right; }
th:nth-child(-n+2), td:nth-child(-n+2) { text-align: left; }
th { border-bottom: 2px solid #555; }
tr.scene-start td { border-top: 2px solid #999; }
.context td, .context th { text-align: left; }
figure { margin: 1em 0; } figcaption { font-size: 0.85em; color: #444; max-width: 1000px; }
img { max-width: 100%; border: 1px solid #ddd; }
.missing { outline: 4px solid #c00; }
#image-check { font-weight: bold; }
.note { color: #555; font-size: 0.9em; }
"""

# Marks any image that did not load, and records the count on <body> (a headless browser test reads it).
CHECK_SCRIPT = """
window.addEventListener('load', function () {
  var imgs = document.querySelectorAll('img'), missing = [];
  imgs.forEach(function (im) {
    if (!im.complete || im.naturalWidth === 0) { im.classList.add('missing'); missing.push(im.getAttribute('src')); }
  });
  document.body.setAttribute('data-images', imgs.length);
  document.body.setAttribute('data-missing-images', missing.length);
  var el = document.getElementById('image-check');
  el.textContent = missing.length ? ('Missing images: ' + missing.join(', ')) : ('All ' + imgs.length + ' images loaded.');
  el.style.color = missing.length ? '#c00' : '#070';
});
"""


def write_metrics_doc(out):
    """docs/metrics.md beside the report, as metrics.html (python3-markdown) or as it is; its name, or None."""
    if not os.path.exists(METRICS_DOC):
        return None
    with open(METRICS_DOC) as f:
        text = f.read()
    try:
        import markdown
    except ImportError:
        shutil.copyfile(METRICS_DOC, os.path.join(out, "metrics.md"))
        return "metrics.md"
    body = markdown.markdown(text, extensions=["tables", "fenced_code"])
    with open(os.path.join(out, "metrics.html"), "w") as f:
        f.write("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>growbench: quality metrics</title>"
                f"<style>{CSS}</style></head><body>{body}</body></html>\n")
    return "metrics.html"


def write_html(path, doc, results_path, rows, figs, grids, failed, caption, metrics_doc=None, peers=()):
    e = html.escape
    how = (f" <a href='{e(metrics_doc)}'>How each quality metric is defined, and its error bound</a>."
           if metrics_doc else "")
    ctx = doc.get("context", {})
    suite = doc.get("suite", {})
    renders = doc.get("renders", {})
    parts = ["<!DOCTYPE html>", "<html lang='en'><head><meta charset='utf-8'>",
             f"<title>growbench report: {e(suite.get('name', ''))}</title>", f"<style>{CSS}</style>",
             f"<script>{CHECK_SCRIPT}</script></head><body>",
             f"<h1>growbench report: suite '{e(suite.get('name', '?'))}'</h1>",
             f"<p>{e(suite.get('description', ''))}</p>", "<p id='image-check'>Checking images...</p>"]
    parts.append("<h2>Context</h2><table class='context'>")
    deps = ctx.get("dependencies", {})
    for k, v in [("results file", os.path.abspath(results_path)),
                 ("commit", f"{ctx.get('growbench_commit', '?')} (uncommitted changes: {ctx.get('dirty', '?')})"),
                 ("date (UTC)", ctx.get("date", "?")),
                 ("machine", f"{ctx.get('cpu_model', '?')}, {ctx.get('hardware_threads', '?')} hardware threads"),
                 ("build", f"{ctx.get('compiler', '?')}, {ctx.get('build_type', '?')}, flags '{ctx.get('cxx_flags', '').strip()}'"),
                 ("libraries", ", ".join(f"{k} {v}" for k, v in deps.items())),
                 ("repetitions", f"{doc.get('repetitions', '?')} per cell, each trial in its own process"),
                 ("renders", f"POV-Ray {renders.get('quality', '-')} ({renders.get('povray', 'not rendered')}), "
                             f"{renders.get('ok', 0)} ok, {renders.get('failed', 0)} failed" if renders else "not rendered")]:
        parts.append(f"<tr><th>{e(k)}</th><td>{e(str(v))}</td></tr>")
    parts.append("</table>")
    if failed:
        parts.append("<p class='note'>Cells that did not finish: " +
                     ", ".join(e(f"{c.row} on {c.scene} seed {c.seed}: {c.status}") for c in failed) + "</p>")

    parts.append("<h2>Renders</h2>")
    if grids:
        # The full grid, then one row per scene (larger cells side by side), folded away.
        src, title = grids[0]
        parts.append(f"<figure><img src='{e(src)}' alt='{e(title)}'><figcaption>{e(title)}</figcaption></figure>")
        if len(grids) > 1:
            parts.append("<details><summary>Per scene</summary>")
            for src, title in grids[1:]:
                parts.append(f"<figure><img src='{e(src)}' alt='{e(title)}'><figcaption>{e(title)}</figcaption></figure>")
            parts.append("</details>")
    else:
        parts.append("<p class='note'>No renders in this results file: run <code>growbench render DIR</code> on the "
                     "results directory, then the report again.</p>")

    parts.append("<h2>Table</h2>")
    parts.append("<table><tr>" + "".join(f"<th>{e(h)}</th>" for h in TABLE_HEAD) + "</tr>")
    prev = None
    for r in rows:
        cls = " class='scene-start'" if prev is not None and r[1] != prev else ""
        prev = r[1]
        parts.append(f"<tr{cls}>" + "".join(f"<td>{e(x)}</td>" for x in r) + "</tr>")
    parts.append("</table>")
    parts.append(f"<p class='note'>{e(caption)} Also as <a href='table.tex'>LaTeX (booktabs)</a> and "
                 f"<a href='table.md'>Markdown</a>.{how}</p>")

    parts.append("<h2>Figures</h2>")
    for name, cap in figs:
        parts.append(f"<figure><img src='{e(name)}.png' alt='{e(name)}'><figcaption>{e(cap)} "
                     f"<a href='{e(name)}.pdf'>PDF</a>{how if name == 'fig-quality' else ''}</figcaption></figure>")
    parts += peers  # the "versus peers" section, when a peers.json was given or found
    parts.append("<p class='note'>Generated by reports/report.py from the results file alone. Intervals: "
                 "distribution-free 95% intervals of the median from order statistics ('~': fewer than 6 repetitions, "
                 "the full range). Exponents: least squares on log-log medians, 95% interval from Student's t.</p>")
    parts.append("</body></html>")
    with open(path, "w") as f:
        f.write("\n".join(parts) + "\n")



# ---------------------------------------------------------------- versus peers (peers.json of `make peers`)

PEERS_HEAD = ["work", "peer", "peer median", "growbench median", "ratio [interval]", "target", "CPU-time ratio",
              "peer count", "growbench count", "check"]


def load_peers(path):
    try:
        with open(path) as f:
            doc = json.load(f)
    except (OSError, ValueError) as e:
        raise ReportError(f"{path}: cannot read peers file: {e}")
    if doc.get("schema") != "growbench-peers/1" or not isinstance(doc.get("cases"), list):
        raise ReportError(f"{path}: not a peers file of scripts/peers (schema growbench-peers/1)")
    return doc


def peers_rows(doc):
    rows = []
    for c in doc["cases"]:
        threads = c.get("growbench_threads")
        rows.append([c["title"], c["peer"], fmt_seconds(c["peer_median_s"]),
                     fmt_seconds(c["growbench_median_s"]) + (f" ({threads} thr.)" if threads else ""),
                     f"{c['ratio']:.1f}x [{c['ratio_low']:.1f}, {c['ratio_high']:.1f}]",
                     f">= {c['target']:g}x" + (" met" if c["ratio"] >= c["target"] else " not met"),
                     f"{c['cpu_ratio']:.1f}x" if c.get("cpu_ratio") else "-",
                     f"{c['peer_count']:,} {c['count_unit']}", f"{c['growbench_count']:,} {c['count_unit']}",
                     ("ok: " if c["check"]["ok"] else "FAILED: ") + c["check"]["what"]])
        if "whole" in c:  # what a user waits for, beside the growth-to-growth ratio
            w = c["whole"]
            rows.append([c["title"] + ": " + w["what"], c["peer"], fmt_seconds(median(w["peer_s"])),
                         fmt_seconds(median(w["growbench_s"])) + (f" ({threads} thr.)" if threads else ""),
                         f"{w['ratio']:.1f}x [{w['ratio_low']:.1f}, {w['ratio_high']:.1f}]", "-", "-", "", "", ""])
    return rows


def peers_figure(doc, out, formats):
    """Ratio per case with its interval, on a log axis, and each case's target as a red bar."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = doc["cases"]
    fig, ax = plt.subplots(figsize=(6.4, 0.55 * len(cases) + 1.2))
    ys = list(range(len(cases)))[::-1]
    for y, c in zip(ys, cases):
        colour = "tab:green" if c["ratio"] >= c["target"] else "tab:orange"
        ax.errorbar([c["ratio"]], [y], xerr=[[c["ratio"] - c["ratio_low"]], [c["ratio_high"] - c["ratio"]]],
                    fmt="o", color=colour, capsize=3)
        ax.plot([c["target"]] * 2, [y - 0.35, y + 0.35], color="tab:red", lw=2)
        if "whole" in c:
            w = c["whole"]
            ax.errorbar([w["ratio"]], [y - 0.2], xerr=[[w["ratio"] - w["ratio_low"]], [w["ratio_high"] - w["ratio"]]],
                        fmt="o", mfc="none", color="grey", capsize=2)
    ax.plot([], [], color="tab:red", lw=2, label="target")
    if any("whole" in c for c in cases):
        ax.plot([], [], "o", mfc="none", color="grey", label="whole operator\nvs growth + meshing")
    ax.set_yticks(ys, [c["name"] for c in cases])
    ax.set_xscale("log")
    ax.axvline(1.0, color="grey", lw=0.8)
    ax.set_xlabel(f"peer time / growbench time (medians, {doc['interval']['level']:.0%} interval)")
    hi = max(max(c["ratio_high"], c["target"], c.get("whole", {}).get("ratio_high", 0)) for c in cases)
    ax.set_xlim(0.8, hi * 2)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=8)
    ax.grid(True, alpha=0.3)
    for ext in formats:
        fig.savefig(os.path.join(out, f"fig-peers.{ext}"), bbox_inches="tight",
                    metadata={"CreationDate": None} if ext == "pdf" else None)
    plt.close(fig)


def peers_html(doc, path, out, formats):
    """Writes fig-peers.* and peers-table.md into out; returns the HTML of the "versus peers" section."""
    e = html.escape
    rows = peers_rows(doc)
    peers_figure(doc, out, formats)
    with open(os.path.join(out, "peers-table.md"), "w") as f:
        f.write("| " + " | ".join(PEERS_HEAD) + " |\n|" + "---|" * len(PEERS_HEAD) + "\n")
        for r in rows:
            f.write("| " + " | ".join(x.replace("|", "\\|") for x in r) + " |\n")
    m = doc.get("machine", {})
    loads = [x for c in doc["cases"] for x in c.get("load_1min", [])]
    first = doc.get("untimed_first_runs", 0)
    first_runs = f"Each side ran {first} untimed time(s) before its timed repetitions. " if first else ""
    parts = ["<h2>Versus peers</h2>",
             f"<p>From {e(os.path.abspath(path))} (<code>make peers</code>, growbench {e(doc['growbench']['version'])}, "
             f"{e(doc.get('started', '?'))}): each peer and growbench on the same input, alternating, "
             f"{doc['repetitions']} repetitions each, each timed inside its own process. Machine: {e(m.get('cpu', '?'))}, "
             f"{m.get('cores', '?')} cores; 1-minute load during the runs {min(loads, default=0):.1f} to "
             f"{max(loads, default=0):.1f}. {first_runs}lindenmayer is timed after {doc.get('lindenmayer_warmup', 0)} untimed "
             f"derivation(s) in its own process (V8 warmed up).</p>",
             "<table><tr>" + "".join(f"<th>{e(h)}</th>" for h in PEERS_HEAD) + "</tr>"]
    parts += ["<tr>" + "".join(f"<td>{e(x)}</td>" for x in r) + "</tr>" for r in rows]
    parts.append("</table>")
    parts.append(f"<p class='note'>Ratio: the peer's median time over growbench's; interval: "
                 f"{e(doc['interval']['method'])} ({doc['interval']['level']:.0%}). CPU-time ratio: the same with "
                 f"CPU seconds (growbench's summed over its threads), which a loaded machine disturbs less. Also as "
                 f"<a href='peers-table.md'>Markdown</a>.</p>")
    parts.append("<figure><img src='fig-peers.png' alt='fig-peers'><figcaption>Peer time over growbench time per "
                 "case, with its interval; red: the case's target. <a href='fig-peers.pdf'>PDF</a></figcaption></figure>")
    return parts


def write_peers_only(path, out, formats):
    """The report of `make peers` alone: the "versus peers" section on its own page."""
    doc = load_peers(path)
    os.makedirs(out, exist_ok=True)
    parts = ["<!DOCTYPE html>", "<html lang='en'><head><meta charset='utf-8'>",
             f"<title>growbench versus peers</title><style>{CSS}</style></head><body>",
             "<h1>growbench versus peers</h1>"] + peers_html(doc, path, out, formats) + ["</body></html>"]
    with open(os.path.join(out, "index.html"), "w") as f:
        f.write("\n".join(parts) + "\n")


# ---------------------------------------------------------------- main

def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("results", nargs="?", help="results.json written by `growbench suite`")
    ap.add_argument("--out", required=True, help="report directory (created)")
    ap.add_argument("--formats", default="png,pdf", help="figure formats (comma-separated; default png,pdf)")
    ap.add_argument("--peers", help="peers.json of `make peers`: adds the \"versus peers\" section (alone, without "
                                    "results); default: a peers.json beside the results file, if there is one")
    args = ap.parse_args(argv)
    if args.results is None and args.peers is None:
        ap.error("give a results file, --peers, or both")
    try:
        if args.results is None:
            write_peers_only(args.peers, args.out, [f for f in args.formats.split(",") if f] or ["png"])
            print(f"report: wrote the versus-peers page {os.path.join(args.out, 'index.html')}", file=sys.stderr)
            return 0
        doc = load_results(args.results)
        cells = [Cell(t) for t in doc["trials"]]
        if not cells:
            raise ReportError(f"{args.results}: no trials to report")
        os.makedirs(args.out, exist_ok=True)
        formats = [f for f in args.formats.split(",") if f]
        if "png" not in formats:
            formats.insert(0, "png")  # the HTML page shows the PNGs
        print(f"report: {len(cells)} cells from {args.results}", file=sys.stderr)
        figs = figures(cells, args.out, formats)

        rows = table_rows(cells, pooled_summaries(doc))
        caption = ("Median growth wall time over all repetitions of all seeds [distribution-free 95% interval; '~': "
                   "the full range, fewer than 6 samples], peak memory of the trial process, GLB file size, nodes, and "
                   "quality metrics (median over seeds).")
        write_latex(os.path.join(args.out, "table.tex"), rows, caption)
        write_markdown(os.path.join(args.out, "table.md"), rows, caption)

        # Renders: the grids named in the results file, copied beside the page so it stands alone.
        grids = []
        renders = doc.get("renders", {})
        base = os.path.dirname(os.path.abspath(args.results))
        names = ([(renders["grid"], "Every algorithm entry (rows) on every scene (columns), the lowest seed, rendered "
                                    "the same way (POV-Ray, shared materials, the scene's camera and light).")]
                 if renders.get("grid") else []) + \
                [(f, f"{scene}: every algorithm entry") for scene, f in renders.get("grid_per_scene", {}).items()]
        for name, title in names:
            src = os.path.join(base, name)
            if os.path.exists(src):
                os.makedirs(os.path.join(args.out, "renders"), exist_ok=True)
                shutil.copyfile(src, os.path.join(args.out, "renders", os.path.basename(name)))
                grids.append(("renders/" + os.path.basename(name), title))
            else:
                print(f"report: warning: render grid {src} is missing", file=sys.stderr)
        failed = [c for c in cells if not c.ok]
        peers_path = args.peers or os.path.join(base, "peers.json")
        peers = peers_html(load_peers(peers_path), peers_path, args.out, formats) if os.path.exists(peers_path) else []
        write_html(os.path.join(args.out, "index.html"), doc, args.results, rows, figs, grids, failed, caption,
                   write_metrics_doc(args.out), peers)
        print(f"report: wrote {len(figs)} figures ({', '.join(formats)}), table.tex, table.md and index.html "
              f"in {args.out}", file=sys.stderr)
    except ReportError as e:
        print(f"report: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:  # the output directory cannot be made or written (a file in the way, a full disk)
        print(f"report: error: {e.filename or args.out}: cannot write: {e.strerror}", file=sys.stderr)
        return 2
    except ImportError as e:
        print(f"report: error: {e}; install Debian's python3-matplotlib, python3-numpy and python3-jsonschema (scripts/install-deps) "
              f"and run with /usr/bin/python3", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
