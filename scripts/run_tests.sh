#!/usr/bin/env bash
# The whole test suite, built with AddressSanitizer + UndefinedBehaviorSanitizer in build-asan/
# (issue 17: a memory error or undefined behaviour anywhere fails the test that hits it), then the
# input readers fuzzed (scripts/fuzz.sh). scripts/run_main.sh uses the plain build in build/.
# Leak checking is off: OSMesa and OMPL's LazyPRM keep allocations to the end of the process.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=build-asan TRIMBOT_SANITIZE=ON scripts/setup.sh
ASAN_OPTIONS="detect_leaks=0:${ASAN_OPTIONS:-}" UBSAN_OPTIONS="print_stacktrace=1:${UBSAN_OPTIONS:-}" \
  ctest --test-dir build-asan --output-on-failure -j 2 "$@"
scripts/fuzz.sh
