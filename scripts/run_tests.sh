#!/usr/bin/env bash
# The whole test suite: set up (packages + build), every test through ctest, then the input
# readers fuzzed and tested under AddressSanitizer + UndefinedBehaviorSanitizer (scripts/fuzz.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
ctest --test-dir build --output-on-failure -j 2 "$@"
scripts/fuzz.sh
