#!/usr/bin/env bash
# Regenerates tests/golden/*_summary.json from the smoke scenarios (and the trim smoke's stored
# cutting paths) after a deliberate change of behaviour (ctest's smoke runs compare their
# summary.json with these byte for byte). Commit them with the change that caused them, saying why
# they changed.
set -euo pipefail
cd "$(dirname "$0")/.."
# The trim smoke's stored cutting paths first (scenarios/trim/smoke.yaml says what they are for).
build/bin/trimbot trim precompute --out scenarios/trim/test_lawn_paths.sqlite --shapes ball --sizes 0.8 \
  --distances 1.08 --bearings 0 > /dev/null
for scenario in navigation/smoke bush_approach/smoke arm/smoke trim/smoke; do
  out=$(mktemp -d)
  build/bin/trimbot run "scenarios/$scenario.yaml" --out "$out" > /dev/null
  cp "$out/summary.json" "tests/golden/${scenario//\//_}_summary.json"
  rm -rf "$out"
done
git status --short tests/golden scenarios/trim/test_lawn_paths.sqlite
