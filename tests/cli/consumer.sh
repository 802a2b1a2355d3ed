#!/usr/bin/env bash
# The installed package as a host sees it: install into a temporary prefix, then build and run a
# small project that find_package(spx)s and links spx::runtime and spx::bullet; the runtime
# component alone (header only, no spx::bullet); and a SPX_RUNTIME_ONLY build of the sources.
# usage: consumer.sh BUILD_DIR SOURCE_DIR OUT_DIR SPX_FILE
set -euo pipefail
build=$1 src=$2 out=$3 spx=$4
rm -rf "$out" && mkdir -p "$out"
fail=0 passed=0
check() {
  local msg=$1
  shift
  if "$@" >"$out/last.log" 2>&1; then passed=$((passed + 1)); else echo "FAIL: $msg"; cat "$out/last.log"; fail=$((fail + 1)); fi
}
consumer() {  # consumer PREFIX NAME [cmake args...]
  local prefix=$1 name=$2
  shift 2
  cmake -S "$src/tests/consumer" -B "$out/$name" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release "$@" &&
    cmake --build "$out/$name" && "$out/$name/consumer" "$spx"
}
cmake --install "$build" --prefix "$out/full" >/dev/null
check "consumer of spx::runtime and spx::bullet" consumer "$out/full" full
check "installed header under include/spx" test -f "$out/full/include/spx/spx_runtime.h"
cmake --install "$build" --prefix "$out/rt" --component runtime >/dev/null
check "header-only consumer of the runtime component" consumer "$out/rt" rt -DWITH_BULLET=OFF
check "the runtime component holds no tools" test ! -e "$out/rt/bin/sdf-build"
if consumer "$out/rt" rt-bullet >/dev/null 2>&1; then
  echo "FAIL: find_package(spx COMPONENTS bullet) succeeded without the bullet component"; fail=$((fail + 1))
else passed=$((passed + 1)); fi
# The runtime alone from the sources: no CGAL, OpenVDB or assimp needed.
check "SPX_RUNTIME_ONLY configure and build" bash -c "cmake -S '$src' -B '$out/rt-only-build' -DSPX_RUNTIME_ONLY=ON \
  -DCMAKE_INSTALL_PREFIX='$out/rt-only' && cmake --build '$out/rt-only-build' && cmake --install '$out/rt-only-build'"
check "SPX_RUNTIME_ONLY builds no tools" test ! -e "$out/rt-only-build/apps"
check "consumer of the SPX_RUNTIME_ONLY install" consumer "$out/rt-only" rt-only-consumer
# The header alone: an architecture-independent package.
check "header-only package" bash -c "cmake -S '$src' -B '$out/hdr-build' -DSPX_RUNTIME_ONLY=ON -DSPX_WITH_BULLET=OFF \
  -DSPX_BUILD_BINDINGS=OFF -DCMAKE_INSTALL_PREFIX='$out/hdr' && cmake --build '$out/hdr-build' && cmake --install '$out/hdr-build'"
check "header-only package holds the header and the CMake files only" \
  bash -c "[ \"\$(cd '$out/hdr' && find . -type f | grep -vc '^./lib/cmake/spx/')\" = 1 ]"
check "header-only version file skips the architecture check" grep -q 'if("TRUE")' "$out/hdr/lib/cmake/spx/spxConfigVersion.cmake"
check "consumer of the header-only package" consumer "$out/hdr" hdr-consumer -DWITH_BULLET=OFF
echo "$passed passed, $fail failed"
[ "$fail" = 0 ]
