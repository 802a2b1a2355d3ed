#!/usr/bin/env bash
# The main job: install what is missing, build, run the whole chain on the car sample
# (and the barrel), and print a short report. Outputs stay in build/samples/<asset>/.
#   scripts/demo.sh [car|barrel ...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" >/dev/null
assets=("$@")
[ ${#assets[@]} -gt 0 ] || assets=(car barrel)
for asset in "${assets[@]}"; do
  make -s -C "$root/samples" ASSET="$asset" BIN="$root/build/release/apps" OUT="$root/build/samples"
  python3 "$root/scripts/summary.py" "$root/build/samples/$asset"
done
