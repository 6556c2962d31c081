#!/usr/bin/env bash
# The main job: set up (packages + build), then run the rectangle navigation trials of the real
# robot headless in the Wageningen garden twin (6 trials, closed loop) -> out/rectangle/.
#   SCENARIO=scenarios/navigation/hourglass.yaml scripts/run_main.sh   another scenario
#   PLAN=scenarios/drives/wageningen_tour.yaml scripts/run_main.sh     an open-loop drive that
#                                                                      records the camera ring
# OUT_DIR sets the output folder; further arguments go to trimbot. Exit code 1: a criterion failed.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
if [ -n "${PLAN:-}" ]; then
  exec build/bin/trimbot drive "$PLAN" --out "${OUT_DIR:-out/drive}" "$@"
fi
SCENARIO="${SCENARIO:-scenarios/navigation/rectangle.yaml}"
exec build/bin/trimbot run "$SCENARIO" --out "${OUT_DIR:-out/$(basename "$SCENARIO" .yaml)}" --jobs 2 "$@"
