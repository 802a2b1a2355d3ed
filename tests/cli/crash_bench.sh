#!/usr/bin/env bash
# crash-bench end to end: two proxies from the chain (sphere-pack --max-spheres), a short run,
# the JSON against its schema, the properties the host promises, and the error contract.
# usage: crash_bench.sh BUILD_DIR SOURCE_DIR OUT_DIR
set -euo pipefail
build=$1 src=$2 out=$3
rm -rf "$out" && mkdir -p "$out"
for n in 40 120; do
  make -s -C "$src/samples" BIN="$build/apps" OUT="$out" ASSET=car NAME=car-$n RES=64 QUIET=1 \
    PACK_FLAGS="--max-spheres $n" "$out/car-$n/car-$n.spx" >/dev/null
done
d=$out/car-40
poses=(--pose "$d/front.obj" --pose "$d/rear.obj" --pose "$d/side.obj" --pose "$d/roof.obj")
bench=$build/samples/crash-bench
"$bench" --rest "$d/rest.obj" "${poses[@]}" --proxy "$out/car-40/car-40.spx" --proxy "$out/car-120/car-120.spx" \
  --json "$out/crash.json" --seconds 2.5 --repeats 2 --seeds 2 --no-stability -q >"$out/table.txt"
/usr/bin/python3 "$src/tests/cli/validate_json.py" "$src/schemas" crash-bench.schema.json "$out/crash.json"
/usr/bin/python3 - "$out/crash.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
names = [c["name"] for c in d["configs"]]
assert names == ["compound-40", "sphereset-40", "compound-120", "sphereset-120", "triangle-mesh"], names
for c in d["configs"]:
    assert c["repeatable"], (c["name"], "timed runs must end in the monitored run's exact state")
    s = c["safety"]
    assert s["ground_tunnels"] == 0 and s["car_tunnels"] == 0, (c["name"], s)
    assert not s["energy_blew_up"], (c["name"], s)
    assert c["reblends"] > 0 and c["max_weight_moved"] > 0.1, (c["name"], "the crash must dent the cars")
    assert len(c["paths"]["cars"]) == d["scene"]["cars"]
base = d["configs"][-1]
assert base["spheres_per_car"] == 0 and abs(base["speedup"] - 1) < 1e-12
for c in d["configs"][:-1]:
    assert 0 < c["spheres_per_car"] <= int(c["name"].split("-")[1])
    assert c["safety"]["crashes"] == 2
    assert abs(c["speedup"] - base["total_ms"] / c["total_ms"]) < 1e-9 * c["speedup"]
    e = c["error"]
    assert len(e["cars"]) == d["scene"]["cars"] and len(e["times_s"]) > 0
    assert 0 < e["median_of_medians_m"] < 0.2 and e["max_m"] < 1.0, e["max_m"]
print("crash-bench JSON: properties hold")
PY

# Errors: one line naming the file, exit 2 (bad input) or 1 (usage), no JSON left behind.
check() {
  local code=$1 pattern=$2
  shift 2
  rm -f "$out/bad.json"
  set +e
  err=$("$@" --json "$out/bad.json" 2>&1 >/dev/null)
  got=$?
  set -e
  if [ "$got" != "$code" ] || ! grep -q -- "$pattern" <<<"$err" || [ "$(grep -c '^Error:' <<<"$err")" != 1 ] ||
     [ -e "$out/bad.json" ]; then
    echo "FAIL: $* -> exit $got (want $code): $err"
    exit 1
  fi
}
check 2 "missing.spx" "$bench" --rest "$d/rest.obj" "${poses[@]}" --proxy "$out/missing.spx"
head -c 100 "$out/car-40/car-40.spx" >"$out/cut.spx"
check 2 "cut.spx: cannot load" "$bench" --rest "$d/rest.obj" "${poses[@]}" --proxy "$out/cut.spx"
check 2 "car-40.spx: pose 1 is 'front'" "$bench" --rest "$d/rest.obj" --pose "$d/rear.obj" --pose "$d/front.obj" \
  --pose "$d/side.obj" --pose "$d/roof.obj" --proxy "$out/car-40/car-40.spx"
check 1 "repeats" "$bench" --rest "$d/rest.obj" "${poses[@]}" --proxy "$out/car-40/car-40.spx" --repeats 0
echo "crash-bench: all checks passed"
