#!/usr/bin/env python3
"""Short report of one chain run from the tools' --report files: spheres, errors, times."""
import json
import os
import sys



def diagonal(obj_path):
    """Bounding-box diagonal of an OBJ's vertices."""
    lo, hi = [1e300] * 3, [-1e300] * 3
    for line in open(obj_path):
        if line.startswith("v "):
            p = [float(x) for x in line.split()[1:4]]
            lo = [min(a, b) for a, b in zip(lo, p)]
            hi = [max(a, b) for a, b in zip(hi, p)]
    return sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5


def main(folder):
    def load(name):
        with open(os.path.join(folder, name)) as f:
            return json.load(f)


    sdf, pack, pose = load("sdf.report.json"), load("pack.report.json"), load("posemap.report.json")
    exports = sorted(n for n in os.listdir(folder) if n.endswith(".report.json") and n.startswith("export."))
    grid = sdf["grid"]["dims"]
    print(f"\n== {os.path.basename(folder)}: {sdf['sdf']['defects']['triangles']} triangles, "
          f"{len(pose['poses']) - 1} poses, grid {grid[0]}x{grid[1]}x{grid[2]}")
    chosen = "every pose jointly" if pose.get("selection") else "the rest pose's, mapped"
    print(f"spheres: {pose['sphere_count']} ({chosen}; the rest alone: {pack['sphere_count']}), "
          f"blend sites: {pose['site_count']}, tets: {pose['tets']['tetrahedra']}")
    print(f"{'pose':>12}  {'median err':>10}  {'max err':>8}  outside")
    for p in pose["poses"]:
        e = p["error"]
        print(f"{p['name']:>12}  {e['median']:10.4f}  {e['max']:8.4f}  {len(p['outside'])}")
    times = [("sdf-build", sdf), ("sphere-pack", pack), ("pose-map", pose)] + [(n[7:-12], load(n)) for n in exports]
    if os.path.exists(os.path.join(folder, "extract.report.json")):
        ex = load("extract.report.json")
        targets = ", ".join(p["name"] for p in ex["poses"])
        print(f"poses from the asset by pose-extract: {targets}")
        times.insert(0, ("pose-extract", ex))
    print("time: " + ", ".join(f"{name} {r['timings_s']['total']:.2f} s" for name, r in times)
          + f"; total {sum(r['timings_s']['total'] for _, r in times):.2f} s")
    print(f"outputs: {folder}")


if __name__ == "__main__":
    main(sys.argv[1])
