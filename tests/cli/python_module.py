#!/usr/bin/python3
"""The Python module against the C++ header: runtime-demo (the header, called from C++) prints the
global blend exactly (%.9g round-trips float32); the module's blends must match value for value.
With a rigged body's SKINNED.spx too, proxy.skin(M) against runtime-demo --skin.
usage: python_module.py MODULE_DIR RUNTIME_DEMO FILE.spx [SKINNED.spx]"""
import subprocess
import sys

import numpy as np

sys.path.insert(0, sys.argv[1])
import spx  # noqa: E402

demo, path = sys.argv[2], sys.argv[3]
failed = 0


def expect(ok, what):
    global failed
    if not ok:
        print("FAIL:", what)
        failed += 1


def header_blend(weights, *flags):
    out = subprocess.run([demo, path, *flags] + [repr(float(w)) for w in weights], check=True, capture_output=True,
                         text=True)
    rows = [line.split() for line in out.stdout.splitlines() if not line.startswith("#")]
    return np.array(rows, dtype=np.float64).astype(np.float32)


proxy = spx.load(path)
n, p, s = proxy.sphere_count, proxy.pose_count, proxy.site_count
expect(proxy.pose_names[0] == "rest" and len(proxy.pose_names) == p, "pose names")
expect(proxy.pose(0).shape == (n, 4) and proxy.pose(0).dtype == np.float32, "pose array shape and type")
expect(proxy.sphere_sites.shape == (n,) and proxy.site_positions.shape == (s, 3), "sites")
rng = np.random.default_rng(4)
for trial in range(6):
    w = np.zeros(p, dtype=np.float32)
    if trial < p:
        w[trial] = 1
    else:
        w = rng.random(p).astype(np.float32)
    ref = header_blend(w)
    got = proxy.blend_global(w)
    expect(np.array_equal(got, ref), f"blend_global trial {trial}: max diff {np.abs(got - ref).max()}")
    if trial < p:
        expect(np.array_equal(got, proxy.pose(trial)), f"weight one on pose {trial} returns S_{trial}")
    local = proxy.blend_local(np.tile(w, (s, 1)))
    expect(np.array_equal(local, ref), f"blend_local with the same weights at every site, trial {trial}")
for morph in ([0] * (p - 1), [1] + [0] * (p - 2), [1, 1] + [0] * (p - 3), rng.random(p - 1) * 2 - 0.5):
    w = np.array(morph, dtype=np.float32)
    got = proxy.blend_morph(w)
    expect(np.array_equal(got, header_blend(w, "--morph")), f"blend_morph at {w}")
try:
    proxy.blend_morph(np.zeros(p, dtype=np.float32))
    expect(False, "a morph blend given the rest's weight too must raise")
except ValueError as e:
    expect("weight count" in str(e), f"message: {e}")
try:
    proxy.blend_global(np.ones(p + 1, dtype=np.float32))
    expect(False, "a wrong weight count must raise")
except ValueError as e:
    expect("weight count" in str(e), f"message: {e}")
try:
    spx.load(path + ".missing")
    expect(False, "a missing file must raise")
except ValueError as e:
    expect(".missing" in str(e), f"message names the file: {e}")
expect(proxy.joint_count == 0 and proxy.joint_names == [], "a proxy without a skin has no joints")
try:
    proxy.skin(np.tile(np.eye(4, dtype=np.float32), (1, 1, 1)))
    expect(False, "skin on a proxy without one must raise")
except ValueError as e:
    expect("no skin" in str(e), f"message: {e}")

if len(sys.argv) > 4:
    rigged = spx.load(sys.argv[4])
    joints = rigged.joint_count
    expect(joints > 0 and len(rigged.joint_names) == joints and len(rigged.joint_parents) == joints, "joints")
    for trial in range(3):
        m = np.tile(np.eye(4), (joints, 1, 1))
        for j in range(joints):
            q = rng.normal(size=4)
            q /= np.linalg.norm(q)
            w, x, y, z = q
            m[j, :3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
            m[j, :3, 3] = rng.normal(size=3)
        m = m.astype(np.float32)
        args = ["%.9g" % v for j in range(joints) for v in m[j].T.reshape(-1)]
        out = subprocess.run([demo, sys.argv[4], "--skin"] + args, check=True, capture_output=True, text=True)
        ref = np.array([line.split() for line in out.stdout.splitlines() if not line.startswith("#")],
                       dtype=np.float64).astype(np.float32)
        got = rigged.skin(m)
        expect(got.shape == (rigged.sphere_count, 4) and got.dtype == np.float32, "skin array shape and type")
        expect(np.array_equal(got, ref), f"skin trial {trial}: max diff {np.abs(got - ref).max()}")
    try:
        rigged.skin(np.zeros((joints + 1, 4, 4), dtype=np.float32))
        expect(False, "a wrong joint count must raise")
    except ValueError as e:
        expect("joint" in str(e), f"message: {e}")
    bad = np.tile(np.eye(4, dtype=np.float32), (joints, 1, 1))
    bad[0, 0, 3] = np.nan
    try:
        rigged.skin(bad)
        expect(False, "matrices that are not finite must raise")
    except ValueError as e:
        expect("finite" in str(e), f"message: {e}")
print(f"{0 if failed else 1} passed, {failed} failed")
sys.exit(1 if failed else 0)
