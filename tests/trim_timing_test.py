#!/usr/bin/python3
"""The trims' wall-clock timing a batch reports (issue 31: trimming one bush must take no longer
in wall time than in simulated time, measured by the CLI's own timing report, never by a timed
test): every trim of the trial in the trial's and the batch's timing.json, its simulated span the
trim_seconds of result.json, its wall time covering its planning, the real-time factor their ratio;
and none of it in summary.json or result.json (wall clock is not reproducible).

Usage: trim_timing_test.py BATCH_DIR (a batch of one trial with trim goals)."""
import json
import sys

from script_checks import check, finish

batch = sys.argv[1]

result = json.load(open(batch + "/trials/000/result.json"))
trial_timing = json.load(open(batch + "/trials/000/timing.json"))
batch_timing = json.load(open(batch + "/timing.json"))
cut = [t for t in result["trims"] if t["cut"]]
check(len(cut) > 0, "the trial cut at least one bush")
# Every trim the stack finished (cut or failed) has a timing, found by its goal.
timings = {t["goal"]: t for t in trial_timing.get("trims", [])}
summed = {t["goal"]: t for t in batch_timing.get("trims", [])}
check(set(timings) <= {t["goal"] for t in result["trims"]}, "trials/000/timing.json: timings of the trial's trims only")
check(summed.keys() == timings.keys(), "timing.json: the trial's trims")
for outcome in cut:
    what = "goal %d: " % outcome["goal"]
    timing = timings.get(outcome["goal"])
    check(timing is not None, what + "has a timing")
    if timing is None or outcome["goal"] not in summed:
        continue
    check(timing["bush"] == outcome["bush"], what + "its bush")
    check(timing["simulated_seconds"] == outcome["trim_seconds"], what + "simulated span = result's trim_seconds")
    check(0.0 < timing["planning_seconds"] < timing["wall_seconds"], what + "0 < planning < wall seconds")
    factor = summed[outcome["goal"]]["real_time_factor"]
    check(abs(factor - timing["simulated_seconds"] / timing["wall_seconds"]) < 1e-12,
          what + "real-time factor = simulated / wall (%.3f)" % factor)
text = open(batch + "/summary.json").read() + open(batch + "/trials/000/result.json").read()
check("wall_seconds" not in text, "no wall clock in summary.json or result.json")
finish()
