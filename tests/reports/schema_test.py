#!/usr/bin/python3
"""harness/record/results.schema.json against real output: a tiny suite's results.json, a trial's record.json and the
committed baseline must validate, a renamed or mistyped field must not, and the C++ reader must name the path of a
mistyped field. Run by ctest with Debian's /usr/bin/python3 (python3-jsonschema).

usage: schema_test.py GROWBENCH WORKDIR
"""
import copy
import json
import os
import shutil
import subprocess
import sys

import jsonschema

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
SCHEMA = json.load(open(os.path.join(ROOT, "harness", "record", "results.schema.json")))
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def validator(definition=None):
    """The results schema, or one of its $defs (trial_record, baseline) as the root."""
    schema = SCHEMA if definition is None else {"$schema": SCHEMA["$schema"], "$defs": SCHEMA["$defs"],
                                                "$ref": f"#/$defs/{definition}"}
    return jsonschema.Draft202012Validator(schema)


def errors(doc, definition=None):
    return [f"{'/'.join(map(str, e.absolute_path))}: {e.message}" for e in validator(definition).iter_errors(doc)]


def run(*args):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True)


jsonschema.Draft202012Validator.check_schema(SCHEMA)
growbench, work = sys.argv[1], sys.argv[2]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
suite = {"schema_version": 1, "name": "schema", "description": "schema test", "repetitions": 2, "warmup": 0, "threads": 1,
         "seeds": [1, 2], "scenes": ["column"],
         "algorithms": [{"name": "spacecol", "params": {"point_count": 300}},
                        {"name": "spacecol", "label": "crash", "params": {"point_count": 300}, "fault": "crash"}]}
suite_file = os.path.join(work, "suite.json")
json.dump(suite, open(suite_file, "w"))
out = run(growbench, "suite", suite_file, "--out", os.path.join(work, "suite"), "-q")
check(out.returncode == 0, f"the suite runs: {out.stdout}{out.stderr}")
results = json.load(open(os.path.join(work, "suite", "results.json")))

# What the suite writes validates, and the schema and the binary agree on the version.
check(errors(results) == [], f"results.json validates: {errors(results)[:5]}")
check(results["schema_version"] == SCHEMA["$defs"]["results"]["properties"]["schema_version"]["const"],
      "the schema's schema_version is the one the binary writes")
record = json.load(open(os.path.join(work, "suite", "trials", "spacecol", "column", "s1", "record.json")))
check(errors(record, "trial_record") == [], f"a suite trial's record.json validates: {errors(record, 'trial_record')[:5]}")
out = run(growbench, "run", "-q", "-a", "spacecol", "-s", "wall", "--set", "point_count=300", "-o", os.path.join(work, "run"))
check(out.returncode == 0, f"growbench run: {out.stdout}{out.stderr}")
run_record = json.load(open(os.path.join(work, "run", "record.json")))
check(errors(run_record, "trial_record") == [], f"growbench run's record.json validates: {errors(run_record, 'trial_record')[:5]}")
check(run_record["output_bytes"]["glb_plain"] > run_record["output_bytes"]["glb"] > 0,
      f"the compact GLB is smaller than the plain size beside it: {run_record['output_bytes']}")
out = run(growbench, "run", "-q", "-a", "spacecol", "-s", "wall", "--set", "point_count=300", "--glb", "plain", "-o",
          os.path.join(work, "run-plain"))
check(out.returncode == 0, f"growbench run --glb plain: {out.stdout}{out.stderr}")
plain_record = json.load(open(os.path.join(work, "run-plain", "record.json")))
check(errors(plain_record, "trial_record") == [], f"--glb plain's record validates: {errors(plain_record, 'trial_record')[:5]}")
check(plain_record["output_bytes"]["glb_plain"] == plain_record["output_bytes"]["glb"] ==
      run_record["output_bytes"]["glb_plain"], "the plain size is the same whichever layout was written")
# A trial spec names its layout; an unknown one does not validate.
with_layout = copy.deepcopy(results)
with_layout["trials"][0]["spec"]["glb"] = "plain"
check(errors(with_layout) == [], f"a spec with a layout validates: {errors(with_layout)[:5]}")
with_layout["trials"][0]["spec"]["glb"] = "draco"
check(any(e.endswith("'draco' is not one of ['plain', 'instanced', 'compact']") for e in errors(with_layout)),
      f"an unknown layout fails: {errors(with_layout)[:3]}")
# No built-in algorithm writes files of its own yet: the record of one that does, by hand. Sizes by file
# name validate; a size that is not a count, or the object written empty (the writer leaves it out), do not.
with_files = copy.deepcopy(run_record)
with_files["output_bytes"]["algorithm_files"] = {"texture.png": 123456, "skeleton.svg": 789}
check(errors(with_files, "trial_record") == [], f"algorithm_files validates: {errors(with_files, 'trial_record')[:5]}")
bad_files = copy.deepcopy(with_files)
bad_files["output_bytes"]["algorithm_files"]["texture.png"] = "big"
check(any(e.startswith("output_bytes/algorithm_files/texture.png:") for e in errors(bad_files, "trial_record")),
      f"a size that is not a count fails: {errors(bad_files, 'trial_record')[:3]}")
bad_files["output_bytes"]["algorithm_files"] = {}
check(any(e.startswith("output_bytes/algorithm_files:") for e in errors(bad_files, "trial_record")),
      "an empty algorithm_files fails (it is left out when there are none)")
baseline = json.load(open(os.path.join(ROOT, "reports", "baselines", "quick.json")))
check(errors(baseline, "baseline") == [], f"the committed baseline validates: {errors(baseline, 'baseline')[:5]}")

# Failures are recorded as such, and every ok cell carries its growth-time summary.
by_label = {}
for t in results["trials"]:
    by_label.setdefault(t["label"], []).append(t)
check(all(t["status"] == "crashed" and "message" in t for t in by_label["crash"]), "the crash cells are recorded")
for t in by_label["spacecol"]:
    g = t.get("summary", {}).get("growth_s")
    times = [s["phases"]["growth"]["wall_s"] for s in t["samples"] if s["status"] == "ok"]
    check(g is not None and g["n"] == len(times) == 2 and g["lo"] <= g["median"] <= g["hi"] and not g["exact"],
          f"{t['id']}: summary.growth_s of its {len(times)} repetitions: {g}")
pooled = results["summary"]["growth_s_over_seeds"]
check([p["cells"] for p in pooled] == [[t["id"] for t in by_label["spacecol"]]], f"one pooled row over both seeds: {pooled}")
check(pooled and pooled[0]["growth_s"]["n"] == 4, "the pooled row holds both seeds' repetitions")

# A renamed field, a mistyped one, a missing required one: each fails, at its path.
def mutated(f):
    d = copy.deepcopy(results)
    f(d)
    return d


sample = lambda d: d["trials"][0]["samples"][0]
cases = {
    "renamed": (lambda d: sample(d)["phases"]["growth"].__setitem__("wal_s", sample(d)["phases"]["growth"].pop("wall_s")),
                "trials/0/samples/0/phases/growth"),
    "mistyped": (lambda d: sample(d)["phases"]["growth"].__setitem__("wall_s", "fast"), "trials/0/samples/0/phases/growth/wall_s"),
    "missing": (lambda d: d["trials"][0].pop("scene_spec"), "trials/0"),
    "unknown phase": (lambda d: sample(d)["phases"].__setitem__("grow", sample(d)["phases"]["growth"]), "trials/0/samples/0/phases"),
    "wrong kind": (lambda d: d.__setitem__("kind", "growbench-baseline"), "kind"),
}
for name, (f, path) in cases.items():
    errs = errors(mutated(f))
    check(any(e.startswith(path + ":") for e in errs), f"a {name} field fails at {path}: {errs[:3]}")

# The C++ reader names the file and the path of a mistyped field, and refuses a renamed one.
for name, expect in [("mistyped", "at trials[0].samples[0].phases.growth.wall_s: expected a number"),
                     ("renamed", "at trials[0].samples[0].phases.growth.wal_s: unknown field 'wal_s' (did you mean 'wall_s'?)")]:
    bad = os.path.join(work, f"{name}.json")
    json.dump(mutated(cases[name][0]), open(bad, "w"))
    out = run(growbench, "compare", bad, os.path.join(work, "suite", "results.json"))
    check(out.returncode == 2 and f"{bad}: {expect}" in out.stderr, f"growbench compare on a {name} field: {out.stderr.strip()}")

print("schema tests:", "FAILED" if failures else "OK")
sys.exit(1 if failures else 0)
