#!/usr/bin/env bash
# proxy-export --physics: the car's and the barrel's rest spheres alone, the skinned RiggedSimple proxy into its
# asset and alone, and the morph-target car into its glTF. Each .glb passes the Khronos glTF
# validator with no error and reads back through assimp sphere for sphere against the .spx (and
# the asset's meshes, skin and clips as pose-extract reads them); bad input is one error line.
# usage: physics.sh BUILD_DIR SOURCE_DIR OUT_DIR EXTRACT_OUT SHARED_DATA
set -uo pipefail
source "$(dirname "$0")/expect.sh"
start_cli_test "$1" "$2" "$3"
ex=$4 data=$5
if [ ! -d "$src/web/node_modules/gltf-validator" ]; then
  echo "FAIL: no glTF validator in $src/web/node_modules (scripts/setup.sh installs it)"
  exit 1
fi
validate() { node "$src/web/validate-gltf.mjs" "$@"; }
export_physics() {  # export_physics NAME PROXY.json [ASSET]
  local name=$1 proxy=$2 asset=${3:-}
  "$bin/proxy-export" "$proxy" -o "$out/$name.spx" -q
  "$bin/proxy-export" "$proxy" -o "$out/$name.glb" --physics ${asset:+--asset "$asset"} -q --report "$out/$name.report.json"
  check "$name: validator errors" validate "$out/$name.glb"
  check "$name: report schema" /usr/bin/python3 "$src/tests/cli/validate_json.py" "$src/schemas" \
    proxy-export-report.schema.json "$out/$name.report.json" >/dev/null
  check "$name: read back" "$build/tests/physics_readback" "$out/$name.glb" "$out/$name.spx" $asset
  check "$name: extensions not required" /usr/bin/python3 -c "
import json, struct, sys
b = open(sys.argv[1], 'rb').read(); n = struct.unpack_from('<I', b, 12)[0]; d = json.loads(b[20:20 + n])
used = set(d['extensionsUsed']); req = set(d.get('extensionsRequired', []))
want = {'KHR_implicit_shapes', 'KHR_physics_rigid_bodies', 'OMI_physics_shape', 'OMI_physics_body'}
sys.exit(not (want <= used and not (want & req)))" "$out/$name.glb"
}

export_physics car "$build/tests/cli-out/car/a/asset.proxy.json"
export_physics barrel "$build/tests/cli-out/barrel/a/asset.proxy.json"
export_physics rigged-alone "$ex/rigged/rigged.proxy.json"
export_physics rigged "$ex/rigged/rigged.proxy.json" "$data/rigged-simple/RiggedSimple.glb"
export_physics car-morph "$ex/car-morph/car-morph.proxy.json" "$ex/in/car-morph.glb"
check "rigged: the report names the joints and the rigid attachment's offsets" /usr/bin/python3 -c "
import json, sys
p = json.load(open(sys.argv[1]))['physics']
sys.exit(not (p['colliders'] > 0 and p['attachment']['spheres_per_joint'] and
              p['attachment']['rigid_against_skinned'][0]['frames'] > 0))" "$out/rigged.report.json"
# Twice: the same bytes.
"$bin/proxy-export" "$ex/rigged/rigged.proxy.json" -o "$out/again.glb" --physics --asset "$data/rigged-simple/RiggedSimple.glb" -q
check "two runs differ" cmp -s "$out/rigged.glb" "$out/again.glb"

# Bad input: one error line, the documented exit code, no output left.
car=$build/tests/cli-out/car/a/asset.proxy.json
expect 1 "--physics.*\.glb" "$out/x.spx" -- "$bin/proxy-export" "$car" -o "$out/x.spx" --physics
expect 1 "--physics.*\.glb" "$out/x.html" -- "$bin/proxy-export" "$car" -o "$out/x.html" --physics
expect 2 "rest.obj.*not a glTF" "$out/x.glb" -- "$bin/proxy-export" "$car" -o "$out/x.glb" --physics \
  --asset "$ex/rigged/poses/rest.obj"
expect 2 "RiggedSimple.glb.*not the asset the proxy was made from" "$out/x.glb" -- "$bin/proxy-export" "$car" \
  -o "$out/x.glb" --physics --asset "$data/rigged-simple/RiggedSimple.glb"
head -c 100 "$data/rigged-simple/RiggedSimple.glb" >"$out/cut.glb"
expect 2 "cut.glb.*truncated" "$out/x.glb" -- "$bin/proxy-export" "$car" -o "$out/x.glb" --physics --asset "$out/cut.glb"
# An asset that already holds a proxy's colliders (this tool's own output): a host would collide
# with both sets, so it is refused, skinned or not.
expect 2 "car-morph.glb: already holds a proxy's colliders (node 'spx-proxy')" "$out/x.glb" -- "$bin/proxy-export" \
  "$ex/car-morph/car-morph.proxy.json" -o "$out/x.glb" --physics --asset "$out/car-morph.glb"
expect 2 "rigged.glb: already holds a proxy's colliders (node 'spx-sphere-" "$out/x.glb" -- "$bin/proxy-export" \
  "$ex/rigged/rigged.proxy.json" -o "$out/x.glb" --physics --asset "$out/rigged.glb"
# An asset whose shape extension has no list to add to (assimp reads it): one line, not a JSON error.
/usr/bin/python3 -c "
import json, struct, sys
b = open(sys.argv[1], 'rb').read(); n = struct.unpack_from('<I', b, 12)[0]; d = json.loads(b[20:20 + n])
d['extensions'] = {'KHR_implicit_shapes': 5}
t = json.dumps(d).encode(); t += b' ' * (-len(t) % 4); tail = b[20 + n:]
open(sys.argv[2], 'wb').write(b'glTF' + struct.pack('<III', 2, 20 + len(t) + len(tail), len(t)) + b'JSON' + t + tail)
" "$ex/in/car-morph.glb" "$out/odd-shapes.glb"
expect 2 "odd-shapes.glb: its extension KHR_implicit_shapes has no list of shapes" "$out/x.glb" -- "$bin/proxy-export" \
  "$ex/car-morph/car-morph.proxy.json" -o "$out/x.glb" --physics --asset "$out/odd-shapes.glb"
expect 1 "--asset.*needs --physics" "$out/x.glb" -- "$bin/proxy-export" "$car" -o "$out/x.glb" --asset "$ex/in/car-morph.glb"

echo "physics: $passed passed, $fail failed"
[ "$fail" -eq 0 ]
