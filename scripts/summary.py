#!/usr/bin/env python3
"""Short report of one chain run from the tools' --report files: spheres, errors, times, warnings.

usage: summary.py FOLDER [--ran-since EPOCH_SECONDS]
With --ran-since (when make was started), a chain whose outputs were already up to date (no
report written since) says that its times are those of the earlier run that wrote them.
"""
import json
import os
import signal
import sys
import time


def diagonal(obj_path):
    """Bounding-box diagonal of an OBJ's vertices."""
    lo, hi = [1e300] * 3, [-1e300] * 3
    for line in open(obj_path):
        if line.startswith("v "):
            p = [float(x) for x in line.split()[1:4]]
            lo = [min(a, b) for a, b in zip(lo, p)]
            hi = [max(a, b) for a, b in zip(hi, p)]
    return sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5


def main(folder, ran_since=None):
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
    steps = [("sdf-build", "sdf"), ("sphere-pack", "pack"), ("pose-map", "posemap")] + [(n[7:-12], n[:-12]) for n in exports]
    if os.path.exists(os.path.join(folder, "extract.report.json")):
        targets = ", ".join(p["name"] for p in load("extract.report.json")["poses"])
        print(f"poses from the asset by pose-extract: {targets}")
        steps.insert(0, ("pose-extract", "extract"))
    reports = {name: load(f"{stem}.report.json") for name, stem in steps}
    times = [(name, reports[name]["timings_s"]["total"],
              os.path.getmtime(os.path.join(folder, f"{stem}.report.json"))) for name, stem in steps]
    # make reruns only what changed: a step whose report is older than this run did not run now.
    earlier = [t for t in times if ran_since is not None and t[2] < ran_since]
    when, mark = "time", set()
    if earlier:
        stamp = time.strftime("%Y-%m-%d %H:%M", time.localtime(max(t[2] for t in earlier)))
        if len(earlier) == len(times):
            when = f"time (nothing ran, every output was up to date: the times of the run at {stamp}; make -B runs it all)"
        else:
            when, mark = f"time (* up to date, not run now: the time of the run at {stamp})", {t[0] for t in earlier}
    print(f"{when}: " + ", ".join(f"{name}{'*' if name in mark else ''} {seconds:.2f} s" for name, seconds, _ in times)
          + f"; total {sum(t[1] for t in times):.2f} s")
    # The tools' warnings, which a make run with QUIET=1 (as the demo's) does not show.
    warned = [(name, w) for name, _ in steps for w in reports[name]["warnings"]]
    if warned:
        print(f"warnings ({len(warned)}, from the reports):")
        for name, w in warned:
            print(f"  {name}: {w}")
    print(f"outputs: {folder}")


if __name__ == "__main__":
    # Piped into `head` or `grep -q`, stop quietly as the tools do, not with a traceback.
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    args = sys.argv[1:]
    since = None
    if len(args) == 3 and args[1] == "--ran-since":
        since = float(args[2])
    elif len(args) != 1:
        sys.exit(__doc__.split("\n\n")[1])
    main(args[0], since)
