#!/usr/bin/python3
"""The Python module against the C++ header: runtime-demo (the header, called from C++) prints the
global blend exactly (%.9g round-trips float32); the module's blends must match value for value.
usage: python_module.py MODULE_DIR RUNTIME_DEMO FILE.spx"""
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


def header_blend(weights):
    out = subprocess.run([demo, path] + [repr(float(w)) for w in weights], check=True, capture_output=True, text=True)
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
print(f"{0 if failed else 1} passed, {failed} failed")
sys.exit(1 if failed else 0)
