#!/usr/bin/env bash
# The test suite; CI runs exactly this (.ci/run). Three parts, each timed (the split is printed at
# the end; budget: <= 25 min on 2 cores from an empty cache, issue 27):
#   1. the plain build (build/, the one scripts/run_main.sh uses) and the ctest suite on it: unit
#      tests, the closed-loop smoke runs, the main job's scenario in short form, the Slurm test - all
#      but the tests of part 2, which would only run twice;
#   2. the unit tests of the robot software and the simulator (ctest label `sanitized`) built with
#      AddressSanitizer + UndefinedBehaviorSanitizer in build-asan/ - only their targets - and run
#      there: a memory error or undefined behaviour fails the test that hits it (issue 17). Not
#      among them: ground_appearance_test (2 min of OpenCV's SIFT over rendered ground types under
#      the sanitizers; the renderer it drives is covered there by the other render tests);
#   3. the input readers' unit tests under the sanitizers and the readers fuzzed (scripts/fuzz.sh).
# Leak checking is off: OSMesa and OMPL's LazyPRM keep allocations to the end of the process.
# Arguments go to both ctest runs (e.g. -R Navigation, or -LE slurm where Slurm cannot start; ctest
# keeps the last -LE only, so with one of yours the plain run also runs the sanitized tests).
set -euo pipefail
cd "$(dirname "$0")/.."
times=()
started=$(date +%s)
lap() {  # NAME: the seconds since the last lap
  local now
  now=$(date +%s)
  times+=("$1 $((now - started)) s")
  started=$now
}
scripts/setup.sh
lap "build"
ctest --test-dir build --output-on-failure -j 2 -LE sanitized "$@"
lap "ctest"
BUILD_DIR=build-asan TRIMBOT_SANITIZE=ON BUILD_TARGET=sanitized_tests scripts/setup.sh
lap "sanitized build"
ASAN_OPTIONS="detect_leaks=0:${ASAN_OPTIONS:-}" UBSAN_OPTIONS="print_stacktrace=1:${UBSAN_OPTIONS:-}" \
  ctest --test-dir build-asan -L sanitized --output-on-failure -j 2 "$@"
lap "sanitized unit tests"
scripts/fuzz.sh
lap "fuzzing (build, sanitized reader tests, fuzzers)"
echo "run_tests: time by part: $(IFS=,; echo "${times[*]}" | sed 's/,/, /g')"
