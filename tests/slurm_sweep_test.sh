#!/usr/bin/env bash
# A real scheduler in the tests (issue 27): a single-node Slurm cluster on localhost
# (scripts/slurm_local_cluster.sh, config written at test time), then through the project's own
# submission path (`trimbot sweep --slurm`):
#   1. bad input is refused before anything is submitted (exit 2, nothing in --out): a partition
#      that does not exist, a work folder that cannot be written, a controller that does not answer;
#   2. a 3-point sweep of the smoke scenario submitted as one job array, one array task cancelled
#      while it runs: it is reported with its seed and resubmitted, and every point's merged
#      summary.json (and sweep.json) is byte-identical to the same sweep run here;
#   3. a `run --slurm --no-bag --video` batch: its array task runs with what the batch asked - its
#      trial has trial.mp4 and no run.bag.
# Exit 77 (ctest: skipped) where Slurm is not installed or cannot start (not root, no daemons).
# Usage: slurm_sweep_test.sh TRIMBOT SOURCE_DIR OUT_DIR [TRIALS]
set -uo pipefail
trimbot=$1
source_dir=$2
out=$3
trials=${4:-2}
cluster_script="$source_dir/scripts/slurm_local_cluster.sh"
scenario="$source_dir/scenarios/navigation/smoke.yaml"
grid="stack.navigation.follower.cruise_speed=0.2,0.25,0.3"

fail() {
  echo "FAIL: $*" >&2
  exit 1
}

"$cluster_script" check || exit 77
rm -rf "$out"
mkdir -p "$out"
cluster="$out/cluster"
exports=$("$cluster_script" start "$cluster") || { echo "Slurm could not start here: skipped" >&2; exit 77; }
trap '"$cluster_script" stop "$cluster"' EXIT
eval "$exports"
export TRIMBOT_MAP_CACHE="$out/map_cache"

# 1. Refused before submission: exit 2, the problem named, --out never created.
expect_refused() {  # NAME PATTERN COMMAND...
  local name=$1 pattern=$2
  shift 2
  local text code
  text=$("$@" 2>&1)
  code=$?
  echo "$name: exit $code: $(echo "$text" | tail -n 1)"
  [ "$code" -eq 2 ] || fail "$name: exit code $code, expected 2"
  echo "$text" | grep -q -- "$pattern" || fail "$name: the message does not name '$pattern'"
  [ ! -e "$out/refused" ] || fail "$name: --out was written"
  [ -z "$(squeue --noheader 2>/dev/null)" ] || fail "$name: something was submitted"
}
expect_refused "unknown partition" "partition 'nope' does not exist" \
  "$trimbot" sweep "$scenario" --grid "$grid" --trials 1 --out "$out/refused" --slurm --partition nope
expect_refused "work folder not writable" "--work-dir" \
  "$trimbot" sweep "$scenario" --grid "$grid" --trials 1 --out "$out/refused" --slurm --work-dir /proc/trimbot_work
expect_refused "output folder not writable" "--out" \
  "$trimbot" run "$scenario" --trials 1 --out /proc/trimbot_out/refused --slurm --work-dir "$out/work_refused"
sed 's/^SlurmctldPort=.*/SlurmctldPort=16899/' "$SLURM_CONF" > "$out/unreachable.conf"
expect_refused "controller not reachable" "Slurm is not reachable" \
  env SLURM_CONF="$out/unreachable.conf" "$trimbot" sweep "$scenario" --grid "$grid" --trials 1 --out "$out/refused" --slurm

# 2. The same sweep here and on the cluster.
"$trimbot" sweep "$scenario" --grid "$grid" --trials "$trials" --jobs 2 --out "$out/local" > "$out/local.log" 2>&1 ||
  fail "the local sweep failed: $(tail -n 5 "$out/local.log")"
"$trimbot" sweep "$scenario" --grid "$grid" --trials "$trials" --out "$out/slurm" --slurm --retries 1 --poll-seconds 1 \
  > "$out/slurm.log" 2>&1 &
sweep=$!
# Cancel the first array task that has run for a second, mid-trial.
cancelled=""
for _ in $(seq 1 300); do
  running=$(squeue --noheader --states=RUNNING --format='%i %M' 2>/dev/null | awk '$2 != "0:00" {print $1; exit}')
  if [ -n "$running" ]; then
    scancel "$running" && cancelled=$running
    break
  fi
  sleep 0.5
done
wait "$sweep"
code=$?
cat "$out/slurm.log"
[ -n "$cancelled" ] || fail "no array task was seen running to cancel"
echo "cancelled array task $cancelled"
[ "$code" -eq 0 ] || fail "trimbot sweep --slurm exited $code"
grep -q "failed: no exit status" "$out/slurm.log" || fail "the cancelled task was not reported"
grep -q "seed [0-9]" "$out/slurm.log" || fail "the cancelled task's seed was not reported"
grep -q "resubmitting" "$out/slurm.log" || fail "the cancelled task was not resubmitted"
for point in "$out"/local/points/*; do
  name=$(basename "$point")
  cmp "$point/summary.json" "$out/slurm/points/$name/summary.json" ||
    fail "point $name: the merged summary.json differs from the local run's"
done
cmp "$out/local/sweep.json" "$out/slurm/sweep.json" || fail "sweep.json differs from the local run's"
echo "3 points x $trials trials: every merged summary.json is byte-identical to the local sweep's"

# 3. What a batch asks each trial to record reaches the array tasks.
"$trimbot" run "$scenario" --trials 1 --out "$out/recorded" --slurm --poll-seconds 1 --no-bag --video \
  > "$out/recorded.log" 2>&1 || fail "trimbot run --slurm --no-bag --video failed: $(tail -n 5 "$out/recorded.log")"
grep -q -- "--no-bag" "$out"/recorded.slurm/submission_*/tasks.txt || fail "the array task was not given --no-bag"
[ -s "$out/recorded/trials/000/trial.mp4" ] || fail "the Slurm task's trial wrote no trial.mp4 (--video)"
[ ! -e "$out/recorded/trials/000/run.bag" ] || fail "the Slurm task's trial wrote run.bag (--no-bag)"
echo "run --slurm --no-bag --video: the task's trial has trial.mp4 and no run.bag"
