#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan) and runs each for SECONDS (default 60),
# seeded with real outputs (the car sample chain, made fresh by BUILD_DIR's tools).
#   scripts/fuzz.sh [SECONDS] [BUILD_DIR]      (BUILD_DIR: default build/release)
# Everything it writes goes under BUILD_DIR/fuzz; crashes land there as crash-* files, and the
# script exits non-zero if any target fails.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-60}
build=$(cd "${2:-$root/build/release}" && pwd)
cxx=$(command -v clang++-14 || command -v clang++ || true)
[ -n "$cxx" ] || { echo "fuzz: clang++ not found (apt-get install clang-14 libclang-rt-14-dev)" >&2; exit 1; }
out=$build/fuzz
rm -rf "$out/corpus-spx" "$out/corpus-json" "$out/corpus-gltf" "$out/corpus-mesh" "$out/seeds"
mkdir -p "$out/corpus-spx" "$out/corpus-json" "$out/corpus-gltf" "$out/corpus-mesh"
flags=(-std=c++17 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
  -I"$root/lib" -I"$root/lib/runtime" -I/usr/include/eigen3 -DSPX_VERSION='"fuzz"')
"$cxx" "${flags[@]}" "$root/tests/fuzz/spx_reader.cpp" -o "$out/spx_reader"
"$cxx" "${flags[@]}" "$root/tests/fuzz/json_readers.cpp" "$root/lib/core/json_io.cpp" "$root/lib/core/file_kind.cpp" "$root/lib/core/atomic_file.cpp" \
  "$root/lib/io/spheres_file.cpp" "$root/lib/io/proxy_file.cpp" "$root/lib/io/skin_file.cpp" "$root/lib/core/version.cpp" \
  -o "$out/json_readers"
"$cxx" "${flags[@]}" "$root/tests/fuzz/gltf_container.cpp" "$root/lib/core/gltf_file.cpp" "$root/lib/core/gltf_meshopt.cpp" "$root/lib/mesh/gltf_input.cpp" "$root/lib/mesh/gltf_check.cpp" "$root/lib/mesh/gltf_clips.cpp" "$root/lib/core/json_io.cpp" "$root/lib/core/file_kind.cpp" \
  "$root/lib/core/atomic_file.cpp" "$root/lib/core/base64.cpp" -lmeshoptimizer -o "$out/gltf_container"
"$cxx" "${flags[@]}" "$root/tests/fuzz/mesh_text.cpp" "$root/lib/mesh/file_checks.cpp" "$root/lib/mesh/ply_input.cpp" "$root/lib/mesh/ply_file.cpp" "$root/lib/mesh/stl_check.cpp" "$root/lib/mesh/obj_check.cpp" "$root/lib/mesh/collada_check.cpp" "$root/lib/core/file_kind.cpp" \
  -o "$out/mesh_text"
# Seeds: the outputs of the car chain, made now by this build's tools (never a stale copy).
make -s -C "$root/samples" ASSET=car BIN="$build/apps" OUT="$out/seeds" RES=48 QUIET=1
seeds=$out/seeds/car
cp "$seeds/car.spx" "$out/corpus-spx/"
cp "$seeds/rest.spheres.json" "$seeds/car.proxy.json" "$seeds/car.json" "$out/corpus-json/"
# A skin: the robot sample's rig at two frames, its clip left out (its 60 Hz matrices run past
# -max_len).
"$build/apps/sample-gen" robot -o "$out/seeds/robot" -q
"$build/apps/pose-extract" "$out/seeds/robot/robot.glb" -o "$out/seeds/robot/poses" --animation 0 --select 2 -q
python3 -c "
import json, sys
skin = json.load(open(sys.argv[1]))
skin.pop('clip', None)
json.dump(skin, open(sys.argv[2], 'w'))
" "$out/seeds/robot/poses/skin.json" "$out/corpus-json/skin.json"
# Assets: the car's spheres as a GLB, the robot's skinned GLB, the barrel's morph-target GLB, and
# that GLB's JSON as a .gltf with its buffer as a data: URI.
"$build/apps/sample-gen" barrel -o "$out/seeds/barrel" -q
cp "$seeds/car.glb" "$out/seeds/robot/robot.glb" "$out/seeds/barrel/barrel-morph.glb" "$out/corpus-gltf/"
python3 -c "
import base64, json, struct, sys
b = open(sys.argv[1], 'rb').read()
n = struct.unpack('<I', b[12:16])[0]
doc = json.loads(b[20:20 + n])
doc['buffers'][0]['uri'] = 'data:application/octet-stream;base64,' + base64.b64encode(b[20 + n + 8:]).decode()
json.dump(doc, open(sys.argv[2], 'w'))
" "$out/seeds/barrel/barrel-morph.glb" "$out/corpus-gltf/barrel.gltf"
# Meshes: the barrel's rest mesh as its OBJ, an OFF, an ASCII PLY, a binary PLY (with a list of
# floats), its triangles as PLY strips (ASCII and binary), a binary and an ASCII STL and a COLLADA
# file.
cp "$out/seeds/barrel/rest.obj" "$out/corpus-mesh/barrel.obj"
python3 -c "
import struct, sys
sys.path.insert(0, sys.argv[3])
from mesh_writers import collada, ply_strips
v, f = [], []
for line in open(sys.argv[1]):
    w = line.split()
    if w and w[0] == 'v': v.append([float(x) for x in w[1:4]])
    if w and w[0] == 'f': f.append([int(x.split('/')[0]) - 1 for x in w[1:]])
out = sys.argv[2]
with open(out + '/barrel.off', 'w') as o:
    o.write('OFF\\n# the barrel\\n%d %d 0\\n' % (len(v), len(f)))
    o.writelines('%g %g %g\\n' % tuple(p) for p in v)
    o.writelines('%d %s\\n' % (len(t), ' '.join(map(str, t))) for t in f)
head = ('ply\\nformat %s 1.0\\nelement vertex %d\\nproperty float x\\nproperty float y\\nproperty float z\\n'
        'element face %d\\nproperty list uchar int vertex_indices\\nproperty list uchar float uv\\nend_header\\n')
with open(out + '/barrel.ply', 'w') as o:
    o.write(head % ('ascii', len(v), len(f)))
    o.writelines('%g %g %g\\n' % tuple(p) for p in v)
    o.writelines('%d %s 2 0.5 0.5\\n' % (len(t), ' '.join(map(str, t))) for t in f)
with open(out + '/barrel-binary.ply', 'wb') as o:
    o.write((head % ('binary_little_endian', len(v), len(f))).encode())
    o.write(b''.join(struct.pack('<3f', *p) for p in v))
    o.write(b''.join(struct.pack('<B%diB2f' % len(t), len(t), *t, 2, 0.5, 0.5) for t in f))
tris = [(t[0], t[k], t[k + 1]) for t in f for k in range(1, len(t) - 1)]
for binary, name in ((False, 'barrel-strips.ply'), (True, 'barrel-strips-binary.ply')):
    open(out + '/' + name, 'wb').write(ply_strips([tuple(p) for p in v], tris, binary))
with open(out + '/barrel.stl', 'wb') as o:
    o.write(b'solid barrel'.ljust(80, b'\\0') + struct.pack('<I', len(tris)))
    o.write(b''.join(struct.pack('<12fH', 0, 0, 0, *v[a], *v[b], *v[c], 0) for a, b, c in tris))
with open(out + '/barrel-ascii.stl', 'w') as o:
    o.write('solid barrel\\n')
    for t in tris:
        o.write('facet normal 0 0 1\\n outer loop\\n' + ''.join('  vertex %g %g %g\\n' % tuple(v[i]) for i in t) + ' endloop\\nendfacet\\n')
    o.write('endsolid barrel\\n')
with open(out + '/barrel.dae', 'wb') as o:
    o.write(collada(v, tris))
" "$out/seeds/barrel/rest.obj" "$out/corpus-mesh" "$root/scripts"
# Inputs that once crashed a target stay in its corpus, so every run retries them first.
cp "$root"/tests/fuzz/regressions/json/* "$out/corpus-json/"
cp "$root"/tests/fuzz/regressions/gltf/* "$out/corpus-gltf/"
cp "$root"/tests/fuzz/regressions/mesh/* "$out/corpus-mesh/"
cd "$out"
status=0
for target in spx_reader json_readers gltf_container mesh_text; do
  corpus=corpus-spx
  [ $target = json_readers ] && corpus=corpus-json
  [ $target = gltf_container ] && corpus=corpus-gltf
  [ $target = mesh_text ] && corpus=corpus-mesh
  echo "fuzz: $target for ${seconds}s" >&2
  if ! "./$target" "$corpus" -max_total_time="$seconds" -max_len=200000 -print_final_stats=1 >"$target.log" 2>&1; then
    status=1
    tail -40 "$target.log"
  fi
  grep -E "stat::number_of_executed_units|stat::new_units_added" "$target.log" | sed "s/^/$target: /"
done
if [ $status = 0 ]; then echo "4 passed, 0 failed"; else echo "0 passed, 1 failed"; fi
exit $status
