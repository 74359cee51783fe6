#!/usr/bin/env bash
# Sets up a fresh Debian 12 machine and runs dcm's whole test suite:
# installs the packages, configures, builds (-j2), runs ctest, then the engine
# and robustness suites under ASan+UBSan (DCM_NO_SANITIZE=1 skips that step)
# and a short fuzz run per target (DCM_NO_FUZZ=1 skips it).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${DCM_BUILD_DIR:-$here/build}
"$here/scripts/install-deps.sh"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2
(cd "$build" && ctest --output-on-failure -j2 --timeout 600)
# The engine and robustness suites again under AddressSanitizer and
# UndefinedBehaviorSanitizer (scripts/sanitize.sh runs everything; ~1 min here).
[ "${DCM_NO_SANITIZE:-0}" = 1 ] || DCM_ASAN_BUILD_DIR="$build-asan" "$here/scripts/sanitize.sh" --quick
# A short fuzz run (libFuzzer, clang-14, a fixed seed so that a run is
# repeatable): the scene parser and the EXR/AOV path 30 s each, the pipe
# protocol, the mesh and the texture loaders 15 s each (docs/FUZZING.md).
if [ "${DCM_NO_FUZZ:-0}" != 1 ]; then
  export DCM_FUZZ_SEED=${DCM_FUZZ_SEED:-1} DCM_FUZZ_BUILD_DIR="$build-fuzz"
  "$here/scripts/fuzz.sh" "${DCM_FUZZ_SECONDS:-30}" fuzz_scene fuzz_exr
  "$here/scripts/fuzz.sh" "${DCM_FUZZ_SECONDS_NEW:-15}" fuzz_pipe fuzz_mesh fuzz_texture
fi
