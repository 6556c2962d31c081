#!/usr/bin/env bash
# The whole test suite: set up (packages + build), then every test through ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
ctest --test-dir build --output-on-failure -j 2 "$@"
