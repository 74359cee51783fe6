# Shared by run.sh and noise.sh (sourced, with `here` set to this folder):
# the tools with their checks, and one Cycles render of the example room.
# Environment: DCM (default build/tools/dcm/dcm of this repository),
# BLENDER (default blender), THREADS (Cycles render threads, default 2).
root="$(cd "$here/../.." && pwd)"
DCM="${DCM:-$root/build/tools/dcm/dcm}"
BLENDER="${BLENDER:-blender}"
THREADS="${THREADS:-2}"
out="$here/out"

# require_tools SCRIPT: blender and the dcm binary are there.
require_tools() {
  command -v "$BLENDER" >/dev/null ||
    { echo "$1: no '$BLENDER' (sudo apt-get install --no-install-recommends blender)" >&2; exit 1; }
  [ -x "$DCM" ] || { echo "$1: no dcm binary at $DCM (build it, or set DCM=...)" >&2; exit 1; }
  mkdir -p "$out"
}

# make_and_render EXR VIEW RES [ARGS...]: one run of make_and_render.py;
# on failure, the end of its log and exit.
make_and_render() {
  local exr="$1" view="$2" res="$3"
  shift 3
  "$BLENDER" -b --factory-startup --python "$here/make_and_render.py" -- \
    --out "$exr" --view "$view" --res "$res" --threads "$THREADS" "$@" > "$out/blender.log" 2>&1 ||
    { tail -20 "$out/blender.log" >&2; exit 1; }
}

# render_room EXR VIEW RES SAMPLES SEED: renders EXR unless it exists.
render_room() {
  [ -f "$1" ] && return 0
  echo "rendering $(basename "$1") (${3}x${3}, $4 spp, seed $5)" >&2
  local t0=$SECONDS
  make_and_render "$1" "$2" "$3" --samples "$4" --seed "$5"
  echo "$(basename "$1"): $((SECONDS - t0)) s" >&2
}

# render_shadow_guide EXR VIEW RES: the sun's shadow guide (1 sample, view
# layer ShadowGuide) unless EXR exists; dcm's blender preset reads it as a
# second input.
render_shadow_guide() {
  [ -f "$1" ] && return 0
  make_and_render "$1" "$2" "$3" --shadow-guide
}

# render_highlight_guide EXR VIEW RES: where the lights are seen in glossy
# surfaces (16 samples of direct glossy light, view layer HighlightGuide)
# unless EXR exists; dcm's blender preset reads it as one more input.
render_highlight_guide() {
  [ -f "$1" ] && return 0
  make_and_render "$1" "$2" "$3" --highlight-guide --samples 16
}

# guided EXR VIEW RES: the render EXR (SAMPLES spp, seed 3) with its shadow
# and highlight guides appended, one file per view as dcm bench takes it;
# renders what is missing. Needs oiiotool.
guided() {
  local render="$1" view="$2" res="$3" shadow="$out/shadow_guide_${2}_${3}.exr"
  local highlight="$out/highlight_guide_${2}_${3}.exr" all="$out/guided_sh_${2}_${3}_${SAMPLES}.exr"
  render_room "$render" "$view" "$res" "$SAMPLES" 3
  render_shadow_guide "$shadow" "$view" "$res"
  render_highlight_guide "$highlight" "$view" "$res"
  [ -f "$all" ] || oiiotool "$render" "$shadow" "$highlight" --chappend --chappend -o "$all"
  echo "$all"
}
