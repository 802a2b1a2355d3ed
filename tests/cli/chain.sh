#!/usr/bin/env bash
# End-to-end: the four tools on one asset, twice (on every core, then with --threads 1), with
# byte-identical outputs, schema-valid JSON, a loadable .spx, and figures that make sense.
# usage: chain.sh BUILD_DIR SCHEMA_DIR OUT_DIR ASSET [REST POSE...]
#   ASSET "car"/"barrel" generates the sample; otherwise REST and POSEs are mesh files.
set -euo pipefail
build=$1 schemas=$2 out=$3 asset=$4
shift 4
bin=$build/apps
rm -rf "$out" && mkdir -p "$out"
if [ "$asset" = car ] || [ "$asset" = barrel ]; then
  "$bin/sample-gen" "$asset" -o "$out/in" -q
  rest=$out/in/rest.obj
  poses=$(ls "$out"/in/*.obj | grep -v '/rest.obj$')
else
  rest=$1
  shift
  poses="$*"
fi
pose_args=()
for p in $poses; do pose_args+=(--pose "$p"); done

run_chain() {  # $1: output folder, then options every tool is given
  local o=$1
  shift
  mkdir -p "$o"
  "$bin/sdf-build" "$rest" -o "$o/rest.vdb" --resolution 96 -q --report "$o/sdf.report.json" "$@"
  "$bin/sphere-pack" "$o/rest.vdb" --mesh "$rest" -o "$o/rest.spheres.json" -q --report "$o/pack.report.json" "$@"
  "$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$o/rest.spheres.json" -o "$o/asset.proxy.json" -q \
    --report "$o/posemap.report.json" "$@"
  "$bin/proxy-eval" "$o/asset.proxy.json" --rest "$rest" "${pose_args[@]}" --blends 4 --colors "$o/errors.glb" -q \
    --report "$o/eval.report.json" "$@"
  for ext in spx json glb ply; do
    "$bin/proxy-export" "$o/asset.proxy.json" -o "$o/proxy.$ext" -q --report "$o/export-$ext.report.json" "$@"
  done
}
# Twice into the same folder (outputs name their inputs' paths), the second time on one thread:
# the bytes must not change, whatever the threads.
run_chain "$out/a" --threads 1
mv "$out/a" "$out/b"
run_chain "$out/a"

fail=0
for f in rest.vdb rest.spheres.json asset.proxy.json proxy.spx proxy.json proxy.glb proxy.ply errors.glb; do
  if ! cmp -s "$out/a/$f" "$out/b/$f"; then
    echo "FAIL: $f differs between a run on one thread and one on every core"
    fail=1
  fi
done
# Each report says the threads it could use.
for r in sdf pack posemap eval export-spx; do
  t=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['threads'])" "$out/b/$r.report.json")
  [ "$t" = 1 ] || { echo "FAIL: $r.report.json of the run with --threads 1 says threads $t"; fail=1; }
done
[ -s "$out/a/proxy.spx" ] || { echo "FAIL: no .spx"; fail=1; }

v() { /usr/bin/python3 "$(dirname "$0")/validate_json.py" "$schemas" "$@" >/dev/null || { echo "FAIL: schema $*"; fail=1; }; }
v spheres.schema.json "$out/a/rest.spheres.json"
v proxy.schema.json "$out/a/asset.proxy.json"
v proxy-plain.schema.json "$out/a/proxy.json"
v sdf-build-report.schema.json "$out/a/sdf.report.json"
v sphere-pack-report.schema.json "$out/a/pack.report.json"
v pose-map-report.schema.json "$out/a/posemap.report.json"
v proxy-eval-report.schema.json "$out/a/eval.report.json"
for ext in spx json glb ply; do v proxy-export-report.schema.json "$out/a/export-$ext.report.json"; done
# The validator really checks: a proxy without sites must be rejected.
/usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1])); del d['sites']; json.dump(d, open(sys.argv[2],'w'))" \
  "$out/a/proxy.json" "$out/a/broken.json"
v proxy-plain.schema.json "$out/a/broken.json" --expect-invalid

# The runtime demo loads the file and prints one line per sphere in the rest pose.
count=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['sphere_count'])" "$out/a/posemap.report.json")
lines=$("$build/samples/runtime-demo" "$out/a/proxy.spx" | grep -vc '^#')
[ "$lines" = "$count" ] || { echo "FAIL: runtime-demo printed $lines spheres, expected $count"; fail=1; }

# proxy-eval and pose-map measure the same thing the same way.
/usr/bin/python3 - "$out/a/posemap.report.json" "$out/a/eval.report.json" <<'PY' || fail=1
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
for p, q in zip(a["poses"], b["poses"]):
    if abs(p["error"]["max"] - q["max"]) > 1e-9 or abs(p["error"]["median"] - q["median"]) > 1e-9:
        print("FAIL: pose-map and proxy-eval disagree on", p["name"]); sys.exit(1)
PY

# Figures: every pose has an error figure; the rest pose's max error is below 5% of the diagonal.
/usr/bin/python3 - "$out/a/posemap.report.json" "$out/a/sdf.report.json" <<'PY' || fail=1
import json, sys
r = json.load(open(sys.argv[1]))
g = json.load(open(sys.argv[2]))
dims = g["grid"]["dims"]; h = g["grid"]["voxel_size"]
diag = h * (sum(d * d for d in dims)) ** 0.5
rest = r["poses"][0]["error"]
for p in r["poses"]:
    print(f"{p['name']:>12}: median {p['error']['median']:.4g} max {p['error']['max']:.4g} outside {len(p['outside'])}")
if not rest["max"] < 0.05 * diag:
    print("FAIL: rest max error", rest["max"], "is not below 5% of", diag); sys.exit(1)
PY
if [ $fail = 0 ]; then echo "1 passed, 0 failed"; else echo "0 passed, 1 failed"; fi
exit $fail
