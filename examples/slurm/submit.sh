#!/bin/bash
# Renders (or reconstructs) a frame or a frame sequence on a Slurm cluster as
# tile jobs (a job array) plus a merge job that runs when they all succeeded.
#
#   submit.sh [--tiles N] [--frames A-B] [--parts DIR] [--wait] [--dcm PATH]
#             [--sbatch ARG]... OUTPUT.exr -- COMMAND INPUT [dcm flags...]
#
#   submit.sh --tiles 8 out/room.exr -- render examples/scenes/room.json
#   submit.sh --tiles 4 --frames 1-24 out/shot.####.exr -- reconstruct in/shot.####.exr --preset blender
#
# --tiles N     tiles per frame (default 8)
# --frames A-B  a sequence: '#' runs in INPUT and OUTPUT are the frame number
# --parts DIR   where the parts and the job logs go (default: OUTPUT's folder/parts)
# --wait        wait for the merge job (sbatch --wait); exit non-zero, naming the
#               failed tile jobs and their logs, if any job failed
# --dcm PATH    the dcm binary as the compute nodes see it (default: dcm on PATH)
# --sbatch ARG  extra sbatch argument for every job (e.g. --partition=render), repeatable
#
# Every path must be visible from the compute nodes (a shared file system).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
tiles=8 frames=- parts= wait=0 dcm=${DCM:-dcm}
extra=()
die() { echo "submit.sh: $*" >&2; exit 2; }
while (($#)); do
  case $1 in
    --tiles) tiles=${2:?--tiles needs N}; shift 2 ;;
    --frames) frames=${2:?--frames needs A-B}; shift 2 ;;
    --parts) parts=${2:?--parts needs DIR}; shift 2 ;;
    --wait) wait=1; shift ;;
    --dcm) dcm=${2:?--dcm needs PATH}; shift 2 ;;
    --sbatch) extra+=("${2:?--sbatch needs an argument}"); shift 2 ;;
    --) die "OUTPUT.exr missing before --" ;;
    -*) die "unknown option $1" ;;
    *) break ;;
  esac
done
(($# >= 4)) && [[ $2 == -- ]] || die "usage: submit.sh [options] OUTPUT.exr -- COMMAND INPUT [dcm flags...]"
output=$1
shift 2
[[ $tiles =~ ^[1-9][0-9]*$ ]] || die "--tiles: expected a positive number, got '$tiles'"
first=- count=1
if [[ $frames != - ]]; then
  [[ $frames =~ ^([0-9]+)(-([0-9]+))?$ ]] || die "--frames: expected A-B, got '$frames'"
  first=$((10#${BASH_REMATCH[1]}))
  last=$((10#${BASH_REMATCH[3]:-${BASH_REMATCH[1]}}))
  ((last >= first)) || die "--frames $frames: B < A"
  count=$((last - first + 1))
  [[ $output == *'#'* ]] || die "--frames: OUTPUT needs a '#' frame pattern (e.g. out/shot.####.exr)"
fi
name=$(basename "$output" .exr)
parts=${parts:-$(dirname "$output")/parts}
mkdir -p "$parts/logs" "$(dirname "$output")"
# The jobs may start in another directory: absolute paths for what they write.
parts=$(cd "$parts" && pwd)
output=$(cd "$(dirname "$output")" && pwd)/$(basename "$output")
if [[ $dcm == */* ]]; then dcm=$(cd "$(dirname "$dcm")" && pwd)/$(basename "$dcm"); fi

array=$(sbatch --parsable "${extra[@]}" --export=ALL,DCM="$dcm" --array=0-$((count * tiles - 1)) \
  --output="$parts/logs/%x-%A_%a.out" \
  "$here/render-tiles.sbatch" "$tiles" "$first" "$parts" "$name" "$@")
array=${array%%;*}
echo "submit.sh: tile jobs: array job $array ($((count * tiles)) tasks: $count frame(s) x $tiles tiles)"
merge_args=(--parsable "${extra[@]}" --export=ALL,DCM="$dcm" --dependency=afterok:"$array"
  --kill-on-invalid-dep=yes --output="$parts/logs/%x-%j.out")
if ((wait == 0)); then
  merge=$(sbatch "${merge_args[@]}" "$here/merge.sbatch" "$tiles" "$frames" "$parts" "$name" "$output")
  echo "submit.sh: merge job ${merge%%;*} runs after every tile job succeeded -> $output"
  echo "submit.sh: follow with: squeue -j $array,${merge%%;*}; logs in $parts/logs"
  exit 0
fi

set +e
merge=$(sbatch --wait "${merge_args[@]}" "$here/merge.sbatch" "$tiles" "$frames" "$parts" "$name" "$output")
rc=$?
set -e
merge=${merge%%;*}
# sbatch --wait returns 0 for a job cancelled before it started (a tile job
# failed, so afterok can never be met): only a COMPLETED merge job counts.
merge_state=$(scontrol -o show job "$merge" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | cut -d= -f2)
if ((rc == 0)) && [[ $merge_state == COMPLETED ]]; then
  echo "submit.sh: merge job $merge done -> $output"
  exit 0
fi
# Which tile jobs failed, and why (scontrol keeps finished jobs for MinJobAge).
failed=()
while read -r line; do
  state=$(grep -o 'JobState=[A-Z_]*' <<<"$line" | cut -d= -f2)
  task=$(grep -o 'ArrayTaskId=[0-9]*' <<<"$line" | cut -d= -f2)
  code=$(grep -o ' ExitCode=[0-9:]*' <<<"$line" | cut -d= -f2)
  if [[ -n $task && $state != COMPLETED ]]; then failed+=("$task:$state:$code"); fi
done < <(scontrol -o show job "$array" 2>/dev/null)
if ((${#failed[@]})); then
  mapfile -t failed < <(printf '%s\n' "${failed[@]}" | sort -n -t: -k1,1)
  echo "submit.sh: error: ${#failed[@]} tile job(s) of array job $array failed; merge job $merge did not run (${merge_state:-state unknown}):" >&2
  for f in "${failed[@]}"; do
    IFS=: read -r task state code <<<"$f"
    log="$parts/logs/dcm-tiles-${array}_$task.out"
    where="tile $((task % tiles))/$tiles"
    if [[ $first != - ]]; then where+=", frame $((first + task / tiles))"; fi
    echo "  task $task ($where): $state, exit code $code; log $log" >&2
    if [[ -f $log ]]; then tail -n 3 "$log" | sed 's/^/    | /' >&2; fi
  done
else
  echo "submit.sh: error: merge job $merge failed (${merge_state:-state unknown}, sbatch exit $rc); log $parts/logs/dcm-merge-$merge.out" >&2
  if [[ -f $parts/logs/dcm-merge-$merge.out ]]; then tail -n 5 "$parts/logs/dcm-merge-$merge.out" | sed 's/^/    | /' >&2; fi
fi
exit 1
