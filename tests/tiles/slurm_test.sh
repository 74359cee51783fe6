#!/bin/bash
# A single-node Slurm cluster on loopback, started and stopped by this test:
# munged with its own key and socket, slurmctld and slurmd (no systemd), all
# state in a temporary folder, nothing listening beyond 127.0.0.1.
#
#   slurm_test.sh DCM_BINARY SOURCE_DIR
#
# 1. A frame of the room scene as N tile jobs (examples/slurm/render-tiles.sbatch,
#    a job array) plus a merge job (merge.sbatch, --dependency=afterok), through
#    examples/slurm/submit.sh --wait: the merged frame is bit-identical to a
#    local one-process render.
# 2. Frames 1-2 where frame 2's scene does not exist: its tile jobs fail, the
#    merge job never runs, and the submission fails naming the failed tasks.
#
# Exit 77 (ctest: skipped) with the reason when Slurm or munge is not installed
# or cannot be started here (e.g. not root).
set -uo pipefail

dcm=${1:?usage: slurm_test.sh DCM_BINARY SOURCE_DIR}
src=${2:?usage: slurm_test.sh DCM_BINARY SOURCE_DIR}
tiles=4
size=128x96

skip() { echo "SKIP: $*"; exit 77; }
fail() { echo "FAIL: $*" >&2; exit 1; }

for tool in munged slurmctld slurmd sbatch sinfo scontrol; do
  command -v "$tool" >/dev/null 2>&1 || [[ -x /usr/sbin/$tool ]] ||
    skip "'$tool' is not installed (Debian: apt-get install --no-install-recommends slurm-wlm munge; scripts/install-deps.sh does)"
done
PATH=$PATH:/usr/sbin
(($(id -u) == 0)) || skip "slurmd must run as root to start jobs (SlurmUser=root); run ctest as root"

tmp=$(mktemp -d /tmp/dcm-slurm-test.XXXXXX) || fail "cannot create a temporary folder"
chmod 700 "$tmp"
pids=()
stop() {
  # Only what this test started, by process id; then the folder.
  for ((i = ${#pids[@]} - 1; i >= 0; --i)); do kill "${pids[i]}" 2>/dev/null; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null
  done
  if [[ ${KEEP_SLURM_TEST_DIR:-0} == 1 ]]; then echo "kept $tmp"; else rm -rf "$tmp"; fi
}
trap stop EXIT
trap 'exit 1' INT TERM

# Two free TCP ports on loopback.
read -r ctld_port slurmd_port < <(/usr/bin/python3 - <<'EOF'
import socket
socks = [socket.socket() for _ in range(2)]
for s in socks:
    s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in socks])
EOF
) || fail "cannot find free ports"

# munge: own key, socket, log and pid file.
mkdir -p "$tmp/munge" "$tmp/state" "$tmp/spool" "$tmp/work"
chmod 700 "$tmp/munge"
if command -v mungekey >/dev/null 2>&1 || [[ -x /usr/sbin/mungekey ]]; then
  mungekey --create --keyfile="$tmp/munge/munge.key" >/dev/null 2>&1 || fail "mungekey failed"
elif command -v create-munge-key >/dev/null 2>&1; then
  dd if=/dev/urandom of="$tmp/munge/munge.key" bs=1024 count=1 status=none || fail "cannot create the munge key"
else
  dd if=/dev/urandom of="$tmp/munge/munge.key" bs=1024 count=1 status=none || fail "cannot create the munge key"
fi
chmod 600 "$tmp/munge/munge.key"
munged --foreground --force --key-file="$tmp/munge/munge.key" --socket="$tmp/munge/munge.socket" \
  --pid-file="$tmp/munge/munged.pid" --log-file="$tmp/munge/munged.log" --seed-file="$tmp/munge/munged.seed" \
  >"$tmp/munge/stdout.log" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [[ -S $tmp/munge/munge.socket ]] && break; sleep 0.1; done
[[ -S $tmp/munge/munge.socket ]] || skip "munged did not start: $(tail -n 3 "$tmp/munge/stdout.log" "$tmp/munge/munged.log" 2>/dev/null | tr '\n' ' ')"

mem=$(awk '/MemTotal/ {print int($2 / 1024 / 2)}' /proc/meminfo)
cat >"$tmp/slurm.conf" <<EOF
ClusterName=dcmtest
SlurmctldHost=localhost(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/munge.socket
CommunicationParameters=NoCtldInAddrAny,NoInAddrAny
SchedulerType=sched/backfill
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
MinJobAge=300
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
NodeName=localhost NodeAddr=127.0.0.1 CPUs=2 RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$tmp/slurm.conf
# Nothing from the caller's environment may redirect the jobs.
unset SLURM_JOB_ID SLURM_ARRAY_TASK_ID SBATCH_PARTITION SBATCH_ACCOUNT

slurmctld -D -i >"$tmp/slurmctld.stdout" 2>&1 &
pids+=($!)
slurmd -D -N localhost >"$tmp/slurmd.stdout" 2>&1 &
pids+=($!)
idle=0
for _ in $(seq 150); do
  state=$(sinfo -h -n localhost -o %t 2>/dev/null)
  if [[ $state == idle ]]; then idle=1; break; fi
  for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null || break 2; done
  sleep 0.2
done
if ((idle == 0)); then
  echo "slurmctld log:"; tail -n 15 "$tmp/slurmctld.log" "$tmp/slurmctld.stdout" 2>/dev/null
  echo "slurmd log:"; tail -n 15 "$tmp/slurmd.log" "$tmp/slurmd.stdout" 2>/dev/null
  skip "the single-node cluster did not come up (node state '${state:-none}'), see the logs above"
fi
# Nothing listens beyond loopback.
if command -v ss >/dev/null 2>&1; then
  for port in "$ctld_port" "$slurmd_port"; do
    ss -ltnH "sport = :$port" | awk '{print $4}' | grep -qv '^127\.0\.0\.1:' &&
      fail "port $port listens beyond 127.0.0.1: $(ss -ltnH "sport = :$port")"
  done
fi
echo "cluster up: slurmctld on 127.0.0.1:$ctld_port, slurmd on 127.0.0.1:$slurmd_port"

same_pixels() {
  /usr/bin/python3 - "$1" "$2" <<'EOF'
import sys
import numpy as np
import OpenImageIO as oiio
a, b = (oiio.ImageBuf(p) for p in sys.argv[1:3])
for buf, path in ((a, sys.argv[1]), (b, sys.argv[2])):
    if buf.has_error:
        sys.exit(f"cannot read {path}: {buf.geterror()}")
pa, pb = a.get_pixels(oiio.FLOAT), b.get_pixels(oiio.FLOAT)
if pa.shape != pb.shape:
    sys.exit(f"shapes differ: {pa.shape} vs {pb.shape}")
differ = int(np.count_nonzero(pa.view(np.uint32) != pb.view(np.uint32)))
if differ:
    sys.exit(f"{differ} values differ")
print(f"bit-identical: {pa.shape[1]}x{pa.shape[0]}, {pa.shape[2]} channels")
EOF
}

cd "$tmp/work" || fail "no work folder"
scene=$src/examples/scenes/room.json
"$dcm" render "$scene" --size $size --quiet -o local.exr >/dev/null || fail "local render failed"

# 1. N tile jobs + a dependent merge job.
start=$(date +%s.%N)
"$src/examples/slurm/submit.sh" --tiles $tiles --wait --dcm "$dcm" out/room.exr -- render "$scene" --size $size \
  >submit.log 2>&1 || { cat submit.log; tail -n 20 out/parts/logs/* 2>/dev/null; fail "the submission failed"; }
cat submit.log
echo "submission took $(echo "$(date +%s.%N) - $start" | bc 2>/dev/null || echo '?') s"
[[ -f out/room.exr ]] || fail "no merged frame out/room.exr"
n=$(ls out/parts/room.tile-*-of-$tiles.exr | wc -l)
((n == tiles)) || fail "expected $tiles parts, found $n"
same_pixels local.exr out/room.exr || fail "the merged frame differs from the local render"
grep -q '"parts": '$tiles out/room.json || fail "merge stats lack the part count"

# 2. A failing tile job fails the submission, with a message naming it.
mkdir -p scenes
cp "$scene" scenes/room.0001.json
"$src/examples/slurm/submit.sh" --tiles 2 --frames 1-2 --wait --dcm "$dcm" bad/room.####.exr -- \
  render "$tmp/work/scenes/room.####.json" --size 64x48 >bad.log 2>&1
rc=$?
cat bad.log
((rc != 0)) || fail "a submission with failing tile jobs succeeded"
grep -q "2 tile job(s) of array job .* failed" bad.log || fail "no clear message about the failed tile jobs"
grep -q "frame 2" bad.log || fail "the message does not name the failed frame"
grep -q "room.0002.json" bad.log || fail "the message does not show the tile job's error"
[[ ! -e bad/room.0001.exr && ! -e bad/room.0002.exr ]] || fail "the merge ran although tile jobs failed"
echo "PASS: $tiles tile jobs + merge bit-identical to one process; failing tile jobs fail the submission"
