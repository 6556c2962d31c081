#!/usr/bin/env bash
# Measures how often `trimbot compare` flags a regression between two batches that differ only in
# their seeds (a false alarm), over PAIRS seed pairs of SCENARIO, and optionally how often it
# flags a candidate with extra overrides against the same baseline seeds (detection).
#   scripts/regression_false_alarms.sh SCENARIO PAIRS OUT_DIR [--set key=value ...]
# Prints one line per pair and the totals; batch folders stay in OUT_DIR.
set -euo pipefail
scenario="$1"; pairs="$2"; out="$3"; shift 3
candidate_sets=("$@")
trimbot="$(dirname "$0")/../build/bin/trimbot"
false_alarms=0; detections=0
for ((k = 0; k < pairs; ++k)); do
  seed_a=$((10000 + 100 * k)); seed_b=$((60000 + 100 * k))
  "$trimbot" run "$scenario" --seed "$seed_a" --jobs 2 --out "$out/a$k" > /dev/null || true
  "$trimbot" run "$scenario" --seed "$seed_b" --jobs 2 --out "$out/b$k" > /dev/null || true
  verdict="no regression"
  if ! "$trimbot" compare "$out/a$k" "$out/b$k" > "$out/compare_$k.md"; then verdict="FALSE ALARM"; false_alarms=$((false_alarms + 1)); fi
  line="pair $k (seeds $seed_a vs $seed_b): $verdict"
  if [ ${#candidate_sets[@]} -gt 0 ]; then
    "$trimbot" run "$scenario" --seed "$seed_a" --jobs 2 --out "$out/c$k" "${candidate_sets[@]}" > /dev/null || true
    if "$trimbot" compare "$out/b$k" "$out/c$k" > "$out/detect_$k.md"; then line+="; candidate: missed"
    else line+="; candidate: detected"; detections=$((detections + 1)); fi
  fi
  echo "$line"
done
echo "false alarms: $false_alarms of $pairs"
if [ ${#candidate_sets[@]} -gt 0 ]; then echo "detections: $detections of $pairs (${candidate_sets[*]})"; fi
