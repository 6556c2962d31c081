#!/usr/bin/env bash
# The main job: set up (packages + build), then run the rectangle navigation trials of the real
# robot headless in the Wageningen garden twin on the robot's own software (6 trials, closed loop,
# localized by its cameras against a visual map) -> out/rectangle_visual/. The map is built from the
# scenario's mapping drive on first use (about 5 min on 2 cores) and cached ($TRIMBOT_MAP_CACHE,
# default ~/.cache/trimbot/maps); later runs reuse it.
#   SCENARIO=scenarios/navigation/hourglass_visual.yaml scripts/run_main.sh   another scenario
#   SCENARIO=scenarios/navigation/rectangle.yaml scripts/run_main.sh          the fast one: pose fixes
#                                                  drawn from ground truth (a test fixture, not localization)
#   PLAN=scenarios/drive_plans/wageningen_tour.yaml scripts/run_main.sh            an open-loop drive that
#                                                                             records the camera ring
# OUT_DIR sets the output folder; further arguments go to trimbot. Exit code 1: a criterion failed.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
if [ -n "${PLAN:-}" ]; then
  exec build/bin/trimbot drive "$PLAN" --out "${OUT_DIR:-out/drive}" "$@"
fi
SCENARIO="${SCENARIO:-scenarios/navigation/rectangle_visual.yaml}"
exec build/bin/trimbot run "$SCENARIO" --out "${OUT_DIR:-out/$(basename "$SCENARIO" .yaml)}" --jobs 2 "$@"
