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
    rows.setdefault((int(b["spheres"]), int(b["examples"])), {})[kind] = b
print(f"{'spheres':>8} {'examples':>8} {'global Msph/s':>14} {'local Msph/s':>13} {'memcpy GB/s':>12} "
      f"{'global/copy':>12} {'local/copy':>11}")
for (n, e), r in sorted(rows.items()):
    copy = r["Memcpy"]["real_time"]
    print(f"{n:>8} {e:>8} {r['BlendGlobal']['items_per_second'] / 1e6:>14.1f} {r['BlendLocal']['items_per_second'] / 1e6:>13.1f} "
          f"{r['Memcpy']['bytes_per_second'] / 1e9:>12.1f} {r['BlendGlobal']['real_time'] / copy:>11.1f}x "
          f"{r['BlendLocal']['real_time'] / copy:>10.1f}x")
PY
echo "raw: $out"
