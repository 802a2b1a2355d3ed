#!/usr/bin/env bash
# proxy-export -o OUT.html in a real browser: the car and the barrel with their example meshes,
# the morph-target car from pose-extract's manifest (a slider per target, two added), the skinned RiggedSimple proxy in its
# asset, and the robot's forearm alone in the robot (--mesh). web/page-test.mjs (headless
# Chromium, playwright-core) opens each page, moves a slider, paints a dent or scrubs and plays the clip, takes screenshots and fails on any console error;
# tests/page_check compares what the page computed with the runtime header and the tools' error.
# Bad input: one error line and the documented exit code, no page left.
# usage: page.sh BUILD_DIR SOURCE_DIR OUT_DIR EXTRACT_OUT SHARED_DATA
set -uo pipefail
source "$(dirname "$0")/expect.sh"
start_cli_test "$1" "$2" "$3"
ex=$4 data=$5
chromium=${SPX_CHROMIUM:-/usr/bin/chromium}
if [ ! -x "$chromium" ]; then
  echo "SKIP: no Chromium at $chromium (scripts/setup.sh installs Debian's chromium; SPX_CHROMIUM names another)"
  exit 77
fi
if [ ! -d "$src/web/node_modules/playwright-core" ]; then
  echo "FAIL: no playwright-core in $src/web/node_modules (scripts/setup.sh installs it)"
  exit 1
fi
page() {  # page NAME PROXY.json [proxy-export options...]
  local name=$1 proxy=$2
  shift 2
  "$bin/proxy-export" "$proxy" -o "$out/$name.spx" -q
  check "$name: proxy-export .html" "$bin/proxy-export" "$proxy" -o "$out/$name.html" "$@" -q --report "$out/$name.report.json"
  check "$name: report schema" /usr/bin/python3 "$src/tests/cli/validate_json.py" "$src/schemas" \
    proxy-export-report.schema.json "$out/$name.report.json" >/dev/null
  check "$name: in the browser" node "$src/web/page-test.mjs" "$out/$name.html" "$out" "$name"
  local asset=() # the asset, and its one mesh when given
  [ "${1:-}" = --asset ] && asset=("$2")
  [ "${3:-}" = --mesh ] && asset+=("$4")
  check "$name: against the runtime" "$build/tests/page_check" "$out/$name.spx" "$out/$name.page.json" "$out/$name.html" \
    "${asset[@]}"
}
poses() {  # the example meshes of a generated sample folder, as --rest/--pose
  local dir=$1; shift
  echo --rest "$dir/rest.obj"
  for p in "$@"; do echo --pose "$dir/$p.obj"; done
}

page car "$build/tests/cli-out/car/a/asset.proxy.json" $(poses "$build/tests/cli-out/car/in" front rear side roof)
page barrel "$build/tests/cli-out/barrel/a/asset.proxy.json" $(poses "$build/tests/cli-out/barrel/in" dent squash top)
page car-morph "$ex/car-morph/car-morph.proxy.json" --manifest "$ex/car-morph/poses/poses.json" --up z
page rigged "$ex/rigged/rigged.proxy.json" --asset "$data/rigged-simple/RiggedSimple.glb"
page spheres-alone "$ex/rigged/rigged.proxy.json"
page arm "$ex/arm/arm.proxy.json" --asset "$ex/in/robot.glb" --mesh r_forearm
# Twice: the same bytes.
"$bin/proxy-export" "$ex/rigged/rigged.proxy.json" -o "$out/again.html" --asset "$data/rigged-simple/RiggedSimple.glb" -q
check "two runs differ" cmp -s "$out/rigged.html" "$out/again.html"

# Bad input: one error line, the documented exit code, no page left.
car=$build/tests/cli-out/car/a/asset.proxy.json
expect 1 "--asset.*no skin" "$out/x.html" -- "$bin/proxy-export" "$car" -o "$out/x.html" --asset "$data/rigged-simple/RiggedSimple.glb"
expect 2 "elephant-rigged.glb.*not the asset the proxy was made from" "$out/x.html" -- "$bin/proxy-export" \
  "$ex/rigged/rigged.proxy.json" -o "$out/x.html" --asset "$data/elephant/elephant-rigged.glb"
expect 1 "--up.*y or z" "$out/x.html" -- "$bin/proxy-export" "$car" -o "$out/x.html" --up x
expect 1 "--up.*\.html" "$out/x.spx" -- "$bin/proxy-export" "$car" -o "$out/x.spx" --up y
expect 1 "poses" "$out/x.html" -- "$bin/proxy-export" "$car" -o "$out/x.html" --rest "$build/tests/cli-out/car/in/rest.obj"

echo "page: $passed passed, $fail failed"
[ "$fail" -eq 0 ]
