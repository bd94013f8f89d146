#!/usr/bin/python3
"""Names from shared files, through every writer: a suite whose suite, scene and entry names carry HTML,
TeX, spreadsheet formulas, shell and Slurm patterns, POV-Ray directives and path steps (`..`) is run,
rendered, summarized, reported, compared, sharded and merged (also through bench/slurm/suite-array.sh, with
a stand-in sbatch that runs what it is given), and added to a history that is plotted. Every command must
succeed, write nothing outside its output folder, and carry each name as inert text: no element, attribute
or script the name brought into a page, no formula cell in the CSV, no directive line in render.pov, a
table.tex that LaTeX sets with every character and a table.md whose rows keep their columns. Names with a control
character are refused (exit 2, naming the key) before anything is written.

usage: hostile_names_test.py GROWBENCH WORKDIR
"""
import csv
import html.parser
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
growbench, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


# Each carries the token "pwn", which must never reach a page as markup.
ENTRY_NAMES = [
    "<script>pwn()</script>",
    "<pwn-tag id=pwn>",
    "x' onerror='pwn",
    'y" onmouseover="pwn',
    "=cmd|' /C calc'!A0 pwn",
    "+@-pwn",
    "..",
    "%j %a %% pwn",
    "`pwn` $(pwn) ; pwn &",
    "{}|\\ pwn",
    "#include \"/etc/passwd\" pwn",
    "$\\frac{$ ^_~ pwn",
    "植物 ☘ pwn",
]
SCENE_NAME = "<b id=pwn>$\\frac{$</b> .."
SUITE_NAME = "../../<i id=pwn>x</i> $x$"
# Every name must be readable where a person reads it: these appear, decoded, in the report's text.
SHOWN = ["<script>pwn()</script>", "x' onerror='pwn", "=cmd|' /C calc'!A0 pwn", SCENE_NAME]


def run(*args, expect=0, cwd=None, env=None):
    r = subprocess.run([str(a) for a in args], capture_output=True, text=True, cwd=cwd, env=env, timeout=600)
    check(r.returncode == expect, f"{' '.join(map(str, args[:3]))}...: exit {r.returncode}, expected {expect}\n"
                                  f"{r.stdout[-2000:]}{r.stderr[-2000:]}")
    return r


def snapshot(root, inside):
    """Every path under root except those under the folders in `inside`."""
    seen = set()
    for d, dirs, files in os.walk(root):
        dirs[:] = [x for x in dirs if os.path.join(d, x) not in inside]
        for x in dirs + files:
            seen.add(os.path.relpath(os.path.join(d, x), root))
    return seen


class Page(html.parser.HTMLParser):
    """The elements, attributes and script text of a page, and its text."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.problems, self.text, self.in_script, self.in_data = [], [], False, False

    def handle_starttag(self, tag, attrs):
        self.in_script = tag == "script"
        # A data block (the report's trial table, the history's series) is never run: it must hold JSON.
        self.in_data = tag == "script" and ("type", "application/json") in attrs
        if tag == "pwn-tag":
            self.problems.append(f"a <{tag}> element")
        for k, v in attrs:
            if (k.startswith("on") or k == "id") and v and "pwn" in v:
                self.problems.append(f"attribute {k}={v!r} on <{tag}>")

    def handle_endtag(self, tag):
        self.in_script = False

    def handle_data(self, data):
        if self.in_script and self.in_data:
            try:
                json.loads(data)
            except ValueError as e:
                self.problems.append(f"a JSON data block that does not parse ({e}): {data[:80]!r}")
            return
        if self.in_script and "pwn" in data:
            self.problems.append(f"script text {data[:80]!r}")
        self.text.append(data)


def check_page(path):
    p = Page()
    with open(path, encoding="utf-8") as f:
        p.feed(f.read())
    check(not p.problems, f"{os.path.relpath(path, work)}: a name became markup: {p.problems[:5]}")
    return "".join(p.text)


def check_pages(folder):
    pages = [os.path.join(d, f) for d, _, fs in os.walk(folder) for f in fs if f.endswith(".html")]
    check(pages, f"no page in {folder}")
    return {p: check_page(p) for p in pages}


def is_number(s):
    try:
        float(s)
        return True
    except ValueError:
        return False


def check_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    check(len(rows) > len(ENTRY_NAMES), f"{path}: {len(rows)} rows")
    for row in rows:
        check(len(row) == len(rows[0]), f"{path}: a row of {len(row)} fields under a header of {len(rows[0])}")
        for cell in row:
            check(is_number(cell) or not cell[:1] in ("=", "+", "-", "@", "\t", "\r"),
                  f"{path}: a cell a spreadsheet reads as a formula: {cell!r}")
    text = "\n".join(",".join(r) for r in rows)
    for name in ENTRY_NAMES:
        check(name in text, f"{path}: the label {name!r} is not there, as text")


def unescaped_bars(line):
    return len(re.findall(r"(?<!\\)\|", line))


def check_markdown(path):
    with open(path, encoding="utf-8") as f:
        lines = [x for x in f.read().splitlines() if x.startswith("|")]
    check(lines, f"{path}: no table")
    for x in lines:
        check("<" not in x and ">" not in x, f"{path}: raw markup in {x[:120]!r}")
        check(unescaped_bars(x) == unescaped_bars(lines[0]), f"{path}: a name split a row's columns: {x[:120]!r}")


def check_tex(path):
    """table.tex compiles with every character set. pdflatex has no glyphs past Latin (the CJK name), so the
    file must say to use lualatex, which sets it with DejaVu Sans and Droid Sans Fallback for CJK. A glyph
    no font has is only a line in the log ("Missing character"), so the log is read too."""
    with open(path, encoding="utf-8") as f:
        first = f.readline()
    check("lualatex" in first and "植" in first, f"{path}: the first line does not name lualatex for 植: {first!r}")
    tex = "lualatex" if "lualatex" in first else "pdflatex"
    if not shutil.which(tex):
        check(False, f"{tex} is missing: scripts/install-deps installs it")
        return
    fonts = ("\\usepackage{fontspec}"
             "\\directlua{luaotfload.add_fallback(\"cjk\", {\"Droid Sans Fallback:mode=node;\"})}"
             "\\setmainfont{DejaVu Sans}[RawFeature={fallback=cjk}]") if tex == "lualatex" else ""
    with tempfile.TemporaryDirectory() as d:
        shutil.copy(path, os.path.join(d, "table.tex"))
        with open(os.path.join(d, "doc.tex"), "w") as f:
            f.write("\\documentclass{article}\\usepackage{booktabs}" + fonts +
                    "\\begin{document}\\input{table}\\end{document}\n")
        r = subprocess.run([tex, "-interaction=nonstopmode", "-halt-on-error", "-no-shell-escape", "doc.tex"],
                           cwd=d, capture_output=True, text=True, timeout=300)  # lualatex builds its font cache once
        check(r.returncode == 0, f"{path}: {tex} fails on it: {r.stdout[-1500:]}")
        with open(os.path.join(d, "doc.log"), encoding="utf-8", errors="replace") as f:
            log = f.read()
        lost = sorted({line.strip() for line in log.splitlines()
                       if "Missing character" in line or "Error in luaotfload" in line})
        check(not lost, f"{path}: {tex} set it without every character: {lost[:5]}")


def check_pov(out):
    povs = [os.path.join(d, f) for d, _, fs in os.walk(out) for f in fs if f.endswith(".pov")]
    check(len(povs) >= len(ENTRY_NAMES), f"{len(povs)} render.pov files in {out}")
    for p in povs:
        with open(p, encoding="utf-8", errors="replace") as f:
            for n, line in enumerate(f, 1):
                if "pwn" in line:
                    check(line.lstrip().startswith("//"), f"{p}:{n}: a name outside a comment: {line[:120]!r}")


def write_suite(folder, names, scene_name, suite_name, points=250):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "hostile.scene.json"), "w", encoding="utf-8") as f:
        json.dump({"schema_version": 1, "base": "wall", "name": scene_name}, f, ensure_ascii=False)
    path = os.path.join(folder, "hostile suite $(touch PWNED) 'q'.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump({"schema_version": 1, "name": suite_name, "repetitions": 1, "warmup": 0, "threads": 1,
                   "seeds": [1], "scenes": ["hostile.scene.json"],
                   "algorithms": [{"name": "spacecol", "label": n, "params": {"point_count": points}} for n in names]},
                  f, ensure_ascii=False)
    return path


shutil.rmtree(work, ignore_errors=True)
# Output folders two levels down, so that a name's `..` steps would still land inside `work`, where the
# snapshot sees them.
top = os.path.join(work, "a", "b")
suite = write_suite(work, ENTRY_NAMES, SCENE_NAME, SUITE_NAME)
out, rep, hist, plot = (os.path.join(top, x) for x in ("out", "report", "history", "plot"))
shards = [os.path.join(top, f"shard{i}") for i in range(2)]
merged = os.path.join(top, "merged", "results.json")
slurm_out = os.path.join(top, "slurm 'out' $(touch PWNED) ;")
outs = {out, rep, hist, plot, *shards, os.path.dirname(merged), slurm_out}
before = snapshot(work, outs)

run(growbench, "suite", suite, "--out", out, "--render", "preview", "-q")
results = os.path.join(out, "results.json")
ids = [t["id"] for t in json.load(open(results, encoding="utf-8"))["trials"]]
check(len(set(ids)) == len(ENTRY_NAMES), f"each entry its own cell: {ids}")
for i in ids:
    check(os.path.isfile(os.path.join(out, "trials", i, "record.json")), f"trial {i!r} is not under --out")
check_pov(out)
check_csv(os.path.join(out, "results.csv"))
summary = run(growbench, "summary", results).stdout
for name in ENTRY_NAMES + [SCENE_NAME]:
    check(name in summary, f"summary does not show {name!r}")
run(growbench, "report", results, "--out", rep)
texts = check_pages(rep)
index = texts.get(os.path.join(rep, "index.html"), "")
for name in SHOWN:
    check(name in index, f"report index.html does not show {name!r} as text")
check_markdown(os.path.join(rep, "table.md"))
check_tex(os.path.join(rep, "table.tex"))
run(growbench, "compare", results, results)
run(growbench, "history", "add", results, "--dir", hist)
run(growbench, "history", "plot", "--dir", hist, "--out", plot)
check_pages(plot)
for i, s in enumerate(shards):
    run(growbench, "suite", suite, "--shard", f"{i}/2", "--out", s, "-q")
run(growbench, "merge", *(os.path.join(s, "results.json") for s in shards), "--out", merged)
check([t["id"] for t in json.load(open(merged, encoding="utf-8"))["trials"]] == ids, "merge: the unsharded cells")

# bench/slurm/suite-array.sh quotes every path into the scripts sbatch runs: a stand-in sbatch runs them
# at once, each array task in turn, so a word that escaped its quotes would run here.
fake = os.path.join(work, "bin")
os.makedirs(fake)
with open(os.path.join(fake, "sbatch"), "w") as f:
    f.write("""#!/usr/bin/python3
import os, subprocess, sys
opts = dict(a[2:].split("=", 1) for a in sys.argv[1:] if a.startswith("--") and "=" in a)
lo, _, hi = opts.get("array", "0").partition("-")
for task in range(int(lo), int(hi or lo) + 1):
    env = dict(os.environ, SLURM_JOB_ID="7", SLURM_ARRAY_TASK_ID=str(task))
    log = opts["output"].replace("%a", str(task))
    with open(log, "a") as out:
        if subprocess.run(["/bin/sh", "-c", opts["wrap"]], cwd=opts["chdir"], env=env, stdout=out, stderr=out).returncode:
            sys.exit(f"sbatch: the job failed, see {log}")
print("7")
""")
os.chmod(os.path.join(fake, "sbatch"), 0o755)
env = dict(os.environ, PATH=fake + os.pathsep + os.environ["PATH"], GROWBENCH=growbench)
run("bash", os.path.join(REPO, "bench", "slurm", "suite-array.sh"), suite, slurm_out, "2", env=env, cwd=work)
slurm_results = os.path.join(slurm_out, "results.json")
check(os.path.isfile(slurm_results) and [t["id"] for t in json.load(open(slurm_results))["trials"]] == ids,
      "suite-array.sh: the merged cells")

after = snapshot(work, outs)
ancestors = {"a", os.path.join("a", "b")}
stray = sorted(after - before - ancestors - {"bin", os.path.join("bin", "sbatch")})
check(not stray, f"written outside the output folders: {stray[:10]}")
check(not any("PWNED" in fs for _, _, fs in os.walk(work)) and not os.path.exists(os.path.join(REPO, "PWNED")),
      "a shell ran a name")

# A control character in any name is refused where it enters, naming the key, and writes nothing.
for where, names, scene, name in [("/algorithms/0/label", ["a\nb"], "s", "ok"),
                                  ("/name", ["ok"], "s\u001b[31m", "ok"),
                                  ("/name", ["ok"], "s", "tab\there")]:
    folder = os.path.join(work, "refused")
    shutil.rmtree(folder, ignore_errors=True)
    path = write_suite(folder, names, scene, name)
    r = run(growbench, "suite", path, "--out", os.path.join(folder, "out"), "-q", expect=2)
    check(where in r.stderr and "control character" in r.stderr, f"the refusal names {where}: {r.stderr.strip()}")
    check(not os.path.exists(os.path.join(folder, "out")), f"a refused suite wrote {folder}/out")

if failures:
    print(f"hostile_names_test: {len(failures)} failure(s)")
    sys.exit(1)
print("hostile_names_test: every writer kept every name inert")
