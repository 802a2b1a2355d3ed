#!/usr/bin/env bash
# Installs the Debian packages the project needs, only those missing.
set -euo pipefail
packages=(cmake g++ make libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev libassimp-dev libopenvdb-dev
  libboost-iostreams-dev libcli11-dev nlohmann-json3-dev libtbb-dev libgtest-dev libbenchmark-dev
  libbullet-dev libmeshoptimizer-dev libdraco-dev python3 python3-jsonschema python3-dev python3-numpy pybind11-dev clang-14 libclang-rt-14-dev
  chromium fonts-dejavu-core)  # Chromium: the proxy page's browser test (headless)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
command -v npm >/dev/null || missing+=(nodejs npm)
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo=sudo
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -q >/dev/null
  $sudo apt-get install -y -q --no-install-recommends "${missing[@]}" >/dev/null
fi
# web/: three.js and esbuild for the proxy page, playwright-core to drive Chromium in its test, the
# glTF validator; pinned by the lockfile.
root=$(cd "$(dirname "$0")/.." && pwd)
if ! cmp -s "$root/web/package-lock.json" "$root/web/node_modules/.spx-installed" 2>/dev/null; then
  echo "setup: npm ci in web/" >&2
  (cd "$root/web" && npm ci --no-audit --no-fund --loglevel=error >/dev/null && cp package-lock.json node_modules/.spx-installed)
fi
