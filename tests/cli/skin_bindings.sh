#!/usr/bin/env bash
# spx_skin from C against spx::skin in the C++ header (runtime-demo --skin): the same spheres,
# line for line, for a few frames of random rigid joint matrices.
# usage: skin_bindings.sh BUILD_DIR SKINNED.spx
set -euo pipefail
build=$1 spx=$2
joints=$(/usr/bin/python3 -c "import struct,sys; b=open(sys.argv[1],'rb').read(); print(struct.unpack_from('<I', b, struct.unpack_from('<I', b, 60)[0])[0])" "$spx")
fail=0 passed=0
for seed in 1 2 3; do
  # shellcheck disable=SC2207
  m=($(/usr/bin/python3 -c "
import sys, numpy as np
rng = np.random.default_rng(int(sys.argv[2]))
out = []
for j in range(int(sys.argv[1])):
    q = rng.normal(size=4); q /= np.linalg.norm(q); w, x, y, z = q
    r = np.array([[1-2*(y*y+z*z), 2*(x*y-z*w), 2*(x*z+y*w)], [2*(x*y+z*w), 1-2*(x*x+z*z), 2*(y*z-x*w)], [2*(x*z-y*w), 2*(y*z+x*w), 1-2*(x*x+y*y)]])
    m = np.eye(4); m[:3, :3] = r; m[:3, 3] = rng.normal(size=3)
    out += ['%.9g' % v for v in m.T.reshape(-1)]
print(' '.join(out))" "$joints" "$seed"))
  demo=$("$build/samples/runtime-demo" "$spx" --skin "${m[@]}")
  c=$("$build/tests/c_api_check" "$spx" --skin "${m[@]}")
  if [ -n "$demo" ] && [ "$c" = "$demo" ]; then passed=$((passed + 1)); else echo "FAIL: spx_skin differs from spx::skin (seed $seed)"; fail=$((fail + 1)); fi
done
if "$build/tests/c_api_check" "$spx" --skin 1 0 0 0 2>/dev/null; then echo "FAIL: a wrong joint count must fail"; fail=$((fail + 1)); else passed=$((passed + 1)); fi
echo "$passed passed, $fail failed"
[ "$fail" = 0 ]
