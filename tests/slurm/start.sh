#!/usr/bin/env bash
# Starts a one-node Slurm cluster on 127.0.0.1 under $1 (state, logs, sockets, config), for
# the tests: munge with a private key and socket, slurmctld and slurmd on ports 16817/16818
# bound to loopback, no accounting (sacct is unavailable, as on many small clusters).
# Needs root and Debian's slurmctld, slurmd, slurm-client and munge. Stop it with stop.sh.
set -euo pipefail
ROOT=$(realpath -m "${1:?usage: start.sh DIR}")
mkdir -p "$ROOT"/{state,spool,log,munge,run}
chmod 700 "$ROOT/munge"
HOST=$(hostname -s)
# munge with a private key and socket
if [ ! -f "$ROOT/munge/munge.key" ]; then
  dd if=/dev/urandom of="$ROOT/munge/munge.key" bs=1024 count=1 status=none
  chmod 400 "$ROOT/munge/munge.key"
fi
SOCK="$ROOT/munge/munge.socket"
munged --force --key-file="$ROOT/munge/munge.key" --socket="$SOCK" \
  --pid-file="$ROOT/munge/munged.pid" --log-file="$ROOT/log/munged.log" --seed-file="$ROOT/munge/seed"
NODE=$(slurmd -C | head -1)
cat > "$ROOT/slurm.conf" <<CONF
ClusterName=impactcal
SlurmctldHost=$HOST(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$SOCK
CommunicationParameters=NoCtldInAddrAny,NoInAddrAny
StateSaveLocation=$ROOT/state
SlurmdSpoolDir=$ROOT/spool
SlurmctldPidFile=$ROOT/run/slurmctld.pid
SlurmdPidFile=$ROOT/run/slurmd.pid
SlurmctldLogFile=$ROOT/log/slurmctld.log
SlurmdLogFile=$ROOT/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MailProg=/bin/true
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MaxArraySize=10001
MaxJobCount=20000
MinJobAge=300
SlurmctldTimeout=30
SlurmdTimeout=30
$NODE NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=debug Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
sed -i 's/UpTime=[^ ]*//' "$ROOT/slurm.conf"
export SLURM_CONF="$ROOT/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for i in $(seq 1 60); do
  if sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then
    echo "slurm up: SLURM_CONF=$SLURM_CONF"; exit 0
  fi
  sleep 0.5
done
echo "slurm did not come up" >&2; tail -20 "$ROOT/log/slurmctld.log" "$ROOT/log/slurmd.log" >&2; exit 1
