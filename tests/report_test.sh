#!/usr/bin/env bash
# report.html in a real browser (issue 32): Debian's Chromium, headless, opens the report of
#   1. a batch of the navigation smoke whose second trial is killed while it runs (it must appear
#      with its seed and reason) and one of its criteria tightened to fail (shown as failed);
#   2. a two-point sweep, and 3. the comparison of its two points; 4. a run with --video (trial.mp4,
#      H.264 in MP4, embedded in the page);
# each page loads with no console message (the page logs one per image that did not load) and no
# broken image (data-broken-images="0" on <body> once loaded), and a screenshot of each is saved
# in OUT for people to look at. Then: the same seed run again gives the same page apart from the
# wall-clock timing section; `trimbot report` on a folder that is not a run, or on a truncated
# summary.json, exits 2 naming the file and leaves report.html as it was.
# Exit 77 (ctest: skipped) where chromium is not installed (scripts/setup.sh installs it).
# Usage: report_test.sh TRIMBOT SOURCE_DIR OUT_DIR
set -uo pipefail
trimbot=$1
source_dir=$2
out=$3
scenario="$source_dir/scenarios/navigation/smoke.yaml"

fail() {
  echo "FAIL: $*" >&2
  exit 1
}

command -v chromium > /dev/null || { echo "chromium is not installed: skipped" >&2; exit 77; }
rm -rf "$out"
mkdir -p "$out"
export TRIMBOT_MAP_CACHE="$out/map_cache"

# Loads DIR/report.html headless: no console message, every image loaded; a screenshot to OUT/NAME.png.
open_in_browser() {  # DIR NAME
  local page="$1/report.html" name=$2
  [ -s "$page" ] || fail "$page was not written"
  # A profile of its own: chromium refuses a second instance on one profile.
  local profile="$out/chromium_profile_$name"
  timeout 120 chromium --headless --no-sandbox --disable-gpu --user-data-dir="$profile" --enable-logging=stderr \
    --v=0 --virtual-time-budget=10000 --dump-dom "file://$(realpath "$page")" > "$out/$name.dom.html" \
    2> "$out/$name.browser.log" || fail "chromium could not open $page (see $out/$name.browser.log)"
  grep -q 'data-broken-images="0"' "$out/$name.dom.html" ||
    fail "$page: images did not load ($(grep -o 'data-broken-images="[^"]*"' "$out/$name.dom.html"))"
  if grep -q "CONSOLE" "$out/$name.browser.log"; then
    grep "CONSOLE" "$out/$name.browser.log" >&2
    fail "$page: console messages"
  fi
  timeout 120 chromium --headless --no-sandbox --disable-gpu --user-data-dir="$profile" --hide-scrollbars \
    --window-size=1400,2000 --screenshot="$out/$name.png" "file://$(realpath "$page")" 2> /dev/null ||
    fail "no screenshot of $page"
  [ -s "$out/$name.png" ] || fail "no screenshot of $page"
  echo "$page: loads in chromium, no console message, no broken image; screenshot $out/$name.png"
}

# 1. A batch of three, the second trial's process killed as soon as it starts; a criterion that fails.
batch="$out/batch"
"$trimbot" run "$scenario" --out "$batch" --trials 3 --jobs 1 \
  --set criteria.ekf_position_error_max_m.max=0.001 > "$out/batch.log" 2>&1 &
runner=$!
killed=""
for _ in $(seq 1 600); do
  if [ -d "$batch/trials/001" ]; then
    child=$(pgrep -P "$runner" | head -n 1)
    if [ -n "$child" ]; then
      kill -KILL "$child" && killed=yes
      break
    fi
  fi
  sleep 0.05
done
wait "$runner"
code=$?
[ -n "$killed" ] || fail "the second trial's process was never seen running"
[ "$code" -eq 1 ] || fail "the batch with a failed criterion exited $code, not 1 (see $out/batch.log)"
open_in_browser "$batch" batch
page="$batch/report.html"
grep -q '<span class="fail">FAIL</span>' "$page" || fail "$page: the batch is not shown as failed"
grep -q '<tr class="fail"><td>ekf_position_error_max_m</td>' "$page" ||
  fail "$page: the failed criterion is not shown as failed"
seed=$(python3 -c "import json; print(json.load(open('$batch/summary.json'))['trials'][1]['seed'])")
grep -q "id=\"trial-001\"" "$page" || fail "$page: no section for the killed trial"
section=$(sed -n '/id="trial-001"/,/<\/section>/p' "$page")
echo "$section" | grep -q "seed $seed" || fail "$page: the killed trial's seed $seed is not shown"
echo "$section" | grep -q "killed by signal 9" || fail "$page: the killed trial's reason is not shown"
echo "the killed trial: seed $seed and 'killed by signal 9' in its section"

# 2. A sweep of two points; 3. the comparison of its points.
sweep="$out/sweep"
"$trimbot" sweep "$scenario" --grid stack.navigation.follower.cruise_speed=0.2,0.3 --out "$sweep" --trials 2 \
  --jobs 1 > "$out/sweep.log" 2>&1 || fail "the sweep failed (see $out/sweep.log)"
open_in_browser "$sweep" sweep
grep -q 'href="points/001/report.html"' "$sweep/report.html" || fail "the sweep's page does not link its points"
compare="$out/compare"
"$trimbot" compare "$sweep/points/000" "$sweep/points/001" --out "$compare" > "$out/compare.log" 2>&1
[ $? -le 1 ] || fail "compare failed (see $out/compare.log)"
open_in_browser "$compare" compare
grep -q "cruise\|success_rate" "$compare/report.html" || fail "the comparison's page has no metrics"

# 4. The same seed again: the same page but for the wall-clock timing.
"$trimbot" run "$scenario" --out "$out/again_a" --trials 1 > /dev/null 2>&1
"$trimbot" run "$scenario" --out "$out/again_b" --trials 1 > /dev/null 2>&1
strip_timing() { sed '/<h2 id="timing">/,/<h2 id="trial-sections">/d' "$1"; }
diff <(strip_timing "$out/again_a/report.html") <(strip_timing "$out/again_b/report.html") > "$out/again.diff" ||
  fail "two runs of one seed give different reports (see $out/again.diff)"
grep -q '<h2 id="timing">' "$out/again_a/report.html" || fail "the report has no timing section"
echo "two runs of one seed: the same report apart from the timing section"

# 5. --video: trials/000/trial.mp4 (H.264 in MP4, as browsers play it), embedded in the page.
video="$out/video"
"$trimbot" run "$scenario" --out "$video" --trials 1 --video > "$out/video.log" 2>&1 || fail "the --video run failed"
movie="$video/trials/000/trial.mp4"
[ -s "$movie" ] || fail "--video wrote no $movie"
[ "$(head -c 8 "$movie" | tail -c 4)" = "ftyp" ] || fail "$movie is not an MP4 file"
grep -q "avc1" "$movie" || fail "$movie does not hold H.264 (avc1)"
grep -q '<video controls preload="metadata" src="trials/000/trial.mp4"' "$video/report.html" ||
  fail "the report does not embed trial.mp4"
open_in_browser "$video" video
cmp "$video/summary.json" "$out/again_a/summary.json" || fail "--video changed the trial's result"

# 6. Bad input: exit 2 naming the file, report.html untouched.
expect_refused() {  # DIR PATTERN
  local text code
  text=$("$trimbot" report "$1" 2>&1)
  code=$?
  [ "$code" -eq 2 ] || fail "trimbot report $1 exited $code, not 2: $text"
  echo "$text" | grep -q "$2" || fail "trimbot report $1 does not name '$2': $text"
  echo "refused: $text"
}
expect_refused "$out/sweep/plots" "is not a result folder"
truncated="$out/truncated"
cp -r "$out/again_a" "$truncated"
before=$(sha256sum "$truncated/report.html")
head -c 200 "$out/again_a/summary.json" > "$truncated/summary.json"
expect_refused "$truncated" "$truncated/summary.json"
[ "$(sha256sum "$truncated/report.html")" = "$before" ] || fail "a refused report overwrote report.html"
echo "PASS"
