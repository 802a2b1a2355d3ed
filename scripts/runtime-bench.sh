#!/usr/bin/env bash
# The runtime header's blends against a memcpy of the same bytes (Google Benchmark, medians of
# 5 repetitions), then a table: spheres blended per second and time relative to the copy.
#   scripts/runtime-bench.sh [OUT.json]        (default: build/runtime-bench.json)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/build/runtime-bench.json}
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" >/dev/null
"$root/build/release/bench/runtime-bench" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_out="$out" --benchmark_out_format=json --benchmark_min_time=0.05 >/dev/null
/usr/bin/python3 - "$out" <<'PY'
import json, sys
rows = {}
for b in json.load(open(sys.argv[1]))["benchmarks"]:
    if b.get("aggregate_name") != "median":
        continue
    kind = b["run_name"].split("/")[0].replace("BM_", "")
    rows.setdefault((int(b["spheres"]), int(b.get("examples", -1))), {})[kind] = b
print(f"{'spheres':>8} {'examples':>8} {'memcpy GB/s':>12} {'global/copy':>12} {'local/copy':>11} "
      f"{'xyzr global/copy':>17} {'normalized local/copy':>22}")
skin = {k: v for k, v in rows.items() if "Skin" in v}
for (n, e), r in sorted(rows.items()):
    if "Memcpy" not in r:
        continue
    copy = r["Memcpy"]["real_time"]
    ratio = lambda k: r[k]["real_time"] / copy
    print(f"{n:>8} {e:>8} {r['Memcpy']['bytes_per_second'] / 1e9:>12.1f} {ratio('BlendGlobal'):>11.1f}x "
          f"{ratio('BlendLocal'):>10.1f}x {ratio('BlendGlobalXyzr'):>16.2f}x {ratio('BlendLocalNormalized'):>21.2f}x")
print(f"\n{'spheres':>8} {'plain LBS Mspheres/s':>21} {'spx::skin Mspheres/s':>21} {'skin/LBS time':>14}")
for (n, _), r in sorted(skin.items()):
    lbs, sk = r["PlainLbs"], r["Skin"]
    print(f"{n:>8} {lbs['items_per_second'] / 1e6:>21.1f} {sk['items_per_second'] / 1e6:>21.1f} "
          f"{sk['real_time'] / lbs['real_time']:>13.2f}x")
PY
echo "raw: $out"
