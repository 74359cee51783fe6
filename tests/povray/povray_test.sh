#!/bin/bash
# `dcm povray` driven with the real POV-Ray on examples/povray/scene.pov.
#
#   povray_test.sh exact|quality|errors DCM_BINARY SOURCE_DIR [POVRAY]
#
# exact: at 96x72, the exact pixels of `dcm povray` (those its sample map marks,
#   with --max-rounds 10 --min-round-share 0: no preview stand-in is left) equal the --full
#   render's within two half-float steps (tests/povray/exact_check.py says
#   why); with the defaults, at most 5 POV-Ray processes render the lit
#   passes (docs/POVRAY.md: 1 preview + 2 rounds x 2) and 10 in all (5 guides),
#   and the PSNR against --full is at least 35 dB (measured 38.5 dB).
# quality: --target-psnr 35 is reached by the report and against --full (within
#   the issue's 0.5 dB), in at most two rounds per run of the quality search
#   (the first validation draw goes with the first) and one per later draw (at
#   most three where the estimate's bound falls short, and the last);
#   --budget 0.2 renders at most 20 % of the pixels.
# errors: a missing scene, a scene without the pass convention, POV-Ray that
#   fails (/bin/false) or crashes in the exact round, an output folder that
#   does not exist, SIGTERM during a render: exit 1 with a message naming the
#   file and the step, no output, no scratch folder left, no POV-Ray left;
#   SIGKILL of dcm: POV-Ray ends with it (plugins/pipe's supervisor).
# Exit 77 (ctest: skipped) where povray is not installed.
set -uo pipefail

mode=${1:?usage: povray_test.sh exact|quality|errors DCM_BINARY SOURCE_DIR [POVRAY]}
dcm=${2:?}
src=${3:?}
povray_bin=${4:-}
skip() { echo "SKIP: $*"; exit 77; }
fail() { echo "FAIL: $*" >&2; exit 1; }
ok() { echo "ok: $*"; }

if [[ -n $povray_bin && -x $povray_bin ]]; then PATH=$(dirname "$povray_bin"):$PATH; fi
command -v povray >/dev/null 2>&1 ||
  skip "povray is not installed (Debian: apt-get install povray; scripts/install-deps.sh does)"

tmp=$(mktemp -d /tmp/dcm-povray-test.XXXXXX) || fail "cannot create a temporary folder"
trap 'rm -rf "$tmp"' EXIT
# The scratch folders go here (TMPDIR). POV-Ray runs through a link of its
# own, so that its processes of this test, and only those, start with "$pov"
# (dcm's command lines start with dcm). The scene's path has a space and a
# quote, which POV-Ray's command line cannot take (dcm passes it in an INI file).
export TMPDIR=$tmp/scratch
mkdir -p "$TMPDIR"
pov=$tmp/povray-under-test
ln -s "$(command -v povray)" "$pov"
running() { pgrep -f "^$pov" >/dev/null; }
mkdir -p "$tmp/my scenes"
scene="$tmp/my scenes/it's a room.pov"
cp "$src/examples/povray/scene.pov" "$scene"
size=96x72
py=/usr/bin/python3
json() { "$py" -c 'import json, sys
d = json.load(open(sys.argv[1]))
for k in sys.argv[2].split("."): d = d[k]
print(d)' "$1" "$2"; }

# clean NAME OUTPUT: what every failed run must leave: no output, no scratch folder, no POV-Ray.
clean() {
  [[ ! -e $2 ]] || fail "$1: the output $2 exists"
  [[ -z $(ls -A "$TMPDIR") ]] || fail "$1: scratch left: $(ls -A "$TMPDIR")"
  if running; then fail "$1: a POV-Ray process is left: $(pgrep -af "^$pov")"; fi
  if guardian; then fail "$1: a scratch guardian is left: $(pgrep -af dcm-scratch-guardian)"; fi
}
# scratch_gone: after dcm was killed, its scratch folder's guardian removes the
# folder and ends (its last removal is 3 s after dcm's death; 6 s allow for load).
guardian() { pgrep -f "dcm-scratch-guardian $TMPDIR/" >/dev/null; }
scratch_gone() {
  for _ in $(seq 120); do
    [[ -z $(ls -A "$TMPDIR") ]] && ! guardian && return 0
    sleep 0.05
  done
  fail "the scratch folder or its guardian outlived dcm by 6 s: $(ls -A "$TMPDIR"; pgrep -af dcm-scratch-guardian)"
}
# expect NAME CODE PATTERN OUTPUT -- COMMAND...: exit CODE, stderr matching PATTERN, then clean.
expect() {
  local name=$1 code=$2 pattern=$3 output=$4
  shift 5
  "$@" 2>"$tmp/err" >/dev/null
  local rc=$?
  [[ $rc -eq $code ]] || fail "$name: exit $rc, not $code: $(cat "$tmp/err")"
  grep -qE -- "$pattern" "$tmp/err" || fail "$name: the message does not match '$pattern': $(cat "$tmp/err")"
  clean "$name" "$output"
  ok "$name: exit $code, $(head -1 "$tmp/err")"
}

case $mode in
exact)
  "$dcm" povray "$scene" -o "$tmp/full.exr" --size $size --full --povray "$pov" -q || fail "dcm povray --full failed"
  "$dcm" povray "$scene" -o "$tmp/all.exr" --size $size --max-rounds 10 --min-round-share 0 --stats "$tmp/all.json" --povray "$pov" \
    --sample-map "$tmp/all.png" -q || fail "dcm povray --max-rounds 10 failed"
  [[ $(json "$tmp/all.json" povray.preview_stand_ins) == 0 ]] || fail "--max-rounds 10 left preview stand-ins"
  read -r _ n _ total _ maxrel _ beyond < <("$py" "$src/tests/povray/exact_check.py" "$tmp/all.exr" "$tmp/full.exr" "$tmp/all.png")
  [[ $n -gt 0 && $n -lt $((total * 2 / 5)) ]] || fail "exact pixels $n of $total: none, or more than 40 %"
  [[ $beyond == 0 ]] || fail "$beyond exact values differ from the full render by more than two half-float steps (max relative $maxrel)"
  ok "$n of $total exact pixels equal the full render's (max relative difference $maxrel)"
  [[ -z $(ls -A "$TMPDIR") ]] || fail "scratch left after a run: $(ls -A "$TMPDIR")"

  "$dcm" povray "$scene" -o "$tmp/dcm.exr" --size $size --reference "$tmp/full.exr" --stats "$tmp/dcm.json" \
    --povray "$pov" -q ||
    fail "dcm povray failed"
  lit=$(json "$tmp/dcm.json" povray.lit_invocations)
  all=$(json "$tmp/dcm.json" povray.invocations)
  psnr=$(json "$tmp/dcm.json" reference.psnr)
  [[ $lit -le 5 && $all -le 10 ]] || fail "$all POV-Ray processes, $lit for the lit passes (at most 10 and 5)"
  awk -v p="$psnr" 'BEGIN { exit !(p >= 35) }' || fail "PSNR $psnr dB against --full, below 35 dB"
  ok "defaults: $all POV-Ray processes ($lit lit), PSNR $psnr dB against --full"
  ;;
quality)
  "$dcm" povray "$scene" -o "$tmp/full.exr" --size $size --full --povray "$pov" -q || fail "dcm povray --full failed"
  "$dcm" povray "$scene" -o "$tmp/q.exr" --size $size --target-psnr 35 --reference "$tmp/full.exr" \
    --stats "$tmp/q.json" --povray "$pov" -q || fail "dcm povray --target-psnr 35 failed"
  reached=$(json "$tmp/q.json" quality.target_reached)
  psnr=$(json "$tmp/q.json" reference.psnr)
  est=$(json "$tmp/q.json" estimated_psnr_low)
  runs=$(json "$tmp/q.json" quality.runs)
  rounds=$(json "$tmp/q.json" povray.rounds)
  [[ $reached == True ]] || fail "--target-psnr 35: not reached by the report (lower bound $est dB)"
  awk -v p="$psnr" 'BEGIN { exit !(p >= 34.5) }' || fail "--target-psnr 35: $psnr dB against --full"
  # Two calls per run (the first validation draw with the first), one per later draw: at most three
  # where the bound falls short, and up to three confirming draws (kMaxConfirmations).
  [[ $rounds -ge 1 && $rounds -le $((2 * runs + 6)) ]] || fail "--target-psnr 35: $rounds rounds for $runs runs"
  ok "--target-psnr 35: $psnr dB against --full (lower bound $est dB), $runs runs in $rounds rounds"
  "$dcm" povray "$scene" -o "$tmp/b.exr" --size $size --budget 0.2 --stats "$tmp/b.json" --povray "$pov" -q ||
    fail "dcm povray --budget 0.2 failed"
  fraction=$(json "$tmp/b.json" exact_fraction)
  rendered=$(json "$tmp/b.json" povray.exact_pixels_rendered)
  awk -v f="$fraction" -v r="$rendered" 'BEGIN { exit !(f <= 0.2 && r <= 0.2 * 96 * 72) }' ||
    fail "--budget 0.2: exact fraction $fraction, $rendered pixels rendered"
  ok "--budget 0.2: exact fraction $fraction ($rendered pixels rendered)"
  ;;
errors)
  out=$tmp/out.exr
  expect "missing scene" 1 "no-such.pov is not a file" "$out" -- "$dcm" povray "$tmp/no-such.pov" -o "$out" --size $size
  echo 'sphere { 0, 1 pigment { rgb 1 } } camera { location -3*z look_at 0 } light_source { <1, 1, -5> rgb 1 }' \
    >"$tmp/plain.pov"
  expect "no pass convention" 1 "plain.pov does not follow the pass convention" "$out" -- \
    "$dcm" povray "$tmp/plain.pov" -o "$out" --size $size
  # The words are there, but the scene ignores Pass: the ID pass is the beauty.
  { echo '// Pass Sparse PixX PixY NPix'; cat "$tmp/plain.pov"; } >"$tmp/ignores.pov"
  expect "scene ignoring Pass" 1 "pass 1 \(object ID\) of ignores.pov does not hold one integer" "$out" -- \
    "$dcm" povray "$tmp/ignores.pov" -o "$out" --size $size
  expect "povray /bin/false" 1 "rendering pass [0-9] \(.*\) of it's a room.pov failed: POV-Ray \(/bin/false\) exited with status 1" \
    "$out" -- "$dcm" povray "$scene" -o "$out" --size $size --povray /bin/false
  # A POV-Ray that renders the guides and the preview, then crashes in the first exact round.
  cat >"$tmp/crashing-povray" <<EOS
#!/bin/sh
case "\$*" in *Sparse=1*) kill -SEGV \$\$ ;; esac
exec "$pov" "\$@"
EOS
  chmod +x "$tmp/crashing-povray"
  expect "POV-Ray crashing mid-run" 1 "rendering pass [04] \(.*\) for [0-9]+ pixels of it's a room.pov failed: .*signal 11" "$out" -- \
    "$dcm" povray "$scene" -o "$out" --size $size --povray "$tmp/crashing-povray"
  expect "output folder missing" 1 "-o: cannot write '$tmp/no-dir/out.exr'" "$tmp/no-dir/out.exr" -- \
    "$dcm" povray "$scene" -o "$tmp/no-dir/out.exr" --size $size --povray "$pov"
  expect "output = scene" 2 "an output never replaces an input" "$out" -- "$dcm" povray "$scene" -o "$scene" --size $size
  cmp -s "$scene" "$src/examples/povray/scene.pov" || fail "the scene was changed"
  expect "bad --size" 2 "--size: must be WIDTHxHEIGHT" "$out" -- "$dcm" povray "$scene" -o "$out" --size 96
  expect "quality goal with --full" 2 "--target-psnr: not with --full" "$out" -- \
    "$dcm" povray "$scene" -o "$out" --size $size --target-psnr 40 --full
  # SIGTERM while POV-Ray renders: dcm ends it and removes the scratch folder.
  "$dcm" povray "$scene" -o "$out" --size 320x240 --full --povray "$pov" -q 2>"$tmp/err" &
  pid=$!
  for _ in $(seq 100); do running && break; sleep 0.05; done
  running || fail "SIGTERM: POV-Ray never started"
  sleep 0.3
  kill -TERM $pid
  wait $pid
  rc=$?
  [[ $rc -eq 143 ]] || fail "SIGTERM: exit $rc, not 143 (killed by SIGTERM)"
  scratch_gone
  clean "SIGTERM" "$out"
  ok "SIGTERM during a render: no output, no scratch, no POV-Ray"
  # SIGKILL: nothing of dcm runs to clean up, but its supervisor takes POV-Ray along.
  "$dcm" povray "$scene" -o "$out" --size 320x240 --full --povray "$pov" -q 2>"$tmp/err" &
  pid=$!
  for _ in $(seq 100); do running && break; sleep 0.05; done
  running || fail "SIGKILL: POV-Ray never started"
  kill -KILL $pid
  wait $pid 2>/dev/null
  for _ in $(seq 60); do running || break; sleep 0.05; done
  if running; then fail "SIGKILL: POV-Ray still runs 3 s after dcm died: $(pgrep -af "^$pov")"; fi
  scratch_gone
  clean "SIGKILL" "$out"
  ok "SIGKILL of dcm during a render: POV-Ray ends with it, no output, no scratch"
  ;;
*) fail "unknown mode $mode" ;;
esac
echo PASS
