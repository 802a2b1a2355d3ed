#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite (ctest, in parallel).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
cd "$root/build/release"
ctest -j "$(nproc)" --output-on-failure --timeout 900
