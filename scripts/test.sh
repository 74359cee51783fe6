#!/usr/bin/env bash
# Sets up a fresh Debian 12 machine and runs dcm's whole test suite:
# installs the packages, configures, builds (-j2), runs ctest.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${DCM_BUILD_DIR:-$here/build}
"$here/scripts/install-deps.sh"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2
cd "$build"
ctest --output-on-failure -j2 --timeout 600
