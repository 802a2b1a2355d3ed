#!/usr/bin/env bash
# pose-extract in the batch pipeline: the samples Makefile from an asset to a .spx (morph
# targets, and a skinned clip with --select), up to date on a second run, byte-identical
# extraction twice, schema-valid manifest and report, pose-map/proxy-eval --manifest.
# usage: extract.sh BUILD_DIR SOURCE_DIR OUT_DIR [SHARED_DATA]
set -euo pipefail
build=$(cd "$1" && pwd) src=$(cd "$2" && pwd) out=$3 data=${4:-}
bin=$build/apps
rm -rf "$out" && mkdir -p "$out" && out=$(cd "$out" && pwd)
fail=0 passed=0
check() {  # check MESSAGE COMMAND...
  local msg=$1
  shift
  if "$@"; then passed=$((passed + 1)); else echo "FAIL: $msg"; fail=$((fail + 1)); fi
}
v() { /usr/bin/python3 "$src/tests/cli/validate_json.py" "$src/schemas" "$@" >/dev/null; }

"$bin/sample-gen" car -o "$out/in" -q
m="make -s -C $src/samples BIN=$bin OUT=$out RES=48"
$m NAME=car-morph ASSET_FILE="$out/in/car-morph.glb" EXTRACT_FLAGS=--morph-targets
check "morph-target asset: no .spx" test -s "$out/car-morph/car-morph.spx"
check "morph-target asset: poses.json schema" v poses.schema.json "$out/car-morph/poses/poses.json"
check "morph-target asset: report schema" v pose-extract-report.schema.json "$out/car-morph/extract.report.json"
check "make would rerun an up-to-date chain" $m NAME=car-morph ASSET_FILE="$out/in/car-morph.glb" -q
# The poses are the sample's OBJ poses, number for number.
for p in rest front rear side roof; do
  check "$p.obj differs from the sample's" cmp -s <(grep -v '^#' "$out/in/$p.obj") <(grep -v '^#' "$out/car-morph/poses/$p.obj")
done
# Twice: the same bytes.
"$bin/pose-extract" "$out/in/car-morph.glb" -o "$out/again" --morph-targets -q
for f in rest.obj front.obj roof.obj poses.json; do
  check "$f differs between two runs" cmp -s "$out/car-morph/poses/$f" "$out/again/$f"
done
# proxy-eval reads the same manifest.
"$bin/proxy-eval" "$out/car-morph/car-morph.proxy.json" --manifest "$out/car-morph/poses/poses.json" -q \
  --report "$out/eval.json"
check "proxy-eval --manifest: the rest and 4 poses" \
  /usr/bin/python3 -c "import json,sys; sys.exit(len(json.load(open(sys.argv[1]))['poses']) != 5)" "$out/eval.json"

if [ -n "$data" ] && [ -e "$data/rigged-simple/RiggedSimple.glb" ]; then
  $m NAME=rigged ASSET_FILE="$data/rigged-simple/RiggedSimple.glb" EXTRACT_FLAGS="--animation 0 --select 2"
  check "skinned clip: no .spx" test -s "$out/rigged/rigged.spx"
  check "skinned clip: poses.json schema" v poses.schema.json "$out/rigged/poses/poses.json"
  check "skinned clip: report schema" v pose-extract-report.schema.json "$out/rigged/extract.report.json"
  check "skinned clip: 2 poses kept" /usr/bin/python3 -c \
    "import json,sys; sys.exit(len(json.load(open(sys.argv[1]))['poses']) != 2)" "$out/rigged/poses/poses.json"
  check "skinned clip: skin.json schema" v skin.schema.json "$out/rigged/poses/skin.json"
  check "skinned clip: the skin has 2 joints, 2 poses and a weight per rest vertex" /usr/bin/python3 -c \
    "import json,sys; s=json.load(open(sys.argv[1])); n=sum(1 for l in open(sys.argv[2]) if l.startswith('v '));
sys.exit(not (len(s['joints']) == 2 and len(s['poses']) == 2 and len(s['vertex_weights']) == n == len(s['vertex_positions'])))" \
    "$out/rigged/poses/skin.json" "$out/rigged/poses/rest.obj"
  check "skinned clip: the .spx has the skin" /usr/bin/python3 -c \
    "import sys; b=open(sys.argv[1],'rb').read(); sys.exit(not (b[10] == 1 and b[38] == 1))" "$out/rigged/rigged.spx"
fi
echo "$passed passed, $fail failed"
[ "$fail" = 0 ]
