#!/usr/bin/env bash
# Sets up a fresh Debian 12 machine and runs dcm's whole test suite:
# installs the packages, configures, builds (-j2), runs ctest, then the engine
# and robustness suites under ASan+UBSan (DCM_NO_SANITIZE=1 skips that step)
# and a short fuzz run per target (DCM_NO_FUZZ=1 skips it).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${DCM_BUILD_DIR:-$here/build}
# --with-renderers: Blender for tests/blender (POV-Ray is in the base list).
"$here/scripts/install-deps.sh" --with-renderers
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2
(cd "$build" && ctest --output-on-failure -j2 --timeout 600)
# The engine and robustness suites again under AddressSanitizer and
# UndefinedBehaviorSanitizer (scripts/sanitize.sh runs everything; ~1 min here).
[ "${DCM_NO_SANITIZE:-0}" = 1 ] || DCM_ASAN_BUILD_DIR="$build-asan" "$here/scripts/sanitize.sh" --quick
# A short fuzz run (libFuzzer, clang-14): a fixed seed and a fixed number of
# inputs per target, so that a landing is not decided by how fast the machine
# was (docs/FUZZING.md). The counts take about 10-20 s per target here; 300 s
# is only a cap.
if [ "${DCM_NO_FUZZ:-0}" != 1 ]; then
  export DCM_FUZZ_SEED=${DCM_FUZZ_SEED:-1} DCM_FUZZ_BUILD_DIR="$build-fuzz"
  DCM_FUZZ_RUNS=100000 "$here/scripts/fuzz.sh" 300 fuzz_scene fuzz_pipe
  DCM_FUZZ_RUNS=1500 "$here/scripts/fuzz.sh" 300 fuzz_exr fuzz_mesh
  DCM_FUZZ_RUNS=200 "$here/scripts/fuzz.sh" 300 fuzz_texture
fi
