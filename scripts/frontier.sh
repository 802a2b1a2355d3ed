#!/usr/bin/env bash
# The error-against-sphere-count frontier: cover selection against the greedy packing on the
# shared meshes and the car sample (bench/frontier_bench.cpp), then the chart and the table.
#   bash scripts/frontier.sh [OUT_DIR]     (default docs/; the JSON lands in build/frontier.json)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/docs}
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" >/dev/null
command -v gnuplot >/dev/null || { sudo=""; [ "$(id -u)" -eq 0 ] || sudo=sudo;
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends gnuplot-nox >/dev/null; }
json=$root/build/frontier.json
"$root/build/release/bench/frontier-bench" --data "$root/../shared/data" --json "$json" -q
mkdir -p "$out"
data=$root/build/frontier
rm -rf "$data" && mkdir -p "$data"
/usr/bin/python3 - "$json" "$data" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
for m in r["meshes"]:
    for method in ("cover", "greedy"):
        with open("%s/%s-%s.dat" % (sys.argv[2], m["mesh"], method), "w") as f:
            for row in m["rows"]:
                if row["method"] == method and row["mode"] == "budget":
                    f.write("%d %.4f %.4f\n" % (row["spheres"], row["median_pct"], row["max_pct"]))
print("| mesh | spheres | cover median / max % (s) | greedy median / max % (s) |")
print("|---|---|---|---|")
for m in r["meshes"]:
    rows = {(x["method"], x["mode"], x["asked"]): x for x in m["rows"]}
    for key in sorted({(x["mode"], x["asked"]) for x in m["rows"]}):
        c, g = rows[("cover",) + key], rows[("greedy",) + key]
        label = "%d" % key[1] if key[0] == "budget" else "tol %g%%" % key[1]
        print("| %s | %s | %.2f / %.2f (%d, %.1f s) | %.2f / %.2f (%d, %.1f s) |" % (
            m["mesh"], label, c["median_pct"], c["max_pct"], c["spheres"], c["seconds"],
            g["median_pct"], g["max_pct"], g["spheres"], g["seconds"]))
over = max(x["overshoot_pct"] for m in r["meshes"] for x in m["rows"])
print("\nlargest overshoot over every row: %.2g %% of the diagonal" % over)
PY
meshes=$(/usr/bin/python3 -c "import json,sys; print(' '.join(m['mesh'] for m in json.load(open(sys.argv[1]))['meshes']))" "$json")
for term in svg png; do
  plot="" sep=""
  i=1
  for m in $meshes; do
    plot="$plot$sep'$data/$m-cover.dat' using 1:3 with linespoints lw 2 lc $i pt 7 title '$m cover', '$data/$m-greedy.dat' using 1:3 with linespoints lw 1 dt 2 lc $i pt 6 title '$m greedy'"
    sep=", "
    i=$((i + 1))
  done
  gnuplot <<GP
set terminal $([ $term = svg ] && echo "svg size 900,600 dynamic" || echo "pngcairo size 900,600")
set output "$out/frontier.$term"
set logscale x 2
set xlabel "spheres"
set ylabel "max vertex error (% of the bounding-box diagonal)"
set title "Max error against sphere count: cover (solid), greedy (dashed)"
set key outside right
set grid
plot $plot
GP
done
echo "chart: $out/frontier.svg (and .png); data: $json"
