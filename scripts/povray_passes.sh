#!/bin/sh
# Every pass of a POV-Ray scene (examples/povray/scene.pov's convention:
# Declare=Pass=0..5) rendered in full and merged into one EXR: the dense check
# set QP of docs/QUALITY.md, read by `dcm reconstruct OUTDIR/full.exr` and
# scripts/quality_check_povray.sh. (examples/povray/run.sh uses `dcm povray`,
# whose full.exr holds only R, G, B.)
#
#   scripts/povray_passes.sh OUTDIR [SIZE] [SCENE.pov]
#
# SIZE: pixels of each side (512); SCENE: examples/povray/scene.pov of this
# repository. Writes OUTDIR/passes/NAME.exr and NAME.log (beauty, id, shader,
# tau, li, normal), OUTDIR/split.txt (the split check) and OUTDIR/full.exr
# (scripts/povray_merge.py). POV-Ray: -D -A +FE +W +H Declare=Pass=N, two
# processes at a time, in a scratch folder OUTDIR/.povray_passes.* (removed on
# exit) through an INI file naming the scene and its folder (POV-Ray splits
# +I and +L at spaces). For another scene than scene.pov, POVRAY_MATTE_SHADERS
# (comma-separated shader IDs without highlight and reflection; empty: none)
# is passed to the merge's check.
set -eu
me=povray_passes.sh
here=$(cd "$(dirname "$0")" && pwd)
py=/usr/bin/python3

if [ $# -lt 1 ] || [ $# -gt 3 ] || [ -z "$1" ]; then echo "usage: $me OUTDIR [SIZE] [SCENE.pov]" >&2; exit 2; fi
out=$1
size=${2:-512}
scene=${3:-$here/../examples/povray/scene.pov}
case $size in '' | *[!0-9]* | 0*) echo "$me: SIZE must be a positive number of pixels, not '$size'" >&2; exit 2 ;; esac
if [ ! -f "$scene" ] || [ ! -r "$scene" ]; then echo "$me: no readable scene file '$scene'" >&2; exit 1; fi
case $scene in *\"*) echo "$me: the scene's path '$scene' holds a '\"', which POV-Ray's INI files cannot quote" >&2; exit 1 ;; esac
command -v povray >/dev/null 2>&1 || { echo "$me: povray is not installed (Debian: apt-get install povray)" >&2; exit 1; }
[ -x "$py" ] || { echo "$me: no $py (with numpy and OpenImageIO)" >&2; exit 1; }
scene_dir=$(cd "$(dirname "$scene")" && pwd)
scene=$scene_dir/$(basename "$scene")

mkdir -p "$out/passes"
O=$(cd "$out" && pwd)
P=$O/passes
S=$(mktemp -d "$O/.povray_passes.XXXXXX")
trap 'rm -rf "$S"' EXIT
printf 'Input_File_Name="%s"\nLibrary_Path="%s"\n' "$scene" "$scene_dir" >"$S/scene.ini"

# stop CODE: ends this shell's jobs (the lanes, the merge), waits for them, exits.
stop() {
    trap - INT TERM HUP USR1
    # Not $(jobs -p): a command substitution is a subshell without the jobs.
    jobs -p >"$S/main.jobs"
    while read -r job; do kill "$job" 2>/dev/null || :; done <"$S/main.jobs"
    wait || :
    exit "$1"
}
trap 'stop 130' INT
trap 'stop 143' TERM
trap 'stop 129' HUP
trap 'stop 1' USR1 # a lane failed (it said why)

name() {
    case $1 in 0) echo beauty ;; 1) echo id ;; 2) echo shader ;; 3) echo tau ;; 4) echo li ;; 5) echo normal ;; esac
}

# lane L PASS...: renders the passes one after another, each to S/passN.exr
# (POV-Ray's working folder), then renamed to P/NAME.exr. POV-Ray runs as a
# job of the lane, which ends it on TERM/HUP/INT. On a failure the lane says
# which pass failed and where its log is, and signals the main shell (USR1).
lane() {
    l=$1
    shift
    trap 'trap - TERM HUP INT; jobs -p >"$S/lane$l.jobs"
          while read -r job; do kill "$job" 2>/dev/null || :; done <"$S/lane$l.jobs"; wait || :; exit 143' TERM HUP INT
    for n in "$@"; do
        what=$(name "$n")
        log=$P/$what.log
        rm -f "$P/$what.exr"
        (cd "$S" && exec povray -D -A +FE +W"$size" +H"$size" Declare=Pass="$n" scene.ini +Opass"$n".exr) \
            </dev/null >"$log" 2>&1 &
        if wait "$!"; then rc=0; else rc=$?; fi
        if [ "$rc" -ne 0 ] || [ ! -s "$S/pass$n.exr" ]; then
            {
                echo "$me: POV-Ray failed on pass $n ($what) of $scene (exit $rc; log: $log):"
                if grep -qE "Error|error:|Fatal error|not found" "$log"; then
                    grep -E "Error|error:|Fatal error|not found" "$log" | tail -5
                else
                    tail -5 "$log"
                fi
            } >&2
            kill -USR1 $$
            exit 1
        fi
        mv "$S/pass$n.exr" "$P/$what.exr"
    done
}

echo "$me: passes 0-5 of $scene at ${size}x$size, 2 POV-Ray processes at a time (out: $out)"
# The two lit passes (L, L_i) are the long ones: one on each lane.
lane 1 0 1 3 &
a=$!
lane 2 4 2 5 &
b=$!
failed=0
wait "$a" || failed=1
wait "$b" || failed=1
[ "$failed" -eq 0 ] || { echo "$me: rendering failed" >&2; exit 1; }
cpu() { sed -n 's/.*with \([0-9.]*\) CPU-seconds total.*/\1/p' "$P/$1.log" | awk '{ s += $1 } END { printf "%.1f", s }'; }
echo "  POV-Ray CPU-s: beauty $(cpu beauty), li $(cpu li), id $(cpu id), shader $(cpu shader)," \
    "tau $(cpu tau), normal $(cpu normal)"

set -- "$O/full.exr" "$P/id.exr" "$P/shader.exr" "$P/tau.exr" "$P/normal.exr" "$P/li.exr" "$P/beauty.exr"
if [ -n "${POVRAY_MATTE_SHADERS+set}" ]; then set -- --matte-shaders "$POVRAY_MATTE_SHADERS" "$@"; fi
# In the background and waited for, so that a signal's stop() ends it at once.
"$py" "$here/povray_merge.py" "$@" >"$S/split.txt" &
if ! wait "$!"; then
    sed 's/^/  /' "$S/split.txt"
    echo "$me: merging the passes failed (a scene other than scene.pov may need POVRAY_MATTE_SHADERS)" >&2
    exit 1
fi
mv "$S/split.txt" "$O/split.txt"
sed 's/^/  /' "$O/split.txt"
echo "$me: wrote $out/full.exr"
