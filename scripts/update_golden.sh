#!/usr/bin/env bash
# Regenerates tests/golden/*_summary.json from the smoke scenarios after a deliberate change of
# behaviour (ctest's smoke runs compare their summary.json with these byte for byte). Commit them
# with the change that caused them, saying why they changed.
set -euo pipefail
cd "$(dirname "$0")/.."
for scenario in navigation/smoke bush_approach/smoke arm/smoke trim/smoke; do
  out=$(mktemp -d)
  build/bin/trimbot run "scenarios/$scenario.yaml" --out "$out" > /dev/null
  cp "$out/summary.json" "tests/golden/${scenario//\//_}_summary.json"
  rm -rf "$out"
done
git status --short tests/golden
