#!/bin/sh
# End-to-end wall clock of `dcm povray` against `dcm povray --full` (the beauty
# pass rendered in full by one POV-Ray process) on one scene, interleaved in
# the same run, with the PSNR of dcm's result against that run's full render.
#
#   examples/povray/bench.sh [PATH/TO/dcm] [OUTDIR] [SIZES] [REPEATS] [SCENE] [-- DCM FLAGS...]
#
# SIZES: square frame sides ("512 1024"). Each repeat renders --full, then dcm
# (with --reference the full render just made). The time is the wall clock
# of the whole command, dcm's own start-up and every POV-Ray process included.
# Prints one line per run and the ratio table; writes OUTDIR/bench.txt.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
dcm=${1:-$here/../../build/tools/dcm/dcm}
out=${2:-$here/out}
sizes=${3:-512 1024}
reps=${4:-2}
scene=${5:-$here/scene.pov}
[ $# -gt 5 ] && shift 5 || set --
[ "${1:-}" = "--" ] && shift
[ -x "$dcm" ] || { echo "bench.sh: no dcm binary at $dcm" >&2; exit 1; }
mkdir -p "$out"
now() { date +%s.%N; }
json() {
    /usr/bin/python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
for k in sys.argv[2].split("."): d = d[k]
print(d)' "$1" "$2"
}
load() { cut -d' ' -f1 /proc/loadavg; }
res=$out/bench.txt
: >"$res"
echo "scene $scene, dcm flags: ${*:-(defaults)}; $(nproc) cores; load at start $(load)"
for size in $sizes; do
    r=1
    while [ "$r" -le "$reps" ]; do
        t=$(now)
        "$dcm" povray "$scene" -o "$out/full_$size.exr" --size "${size}x$size" --full -q
        tf=$(awk -v a="$t" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }')
        l1=$(load)
        t=$(now)
        "$dcm" povray "$scene" -o "$out/dcm_$size.exr" --size "${size}x$size" --reference "$out/full_$size.exr" \
            --stats "$out/dcm_$size.json" --sample-map "$out/map_$size.png" -q "$@"
        td=$(awk -v a="$t" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }')
        psnr=$(json "$out/dcm_$size.json" reference.psnr)
        frac=$(json "$out/dcm_$size.json" exact_fraction)
        lit=$(json "$out/dcm_$size.json" povray.lit_invocations)
        all=$(json "$out/dcm_$size.json" povray.invocations)
        standins=$(json "$out/dcm_$size.json" povray.preview_stand_ins)
        inproc=$(json "$out/dcm_$size.json" time_wall_s)
        line=$(awk -v s="$size" -v r="$r" -v f="$tf" -v d="$td" -v p="$psnr" -v e="$frac" -v l="$lit" -v a="$all" \
            -v si="$standins" -v l1="$l1" -v l2="$(load)" -v ip="$inproc" \
            'BEGIN { printf "%5d  %d  full %7.2f s  dcm %6.2f s  %5.2fx  %6.2f dB  exact %5.2f %%  stand-ins %5d  POV-Ray %d (%d lit)  load %s/%s  in-process %.2f s\n",
                     s, r, f, d, f / d, p, 100 * e, si, a, l, l1, l2, ip }')
        echo "$line"
        echo "$line" >>"$res"
        r=$((r + 1))
    done
done
# The table: medians over the repeats (the speed-up: of the paired ratios).
/usr/bin/python3 - "$res" <<'PY'
import statistics as st, sys
rows = [l.split() for l in open(sys.argv[1])]
print("  size  full s  dcm s  speed-up  PSNR dB  exact %   (medians of the repeats)")
for size in dict.fromkeys(r[0] for r in rows):
    rs = [r for r in rows if r[0] == size]
    f, d = [float(r[3]) for r in rs], [float(r[6]) for r in rs]
    ratio = [a / b for a, b in zip(f, d)]
    print(f"{size:>6}  {st.median(f):6.2f}  {st.median(d):5.2f}  {st.median(ratio):7.2f}x"
          f"  {st.median(float(r[9]) for r in rs):7.2f}  {st.median(float(r[12]) for r in rs):6.2f}")
PY
