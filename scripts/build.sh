#!/usr/bin/env bash
# Configures and builds the Release tree in build/release (incremental).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$root/build/release"
log=$root/build/release/configure.log
if ! cmake -S "$root" -B "$root/build/release" -DCMAKE_BUILD_TYPE=Release >"$log" 2>&1; then
  cat "$log" >&2
  exit 1
fi
cmake --build "$root/build/release" -j "$(nproc)"
