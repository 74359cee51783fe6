#!/bin/sh
# dcm on POV-Ray 3.7 renders of scene.pov (passes selected by Declare=Pass=N).
#
#   examples/povray/run.sh [PATH/TO/dcm] [OUTDIR] [SIZE]
#
# 1. Dense mode: every pass rendered in full, merged into one EXR (povtool.py
#    merge checks L = L_i*tau + L_c), `dcm reconstruct` on it: the exact
#    fraction and the PSNR against the full render.
# 2. The sparse round trip for real: the cheap guide passes (IDs, tau, normal) in
#    full (the dense mode's); then `dcm plan` asks for pixels and POV-Ray
#    renders the expensive passes (L_i, L) for just those pixels, one process
#    per pass and round, through a mesh_camera with one triangle per requested
#    pixel, until plan says done; `dcm reconstruct` with the samples. Reports
#    POV-Ray's time for the sparse passes against the full ones, the PSNR
#    against the full render and the difference to the dense-mode result.
# Writes OUTDIR/summary.txt ("key value" lines; tests/povray reads it).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
dcm=${1:-$here/../../build/tools/dcm/dcm}
out=${2:-$here/out}
size=${3:-512}
py=/usr/bin/python3
tool=$here/povtool.py
max_rounds=${DCM_POVRAY_MAX_ROUNDS:-60}

command -v povray >/dev/null 2>&1 || { echo "run.sh: povray is not installed (Debian: apt-get install povray)" >&2; exit 1; }
[ -x "$dcm" ] || { echo "run.sh: no dcm binary at $dcm (build it, or pass its path)" >&2; exit 1; }
case $size in ''|*[!0-9]*) echo "run.sh: SIZE must be a number of pixels" >&2; exit 2 ;; esac
P=$out/passes
R=$out/rounds
mkdir -p "$P" "$R"
rm -f "$R"/* "$P"/*.cpu "$out/summary.txt" "$out/samples.exr"

# pov LOG OUT.exr WIDTH HEIGHT ARGS...: one POV-Ray process (no display, no
# antialiasing, linear half-float EXR). POV-Ray's own CPU time (parse +
# bounding + trace, all threads) is appended to LOG.cpu. Include files
# (pixels.inc) are found through +L$out.
# It runs as a background job: POV-Ray is started in the background of the
# job and waited for, so that the TERM of run.sh's cleanup (below) reaches
# POV-Ray, which no interrupted run leaves behind.
pov() {
    log=$1 dst=$2 w=$3 h=$4
    shift 4
    pov_pid=
    trap '[ -z "$pov_pid" ] || kill "$pov_pid" 2>/dev/null; wait; rm -f "$dst".tmp.*; exit 143' TERM HUP
    povray -D -A +FE +W"$w" +H"$h" +L"$out" "$@" +I"$here/scene.pov" +O"$dst.tmp.exr" >"$log" 2>&1 &
    pov_pid=$!
    if ! wait "$pov_pid"; then
        echo "run.sh: povray failed (log: $log):" >&2
        grep -iE "error|fatal" "$log" >&2 || tail -5 "$log" >&2
        return 1
    fi
    mv "$dst.tmp.exr" "$dst"
    sed -n 's/.*with \([0-9.]*\) CPU-seconds total.*/\1/p' "$log" |
        awk '{ s += $1 } END { printf "%.3f\n", s }' >>"$log.cpu"
}
# Interrupted (Ctrl-C, TERM, HUP), run.sh ends its POV-Ray jobs before it exits.
end_jobs() {
    trap - INT TERM HUP
    # Not $(jobs -p): a command substitution is a subshell without the jobs.
    jobs -p >"$out/.jobs"
    while read -r job; do kill "$job" 2>/dev/null || :; done <"$out/.jobs"
    rm -f "$out/.jobs"
    wait
}
trap 'end_jobs; exit 130' INT
trap 'end_jobs; exit 143' TERM
trap 'end_jobs; exit 129' HUP
# wait_all PID...: waits for every process; fails if any failed.
wait_all() {
    rc=0
    for pid in "$@"; do wait "$pid" || rc=1; done
    return $rc
}
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.3f\n", b - a }'; }
add() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", a + b }'; }
sum() { awk '{ s += $1 } END { printf "%.2f", s }' "$@"; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }
pct() { awk -v f="$1" 'BEGIN { printf "%.2f", 100 * f }'; }
json() {
    "$py" -c 'import json, sys
d = json.load(open(sys.argv[1]))
for k in sys.argv[2].split("."): d = d[k]
print(d)' "$1" "$2"
}

echo "POV-Ray passes of $here/scene.pov at ${size}x${size} (out: $out)"
# ---- 1. dense mode ----------------------------------------------------------
# Each group of passes as processes at the same time: the 2 cores share the
# work, and POV-Ray's start-up (about 0.6 s, mostly waiting) overlaps.
t=$(now)
pov "$P/id.log" "$P/id.exr" "$size" "$size" Declare=Pass=1 & a=$!
pov "$P/shader.log" "$P/shader.exr" "$size" "$size" Declare=Pass=2 & b=$!
pov "$P/tau.log" "$P/tau.exr" "$size" "$size" Declare=Pass=3 & c=$!
pov "$P/normal.log" "$P/normal.exr" "$size" "$size" Declare=Pass=5 & d=$!
wait_all $a $b $c $d
guides_wall=$(elapsed "$t")
t=$(now)
pov "$P/li.log" "$P/li.exr" "$size" "$size" Declare=Pass=4 & a=$!
pov "$P/beauty.log" "$P/beauty.exr" "$size" "$size" Declare=Pass=0 & b=$!
wait_all $a $b
full_wall=$(elapsed "$t")
guides_cpu=$(sum "$P/id.log.cpu" "$P/shader.log.cpu" "$P/tau.log.cpu" "$P/normal.log.cpu")
full_cpu=$(sum "$P/li.log.cpu" "$P/beauty.log.cpu")
beauty_cpu=$(sum "$P/beauty.log.cpu")
echo "  full renders: guides (id, shader, tau, normal) ${guides_wall} s wall, ${guides_cpu} CPU-s;" \
    "L_i + L ${full_wall} s wall, ${full_cpu} CPU-s (L alone ${beauty_cpu} CPU-s)"
"$py" "$tool" merge "$out/full.exr" "$P/id.exr" "$P/shader.exr" "$P/tau.exr" "$P/normal.exr" \
    "$P/li.exr" "$P/beauty.exr" >"$out/split.txt"
sed 's/^/  /' "$out/split.txt"
"$py" "$tool" merge "$out/guides.exr" "$P/id.exr" "$P/shader.exr" "$P/tau.exr" "$P/normal.exr"
t=$(now)
"$dcm" reconstruct "$out/full.exr" -o "$out/dense.exr" --stats "$out/dense.json" --quiet
dense_dcm=$(elapsed "$t")
dense_frac=$(json "$out/dense.json" exact_fraction)
dense_psnr=$(json "$out/dense.json" reference.psnr)

# ---- 2. the sparse round trip -----------------------------------------------
samples=""
round=0
requested=0
pov_wall=0 dcm_wall=0 glue_wall=0
t_all=$(now)
while :; do
    t=$(now)
    # shellcheck disable=SC2086
    state=$("$dcm" plan "$out/guides.exr" $samples --list "$R/next.txt" --mask "$R/next.exr" --quiet)
    dcm_wall=$(add "$dcm_wall" "$(elapsed "$t")")
    [ "$state" = "done" ] && break
    case $state in "pending "*) ;; *) echo "run.sh: unexpected answer of dcm plan: $state" >&2; exit 1 ;; esac
    [ "$round" -lt "$max_rounds" ] || { echo "run.sh: dcm plan still pending after $max_rounds rounds" >&2; exit 1; }
    t=$(now)
    # The list as POV-Ray arrays for scene.pov's Sparse mode.
    awk 'BEGIN { n = 0 }
         NR == 1 && !/^# dcm plan:/ { exit 1 }
         /^#/ { next }
         NF == 2 { x[n] = $1; y[n] = $2; n++ }
         END {
           if (n == 0) exit 1
           printf "#declare NPix = %d;\n#declare PixX = array[%d] {", n, n
           for (i = 0; i < n; i++) printf "%s%s%d", (i ? "," : ""), (i % 24 ? "" : "\n"), x[i]
           printf "\n}\n#declare PixY = array[%d] {", n
           for (i = 0; i < n; i++) printf "%s%s%d", (i ? "," : ""), (i % 24 ? "" : "\n"), y[i]
           printf "\n}\n"
         }' "$R/next.txt" >"$out/pixels.inc.tmp" || { echo "run.sh: cannot read the list $R/next.txt" >&2; exit 1; }
    mv "$out/pixels.inc.tmp" "$out/pixels.inc"
    n=${state#pending }
    # One mesh_camera face per pixel: an image sw wide, one row per sw faces
    # plus the row POV-Ray 3.7 skips (povtool.py sparse_size); render rows 2..
    sw=$((n < size ? n : size))
    sh=$(((n + sw - 1) / sw + 1))
    glue_wall=$(add "$glue_wall" "$(elapsed "$t")")
    t=$(now)
    sparse="+SR2 Declare=Sparse=1 Declare=FullW=$size Declare=FullH=$size"
    # shellcheck disable=SC2086
    pov "$R/li.log" "$R/li_$round.exr" "$sw" "$sh" Declare=Pass=4 $sparse & a=$!
    # shellcheck disable=SC2086
    pov "$R/beauty.log" "$R/beauty_$round.exr" "$sw" "$sh" Declare=Pass=0 $sparse & b=$!
    wait_all $a $b
    pov_wall=$(add "$pov_wall" "$(elapsed "$t")")
    t=$(now)
    "$py" "$tool" scatter "$R/next.txt" "$R/li_$round.exr" "$R/beauty_$round.exr" "$out/samples.exr"
    glue_wall=$(add "$glue_wall" "$(elapsed "$t")")
    echo "  round $round: $n pixels, POV-Ray $(tail -1 "$R/li.log.cpu") + $(tail -1 "$R/beauty.log.cpu") CPU-s"
    samples="--samples $out/samples.exr"
    requested=$((requested + n))
    round=$((round + 1))
done
t=$(now)
# shellcheck disable=SC2086
"$dcm" reconstruct "$out/guides.exr" $samples --reference "$P/beauty.exr" -o "$out/sparse.exr" \
    --stats "$out/sparse.json" --sample-map "$out/sample_map.png" --preview "$out/sparse.png" --quiet
dcm_wall=$(add "$dcm_wall" "$(elapsed "$t")")
sparse_total=$(elapsed "$t_all")
sparse_frac=$(json "$out/sparse.json" exact_fraction)
sparse_psnr=$(json "$out/sparse.json" reference.psnr)
sparse_cpu=$(sum "$R/li.log.cpu" "$R/beauty.log.cpu")
# shellcheck disable=SC2046
set -- $("$py" "$tool" compare "$out/sparse.exr" "$out/dense.exr")
sd_max=$2 sd_count=$4 sd_rms=$6
# shellcheck disable=SC2046
set -- $("$py" "$tool" check "$out/samples.exr" "$out/full.exr")
same_max=$4 same_count=$6 same_beyond=$8

cat <<EOF
dense mode: every pass in full, dcm reconstruct ${dense_dcm} s
  exact pixels   $(pct "$dense_frac") %, PSNR $(printf '%.2f' "$dense_psnr") dB against the full render
sparse mode: $round rounds of dcm plan, 2 POV-Ray processes each (mesh_camera)
  exact pixels   $(pct "$sparse_frac") % ($requested of $((size * size)) rendered), PSNR $(printf '%.2f' "$sparse_psnr") dB against the full render
  L_i + L        sparse ${sparse_cpu} CPU-s, ${pov_wall} s wall; full ${full_cpu} CPU-s, ${full_wall} s wall
  speed-up       $(ratio "$full_cpu" "$sparse_cpu")x in POV-Ray CPU time, $(ratio "$full_wall" "$pov_wall")x in POV-Ray wall time
  round trip     ${sparse_total} s in all: POV-Ray ${pov_wall} s, dcm plan + reconstruct ${dcm_wall} s, list/scatter ${glue_wall} s
  rendered       against the same pixels of the full render: max |difference| ${same_max}, ${same_count} pixels differ, ${same_beyond} by more than 1e-3
  sparse - dense max |difference| ${sd_max}, RMS ${sd_rms}, ${sd_count} pixels differ
EOF
cat >"$out/summary.txt.tmp" <<EOF
size $size
rounds $round
requested $requested
dense_fraction $dense_frac
dense_psnr $dense_psnr
sparse_fraction $sparse_frac
sparse_psnr $sparse_psnr
sparse_dense_maxdiff $sd_max
sparse_dense_differing $sd_count
sparse_dense_rms $sd_rms
samples_maxdiff $same_max
samples_differing $same_count
samples_beyond $same_beyond
guides_cpu $guides_cpu
guides_wall $guides_wall
full_cpu $full_cpu
full_wall $full_wall
beauty_cpu $beauty_cpu
sparse_cpu $sparse_cpu
sparse_pov_wall $pov_wall
sparse_total_wall $sparse_total
dcm_wall $dcm_wall
glue_wall $glue_wall
EOF
mv "$out/summary.txt.tmp" "$out/summary.txt"
