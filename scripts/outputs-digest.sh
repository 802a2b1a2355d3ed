#!/usr/bin/env bash
# Runs every tool over the samples and the shared meshes and prints one digest line per output
# file (reports without their timings). Run it before and after a change that must not change
# outputs, and diff the two listings:
#   bash scripts/outputs-digest.sh [BUILD_DIR] > before.txt ... > after.txt; diff before.txt after.txt
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build/release}" && pwd)
bin=$build/apps data=$root/../shared/data
out=$build/outputs-digest
rm -rf "$out" && mkdir -p "$out"
run() {  # NAME REST POSES... : the whole chain, with and without --mesh, every export
  local name=$1 rest=$2 d=$out/$1
  shift 2
  mkdir -p "$d"
  local poses=()
  for p in "$@"; do poses+=(--pose "$p"); done
  "$bin/sdf-build" "$rest" -o "$d/rest.vdb" --resolution 64 -q --report "$d/sdf.r.json"
  "$bin/sphere-pack" "$d/rest.vdb" --mesh "$rest" -o "$d/mesh.spheres.json" -q --report "$d/pack.r.json"
  "$bin/sphere-pack" "$d/rest.vdb" -o "$d/field.spheres.json" --method greedy --max-spheres 40 -q --report "$d/packf.r.json"
  "$bin/sphere-pack" "$d/rest.vdb" --mesh "$rest" --tolerance 2% -o "$d/tol.spheres.json" -q --report "$d/packt.r.json"
  if [ $# -gt 0 ]; then
    "$bin/pose-map" --rest "$rest" "${poses[@]}" --spheres "$d/mesh.spheres.json" -o "$d/p.proxy.json" -q --report "$d/map.r.json"
    "$bin/pose-map" --rest "$rest" "${poses[@]}" --spheres "$d/tol.spheres.json" -o "$d/f.proxy.json" --fill-gaps -q \
      --report "$d/fill.r.json"
    for ext in spx json glb ply; do "$bin/proxy-export" "$d/p.proxy.json" -o "$d/p.$ext" -q; done
    "$bin/proxy-export" "$d/p.proxy.json" -o "$d/colors.glb" --rest "$rest" "${poses[@]}" -q
    "$bin/proxy-eval" "$d/p.proxy.json" --rest "$rest" "${poses[@]}" --colors "$d/eval.ply" -q --report "$d/eval.r.json"
  fi
}
"$bin/sample-gen" car -o "$out/car-in" -q
"$bin/sample-gen" barrel -o "$out/barrel-in" -q
run car "$out/car-in/rest.obj" "$out"/car-in/{front,rear,side,roof}.obj
run barrel "$out/barrel-in/rest.obj" "$out"/barrel-in/{dent,squash,top}.obj
if [ -f "$data/README.md" ]; then
  for set in cube cylinder elephant; do run "$set" "$data/$set/rest.obj" "$data/$set"/pose-*.obj; done
  run hemisphere "$data/broken/hemisphere.obj"
  run bunny "$data/static/bunny.off"
fi
cd "$out"
for f in $(find . -type f | LC_ALL=C sort); do
  case $f in
    *.r.json) echo "$(/usr/bin/python3 -c "
import json,sys
r=json.load(open(sys.argv[1]))
def strip(x):
    if isinstance(x, dict): return {k: strip(v) for k, v in x.items() if k not in ('timings_s', 'runtime')}
    if isinstance(x, list): return [strip(v) for v in x]
    return x
print(json.dumps(strip(r), sort_keys=True))" "$f" | md5sum | cut -c1-32)  $f" ;;
    *) echo "$(md5sum <"$f" | cut -c1-32)  $f" ;;
  esac
done
