#!/usr/bin/env bash
# The main job: install what is missing, build, run the whole chain on the car sample
# (and the barrel, and the car again from its morph-target glTF through pose-extract), and print
# a short report. Outputs stay in build/samples/<asset>/.
#   scripts/demo.sh [car|barrel|car-morph|barrel-morph ...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" >/dev/null
assets=("$@")
[ ${#assets[@]} -gt 0 ] || assets=(car barrel car-morph)
m="make -s -C $root/samples BIN=$root/build/release/apps OUT=$root/build/samples QUIET=1"  # summary.py says it all
for asset in "${assets[@]}"; do
  started=$(date +%s)
  case $asset in
    *-morph)  # sample-gen's glTF with the poses as morph targets, through pose-extract
      base=${asset%-morph}
      $m ASSET="$base" >/dev/null
      $m NAME="$asset" ASSET_FILE="$root/build/samples/$base/$asset.glb" EXTRACT_FLAGS=--morph-targets PAGE_FLAGS="--up z" ;;
    *) $m ASSET="$asset" ;;
  esac
  python3 "$root/scripts/summary.py" "$root/build/samples/$asset" --ran-since "$started"
done
