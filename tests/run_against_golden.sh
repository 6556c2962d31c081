#!/bin/sh
# Runs a scenario and checks that it passes its criteria and that its summary.json is byte for byte
# the golden one (all but the scenario file's path): the same scenario and seed give the same
# bytes, so any change of behaviour shows.
# A deliberate change of behaviour regenerates the golden files: scripts/update_golden.sh.
#   run_against_golden.sh TRIMBOT SCENARIO OUT_DIR GOLDEN_SUMMARY
trimbot=$1 scenario=$2 out=$3 golden=$4
"$trimbot" run "$scenario" --out "$out" || exit $?
# Every byte but the scenario file's absolute path (where the checkout sits is not behaviour).
without_path() { grep -v '^  "scenario_file": ' "$1"; }
without_path "$golden" > "$out/golden_summary.json"
without_path "$out/summary.json" > "$out/summary_without_path.json"
if ! cmp -s "$out/golden_summary.json" "$out/summary_without_path.json"; then
  echo "$out/summary.json differs from $golden (a change of behaviour; if deliberate: scripts/update_golden.sh):"
  diff "$out/golden_summary.json" "$out/summary_without_path.json" | head -40
  exit 1
fi
echo "summary.json identical to $golden"
