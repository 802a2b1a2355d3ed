#!/usr/bin/env bash
# Precompute speed: every stage on real meshes against its baseline (bench/precompute_bench.cpp),
# the default route against the paper's, and pose-map over more and more frames of a clip; then
# the tables and the chart of time against frames and against triangles.
#   bash scripts/precompute.sh [OUT_DIR] [precompute-bench options...]
#   (default docs/; the JSON lands in build/precompute.json)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$root/docs}
shift || true
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" >/dev/null
command -v gnuplot >/dev/null || { sudo=""; [ "$(id -u)" -eq 0 ] || sudo=sudo;
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends gnuplot-nox >/dev/null; }
json=$root/build/precompute.json
"$root/build/release/bench/precompute-bench" --data "$root/../shared/data" --json "$json" "$@"
mkdir -p "$out"
data=$root/build/precompute
rm -rf "$data" && mkdir -p "$data"
/usr/bin/python3 - "$json" "$data" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
d = sys.argv[2]
if r.get("sdf"):
    print("| cells | voxels | ours | OpenVDB filled | speedup (medians) | least speedup of a pair | ours max / mean error (voxels) |")
    print("|---|---|---|---|---|---|---|")
for c in r.get("sdf", []):
    print("| %d | %.2f M | %.2f s | %.2f s | %.2fx | %.2fx | %.2f / %.3f |" % (
        c["resolution"], c["voxels"] / 1e6, c["sdf_s"], c["openvdb_filled_s"], c["speedup_vs_openvdb"],
        c.get("least_pair_speedup", c["speedup_vs_openvdb"]), c["against_exact"]["ours_max_error_voxels"],
        c["against_exact"]["ours_mean_error_voxels"]))
if r.get("routes"):
    print("\n| asset | triangles | poses | paper route: sdf + pack + pose-map (spheres) | default route (spheres) | default / paper | default from its --cache | cached / paper | peak memory paper / default |")
    print("|---|---|---|---|---|---|---|---|---|")
    with open(d + "/routes.dat", "w") as f:
        for x in r["routes"]:
            p, q, c = x["paper"], x["default"], x["cached"]
            print("| %s | %d | %d | %.2f + %.2f + %.2f = %.2f s (%d) | %.2f + %.2f + %.2f = %.2f s (%d) | %.2fx | %.2f + %.2f + %.2f = %.2f s | %.2fx | %.2f / %.2f GiB |" % (
                x["mesh"], x["triangles"], x["poses"], p["sdf_s"], p["pack_s"], p["pose_map_s"], p["total_s"], p["spheres"],
                q["sdf_s"], q["pack_s"], q["pose_map_s"], q["total_s"], q["spheres"], x["default_over_paper"],
                c["sdf_s"], c["pack_s"], c["pose_map_s"], c["total_s"], x["cached_over_paper"], p["peak_gib"], q["peak_gib"]))
            f.write("%d %.4f %.4f \"%s\"\n" % (x["triangles"], p["total_s"], q["total_s"], x["mesh"]))
b = r.get("batch")
if b:
    print("\nA batch of %d default routes (%s), the ways in turn:\n" % (len(b["chains"]), ", ".join(b["chains"])))
    print("| way | batch time | against one at a time | most memory of one process |")
    print("|---|---|---|---|")
    said = {"one_at_a_time": "one at a time, every core", "two_at_a_time_one_thread_each": "two at a time, --threads 1 each",
            "two_at_a_time_every_core_each": "two at a time, every core each"}
    for w in b["ways"]:
        print("| %s | %.2f s | %.2fx | %.2f GiB |" % (said.get(w["way"], w["way"]), w["seconds"], w["over_first"], w["peak_gib"]))
for s in r.get("frame_sweeps", []):
    print("\n%s (%d triangles): pose-map at the defaults\n" % (s["clip"], s["triangles"]))
    cached = all("cached_s" in row for row in s["rows"])
    print("| frames | time | against the first row | peak memory | spheres |" + (" from the cache | against its first row |" if cached else ""))
    print("|---|---|---|---|---|" + ("---|---|" if cached else ""))
    with open("%s/%s.dat" % (d, s["clip"]), "w") as f:
        for row in s["rows"]:
            print("| %d | %.2f s%s | %.2fx | %.2f GiB | %d |" % (row["frames"], row["pose_map_s"],
                  "" if row["runs"] > 1 else " (1 run)", row["over_first"], row["peak_gib"], row["spheres"]) +
                  (" %.2f s | %.2fx |" % (row["cached_s"], row["cached_over_first"]) if cached else ""))
            f.write("%d %.4f %.4f\n" % (row["frames"], row["pose_map_s"], row["peak_gib"]))
for c in r.get("dense", []):
    print("\n%s (%d triangles, %d vertices): sphere-pack, the cover on spaced vertices against every vertex's\n" % (
        c["mesh"], c["triangles"], c["vertices"]))
    print("| mode | spaced: time, memory, spheres, max / median error, samples covered | every vertex: the same | every / spaced time |")
    print("|---|---|---|---|")
    for row in c["rows"]:
        cell = lambda m: "%.1f s, %.2f GiB, %d, %.5f / %.5f, %d" % (m["s"], m["peak_gib"], m["spheres"], m["max_error"],
                                                                   m["median_error"], m["samples_covered"])
        print("| %s%s | %s | %s | %.2fx |" % (row["mode"], "" if row["runs"] > 1 else " (1 run)", cell(row["spaced"]),
                                           cell(row["every_vertex"]), row["every_over_spaced"]))
if r.get("dense_poses"):
    print("\npose-map at the default tolerance on poses split at their midpoints, spaced against every vertex's\n")
    print("| poses | spaced: time, memory, spheres, worst max / mean median error, samples, rounds | every vertex: the same | every / spaced time |")
    print("|---|---|---|---|")
for c in r.get("dense_poses", []):
    cell = lambda m: "%.1f s, %.2f GiB, %d, %.4f / %.4f, %d, %d" % (m["s"], m["peak_gib"], m["spheres"], m["max_error"],
                                                                   m["mean_median_error"], m["samples"], m["rounds"])
    print("| %s, %d x %d triangles%s | %s | %s | %.2fx |" % (c["mesh"], c["poses"] + 1, c["triangles"],
          "" if c["runs"] > 1 else " (1 run)", cell(c["spaced"]), cell(c["every_vertex"]), c["every_over_spaced"]))
PY
clips=$(/usr/bin/python3 -c "import json,sys; print(' '.join(s['clip'] for s in json.load(open(sys.argv[1])).get('frame_sweeps', [])))" "$json")
# The chart needs both halves: the sweep and the routes (not with --sweep-only or --no-routes).
[ -n "$clips" ] && [ -f "$data/routes.dat" ] || { echo "data: $json"; exit 0; }
for term in svg png; do
  plot="" sep="" i=1
  for c in $clips; do
    plot="$plot$sep'$data/$c.dat' using 1:2 with linespoints lw 2 lc $i pt 7 title '$c'"
    sep=", " i=$((i + 1))
  done
  gnuplot <<GP
set terminal $([ $term = svg ] && echo "svg size 1100,450 dynamic" || echo "pngcairo size 1100,450")
set output "$out/precompute.$term"
set multiplot layout 1,2
set grid
set key top left
set title "pose-map at the defaults over one clip"
set xlabel "frames"
set ylabel "seconds (median)"
plot $plot
set title "the whole chain, 4 poses"
set key bottom right
set logscale xy
set yrange [0.1:100]
set xlabel "triangles"
set ylabel "seconds (median)"
plot '$data/routes.dat' using 1:2 with linespoints lw 2 pt 6 dt 2 title "paper's route (greedy, mapped as given)", \
     '$data/routes.dat' using 1:3 with linespoints lw 2 pt 7 title "default route (cover, joint selection)", \
     '$data/routes.dat' using 1:3:4 with labels offset 0,1.2 notitle
unset multiplot
GP
done
echo "chart: $out/precompute.svg (and .png); data: $json"
