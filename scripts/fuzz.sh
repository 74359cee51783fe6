#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang-14) and runs each for SECONDS
# (default 60) on its seed corpus: all five, or the TARGETs named. Exits
# non-zero when a build fails or a target finds a crash, a sanitizer report, a
# timeout, an out-of-memory or a violated contract; the reproducer is left in
# the build dir (crash-*, oom-*, timeout-*) and its path printed.
#
#   scripts/fuzz.sh [SECONDS [TARGET...]]
#   scripts/fuzz.sh 30 fuzz_pipe fuzz_mesh   # two targets, 30 s each
#   DCM_FUZZ_SEED=N scripts/fuzz.sh   # libFuzzer's -seed (0, the default: random;
#                                     # the test command uses a fixed one)
#   DCM_FUZZ_BUILD_DIR=/x scripts/fuzz.sh 300
#   DCM_FUZZ_RUNS=N scripts/fuzz.sh   # stop after N inputs rather than after SECONDS
#                                     # (SECONDS stays a cap): with a fixed seed the
#                                     # same inputs on any machine, as the test command runs it
#
# Packages: clang-14 and libclang-rt-14-dev (libFuzzer and the sanitizer
# runtimes), plus dcm's own build dependencies (scripts/install-deps.sh).
set -euo pipefail
seconds=${1:-60}
shift $(( $# > 0 ? 1 : 0 ))
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_scene fuzz_exr fuzz_pipe fuzz_mesh fuzz_texture)
here=$(cd "$(dirname "$0")/.." && pwd)
build=${DCM_FUZZ_BUILD_DIR:-$here/build-fuzz}
cxx=${CXX_FUZZ:-clang++-14}

# Installs clang-14 and libclang-rt-14-dev (and the build dependencies) if missing.
"$here/scripts/install-deps.sh" --with-fuzz
if ! command -v "$cxx" >/dev/null; then
  echo "fuzz.sh: $cxx not found (scripts/install-deps.sh --with-fuzz)" >&2
  exit 2
fi
cmake -S "$here/fuzz" -B "$build" -G Ninja -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j"${DCM_JOBS:-2}" --target "${targets[@]}"

# The targets check their own contracts and abort on a violation; sanitizer
# reports abort too. Leaks count as findings. -timeout=60: an EXR header may
# declare an attribute of ~2 GB that OpenEXR allocates before it finds the
# file short (seconds on a loaded machine under ASan; see docs/FUZZING.md).
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

status=0
for target in "${targets[@]}"; do
  corpus="$build/corpus/$target"   # grows during the run; the seeds stay in the repo
  # A counted run starts from the seeds alone, so that it is the same run every time.
  [ -n "${DCM_FUZZ_RUNS:-}" ] && rm -rf "$corpus"
  mkdir -p "$corpus" "$build/artifacts/$target"
  seeds="$here/fuzz/corpus/${target#fuzz_}"
  dict=()
  [ -f "$here/fuzz/${target#fuzz_}.dict" ] && dict=(-dict="$here/fuzz/${target#fuzz_}.dict")
  echo "fuzz.sh: $target for ${seconds} s"
  set +e
  runs=()
  [ -n "${DCM_FUZZ_RUNS:-}" ] && runs=(-runs="$DCM_FUZZ_RUNS")
  flags=(-max_total_time="$seconds" -timeout=60 -rss_limit_mb=2560 -malloc_limit_mb=2048
         -max_len=65536 -print_final_stats=1 -seed="${DCM_FUZZ_SEED:-0}")
  if [ -n "${DCM_FUZZ_RUNS:-}" ] && setarch "$(uname -m)" -R true 2>/dev/null; then
    # libFuzzer's comparison tables hold pointers: a counted run repeats only
    # where the process's addresses do (docs/FUZZING.md). So: no address
    # randomisation, and the same environment, arguments and program path
    # wherever the clone is (the stack's layout follows their size).
    stage="$build/run/$target"
    rm -rf "$stage"
    mkdir -p "$stage/corpus" "$stage/artifacts"
    cp -r "$seeds" "$stage/seeds"
    cp "$build/$target" "$stage/target"
    [ ${#dict[@]} -gt 0 ] && cp "${dict[0]#-dict=}" "$stage/dict" && dict=(-dict=dict)
    (cd "$stage" && env -i PATH=/usr/bin:/bin ASAN_OPTIONS="$ASAN_OPTIONS" UBSAN_OPTIONS="$UBSAN_OPTIONS" TMPDIR=/tmp \
      setarch "$(uname -m)" -R ./target corpus seeds "${dict[@]}" "${runs[@]}" "${flags[@]}" \
      -artifact_prefix=artifacts/) >"$build/$target.log" 2>&1
    rc=$?
    cp "$stage"/artifacts/* "$build/artifacts/$target/" 2>/dev/null
  else
    "$build/$target" "$corpus" "$seeds" "${dict[@]}" "${runs[@]}" "${flags[@]}" \
      -artifact_prefix="$build/artifacts/$target/" >"$build/$target.log" 2>&1
    rc=$?
  fi
  set -e
  grep -E '^stat::number_of_executed_units|^#[0-9]+.*DONE' "$build/$target.log" | tail -2 || true
  if [ $rc -ne 0 ]; then
    echo "fuzz.sh: $target FAILED (exit $rc); log: $build/$target.log" >&2
    grep -E 'ERROR|SUMMARY|violates|does not name|terminate called|what\(\)|Test unit written' "$build/$target.log" | head -20 >&2 || true
    status=1
  fi
done
exit $status
