#!/usr/bin/env bash
# The error contract: one "Error: <file>: ..." line on stderr, the documented exit code,
# and no output file left behind (or the previous one intact).
# usage: errors.sh BUILD_DIR OUT_DIR
set -uo pipefail
bin=$1/apps out=$2
rm -rf "$out" && mkdir -p "$out"
fail=0 passed=0
"$bin/sample-gen" barrel -o "$out/in" -q
"$bin/sdf-build" "$out/in/rest.obj" -o "$out/rest.vdb" --resolution 32 -q
"$bin/sphere-pack" "$out/rest.vdb" -o "$out/s.json" --method greedy -q

source "$(dirname "$0")/expect.sh"

expect 2 "Error: $out/missing.obj: cannot open" "$out/x.vdb" -- "$bin/sdf-build" "$out/missing.obj" -o "$out/x.vdb"
# An empty value, as a make variable that was not set gives it (-o $(OUT)): exit 1 naming the
# option (an empty output or --report was an internal error, exit 5), and an output that names a
# folder (exit 4, "cannot rename temporary file into place").
expect 1 "Error: --output: is empty (a shell or make variable that was not set?)" "" -- "$bin/sdf-build" "$out/in/rest.obj" -o ""
expect 1 "Error: --report: is empty" "$out/x.vdb" -- "$bin/sdf-build" "$out/in/rest.obj" -o "$out/x.vdb" --report ""
expect 1 "Error: input: is empty" "$out/x.vdb" -- "$bin/sdf-build" "" -o "$out/x.vdb"
expect 1 "Error: --output: is empty" "" -- "$bin/pose-extract" "$out/in/barrel-morph.glb" -o "" --morph-targets
# An output folder where a file is (or in one): refused before the clip is read, the file kept.
printf 'a file\n' >"$out/px-file"
expect 4 "px-file: cannot make the folder: .*px-file is a file$" "" -- "$bin/pose-extract" "$out/in/barrel-morph.glb" \
  -o "$out/px-file" --morph-targets
expect 4 "px-file/poses: cannot make the folder: .*px-file is a file, not a folder the output can go in" "" -- \
  "$bin/pose-extract" "$out/in/barrel-morph.glb" -o "$out/px-file/poses" --morph-targets
check "pose-extract -o wrote over a file" grep -qx "a file" "$out/px-file"
expect 1 "Error: --manifest: is empty" "$out/p.json" -- "$bin/pose-map" --manifest "" --spheres "$out/s.json" -o "$out/p.json"
expect 1 "Error: --output: $out/ is a folder; give the name of the file to write" "" -- "$bin/sdf-build" "$out/in/rest.obj" -o "$out/"
# A value that is not of the option's kind, said as the option and what it takes (CLI11 said
# "Could not convert: --resolution = abc").
expect 1 "Error: --resolution: 'abc' is not a whole number (see sdf-build --help)" "$out/x.vdb" -- \
  "$bin/sdf-build" "$out/in/rest.obj" -o "$out/x.vdb" --resolution abc
expect 1 "Error: --times: '0.5s' is not a number (or a list of them)" "" -- \
  "$bin/pose-extract" "$out/in/barrel-morph.glb" -o "$out/t" --animation 0 --times 0.5s
# A .blend of Blender 2.80 or later (the artist's own file), which assimp's Blender reader fails
# on with a word about its internals, or crashes on: exit 3 naming the version and the export.
{ printf 'BLENDER-v402REND'; head -c 400 /dev/zero; } >"$out/scene.blend"
expect 3 "scene.blend: is a .blend file of Blender 4.2; assimp's Blender reader stops at Blender 2.79 .*export glTF 2.0 from Blender" \
  "$out/x.vdb" -- "$bin/sdf-build" "$out/scene.blend" -o "$out/x.vdb"
{ printf '\x28\xb5\x2f\xfd'; head -c 400 /dev/zero; } >"$out/packed.blend"
expect 3 "packed.blend: is a .blend file compressed with Zstandard (Blender 3.0 or later)" "" -- \
  "$bin/pose-extract" "$out/packed.blend" -o "$out/pb" --morph-targets
# A format artists hand over that is not read here: the way to one that is.
echo "abc" >"$out/crash.abc"
expect 3 "crash.abc: unknown mesh format '.abc' (use .*); an Alembic cache: write its frames as OBJ files" "$out/x.vdb" -- \
  "$bin/sdf-build" "$out/crash.abc" -o "$out/x.vdb"
# A file name holding a newline (a script's $(ls) gone wrong): the error stays one line, the
# newline written as \n (it was split over two lines, the second not starting "Error:").
said=$("$bin/sdf-build" "$out/no
such.obj" -o "$out/x.vdb" 2>&1)
check "an error naming a file with a newline is not one line: $said" [ "$(wc -l <<<"$said")" = 1 ]
check "an error naming a file with a newline does not write it as \\n: $said" grep -qF 'no\nsuch.obj: cannot open' <<<"$said"
cp "$out/in/rest.obj" "$out/new
line.obj"
said=$("$bin/sdf-build" "$out/new
line.obj" -o "$out/new
line.vdb" --resolution 16 2>&1)
check "the log line naming a file with a newline is not one line: $said" [ "$(wc -l <<<"$said")" = 1 ]
rm -f "$out/new
line.vdb"
# A path a pipeline wrote on Windows: the error says why it is not found here.
expect 2 "poses\\\\rest.obj: cannot open: no such file (a Windows path?" "$out/x.vdb" -- "$bin/sdf-build" 'poses\rest.obj' -o "$out/x.vdb"
: >"$out/empty.obj"
expect 2 "empty.obj: file is empty" "$out/x.vdb" -- "$bin/sdf-build" "$out/empty.obj" -o "$out/x.vdb"
echo "v 0 0 0" >"$out/mesh.abc"
expect 3 "mesh.abc: unknown mesh format" "$out/x.vdb" -- "$bin/sdf-build" "$out/mesh.abc" -o "$out/x.vdb"
printf 'garbage\n\001\002\n' >"$out/garbage.obj"
expect 2 "garbage.obj" "$out/x.vdb" -- "$bin/sdf-build" "$out/garbage.obj" -o "$out/x.vdb"
# An OFF cut short after its vertices (assimp's triangulation aborted the tool on its faces with
# no corners), and a PLY face naming a vertex past its 4 (read past the vertices' end).
printf 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n' >"$out/cut.off"
expect 2 "cut.off: face 2 has no corners" "$out/x.vdb" -- "$bin/sdf-build" "$out/cut.off" -o "$out/x.vdb"
printf 'ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 7\n' >"$out/past.ply"
expect 2 "past.ply: face 4 names vertex 7 (counted from 0), past its 4 vertices" "$out/x.vdb" -- "$bin/sdf-build" "$out/past.ply" -o "$out/x.vdb"
expect 2 "cut.off: face 2 has no corners" "$out/cut" -- "$bin/pose-extract" "$out/cut.off" -o "$out/cut"
# assimp's error on an ASCII STL's number quotes the rest of the file: the line keeps its start
# and its end (it was 258 000 characters long here). A normal's word, which the STL check leaves
# to the reader (a coordinate's it names itself).
awk 'BEGIN { print "solid s"; f = "facet normal %s\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
             printf f, "q 0 0"; for (i = 0; i < 3000; i++) printf f, "0 0 0"; print "endsolid s" }' >"$out/long.stl"
expect 2 "long.stl: cannot read mesh: Cannot parse string \"q.* \[\.\.\. [0-9]* characters \.\.\.\] .* as a real number" "$out/x.vdb" -- \
  "$bin/sdf-build" "$out/long.stl" -o "$out/x.vdb"
said=$("$bin/sdf-build" "$out/long.stl" -o "$out/x.vdb" 2>&1)
check "a long error line shortened (${#said} characters)" [ "${#said}" -lt 400 ]
# A PLY cut short within its header: assimp's reader never returned.
printf 'ply\nformat ascii 1.0\nelement vertex 4\nproperty fl' >"$out/head.ply"
expect 2 "head.ply: its PLY header does not end" "$out/x.vdb" -- timeout 60 "$bin/sdf-build" "$out/head.ply" -o "$out/x.vdb"
# A COLLADA <p> holding a word that is no whole number: assimp's reader never moved past it and
# allocated without end (6 GB in 15 s); under this 3 GB limit the code before said "out of memory;
# try a coarser --resolution" (exit 3).
cat >"$out/tet.dae" <<'EOF'
<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <library_geometries>
    <geometry id="tet">
      <mesh>
        <source id="tet-positions">
          <float_array id="tet-array" count="12">0 0 0 1 0 0 0 1 0 0 0 1</float_array>
          <technique_common>
            <accessor source="#tet-array" count="4" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="tet-vertices"><input semantic="POSITION" source="#tet-positions"/></vertices>
        <triangles count="4">
          <input semantic="VERTEX" source="#tet-vertices" offset="0"/>
          <p>0 2 1 0 1 3 0 3 2 1 2 3</p>
        </triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene"><node id="tet-node"><instance_geometry url="#tet"/></node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
EOF
sed 's|<p>0 2 1 0 1 3 |<p>0 2 1 0 1 3.5 |' "$out/tet.dae" >"$out/bad.dae"
"$bin/sdf-build" "$out/tet.dae" -o "$out/tet.vdb" --resolution 16 -q
check "a COLLADA tetrahedron reads" test -s "$out/tet.vdb"
# Capped (assimp's reader of such a file ran away with 6 GB), but not under the sanitizers, whose
# shadow memory the cap refuses (SPX_SANITIZED).
cap=(bash -c 'ulimit -v 3000000 && exec "$@"' limited)
[ -n "${SPX_SANITIZED:-}" ] && cap=()
expect 2 "bad.dae: line 17: <p> holds '3.5', where the COLLADA reader takes whole numbers" "$out/x.vdb" -- \
  "${cap[@]}" timeout 60 "$bin/sdf-build" "$out/bad.dae" -o "$out/x.vdb"
expect 1 "resolution" "$out/x.vdb" -- "$bin/sdf-build" "$out/in/rest.obj" -o "$out/x.vdb" --resolution 0
expect 1 "resolution" "$out/x.vdb" -- "$bin/sdf-build" "$out/in/rest.obj" -o "$out/x.vdb" --resolution abc
expect 3 "GiB" "$out/x.vdb" -- "$bin/sdf-build" "$out/in/rest.obj" -o "$out/x.vdb" --resolution 20000
expect 1 "Error:" "" -- "$bin/sdf-build" "$out/in/rest.obj" --no-such-option
expect 4 "x.vdb: cannot create output: its folder .*/no/such/dir is not there" "" -- "$bin/sdf-build" "$out/in/rest.obj" -o "$out/no/such/dir/x.vdb"
expect 4 "x.vdb: cannot create output: its folder .*/px-file is a file" "" -- "$bin/sdf-build" "$out/in/rest.obj" -o "$out/px-file/x.vdb"
# An output's folder that is not there fails before the work, the others not written either.
expect 4 "r.json: cannot create output: its folder" "$out/y.vdb" -- "$bin/sdf-build" "$out/in/rest.obj" -o "$out/y.vdb" --report "$out/no/r.json"
expect 4 "c.glb: cannot create output: its folder" "" -- "$bin/proxy-eval" "$out/none.proxy.json" --colors "$out/no/c.glb"
# ... but a tool that creates its output folder takes a --report there.
"$bin/sample-gen" barrel -o "$out/made/here" --report "$out/made/here/r.json" -q
check "sample-gen writes its --report into the folder it creates" test -s "$out/made/here/r.json"
expect 2 "rest.obj: is a mesh, not a field: sdf-build makes the field from it" "$out/y.json" -- \
  "$bin/sphere-pack" "$out/in/rest.obj" -o "$out/y.json"
expect 2 "s.json: is a JSON file, not a field (.vdb from sdf-build)" "$out/y.json" -- "$bin/sphere-pack" "$out/s.json" -o "$out/y.json"
printf 'not a field\n' >"$out/field.txt"
expect 2 "field.txt: not a readable OpenVDB file" "$out/y.json" -- "$bin/sphere-pack" "$out/field.txt" -o "$out/y.json"
expect 2 "rest.obj: is a mesh, not JSON" "$out/y.json" -- "$bin/pose-map" --manifest "$out/in/rest.obj" --spheres "$out/s.json" \
  -o "$out/y.json"
cp "$out/in/rest.obj" "$out/fake.vdb"
expect 2 "fake.vdb" "$out/y.json" -- "$bin/sphere-pack" "$out/fake.vdb" -o "$out/y.json"
expect 1 "min radius" "$out/y.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/y.json" --min-radius 0.1 --max-radius 0.01
expect 1 "min-radius" "$out/y.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/y.json" --min-radius -2
# A least radius past the body's depth: both methods say so (the cover said the field held no interior).
for method in cover greedy; do
  expect 2 "rest.vdb: no .*sphere fits: the largest interior distance.* is below the min radius 1e+06" "$out/y.json" -- \
    "$bin/sphere-pack" "$out/rest.vdb" -o "$out/y.json" --min-radius 1e6 --method $method
done

# --tolerance and --max-spheres combine: the tighter wins, and the report says which.
for method in greedy cover; do
  "$bin/sphere-pack" "$out/rest.vdb" --mesh "$out/in/rest.obj" --tolerance 0.5% --max-spheres 5 -o "$out/t.json" \
    --report "$out/t.report.json" --method $method 2> "$out/t.log"
  if grep -q "t.json: 5 spheres, radii .*; limited by max_spheres (tighter than the tolerance)$" "$out/t.log"; then
    passed=$((passed + 1)); else echo "FAIL: sphere-pack --method $method's last line does not say what limited it"; cat "$out/t.log"; fail=$((fail + 1)); fi
done
if /usr/bin/python3 -c "import json,sys; r=json.load(open(sys.argv[1])); sys.exit(0 if r['sphere_count']==5 and 'max_spheres' in r['tolerance']['limited_by'] else 1)" "$out/t.report.json"; then
  passed=$((passed + 1)); else echo "FAIL: --max-spheres did not win over --tolerance"; fail=$((fail + 1)); fi
"$bin/sphere-pack" "$out/rest.vdb" --mesh "$out/in/rest.obj" --tolerance 3% --max-spheres 500 -o "$out/t.json" -q \
  --report "$out/t.report.json"
if /usr/bin/python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['tolerance']; sys.exit(0 if r['met'] and r['max_error']<=r['target'] and r['spheres']<500 else 1)" "$out/t.report.json"; then
  passed=$((passed + 1)); else echo "FAIL: --tolerance did not win over a loose --max-spheres"; fail=$((fail + 1)); fi
# Without --mesh, the mesh the field records is used while it is there; else the error names it.
if "$bin/sphere-pack" "$out/rest.vdb" --tolerance 2% -o "$out/auto.json" -q &&
  /usr/bin/python3 -c "import json,sys; sys.exit(0 if json.load(open(sys.argv[1]))['source']['mesh'].endswith('in/rest.obj') else 1)" "$out/auto.json"; then
  passed=$((passed + 1)); else echo "FAIL: sphere-pack did not take the mesh the field records"; fail=$((fail + 1)); fi
cp "$out/in/rest.obj" "$out/gone.obj"
"$bin/sdf-build" "$out/gone.obj" -o "$out/gone.vdb" --resolution 32 -q
rm "$out/gone.obj"
expect 1 "mesh: is needed by the cover method .*gone.vdb was built from .*gone.obj, which is not there from this folder; pass it with --mesh" \
  "$out/u.json" -- "$bin/sphere-pack" "$out/gone.vdb" -o "$out/u.json"
# The field records its mesh as seen from its own folder too: sphere-pack finds it from any working
# folder, and after the two are moved together.
mkdir -p "$out/away/meshes" "$out/away/fields"
cp "$out/in/rest.obj" "$out/away/meshes/body.obj"
(cd "$out/away/meshes" && "$bin/sdf-build" body.obj -o ../fields/body.vdb --resolution 32 -q)
if (cd / && "$bin/sphere-pack" "$out/away/fields/body.vdb" -o "$out/away/s.json" --max-spheres 4 -q) &&
  /usr/bin/python3 -c "import json,sys; sys.exit(0 if json.load(open(sys.argv[1]))['source']['mesh'].endswith('away/meshes/body.obj') else 1)" "$out/away/s.json"; then
  passed=$((passed + 1)); else echo "FAIL: sphere-pack from another folder did not find the field's mesh beside the field"; fail=$((fail + 1)); fi
# A mesh given to sdf-build by its absolute path is named so (not as seen from the field's folder).
(cd "$out/away/fields" && "$bin/sdf-build" "$out/away/meshes/body.obj" -o abs.vdb --resolution 32 -q)
said=$(cd "$out/away/fields" && "$bin/sphere-pack" abs.vdb -o abs.json --max-spheres 4 2>&1)
if grep -q "^sphere-pack: using the mesh abs.vdb was built from: $out/away/meshes/body.obj (--mesh not given)$" <<<"$said"; then
  passed=$((passed + 1)); else echo "FAIL: sphere-pack named the field's mesh otherwise than sdf-build was given it: $said"; fail=$((fail + 1)); fi
mv "$out/away" "$out/moved"
if (cd "$out/moved/fields" && "$bin/sphere-pack" body.vdb -o s.json --max-spheres 4 -q) && [ -s "$out/moved/fields/s.json" ]; then
  passed=$((passed + 1)); else echo "FAIL: sphere-pack did not find the field's mesh after both were moved together"; fail=$((fail + 1)); fi
rm "$out/moved/meshes/body.obj"
expect 1 "moved/fields/body.vdb was built from body.obj, which is not there from this folder nor from the field's (.*moved/meshes/body.obj); pass it with --mesh" \
  "$out/u.json" -- "$bin/sphere-pack" "$out/moved/fields/body.vdb" -o "$out/u.json"
expect 1 "mesh: is needed by --tolerance" "$out/u.json" -- "$bin/sphere-pack" "$out/gone.vdb" --method greedy --tolerance 1% -o "$out/u.json"
expect 1 "tolerance" "$out/u.json" -- "$bin/sphere-pack" "$out/rest.vdb" --mesh "$out/in/rest.obj" --tolerance abc -o "$out/u.json"

# --mesh must be the mesh the field was built from: a pose or another model is refused, naming both.
expect 2 "dent.obj: is not the mesh .*rest.vdb (built from .*rest.obj) was built from: its bounding box differs" \
  "$out/m.json" -- "$bin/sphere-pack" "$out/rest.vdb" --mesh "$out/in/dent.obj" -o "$out/m.json"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n' >"$out/other.obj"
expect 2 "other.obj: is not the mesh .*rest.vdb .*: [0-9] of its solid's 4 surface vertices lie more than 2 voxels off" \
  "$out/m.json" -- "$bin/sphere-pack" "$out/rest.vdb" --mesh "$out/other.obj" -o "$out/m.json"

# Poses that do not share the rest topology.
head -n -1 "$out/in/dent.obj" >"$out/short.obj"
expect 2 "short.obj: has .* triangles, the rest mesh has" "$out/p.json" -- \
  "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/short.obj" --spheres "$out/s.json" -o "$out/p.json"
echo '{"format": "spx-spheres", "version": 1}' >"$out/bad-spheres.json"
expect 2 "bad-spheres.json: missing field" "$out/p.json" -- \
  "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" --spheres "$out/bad-spheres.json" -o "$out/p.json"
echo '{"format": "spx-spheres", "version": 7, "spheres": []}' >"$out/new-spheres.json"
expect 3 "newer than this tool" "$out/p.json" -- \
  "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" --spheres "$out/new-spheres.json" -o "$out/p.json"
echo '{not json' >"$out/broken.proxy.json"
expect 2 "broken.proxy.json: not valid JSON" "$out/z.spx" -- "$bin/proxy-export" "$out/broken.proxy.json" -o "$out/z.spx"
expect 1 "unknown output format" "$out/z.txt" -- "$bin/proxy-export" "$out/broken.proxy.json" -o "$out/z.txt"
# No pose at all: the error says what to give for a body that does not deform.
expect 1 "\-\-pose: give at least one example pose (for a body that does not deform, the rest itself: \-\-pose .*rest.obj)" \
  "$out/o.json" -- "$bin/pose-map" --rest "$out/in/rest.obj" --spheres "$out/s.json" -o "$out/o.json"
# Another of the chain's files where a proxy is read: the error says which it is and what reads it.
expect 2 "s.json: is not a proxy file .*; it is sphere-pack's spheres file, which pose-map makes a proxy of" "$out/z.spx" \
  -- "$bin/proxy-export" "$out/s.json" -o "$out/z.spx"

# A pose in another unit (centimetres against metres) is warned about, by name.
/usr/bin/python3 -c "
import sys
out = open(sys.argv[2], 'w')
for line in open(sys.argv[1]):
    w = line.split()
    out.write('v %g %g %g\n' % tuple(100 * float(x) for x in w[1:4]) if w and w[0] == 'v' else line)
" "$out/in/dent.obj" "$out/dent-cm.obj"
said=$("$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/dent-cm.obj" --spheres "$out/s.json" -o "$out/cm.json" 2>&1)
if grep -q "dent-cm.obj: its size is .*another unit" <<<"$said"; then passed=$((passed + 1)); else
  echo "FAIL: no unit-scale warning"; fail=$((fail + 1)); fi
# A mesh far from the origin for its size, read in single precision as every mesh reader reads:
# past a voxel it is refused naming the file (the field followed the rounded vertices without a
# word), past a tenth of one warned about, and the report says by how much.
for off in 1e5 1e6; do
  for mesh in rest dent; do
    awk -v o=$off '/^v /{printf "v %.9g %.9g %.9g\n", $2 + o, $3, $4; next} {print}' "$out/in/$mesh.obj" >"$out/$mesh-$off.obj"
  done
done
expect 2 "rest-1e6.obj: its coordinates reach 1e+06, where the mesh readers' single precision places a vertex only to within 0.03125 of the file's, .* voxels of .*: the field would follow that reading, not the file; move the mesh near the origin" \
  "$out/far.vdb" -- "$bin/sdf-build" "$out/rest-1e6.obj" -o "$out/far.vdb" --resolution 32
said=$("$bin/sdf-build" "$out/rest-1e5.obj" -o "$out/far.vdb" --resolution 32 --report "$out/far.json" 2>&1)
check "a mesh read coarser than a tenth of a voxel is warned about: $said" \
  eval 'grep -q "warning: .*rest-1e5.obj: its coordinates reach 1e+05, .* within 0.003906 of the file.s, 0.17.. of a voxel" <<<"$said"'
check "the report gives the reading's rounding" /usr/bin/python3 -c \
  "import json,sys; sys.exit(0 if json.load(open(sys.argv[1]))['mesh']['read_rounding'] == 2**-8 else 1)" "$out/far.json"
said=$("$bin/sdf-build" "$out/in/rest.obj" -o "$out/near.vdb" --resolution 32 2>&1)
check "a mesh near the origin is not warned about: $said" eval '! grep -q "single precision" <<<"$said"'
expect 2 "dent-1e6.obj: its coordinates reach 1e+06, .* move the mesh near the origin" "$out/far-map.json" -- \
  "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/dent-1e6.obj" --spheres "$out/s.json" -o "$out/far-map.json"
# Swapped rest and pose: the rest spheres do not fit the "rest" mesh.
# A pose that is inside out (mirrored): named, for the map as given and for the selection; an open
# body's mirrored pose, whose field encloses nothing, is named too (the rest was).
awk '/^v /{printf "v %.9g %.9g %.9g\n", -$2, $3, $4; next} {print}' "$out/in/dent.obj" >"$out/mirror.obj"
for how in --map-given --tolerance=2%; do
  expect 2 "mirror.obj: is inside out (signed volume -.*flip its faces" "$out/mi.json" -- "$bin/pose-map" \
    --rest "$out/in/rest.obj" --pose "$out/mirror.obj" --spheres "$out/s.json" -o "$out/mi.json" $how
done
expect 2 "swapped" "$out/sw.json" -- "$bin/pose-map" --rest "$out/in/squash.obj" --pose "$out/in/rest.obj" \
  --spheres "$out/s.json" -o "$out/sw.json"
# ... said before the tets are made (it came after Mesh_3's whole run, seconds on a large mesh).
said=$("$bin/pose-map" --rest "$out/in/squash.obj" --pose "$out/in/rest.obj" --spheres "$out/s.json" -o "$out/sw.json" -v 2>&1)
check "spheres that do not fit the rest said only after the tets: $said" \
  eval 'grep -q "swapped" <<<"$said" && ! grep -q "tets\|tetrahedralize" <<<"$said"'

# Counts and tolerances users mistype.
expect 1 "max-spheres: must be above 0, not 0" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/n.json" --max-spheres 0
expect 1 "max-spheres: must be above 0, not -5" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/n.json" --max-spheres -5
expect 1 "threads: must be above 0, not 0" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/n.json" --threads 0
expect 1 "fill-max: must be above 0, not 0" "$out/n.json" -- "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" \
  --spheres "$out/s.json" -o "$out/n.json" --fill-gaps --fill-max 0
expect 1 "tet-size: must be above 0, not -1" "$out/n.json" -- "$bin/pose-map" --rest "$out/in/rest.obj" \
  --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/n.json" --tet-size -1
expect 1 "tet-size: 1e+09 is larger than the body" "$out/n.json" -- "$bin/pose-map" --rest "$out/in/rest.obj" \
  --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/n.json" --tet-size 1e9

# An option the run would ignore (another method's, or one that needs a flag not given) is an
# error naming it, not dropped.
pm() { "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/n.json" "$@"; }
expect 1 "fill-max requires --fill-gaps" "$out/n.json" -- pm --fill-max 3
expect 1 "fill-tolerance requires --fill-gaps" "$out/n.json" -- pm --fill-tolerance 1%
expect 1 "fill-min-radius requires --fill-gaps" "$out/n.json" -- pm --fill-min-radius 0.01
expect 1 "clip-overshoot requires --hold-over-clip" "$out/n.json" -- pm --clip-overshoot 1%
for selection in "--tolerance 1%" "--max-spheres 5" "--samples 100" "--seed 2" "--polish 2" --every-vertex; do
  expect 1 "excludes" "$out/n.json" -- pm --map-given $selection
done
expect 1 "samples: is for the cover method" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/n.json" \
  --method greedy --samples 100
expect 1 "seed: is for the cover method" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/n.json" \
  --method greedy --seed 3
expect 1 "every-vertex: is for the cover method" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/n.json" \
  --method greedy --every-vertex
expect 1 "cache: is for the cover method" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/n.json" \
  --method greedy --cache "$out/cache"
printf 'a file\n' >"$out/a-file"
expect 4 "a-file: cannot make the folder: .*a-file is a file" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" \
  --mesh "$out/in/rest.obj" -o "$out/n.json" --cache "$out/a-file"
# --cache-limit: a size that is not one (negative, a unit it does not know) or without --cache.
expect 1 "--cache-limit: must be 0 or more, not -1" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" \
  --mesh "$out/in/rest.obj" -o "$out/n.json" --cache "$out/cache" --cache-limit -1
expect 1 "--cache-limit: zb unit not recognized" "$out/n.json" -- "$bin/pose-map" --rest "$out/in/rest.obj" \
  --pose "$out/in/dent.obj" --spheres "$out/n.json" -o "$out/n.json" --cache "$out/cache" --cache-limit 3zb
expect 1 "--cache-limit requires --cache" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" \
  --mesh "$out/in/rest.obj" -o "$out/n.json" --cache-limit 1gb
expect 1 "polish requires --max-spheres" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/n.json" --polish 2
expect 1 "grid-centers: is for --method greedy" "$out/n.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/n.json" \
  --grid-centers
expect 1 "fill-tolerance: 'abc'" "$out/n.json" -- "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" \
  --spheres "$out/s.json" -o "$out/n.json" --fill-gaps --fill-tolerance abc
"$bin/sphere-pack" "$out/rest.vdb" --mesh "$out/in/rest.obj" --tolerance 2 -o "$out/big.json" --report "$out/big.report.json" \
  2>"$out/big.err"
if grep -q "warning: tolerance 2 is .* of the mesh's bounding-box diagonal .*did you mean 2%" "$out/big.err" &&
   /usr/bin/python3 -c "import json,sys; r=json.load(open(sys.argv[1])); sys.exit(0 if r['pack']['stop_reason']==r['tolerance']['limited_by'] else 1)" "$out/big.report.json"; then
  passed=$((passed + 1)); else echo "FAIL: --tolerance 2 (no %): $(cat "$out/big.err")"; fail=$((fail + 1)); fi
"$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/ft.json" -q \
  --fill-gaps --fill-tolerance 2% --report "$out/ft.report.json"
if /usr/bin/python3 -c "import json,sys; r=json.load(open(sys.argv[1])); sys.exit(0 if abs(r['fill_gaps']['target'] - 0.02 * float(sys.argv[2])) < 1e-9 else 1)" \
     "$out/ft.report.json" "$(/usr/bin/python3 -c "
import sys
v=[list(map(float,l.split()[1:4])) for l in open(sys.argv[1]) if l.startswith('v ')]
print(sum((max(c)-min(c))**2 for c in zip(*v))**0.5)" "$out/in/rest.obj")"; then
  passed=$((passed + 1)); else echo "FAIL: --fill-tolerance 2% not 2% of the diagonal"; fail=$((fail + 1)); fi

# Files of the wrong kind, counts a file cannot hold.
"$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/ok.proxy.json" -q
"$bin/proxy-export" "$out/ok.proxy.json" -o "$out/ok.spx" -q
expect 1 "Error: --ply-pose: no pose 12" "$out/o.ply" -- "$bin/proxy-export" "$out/ok.proxy.json" -o "$out/o.ply" --ply-pose 12
expect 1 "ply-pose: is for a .ply output" "$out/n.spx" -- "$bin/proxy-export" "$out/ok.proxy.json" -o "$out/n.spx" --ply-pose 1
expect 1 "stacked: is for a .glb of sphere meshes" "$out/n.spx" -- "$bin/proxy-export" "$out/ok.proxy.json" -o "$out/n.spx" --stacked
expect 1 "ply-pose: must be 0 or more, not -1" "$out/n.ply" -- "$bin/proxy-export" "$out/ok.proxy.json" -o "$out/n.ply" --ply-pose -1
ev() { "$bin/proxy-eval" "$out/ok.proxy.json" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" "$@"; }
expect 1 "coverage-samples: Value 0 not in range 1 to 1024" "" -- ev --coverage-samples 0
# Counts past what any run needs, mistyped: refused before the work (each ran for days or filled
# memory: --samples 2e9 passed 3.8 GB in 9 s, --between 1e9 5.8 GB).
expect 1 "coverage-samples: Value 100000 not in range 1 to 1024" "" -- ev --coverage-samples 100000
expect 1 "samples: Value 2000000000 not in range 0 to 1000000" "$out/y.json" -- "$bin/sphere-pack" "$out/rest.vdb" \
  -o "$out/y.json" --samples 2000000000
expect 1 "samples: Value 2000000000 not in range 0 to 1000000" "$out/y.json" -- "$bin/pose-map" --rest "$out/in/rest.obj" \
  --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/y.json" --samples 2000000000
expect 1 "color-pose requires --colors" "" -- ev --color-pose 1
# A mistyped count of blends is refused before any work (it grew past 6 GB in 16 s).
expect 1 "blends: at most 100000, not 1000000000" "" -- ev --blends 1000000000
expect 1 "color-scale requires --colors" "" -- ev --color-scale 0.1
expect 1 "color-scale: must be above 0, not -1" "$out/n.ply" -- ev --colors "$out/n.ply" --color-scale -1
expect 1 "color-pose: is for a .ply" "$out/n.glb" -- ev --colors "$out/n.glb" --color-pose 1
expect 1 "memory-limit: must be above 0, not 0" "$out/n.vdb" -- "$bin/sdf-build" "$out/in/rest.obj" -o "$out/n.vdb" --memory-limit 0
# A zero where the library reads zero as "the default" was taken silently as the default.
expect 1 "voxel-size: must be above 0, not 0" "$out/n.vdb" -- "$bin/sdf-build" "$out/in/rest.obj" -o "$out/n.vdb" --voxel-size 0
expect 1 "min-radius: must be above 0, not 0" "$out/y.json" -- "$bin/sphere-pack" "$out/rest.vdb" -o "$out/y.json" \
  --method greedy --min-radius 0
pm0() { "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/y.json" "$@"; }
expect 1 "max-radius: must be above 0, not 0" "$out/y.json" -- pm0 --max-radius 0
expect 1 "fill-min-radius: must be above 0, not 0" "$out/y.json" -- pm0 --fill-gaps --fill-min-radius 0
expect 1 "min-radius: must be above 0, not 0" "$out/y.json" -- pm0 --min-radius 0
expect 1 "map-given excludes --min-radius" "$out/y.json" -- pm0 --map-given --min-radius 0.01
expect 1 "min-radius: needs a spheres file with candidates (sphere-pack's cover method)" "$out/y.json" -- \
  pm0 --min-radius 0.1
# What proxy-eval's options ask of the proxy is told before the examples are measured.
expect 1 "color-pose: no pose 5 (there are poses 0..1)" "$out/n.ply" -- ev --colors "$out/n.ply" --color-pose 5
check "proxy-eval measured the examples before telling --color-pose is past the poses" \
  bash -c '! "$@" 2>&1 | grep -q median' _ "$bin/proxy-eval" "$out/ok.proxy.json" --rest "$out/in/rest.obj" \
  --pose "$out/in/dent.obj" --colors "$out/n.ply" --color-pose 5
expect 1 "asset: the proxy has no skin" "" -- ev --asset "$out/in/rest.obj"
# More poses than the runtime reads: the count, the limit and what to do about it.
python3 -c "
import json, sys
p = json.load(open(sys.argv[1]))
p['poses'] += [dict(p['poses'][1], name='more-%d' % k) for k in range(298)]
json.dump(p, open(sys.argv[2], 'w'))
" "$out/ok.proxy.json" "$out/many.proxy.json"
expect 3 "many.proxy.json: has 300 poses (the rest and 299 examples); a .spx holds at most 256.*pose-extract --select" \
  "$out/many.spx" -- "$bin/proxy-export" "$out/many.proxy.json" -o "$out/many.spx"
expect 2 "ok.spx: is a runtime .spx file" "$out/o.json" -- "$bin/proxy-export" "$out/ok.spx" -o "$out/o.json"
expect 2 "rest.vdb: is an OpenVDB file" "$out/o.json" -- "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" \
  --spheres "$out/rest.vdb" -o "$out/o.json"
printf 'MeshVersionFormatted 1\nDimension 3\nVertices\n100000000000\n0 0 0 0\n' >"$out/huge.mesh"
expect 2 "huge.mesh: section Vertices claims 100000000000 entries" "$out/o.json" -- "$bin/pose-map" --rest "$out/in/rest.obj" \
  --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/o.json" --tets "$out/huge.mesh"
# A --cache folder that cannot be made (a file in the way, the rest mesh mistyped): refused before
# any work, the file kept as it was.
cp "$out/in/dent.obj" "$out/dent-copy.obj"
expect 4 "Error: .*dent-copy.obj: cannot make the folder: .*dent-copy.obj is a file" "$out/o.json" -- \
  "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/o.json" \
  --cache "$out/dent-copy.obj"
check "--cache wrote over a file" cmp -s "$out/in/dent.obj" "$out/dent-copy.obj"
# ... but a tets file it cannot write (a folder in its place) is a warning: the proxy does not need it.
"$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/c.json" \
  --cache "$out/cache" -q --report "$out/c.report.json"
tets_file=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['tets']['cache']['file'])" "$out/c.report.json")
rm -f "$tets_file" && mkdir "$tets_file"
"$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/dent.obj" --spheres "$out/s.json" -o "$out/c2.json" \
  --cache "$out/cache" 2>"$out/c2.err"
check "--cache: a tets file it cannot write failed the run" test -s "$out/c2.json"
check "--cache: a tets file it cannot write was not warned about" grep -q "warning: .*the tets are not cached" "$out/c2.err"
# A proxy measured or drawn on another mesh (the barrel moved away), or with a manifest of
# another pose count: refused, naming the mesh or the manifest, not measured without a word. How far
# the union pokes out counts the spheres whose centres are outside too (it said 0 % where all were).
/usr/bin/python3 -c "
import sys
out = open(sys.argv[2], 'w')
for line in open(sys.argv[1]):
    w = line.split()
    out.write('v %g %s %s\n' % (float(w[1]) + 100, w[2], w[3]) if w and w[0] == 'v' else line)
" "$out/in/rest.obj" "$out/far.obj"
expect 2 "far.obj: its rest does not hold the proxy's rest spheres (.* centres outside, the union up to [1-9][0-9][0-9][0-9.]* % of its diagonal out): not the mesh the proxy was made from" "" -- \
  "$bin/proxy-eval" "$out/ok.proxy.json" --rest "$out/far.obj" --pose "$out/far.obj"
expect 2 "far.obj: its rest does not hold the proxy's rest spheres (.* centres outside, the union up to [1-9][0-9][0-9][0-9.]* % of its diagonal out): not the mesh the proxy was made from" "$out/far.glb" -- \
  "$bin/proxy-export" "$out/ok.proxy.json" --rest "$out/far.obj" --pose "$out/far.obj" -o "$out/far.glb"
"$bin/pose-extract" "$out/in/barrel-morph.glb" -o "$out/pm" --morph-targets -q
python3 -c "
import json, sys
m = json.load(open(sys.argv[1])); m['poses'].append(dict(m['poses'][0])); json.dump(m, open(sys.argv[2], 'w'))
" "$out/pm/poses.json" "$out/pm/twice.json"
expect 2 "twice.json: lists the pose file '.*' twice" "$out/tw.json" -- "$bin/pose-map" --manifest "$out/pm/twice.json" \
  --spheres "$out/s.json" -o "$out/tw.json"
# The same file written another way ("./dent.obj"): mapped twice without a word before.
python3 -c "
import json, sys
m = json.load(open(sys.argv[1])); again = dict(m['poses'][0]); again['file'] = './' + again['file']; again['name'] += '-again'
m['poses'].append(again); json.dump(m, open(sys.argv[2], 'w'))
" "$out/pm/poses.json" "$out/pm/twice2.json"
expect 2 "twice2.json: lists the pose file '\([^']*\)' twice (the second time as './\1')" "$out/tw.json" -- \
  "$bin/pose-map" --manifest "$out/pm/twice2.json" --spheres "$out/s.json" -o "$out/tw.json"
# A manifest written by hand or by another tool: what the schema requires and no more (no
# generator, no source). It was refused as "missing field 'generator'", which the schema does not
# ask for.
python3 -c "
import json, sys
m = json.load(open(sys.argv[1]))
hand = {'format': 'spx.poses', 'version': 1, 'rest': m['rest'], 'poses': [{'name': p['name'], 'file': p['file']} for p in m['poses']]}
json.dump(hand, open(sys.argv[2], 'w'))
" "$out/pm/poses.json" "$out/pm/hand.json"
check "pose-map refused a hand-written manifest (no generator, no source)" \
  "$bin/pose-map" --manifest "$out/pm/hand.json" --spheres "$out/s.json" -o "$out/hand.proxy.json" -q
check "proxy-eval refused a hand-written manifest" "$bin/proxy-eval" "$out/hand.proxy.json" --manifest "$out/pm/hand.json" -q
expect 2 "pm/poses.json: lists [0-9]* poses; .*ok.proxy.json has 1 example pose$" "" -- \
  "$bin/proxy-eval" "$out/ok.proxy.json" --manifest "$out/pm/poses.json"
# More poses than a .spx holds (the runtime's SPX_MAX_POSES, 256 with the rest): pose-map and
# proxy-eval refuse before any work, naming the manifest or the proxy.
python3 -c "
import json, shutil, sys
out = sys.argv[1]
m = json.load(open(out + '/pm/poses.json'))
first = m['poses'][0]
m['poses'] = [dict(first, name='p%03d' % i, file='p%03d.obj' % i) for i in range(256)]
for i in range(256):
    shutil.copy(out + '/pm/' + first['file'], out + '/pm/p%03d.obj' % i)
json.dump(m, open(out + '/pm/long.json', 'w'))
p = json.load(open(out + '/ok.proxy.json'))
p['poses'] = [dict(p['poses'][-1], name='p%03d' % i) for i in range(257)]
json.dump(p, open(out + '/long.proxy.json', 'w'))
" "$out"
expect 3 "pm/long.json: has 257 poses (the rest and 256 examples); a .spx holds at most 256" "$out/long.json" -- \
  "$bin/pose-map" --manifest "$out/pm/long.json" --spheres "$out/s.json" -o "$out/long.json"
expect 3 "long.proxy.json: has 257 poses .*: map fewer poses" "" -- "$bin/proxy-eval" "$out/long.proxy.json" --manifest "$out/pm/long.json"
if said=$("$1/samples/runtime-demo" --help) && grep -q "usage: runtime-demo" <<<"$said"; then passed=$((passed + 1)); else
  echo "FAIL: runtime-demo --help"; fail=$((fail + 1)); fi

# pose-extract: what the asset lacks, and clip/mesh/frame choices it does not have. No manifest.
glb=$out/in/barrel-morph.glb px=$out/px
expect 2 "rest.obj: has no morph targets" "$px/poses.json" -- "$bin/pose-extract" "$out/in/rest.obj" -o "$px" --morph-targets
expect 2 "rest.obj: has no animation clips" "$px/poses.json" -- "$bin/pose-extract" "$out/in/rest.obj" -o "$px" --animation 0
printf '{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"name":"empty"}]}' >"$out/empty.gltf"
expect 2 "empty.gltf: contains no triangle mesh" "$px/poses.json" -- "$bin/pose-extract" "$out/empty.gltf" -o "$px" --morph-targets
# A glTF whose JSON does not parse, or a GLB of garbage: what is wrong with the file, not assimp's
# "no suitable reader" or "no triangle mesh".
head -c 60 "$out/empty.gltf" >"$out/cut.gltf"
expect 2 "cut.gltf: not a glTF: its JSON does not parse (.*column 61" "$px/poses.json" -- \
  "$bin/pose-extract" "$out/cut.gltf" -o "$px" --morph-targets
python3 -c "
import struct, sys
b = bytearray(open(sys.argv[1], 'rb').read())
b[b.index(b':', 20)] = ord(';')  # the JSON chunk's first colon
open(sys.argv[2], 'wb').write(b)
" "$glb" "$out/bad-json.glb"
expect 2 "bad-json.glb: not a glTF: its JSON does not parse" "$px/poses.json" -- \
  "$bin/pose-extract" "$out/bad-json.glb" -o "$px" --morph-targets
{ printf 'glTF\002\000\000\000\377\377\377\000'; head -c 4000 "$glb" | tail -c 3000; } >"$out/garbage.glb"
expect 2 "garbage.glb: truncated: its header says 16777215 bytes" "$px/poses.json" -- \
  "$bin/pose-extract" "$out/garbage.glb" -o "$px" --morph-targets
# The same files given where a mesh is read (a rest, a pose): the same answers.
expect 2 "cut.gltf: not a glTF: its JSON does not parse (.*column 61" "$out/x.vdb" -- \
  "$bin/sdf-build" "$out/cut.gltf" -o "$out/x.vdb"
expect 2 "garbage.glb: truncated: its header says 16777215 bytes" "$out/x.vdb" -- \
  "$bin/sdf-build" "$out/garbage.glb" -o "$out/x.vdb"
head -c 100 "$out/in/rest.obj" | tr 'v' '\001' >"$out/junk.glb"
expect 2 "junk.glb: not a glTF (neither GLB nor JSON)" "$out/x.vdb" -- "$bin/sdf-build" "$out/junk.glb" -o "$out/x.vdb"
printf '{"asset":{"version":"2.0"}}' >"$out/bare.gltf"
expect 2 "bare.gltf: contains no mesh" "$out/x.vdb" -- "$bin/sdf-build" "$out/bare.gltf" -o "$out/x.vdb"
# JSON of the wrong types where the reader follows buffers: the member named, not a JSON error.
printf '{"asset":{"version":"2.0"},"buffers":[{"uri":5}],"meshes":[{}]}' >"$out/odd-uri.gltf"
expect 2 "odd-uri.gltf: not a glTF 2.0 asset: a buffer's 'uri' is not a string" "$out/x.vdb" -- \
  "$bin/sdf-build" "$out/odd-uri.gltf" -o "$out/x.vdb"
printf '{"asset":{"version":2},"meshes":[{}]}' >"$out/odd-version.gltf"
expect 2 "odd-version.gltf: not a glTF 2.0 asset .no asset.version 2.x" "$px/poses.json" -- \
  "$bin/pose-extract" "$out/odd-version.gltf" -o "$px" --morph-targets
printf '{"asset":{"version":"2.0"},"buffers":[],"bufferViews":[{"buffer":-1}],"meshes":[{}]}' >"$out/odd-view.gltf"
expect 2 "odd-view.gltf: not a glTF 2.0 asset: a bufferView's 'buffer' is not a whole number 0 or above .-1." \
  "$out/x.vdb" -- "$bin/sdf-build" "$out/odd-view.gltf" -o "$out/x.vdb"
expect 2 "bad-json.glb: not a glTF: its JSON does not parse" "$out/o.json" -- "$bin/pose-map" --rest "$out/in/rest.obj" \
  --pose "$out/bad-json.glb" --spheres "$out/s.json" -o "$out/o.json"
expect 1 "\-\-animation: no clip named 'Walk'" "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px" --animation Walk
expect 1 "\-\-animation: no clip 4 " "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px" --animation 4
expect 1 "\-\-mesh: no mesh or node named 'lid'" "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px" --mesh lid --morph-targets
expect 1 "\-\-frames: frame 9 is outside the clip" "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px" --animation 0 --frames 1,9
expect 1 "\-\-times: 4.5 s is outside the clip" "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px" --animation barrel --times 4.5
expect 1 "\-\-times: -1 s is outside the clip" "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px" --animation 0 --times=-1
expect 1 "\-\-times: 0.5 s is asked twice" "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px" --animation 0 --times 0.5,1,0.5
expect 1 "\-\-frames: frame 1 is asked twice" "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px" --animation 0 --frames 1,0,1
# Ranges of frames, both ends in: "3,0-2" is "3,0,1,2" (it was "Could not convert"); a word that is
# neither a frame nor a range names itself.
"$bin/pose-extract" "$glb" -o "$out/ranged" --animation 0 --frames 3,0-2 -q
"$bin/pose-extract" "$glb" -o "$out/listed" --animation 0 --frames 3,0,1,2 -q
check "--frames 3,0-2 wrote other poses than --frames 3,0,1,2" cmp -s "$out/ranged/poses.json" "$out/listed/poses.json"
expect 1 "\-\-frames: '3-1' runs backwards; write it 1-3" "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px" --animation 0 --frames 0,3-1
expect 1 "\-\-frames: '1.5' is not a frame (a whole number from 0) or a range of them (10-20)" "$px/poses.json" -- \
  "$bin/pose-extract" "$glb" -o "$px" --animation 0 --frames 1.5
# Neither --morph-targets nor --animation: the error lists what the asset holds to choose from.
expect 1 "give \-\-morph-targets or \-\-animation .*barrel-morph.glb holds 1 clip: 0 'barrel' (5 frames over 4 s); 3 morph targets" \
  "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px"
expect 1 "\-\-select" "$px/poses.json" -- "$bin/pose-extract" "$glb" -o "$px" --animation 0 --select 0
expect 1 "\-\-manifest" "$out/o.json" -- "$bin/pose-map" --manifest "$out/in/rest.obj" --rest "$out/in/rest.obj" \
  --spheres "$out/s.json" -o "$out/o.json"
expect 2 "rest.obj" "$out/o.json" -- "$bin/pose-map" --manifest "$out/in/rest.obj" --spheres "$out/s.json" -o "$out/o.json"

# An output over an input, or two outputs on one file: refused before any work, the input intact.
cp "$out/in/rest.obj" "$out/mine.obj"
before=$(md5sum <"$out/mine.obj")
expect 1 "output: .*mine.obj is also the input: writing it would overwrite an input" "" -- \
  "$bin/sdf-build" "$out/mine.obj" -o "$out/mine.obj"
check "the input refused as an output is intact" [ "$before" = "$(md5sum <"$out/mine.obj")" ]
cp "$out/s.json" "$out/s-keep.json"
expect 1 "output: .*s-keep.json is also --spheres's file" "" -- "$bin/pose-map" --rest "$out/in/rest.obj" \
  --pose "$out/in/dent.obj" --spheres "$out/s-keep.json" -o "$out/s-keep.json"
expect 1 "report: writes the file --output writes" "$out/same.vdb" -- "$bin/sdf-build" "$out/in/rest.obj" \
  -o "$out/same.vdb" --report "$out/same.vdb"

# A failed run keeps the previous output intact.
"$bin/sdf-build" "$out/in/rest.obj" -o "$out/keep.vdb" --resolution 16 -q
before=$(md5sum <"$out/keep.vdb")
"$bin/sdf-build" "$out/garbage.obj" -o "$out/keep.vdb" 2>/dev/null
after=$(md5sum <"$out/keep.vdb")
if [ "$before" = "$after" ]; then passed=$((passed + 1)); else echo "FAIL: failed run changed keep.vdb"; fail=$((fail + 1)); fi

# A failed run's --report says it failed (an earlier run's "ok" report is not left to be read as
# this one's): status "error", the message and the exit code, by its schema.
"$bin/sdf-build" "$out/in/rest.obj" -o "$out/keep.vdb" --resolution 16 -q --report "$out/run.report.json"
for run in "sdf-build $out/garbage.obj -o $out/keep.vdb:2" "sdf-build $out/in/rest.obj -o $out/keep.vdb --resolution 0:1" \
           "sphere-pack $out/field.txt -o $out/y.json:2" "sdf-build $out/in/rest.obj --no-such-option:1"; do
  args=${run%:*} want=${run##*:}
  # shellcheck disable=SC2086
  "$bin"/$args --report "$out/run.report.json" 2>/dev/null
  check "a failed run's report ($args)" /usr/bin/python3 -c "import json,sys; r=json.load(open(sys.argv[1])); \
sys.exit(0 if r['status']=='error' and r['exit_code']==int(sys.argv[2]) and r['error'] else 1)" "$out/run.report.json" "$want"
  check "a failed run's report validates ($args)" /usr/bin/python3 "$(dirname "$0")/validate_json.py" \
    "$(dirname "$0")/../../schemas" failed-report.schema.json "$out/run.report.json"
done
# A file name that is not UTF-8 (a Latin-1 name from an old archive): the chain runs and its
# reports say the byte as U+FFFD. Writing the report was an internal error (exit 5) after the
# field was written, and a failed run's report was not written at all.
latin=$out/$'caf\xe9'
cp "$out/in/rest.obj" "$latin.obj"
"$bin/sdf-build" "$latin.obj" -o "$latin.vdb" --resolution 32 -q --report "$out/latin-sdf.json" &&
  "$bin/sphere-pack" "$latin.vdb" -o "$latin.spheres.json" --method greedy -q --report "$out/latin-pack.json"
check "a file name that is not UTF-8 (exit $?)" /usr/bin/python3 -c "import json,sys
for f in sys.argv[1:]: assert 'caf\ufffd' in json.dumps(json.load(open(f)), ensure_ascii=False), f" \
  "$out/latin-sdf.json" "$out/latin-pack.json" "$latin.spheres.json"
expect 2 "-gone.obj: cannot open: no such file" "" -- "$bin/sdf-build" "$latin-gone.obj" -o "$out/x.vdb" --report "$out/latin-gone.json"
check "a failed run's report on a file name that is not UTF-8" /usr/bin/python3 -c "import json,sys
r = json.load(open(sys.argv[1])); sys.exit(0 if r['status'] == 'error' and 'caf\ufffd-gone.obj' in r['error'] else 1)" \
  "$out/latin-gone.json"
# ... but never one that names an input.
before=$(md5sum <"$out/mine.obj")
"$bin/sdf-build" "$out/mine.obj" -o "$out/z.vdb" --resolution 0 --report "$out/mine.obj" 2>/dev/null
check "a failed run's report never over an input" [ "$before" = "$(md5sum <"$out/mine.obj")" ]

# Out of memory (an address-space limit stands in for a full machine): exit 3, and what to try
# names the tool's own options (it said "try a coarser --resolution" from every tool, an option
# only sdf-build takes). A mesh assimp had no memory to read is no bad file: it was "cannot read
# mesh: std::bad_alloc", exit 2.
# Under the sanitizers (SPX_SANITIZED, set by the build) a cap on the address space tests
# nothing: ASan reserves terabytes of shadow memory at start, which the cap refuses first.
if [ -n "${SPX_SANITIZED:-}" ]; then
  echo "skipped under the sanitizers: the two out-of-memory checks (ulimit -v)"
else
  expect 3 "Error: sdf-build: out of memory; try a coarser --resolution$" "$out/x.vdb" -- \
    bash -c 'ulimit -v 250000 && exec "$@"' - "$bin/sdf-build" "$out/in/rest.obj" -o "$out/x.vdb" --resolution 600
  awk 'BEGIN { for (i = 0; i < 1500000; i++) print "v", i % 1000, int(i / 1000), i % 7;
               for (i = 1; i < 1500000; i += 3) print "f", i, i + 1, i + 2 }' >"$out/large.obj"
  expect 3 "Error: pose-map: out of memory; try fewer poses, fewer --samples, or a rest field from a coarser sdf-build --resolution$" \
    "$out/y.json" -- bash -c 'ulimit -v 150000 && exec "$@"' - "$bin/pose-map" --rest "$out/large.obj" \
    --pose "$out/large.obj" --spheres "$out/s.json" -o "$out/y.json"
  rm -f "$out/large.obj"
fi

# --help and --version succeed on every tool, and the help ends with the exit codes a script
# branches on, as lib/core/error.hpp numbers them.
codes=$(sed -n '/enum class ExitCode/,/};/p' "$(dirname "$0")/../../lib/core/error.hpp" | grep -o '= [0-9]' | tr -dc '0-9')
check "error.hpp numbers the exit codes 0 to 5 ($codes)" [ "$codes" = 012345 ]
for t in pose-extract sdf-build sphere-pack pose-map proxy-export proxy-eval sample-gen; do
  if help=$("$bin/$t" --help) && said=$("$bin/$t" --version) && grep -q "(spx) " <<<"$said"; then passed=$((passed + 1)); else
    echo "FAIL: $t --help/--version"; fail=$((fail + 1)); fi
  check "$t --help lists the exit codes" eval 'grep -q "^Exit codes:" <<<"$help" &&
    [ "$(grep -c "^  [0-5]  " <<<"$help")" = 6 ] && grep -q "^  2  bad input" <<<"$help" && grep -q "^  4  an output" <<<"$help"'
done
# A bad .spx gives the demo's status line and a non-zero exit.
head -c 50 /dev/urandom >"$out/junk.spx"
if "$1/samples/runtime-demo" "$out/junk.spx" 2>"$out/demo.err"; then echo "FAIL: demo accepted junk"; fail=$((fail + 1));
elif grep -q "not an .spx file\|truncated" "$out/demo.err"; then passed=$((passed + 1)); else
  echo "FAIL: demo said $(cat "$out/demo.err")"; fail=$((fail + 1)); fi

echo "$passed passed, $fail failed"
[ "$fail" = 0 ]
