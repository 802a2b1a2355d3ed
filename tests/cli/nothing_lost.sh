#!/usr/bin/env bash
# Nothing lost: a tool killed at any moment leaves the previous output intact (or none), a failed
# run stops make, and make -j gives the same bytes as make -j1.
# usage: nothing_lost.sh BUILD_DIR SOURCE_DIR OUT_DIR
set -uo pipefail
build=$1 src=$2 out=$3
bin=$build/apps
rm -rf "$out" && mkdir -p "$out"
passed=0 failed=0
check() { if eval "$2"; then passed=$((passed + 1)); else echo "FAIL: $1"; failed=$((failed + 1)); fi; }

"$bin/sample-gen" car -o "$out/in" -q
"$bin/sdf-build" "$out/in/rest.obj" -o "$out/rest.vdb" --resolution 32 -q
before=$(md5sum <"$out/rest.vdb")
# The complete result of the long run below: a killed run may leave this or the old file, never
# anything else.
"$bin/sdf-build" "$out/in/rest.obj" -o "$out/full.vdb" --resolution 600 -q
full=$(md5sum <"$out/full.vdb")
cp "$out/rest.vdb" "$out/old.vdb"
# Kill a long run at several moments (loading, building, writing): the old file stays.
killed=0
for delay in 0.05 0.3 0.8 1.5 2.5; do
  cp "$out/old.vdb" "$out/rest.vdb"
  "$bin/sdf-build" "$out/in/rest.obj" -o "$out/rest.vdb" --resolution 600 -q &
  pid=$!
  sleep "$delay"
  # A run that already finished cannot be killed: then it must have left the complete file.
  if kill -9 "$pid" 2>/dev/null; then killed=$((killed + 1)); else
    check "unkillable run after ${delay}s did not finish" '[ "$(md5sum <"$out/rest.vdb")" = "$full" ]'; fi
  wait "$pid" 2>/dev/null
  check "killed after ${delay}s: rest.vdb is neither the old file nor the complete new one" \
    '[ "$(md5sum <"$out/rest.vdb")" = "$before" ] || [ "$(md5sum <"$out/rest.vdb")" = "$full" ]'
done
check "no run was killed mid-way (the kills tested nothing)" '[ "$killed" -ge 2 ]'
# A killed first run leaves no file under the target name (or, if it finished, the whole one).
"$bin/sdf-build" "$out/in/rest.obj" -o "$out/fresh.vdb" --resolution 600 -q &
pid=$!
sleep 0.5
kill -9 "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
check "killed first run left a partial fresh.vdb" '[ ! -e "$out/fresh.vdb" ] || [ "$(md5sum <"$out/fresh.vdb")" = "$full" ]'

# Ended by a signal it can catch (Ctrl-C, make's or a farm's SIGTERM, a closed terminal) while it
# writes: the old file stays (or, signalled just after the rename, the complete one), and the
# temporary file beside it is gone too.
landed=0
rm -f "$out"/.rest.vdb.tmp.*  # what the kill -9 runs above may have left
for sig in INT TERM HUP; do
  cp "$out/old.vdb" "$out/rest.vdb"
  # (as a terminal would start it: a background job of a script ignores SIGINT otherwise)
  python3 -c "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); os.execv(sys.argv[1], sys.argv[1:])" \
    "$bin/sdf-build" "$out/in/rest.obj" -o "$out/rest.vdb" --resolution 600 -q &
  pid=$!
  tmp=$out/.rest.vdb.tmp.$pid  # its own (exec keeps the pid)
  while kill -0 "$pid" 2>/dev/null && [ ! -e "$tmp" ]; do sleep 0.005; done
  kill -s "$sig" "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  [ "$(md5sum <"$out/rest.vdb")" = "$before" ] && landed=$((landed + 1))
  check "SIG$sig: rest.vdb is neither the old file nor the complete new one" \
    '[ "$(md5sum <"$out/rest.vdb")" = "$before" ] || [ "$(md5sum <"$out/rest.vdb")" = "$full" ]'
  check "SIG$sig left its temporary file" '[ ! -e "$tmp" ]'
done
check "no signal landed while the file was written (the signals tested nothing)" '[ "$landed" -ge 2 ]'

# A full disk while a tool writes (a file-size limit stands in for one: `ulimit -f`, in KiB):
# exit 4 with one line naming the output, the previous output byte for byte, no temporary file.
# (sdf-build's .vdb went through OpenVDB's own file writer, which never checks its stream: a full
# disk left a cut .vdb and exit 0.)
d=$out/full-disk && mkdir -p "$d"
"$bin/sdf-build" "$out/in/rest.obj" -o "$d/rest.vdb" --resolution 48 -q
"$bin/sphere-pack" "$d/rest.vdb" --mesh "$out/in/rest.obj" -o "$d/rest.spheres.json" -q
"$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/front.obj" "$out/in/roof.obj" \
  --spheres "$d/rest.spheres.json" -o "$d/car.proxy.json" -q
for ext in spx glb ply html; do "$bin/proxy-export" "$d/car.proxy.json" -o "$d/car.$ext" -q; done
limited() {  # limited KIB XFSZ OUTPUT TOOL ARGS...: run TOOL under a file-size limit, writing OUTPUT,
  # with SIGXFSZ ignored ('') or at its default (-)
  local kib=$1 xfsz=$2 target=$3 old
  shift 3
  old=$(md5sum <"$target")
  (ulimit -f "$kib" && trap "$xfsz" XFSZ && exec "$@" -o "$target" -q) 2>"$d/err" >/dev/null
  local rc=$?
  check "$(basename "$target") past the limit: exit $rc, not 4" '[ "$rc" = 4 ]'
  check "$(basename "$target") past the limit: not one line naming it: $(cat "$d/err")" \
    '[ "$(wc -l <"$d/err")" = 1 ] && grep -q "^Error: $target: write failed: File too large$" "$d/err"'
  check "$(basename "$target") past the limit: the previous output changed" '[ "$(md5sum <"$target")" = "$old" ]'
  check "$(basename "$target") past the limit: a temporary file left" \
    '[ -z "$(find "$d" -name ".$(basename "$target").tmp.*")" ]'
}
# Past the limit a write fails with EFBIG where SIGXFSZ is ignored, as a full disk's fails with
# ENOSPC; where it is not (a shell's default), the tools ignore it themselves.
for xfsz in '' -; do limited 16 "$xfsz" "$d/rest.vdb" "$bin/sdf-build" "$out/in/rest.obj" --resolution 48; done
limited 16 - "$d/rest.spheres.json" "$bin/sphere-pack" "$d/rest.vdb" --mesh "$out/in/rest.obj"
limited 4 - "$d/car.proxy.json" "$bin/pose-map" --rest "$out/in/rest.obj" --pose "$out/in/front.obj" \
  "$out/in/roof.obj" --spheres "$d/rest.spheres.json"
for ext in spx glb ply html; do limited 2 - "$d/car.$ext" "$bin/proxy-export" "$d/car.proxy.json"; done

# pose-extract again into the same folder: the earlier run's files that this one does not write
# go (they were a second set of poses beside the manifest), and a run that fails half-way leaves no
# manifest (the earlier one named the earlier poses beside the new rest).
"$bin/sample-gen" robot -o "$out/in" -q
d=$out/rerun
files() { (cd "$d" && ls | tr '\n' ' '); }
removed() { python3 -c "import json,sys; print(' '.join(json.load(open(sys.argv[1]))['output']['removed_from_earlier_run']))" "$1"; }
"$bin/pose-extract" "$out/in/car-morph.glb" -o "$d" --morph-targets -q
"$bin/pose-extract" "$out/in/robot.glb" -o "$d" --animation 0 --select 3 -q --report "$out/rerun.json"
check "clip after morph targets: the folder holds $(files)" \
  '[ "$(files)" = "pose-00.obj pose-01.obj pose-02.obj poses.json rest.obj skin.json " ]'
check "clip after morph targets: the report says $(removed "$out/rerun.json")" \
  '[ "$(removed "$out/rerun.json")" = "front.obj rear.obj roof.obj side.obj" ]'
"$bin/pose-extract" "$out/in/robot.glb" -o "$d" --animation 0 --select 2 -q
check "2 frames after 3: the folder holds $(files)" '[ "$(files)" = "pose-00.obj pose-01.obj poses.json rest.obj skin.json " ]'
"$bin/pose-extract" "$out/in/car-morph.glb" -o "$d" --morph-targets -q
check "morph targets after a clip: the folder holds $(files)" \
  '[ "$(files)" = "front.obj poses.json rear.obj rest.obj roof.obj side.obj " ]'
(ulimit -f 200 && exec "$bin/pose-extract" "$out/in/robot.glb" -o "$d" --animation 0 --select 3 -q) 2>/dev/null
rc=$?
check "a clip's skin past the limit: exit $rc, not 4" '[ "$rc" = 4 ]'
check "a clip's skin past the limit: a manifest left beside the new rest ($(files))" '[ ! -e "$d/poses.json" ]'
# The run after it removes the failed run's files it does not write too (their list was beside them).
"$bin/pose-extract" "$out/in/robot.glb" -o "$d" --animation 0 --select 2 -q
check "2 frames after a failed 3: the folder holds $(files)" \
  '[ "$(files)" = "pose-00.obj pose-01.obj poses.json rest.obj skin.json " ]'
check "a run's list of its files left after its manifest" '[ -z "$(find "$d" -name ".*" -type f)" ]'
# Two runs into one folder at once (make -j with two rules writing it): the manifest named poses
# of the other run (the robot's frames 0-2 and 6-9: 3 of the 4 trials below). A run holds the
# folder from clearing the earlier files to its manifest: while another holds it (flock here), it
# waits and writes nothing.
"$bin/pose-extract" "$out/in/robot.glb" -o "$out/ref-a" --animation 0 --frames 0-2 -q
"$bin/pose-extract" "$out/in/robot.glb" -o "$out/ref-b" --animation 0 --frames 6-9 -q
d=$out/together && mkdir -p "$d"
flock "$d" sleep 6 &
holder=$!
sleep 0.5
"$bin/pose-extract" "$out/in/robot.glb" -o "$d" --animation 0 --frames 0-2 2>"$out/waited.err" &
waiter=$!
sleep 1.5
check "a run wrote its manifest while another held the folder" '[ ! -e "$d/poses.json" ]'
wait "$holder" "$waiter"
check "a run that waited for the folder did not say so: $(cat "$out/waited.err")" \
  'grep -q "another run is writing poses here; waiting for it to finish" "$out/waited.err"'
check "a run that waited for the folder left $(files)" \
  '[ "$(files)" = "pose-00.obj pose-01.obj pose-02.obj poses.json rest.obj skin.json " ]'
# The manifest's files all of its own run, whichever ran last.
own_run() {
  local n ref
  n=$(python3 -c "import json,sys; print(len(json.load(open(sys.argv[1]))['poses']))" "$d/poses.json")
  [ "$n" = 3 ] && ref=$out/ref-a || ref=$out/ref-b
  for f in $(cd "$ref" && ls); do cmp -s "$d/$f" "$ref/$f" || return 1; done
  [ "$(files)" = "$(cd "$ref" && ls | tr '\n' ' ')" ]
}
for trial in 1 2 3 4; do
  "$bin/pose-extract" "$out/in/robot.glb" -o "$d" --animation 0 --frames 0-2 -q &
  "$bin/pose-extract" "$out/in/robot.glb" -o "$d" --animation 0 --frames 6-9 -q &
  wait
  check "two runs at once into one folder, trial $trial: the manifest names another run's files ($(files))" own_run
done

# Outputs that are not plain files. A symbolic link a pipeline keeps ("latest") stays a link and
# the file it names is written; a pipe, and the process's own stdout (a link into /proc, where
# /dev/stdout points), are written as streams. Each was replaced by a file: the link, the pipe
# (its reader got nothing), and, as root, /dev/stdout itself.
mkdir -p "$out/store" && ln -s store/report.json "$out/latest.json"
"$bin/sdf-build" "$out/in/rest.obj" -o "$out/linked.vdb" --resolution 16 -q --report "$out/latest.json"
check "a --report through a link replaced the link" '[ -L "$out/latest.json" ] && grep -q "\"status\": \"ok\"" "$out/store/report.json"'
ln -s /proc/self/fd/1 "$out/own-stdout"
report=$("$bin/sdf-build" "$out/in/rest.obj" -o "$out/linked.vdb" --resolution 16 -q --report "$out/own-stdout")
check "a --report to the process's stdout did not reach it" '[ -L "$out/own-stdout" ] && grep -q "\"status\": \"ok\"" <<<"$report"'
mkfifo "$out/pipe"
timeout 30 cat "$out/pipe" >"$out/piped.json" &  # bounded: a pipe replaced by a file is never opened
reader=$!
"$bin/sdf-build" "$out/in/rest.obj" -o "$out/linked.vdb" --resolution 16 -q --report "$out/pipe"
wait "$reader"
check "a --report into a pipe did not reach its reader" '[ -p "$out/pipe" ] && grep -q "\"status\": \"ok\"" "$out/piped.json"'

# A name at the file system's limit (255 bytes): its temporary file's name was longer, and the
# run failed with "File name too long".
long=$(printf 'a%.0s' $(seq 251)).vdb
"$bin/sdf-build" "$out/in/rest.obj" -o "$out/$long" --resolution 16 -q
check "an output named in 255 bytes was not written" '[ -s "$out/$long" ] && ! ls -a "$out" | grep -q "\.tmp\."'

# make -j1 with each tool on one thread (THREADS=1) and make -j2 on every core give the same
# bytes (same output folder, so recorded paths match).
m="make -s -C $src/samples ASSET=car BIN=$bin OUT=$out/make RES=48"
$m -j1 THREADS=1 >/dev/null 2>&1
check "make THREADS=1: the tools ran on one thread" \
  '[ "$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[\"threads\"])" "$out/make/car/posemap.report.json")" = 1 ]'
mv "$out/make" "$out/make-j1"
$m -j2 >/dev/null 2>&1
for f in rest.vdb rest.spheres.json car.proxy.json car.spx car.json car.glb car.ply; do
  check "make -j2 differs from -j1 THREADS=1 in $f" 'cmp -s "$out/make-j1/car/$f" "$out/make/car/$f"'
done
# A failed step stops make and leaves no output for make to trust.
touch "$out/make/car/.meshes"  # the sample is up to date ...
sleep 1
printf 'garbage\n' >"$out/make/car/rest.obj"  # ... but its rest mesh is now broken and newer
if $m >/dev/null 2>&1; then check "make succeeded on a broken rest mesh" false; else passed=$((passed + 1)); fi
check "a failed sdf-build left rest.vdb for make to trust" '[ ! -e "$out/make/car/rest.vdb" ] || [ "$out/make/car/rest.vdb" -ot "$out/make/car/rest.obj" ]'

echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
