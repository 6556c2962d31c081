#!/usr/bin/env bash
# A throw-away single-node Slurm cluster on localhost, for tests (ctest) and CI.
#
#   scripts/slurm_local_cluster.sh check        exit 0 if the Slurm/munge binaries are there, else 77
#   scripts/slurm_local_cluster.sh start DIR    start munged, slurmctld, slurmd with everything in DIR;
#                                               prints "export SLURM_CONF=DIR/slurm.conf" on stdout
#   scripts/slurm_local_cluster.sh stop DIR     stop what `start DIR` started (exit 0 if nothing runs)
#
# Debian 12 packages: slurmctld slurmd slurm-client munge. Nothing under /etc is used or changed and
# no systemd is needed: every config, key, socket, pid, log and state file lives in DIR, and the ports
# are non-default, so this cannot collide with (or join) a real installation on the same machine.
# Must run as root (SlurmUser=root; slurmd has to be root to start jobs).
#
# Ports can be moved with SLURM_LOCAL_CTLD_PORT / SLURM_LOCAL_SLURMD_PORT, e.g. to run two clusters.
# Only stdout line of `start` is the export line, so `eval "$(scripts/slurm_local_cluster.sh start D)"`
# works; all progress and error messages go to stderr.
set -euo pipefail

# 77 is ctest's SKIP_RETURN_CODE: a machine without Slurm skips the tests instead of failing them.
readonly SKIP=77
readonly BINARIES=(slurmctld slurmd sbatch squeue sinfo scancel munged)
readonly CTLD_PORT="${SLURM_LOCAL_CTLD_PORT:-16817}"
readonly SLURMD_PORT="${SLURM_LOCAL_SLURMD_PORT:-16818}"
readonly START_TIMEOUT=60   # seconds to wait for the node to become idle
readonly STOP_TIMEOUT=30    # seconds to wait for each daemon to exit before SIGKILL

log() { echo "slurm_local_cluster: $*" >&2; }

usage() {
  echo "usage: $0 check | start DIR | stop DIR" >&2
  exit 2
}

# Slurm daemons are in /usr/sbin, which a non-login root shell (e.g. under ctest) may lack in PATH.
export PATH="${PATH}:/usr/sbin:/sbin"

cmd_check() {
  local missing=() b
  for b in "${BINARIES[@]}"; do
    command -v "$b" >/dev/null 2>&1 || missing+=("$b")
  done
  if ((${#missing[@]})); then
    log "missing: ${missing[*]} (Debian: apt-get install slurmctld slurmd slurm-client munge)"
    return "$SKIP"
  fi
  # slurmd must be root to launch jobs and SlurmUser=root below; a non-root run would only fail later.
  if [[ $(id -u) -ne 0 ]]; then
    log "must run as root"
    return "$SKIP"
  fi
  return 0
}

# Absolute path, so the pid files and slurm.conf paths do not depend on the caller's cwd.
abs_dir() {
  mkdir -p "$1"
  (cd "$1" && pwd -P)
}

# Unix socket paths are limited to 107 bytes; slurmd puts per-step sockets in its spool dir
# ("<node>_<job>.<step>") and munged its socket in DIR. A deep DIR (ctest's build tree) would exceed
# that, so sockets then go through a short symlink in /tmp named after a hash of DIR.
runtime_dir() {
  local dir=$1
  if ((${#dir} <= 60)); then
    echo "$dir"
  else
    echo "/tmp/slurm-lc-$(printf '%s' "$dir" | cksum | cut -d' ' -f1)"
  fi
}

# A daemon that exited but whose zombie pid 1 has not reaped yet (slow in some sandboxes: seconds)
# still answers kill -0; count state Z as gone.
pid_alive() {
  [[ -n ${1:-} ]] && kill -0 "$1" 2>/dev/null || return 1
  local stat
  stat=$(cat "/proc/$1/stat" 2>/dev/null) || return 1
  stat=${stat##*) }
  [[ ${stat%% *} != Z ]]
}

# Stop the daemon whose pid is in FILE, but only if that pid still runs a program named NAME:
# after a reboot or a crash the pid may have been reused by an unrelated process.
stop_daemon() {
  local name=$1 pidfile=$2 pid comm i
  [[ -f $pidfile ]] || return 0
  pid=$(tr -dc '0-9' <"$pidfile" || true)
  if ! pid_alive "$pid"; then
    rm -f "$pidfile"
    return 0
  fi
  comm=$(cat "/proc/$pid/comm" 2>/dev/null || true)
  if [[ $comm != "$name"* ]]; then
    log "pid $pid in $pidfile is '$comm', not $name: left alone"
    rm -f "$pidfile"
    return 0
  fi
  kill -TERM "$pid" 2>/dev/null || true
  for ((i = 0; i < STOP_TIMEOUT * 10; i++)); do
    pid_alive "$pid" || break
    sleep 0.1
  done
  if pid_alive "$pid"; then
    log "$name (pid $pid) ignored SIGTERM for ${STOP_TIMEOUT}s: SIGKILL"
    kill -KILL "$pid" 2>/dev/null || true
    for ((i = 0; i < 50; i++)); do pid_alive "$pid" || break; sleep 0.1; done
  fi
  rm -f "$pidfile"
}

# slurmstepd (one per running job step) outlives slurmd on purpose; so do the job's processes.
# Cancel every job while the controller is still up, so a stop leaves nothing of ours running.
cancel_all_jobs() {
  local conf=$1 i
  [[ -f $conf ]] || return 0
  # Only ask a running controller: an unreachable one makes each client call hang ~9 s in retries.
  pid_alive "$(tr -dc '0-9' 2>/dev/null <"${conf%/*}/slurmctld.pid" || true)" || return 0
  SLURM_CONF=$conf timeout 10 squeue -h -o %i >/dev/null 2>&1 || return 0
  SLURM_CONF=$conf timeout 10 scancel --full --quiet --user="$(id -un)" >/dev/null 2>&1 || true
  for ((i = 0; i < 150; i++)); do
    [[ -z $(SLURM_CONF=$conf timeout 10 squeue -h -o %i 2>/dev/null || true) ]] && return 0
    sleep 0.2
  done
  log "jobs still listed after scancel; stopping anyway"
}

# Last resort for steps that survived: a slurmstepd of this cluster keeps DIR/slurmd.log open.
kill_leftover_stepds() {
  local dir=$1 p fd
  for p in $(pgrep -x slurmstepd 2>/dev/null || true); do
    for fd in /proc/"$p"/fd/*; do
      if [[ $(readlink "$fd" 2>/dev/null || true) == "$dir"/* ]]; then
        log "killing leftover slurmstepd $p"
        kill -KILL "$p" 2>/dev/null || true
        break
      fi
    done
  done
}

cmd_stop() {
  local dir=$1
  [[ -d $dir ]] || return 0
  dir=$(abs_dir "$dir")
  cancel_all_jobs "$dir/slurm.conf"
  # slurmd before slurmctld (it reports to it), munged last (both daemons authenticate through it).
  stop_daemon slurmd "$dir/slurmd.pid"
  stop_daemon slurmctld "$dir/slurmctld.pid"
  kill_leftover_stepds "$dir"
  stop_daemon munged "$dir/munged.pid"
  local rt
  rt=$(runtime_dir "$dir")
  [[ $rt != "$dir" && -L $rt ]] && rm -f "$rt"
  return 0
}

# Print the end of every log, so a failed start in CI explains itself without a re-run.
dump_logs() {
  local dir=$1 f
  for f in "$dir"/munged.log "$dir"/slurmctld.log "$dir"/slurmd.log "$dir"/*.stderr; do
    [[ -s $f ]] || continue
    echo "----- tail of $f -----" >&2
    tail -n 40 "$f" >&2
  done
}

fail_start() {
  local dir=$1
  shift
  log "start failed: $*"
  dump_logs "$dir"
  cmd_stop "$dir"
  exit 1
}

# bash can probe a TCP port without ss/netstat: a successful connect means someone already listens.
port_in_use() {
  (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null
}

write_slurm_conf() {
  local dir=$1 rt=$2 node=$3 cpus=$4 mem_mb=$5
  cat >"$dir/slurm.conf" <<EOF
# Generated by scripts/slurm_local_cluster.sh at $(date -u +%Y-%m-%dT%H:%M:%SZ); rewritten on each start.
ClusterName=localtest
SlurmctldHost=${node}(127.0.0.1)
SlurmctldPort=${CTLD_PORT}
SlurmdPort=${SLURMD_PORT}
SlurmUser=root
SlurmdUser=root

# Our own munged, not the system one (which may not exist or may have another key).
AuthType=auth/munge
AuthInfo=socket=${rt}/munge.socket
CredType=cred/munge

StateSaveLocation=${dir}/state
SlurmdSpoolDir=${rt}/spool
SlurmctldPidFile=${dir}/slurmctld.pid
SlurmdPidFile=${dir}/slurmd.pid
SlurmctldLogFile=${dir}/slurmctld.log
SlurmdLogFile=${dir}/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
# Nonexistent plugstack file: keeps /etc/slurm/plugstack.conf (SPANK plugins) out of the test cluster.
PlugStackConfig=${dir}/plugstack.conf
MailProg=/bin/true

# A container has no usable cgroups: track processes through /proc, bind no tasks.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
MpiDefault=none
# No slurmdbd: nothing is accounted, so sacct has nothing to show.
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none

# Cores, not whole nodes, are the unit: two 1-CPU jobs run side by side on 2 cores.
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
# A node that was down (e.g. slurmd restarted) comes back by itself.
ReturnToService=2
# Trust the node line below even if the hardware layout differs (CI machines vary).
SlurmdParameters=config_overrides
# Without accounting, squeue/scontrol are the only way to see a finished job's final state
# (COMPLETED, FAILED, CANCELLED...): keep finished jobs in the controller for 5 minutes.
MinJobAge=300
# A dead slurmd is noticed soon.
SlurmdTimeout=30
InactiveLimit=0
KillWait=5

NodeName=${node} NodeAddr=127.0.0.1 NodeHostname=${node} CPUs=${cpus} RealMemory=${mem_mb} State=UNKNOWN
PartitionName=debug Nodes=${node} Default=YES MaxTime=INFINITE State=UP
EOF
}

cmd_start() {
  local dir rt node cpus mem_kb mem_mb i state port d
  cmd_check || exit $?
  dir=$(abs_dir "$1")
  # Never two sets of daemons on one DIR: stop whatever a previous start left behind.
  cmd_stop "$dir"

  for port in "$CTLD_PORT" "$SLURMD_PORT"; do
    # Slurm silently truncates a port above 65535; catch typos here.
    if [[ ! $port =~ ^[0-9]+$ ]] || ((port < 1024 || port > 65535)); then
      log "bad port '$port'"
      exit 2
    fi
    if port_in_use "$port"; then
      log "port $port is in use (another cluster?); set SLURM_LOCAL_CTLD_PORT/SLURM_LOCAL_SLURMD_PORT"
      exit 1
    fi
  done

  rt=$(runtime_dir "$dir")
  if [[ $rt != "$dir" ]]; then
    rm -f "$rt"
    ln -s "$dir" "$rt"
  fi

  # Throw-away: no job or node state carries over from an earlier run.
  rm -rf "$dir/state" "$dir/spool"
  rm -f "$dir"/*.log "$dir"/*.stderr "$dir/munge.socket" "$dir/munge.socket.lock"
  mkdir -p "$dir/state" "$dir/spool"
  # munged refuses key/socket/log dirs writable by group or others.
  chmod 0755 "$dir"

  # --- munge: a fresh key per cluster, readable only by the user munged runs as (root here) ---
  rm -f "$dir/munge.key"
  if command -v mungekey >/dev/null 2>&1; then
    mungekey --create --keyfile="$dir/munge.key" 2>>"$dir/munged.stderr"
  else
    dd if=/dev/urandom of="$dir/munge.key" bs=1 count=1024 status=none
  fi
  chown root:root "$dir/munge.key"
  chmod 0400 "$dir/munge.key"
  # Detached stdio: a daemon holding our stdout would hang a caller's $(...) forever.
  munged --key-file="$dir/munge.key" --socket="$rt/munge.socket" --pid-file="$dir/munged.pid" \
    --log-file="$dir/munged.log" --seed-file="$dir/munged.seed" \
    </dev/null >>"$dir/munged.stderr" 2>&1 || fail_start "$dir" "munged did not start"
  for ((i = 0; i < 100; i++)); do
    [[ -S $rt/munge.socket ]] && break
    sleep 0.1
  done
  [[ -S $rt/munge.socket ]] || fail_start "$dir" "no munge socket after 10 s"
  if command -v munge >/dev/null 2>&1 && command -v unmunge >/dev/null 2>&1; then
    munge -n -S "$rt/munge.socket" | unmunge -S "$rt/munge.socket" >/dev/null 2>>"$dir/munged.stderr" ||
      fail_start "$dir" "munge credential round trip failed"
  fi

  # --- slurm.conf, sized from this machine at start time ---
  # slurmd identifies itself by the short hostname; -N below pins it to the same name.
  node=$(hostname -s)
  cpus=$(nproc)
  mem_kb=$(awk '/^MemTotal:/ {print $2}' /proc/meminfo)
  # Slightly below the real total: slurmd drains a node reporting less memory than configured.
  mem_mb=$((mem_kb * 9 / 10 / 1024))
  ((mem_mb >= 1)) || mem_mb=1
  write_slurm_conf "$dir" "$rt" "$node" "$cpus" "$mem_mb"

  export SLURM_CONF="$dir/slurm.conf"
  slurmctld -f "$SLURM_CONF" </dev/null >>"$dir/slurmctld.stderr" 2>&1 ||
    fail_start "$dir" "slurmctld did not start"
  slurmd -f "$SLURM_CONF" -N "$node" </dev/null >>"$dir/slurmd.stderr" 2>&1 ||
    fail_start "$dir" "slurmd did not start"

  # --- bounded wait until the node is schedulable ---
  state=""
  for ((i = 0; i < START_TIMEOUT * 4; i++)); do
    state=$(timeout 10 sinfo -h -N -n "$node" -o %T 2>/dev/null || true)
    # "idle" exactly; "idle*" (not responding) or "idle~" are not ready.
    [[ $state == idle ]] && break
    # A daemon that died will not come back: do not wait out the full timeout.
    if ((i > 4)); then
      for d in munged slurmctld slurmd; do
        pid_alive "$(tr -dc '0-9' 2>/dev/null <"$dir/$d.pid" || true)" || fail_start "$dir" "$d exited"
      done
    fi
    sleep 0.25
  done
  [[ $state == idle ]] || fail_start "$dir" "node '$node' not idle after ${START_TIMEOUT}s (state: '${state}')"
  log "cluster up in $dir (node $node, $cpus CPUs, ${mem_mb} MB, ports $CTLD_PORT/$SLURMD_PORT)"
  echo "export SLURM_CONF=$dir/slurm.conf"
}

main() {
  (($# >= 1)) || usage
  case $1 in
    check)
      (($# == 1)) || usage
      cmd_check
      ;;
    start)
      (($# == 2)) || usage
      cmd_start "$2"
      ;;
    stop)
      (($# == 2)) || usage
      cmd_stop "$2"
      ;;
    *) usage ;;
  esac
}

main "$@"
