#!/usr/bin/env bash
# The main job: set up (packages + build), then drive the robot headless in the test garden.
# Outputs (ring images, depth, labels, IMU/odometry logs, ground truth, summary) go to out/drive/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
build/bin/trimbot drive scenarios/drives/lawn_loop.yaml --out "${OUT_DIR:-out/drive}" "$@"
