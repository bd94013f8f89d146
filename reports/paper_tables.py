"""table.tex: the report's numbers as tables that fit a printed page.

One table per quantity (growth time, memory, file size, nodes, each quality metric), algorithm entries as rows
and scenes as columns, one unit per table. A table goes in one column (`table`) when its estimated width fits
there, across the page (`table*`) when it fits the page, and otherwise its scenes are split over several tables;
more than MAX_ROWS entries split its rows. The width estimate is the rule below; tests/reports/paper_tables_test.py
compiles the output with pdflatex in a two-column article and fails on an overfull box or a float too large.

Needs \\usepackage{booktabs}. Units are written as text (ms, MiB, $\\mu$s), so no siunitx is needed.
"""

COLUMN_PT = 229.0  # \\columnwidth of a two-column 10pt article on letter paper (229.87pt): the narrowest usual
PAGE_PT = 469.0  # its \\textwidth (469.75pt)
# The rule: a cell's width is the sum of its characters' widths at \\footnotesize (8pt Computer Modern, rounded
# up: digits 4.25pt, most lower-case letters under 4.5pt, capitals and m, w under 7pt), plus 2 \\tabcolsep.
NARROW = set(".,;:[]()'!|ilj ")
WIDE = set("mwMW") | set("ABCDEFGHIJKLMNOPQRSTUVWXYZ")
TABCOLSEP_PT = 4.0
MAX_ROWS = 40  # \\footnotesize rows under a caption in a float of a 9 in text height, with room to spare

LATEX_SPECIAL = {"\\": "\\textbackslash{}", "&": "\\&", "%": "\\%", "_": "\\_", "#": "\\#", "~": "$\\sim$",
                 "[": "{[}", "]": "{]}", "$": "\\$", "{": "\\{", "}": "\\}", "^": "\\^{}",
                 "<": "\\textless{}", ">": "\\textgreater{}", "|": "\\textbar{}"}


def escape(s):
    """Text for LaTeX: each special character replaced once (labels and reasons are free text), on one line
    (a line break or control character inside a cell would end it or the paragraph)."""
    import re
    s = " ".join("".join(c if c.isprintable() else " " for c in str(s)).split())
    return re.sub(r"[\\&%_#~\[\]$\{\}^<>|]", lambda m: LATEX_SPECIAL[m.group(0)], s)


def sig(x):
    """A number with three significant figures and no exponent: 0.0123, 1.23, 12.3, 123, 12300."""
    a = abs(x)
    if a >= 100 or a == 0:
        return f"{x:.0f}"
    if a >= 10:
        return f"{x:.1f}"
    if a >= 1:
        return f"{x:.2f}"
    digits = 3
    while a < 0.1 and digits < 9:
        a *= 10
        digits += 1
    return f"{x:.{digits}f}"


def time_unit(values):
    """(name in LaTeX, name in text, seconds per unit) for these times: the unit in which their median reads between
    1 and 1000, so that most cells need neither leading zeros nor many digits."""
    mid = sorted(values)[len(values) // 2] if values else 0.0
    if mid < 1e-3:
        return "$\\mu$s", "us", 1e-6
    if mid < 1:
        return "ms", "ms", 1e-3
    return "s", "s", 1.0


def bytes_unit(values):
    top = max(values, default=0.0)
    for name, f in (("GiB", 2 ** 30), ("MiB", 2 ** 20), ("KiB", 2 ** 10)):
        if top >= f:
            return name, name, f
    return "B", "B", 1


# Each quantity: (key, title, what its number is, unit chooser or None). The key names a row_numbers field, or a
# quality metric ("metric:KEY").
QUANTITIES = [
    ("time", "Growth time", "the median wall time of the growth phase over the repetitions of the valid seeds "
     "pooled; in brackets the distribution-free 95\\% CI of the median (6 trials or more) or the range of the trials "
     "(2 to 5); a number without brackets is a single trial", time_unit),
    ("growth_rss", "Growth peak RSS", "the growth phase's own peak resident memory, median over the valid seeds' "
     "trials; * the peak could not be reset at the phase's start and is the process's up to then", bytes_unit),
    ("query_rss", "Query structure peak RSS", "the query structure build's own peak resident memory, median over the "
     "valid seeds' trials; * as for the growth peak", bytes_unit),
    ("glb", "GLB file size", "the plant's binary glTF as written, median over the valid seeds", bytes_unit),
    ("nodes", "Plant nodes", "median over the valid seeds", None),
]


def metric_quantities(quality):
    """One table per quality metric: (key, title, what) from the report's QUALITY list."""
    return [(f"metric:{k}", title[0].upper() + title[1:], "median over the valid seeds where the metric applies; "
             "n/a: it applies to none", None) for k, title, _ in quality]


def plant_mark(r):
    """The cell's text when no seed's plant is valid: what happened instead."""
    group, failed = r["group"], r["failed"]
    if len(failed) == len(group):
        return ", ".join(sorted({c.status for c in failed}))
    verdicts = {c.verdict for c in group if c.ok}
    return "not appl." if verdicts == {"not_applicable"} else "degen." if verdicts == {"degenerate"} else "not valid"


def cell_text(r, key, scale):
    """One cell: the row's number in the table's unit, or why there is none."""
    if r is None:
        return ""
    if not r["valid"]:
        return plant_mark(r)
    partial = "$^\\dagger$" if len(r["valid"]) < len(r["group"]) else ""
    if key == "time":
        t = r["time"]
        text = sig(t["median"] / scale)
        if t.get("n", 1) >= 2 and "lo" in t:
            text += f" [{sig(t['lo'] / scale)}, {sig(t['hi'] / scale)}]"
        return text + partial
    if key.startswith("metric:"):
        m = r["metrics"].get(key[len("metric:"):], "absent")
        return "--" if m == "absent" else "n/a" if m is None else f"{m:.3f}" + partial
    if key not in r:
        return "--"
    v = r[key]
    if isinstance(v, tuple):  # a memory peak and whether it was reset
        return sig(v[0] / scale) + ("" if v[1] else "*") + partial
    return (sig(v / scale) if scale != 1 or not float(v).is_integer() else f"{v:.0f}") + partial


def numbers_of(rows, key):
    """The raw numbers of one quantity over these rows (for its unit)."""
    out = []
    for r in rows.values():
        if not r["valid"]:
            continue
        if key == "time":
            out.append(r["time"]["median"])
        elif key in r and not key.startswith("metric:"):
            out.append(r[key][0] if isinstance(r[key], tuple) else r[key])
    return out


def width_pt(texts):
    """The rule: the widest cell's characters (NARROW, WIDE, others), plus the column's padding; LaTeX markup not counted."""
    import re
    plain = [re.sub(r"\$\^\\dagger\$", "+", re.sub(r"\$\\mu\$", "u", t)) for t in texts]
    chars = lambda t: sum(2.8 if ch in NARROW else 7.0 if ch in WIDE else 4.5 for ch in t)
    return max((chars(t) for t in plain), default=0) + 2 * TABCOLSEP_PT


def split_columns(label_w, widths):
    """Groups of consecutive scene columns, each fitting the page width beside the label column: as few groups as
    the greedy packing needs, their sizes evened out where they still fit (ten scenes as 5 + 5, not 8 + 2)."""
    groups, current, total = [], [], label_w
    for i, w in enumerate(widths):
        if current and total + w > PAGE_PT:
            groups.append(current)
            current, total = [], label_w
        current.append(i)
        total += w
    if current:
        groups.append(current)
    k, n = len(groups), len(widths)
    even = [list(range(g * n // k, (g + 1) * n // k)) for g in range(k)]
    if all(label_w + sum(widths[i] for i in g) <= PAGE_PT for g in even):
        return even
    return groups


def one_table(title, what, unit_tex, labels, scenes, cells, part, parts):
    """The LaTeX of one float: `cells[i][j]` is entry i on scene j."""
    head_w = width_pt(["algorithm"] + labels)
    total = head_w + sum(width_pt([scene] + [row[j] for row in cells]) for j, scene in enumerate(scenes))
    env = "table" if total <= COLUMN_PT else "table*"
    unit = f" ({unit_tex})" if unit_tex else ""
    cont = f" (part {part} of {parts})" if parts > 1 else ""
    lines = [f"\\begin{{{env}}}[tbp]", "\\centering", "\\footnotesize", f"\\setlength{{\\tabcolsep}}{{{TABCOLSEP_PT:g}pt}}",
             f"\\caption{{{escape(title)}{unit}{cont}: {what}.}}",
             "\\begin{tabular}{l" + "r" * len(scenes) + "}", "\\toprule",
             " & ".join(["algorithm"] + [escape(s) for s in scenes]) + " \\\\", "\\midrule"]
    for i, label in enumerate(labels):
        lines.append(" & ".join([escape(label)] + [cells[i][j] for j in range(len(scenes))]) + " \\\\")
    lines += ["\\bottomrule", "\\end{tabular}", f"\\end{{{env}}}", ""]
    return lines


def quantity_tables(key, title, what, unit_of, rows, labels, scenes):
    """Every float of one quantity: its scenes split to fit the page width, its entries into MAX_ROWS chunks."""
    unit_tex, scale = "", 1
    if unit_of:
        unit_tex, _, scale = unit_of(numbers_of(rows, key))
    cells = [[cell_text(rows.get((label, scene)), key, scale) for scene in scenes] for label in labels]
    if all(text in ("", "--") for row in cells for text in row):
        return []  # no cell records this quantity
    head_w = width_pt(["algorithm"] + labels)
    widths = [width_pt([s] + [cells[i][j] for i in range(len(labels))]) for j, s in enumerate(scenes)]
    col_groups = split_columns(head_w, widths)
    row_groups = [list(range(k, min(k + MAX_ROWS, len(labels)))) for k in range(0, len(labels), MAX_ROWS)]
    parts = len(col_groups) * len(row_groups)
    out, part = [], 0
    for rg in row_groups:
        for cg in col_groups:
            part += 1
            out += one_table(title, what, unit_tex, [labels[i] for i in rg], [scenes[j] for j in cg],
                             [[cells[i][j] for j in cg] for i in rg], part, parts)
    return out


LEGEND = ("In every table: a row is an algorithm entry, a column a scene; only plants judged valid enter a number "
          "(docs/metrics.md, Validity). $^\\dagger$: some seeds' plants were left out (listed below); degen.: every "
          "seed's plant was degenerate; not appl.: the algorithm does not apply to the scene; a status (timeout, "
          "error, ...): no seed finished; --: not recorded; empty: not run.")


def write_tex(path, rows_by_cell, labels, scenes, quality, notes=()):
    """table.tex from row_numbers keyed by (label, scene)."""
    lines = ["% growbench report tables; needs \\usepackage{booktabs}. One float per quantity: `table` where it",
             "% fits a column, `table*` where it needs the page (reports/paper_tables.py).",
             "", f"\\noindent{{\\footnotesize {LEGEND}\\par}}", ""]
    for key, title, what, unit_of in QUANTITIES + metric_quantities(quality):
        lines += quantity_tables(key, title, what, unit_of, rows_by_cell, labels, scenes)
    if notes:  # the plants left out of comparisons: text, not a float, so that a long list breaks across pages
        lines += ["\\paragraph{" + escape(notes[0]) + "}", "{\\footnotesize\\raggedright"]
        lines += [escape(n) + ("\\\\" if i + 1 < len(notes) - 1 else "") for i, n in enumerate(notes[1:])]
        lines += ["\\par}", ""]
    beyond = beyond_latin(lines)
    if beyond:
        lines.insert(0, f"% Names here hold characters pdflatex cannot set ({' '.join(beyond)}): compile with lualatex or "
                        "xelatex and a font that has them.")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))
    return beyond


def beyond_latin(lines):
    """The characters of `lines` past Latin Extended-A, which pdflatex's T1 fonts do not hold (CJK, symbols):
    a name may be any UTF-8, and a table that names them is still a valid document for lualatex."""
    return sorted({c for line in lines for c in line if ord(c) > 0x17F})
