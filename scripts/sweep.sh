#!/usr/bin/env bash
# Speed/accuracy sweep for one sample asset: the chain over a range of min radii, then a CSV
# and charts (SVG and PNG) of error against sphere count, error against runtime blend time,
# and precompute time against sphere count.
#   scripts/sweep.sh [car|barrel] [OUT_DIR]        (default: car, build/sweep/<asset>)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
asset=${1:-car}
out=${2:-$root/build/sweep/$asset}
bash "$root/scripts/setup.sh"
command -v gnuplot >/dev/null || { sudo=""; [ "$(id -u)" -eq 0 ] || sudo=sudo;
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends gnuplot-nox >/dev/null; }
bash "$root/scripts/build.sh" >/dev/null
bin=$root/build/release/apps
mkdir -p "$out"
"$bin/sample-gen" "$asset" -o "$out/in" -q
poses=$(ls "$out"/in/*.obj | grep -v '/rest.obj$')
pose_args=$(for p in $poses; do printf -- '--pose %s ' "$p"; done)
"$bin/sdf-build" "$out/in/rest.obj" -o "$out/rest.vdb" --resolution 128 -q --report "$out/sdf.json"
diag=$(python3 -c "import sys; sys.path.insert(0, '$root/scripts'); from summary import diagonal; print(diagonal('$out/in/rest.obj'))")

rows=()
for pct in 8 6 4.5 3.5 2.7 2 1.5 1.1 0.8; do
  r=$(python3 -c "print($diag * $pct / 100)")
  tag=r$pct
  echo "sweep: $asset min radius $pct% of the diagonal" >&2
  "$bin/sphere-pack" "$out/rest.vdb" --mesh "$out/in/rest.obj" --method greedy --min-radius "$r" -o "$out/$tag.spheres.json" -q \
    --report "$out/$tag.pack.json"
  # shellcheck disable=SC2086
  "$bin/pose-map" --rest "$out/in/rest.obj" $pose_args --spheres "$out/$tag.spheres.json" -o "$out/$tag.proxy.json" -q \
    --report "$out/$tag.posemap.json"
  # shellcheck disable=SC2086
  "$bin/proxy-eval" "$out/$tag.proxy.json" --rest "$out/in/rest.obj" $pose_args --blends 12 -q --report "$out/$tag.eval.json"
  rows+=("$pct $out/sdf.json $out/$tag.pack.json $out/$tag.posemap.json $out/$tag.eval.json")
done
python3 - "$out/sweep.csv" "${rows[@]}" <<'PY'
import json, sys
out = open(sys.argv[1], "w")
out.write("min_radius_pct,spheres,rest_median,rest_max,pose_median,pose_max,blend_median,blend_max,blend_us,precompute_s\n")
for row in sys.argv[2:]:
    pct, sdf, pack, posemap, ev = row.split()
    sdf, pack, posemap, ev = (json.load(open(f)) for f in (sdf, pack, posemap, ev))
    rest, poses = ev["poses"][0], ev["poses"][1:]
    pre = sdf["timings_s"]["total"] + pack["timings_s"]["total"] + posemap["timings_s"]["total"]
    out.write(f"{pct},{pack['sphere_count']},{rest['median']},{rest['max']},"
              f"{sorted(p['median'] for p in poses)[len(poses) // 2]},{max(p['max'] for p in poses)},"
              f"{ev['blends']['median']},{ev['blends']['max']},{ev['runtime']['blend_global_us_median']},{pre}\n")
PY
for term in svg png; do
  gnuplot <<GP
set terminal $([ $term = svg ] && echo "svg size 1500,480 dynamic" || echo "pngcairo size 1500,480")
set output "$out/sweep.$term"
set datafile separator ","
set key top right
set key font ",9"
set grid
set logscale x
set logscale y
set multiplot layout 1,3 title "$asset: speed and accuracy against sphere count (min radius swept, 128 voxels)"
set xlabel "spheres"; set ylabel "vertex-to-union error (m)"; set title "error"
plot "$out/sweep.csv" u 2:4 w lp t "rest max", "" u 2:6 w lp t "worst pose max", "" u 2:8 w lp t "blend max", \
     "" u 2:3 w lp dt 2 t "rest median", "" u 2:5 w lp dt 2 t "pose median", "" u 2:7 w lp dt 2 t "blend median"
set xlabel "global blend per frame (microseconds)"; set title "error against runtime cost"
plot "$out/sweep.csv" u 9:6 w lp t "worst pose max", "" u 9:5 w lp dt 2 t "pose median"
unset logscale y
set yrange [0:*]
set xlabel "spheres"; set ylabel "seconds"; set title "precompute (sdf-build + sphere-pack + pose-map)"
plot "$out/sweep.csv" u 2:10 w lp t "precompute"
unset multiplot
GP
done
column -s, -t "$out/sweep.csv"
echo "charts: $out/sweep.svg $out/sweep.png"
