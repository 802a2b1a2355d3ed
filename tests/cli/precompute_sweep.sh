#!/usr/bin/env bash
# precompute-bench's frame sweep end to end, small (2 and 4 frames of both clips, 3 repeats):
# every run is in the JSON, each count's median and its ratio to the first count follow from
# them (the median of the per-repeat ratios: the counts take turns within a repeat), each run is
# followed by one from a --cache written before (the bench fails unless it writes the same proxy;
# `--no-sweep-cache` leaves them out), `--sweep-only` runs nothing else and -q prints nothing.
# `--frames` with no counts skips the sweep; a count of 0 is a usage error.
# usage: precompute_sweep.sh BUILD_DIR DATA_DIR OUT_DIR
set -euo pipefail
build=$1 data=$2 out=$3
rm -rf "$out" && mkdir -p "$out"
"$build/bench/precompute-bench" --data "$data" --json "$out/bench.json" --repeats 3 --frames 2 4 --sweep-only \
  --work "$out/work" -q 2> "$out/quiet.err"
[ ! -s "$out/quiet.err" ] || { echo "-q printed:"; cat "$out/quiet.err"; exit 1; }
/usr/bin/python3 - "$out/bench.json" <<'PY'
import json, statistics, sys
d = json.load(open(sys.argv[1]))
assert d["repeats"] == 3 and "routes" not in d and "sdf" not in d and "chains" not in d, list(d)
sweeps = d["frame_sweeps"]
assert [s["clip"] for s in sweeps] == ["elephant-walk", "RiggedSimple"], sweeps
for s in sweeps:
    rows = s["rows"]
    assert [r["frames"] for r in rows] == [2, 4] and s["triangles"] > 0, s
    first = rows[0]["pose_map_runs_s"]
    for r in rows:
        runs = r["pose_map_runs_s"]
        assert r["runs"] == 3 and len(runs) == 3 and min(runs) > 0, r
        assert r["pose_map_s"] == statistics.median(runs), r
        assert abs(r["over_first"] - statistics.median(b / a for a, b in zip(first, runs))) < 1e-12, r
        assert r["spheres"] > 0 and r["peak_gib"] > 0, r
        cached = r["cached_runs_s"]  # each run followed by one from the cache, the same proxy
        assert len(cached) == 3 and min(cached) > 0 and r["cached_s"] == statistics.median(cached), r
        assert abs(r["cached_over_first"] - statistics.median(
            b / a for a, b in zip(rows[0]["cached_runs_s"], cached))) < 1e-12, r
    assert rows[0]["over_first"] == 1.0 and rows[0]["cached_over_first"] == 1.0, rows[0]
print("precompute-bench sweep: " + ", ".join(
    "%s %.2fx at %d frames" % (s["clip"], s["rows"][1]["over_first"], s["rows"][1]["frames"]) for s in sweeps))
PY
"$build/bench/precompute-bench" --data "$data" --json "$out/plain.json" --repeats 1 --frames 2 --sweep-only \
  --no-sweep-cache --work "$out/work" -q
/usr/bin/python3 -c "
import json,sys
rows = [r for s in json.load(open(sys.argv[1]))['frame_sweeps'] for r in s['rows']]
assert rows and not any('cached_s' in r for r in rows), rows" "$out/plain.json"
"$build/bench/precompute-bench" --data "$data" --json "$out/none.json" --sweep-only --frames -q
/usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['frame_sweeps'] == [], d" "$out/none.json"
rc=0
"$build/bench/precompute-bench" --data "$data" --json "$out/zero.json" --sweep-only --frames 4 0 -q 2> "$out/zero.err" || rc=$?
[ "$rc" -eq 1 ] && grep -q -- '--frames: a frame count must be at least 1' "$out/zero.err" && [ ! -e "$out/zero.json" ] ||
  { echo "--frames 4 0: exit $rc, $(cat "$out/zero.err")"; exit 1; }
