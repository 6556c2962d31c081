#!/usr/bin/env bash
# Installs the Debian packages the project needs (only those missing), then configures and builds.
# Idempotent: a second run installs nothing and rebuilds only what changed.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ninja-build ccache pkg-config
  libeigen3-dev libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  liburdfdom-dev liburdfdom-headers-dev libconsole-bridge-dev
  libmujoco-dev libqhull-dev libosmesa6-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-calib3d-dev libopencv-features2d-dev
  libopencv-flann-dev libopencv-videoio-dev  # trial.mp4 (FFmpeg backend)
  liborocos-kdl-dev libfcl-dev liboctomap-dev
  libompl-dev libboost-dev libnanoflann-dev libopen3d-dev libnlopt-cxx-dev libopengv-dev libceres-dev libsqlite3-dev
  libgtest-dev libgmock-dev libbenchmark-dev python3
  clang clang-format libclang-rt-dev
  slurmctld slurmd slurm-client munge
  chromium  # the report test opens report.html headless (issue 32)
  librosbag-storage-dev libstd-msgs-dev libgeometry-msgs-dev libnav-msgs-dev libsensor-msgs-dev libtf2-msgs-dev
  python3-rosbag python3-yaml  # run.bag: written with rosbag_storage, read back by the bag test
)

missing=()
for package in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# BUILD_DIR (default build/), BUILD_TYPE (default Release: -O2, no debug information; RelWithDebInfo
# for a debugger), TRIMBOT_SANITIZE=ON (AddressSanitizer + UndefinedBehaviorSanitizer, what
# scripts/run_tests.sh builds in build-asan/) and BUILD_TARGET (default: everything) choose the build.
BUILD_DIR="${BUILD_DIR:-build}"
if [ ! -f "$BUILD_DIR/build.ninja" ]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" -DTRIMBOT_SANITIZE="${TRIMBOT_SANITIZE:-OFF}"
fi
# Two cores: two compile jobs keep memory and time in check.
cmake --build "$BUILD_DIR" -j "${BUILD_JOBS:-2}" ${BUILD_TARGET:+--target "$BUILD_TARGET"}
