#!/usr/bin/env bash
# The budget cells' spread over surface-sample draws: frontier-bench once per seed (the cover's
# samples are drawn at random, so one run is one draw), then per mesh and budget the least and
# largest median and max, the mean max, and any overshoot.
#   bash scripts/frontier-spread.sh [SEEDS...]     (default 1 2 3 4 5; JSON in build/frontier-spread/)
#   BUDGETS="32 64 128" MESHES="bunny knight fertility elephant car" RESOLUTION=128 override the cells.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
seeds=("$@")
[ ${#seeds[@]} -gt 0 ] || seeds=(1 2 3 4 5)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" >/dev/null
dir=$root/build/frontier-spread
rm -rf "$dir" && mkdir -p "$dir"
for s in "${seeds[@]}"; do
  # shellcheck disable=SC2086
  "$root/build/release/bench/frontier-bench" --data "$root/../shared/data" --resolution "${RESOLUTION:-128}" \
    --budgets ${BUDGETS:-32 64 128} --tolerances 5 --mesh ${MESHES:-bunny knight fertility elephant car} \
    --seed "$s" --json "$dir/seed-$s.json" -q
done
/usr/bin/python3 - "$dir"/seed-*.json <<'PY'
import json, statistics, sys
cells, order = {}, []
for path in sys.argv[1:]:
    r = json.load(open(path))
    for m in r["meshes"]:
        for x in m["rows"]:
            if x["method"] == "cover" and x["mode"] == "budget":
                key = (m["mesh"], int(x["asked"]))
                if key not in cells:
                    order.append(key)
                cells.setdefault(key, []).append(x)
print("| mesh | spheres | draws | median % (least-largest) | max % (least-largest) | mean max % | overshoot % |")
print("|---|---|---|---|---|---|---|")
for key in order:
    rows = cells[key]
    med = [x["median_pct"] for x in rows]
    mx = [x["max_pct"] for x in rows]
    print("| %s | %d | %d | %.2f-%.2f | %.2f-%.2f | %.2f | %.2g |" % (
        key[0], key[1], len(rows), min(med), max(med), min(mx), max(mx), statistics.mean(mx),
        max(x["overshoot_pct"] for x in rows)))
PY
