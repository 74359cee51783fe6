#!/usr/bin/env bash
# Installs the Debian 12 packages dcm needs to build, test and run its examples.
# Only what is missing is installed; nothing is downloaded outside apt.
# Usage: scripts/install-deps.sh [--with-renderers] [--with-fuzz]
set -euo pipefail

packages=(
  # toolchain
  cmake g++ ninja-build pkg-config
  # engine, providers and tool
  libopenimageio-dev openimageio-tools libopenexr-dev libimath-dev
  libopencolorio-dev libembree-dev libtbb-dev
  libcli11-dev nlohmann-json3-dev libassimp-dev
  # the text of the sample map's legend and the error map's colour bar (DejaVu Sans)
  fonts-dejavu-core
  # the Python module (python/, for /usr/bin/python3)
  pybind11-dev python3-pybind11
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # tests/tiles/slurm_test.sh: a single-node Slurm cluster on loopback
  # (the test starts munged, slurmctld and slurmd itself; no systemd)
  slurm-wlm munge
  # tests/povray: POV-Ray 3.7 driven for real (examples/povray)
  povray
  # tests/blender: pgrep checks that no Blender outlives `dcm blender`
  procps
  # helper scripts (plots, checks): Debian's python, not the one first on PATH
  # (tools/bench/error_strip.py imports PIL itself)
  python3-numpy python3-matplotlib python3-openimageio python3-pil
  # scripts/tiles-benchmark.sh: wall time and peak memory per process
  time
  # docs/ENGINE.md: instruction counts of the engine benchmark (callgrind)
  valgrind
)
for arg in "$@"; do
  case "$arg" in
    --with-renderers) packages+=(blender) ;;                   # examples/blender, tests/blender
    --with-fuzz) packages+=(clang-14 libclang-rt-14-dev) ;;    # scripts/fuzz.sh (libFuzzer)
    *) echo "install-deps: unknown option $arg" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present" >&2
  exit 0
fi

echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done" >&2
