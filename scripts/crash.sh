#!/usr/bin/env bash
# The crash benchmark (paper, Table 1 and Figure 5): car proxies at 320, 114 and 66 spheres from
# the chain (sphere-pack --max-spheres), then crash-bench in one process, then charts.
#   scripts/crash.sh [OUT_DIR] [crash-bench options...]
# (default: build/crash; options default to --repeats 5 --seeds 5)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/build/crash}
shift || true
mkdir -p "$out" && out=$(cd "$out" && pwd)  # make runs in samples/: relative paths would land there
options=("$@")
[ ${#options[@]} -gt 0 ] || options=(--repeats 5 --seeds 5)
bash "$root/scripts/setup.sh"
command -v gnuplot >/dev/null || { sudo=""; [ "$(id -u)" -eq 0 ] || sudo=sudo;
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends gnuplot-nox >/dev/null; }
bash "$root/scripts/build.sh" >/dev/null
mkdir -p "$out"
proxies=()
for n in 320 114 66; do
  make -s -C "$root/samples" BIN="$root/build/release/apps" OUT="$out" ASSET=car NAME=car-$n QUIET=1 \
    PACK_FLAGS="--max-spheres $n" "$out/car-$n/car-$n.spx" >/dev/null
  proxies+=(--proxy "$out/car-$n/car-$n.spx")
done
d=$out/car-320
"$root/build/release/samples/crash-bench" --rest "$d/rest.obj" --pose "$d/front.obj" --pose "$d/rear.obj" \
  --pose "$d/side.obj" --pose "$d/roof.obj" "${proxies[@]}" --json "$out/crash.json" "${options[@]}" | tee "$out/table.txt"

# Figure 5: median and max error over time, one line per car, one column per proxy (the
# sphere-set runs); and the speed/accuracy trade-off for both proxy kinds.
/usr/bin/python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
d = json.load(open(out + "/crash.json"))
proxies = [c for c in d["configs"] if c["spheres_per_car"] > 0]
for c in proxies:
    e = c["error"]
    with open(f"{out}/error-{c['name']}.dat", "w") as f:
        for i, t in enumerate(e["times_s"]):
            f.write(f"{t} " + " ".join(f"{car['median'][i]} {car['max'][i]}" for car in e["cars"]) + "\n")
for kind in ("compound", "sphereset"):
    with open(f"{out}/tradeoff-{kind}.dat", "w") as f:
        for c in proxies:
            if c["name"].startswith(kind + "-"):
                f.write(f"{c['spheres_per_car']} {c['speedup']} {c['error']['median_of_medians_m']} {c['error']['max_m']}\n")
open(out + "/columns.txt", "w").write(" ".join(c["name"] for c in proxies if c["name"].startswith("sphereset-")) + "\n")
open(out + "/cars.txt", "w").write(str(d["scene"]["cars"]) + "\n")
PY
cols=$(cat "$out/columns.txt")
cars=$(cat "$out/cars.txt")
for term in svg png; do
  gnuplot <<GP
set terminal $([ $term = svg ] && echo "svg size 1500,700 dynamic" || echo "pngcairo size 1500,700")
cd "$out"  # file names in the SVG's titles stay relative
set output "crash-error.$term"
set key off
set grid
set format y "%.4f"
set multiplot layout 2,3 title "Car crash (first seed): vertex-to-union error over time, one colour per car (car 5.25 m long)"
do for [row=1:2] {
  do for [n in "$cols"] {
    set title sprintf("%s spheres per car: %s", n[11:], row == 1 ? "median" : "max")
    set xlabel "time (s)"; set ylabel "error (m)"
    plot for [car=1:$cars] "error-".n.".dat" u 1:(column(2*car + row - 1)) w l lw 1.2
  }
}
unset multiplot
GP
  gnuplot <<GP
set terminal $([ $term = svg ] && echo "svg size 760,500 dynamic" || echo "pngcairo size 760,500")
cd "$out"
set output "crash-tradeoff.$term"
set grid
set key top left
set xlabel "median vertex-to-union error over the crash (m)"; set ylabel "speedup over the triangle mesh (x)"
set title "Speed against accuracy: sphere proxies vs 1536-triangle GImpact meshes"
set offsets 0.004, 0.006, 3, 3
set yrange [0:*]
plot "tradeoff-sphereset.dat" u 3:2 w lp pt 7 t "sphere-set narrow phase", \
     "tradeoff-compound.dat" u 3:2 w lp pt 5 dt 2 t "Bullet compound", \
     "tradeoff-sphereset.dat" u 3:2:(sprintf("%d", \$1)) w labels offset 0,1 notitle, \
     "tradeoff-compound.dat" u 3:2:(sprintf("%d", \$1)) w labels offset 0,-1 notitle
GP
done
echo "charts: $out/crash-error.svg $out/crash-tradeoff.svg (and .png)"
