#!/usr/bin/env bash
# The main job: set up (packages + build), then drive the robot headless in a garden.
# PLAN picks the drive plan (default: the Wageningen test garden tour); OUT_DIR the output folder.
# Outputs (ring images, depth, labels, IMU/odometry logs, ground truth, summary) go to out/drive/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
build/bin/trimbot drive "${PLAN:-scenarios/drives/wageningen_tour.yaml}" --out "${OUT_DIR:-out/drive}" "$@"
