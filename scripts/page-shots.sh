#!/usr/bin/env bash
# The proxy page as the README shows it: the demo's car, barrel and morph-target car, and the
# rigged elephant's walk (every 10th frame of its clip through the chain, skinned in its asset),
# each page made by samples/Makefile, opened by the browser test (web/page-test.mjs: slider,
# brush, scrubber, play, no console error), checked against the runtime header
# (tests/page_check), its screenshots copied to docs/page/.
#   scripts/page-shots.sh    (after scripts/build.sh; runs scripts/demo.sh's chain for what is missing)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build/release out=$root/build/samples shots=$root/docs/page
data=$(cd "$root/../shared/data" && pwd)
m="make -s -C $root/samples BIN=$build/apps OUT=$out QUIET=1"
$m ASSET=car >/dev/null
$m ASSET=barrel >/dev/null
$m NAME=car-morph ASSET_FILE="$out/car/car-morph.glb" EXTRACT_FLAGS=--morph-targets PAGE_FLAGS="--up z" >/dev/null
$m NAME=elephant-walk ASSET_FILE="$data/elephant/elephant-rigged.glb" EXTRACT_FLAGS="--animation 0 --every 10" >/dev/null
mkdir -p "$shots"
for name in car barrel car-morph elephant-walk; do
  d=$out/$name
  node "$root/web/page-test.mjs" "$d/$name.html" "$d" "$name"
  asset=""
  [ "$name" = elephant-walk ] && asset=$data/elephant/elephant-rigged.glb
  "$build/tests/page_check" "$d/$name.spx" "$d/$name.page.json" "$d/$name.html" $asset | tail -1
  cp "$d/$name"-*.png "$shots/"  # after a slider, a dent or the scrubber
done
ls -l "$shots"
