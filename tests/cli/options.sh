#!/usr/bin/env bash
# Every option does what its help says: each is run and its effect read from the report or the
# output file (GLB and PLY outputs are read back by readback.py, which checks their structure).
# usage: options.sh BUILD_DIR OUT_DIR
set -uo pipefail
bin=$1/apps out=$2 here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$out" && mkdir -p "$out"
passed=0 failed=0
py() { /usr/bin/python3 -c "$@"; }
check() { if eval "$2"; then passed=$((passed + 1)); else echo "FAIL: $1"; failed=$((failed + 1)); fi; }
field() { py "import json,sys; r=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$1" "$2"; }

"$bin/sample-gen" barrel -o "$out/in" -q
rest=$out/in/rest.obj poses=("$out/in/dent.obj" "$out/in/squash.obj" "$out/in/top.obj")
pose_args=()
for p in "${poses[@]}"; do pose_args+=(--pose "$p"); done

# sdf-build: --voxel-size, --band, --memory-limit
"$bin/sdf-build" "$rest" -o "$out/vs.vdb" --voxel-size 0.05 -q --report "$out/vs.json"
check "--voxel-size 0.05 not used" '[ "$(field "$out/vs.json" "r[\"grid\"][\"voxel_size\"]")" = "0.05" ]'
"$bin/sdf-build" "$rest" -o "$out/b3.vdb" --resolution 32 -q --report "$out/b3.json"
"$bin/sdf-build" "$rest" -o "$out/b6.vdb" --resolution 32 --band 6 -q --report "$out/b6.json"
check "--band 6 did not widen the grid" \
  '[ "$(field "$out/b6.json" "r[\"grid\"][\"band_voxels_exterior\"]")" = 6 ] &&
   [ "$(field "$out/b6.json" "r[\"grid\"][\"dims\"][0]")" -gt "$(field "$out/b3.json" "r[\"grid\"][\"dims\"][0]")" ]'
"$bin/sdf-build" "$rest" -o "$out/m.vdb" --resolution 64 --memory-limit 0.00001 -q 2>"$out/m.err"
code=$?
check "--memory-limit 0.00001 did not refuse (exit 3)" '[ "$code" = 3 ] && grep -q "GiB" "$out/m.err" && [ ! -e "$out/m.vdb" ]'
"$bin/sdf-build" "$rest" -o "$out/m.vdb" --resolution 64 --memory-limit 1 -q
check "--memory-limit 1 refused a small grid" '[ -s "$out/m.vdb" ]'

# --threads: a cap above the cores is every core (not a table sized by it), 1 is one.
"$bin/sdf-build" "$rest" -o "$out/t.vdb" --resolution 32 --threads 99999999999999 -q --report "$out/t.json"
check "--threads past the cores failed or said more threads than cores" \
  '[ -s "$out/t.vdb" ] && [ "$(field "$out/t.json" "r[\"threads\"]")" = "$(nproc)" ]'
"$bin/sdf-build" "$rest" -o "$out/t.vdb" --resolution 32 --threads 1 -q --report "$out/t.json"
check "--threads 1 not said in the report" '[ "$(field "$out/t.json" "r[\"threads\"]")" = 1 ]'

# sphere-pack: --grid-centers keeps the greedy method's centers on voxel centers
"$bin/sphere-pack" "$out/b3.vdb" --mesh "$rest" -o "$out/s.json" -q --report "$out/s.report.json" --method greedy
"$bin/sphere-pack" "$out/b3.vdb" --mesh "$rest" -o "$out/g.json" --grid-centers -q --report "$out/g.report.json" \
  --method greedy
check "--grid-centers still refined centers" '[ "$(field "$out/g.report.json" "r[\"pack\"][\"centers_refined\"]")" = 0 ] &&
   [ "$(field "$out/s.report.json" "r[\"pack\"][\"centers_refined\"]")" -gt 0 ]'
check "--grid-centers centers are not on voxel centers" '[ "$(py "
import json,sys
f=json.load(open(sys.argv[1])); h=f[\"voxel_size\"]
print(all(abs(c/h-round(c/h))<1e-6 for s in f[\"spheres\"] for c in s[:3]))" "$out/g.json")" = True ]'
# sphere-pack's --samples, --seed and --every-vertex, kept in the spheres file (the defaults are
# not written), are how pose-map's selection draws each pose's samples unless given its own: the
# same proxy as the same options given to pose-map, and its report says which it drew.
"$bin/sphere-pack" "$out/b3.vdb" --mesh "$rest" -o "$out/sd.json" -q --samples 300 --seed 5 --every-vertex
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/sd.json" -o "$out/sd.proxy.json" -q \
  --report "$out/sd.report.json"
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/sd.json" -o "$out/sd-given.proxy.json" -q \
  --samples 300 --seed 5 --every-vertex
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/sd.json" -o "$out/sd-own.proxy.json" -q \
  --samples 200 --report "$out/sd-own.report.json"
sampled() { field "$1" "$2 == {'area_samples': $3, 'seed': $4, 'every_vertex': $5}"; }
check "sphere-pack --samples 300 --seed 5 --every-vertex: not kept in the spheres file" \
  '[ "$(sampled "$out/sd.json" "r[\"sampling\"]" 300 5 True)" = True ]'
check "pose-map did not draw as the spheres file's sphere-pack did" 'cmp -s "$out/sd.proxy.json" "$out/sd-given.proxy.json" &&
   [ "$(sampled "$out/sd.report.json" "r[\"selection\"][\"sampling\"]" 300 5 True)" = True ]'
check "pose-map --samples 200 did not win over the spheres file's (the rest kept)" \
  '[ "$(sampled "$out/sd-own.report.json" "r[\"selection\"][\"sampling\"]" 200 5 True)" = True ]'
# --min-radius, kept in the spheres file, holds for pose-map's selection too (its own candidates
# brought spheres down to 0.029 back before); pose-map's --min-radius asks it of a file without.
"$bin/sphere-pack" "$out/b3.vdb" --mesh "$rest" -o "$out/mr.json" -q --min-radius 0.05
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/mr.json" -o "$out/mr.proxy.json" -q \
  --report "$out/mr.report.json"
"$bin/sphere-pack" "$out/b3.vdb" --mesh "$rest" -o "$out/m0.json" -q
check "sphere-pack at the default sampling wrote it" '[ "$(field "$out/m0.json" "\"sampling\" in r")" = False ]'
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/m0.json" -o "$out/m0.proxy.json" -q --min-radius 0.05
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/m0.json" -o "$out/m1.proxy.json" -q
least_rest() { py "import json,sys; print(min(s[3] for s in json.load(open(sys.argv[1]))['poses'][0]['spheres']))" "$1"; }
check "sphere-pack --min-radius 0.05: not kept in the spheres file" '[ "$(field "$out/mr.json" "r[\"min_radius_asked\"]")" = 0.05 ]'
check "sphere-pack --min-radius 0.05: pose-map chose a smaller sphere" \
  'py "import sys; sys.exit(not float(sys.argv[1]) >= 0.05)" "$(least_rest "$out/mr.proxy.json")" &&
   [ "$(field "$out/mr.report.json" "r[\"selection\"][\"min_radius\"]")" = 0.05 ] &&
   [ "$(field "$out/mr.report.json" "r[\"selection\"][\"candidates_below_min_radius\"] > 0")" = True ]'
check "pose-map --min-radius 0.05: a smaller sphere chosen, or none smaller without it" \
  'py "import sys; sys.exit(not (float(sys.argv[1]) >= 0.05 > float(sys.argv[2])))" \
     "$(least_rest "$out/m0.proxy.json")" "$(least_rest "$out/m1.proxy.json")"'
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/m0.json" -o "$out/mbig.proxy.json" -q --min-radius 5 \
  2>"$out/mbig.err"
code=$?
check "pose-map --min-radius past every candidate: not exit 1 naming it, or a proxy of no sphere written" \
  '[ "$code" = 1 ] && grep -q "min-radius: 5 leaves no sphere: every candidate is smaller at rest" "$out/mbig.err" &&
   [ ! -e "$out/mbig.proxy.json" ]'
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/m0.json" -o "$out/mmax.proxy.json" -q --max-radius 0.01 \
  --min-radius 0.1 2>"$out/mmax.err"
code=$?
check "pose-map --min-radius over --max-radius: not exit 1 naming it" \
  '[ "$code" = 1 ] && grep -q "min-radius: is larger than the max radius (0.01)" "$out/mmax.err"'
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/mr.json" -o "$out/mmax.proxy.json" -q --max-radius 0.01 \
  2>"$out/mmax.err"
code=$?
check "pose-map --max-radius under the file's --min-radius: not exit 1 naming it" \
  '[ "$code" = 1 ] && grep -q "max-radius: is smaller than the spheres file.s min radius (0.05" "$out/mmax.err"'
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/mr.json" -o "$out/mmax.proxy.json" -q --max-radius 0.01 \
  --map-given
check "pose-map --map-given refused a --max-radius under a min radius it does not select by" '[ -s "$out/mmax.proxy.json" ]'
# --cache: the candidates written by a run at one tolerance, read by a run at another (the same
# folder pose-map keeps its tets in), which writes the spheres a run without it writes.
"$bin/sphere-pack" "$out/b3.vdb" --mesh "$rest" -o "$out/k1.json" -q --tolerance 5% --cache "$out/cache/tools" \
  --report "$out/k1.report.json"
"$bin/sphere-pack" "$out/b3.vdb" --mesh "$rest" -o "$out/k2.json" -q --cache "$out/cache/tools" --report "$out/k2.report.json"
"$bin/sphere-pack" "$out/b3.vdb" --mesh "$rest" -o "$out/k0.json" -q
check "sphere-pack --cache: not written, then not read" \
  '[ "$(field "$out/k1.report.json" "r[\"cover\"][\"cache\"][\"voxel_candidates_read\"]")" = False ] &&
   [ "$(field "$out/k2.report.json" "r[\"cover\"][\"cache\"][\"voxel_candidates_read\"]")" = True ] &&
   [ "$(field "$out/k2.report.json" "r[\"cover\"][\"cache\"][\"sample_balls_made\"]")" = 0 ]'
check "sphere-pack --cache: a report that does not fit its schema" \
  '/usr/bin/python3 "$here/validate_json.py" "$here/../../schemas" sphere-pack-report.schema.json "$out/k1.report.json" \
     "$out/k2.report.json" >/dev/null 2>&1'
check "sphere-pack --cache: the spheres differ from a run without it" 'cmp -s "$out/k0.json" "$out/k2.json"'
# --max-spheres past what any error needs: the spheres used are said, fewer than asked.
said=$("$bin/sphere-pack" "$out/b3.vdb" --mesh "$rest" -o "$out/many.json" --max-spheres 100000 --polish 0 \
  --report "$out/many.report.json" 2>&1)
check "--max-spheres 100000: the spheres used not said" \
  'grep -q "of the 100000 spheres asked: no other candidate lowered any sample" <<<"$said" &&
   [ "$(field "$out/many.json" "len(r[\"spheres\"])")" -lt 100000 ]'
check "--max-spheres 100000: the report says max_spheres decided" \
  '[ "$(field "$out/many.report.json" "r[\"cover\"][\"limited_by\"].startswith(\"the candidates\")")" = True ]'

# pose-map: --tet-size, --tets, --max-radius, the --fill-* options
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/s.json" -o "$out/p.proxy.json" -q --report "$out/p.json"
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/s.json" -o "$out/t.proxy.json" --tet-size 0.3 -q \
  --report "$out/t.json"
check "--tet-size 0.3 did not coarsen the tets" \
  '[ "$(field "$out/t.json" "r[\"tets\"][\"vertices\"]")" -lt "$(field "$out/p.json" "r[\"tets\"][\"vertices\"]")" ]'
# --cache: the tets written by the first run (the folder made, its report in it), read by the
# next, the same proxy as meshing gives.
for run in 1 2; do
  "$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/s.json" -o "$out/c$run.proxy.json" -q \
    --cache "$out/cache/tools" --report "$out/cache/tools/c$run.json"
done
check "--cache: not written, then not read" \
  '[ "$(field "$out/cache/tools/c1.json" "r[\"tets\"][\"cache\"][\"read\"]")" = False ] &&
   [ "$(field "$out/cache/tools/c2.json" "r[\"tets\"][\"cache\"][\"read\"]")" = True ] &&
   head -1 "$(field "$out/cache/tools/c2.json" "r[\"tets\"][\"cache\"][\"file\"]")" | grep -q "^# spx tets cache "'
check "--cache: a report that does not fit its schema" \
  '/usr/bin/python3 "$here/validate_json.py" "$here/../../schemas" pose-map-report.schema.json "$out/cache/tools/c1.json" \
     "$out/cache/tools/c2.json" >/dev/null 2>&1'
check "--cache: the proxy differs from the one meshed afresh" \
  'cmp -s "$out/p.proxy.json" "$out/c1.proxy.json" && cmp -s "$out/p.proxy.json" "$out/c2.proxy.json"'
# ... and each pose's field's part (sphere-pack's candidates at 1 %, where poses are asked for their own):
# written by the first run, read by the next (nothing grown again), the proxy as built afresh.
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/k0.json" -o "$out/f1.proxy.json" -q --tolerance 1%
for run in 1 2; do
  "$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/k0.json" -o "$out/f1c$run.proxy.json" -q \
    --tolerance 1% --cache "$out/cache/tools" --report "$out/cache/tools/f1c$run.json"
done
poses_cached=$(py "
import json,sys
a, b = ([p['cache'] for p in json.load(open(f))['poses']] for f in sys.argv[1:3])
written = sum(1 for c in a if c and not c['read'] and c['candidates_grown'] > 0)
read = all(c['read'] and c['candidates_grown'] == 0 for c in b if c)
print(written > 0 and read and [c and c['file'] for c in a] == [c and c['file'] for c in b])" \
  "$out/cache/tools/f1c1.json" "$out/cache/tools/f1c2.json")
check "--cache: no pose's field written, then read" '[ "$poses_cached" = True ]'
check "--cache: a poses' report that does not fit its schema" \
  '/usr/bin/python3 "$here/validate_json.py" "$here/../../schemas" pose-map-report.schema.json "$out/cache/tools/f1c1.json" \
     "$out/cache/tools/f1c2.json" >/dev/null 2>&1'
check "--cache: the poses' fields from the cache map another proxy" \
  'cmp -s "$out/f1.proxy.json" "$out/f1c1.proxy.json" && cmp -s "$out/f1.proxy.json" "$out/f1c2.proxy.json"'
# A pose's file it cannot write (a folder in its place) is a warning: the proxy does not need it.
pose_file=$(py "
import json,sys
print(next(p['cache']['file'] for p in json.load(open(sys.argv[1]))['poses'] if p['cache']))" "$out/cache/tools/f1c1.json")
rm -f "$pose_file" && mkdir "$pose_file"
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/k0.json" -o "$out/f1c3.proxy.json" \
  --tolerance 1% --cache "$out/cache/tools" 2>"$out/f1c3.err"
check "--cache: a pose's file it cannot write changed the proxy" 'cmp -s "$out/f1.proxy.json" "$out/f1c3.proxy.json"'
check "--cache: a pose's file it cannot write was not warned about" \
  'grep -q "warning: .*: a pose.s field is not cached" "$out/f1c3.err"'
# --cache-limit: the folder's other cache files (sphere-pack's candidates, other runs' tets and
# poses) removed, least recently used first; this run's kept, and the same proxy.
mkdir -p "$out/cache/lim" && cp "$out"/cache/tools/*-*.* "$out/cache/lim/" 2>/dev/null
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/k0.json" -o "$out/f1c4.proxy.json" -q \
  --tolerance 1% --cache "$out/cache/lim" --cache-limit 1kb --report "$out/f1c4.json"
trimmed=$(py "
import json,os,sys
r=json.load(open(sys.argv[1])); c=r['cache_folder']
used={os.path.basename(p['cache']['file']) for p in r['poses'] if p['cache']} | {os.path.basename(r['tets']['cache']['file'])}
left={f for f in os.listdir(sys.argv[2]) if '-' in f and not f.endswith('.json')}
print(c['limit_bytes'] == 1024 and c['files_removed'] > 0 and left == used and c['files_kept'] == len(used)
      and c['bytes_kept'] == sum(os.path.getsize(os.path.join(sys.argv[2], f)) for f in used))" \
  "$out/f1c4.json" "$out/cache/lim")
check "--cache-limit 1kb: kept another run's file or removed this run's" '[ "$trimmed" = True ]'
check "--cache-limit 1kb: the proxy changed" 'cmp -s "$out/f1.proxy.json" "$out/f1c4.proxy.json"'
check "--cache-limit: a report that does not fit its schema, or a limit not 4 GiB by default" \
  '/usr/bin/python3 "$here/validate_json.py" "$here/../../schemas" pose-map-report.schema.json "$out/f1c4.json" \
     >/dev/null 2>&1 && [ "$(field "$out/cache/tools/f1c2.json" "r[\"cache_folder\"][\"limit_bytes\"]")" = 4294967296 ]'
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/s.json" -o "$out/r.proxy.json" --max-radius 0.1 -q
check "--max-radius 0.1 exceeded" '[ "$(py "
import json,sys
p=json.load(open(sys.argv[1])); print(max(s[3] for q in p[\"poses\"] for s in q[\"spheres\"]) <= 0.1)" "$out/r.proxy.json")" = True ]'
"$bin/pose-map" --rest "$rest" "${pose_args[@]}" --spheres "$out/s.json" -o "$out/f.proxy.json" -q --report "$out/f.json" \
  --fill-gaps --fill-tolerance 1% --fill-min-radius 0.02 --fill-max 2
check "--fill-max 2 / --fill-min-radius 0.02 not honoured" '[ "$(py "
import json,sys
f=json.load(open(sys.argv[1]))[\"fill_gaps\"]
print(f[\"min_radius\"] == 0.02 and all(p[\"added\"] <= 2 for p in f[\"poses\"]) and f[\"spheres_after\"] > f[\"spheres_before\"])" "$out/f.json")" = True ]'
# A user tet mesh (MEDIT) of a box: 5 tets, the pose a shifted box.
cat >"$out/box.obj" <<'OBJ'
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
v 0 0 1
v 1 0 1
v 0 1 1
v 1 1 1
f 1 3 2
f 2 3 4
f 5 6 7
f 6 8 7
f 1 2 5
f 2 6 5
f 3 7 4
f 4 7 8
f 1 5 3
f 3 5 7
f 2 4 6
f 4 8 6
OBJ
sed 's/^v \([0-9]\) /v 1\1 /' "$out/box.obj" | sed 's/^v 10 /v 0.5 /; s/^v 11 /v 1.5 /' >"$out/box-moved.obj"
printf 'MeshVersionFormatted 1\nDimension 3\nVertices\n8\n0 0 0 0\n1 0 0 0\n0 1 0 0\n1 1 0 0\n0 0 1 0\n1 0 1 0\n0 1 1 0\n1 1 1 0\nTetrahedra\n5\n1 2 3 5 1\n2 4 3 8 1\n2 5 6 8 1\n3 5 8 7 1\n2 3 5 8 1\nEnd\n' >"$out/box.mesh"
"$bin/sdf-build" "$out/box.obj" -o "$out/box.vdb" --resolution 16 -q
"$bin/sphere-pack" "$out/box.vdb" --mesh "$out/box.obj" -o "$out/box.spheres.json" -q
"$bin/pose-map" --rest "$out/box.obj" --pose "$out/box-moved.obj" --spheres "$out/box.spheres.json" --tets "$out/box.mesh" \
  -o "$out/box.proxy.json" -q --report "$out/box.json"
check "--tets box.mesh not used" '[ "$(field "$out/box.json" "r[\"tets\"][\"tetrahedra\"]")" = 5 ] &&
  [ "$(field "$out/box.json" "r[\"tets\"][\"method\"]")" = "user tets" ]'
check "--tets: a shifted box did not shift the spheres by 0.5" '[ "$(py "
import json,sys
p=json.load(open(sys.argv[1]))[\"poses\"]
print(all(abs(b[0]-a[0]-0.5)<1e-9 and abs(b[3]-a[3])<1e-9 for a,b in zip(p[0][\"spheres\"],p[1][\"spheres\"])))" "$out/box.proxy.json")" = True ]'

# proxy-eval: --seed, --blends, --coverage-samples, --colors with --color-pose and --color-scale
ev() { "$bin/proxy-eval" "$out/p.proxy.json" --rest "$rest" "${pose_args[@]}" -q "$@"; }
# 4 examples: the 6 midpoints come first, then random blends drawn with the seed.
ev --seed 3 --blends 8 --report "$out/e3.json"
ev --seed 3 --blends 8 --report "$out/e3b.json"
ev --seed 4 --blends 8 --report "$out/e4.json"
same() { py "import json,sys; a,b=(json.load(open(f))['blends']['samples'] for f in sys.argv[1:3]); print(a==b)" "$1" "$2"; }
check "--seed: same seed gave other blends" '[ "$(same "$out/e3.json" "$out/e3b.json")" = True ]'
check "--seed: another seed gave the same blends" '[ "$(same "$out/e3.json" "$out/e4.json")" = False ]'
check "--blends 8 did not give 8 blends" '[ "$(field "$out/e3.json" "r[\"blends\"][\"count\"]")" = 8 ]'
ev --coverage-samples 8 --report "$out/c8.json"
ev --coverage-samples 40 --report "$out/c40.json"
check "--coverage-samples changed nothing" '[ "$(field "$out/c8.json" "r[\"poses\"][0][\"coverage\"]")" != "$(field "$out/c40.json" "r[\"poses\"][0][\"coverage\"]")" ]'
ev --colors "$out/c1.ply" --color-pose 1 --color-scale 0.01 --report "$out/col.json"
ev --colors "$out/c0.ply" --color-pose 0
check "--color-scale 0.01 not used" '[ "$(field "$out/col.json" "r[\"colors\"][\"scale\"]")" = 0.01 ]'
check "--color-pose: pose 1 and pose 0 wrote the same PLY" '! cmp -s "$out/c1.ply" "$out/c0.ply"'
check "--colors .ply does not read back with colours" \
  '[ "$(py "import json,sys; print(json.loads(sys.argv[1])[\"colors\"])" "$("$here/readback.py" "$out/c1.ply")")" = True ]'
ev --colors "$out/c.glb"
check "--colors .glb does not read back" '"$here/readback.py" "$out/c.glb" >/dev/null'

# proxy-export: --ply-pose, --stacked, --rest/--pose; GLB and PLY read back
"$bin/proxy-export" "$out/p.proxy.json" -o "$out/x0.ply" -q
"$bin/proxy-export" "$out/p.proxy.json" -o "$out/x2.ply" --ply-pose 2 -q
b0=$("$here/readback.py" "$out/x0.ply") b2=$("$here/readback.py" "$out/x2.ply")
check "--ply-pose 2 wrote the rest pose" '[ "$b0" != "$b2" ]'
check "PLY spheres outside the proxy's bounds" '[ "$(py "
import json,sys
b=json.loads(sys.argv[1])[\"bounds\"]; p=json.load(open(sys.argv[2]))[\"poses\"][0][\"spheres\"]
lo=[min(s[k]-s[3] for s in p if s[3]>0) for k in range(3)]; hi=[max(s[k]+s[3] for s in p if s[3]>0) for k in range(3)]
print(all(lo[k]-1e-3<=b[0][k] and b[1][k]<=hi[k]+1e-3 and b[1][k]-b[0][k] > 0.9*(hi[k]-lo[k]) for k in range(3)))" "$b0" "$out/p.proxy.json")" = True ]'
"$bin/proxy-export" "$out/p.proxy.json" -o "$out/spread.glb" -q
"$bin/proxy-export" "$out/p.proxy.json" -o "$out/stacked.glb" --stacked -q
"$bin/proxy-export" "$out/p.proxy.json" -o "$out/meshes.glb" --rest "$rest" "${pose_args[@]}" -q
s1=$("$here/readback.py" "$out/spread.glb") s2=$("$here/readback.py" "$out/stacked.glb") s3=$("$here/readback.py" "$out/meshes.glb")
check "GLB does not read back" '[ -n "$s1" ] && [ -n "$s2" ] && [ -n "$s3" ]'
check "--stacked: poses not in place, or not spread without it" '[ "$(py "
import json,sys
a=json.loads(sys.argv[1]); b=json.loads(sys.argv[2])
print(a[\"vertices\"]==b[\"vertices\"] and a[\"vertices\"]>0 and (a[\"bounds\"][1][0]-a[\"bounds\"][0][0]) + (sum(abs(t[0]) for t in a[\"translations\"])) > (b[\"bounds\"][1][0]-b[\"bounds\"][0][0]) + (sum(abs(t[0]) for t in b[\"translations\"])))" "$s1" "$s2")" = True ]'
check "--rest/--pose: no pose meshes in the GLB" '[ "$(py "
import json,sys
a=json.loads(sys.argv[1]); c=json.loads(sys.argv[2]); print(c[\"vertices\"] > a[\"vertices\"])" "$s1" "$s3")" = True ]'

# A deep output folder (a farm's paths run long) and a long pose name: each tool's summary line
# keeps its end, where the counts and what limited the run are.
deep=$out/$(printf 'd%.0s' {1..120})/$(printf 'e%.0s' {1..120})
mkdir -p "$deep"
long_name=$(printf 'p%.0s' {1..250})  # with .obj, the longest name a file can have
cp "${poses[0]}" "$deep/$long_name.obj"
"$bin/sdf-build" "$rest" -o "$deep/rest.vdb" --resolution 32 2>"$out/deep.log"
"$bin/sphere-pack" "$deep/rest.vdb" -o "$deep/s.json" --max-spheres 1 2>>"$out/deep.log"
"$bin/pose-map" --rest "$rest" --pose "$deep/$long_name.obj" --spheres "$deep/s.json" -o "$deep/p.json" 2>>"$out/deep.log"
"$bin/proxy-eval" "$deep/p.json" --rest "$rest" --pose "$deep/$long_name.obj" 2>>"$out/deep.log"
check "a deep output path cut sdf-build's line short" "grep -q '^sdf-build: $deep/rest.vdb: [0-9]* triangles -> .* inside\$' '$out/deep.log'"
check "a deep output path cut sphere-pack's line short" "grep -q '^sphere-pack: $deep/s.json: 1 sphere, radii .*; limited by max_spheres\$' '$out/deep.log'"
check "a deep output path cut pose-map's line short" "grep -q '^pose-map: $deep/p.json: 1 sphere x 2 poses, 1 blend site, max error [0-9.e+-]* ([0-9.e+-]*% of the diagonal) in \\(the rest\\|pose $long_name\\); limited by max_spheres\$' '$out/deep.log'"
check "a long pose name cut pose-map's pose line short" "grep -q '^pose-map:   $long_name error median .*, [0-9]* centres\\? outside\$' '$out/deep.log'"
check "a long pose name cut proxy-eval's pose line short" "grep -q '^proxy-eval: $long_name median .* coverage [0-9.]*\$' '$out/deep.log'"

# The summary lines say the tolerance each met (the default goes unsaid otherwise) and the max
# error, the figures their reports hold; proxy-eval finds every pose's max within what pose-map
# says it met.
"$bin/sphere-pack" "$deep/rest.vdb" --mesh "$rest" -o "$out/met.json" --report "$out/met.pack.json" 2>"$out/met.log"
"$bin/pose-map" --rest "$rest" --pose "${poses[@]}" --spheres "$out/met.json" -o "$out/met.proxy.json" \
  --report "$out/met.map.json" 2>>"$out/met.log"
"$bin/proxy-eval" "$out/met.proxy.json" --rest "$rest" --pose "${poses[@]}" --report "$out/met.eval.json" -q
check "the summary lines name the tolerance met and the max error, as the reports" '[ "$(py "
import json, re, sys
log = open(sys.argv[1]).read(); pack = json.load(open(sys.argv[2]))[\"tolerance\"]; sel = json.load(open(sys.argv[3]))
m = re.search(r\"met.json: \d+ spheres, radii \S+, max error (\S+) \((\S+)% of the diagonal\); met the default tolerance 2% \((\S+)\)$\", log, re.M)
p = re.search(r\"met.proxy.json: .*; met the tolerance (\S+) \(2% of the diagonal\) in every pose$\", log, re.M)
close = lambda a, b: abs(a - b) <= 1e-3 * abs(b)
ok = m and p and close(float(m[1]), pack[\"max_error\"]) and close(float(m[3]), pack[\"target\"]) and float(m[2]) <= 2
evaluated = json.load(open(sys.argv[4]))[\"poses\"]
ok = ok and close(float(p[1]), sel[\"selection\"][\"target\"]) and len(evaluated) == 1 + len(sys.argv[5:])
ok = ok and all(q[\"max\"] <= sel[\"selection\"][\"target\"] for q in evaluated)
print(bool(ok))" "$out/met.log" "$out/met.pack.json" "$out/met.map.json" "$out/met.eval.json" "${poses[@]}")" = True ]'

echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
