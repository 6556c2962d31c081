#!/usr/bin/env bash
# Fuzzes the input readers under AddressSanitizer + UndefinedBehaviorSanitizer (issue 17): builds
# tests/fuzz with clang into build-fuzz, then runs each libFuzzer target for FUZZ_SECONDS (default
# 30) from the project's own good files. A crash, a sanitizer finding, a hang over 10 s or an
# exception other than InputError fails the run; libFuzzer leaves the input as crash-* / timeout-*.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${FUZZ_SECONDS:-30}"
build="${FUZZ_BUILD_DIR:-build-fuzz}"
if [ ! -f "$build/build.ninja" ]; then
  CXX=clang++ cmake -S tests/fuzz -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null
fi
cmake --build "$build" -j "${BUILD_JOBS:-2}"
echo "fuzz: the readers' unit tests under AddressSanitizer + UndefinedBehaviorSanitizer"
(cd "$build" && ./sanitized_reader_tests --gtest_brief=1)

mkdir -p "$build/corpus/yaml" "$build/corpus/scenario" "$build/corpus/pair" "$build/findings"
cp garden_scenes/gardens/*.yaml robot/config/robot_parameters.yaml robot/calibration/*.yaml "$build/corpus/yaml/"
for file in scenarios/*/*.yaml; do cp "$file" "$build/corpus/scenario/$(echo "$file" | tr / _)"; done
cp tests/fuzz/corpus/pair/* "$build/corpus/pair/"
for run in "fuzz_yaml_inputs yaml" "fuzz_scenario scenario" "fuzz_pair_file pair"; do
  set -- $run
  echo "fuzz: $1 for ${seconds} s"
  (cd "$build/findings" && "../$1" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=16384 \
     -print_final_stats=1 "../corpus/$2" 2>&1 | grep -E "^(#[0-9]+ +DONE|stat::number_of_executed_units|==[0-9]+==ERROR|SUMMARY)" || true)
  # libFuzzer exits non-zero on a finding; pipefail would hide which: check for its artifacts.
  if ls "$build/findings"/crash-* "$build/findings"/timeout-* "$build/findings"/oom-* > /dev/null 2>&1; then
    echo "fuzz: $1 found an input that breaks it (in $build/findings)" >&2
    exit 1
  fi
done
echo "fuzz: no findings"
