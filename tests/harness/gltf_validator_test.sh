#!/usr/bin/env bash
# Every .glb the tests write passes the Khronos glTF validator (tools/gltf, pinned) with no errors: the unit
# tests that write glTF (run here with their temporary files kept under OUT), and `growbench run` of small
# plants in every layout: ivy (leaves), an L-system with vertex colours, space colonization, and one with no
# geometry at all.
#   tests/harness/gltf_validator_test.sh GROWBENCH_TESTS GROWBENCH OUT
set -euo pipefail
tests=$1 growbench=$2 out=$3
src=$(cd "$(dirname "$0")/../.." && pwd)
if [[ ! -d "$src/tools/gltf/node_modules/gltf-validator" ]]; then
  echo "gltf_validator_test: the validator is not installed: npm ci --prefix tools/gltf (scripts/install-deps runs it)" >&2
  exit 1
fi
rm -rf "$out"
mkdir -p "$out/tmp"
TMPDIR="$out/tmp" "$tests" --gtest_filter='Glb.*:Exporters.*:PlantAttributes*.*' > "$out/tests.log"
for layout in plain instanced compact; do
  "$growbench" run -q -a ivy -s wall --set max_root_length=0.75 --glb $layout -o "$out/ivy-$layout" > /dev/null
  "$growbench" run -q -a lsystem -s column --set grammar=bracketed-plant --set generations=4 --set tube_uvs=true --organ color_jitter=0.3 \
    --glb $layout -o "$out/lsystem-$layout" > /dev/null
  "$growbench" run -q -a spacecol -s envelope --set point_count=2000 --glb $layout -o "$out/spacecol-$layout" > /dev/null
  # A plant with no geometry (a suite's input check grows none): still a valid file.
  "$growbench" run -q -a spacecol -s envelope --set point_count=300 --max-steps 0 --glb $layout -o "$out/empty-$layout" > /dev/null
done
mapfile -t files < <(find "$out" -name '*.glb' | sort)
echo "gltf_validator_test: ${#files[@]} .glb files"
node "$src/tools/gltf/validate.mjs" "${files[@]}"
