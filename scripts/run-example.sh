#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: installs the packages, builds the
# dcm command (-j2), renders the bundled room scene with DCM and in full with
# the internal Embree tracer, and prints exact-pixel fraction, times, speed-up
# and error. Outputs go to out/ (EXR, stats JSON, sample map, preview).
# Usage: scripts/run-example.sh [SCENE.json] [extra dcm render flags...]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${DCM_BUILD_DIR:-$here/build}
scene=${1:-$here/examples/scenes/room.json}
shift || true
"$here/scripts/install-deps.sh"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target dcm
mkdir -p "$here/out"
name=$(basename "$scene" .json)
"$build/tools/dcm/dcm" render "$scene" -o "$here/out/$name.exr" --with-reference \
  --stats "$here/out/$name.json" --sample-map "$here/out/${name}_samples.png" \
  --preview "$here/out/$name.png" "$@"
echo "outputs: $here/out/$name.{exr,json,png} and ${name}_samples.png" >&2
