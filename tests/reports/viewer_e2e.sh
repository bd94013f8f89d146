#!/usr/bin/env bash
# The report's interactive parts, end to end, as a reader meets them. The 3D viewer: a small suite (a plant that grows over many steps,
# and an L-system, drawn at one step), reported, and each trial page opened from file:// in Debian's
# headless chromium with the network refused (tools/viewer/test.mjs drives it): the viewer loads the plant
# and its scene, draws, its toggles and orbit change the picture, and the playback slider shows fewer
# triangles at earlier steps. Then the same check must fail on a page whose plant data is gone.
# Usage: viewer_e2e.sh GROWBENCH_BINARY WORK_DIR
set -euo pipefail
gb=$1
work=$2
here=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$work"
mkdir -p "$work"
fail() { echo "viewer_e2e: FAIL: $*" >&2; exit 1; }
[[ -d "$here/tools/viewer/node_modules/puppeteer-core" ]] || fail "tools/viewer has no node_modules (scripts/install-deps installs them)"
cat > "$work/small.json" <<'JSON'
{
  "schema_version": 1,
  "name": "viewer",
  "description": "the 3D viewer's end-to-end test",
  "repetitions": 1,
  "warmup": 0,
  "threads": 1,
  "seeds": [1],
  "scenes": ["wall"],
  "algorithms": [
    {"name": "spacecol", "params": {"point_count": 1500}},
    {"name": "lsystem", "label": "blossom", "params": {"grammar": "cherry-blossom"}}
  ]
}
JSON
"$gb" suite "$work/small.json" --out "$work/run" -q > "$work/suite.log" 2>&1 || { cat "$work/suite.log"; fail "suite"; }
"$gb" report "$work/run/results.json" --out "$work/report" > "$work/report.log" 2>&1 || { cat "$work/report.log"; fail "report"; }
grows=$(ls "$work"/report/trials/spacecol*.html)
once=$(ls "$work"/report/trials/blossom*.html)
[[ -s "$work/report/viewer/growbench-viewer.js" ]] || fail "the report has no viewer script"
node "$here/tools/viewer/test.mjs" --require-growth --require-scene $grows || fail "the spacecol page"
node "$here/tools/viewer/test.mjs" --require-scene $once || fail "the L-system page"
# The index's table sorts and filters, and its plot's points open the trial pages.
node "$here/tools/viewer/test-index.mjs" "$work/report/index.html" || fail "the index's trials table and plot"
# A page whose plant is gone must fail the same check, with the viewer saying so.
rm "$work"/report/trials/spacecol*/plant.glb.js
if node "$here/tools/viewer/test.mjs" $grows > "$work/negative.log" 2>&1; then
  cat "$work/negative.log"
  fail "test.mjs passed a page whose plant.glb.js is missing"
fi
grep -q "The 3D view failed: cannot load" "$work/negative.log" || { cat "$work/negative.log"; fail "the missing plant was not reported"; }
echo "viewer_e2e: passed"
