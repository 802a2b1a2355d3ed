#!/usr/bin/env bash
# Accuracy at the sphere count the tolerance picks (1% of the diagonal by default), before and
# after gap filling, for the car sample and the shared elephant (rest + 4 poses).
#   scripts/accuracy.sh [TOLERANCE]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
tol=${1:-1%}
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" >/dev/null
bin=$root/build/release/apps
out=$root/build/accuracy
mkdir -p "$out"
"$bin/sample-gen" car -o "$out/car" -q
data=$root/../shared/data/elephant
run() {  # name resolution rest poses...
  local name=$1 res=$2 rest=$3
  shift 3
  local args=()
  for p in "$@"; do args+=(--pose "$p"); done
  "$bin/sdf-build" "$rest" -o "$out/$name.vdb" --resolution "$res" -q
  "$bin/sphere-pack" "$out/$name.vdb" --mesh "$rest" --method greedy --tolerance "$tol" -o "$out/$name.spheres.json" -q \
    --report "$out/$name.pack.json"
  for mode in plain fill; do
    local flag=()
    [ $mode = fill ] && flag=(--fill-gaps)
    "$bin/pose-map" --rest "$rest" "${args[@]}" --spheres "$out/$name.spheres.json" "${flag[@]}" \
      -o "$out/$name.$mode.proxy.json" -q --report "$out/$name.$mode.posemap.json"
    "$bin/proxy-eval" "$out/$name.$mode.proxy.json" --rest "$rest" "${args[@]}" --blends 12 -q \
      --report "$out/$name.$mode.eval.json"
  done
  python3 - "$name" "$out/$name.pack.json" "$out/$name.plain.eval.json" "$out/$name.fill.eval.json" <<'PY'
import json, sys
name, pack, plain, fill = sys.argv[1], *(json.load(open(f)) for f in sys.argv[2:])
t = pack["tolerance"]
print(f"\n{name}: tolerance {t['target']:.4g} -> {plain['sphere_count']} spheres (rest max {t['max_error']:.4g}); "
      f"with gap filling {fill['sphere_count']} spheres")
print(f"{'':>10} {'before: median':>15} {'max':>8} {'after: median':>14} {'max':>8} {'max/rest':>9}")
rest_after = fill["poses"][0]["max"]
rows = [(p["name"], p, q) for p, q in zip(plain["poses"], fill["poses"])] + [("blends", plain["blends"], fill["blends"])]
for label, p, q in rows:
    print(f"{label:>10} {p['median']:15.4g} {p['max']:8.4g} {q['median']:14.4g} {q['max']:8.4g} {q['max'] / rest_after:9.2f}")
PY
}
run car 128 "$out/car/rest.obj" "$out/car/front.obj" "$out/car/rear.obj" "$out/car/side.obj" "$out/car/roof.obj"
if [ -d "$data" ]; then
  run elephant 192 "$data/rest.obj" "$data"/pose-*.obj
fi
