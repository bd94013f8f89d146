#!/usr/bin/env bash
# End to end: a tiny suite, rendered, reported; the report's index.html opened in Debian's headless
# chromium, which must find every image. Then a figure is removed and the same check must fail.
# Usage: report_e2e.sh GROWBENCH_BINARY WORK_DIR
set -euo pipefail
gb=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
cat > "$work/tiny.json" <<'JSON'
{
  "schema_version": 1,
  "name": "tiny",
  "description": "report end-to-end test",
  "repetitions": 2,
  "warmup": 0,
  "threads": 1,
  "seeds": [1, 2],
  "scenes": ["wall", "column"],
  "algorithms": [
    {"name": "spacecol", "params": {"point_count": 600}},
    {"name": "hadrich", "params": {"max_particles": 300}}
  ]
}
JSON
fail() { echo "report_e2e: FAIL: $*" >&2; exit 1; }

"$gb" suite "$work/tiny.json" --out "$work/run" --render preview -q > "$work/suite.log" 2>&1 || { cat "$work/suite.log"; fail "suite"; }
[[ -f "$work/run/grid.png" ]] || fail "no grid.png"
"$gb" report "$work/run/results.json" --out "$work/report" > "$work/report.log" 2>&1 || { cat "$work/report.log"; fail "report"; }
for f in index.html table.tex table.md fig-time-vs-size.png fig-time-vs-size.pdf fig-memory-vs-size.png fig-file-size.png \
         fig-seeds.png fig-quality.png fig-growth-curves.png renders/grid.png; do
  [[ -s "$work/report/$f" ]] || fail "report has no $f"
done
grep -q '\\toprule' "$work/report/table.tex" || fail "table.tex is not booktabs"
# The quality figure links the metrics' definitions, rendered beside the page.
grep -q "href='metrics.html'" "$work/report/index.html" || fail "index.html does not link metrics.html"
grep -q '<h2>penetration_nodes, penetration_samples</h2>' "$work/report/metrics.html" || fail "metrics.html is not docs/metrics.md"
grep -q 'http' "$work/report/index.html" && fail "index.html refers to the network"
# Each grid cell links to its trial's page, whose render resolves from where the page is.
links=$(grep -o "class='cell' href='trials/[^']*'" "$work/report/index.html" | wc -l)
(( links >= 8 )) || fail "only $links grid cells link to trial pages"
page=$(grep -o "class='cell' href='trials/[^']*'" "$work/report/index.html" | head -1 | sed "s/.*href='//; s/'$//")
[[ -f "$work/report/$page" ]] || fail "the grid links $page, which is not there"
img=$(grep -o "<img src='[^']*'" "$work/report/$page" | head -1 | sed "s/<img src='//; s/'$//")
[[ -n "$img" && -f "$(dirname "$work/report/$page")/$img" ]] || fail "the trial page's render '$img' does not resolve"
grep -q "record.json" "$work/report/$page" || fail "the trial page does not link its record"

browser=$(command -v chromium || command -v chromium-browser || true)
[[ -n "$browser" ]] || fail "chromium is not installed (scripts/install-deps installs it)"
check() {  # prints the <body> attributes the page's own check writes once every image has loaded or failed
  timeout 120 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$work/chromium" \
    --virtual-time-budget=10000 --dump-dom "file://$work/report/index.html" 2>/dev/null | grep -o '<body[^>]*>'
}
body=$(check) || fail "chromium did not load the page"
echo "report_e2e: $body"
[[ "$body" == *'data-missing-images="0"'* ]] || fail "images missing: $body"
images=$(sed -E 's/.*data-images="([0-9]+)".*/\1/' <<< "$body")
(( images >= 8 )) || fail "only $images images on the page"
timeout 120 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$work/chromium" \
  --window-size=1400,3000 --screenshot="$work/report/screenshot.png" "file://$work/report/index.html" > /dev/null 2>&1 \
  || fail "no screenshot"
[[ -s "$work/report/screenshot.png" ]] || fail "empty screenshot"

# The check can fail: without one figure the page reports it.
rm "$work/report/fig-quality.png"
body=$(check) || fail "chromium did not load the page"
[[ "$body" == *'data-missing-images="1"'* ]] || fail "a removed figure was not noticed: $body"

# A file that is not results: a clear error, exit status 2.
echo '{}' > "$work/not-results.json"
set +e
"$gb" report "$work/not-results.json" --out "$work/bad" > "$work/bad.log" 2>&1
rc=$?
set -e
[[ $rc -eq 2 ]] || fail "report on a non-results file exited $rc"
grep -q 'not a growbench results file' "$work/bad.log" || fail "unclear error: $(cat "$work/bad.log")"
echo "report_e2e: ok"
