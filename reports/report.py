#!/usr/bin/python3
"""growbench report: figures, tables and an HTML page from one results file.

Reads only the results JSON that `growbench suite` writes (and the render images it names); never the
algorithms' code. Run with Debian's /usr/bin/python3, which sees python3-matplotlib and python3-numpy:

    /usr/bin/python3 reports/report.py out/demo/results.json --out out/demo/report

Writes into OUT: fig-*.png and fig-*.pdf, table.tex (booktabs), table.md, renders/ (copies of the
comparison grids), trials/ (a page per trial: its render, a 3D view of its plant on its scene with growth
playback (reports/viewer.py), its numbers and files), and index.html. Nothing needs the network: the pages
work opened from file://.

The file is checked against harness/record/results.schema.json first (python3-jsonschema), the
schema whose version the C++ writes: a renamed or mistyped field is an error naming the file and the
JSON path.

Verdicts: each cell's plant is valid, degenerate or not_applicable ("verdict" of the cell; absent in files
written before plants were judged, which counts as valid with nothing to mark). Only valid plants enter
what compares cells: the table rows' pooled numbers, the scaling fits and every figure. The others are
marked in the table's verdict column and listed with their reasons under the tables and in the page's
"Plants left out of comparisons". A metric that does not apply is null in the file: "n/a" in the
tables, absent from the figures, never part of a median.

Memory: the growth phase's own peak resident memory (phases.growth.peak_rss_bytes) and the query
structure's (phases.query_build.peak_rss_bytes); the whole process's peak stays in the record only.

Statistics:
- growth times: the medians and intervals the suite wrote into results.json ("summary" of each cell,
  and "summary.growth_s_over_seeds" for the table's rows, whose valid seeds are pooled), computed by the
  same C++ as `growbench summary` (harness/stats/stats.hpp): with "exact" (6 samples or more) the
  distribution-free 95% CI of the median, otherwise the full range of the samples; one sample has no
  interval. A results file written before the suite wrote them shows medians without intervals;
- scaling exponents: least squares of log(time) on log(nodes) over an algorithm's valid cells (their
  median times), with a 95% interval from Student's t on the slope's standard error; fitted only for an
  entry with at least 3 distinct sizes spanning a factor of 2.
"""

import argparse
import html
import json
import math
import os
import re
import shutil
import sys

import explore
import paper_tables
import viewer

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
# A trial page loads a plant.glb up to this size (MB) at once, a larger one when asked.
VIEWER_AUTOLOAD_MB = 40
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
        # The whole process's peak (kept in the record; never shown as the algorithm's memory), and the
        # growth phase's and the query structure's own peaks (reset at each phase's start where the kernel
        # allows: *_reset False when it did not, and the peak is the process's so far).
        self.rss = [s.get("child_max_rss_bytes", 0) for s in ok]
        self.growth_rss, self.growth_rss_reset = phase_peaks(ok, "growth")
        self.query_rss, self.query_rss_reset = phase_peaks(ok, "query_build")
        counts = t.get("counts", {})
        self.nodes = counts.get("nodes", 0)
        self.leaves = counts.get("leaves", 0)
        self.bytes = t.get("output_bytes", {})
        self.metrics = t.get("metrics", {})
        alloc = t.get("alloc", {}).get("growth", {})
        self.alloc_bytes = alloc.get("bytes", 0)
        self.alloc_count = alloc.get("count", 0)
        self.ok = self.status == "ok" and len(self.growth) > 0
        # The plant's verdict: None when the file was written before plants were judged (counted as valid).
        verdict = t.get("verdict")
        self.verdict = verdict.get("status") if isinstance(verdict, dict) else None
        self.reasons = list(verdict.get("reasons") or []) if isinstance(verdict, dict) else []
        # Whether the cell enters comparisons across cells (pooled medians, fits, figures).
        self.valid = self.ok and self.verdict in (None, "valid")
        # The suite's median and interval of the growth time (None in files written before it did).
        self.growth_summary = t.get("summary", {}).get("growth_s")

    def id(self):
        return self.t.get("id") or f"{self.row}/{self.scene}/s{self.seed}"

    def growth_median(self):
        return self.growth_summary["median"] if self.growth_summary else median(self.growth)

    def growth_interval(self):
        """(lo, hi) of the median growth time: the 95% CI (exact) or the range; None with one sample or no
        summary in the file."""
        s = self.growth_summary
        if not s or s.get("n", len(self.growth)) < 2:
            return None
        return s["lo"], s["hi"]

    def growth_cv(self):
        """The coefficient of variation of the growth times (sample standard deviation over the mean), or None
        under 2 repetitions."""
        g = self.growth
        if len(g) < 2:
            return None
        mean = sum(g) / len(g)
        if mean <= 0:
            return None
        return math.sqrt(sum((x - mean) ** 2 for x in g) / (len(g) - 1)) / mean


def phase_peaks(samples, phase):
    """The phase's own peak RSS over these samples, and whether every one was reset at the phase's start."""
    ps = [s["phases"][phase] for s in samples if isinstance(s["phases"].get(phase), dict)
          and s["phases"][phase].get("peak_rss_bytes") is not None]
    return [p["peak_rss_bytes"] for p in ps], all(p.get("peak_rss_reset", True) for p in ps)


VERDICT_WORDS = {"valid": "valid", "degenerate": "degenerate", "not_applicable": "not applicable"}
VERDICT_SHORT = {"degenerate": "degenerate", "not_applicable": "n/a"}


def excluded_cells(cells):
    """The cells whose plants were judged other than valid: kept, marked, left out of comparisons."""
    return [c for c in cells if c.verdict not in (None, "valid")]


def excluded_note(c):
    """'spacecol/envelope/s1: degenerate: flat; stunted'."""
    words = VERDICT_WORDS.get(c.verdict, c.verdict)
    return f"{c.id()}: {words}" + (f": {'; '.join(c.reasons)}" if c.reasons else "")


def machine_warnings(doc, cells):
    """The banners of a run whose timings the machine may have disturbed: a load average over a quarter of the
    hardware threads when it began, or more than a quarter of the repeated cells with a growth-time coefficient
    of variation over 10%."""
    ctx = doc.get("context", {})
    out = []
    load = ctx.get("load_average_start")
    threads = ctx.get("hardware_threads") or 0
    if isinstance(load, list) and load and isinstance(load[0], (int, float)) and threads > 0 \
            and load[0] > 0.25 * threads:
        out.append(f"The machine was busy when this run began (load {load[0]:.2f} over the last minute, on {threads} "
                   f"hardware thread{'s' if threads != 1 else ''}): timings may be slower and noisier than a quiet "
                   f"machine's.")
    repeated = [c for c in cells if c.ok and len(c.growth) >= 2]
    noisy = [c for c in repeated if (c.growth_cv() or 0) > 0.10]
    if repeated and 4 * len(noisy) > len(repeated):
        out.append(f"The growth times of {len(noisy)} of {len(repeated)} cells with 2 or more repetitions varied by "
                   f"more than 10% over repetitions (coefficient of variation): timings are noisy.")
    return out


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


def growth_time_text(summary, times):
    """The growth time as what it is: 'median CI [lo, hi]' (the distribution-free 95% CI of the median, 6 samples or
    more), 'median range [lo, hi]' (the smallest and largest sample, 2 to 5), 'time (1 trial)'; from the summary the
    suite wrote, or without one the median of `times` alone."""
    if summary:
        if summary.get("n", 2) <= 1:
            return f"{fmt_seconds(summary['median'])} (1 trial)"
        kind = "CI" if summary["exact"] else "range"
        return f"{fmt_seconds(summary['median'])} {kind} [{fmt_seconds(summary['lo'])}, {fmt_seconds(summary['hi'])}]"
    if not times:
        return "-"
    if len(times) == 1:
        return f"{fmt_seconds(times[0])} (1 trial)"
    return f"{fmt_seconds(median(times))} [no interval in this file]"


def metric_values(cells, key):
    """The non-null numbers of metric `key` over these cells (null: the metric does not apply to that plant)."""
    return [c.metrics[key] for c in cells
            if isinstance(c.metrics.get(key), (int, float)) and not isinstance(c.metrics.get(key), bool)]


def pooled_text(valid, failed):
    """'3 seeds x 2 reps': what the row's numbers pool, and the cells that did not finish."""
    reps = [len(c.growth) for c in valid]
    plural = lambda n, w: f"{n} {w}{'' if n == 1 else 's'}"
    if not valid:
        text = "none"
    elif len(set(reps)) == 1:
        text = f"{plural(len(valid), 'seed')} x {plural(reps[0], 'rep')}"
    else:
        text = f"{plural(sum(reps), 'trial')} over {plural(len(valid), 'seed')}"
    if failed:
        text += f" ({len(failed)} failed: {', '.join(sorted({c.status for c in failed}))})"
    return text


def verdict_text(group):
    """'valid', or how many of the row's seeds were judged otherwise: 'degenerate (2 of 3 seeds)'; '-' when no cell
    of the row was judged (a file written before plants were)."""
    if not any(c.verdict is not None for c in group):
        return "-"
    counts = {}
    for c in excluded_cells(group):
        counts[c.verdict] = counts.get(c.verdict, 0) + 1
    if not counts:
        return "valid"
    n = len(group)
    return ", ".join(f"{VERDICT_SHORT.get(v, v)} ({k} of {n} seed{'' if n == 1 else 's'})" for v, k in counts.items())


# ---------------------------------------------------------------- tables

GROWTH_HEAD = "growth time (median; 95% CI or range)"
TABLE_HEAD = ["algorithm", "scene", "trials pooled", "verdict", GROWTH_HEAD, "growth peak RSS", "query peak RSS",
              "GLB size", "nodes", "coverage", "attached", "penetration", "leaf overlap", "leaf light"]
TABLE_LEFT = 4  # the columns aligned left: algorithm, scene, trials pooled, verdict
# The quality metrics the tables show, in TABLE_HEAD's order.
TABLE_METRICS = ["coverage", "attached_fraction", "penetration_samples", "leaf_overlap", "leaf_light_exposure"]
CAPTION = ("Growth time: the median wall time over the repetitions of the row's valid seeds pooled ('trials "
           "pooled'), with the distribution-free 95% CI of the median ('CI', 6 trials or more) or the range of the "
           "trials ('range', 2 to 5); '1 trial': one trial, no interval. Growth peak RSS and query peak RSS: the "
           "growth phase's and the query structure build's own peak resident memory (median over those trials; "
           "'*': the peak could not be reset at the phase's start and is the process's up to then). GLB size, "
           "nodes and the quality metrics: medians over the valid seeds; n/a: a metric that does not apply to the "
           "plant. Verdict: valid, or how many seeds' plants were degenerate or not applicable (n/a); those are "
           "left out of every number of the row and of every figure, and listed with their reasons; '-': not "
           "judged (a file written before plants were).")


def table_groups(cells):
    """(label, scene, cells) per algorithm entry x scene, in the order the results file first names each."""
    for scene in ordered(c.scene for c in cells):
        for label in ordered(c.row for c in cells):
            group = [c for c in cells if c.scene == scene and c.row == label]
            if group:
                yield label, scene, group


def row_numbers(group, pooled=None):
    """The numbers of one table row (an entry on a scene, seeds pooled), before any formatting: what the HTML,
    Markdown and LaTeX tables print. Only valid seeds enter a number; `time` is the suite's summary over them
    (n, median, lo, hi, exact) or, without one, {"median", "n"} of their trials; a metric is None where it does not
    apply to any valid seed and absent where no cell records it."""
    pooled = pooled or {}
    valid = [c for c in group if c.valid]
    r = {"group": group, "valid": valid, "failed": [c for c in group if not c.ok]}
    if not valid:
        return r
    times = [x for c in valid for x in c.growth]
    r["time"] = pooled.get(frozenset(c.id() for c in valid)) or {"median": median(times), "n": len(times)}
    r["times"] = times
    for key in ("growth_rss", "query_rss"):
        values = [x for c in valid for x in getattr(c, key)]
        if values:
            r[key] = (median(values), all(getattr(c, key + "_reset") for c in valid))
    glb = [c.bytes["glb"] for c in valid if c.bytes.get("glb") is not None]
    if glb:
        r["glb"] = median(glb)
    r["nodes"] = median([c.nodes for c in valid])
    r["metrics"] = {}
    for key, *_ in QUALITY:
        if any(key in c.metrics for c in valid):
            v = metric_values(valid, key)
            r["metrics"][key] = median(v) if v else None
    return r


def table_rows(cells, pooled=None):
    """One row per algorithm entry x scene (seeds pooled): repetition times of every valid seed together, with the
    interval the suite computed over them (`pooled`: pooled_summaries of the results file). Seeds whose plants are
    not valid are counted in the verdict column and enter no number; a row without a valid seed shows none."""
    rows = []
    for label, scene, group in table_groups(cells):
        r = row_numbers(group, pooled)
        failed = r["failed"]
        head = [label, scene, pooled_text(r["valid"], failed), verdict_text(group)]
        if not r["valid"]:
            # Nothing to show as a result: the statuses of cells that did not finish, else (plants that were not
            # valid) no numbers at all.
            first = ", ".join(sorted({c.status for c in failed})) if len(failed) == len(group) else "-"
            rows.append(head + [first] + ["-"] * (len(TABLE_HEAD) - len(head) - 1))
            continue
        summary = r["time"] if "lo" in r["time"] else None
        memory = lambda k: "-" if k not in r else fmt_bytes(r[k][0]) + ("" if r[k][1] else " *")
        metric = lambda k: "-" if k not in r["metrics"] else ("n/a" if r["metrics"][k] is None else
                                                              fmt_frac(r["metrics"][k]))
        rows.append(head + [growth_time_text(summary, r["times"]), memory("growth_rss"), memory("query_rss"),
                            fmt_bytes(r["glb"]) if "glb" in r else "-", f"{r['nodes']:.0f}",
                            *(metric(k) for k in TABLE_METRICS)])
    return rows


def table_notes(cells):
    """The lines under the tables: each plant left out of comparisons, with its reasons."""
    ex = excluded_cells(cells)
    if not ex:
        return []
    return ["Left out of comparisons (verdict not valid):"] + [excluded_note(c) for c in ex]


def md_text(s):
    """Free text (labels, scenes, reasons) for Markdown: shown as written, never as markup or HTML, on one line."""
    s = html.escape(" ".join(str(s).split()), quote=False)
    return re.sub(r"([\\`*\[\]|])", r"\\\1", s)  # '_' within a word is not emphasis: left readable


def write_markdown(path, rows, caption, notes=()):
    lines = ["| " + " | ".join(TABLE_HEAD) + " |",
             "|" + "|".join(["---"] * TABLE_LEFT + ["---:"] * (len(TABLE_HEAD) - TABLE_LEFT)) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(md_text(x) for x in r) + " |")
    lines += ["", caption, ""]
    if notes:
        lines += [notes[0], ""] + [f"- {md_text(n)}" for n in notes[1:]] + [""]
    with open(path, "w") as f:
        f.write("\n".join(lines))


# ---------------------------------------------------------------- figures

def scaling_fit(xs, ys):
    """fig-time-vs-size's fit of one entry: (the number of distinct sizes, fit_exponent or None). None unless there
    are at least 3 distinct sizes (node counts) spanning a factor of 2: two sizes fix a line and test nothing."""
    sizes = sorted({x for x in xs if x > 0})
    if len(sizes) < 3 or sizes[-1] < 2 * sizes[0]:
        return len(sizes), None
    return len(sizes), fit_exponent(xs, ys)


def scaling_legend(label, sizes, fit):
    """'spacecol: 4 sizes, k = 1.12 [0.98, 1.25]' or 'ivy: 2 sizes, no fit'."""
    text = f"{label}: {sizes} size{'' if sizes == 1 else 's'}"
    if fit is None:
        return text + (" within 2x, no fit" if sizes >= 3 else ", no fit")
    b, ci, _ = fit
    return text + f", k = {b:.2f}" + (f" [{ci[0]:.2f}, {ci[1]:.2f}]" if ci else "")


def time_axis_label(pts):
    """The y label of a growth-time figure, saying what its points and bars are."""
    if any(c.growth_interval() for c in pts):
        return "growth wall time (s)\npoints: median over repetitions;\nbars: 95% CI (6+ repetitions) or range"
    if all(len(c.growth) <= 1 for c in pts):
        return "growth wall time (s)\none trial per point (no interval)"
    return "growth wall time (s)\npoints: median over repetitions\n(no intervals in this file)"


def time_points(ax, pts, x, fmt, colour, label, **style):
    """Draws one series of a growth-time figure: the medians as points (joined when `style` has a line style), and
    interval bars only at the points that have an interval (none for one trial)."""
    med = [c.growth_median() for c in pts]
    ax.plot(x, med, marker=fmt, color=colour, ms=4, label=label, **({"ls": "none"} | style))
    bars = [(xi, m, c.growth_interval()) for xi, m, c in zip(x, med, pts) if c.growth_interval()]
    if bars:
        ax.errorbar([p[0] for p in bars], [p[1] for p in bars],
                    yerr=[[max(p[1] - p[2][0], 0) for p in bars], [max(p[2][1] - p[1], 0) for p in bars]],
                    fmt="none", ecolor=colour, capsize=2, lw=1)


# The quality of the Pareto figures unless the report is asked for another (--pareto-metric), and the metrics for
# which less is better (every other is better higher).
PARETO_METRIC = "coverage"
LOWER_IS_BETTER = {"penetration_nodes", "penetration_samples", "self_intersections", "self_intersection_fraction",
                   "leaf_overlap", "adhesion_mean_m", "adhesion_median_m", "adhesion_p90_m"}


# Every figure is drawn at the width it is printed at, a single column or the full text width of a two-column
# paper, with no font under MIN_FONT_PT there (tests/reports/paper_figures_test.py reads the PDFs).
COLUMN_IN, PAGE_IN, MIN_FONT_PT = 3.5, 7.0, 7
STYLE = {"font.size": 8, "axes.titlesize": 8, "axes.labelsize": 8, "xtick.labelsize": 7, "ytick.labelsize": 7,
         "legend.fontsize": 7, "figure.titlesize": 8, "axes.grid": True, "grid.alpha": 0.3, "grid.linewidth": 0.5,
         "lines.markersize": 3.5, "lines.linewidth": 1.0, "axes.linewidth": 0.6, "pdf.fonttype": 42,
         "savefig.dpi": 200, "legend.frameon": False,
         # Labels, scenes and commits are data, never TeX: a label "$\frac{$" is drawn as written.
         "text.parse_math": False}
LEFT_OUT = " Plants judged degenerate or not applicable are left out (listed under the table)."


def tick_text(v, _pos=None):
    """A log axis's tick as plain text (10k, 0.01): matplotlib's 10^n sets the exponent at 70% of the tick size."""
    if v <= 0:
        return ""
    for f, suffix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if v >= f:
            return f"{v / f:g}{suffix}"
    return f"{v:g}"


def plain_log_ticks(ax):
    """Plain tick labels on the log axes of `ax`; where the axis spans under two decades the minor ticks at 2 and 5
    times a power of ten are labelled too, and under one decade those at 2 to 8, so that it has several labels."""
    from matplotlib.ticker import FuncFormatter, NullFormatter

    def minor(labelled):
        def text(v, pos=None):
            mantissa = v / 10 ** math.floor(math.log10(v) + 1e-9) if v > 0 else 0
            return tick_text(v) if any(math.isclose(mantissa, m, rel_tol=1e-6) for m in labelled) else ""
        return FuncFormatter(text)
    for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        if axis.get_scale() != "log":
            continue
        axis.set_major_formatter(FuncFormatter(tick_text))
        lo, hi = min(lo, hi), max(lo, hi)
        span = hi / lo if lo > 0 else math.inf
        axis.set_minor_formatter(minor((2, 3, 4, 6, 8, 5)) if span < 10 else minor((2, 5)) if span < 100
                                 else NullFormatter())


class Canvas:
    """What every figure shares: pyplot, the entries' colours and markers, the valid cells, and what was written."""

    def __init__(self, cells, out, formats):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np
        plt.rcParams.update(STYLE)
        self.plt, self.np, self.out, self.formats = plt, np, out, formats
        self.cells = cells
        self.labels = ordered(c.label for c in cells)
        self.scenes = ordered(c.scene for c in cells)
        self.colours = {l: plt.cm.tab10(i % 10) for i, l in enumerate(self.labels)}
        self.markers = "osD^v<>ph*"
        self.marker = {l: self.markers[i % len(self.markers)] for i, l in enumerate(self.labels)}
        # Only valid plants (or unjudged, in older files) enter the figures: they compare cells.
        self.good = [c for c in cells if c.valid and c.nodes > 0]
        self.written = []

    def figure(self, width, height):
        return self.plt.figure(figsize=(width, height), layout="constrained")

    def save(self, fig, name, caption):
        """Writes the figure at its own size (no tight crop: the PDF is exactly as wide as the page asks)."""
        width = fig.get_size_inches()[0]
        for ax in fig.axes:
            plain_log_ticks(ax)
        for ext in self.formats:
            fig.savefig(os.path.join(self.out, f"{name}.{ext}"), metadata={"CreationDate": None} if ext == "pdf" else None)
        self.plt.close(fig)
        self.written.append((name, caption + f" Drawn {width:g} in wide."))

    def legend_panel(self, ax, handles=None, labels=None, **kw):
        """An axes given over to the legend, beside the plots rather than over their data."""
        ax.axis("off")
        if handles is None:
            handles, labels = [], []
            for a in ax.figure.axes:
                for h, l in zip(*a.get_legend_handles_labels()):
                    if l not in labels:
                        handles.append(h)
                        labels.append(l)
        if handles:
            # A long legend packs its rows closer and then takes two columns, rather than run off the figure.
            packed = {"labelspacing": 0.25, "handlelength": 1.5} if len(handles) > 6 else {}
            packed |= {"ncols": 2, "columnspacing": 0.8} if len(handles) > 12 else {}
            legend = ax.legend(handles, labels, loc="upper left", borderaxespad=0, **(packed | kw))
            # Taller than its panel: the figure grows (its width stays the page's) until the legend fits.
            fig = ax.figure
            for _ in range(4):
                fig.canvas.draw()
                need, have = legend.get_window_extent().height, ax.get_window_extent().height
                if need <= have:
                    break
                width, height = fig.get_size_inches()
                fig.set_size_inches(width, height * (need / have + 0.05))

    def scene_styles(self):
        """({scene: colour}, {scene: marker}): ten colours and ten markers, each of up to ten scenes its own
        colour, and past ten the marker shifts, so that no two of up to a hundred scenes share both."""
        colour = {s: self.plt.cm.tab10(i % 10) for i, s in enumerate(self.scenes)}
        marker = {s: self.markers[(i + i // 10) % len(self.markers)] for i, s in enumerate(self.scenes)}
        return colour, marker

    def entry_handles(self, labels=None, markers=True):
        from matplotlib.lines import Line2D
        return [Line2D([], [], color=self.colours[l], marker=self.marker[l] if markers else None, ls="-", label=l)
                for l in (labels or self.labels)], list(labels or self.labels)

    def panels(self, n, ncol, panel_h, extra=0):
        """A full-width figure of n panels in rows of ncol (and `extra` more slots, e.g. for a legend)."""
        slots = n + extra
        ncol = max(1, min(ncol, slots))
        nrow = math.ceil(slots / ncol)
        fig = self.figure(PAGE_IN, panel_h * nrow + 0.3)
        axes = [fig.add_subplot(nrow, ncol, i + 1) for i in range(slots)]
        return fig, axes


def figure_time_vs_size(F):
    np = F.np
    fig = F.figure(PAGE_IN, 3.2)
    gs = fig.add_gridspec(1, 2, width_ratios=[3, 2])
    ax, lax = fig.add_subplot(gs[0]), fig.add_subplot(gs[1])
    for label in F.labels:
        pts = [c for c in F.good if c.label == label]
        if not pts:
            continue
        x = np.array([c.nodes for c in pts], dtype=float)
        med = np.array([c.growth_median() for c in pts])
        sizes, fit = scaling_fit(x, med)
        if fit:
            b, ci, a = fit
            xs = np.geomspace(x.min(), x.max(), 20)
            ax.plot(xs, np.exp(a) * xs ** b, "-", color=F.colours[label], alpha=0.6, lw=1)
        time_points(ax, pts, x, F.marker[label], F.colours[label], scaling_legend(label, sizes, fit))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("plant nodes (output size)")
    ax.set_ylabel(time_axis_label(F.good))
    ax.set_title("Growth time against output size")
    handles, names = ax.get_legend_handles_labels()
    F.legend_panel(lax, handles, names)
    F.save(fig, "fig-time-vs-size", "Growth wall time against plant size, log-log: one point per valid cell (the "
           "median over its repetitions); bars where a cell has an interval: the distribution-free 95% CI of the "
           "median (6 repetitions or more) or the range of its repetitions (2 to 5); a single trial has none. Lines: "
           "least-squares fits, drawn only for an entry with at least 3 distinct sizes (node counts) spanning a factor "
           "of 2; the legend gives each entry's number of distinct sizes and its exponent k with the 95% interval "
           "(Student's t). The fit spans every valid cell of an algorithm entry in this suite, so where cells differ "
           "in scene as well as size it mixes both; the scaling suite (bench/suites/scaling.json) varies only the "
           "size, on one scene." + LEFT_OUT)


def figure_memory(F):
    fig = F.figure(PAGE_IN, 2.8)
    gs = fig.add_gridspec(1, 3, width_ratios=[3, 3, 1.5])
    axes = [fig.add_subplot(gs[0]), fig.add_subplot(gs[1])]
    for label in F.labels:
        pts = [c for c in F.good if c.label == label]
        mem = [c for c in pts if c.growth_rss]
        if mem:
            axes[0].plot([c.nodes for c in mem], [median(c.growth_rss) / 2 ** 20 for c in mem], F.marker[label],
                         color=F.colours[label], label=label)
        if pts:
            axes[1].plot([c.nodes for c in pts], [max(c.alloc_bytes, 1) / 2 ** 20 for c in pts], F.marker[label],
                         color=F.colours[label], label=label)
    one = all(len(c.growth_rss) <= 1 for c in F.good)
    rss = "growth peak RSS (MiB)\n" + ("one trial per point" if one else "median over repetitions")
    for a, t in zip(axes, [rss, "bytes allocated during growth (MiB)"]):
        a.set_xscale("log")
        a.set_yscale("log")
        a.set_xlabel("plant nodes")
        a.set_ylabel(t)
    axes[0].set_title("Growth phase's peak memory")
    axes[1].set_title("Allocated during growth")
    F.legend_panel(fig.add_subplot(gs[2]), *F.entry_handles(ordered(c.label for c in F.good)))
    F.save(fig, "fig-memory-vs-size", "Growth peak RSS (the growth phase's own peak resident memory, reset at its "
           "start; median over repetitions) and bytes allocated in the growth phase (counted by a replaced operator "
           "new), against plant size, log-log." + LEFT_OUT)


def figure_file_size(F):
    """Points on a log axis (a bar's length means nothing there), with the range over cells."""
    np = F.np
    fig = F.figure(PAGE_IN, 2.8)
    gs = fig.add_gridspec(1, 2, width_ratios=[5, 1.2])
    ax = fig.add_subplot(gs[0])
    labels = ordered(c.label for c in F.good)
    width = 0.7 / len(FORMATS)
    for k, (fmt, fmt_label) in enumerate(FORMATS):
        xs, meds, los, his = [], [], [], []
        for j, label in enumerate(labels):
            v = [c.bytes[fmt] / 2 ** 20 for c in F.good if c.label == label and c.bytes.get(fmt) is not None]
            if v:  # no point: this entry has no such file
                m = median(v)
                xs.append(j + (k - (len(FORMATS) - 1) / 2) * width)
                meds.append(m)
                los.append(m - min(v))
                his.append(max(v) - m)
        if xs:
            ax.errorbar(xs, meds, yerr=[los, his], fmt=F.markers[k], capsize=1.5, lw=0.8, label=fmt_label)
    ax.set_xticks(np.arange(len(labels)))
    ax.set_xticklabels(labels, rotation=25, ha="right")
    ax.set_yscale("log")
    ax.set_ylabel("file size (MiB)\nmedian over cells, bars: range")
    ax.set_title("Output file size per format")
    F.legend_panel(fig.add_subplot(gs[1]), *ax.get_legend_handles_labels())
    F.save(fig, "fig-file-size", "Output file size per format (OBJ with MTL, binary PLY, binary glTF in the plain "
           "layout and as written: compact unless the run chose another `--glb` layout), log scale: points are the "
           "median over every scene and seed of each algorithm entry with a valid plant, bars span the smallest to "
           "the largest. Runs recorded before the plain size was kept have no GLB plain point." + LEFT_OUT)


def entry_axis(F, ax, labels, first):
    """Algorithm entries down the y axis, the first at the top; named only on the first panel of a row."""
    ax.set_yticks(range(len(labels)))
    ax.set_yticklabels(labels if first else [])
    ax.set_ylim(len(labels) - 0.5, -0.5)
    ax.grid(axis="y", visible=False)


def figure_seeds(F):
    """Per scene: each entry's seeds as points (drawn over the box), a box only over 5 seeds or more."""
    np = F.np
    rows = ordered(c.row for c in F.good)
    labels = rows
    if not labels:
        return
    ncol = 4
    fig, axes = F.panels(len(F.scenes), ncol, 0.45 + 0.14 * len(labels))
    for idx, scene in enumerate(F.scenes):
        a = axes[idx]
        for j, label in enumerate(labels):
            cs = [c for c in F.good if c.scene == scene and c.row == label]
            v = sorted(c.growth_median() for c in cs)
            if not v:
                continue
            entry = cs[0].label
            if len(v) >= 5:
                a.boxplot([v], positions=[j], vert=False, widths=0.6, showfliers=False, manage_ticks=False,
                          medianprops={"color": "k"})
            else:
                a.plot([median(v)], [j], "|", color="k", ms=8)
            jitter = np.linspace(-0.2, 0.2, len(v)) if len(v) > 1 else [0.0]
            a.plot(v, [j + d for d in jitter], F.marker[entry], color=F.colours[entry], zorder=3, ms=3)
        a.set_xscale("log")
        a.set_title(scene)
        entry_axis(F, a, labels, idx % ncol == 0)
        if idx >= len(F.scenes) - ncol:
            a.set_xlabel("growth time (s)")
    for a in axes[len(F.scenes):]:
        a.axis("off")
    F.save(fig, "fig-seeds", "Growth time across seeds, per scene: each point is one valid seed's median over its "
           "repetitions; the black tick is their median, and a box (quartiles, whiskers to the extremes) is drawn only "
           "over 5 seeds or more." + LEFT_OUT)


def figure_quality(F):
    """Per metric: each entry's median over seeds per scene, a line over the seeds' range; n/a draws nothing."""
    import textwrap
    keys = [(k, "\n".join(textwrap.wrap(t, 26))) for k, t, _ in QUALITY if metric_values(F.good, k)]
    labels = ordered(c.row for c in F.good)  # a sweep's values are rows of their own
    if not keys or not labels:
        return
    ncol = 4
    fig, axes = F.panels(len(keys), ncol, 0.5 + 0.16 * len(labels), extra=1 + (-(len(keys) + 1)) % ncol)
    scene_colour, scene_marker = F.scene_styles()
    step = 0.7 / max(1, len(F.scenes))
    for idx, (key, title) in enumerate(keys):
        a = axes[idx]
        for j, label in enumerate(labels):
            for i, scene in enumerate(F.scenes):
                v = metric_values([c for c in F.good if c.scene == scene and c.row == label], key)
                if not v:
                    continue
                y = j + (i - (len(F.scenes) - 1) / 2) * step
                if len(v) > 1:
                    a.plot([min(v), max(v)], [y, y], "-", color=scene_colour[scene], lw=0.8)
                a.plot([median(v)], [y], scene_marker[scene], color=scene_colour[scene], ms=3)
        a.set_xlim(-0.03, 1.03)
        a.set_title(title)
        a.set_xlabel("fraction")
        entry_axis(F, a, labels, idx % ncol == 0)
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=scene_colour[s], marker=scene_marker[s], ls="-", label=s) for s in F.scenes]
    for a in axes[len(keys):]:
        a.axis("off")
    F.legend_panel(axes[-1], handles, list(F.scenes), title="scene")
    F.save(fig, "fig-quality", "Quality metrics computed identically for every algorithm (harness/output/metrics.hpp): "
           "coverage of the climbable surface, fraction of nodes attached, penetration into solids, self-intersection, "
           "leaf overlap and leaf light exposure with and without the plant's own shade. Per algorithm entry (rows) "
           "and scene (colour and marker): the median over the valid seeds, and a line over their range where there are two or "
           "more. A metric that does not apply (no climbable surface, no leaves, no segments) draws nothing: it is "
           "not 0." + LEFT_OUT)


def curve_fractions(c):
    """A cell's growth curve on common axes: (elapsed share of its growth time, share of its final nodes)."""
    curve = c.t.get("curve") or {}
    nodes = curve.get("nodes") or []
    when = curve.get("wall_s") or curve.get("step") or []
    if len(nodes) < 2 or len(when) != len(nodes) or nodes[-1] <= 0 or when[-1] <= 0:
        return None
    return [w / when[-1] for w in when], [n / nodes[-1] for n in nodes]


def figure_growth_curves(F):
    labels = ordered(c.label for c in F.good)
    if not labels:
        return
    ncol = 4
    fig, axes = F.panels(len(F.scenes), ncol, 1.55, extra=1)
    for idx, scene in enumerate(F.scenes):
        a = axes[idx]
        top = 1.0
        for label in labels:
            pts = sorted((c for c in F.good if c.scene == scene and c.label == label), key=lambda c: c.seed)
            xy = curve_fractions(pts[0]) if pts else None
            if xy:
                a.plot(*xy, color=F.colours[label], label=label)
                top = max(top, max(xy[1]))
        a.set_xlim(0, 1)
        a.set_ylim(0, 1.02 * top)  # a plant that shrank before it ended rises above 1: drawn, not cut off
        a.set_title(scene)
        if idx % ncol == 0:
            a.set_ylabel("share of final nodes")
        a.set_xlabel("share of growth time")
    F.legend_panel(axes[len(F.scenes)], *F.entry_handles(labels, markers=False))
    for a in axes[len(F.scenes) + 1:]:
        a.axis("off")
    F.save(fig, "fig-growth-curves", "Growth curves on common axes: the plant's nodes as a share of its final count "
           "against the elapsed share of its growth phase's wall time (lowest valid seed of each cell). An algorithm "
           "that builds its plant in one pass at the end (an L-system's interpretation) rises at the right; one that "
           "grows a little every step rises steadily; a curve that falls, or rises above 1, is a plant that had more "
           "nodes earlier than at its end (a rule or step that removes some)." + LEFT_OUT)


def figures(cells, out, formats, pareto_metric=PARETO_METRIC):
    """Every figure of the report, each at a paper width; returns [(name, caption)]."""
    F = Canvas(cells, out, formats)
    F.pareto_metric = pareto_metric
    for draw in (figure_time_vs_size, figure_memory, figure_file_size, figure_seeds, figure_quality,
                 figure_growth_curves, sweep_figures, pareto_figures):
        draw(F)
    return F.written


def swept_numbers(cells):
    """The sweep keys whose values are numbers and take at least two values across these cells."""
    keys = ordered(k for c in cells for k in (c.t.get("sweep") or {}))
    out = []
    for k in keys:
        vals = {c.t["sweep"].get(k) for c in cells if k in (c.t.get("sweep") or {})}
        if len(vals) > 1 and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
            out.append(k)
    return out


def sweep_figures(F):
    """One figure per swept numeric parameter: growth time against it, one line per entry and scene (the
    seed's Figure 16 for the vines' resolution, and any other sweep)."""
    np = F.np
    good = F.good
    for key in swept_numbers(good):
        fig = F.figure(PAGE_IN, 3.0)
        gs = fig.add_gridspec(1, 2, width_ratios=[3, 2])
        ax = fig.add_subplot(gs[0])
        spans, drawn = [], []
        scenes = ordered(c.scene for c in good)
        for label in F.labels:
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
                time_points(ax, pts, x, F.markers[j % len(F.markers)], F.colours[label], f"{label} on {scene}",
                            ls=["-", "--", ":", "-."][j % 4], lw=1)
                drawn += pts
                spans.append(x.max() / max(x.min(), 1e-300))
        if not spans:
            F.plt.close(fig)
            continue
        if max(spans) >= 4:
            ax.set_xscale("log")
            ax.set_yscale("log")
        ax.set_xlabel(key)
        ax.set_ylabel(time_axis_label(drawn))
        ax.set_title(f"Growth time against {key}")
        F.legend_panel(fig.add_subplot(gs[1]), *ax.get_legend_handles_labels())
        F.save(fig, f"fig-sweep-{re.sub(r'[^A-Za-z0-9_]+', '-', key)}",
               f"Growth wall time against the swept parameter {key}: one line per algorithm entry and scene (its lowest "
               f"valid seed); points are the median over repetitions, bars (where a cell has 2 or more) the "
               f"distribution-free 95% CI of the median (6 repetitions or more) or the range of the repetitions." +
               LEFT_OUT)


def numeric_metrics(cells):
    return sorted({k for c in cells for k, v in c.metrics.items()
                   if isinstance(v, (int, float)) and not isinstance(v, bool)})


def pareto_points(cells, scene, metric):
    """Per algorithm entry on `scene`: one point per sweep value (table row), in the suite's order: (growth time, the
    metric, row), each the median over the row's valid seeds (a seed's time: its median over repetitions). A row
    whose metric applies to no valid seed has no point."""
    out = {}
    for label in ordered(c.label for c in cells):
        pts = []
        for row in ordered(c.row for c in cells if c.label == label and c.scene == scene):
            group = [c for c in cells if c.row == row and c.scene == scene]
            q = metric_values(group, metric)
            if q:
                pts.append((median([c.growth_median() for c in group]), median(q), row))
        if pts:
            out[label] = pts
    return out


def pareto_front(points, lower_is_better=False):
    """The points no other beats: none is at least as fast and strictly better, or strictly faster and as good.
    Sorted by time."""
    sign = -1.0 if lower_is_better else 1.0
    front, best = [], -math.inf
    for p in sorted(points, key=lambda p: (p[0], -sign * p[1])):
        if sign * p[1] > best:
            front.append(p)
            best = sign * p[1]
    return front


def pareto_figures(F):
    """Per scene with a sweep: the chosen quality against growth time, one line per entry through its sweep, its
    Pareto front marked, and the front over all entries."""
    metric = F.pareto_metric
    lower = metric in LOWER_IS_BETTER
    title = next((t for k, t, _ in QUALITY if k == metric), metric)
    for scene in F.scenes:
        by_label = pareto_points([c for c in F.good if c.scene == scene], scene, metric)
        if not any(len(p) >= 2 for p in by_label.values()):
            continue  # no sweep here: a point per entry is the tables' business
        fig = F.figure(COLUMN_IN, 2.5 + 0.14 * math.ceil(len(by_label) / 2) + 0.25)
        gs = fig.add_gridspec(2, 1, height_ratios=[2.5, 0.14 * math.ceil(len(by_label) / 2) + 0.25])
        ax = fig.add_subplot(gs[0])
        everything = []
        for label, pts in by_label.items():
            colour = F.colours[label]
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "-", color=colour, lw=0.6, alpha=0.5)
            front = pareto_front(pts, lower)
            ax.plot([p[0] for p in pts if p not in front], [p[1] for p in pts if p not in front], F.marker[label],
                    mfc="none", color=colour, ms=3.5)
            ax.plot([p[0] for p in front], [p[1] for p in front], F.marker[label], color=colour, ms=4,
                    drawstyle="steps-post", ls="-", lw=1.4, label=label)
            everything += pts
        overall = pareto_front(everything, lower)
        ax.plot([p[0] for p in overall], [p[1] for p in overall], "--", color="0.35", lw=0.8,
                drawstyle="steps-post", label="front over all entries", zorder=0)
        ax.set_xscale("log")
        ax.set_xlabel("growth time (s), median over seeds")
        ax.set_ylabel(f"{title}\n({'lower' if lower else 'higher'} is better)")
        ax.set_title(f"Quality against cost: {scene}")
        F.legend_panel(fig.add_subplot(gs[1]), *ax.get_legend_handles_labels(), ncol=2)
        F.save(fig, f"fig-pareto-{re.sub(r'[^A-Za-z0-9_]+', '-', scene)}",
               f"Quality against cost on {scene}: {title} ({'lower' if lower else 'higher'} is better; the median over "
               f"a sweep value's valid seeds) against growth wall time (the median over those seeds of each seed's "
               f"median over repetitions), log scale. One thin line per algorithm entry through its sweep values in "
               f"the suite's order; filled markers joined by a step: that entry's Pareto front (no other of its points "
               f"is both faster and better); hollow markers: dominated. Dashed grey: the front over all entries. An "
               f"entry without a sweep is a single point." + LEFT_OUT)


# ---------------------------------------------------------------- HTML

def slug(text):
    """A file name for a trial id: 'ivy-luft/wall/s1' -> 'ivy-luft_wall_s1'."""
    return re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("_") or "trial"


def own_path(base, name):
    """BASE/NAME if NAME is a relative path that stays inside BASE once symlinks are resolved, else None:
    a results file names its own renders, and the report copies or links nothing else."""
    if not isinstance(name, str) or not name or os.path.isabs(name) or "\0" in name:
        return None
    root = os.path.realpath(base)
    real = os.path.realpath(os.path.join(root, name))
    return os.path.join(base, name) if real != root and os.path.commonpath([root, real]) == root else None


def copy_grids(doc, base, out, pages):
    """The grids the results file names, copied beside the page, with their cells' links to trial pages (from
    IMAGE.map.json beside each image, as percentages of the image so that they scale with it)."""
    renders = doc.get("renders", {})
    what = "rendered the same way (POV-Ray, shared materials; the camera frames each plant where the scene's does not)"
    names = [(p, f"Every algorithm entry (rows) on the scenes of this page (columns), the lowest seed, {what}.", False)
             for p in renders.get("grid_pages") or []]
    if not names and renders.get("grid"):
        names = [(renders["grid"], f"Every algorithm entry (rows) on every scene (columns), the lowest seed, {what}.",
                  False)]
    names += [(f, f"{scene}: every algorithm entry", True) for scene, f in renders.get("grid_per_scene", {}).items()]
    grids = []
    for name, title, per_scene in names:
        src = own_path(base, name)
        if src is None or not src.endswith(".png"):
            print(f"report: warning: render grid {name!r} is not a PNG inside {base}; left out", file=sys.stderr)
            continue
        if not os.path.isfile(src):
            print(f"report: warning: render grid {src} is missing", file=sys.stderr)
            continue
        os.makedirs(os.path.join(out, "renders"), exist_ok=True)
        shutil.copyfile(src, os.path.join(out, "renders", os.path.basename(name)))
        links = []
        try:
            with open(src + ".map.json") as f:
                m = json.load(f)
            for c in m.get("cells", []):
                if c.get("trial") in pages:
                    links.append((100.0 * c["x"] / m["width"], 100.0 * c["y"] / m["height"], 100.0 * c["w"] / m["width"],
                                  100.0 * c["h"] / m["height"], pages[c["trial"]], c["trial"]))
        except (OSError, ValueError, KeyError, TypeError, ZeroDivisionError):
            pass  # a grid without its map (rendered before maps were written) simply has no links
        grids.append({"src": "renders/" + os.path.basename(name), "title": title, "links": links,
                      "per_scene": per_scene})
    return grids


def grid_html(g):
    e = html.escape
    cells = "".join(f"<a class='cell' href='{e(href)}' title='{e(tid)}' style='left:{x:.3f}%;top:{y:.3f}%;"
                    f"width:{w:.3f}%;height:{h:.3f}%'></a>" for x, y, w, h, href, tid in g["links"])
    return (f"<figure><div class='grid-image'><img src='{e(g['src'])}' alt='{e(g['title'])}'>{cells}</div>"
            f"<figcaption>{e(g['title'])}</figcaption></figure>")


def trial_dir_of(c, base):
    """The trial's directory in the results directory: where its render (or record) is."""
    render = c.t.get("render") or {}
    png = own_path(base, render.get("png"))
    if png:
        return os.path.dirname(png)
    # A trial id from the file names a folder under trials/, and only there (own_path: no "..", no link out).
    d = own_path(base, os.path.join("trials", *c.id().split("/")))
    return d if d and os.path.isdir(d) else None


def write_trial_pages(cells, base, out, views=None):
    """One page per trial under OUT/trials/: its render, its 3D view (VIEWS: the viewer's HTML per trial id, from
    viewer.write_assets), verdict, numbers and files (links into the results directory). Returns {trial id: the
    page's path relative to OUT}."""
    e = html.escape
    pages = {}
    os.makedirs(os.path.join(out, "trials"), exist_ok=True)
    for c in cells:
        name = f"trials/{slug(c.id())}.html"
        here = os.path.join(out, "trials")
        rel = lambda p: os.path.relpath(p, here)
        d = trial_dir_of(c, base)
        render = c.t.get("render") or {}
        parts = ["<!DOCTYPE html>", "<html lang='en'><head><meta charset='utf-8'>",
                 f"<title>growbench trial {e(c.id())}</title><style>{CSS}</style></head><body>",
                 "<p><a href='../index.html'>Back to the report</a></p>", f"<h1>{e(c.id())}</h1>"]
        verdict = VERDICT_WORDS.get(c.verdict, c.verdict) if c.verdict else "not judged"
        parts.append(f"<p>Status: {e(c.status)}. Verdict: {e(verdict)}" +
                     (f" ({e('; '.join(c.reasons))})" if c.reasons else "") + ".</p>")
        png = own_path(base, render.get("png"))
        if png and render.get("status") == "ok":
            shares = ", ".join(f"{label} {render[k]:.3f}" for k, label in
                               (("visible_share", "plant points visible"), ("plant_pixel_share", "plant pixels"))
                               if isinstance(render.get(k), (int, float)))
            parts.append(f"<figure><img src='{e(rel(png))}' alt='render of {e(c.id())}'><figcaption>POV-Ray "
                         f"{e(str(render.get('quality', '')))}, camera {e(str(render.get('camera', '?')))}"
                         f"{'; ' + e(shares) if shares else ''}.</figcaption></figure>")
        if views and c.id() in views:
            parts.append(views[c.id()])
        rows = [("growth time", growth_time_text(c.growth_summary, c.growth)), ("nodes", f"{c.nodes}")]
        rows += [(k, "n/a" if v is None else f"{v:.4g}" if isinstance(v, float) else str(v))
                 for k, v in sorted(c.metrics.items()) if not isinstance(v, (list, dict))]
        parts.append("<table class='context'>" + "".join(f"<tr><th>{e(k)}</th><td>{e(v)}</td></tr>" for k, v in rows) +
                     "</table>")
        curve = explore.growth_curve_svg(c.t.get("curve"))
        if curve:
            parts.append(f"<h2>Growth</h2><figure>{curve}<figcaption>Nodes over the growth steps (the record's growth "
                         "curve): what the 3D view's playback shows, step by step."
                         "</figcaption></figure>")
        if d and os.path.isdir(d):
            files = sorted(f for f in os.listdir(d) if os.path.isfile(os.path.join(d, f)))
            parts.append("<h2>Files</h2><ul>" + "".join(
                f"<li><a href='{e(rel(os.path.join(d, f)))}'>{e(f)}</a> ({fmt_bytes(os.path.getsize(os.path.join(d, f)))})"
                "</li>" for f in files) + "</ul>")
        parts.append("</body></html>")
        with open(os.path.join(out, name), "w") as f:
            f.write("\n".join(parts) + "\n")
        pages[c.id()] = name
    return pages


CSS = """
body { font-family: DejaVu Sans, sans-serif; margin: 2em auto; padding: 0 2em; max-width: 1400px; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; margin-top: 2em; }
table { border-collapse: collapse; font-size: 0.85em; }
th, td { padding: 3px 8px; border-bottom: 1px solid #ddd; text-align: right; }
th:nth-child(-n+4), td:nth-child(-n+4) { text-align: left; }
th { border-bottom: 2px solid #555; }
tr.scene-start td { border-top: 2px solid #999; }
.context td, .context th { text-align: left; }
figure { margin: 1em 0; } figcaption { font-size: 0.85em; color: #444; max-width: 1000px; }
img { max-width: 100%; border: 1px solid #ddd; }
.missing { outline: 4px solid #c00; }
#image-check { font-weight: bold; }
.note { color: #555; font-size: 0.9em; }
.banner { background: #fff3b0; border: 1px solid #d9b300; padding: 0.6em 1em; margin: 1em 0; }
.banner p { margin: 0.3em 0; }
.left-out li { font-size: 0.9em; }
.wide { overflow-x: auto; } table.results { font-size: 0.8em; } table.results td { white-space: nowrap; }
.grid-image { position: relative; display: inline-block; max-width: 100%; } .grid-image img { display: block; }
.grid-image a.cell { position: absolute; } .grid-image a.cell:hover { outline: 3px solid #2a6fdb; }
#gb-trials tr.left-out-row td { color: #777; } #gb-plot a.gb-point circle:hover { stroke: #000; stroke-width: 2; }
#gb-trials th { white-space: nowrap; user-select: none; }
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


def machine_state_rows(ctx):
    """The context rows of the machine's state, where the run recorded it: the load averages (1, 5, 15 minutes)
    when it began and ended, the CPU clock and its frequency governor."""
    rows = []
    loads = [f"{when} {', '.join(f'{x:.2f}' for x in ctx[k])}"
             for when, k in (("at the start", "load_average_start"), ("at the end", "load_average_end"))
             if isinstance(ctx.get(k), list)]
    if loads:
        rows.append(("load average (1, 5, 15 min)", "; ".join(loads)))
    clock = ([f"{ctx['cpu_mhz']:.0f} MHz"] if isinstance(ctx.get("cpu_mhz"), (int, float)) else []) + \
            ([f"governor {ctx['cpu_governor']}"] if ctx.get("cpu_governor") else [])
    if clock:
        rows.append(("CPU clock", ", ".join(clock)))
    return rows


def plugin_rows(ctx):
    """One context row per plugin the run loaded: which file, which build of it (its content hash), its own
    version and the ABI it speaks, so that a figure says exactly which program grew it."""
    return [(f"plugin {p.get('name', '?')}",
             f"{p.get('path', '?')} (version {p.get('version') or '-'}, ABI {p.get('abi_version', '?')}, "
             f"xxh3 {p.get('hash', '?')})")
            for p in ctx.get("plugins", []) if isinstance(p, dict)]


def write_html(path, doc, results_path, rows, figs, grids, failed, caption, metrics_doc=None, peers=(), cells=(),
               explore_section=""):
    e = html.escape
    how = (f" <a href='{e(metrics_doc)}'>How each quality metric is defined, and its error bound</a>."
           if metrics_doc else "")
    ctx = doc.get("context", {})
    suite = doc.get("suite", {})
    renders = doc.get("renders", {})
    parts = ["<!DOCTYPE html>", "<html lang='en'><head><meta charset='utf-8'>",
             f"<title>growbench report: {e(suite.get('name', ''))}</title>", f"<style>{CSS}</style>",
             f"<script>{CHECK_SCRIPT}</script></head><body>",
             f"<h1>growbench report: suite '{e(suite.get('name', '?'))}'</h1>"]
    warnings = machine_warnings(doc, cells)
    if warnings:  # the machine's state may have disturbed the timings: said before anything else
        parts.append("<div class='banner' id='machine-banner'>" + "".join(f"<p>{e(w)}</p>" for w in warnings) +
                     "</div>")
    parts += [f"<p>{e(suite.get('description', ''))}</p>", "<p id='image-check'>Checking images...</p>"]
    parts.append("<h2>Context</h2><table class='context'>")
    deps = ctx.get("dependencies", {})
    for k, v in [("results file", os.path.abspath(results_path)),
                 ("commit", f"{ctx.get('growbench_commit', '?')} (uncommitted changes: {ctx.get('dirty', '?')})"),
                 ("date (UTC)", ctx.get("date", "?")),
                 ("machine", f"{ctx.get('cpu_model', '?')}, {ctx.get('hardware_threads', '?')} hardware threads"),
                 *machine_state_rows(ctx),
                 ("build", f"{ctx.get('compiler', '?')}, {ctx.get('build_type', '?')}, flags '{ctx.get('cxx_flags', '').strip()}'"),
                 ("libraries", ", ".join(f"{k} {v}" for k, v in deps.items())),
                 *plugin_rows(ctx),
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
        # The grid's pages, then each scene's entries side by side, folded away; every cell links to its trial.
        main = [g for g in grids if not g["per_scene"]]
        per_scene = [g for g in grids if g["per_scene"]]
        parts += [grid_html(g) for g in main]
        if per_scene:
            parts.append("<details><summary>Per scene</summary>")
            parts += [grid_html(g) for g in per_scene]
            parts.append("</details>")
        parts.append("<p class='note'>Click a cell for its trial's page: the render, its numbers, its record and "
                     "files.</p>")
    else:
        parts.append("<p class='note'>No renders in this results file: run <code>growbench render DIR</code> on the "
                     "results directory, then the report again.</p>")

    parts.append("<h2>Table</h2>")
    parts.append("<div class='wide'><table class='results'><tr>" + "".join(f"<th>{e(h)}</th>" for h in TABLE_HEAD) +
                 "</tr>")
    prev = None
    for r in rows:
        cls = " class='scene-start'" if prev is not None and r[1] != prev else ""
        prev = r[1]
        parts.append(f"<tr{cls}>" + "".join(f"<td>{e(x)}</td>" for x in r) + "</tr>")
    parts.append("</table></div>")
    parts.append(f"<p class='note'>{e(caption)} Also as <a href='table.tex'>LaTeX (booktabs)</a> and "
                 f"<a href='table.md'>Markdown</a>.{how}</p>")
    parts.append(explore_section)

    # Every plant judged other than valid, with its reasons: kept and shown, never silently dropped.
    parts.append("<h2 id='left-out'>Plants left out of comparisons</h2>")
    ex = excluded_cells(cells)
    if ex:
        parts.append("<p>These plants were judged degenerate or not applicable (docs/metrics.md, \"Validity\"): the "
                     "table marks them in its verdict column, and they enter no pooled number, fit or figure.</p>")
        parts.append("<ul class='left-out'>" + "".join(f"<li>{e(excluded_note(c))}</li>" for c in ex) + "</ul>")
    elif any(c.verdict is not None for c in cells):
        parts.append("<p>None: every plant that grew was judged valid.</p>")
    else:
        parts.append("<p>None marked: this results file has no verdicts (written before growbench judged its "
                     "plants), so every plant that grew is compared.</p>")

    parts.append("<h2>Figures</h2>")
    for name, cap in figs:
        parts.append(f"<figure><img src='{e(name)}.png' alt='{e(name)}'><figcaption>{e(cap)} "
                     f"<a href='{e(name)}.pdf'>PDF</a>{how if name == 'fig-quality' else ''}</figcaption></figure>")
    parts += peers  # the "versus peers" section, when a peers.json was given or found
    parts.append("<p class='note'>Generated by reports/report.py from the results file alone. Growth-time "
                 "intervals: 'CI', the distribution-free 95% interval of the median from order statistics (6 trials "
                 "or more); 'range', the smallest to the largest trial (2 to 5); one trial has none. Exponents k: "
                 "least squares on log-log medians, fitted only over 3 or more distinct sizes spanning a factor of 2, "
                 "with a 95% interval from Student's t. Memory: each phase's own peak resident memory; the trial "
                 "process's peak stays in the results file.</p>")
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

    plt.rcParams.update(STYLE)
    cases = doc["cases"]
    fig, ax = plt.subplots(figsize=(PAGE_IN, 0.4 * len(cases) + 1.0), layout="constrained")
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
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1))
    plain_log_ticks(ax)
    for ext in formats:
        fig.savefig(os.path.join(out, f"fig-peers.{ext}"), metadata={"CreationDate": None} if ext == "pdf" else None)
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

def write_report(doc, results_path, out, formats, peers_path=None, pareto_metric=None, viewer_mb=VIEWER_AUTOLOAD_MB):
    """Figures, tables and index.html in `out` from a results document already read and checked (load_results).
    VIEWER_MB: the size in MB above which a trial page's 3D view waits for a click; None: no 3D views."""
    cells = [Cell(t) for t in doc["trials"]]
    if not cells:
        raise ReportError(f"{results_path}: no trials to report")
    os.makedirs(out, exist_ok=True)
    formats = list(formats)
    if "png" not in formats:
        formats.insert(0, "png")  # the HTML page shows the PNGs
    print(f"report: {len(cells)} cells from {results_path}", file=sys.stderr)
    if pareto_metric and pareto_metric not in numeric_metrics(cells):
        raise ReportError(f"--pareto-metric {pareto_metric}: no cell of {results_path} has it; its metrics: "
                          f"{', '.join(numeric_metrics(cells)) or 'none'}")
    figs = figures(cells, out, formats, pareto_metric or PARETO_METRIC)

    pooled = pooled_summaries(doc)
    rows = table_rows(cells, pooled)
    notes = table_notes(cells)
    beyond = paper_tables.write_tex(
        os.path.join(out, "table.tex"),
        {(label, scene): row_numbers(group, pooled) for label, scene, group in table_groups(cells)},
        ordered(c.row for c in cells), ordered(c.scene for c in cells), QUALITY, notes)
    if beyond:
        print(f"report: note: table.tex holds characters pdflatex cannot set ({' '.join(beyond)}); "
              "compile it with lualatex or xelatex and a font that has them", file=sys.stderr)
    write_markdown(os.path.join(out, "table.md"), rows, CAPTION, notes)

    base = os.path.dirname(os.path.abspath(results_path))
    views = None
    if viewer_mb is not None:
        views = viewer.write_assets(doc, cells, base, out, own_path, slug, trial_dir_of, viewer_mb)
    pages = write_trial_pages(cells, base, out, views)
    grids = copy_grids(doc, base, out, pages)
    failed = [c for c in cells if not c.ok]
    peers_path = peers_path or os.path.join(base, "peers.json")
    peers = peers_html(load_peers(peers_path), peers_path, out, formats) if os.path.exists(peers_path) else []
    write_html(os.path.join(out, "index.html"), doc, results_path, rows, figs, grids, failed, CAPTION,
               write_metrics_doc(out), peers, cells, explore.explore_html(cells, pages, QUALITY))
    print(f"report: wrote {len(figs)} figures ({', '.join(formats)}), table.tex, table.md and index.html "
          f"in {out}", file=sys.stderr)
    return figs


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("results", nargs="?", help="results.json written by `growbench suite`")
    ap.add_argument("--out", required=True, help="report directory (created)")
    ap.add_argument("--formats", default="png,pdf", help="figure formats (comma-separated; default png,pdf)")
    ap.add_argument("--peers", help="peers.json of `make peers`: adds the \"versus peers\" section (alone, without "
                                    "results); default: a peers.json beside the results file, if there is one")
    ap.add_argument("--pareto-metric", help=f"the quality metric of the quality-against-cost (Pareto) figures, one "
                                             f"per scene of a suite with sweeps (default {PARETO_METRIC})")
    ap.add_argument("--viewer-autoload-mb", type=float, default=VIEWER_AUTOLOAD_MB,
                    help=f"a trial page loads its 3D view at once when plant.glb is at most this many MB, else on a "
                         f"click (default {VIEWER_AUTOLOAD_MB:g})")
    ap.add_argument("--no-viewer", action="store_true",
                    help="no 3D views: each one copies its plant.glb into the report, as base64 (4/3 of its size)")
    args = ap.parse_args(argv)
    if args.results is None and args.peers is None:
        ap.error("give a results file, --peers, or both")
    try:
        if args.results is None:
            write_peers_only(args.peers, args.out, [f for f in args.formats.split(",") if f] or ["png"])
            print(f"report: wrote the versus-peers page {os.path.join(args.out, 'index.html')}", file=sys.stderr)
            return 0
        doc = load_results(args.results)
        write_report(doc, args.results, args.out, [f for f in args.formats.split(",") if f], args.peers,
                     args.pareto_metric, None if args.no_viewer else args.viewer_autoload_mb)
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
