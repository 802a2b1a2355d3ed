#!/usr/bin/env bash
# pose-extract in the batch pipeline: the samples Makefile from an asset to a .spx (morph
# targets, and a skinned clip with --select), up to date on a second run, byte-identical
# extraction twice, schema-valid manifest and report, pose-map/proxy-eval --manifest.
# usage: extract.sh BUILD_DIR SOURCE_DIR OUT_DIR [SHARED_DATA]
set -euo pipefail
source "$(dirname "$0")/expect.sh"
start_cli_test "$1" "$2" "$3"
data=${4:-}
v() { /usr/bin/python3 "$src/tests/cli/validate_json.py" "$src/schemas" "$@" >/dev/null; }

"$bin/sample-gen" car -o "$out/in" -q
m="make -s -C $src/samples BIN=$bin OUT=$out RES=48"
started=$(date +%s)
$m NAME=car-morph ASSET_FILE="$out/in/car-morph.glb" EXTRACT_FLAGS=--morph-targets QUIET=1 > "$out/quiet.log" 2>&1
check "morph-target asset: no .spx" test -s "$out/car-morph/car-morph.spx"
check "make QUIET=1: a tool printed more than errors" test ! -s "$out/quiet.log"
check "morph-target asset: poses.json schema" v poses.schema.json "$out/car-morph/poses/poses.json"
check "morph-target asset: report schema" v pose-extract-report.schema.json "$out/car-morph/extract.report.json"
check "make would rerun an up-to-date chain" $m NAME=car-morph ASSET_FILE="$out/in/car-morph.glb" -q
# The demo's summary: the times of this run, and, where nothing ran since, says whose times they are.
# Read whole, then matched: grep -q would close the pipe while summary.py still prints (a broken pipe).
summary_says() { local said; said=$(/usr/bin/python3 "$src/scripts/summary.py" "$out/car-morph" --ran-since "$1") && grep -q "$2" <<<"$said"; }
check "summary: a chain that ran is not called up to date" summary_says "$started" "^time: pose-extract"
check "summary: an up-to-date chain's times are not called this run's" \
  summary_says "$(( $(date +%s) + 1 ))" "^time (nothing ran, every output was up to date"
# A warning reaches whoever runs make (the tools are not quiet unless QUIET=1), and the demo's
# summary, whose make is quiet, repeats the reports' warnings: spheres no smaller than 0.5 m miss
# the car's tolerance.
$m NAME=car-warn ASSET_FILE="$out/in/car-morph.glb" EXTRACT_FLAGS=--morph-targets PACK_FLAGS="--min-radius 0.5" \
  > "$out/warn.log" 2>&1
check "make: a tool's summary line is not shown" grep -q "^sphere-pack: .*rest.spheres.json: [0-9]* spheres" "$out/warn.log"
check "make: a tool's warning is not shown" grep -q "^sphere-pack: warning: tolerance .* not met" "$out/warn.log"
summary_warns() { local said; said=$(/usr/bin/python3 "$src/scripts/summary.py" "$1") && grep -q "$2" <<<"$said"; }
check "summary: the reports' warnings are not repeated" \
  summary_warns "$out/car-warn" "^  sphere-pack: tolerance .* not met"
check "summary: a chain with no warning is said to have some" \
  bash -c '! /usr/bin/python3 "$1" "$2" | grep -q "^warnings"' _ "$src/scripts/summary.py" "$out/car-morph"
# The poses are the sample's OBJ poses, number for number.
for p in rest front rear side roof; do
  check "$p.obj differs from the sample's" cmp -s <(grep -v '^#' "$out/in/$p.obj") <(grep -v '^#' "$out/car-morph/poses/$p.obj")
done
# Twice: the same bytes.
"$bin/pose-extract" "$out/in/car-morph.glb" -o "$out/again" --morph-targets -q
for f in rest.obj front.obj roof.obj poses.json; do
  check "$f differs between two runs" cmp -s "$out/car-morph/poses/$f" "$out/again/$f"
done
# proxy-eval reads the same manifest.
"$bin/proxy-eval" "$out/car-morph/car-morph.proxy.json" --manifest "$out/car-morph/poses/poses.json" \
  --report "$out/eval.json" > "$out/eval.log" 2>&1
check "proxy-eval: a proxy without a skin is played by its blends, and no line says otherwise" \
  bash -c '! grep -q "by its skin\|host skins" "$1"' _ "$out/eval.log"
check "proxy-eval --manifest: the rest and 4 poses" \
  /usr/bin/python3 -c "import json,sys; sys.exit(len(json.load(open(sys.argv[1]))['poses']) != 5)" "$out/eval.json"
# Over the asset's clip of morph weights, as a host plays it: each crumple in turn, then all four
# at once. The morph blend at the crumples is the proxy's error there, and it holds better than
# the global blend where the crumples add up.
"$bin/proxy-eval" "$out/car-morph/car-morph.proxy.json" --manifest "$out/car-morph/poses/poses.json" \
  --asset "$out/in/car-morph.glb" --tolerance 2% --chart "$out/morph-clip.svg" --report "$out/morph-clip.json" \
  > "$out/morph-clip.log" 2>&1
check "proxy-eval --asset of morph targets: report schema" v proxy-eval-report.schema.json "$out/morph-clip.json"
check "proxy-eval --asset of morph targets: no chart" grep -q "morph blend (spx::blend_morph)" "$out/morph-clip.svg"
check "proxy-eval --asset of morph targets: the clip's frames measured as the morph weights say" /usr/bin/python3 - \
  "$out/morph-clip.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
m, poses = r["motion"], {p["name"]: p for p in r["poses"]}
assert m["morph_targets"] == ["front", "rear", "side", "roof"] and m["morph_targets_without_examples"] == [], m["morph_targets"]
s = m["summary"]
assert (s["morph_blend"]["frames_seen"]["frames"], s["morph_blend"]["frames_unseen"]["frames"], m["times"]) == (5, 1, 11), s
for f in m["frames"]:
    w = f["morph_weights"]
    if f["seen"]:  # the rest or one crumple: the proxy's own spheres there
        name = "rest" if not any(w) else ["front", "rear", "side", "roof"][w.index(1)]
        want = poses[name]["max"]
        assert abs(f["morph_blend"]["max"] - want) <= 1e-6 * want, (f, poses[name])
last = m["frames"][-1]
assert last["morph_weights"] == [1, 1, 1, 1] and not last["seen"], last
assert last["morph_blend"]["max"] < last["global_blend"]["max"], last
assert last["morph_blend"]["overshoot"] < last["global_blend"]["overshoot"], last
PY
# Held over the blends (the crumples taken two and more at once, as morph targets add): no sphere
# pokes out anywhere in the clip, at the price of the examples' error, which pose-map says.
"$bin/pose-map" --manifest "$out/car-morph/poses/poses.json" --spheres "$out/car-morph/rest.spheres.json" \
  -o "$out/held.proxy.json" --hold-over-blends --report "$out/held.report.json" > "$out/held.log" 2>&1
check "pose-map --hold-over-blends: report schema" v pose-map-report.schema.json "$out/held.report.json"
check "pose-map --hold-over-blends: the tolerance lost at the examples is not said" \
  grep -q "warning: --hold-over-blends: max error .* past the tolerance" "$out/held.log"
"$bin/proxy-eval" "$out/held.proxy.json" --manifest "$out/car-morph/poses/poses.json" --asset "$out/in/car-morph.glb" \
  --report "$out/held-clip.json" > /dev/null 2>&1
check "pose-map --hold-over-blends: a sphere pokes out over the morph clip" /usr/bin/python3 - \
  "$out/held-clip.json" "$out/held.report.json" <<'PY'
import json, sys
m, held = json.load(open(sys.argv[1]))["motion"], json.load(open(sys.argv[2]))["hold_over_blends"]
assert held["blends"] == 21 and held["overshoot_before"] > 0 and held["tolerance_kept"] is False, held
worst = m["summary"]["morph_blend"]["all"]["percent_of_diagonal"]["overshoot_worst"]  # the .spx's float32 alone
assert worst < 1e-4 and m["summary"]["morph_blend"]["all"]["frames_with_centers_outside"] == 0, m["summary"]["morph_blend"]
PY
# A clip weighing a target at 1e30: no host's blend adds that; the asset is named, not the proxy.
/usr/bin/python3 - "$out/in/car-morph.glb" "$out/huge-weight.glb" <<'PY'
import json, struct, sys
b = bytearray(open(sys.argv[1], "rb").read())
n = struct.unpack_from("<I", b, 12)[0]
doc = json.loads(bytes(b[20:20 + n]))
acc = doc["accessors"][doc["animations"][0]["samplers"][0]["output"]]
at = 20 + n + 8 + doc["bufferViews"][acc["bufferView"]].get("byteOffset", 0) + acc.get("byteOffset", 0)
struct.pack_into("<f", b, at + 4 * 5, 1e30)  # key 1's weight of target 1
open(sys.argv[2], "wb").write(b)
PY
set +e
expect 2 "huge-weight.glb: clip 'car' at 0.500000 s weighs its morph targets (.*) past what a host's blend can add" \
  "" -- "$bin/proxy-eval" "$out/car-morph/car-morph.proxy.json" --asset "$out/huge-weight.glb" \
  --report "$out/huge.json"
set -e

if [ -n "$data" ] && [ -e "$data/rigged-simple/RiggedSimple.glb" ]; then
  $m NAME=rigged ASSET_FILE="$data/rigged-simple/RiggedSimple.glb" EXTRACT_FLAGS="--animation 0 --select 2"
  check "skinned clip: no .spx" test -s "$out/rigged/rigged.spx"
  # RiggedSimple's fold keeps balls of a millionth of its diagonal: said, and counted (none on the car).
  check "skinned clip: pose-map did not say which spheres are too small to collide with" /usr/bin/python3 - \
    "$out/rigged/posemap.report.json" "$out/car-morph/posemap.report.json" "$out/car-morph/pack.report.json" <<'PY'
import json, sys
rigged, car, car_pack = (json.load(open(f)) for f in sys.argv[1:4])
t = rigged["tiny_spheres"]
assert t["count"] >= 1 and any("too small for a host to collide with" in w for w in rigged["warnings"]), t
assert car["tiny_spheres"]["count"] == 0 == car_pack["tiny_spheres"]["count"], car["tiny_spheres"]
PY
  check "skinned clip: poses.json schema" v poses.schema.json "$out/rigged/poses/poses.json"
  check "skinned clip: report schema" v pose-extract-report.schema.json "$out/rigged/extract.report.json"
  check "skinned clip: 2 poses kept" /usr/bin/python3 -c \
    "import json,sys; sys.exit(len(json.load(open(sys.argv[1]))['poses']) != 2)" "$out/rigged/poses/poses.json"
  check "skinned clip: skin.json schema" v skin.schema.json "$out/rigged/poses/skin.json"
  check "skinned clip: the skin has 2 joints, 2 poses and a weight per rest vertex" /usr/bin/python3 -c \
    "import json,sys; s=json.load(open(sys.argv[1])); n=sum(1 for l in open(sys.argv[2]) if l.startswith('v '));
sys.exit(not (len(s['joints']) == 2 and len(s['poses']) == 2 and len(s['vertex_weights']) == n == len(s['vertex_positions'])))" \
    "$out/rigged/poses/skin.json" "$out/rigged/poses/rest.obj"
  check "skinned clip: the .spx has the skin" /usr/bin/python3 -c \
    "import sys; b=open(sys.argv[1],'rb').read(); sys.exit(not (b[10] == 1 and b[38] == 1))" "$out/rigged/rigged.spx"
  # The proxy calls a clip's poses by the manifest's names (the clip and the time), as the skin does.
  check "skinned clip: the proxy's pose names are the manifest's and the skin's" /usr/bin/python3 - \
    "$out/rigged/rigged.proxy.json" "$out/rigged/poses/poses.json" "$out/rigged/poses/skin.json" <<'PY'
import json, sys
proxy, manifest, skin = (json.load(open(f)) for f in sys.argv[1:4])
names = [p["name"] for p in proxy["poses"]][1:]
assert names == [p["name"] for p in manifest["poses"]] == [p["name"] for p in skin["poses"]], names
assert all("@" in n for n in names), names
PY
  "$bin/proxy-eval" "$out/rigged/rigged.proxy.json" --manifest "$out/rigged/poses/poses.json" -q \
    --report "$out/rigged/eval.json"
  check "skinned clip: proxy-eval --manifest finds the proxy's pose names, no warning" /usr/bin/python3 -c \
    "import json,sys; r=json.load(open(sys.argv[1])); sys.exit(any('matched by order' in w for w in r['warnings']))" \
    "$out/rigged/eval.json"

  "$bin/proxy-eval" "$out/rigged/rigged.proxy.json" --manifest "$out/rigged/poses/poses.json" > "$out/rigged/eval.log" 2>&1
  check "skinned clip: proxy-eval without --asset names it (blends of a clip's frames are no motion of it)" \
    grep -q "plays this proxy by its skin.*--asset" "$out/rigged/eval.log"
  check "skinned clip: proxy-eval's blends line says a host skins the proxy instead" \
    grep -q "blends .* over .* blends (a host skins this proxy instead)" "$out/rigged/eval.log"

  # The whole clip as a host plays it (proxy-eval --asset): each frame and half-way between.
  # At the 2 frames the chain saw, no sphere pokes out and the best-fit blend is that example's
  # spheres, which the skin gives too (vertex orders of the asset and the OBJ poses agree).
  rig="$data/rigged-simple/RiggedSimple.glb" r="$out/rigged"
  "$bin/proxy-eval" "$r/rigged.proxy.json" --manifest "$r/poses/poses.json" --asset "$rig" --animation 0 \
    --tolerance 2% --chart "$r/motion.svg" -q --report "$r/motion.json"
  check "motion: report schema" v proxy-eval-report.schema.json "$r/motion.json"
  check "motion: chart drawn" grep -q "<polyline" "$r/motion.svg"
  check "motion: the frames seen, and between them" /usr/bin/python3 - "$r/motion.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))["motion"]
rows, d = m["frames"], m["diagonal"]
seen = [f for f in rows if f["seen"]]
assert len(seen) == 2, len(seen)
assert sum(f["between"] for f in rows) == sum(not f["between"] for f in rows) - 1
for f in seen:
    s, b = f["skinned"], f["best_fit_blend"]
    assert s["overshoot"] <= 1e-5 * d and s["centers_outside"] == 0, f
    assert s["max"] <= 1.25 * m["tolerance"], f
    assert abs(b["max"] - s["max"]) <= 1e-4 * d, f
assert m["summary"]["skinned"]["all"]["frames"] == len(rows) == m["times"]
PY
  # --hold-over-clip: the radius holds at every frame of the clip and half-way between (the
  # times proxy-eval measures by default), not only at the 2 poses: no sphere pokes out anywhere.
  "$bin/pose-map" --manifest "$r/poses/poses.json" --spheres "$r/rest.spheres.json" -o "$r/held.proxy.json" \
    --hold-over-clip -q --report "$r/held.report.json"
  check "held over the clip: report schema" v pose-map-report.schema.json "$r/held.report.json"
  # The skinned selection and the clip's radii on one thread: the same proxy, byte for byte.
  "$bin/pose-map" --manifest "$r/poses/poses.json" --spheres "$r/rest.spheres.json" -o "$r/held-1.proxy.json" \
    --hold-over-clip --threads 1 -q
  check "held over the clip: --threads 1 wrote another proxy" cmp -s "$r/held.proxy.json" "$r/held-1.proxy.json"
  "$bin/proxy-eval" "$r/held.proxy.json" --manifest "$r/poses/poses.json" --asset "$rig" --animation 0 -q \
    --report "$r/held-motion.json"
  check "held over the clip: no sphere out at any time of the clip" /usr/bin/python3 - "$r/held-motion.json" "$r/held.report.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))["motion"]
clip = json.load(open(sys.argv[2]))["map"]["clip"]
assert clip["times"] >= len(m["frames"]), (clip, len(m["frames"]))  # 60 Hz between keys
assert clip["overshoot"] > 0, clip  # the default allowance between the poses
for f in m["frames"]:
    s = f["skinned"]
    allowed = 1e-6 * m["diagonal"] + (0 if f["seen"] else clip["overshoot"])
    assert s["overshoot"] <= allowed and s["centers_outside"] == 0, (f, allowed)
PY
  # A budget past what any error needs: the spheres used are said, and the report names the
  # candidates as what decided, not max_spheres.
  said=$("$bin/pose-map" --manifest "$r/poses/poses.json" --spheres "$r/rest.spheres.json" -o "$r/many.proxy.json" \
    --max-spheres 100000 --polish 0 --report "$r/many.report.json" 2>&1)
  check "pose-map --max-spheres 100000: the spheres used said, the candidates named" /usr/bin/python3 - \
    "$r/many.report.json" "$said" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))["selection"]
assert s["spheres"] < 100000 and s["limited_by"].startswith("the candidates"), s["limited_by"]
assert "%d of the 100000 spheres asked" % s["spheres"] in sys.argv[2], sys.argv[2]
PY
  check "skin.json's clip: every key, and 60 Hz or finer between them" /usr/bin/python3 - "$r/poses/skin.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))["clip"]
t = c["times"]
assert t == sorted(t) and len(t) == len(c["joint_matrices"]), c.keys()
assert all(b - a <= 1 / 60 + 1e-9 for a, b in zip(t, t[1:])), max(b - a for a, b in zip(t, t[1:]))
assert len(t) > 100  # RiggedSimple's 3 keys are 1.04 s apart
PY
  # The character host plays the clip in Bullet with the proxy's spheres skinned every frame.
  host=$build/samples/character-host
  if [ -x "$host" ]; then
    "$host" "$r/rigged.spx" --asset "$rig" --seconds 3 --objects 10 --json "$r/host.json" -q
    check "character host: the clip played, objects fell on the spheres" /usr/bin/python3 - "$r/host.json" "$r/rigged.spx" <<'PY'
import json, math, struct, sys
h = json.load(open(sys.argv[1]))
assert h["frames"] == 180 and h["objects"]["dropped"] == 10, h
assert h["body_contacts"] > 0 and h["contacts_checked"] > 0, h
# A contact on the spheres lies inside the body, at most about the proxy's error from its surface.
assert math.isfinite(h["contact_to_mesh_m"]["max"]) and h["contact_to_mesh_m"]["max"] < 0.1 * 3, h
assert h["joints"] == 2 and h["spheres"] > 0, h
PY
  fi
  set +e
  expect 1 "asset.*no skin" "" -- "$bin/proxy-eval" "$out/car-morph/car-morph.proxy.json" --asset "$rig" --animation 0
  expect 2 "car-morph.glb: has no joint" "" -- "$bin/proxy-eval" "$r/rigged.proxy.json" --asset "$out/in/car-morph.glb" --animation 0
  expect 1 "times" "" -- "$bin/proxy-eval" "$r/rigged.proxy.json" --asset "$rig" --animation 0 --times 99
  expect 1 "between: Value 1000000000 not in range 0 to 1000" "" -- "$bin/proxy-eval" "$r/rigged.proxy.json" \
    --asset "$rig" --animation 0 --between 1000000000
  if [ -x "$host" ]; then
    expect 2 "car-morph.glb: has no joint" "" -- "$host" "$r/rigged.spx" --asset "$out/in/car-morph.glb"
    expect 2 "rigged.proxy.json: .*spx" "" -- "$host" "$r/rigged.proxy.json" --asset "$rig"
  fi
  # A rigged body's proxy follows its skin: no blends to hold it over.
  expect 1 "hold-over-blends: is for blended examples" "$out/bad.proxy.json" -- "$bin/pose-map" \
    --manifest "$r/poses/poses.json" --spheres "$r/rest.spheres.json" -o "$out/bad.proxy.json" --hold-over-blends
  expect 1 "hold-over-blends.*excludes.*hold-over-clip\|hold-over-clip.*excludes.*hold-over-blends" "$out/bad.proxy.json" -- \
    "$bin/pose-map" --manifest "$r/poses/poses.json" --spheres "$r/rest.spheres.json" -o "$out/bad.proxy.json" \
    --hold-over-blends --hold-over-clip
  # pose-map refuses a rig that does not fit its poses, naming the file and the field.
  pm() { "$bin/pose-map" --rest "$r/poses/rest.obj" "$@" --spheres "$r/rest.spheres.json" -o "$out/bad.proxy.json"; }
  poses=(--pose "$r/poses/pose-00.obj" --pose "$r/poses/pose-01.obj")
  /usr/bin/python3 - "$r/poses/skin.json" "$out" <<'PY'
import json, sys
skin = json.load(open(sys.argv[1]))
more = json.loads(json.dumps(skin)); more["poses"][1]["joint_matrices"].append(more["poses"][1]["joint_matrices"][0])
json.dump(more, open(sys.argv[2] + "/skin-more-joints.json", "w"))
skin["poses"][0]["joint_matrices"][0][0] = 123456789.25  # a unique token, then out of range
open(sys.argv[2] + "/skin-infinite.json", "w").write(json.dumps(skin).replace("123456789.25", "1e999"))
cycle = json.load(open(sys.argv[1])); cycle["joints"][0]["parent"] = len(cycle["joints"]) - 1
json.dump(cycle, open(sys.argv[2] + "/skin-cycle.json", "w"))
PY
  expect 2 "skin-more-joints.json: pose '.*' joint_matrices does not hold one matrix per joint" "$out/bad.proxy.json" -- pm "${poses[@]}" --skin "$out/skin-more-joints.json"
  expect 2 "skin-infinite.json: .*1e999" "$out/bad.proxy.json" -- pm "${poses[@]}" --skin "$out/skin-infinite.json"
  expect 2 "skin-cycle.json: joints: following joint 0's parents never reaches a root (-1): they form a cycle" \
    "$out/bad.proxy.json" -- pm "${poses[@]}" --skin "$out/skin-cycle.json"
  expect 2 "rest.obj: is not the skin of its joint matrices" "$out/bad.proxy.json" -- pm --pose "$r/poses/pose-00.obj" --pose "$r/poses/rest.obj" --skin "$r/poses/skin.json"
  # Another mesh's spheres (the car at a thousandth of its size, inside the cylinder): a skinned
  # body's fields are built at the spheres' voxel; the failure says whose voxel, not a resolution.
  /usr/bin/python3 -c "
import sys
out = open(sys.argv[2], 'w')
for line in open(sys.argv[1]):
    w = line.split()
    out.write('v %g %g %g\n' % tuple(1e-3 * float(x) for x in w[1:4]) if w and w[0] == 'v' else line)
" "$out/in/rest.obj" "$out/tiny.obj"
  "$bin/sdf-build" "$out/tiny.obj" -o "$out/tiny.vdb" --resolution 48 -q
  "$bin/sphere-pack" "$out/tiny.vdb" -o "$out/tiny.spheres.json" -q
  expect 3 "rest.obj: the spheres file's voxel (.*tiny.obj) is too fine for this mesh: a .* grid needs .* GiB limit; is the spheres file another mesh.s" "$out/bad.proxy.json" -- \
    "$bin/pose-map" --manifest "$r/poses/poses.json" --spheres "$out/tiny.spheres.json" -o "$out/bad.proxy.json"
  set -e
fi

# One mesh of an asset of several (MESH=, pose-extract --mesh): the robot's right forearm. Its
# page and proxy-eval take the same --mesh; without it, they name the meshes the proxy leaves
# uncovered and the --mesh that takes its one, and proxy-eval's error on the poses names --mesh.
"$bin/sample-gen" robot -o "$out/in" -q
$m NAME=arm ASSET_FILE="$out/in/robot.glb" EXTRACT_FLAGS="--animation 0 --select 3" MESH=r_forearm QUIET=1
a=$out/arm robot=$out/in/robot.glb
n_arm=$(grep -c '^v ' "$a/poses/rest.obj")
check "one mesh: the page shows that mesh alone, with no warning" /usr/bin/python3 - "$a/export.html.report.json" "$n_arm" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
p = r["page"]
assert p["mesh"] == "r_forearm" and p["vertices"] == int(sys.argv[2]) and p["meshes_without_spheres"] == [], p
assert not r["warnings"], r["warnings"]
PY
check "one mesh: page report schema" v proxy-export-report.schema.json "$a/export.html.report.json"
"$bin/proxy-export" "$a/arm.proxy.json" -o "$a/whole.html" --asset "$robot" --report "$a/whole.json" 2> "$a/whole.log"
check "one mesh, the page without --mesh: the meshes left uncovered and --mesh not named" grep -q \
  "warning: 11 of the 13 meshes of .*robot.glb hold no sphere of the proxy ('head', .*'torso'.*): the page shows them uncovered; a proxy of one mesh (pose-extract --mesh) takes --mesh r_forearm$" \
  "$a/whole.log"
check "one mesh, the page without --mesh: the whole robot, the uncovered meshes in the report" /usr/bin/python3 - \
  "$a/whole.json" "$n_arm" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))["page"]
assert p["mesh"] is None and p["vertices"] > 10 * int(sys.argv[2]), p
assert len(p["meshes_without_spheres"]) == 11 and "r_forearm" not in p["meshes_without_spheres"], p
PY
# proxy-eval with the same --mesh: the clip the manifest's poses came from without --animation.
"$bin/proxy-eval" "$a/arm.proxy.json" --manifest "$a/poses/poses.json" --asset "$robot" --mesh r_forearm \
  --report "$a/motion.json" > "$a/motion.log" 2>&1
check "one mesh: proxy-eval says which clip it measures without --animation" \
  grep -q "clip 'robot' (the clip .*poses.json's poses came from; --animation names another)" "$a/motion.log"
check "one mesh: proxy-eval report schema" v proxy-eval-report.schema.json "$a/motion.json"
check "one mesh: proxy-eval measured that mesh, no sphere out at the frames seen" /usr/bin/python3 - "$a/motion.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
m = r["motion"]
assert m["mesh"] == "r_forearm" and m["meshes_without_spheres"] == [] and m["clip"] == "robot", m["mesh"]
assert not r["warnings"], r["warnings"]
seen = [f["skinned"] for f in m["frames"] if f["seen"]]
assert len(seen) == 3 and all(s["overshoot"] <= 1e-6 * m["diagonal"] for s in seen), seen
PY
"$bin/proxy-eval" "$a/arm.proxy.json" --asset "$robot" > "$a/whole-eval.log" 2>&1
check "one mesh, proxy-eval without --mesh: the meshes measured uncovered are named" grep -q \
  "warning: 11 of the 13 meshes .* their error is measured; a proxy of one mesh (pose-extract --mesh) takes --mesh r_forearm" \
  "$a/whole-eval.log"
check "one mesh, proxy-eval without --animation: the asset's only clip" grep -q "clip 'robot' (the asset's only clip" \
  "$a/whole-eval.log"
# The robot with a second clip: without --animation (and no manifest) proxy-eval asks for one.
/usr/bin/python3 - "$robot" "$a/two-clips.glb" <<'PY'
import json, struct, sys
b = open(sys.argv[1], "rb").read()
n = struct.unpack_from("<I", b, 12)[0]
doc = json.loads(b[20:20 + n])
doc["animations"].append(dict(doc["animations"][0], name="again"))
text = json.dumps(doc).encode()
text += b" " * (-len(text) % 4)
rest = b[20 + n:]
open(sys.argv[2], "wb").write(b[:8] + struct.pack("<III", 12 + 8 + len(text) + len(rest), len(text), 0x4E4F534A) + text + rest)
PY
set +e
expect 1 "--animation: names the clip to measure: .*two-clips.glb has 2 clips ('robot', 'again')" "" -- \
  "$bin/proxy-eval" "$a/arm.proxy.json" --asset "$a/two-clips.glb" --mesh r_forearm
expect 2 "robot.glb: has 1582 welded vertices, the rest mesh $n_arm: not the asset the poses came from (its 13 meshes merged: poses of one mesh, pose-extract --mesh, need the same --mesh here)" "" -- \
  "$bin/proxy-eval" "$a/arm.proxy.json" --manifest "$a/poses/poses.json" --asset "$robot"
expect 1 "--mesh: is for a .html page with --asset" "$a/x.glb" -- "$bin/proxy-export" "$a/arm.proxy.json" -o "$a/x.glb" \
  --mesh r_forearm
expect 1 "--mesh: is for a .html page with --asset" "$a/x.glb" -- "$bin/proxy-export" "$a/arm.proxy.json" -o "$a/x.glb" \
  --physics --asset "$robot" --mesh r_forearm
expect 1 "--mesh: no mesh or node named 'wheel' in .*robot.glb" "$a/x.html" -- "$bin/proxy-export" "$a/arm.proxy.json" \
  -o "$a/x.html" --asset "$robot" --mesh wheel
set -e
echo "$passed passed, $fail failed"
[ "$fail" = 0 ]
