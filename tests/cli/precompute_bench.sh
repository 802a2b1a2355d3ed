#!/usr/bin/env bash
# precompute-bench's SDF pairs end to end, small (the armadillo at 32 cells, 3 pairs): every pair
# is in the JSON, the medians and the least pair follow from them, and our field is what the
# README claims beside OpenVDB's (no sign error, under half a voxel from the exact distance).
# usage: precompute_bench.sh BUILD_DIR DATA_DIR OUT_DIR
set -euo pipefail
build=$1 data=$2 out=$3
rm -rf "$out" && mkdir -p "$out"
"$build/bench/precompute-bench" --data "$data" --json "$out/bench.json" --repeats 3 --resolution 32 \
  --no-routes --no-chains -q
/usr/bin/python3 - "$out/bench.json" <<'PY'
import json, statistics, sys
d = json.load(open(sys.argv[1]))
assert d["repeats"] == 3 and len(d["sdf"]) == 1, d
c = d["sdf"][0]
assert c["mesh"] == "armadillo" and c["resolution"] == 32, c
ours, base = c["sdf_runs_s"], c["openvdb_filled_runs_s"]
assert len(ours) == 3 and len(base) == 3 and min(ours + base) > 0, (ours, base)
assert c["sdf_s"] == statistics.median(ours) and c["openvdb_filled_s"] == statistics.median(base), c
assert abs(c["least_pair_speedup"] - min(b / o for o, b in zip(ours, base))) < 1e-12, c
assert abs(c["speedup_vs_openvdb"] - c["openvdb_filled_s"] / c["sdf_s"]) < 1e-12, c
exact = c["against_exact"]
assert exact["sampled_voxels"] > 1000 and exact["near_surface_voxels"] > 1000, exact
assert exact["ours_sign_errors"] == 0 and exact["near_surface_sign_errors"] == 0, exact
assert exact["ours_max_error_voxels"] < 0.5, exact
print(f"precompute-bench: 3 pairs, least {c['least_pair_speedup']:.2f}x, ours max "
      f"{exact['ours_max_error_voxels']:.3f} voxels")
PY
