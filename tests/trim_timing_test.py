#!/usr/bin/python3
"""The trims' wall-clock timing a batch reports (issue 31: trimming one bush must take no longer
in wall time than in simulated time, measured by the CLI's own timing report, never by a timed
test): every trim of the trial in the trial's and the batch's timing.json, its simulated span the
trim_seconds of result.json, its wall time covering its planning, the real-time factor their ratio;
and none of it in summary.json or result.json (wall clock is not reproducible).

Usage: trim_timing_test.py BATCH_DIR (a batch of one trial with trim goals)."""
import json
import sys

batch = sys.argv[1]
failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what)
    if not condition:
        failures.append(what)


result = json.load(open(batch + "/trials/000/result.json"))
trial_timing = json.load(open(batch + "/trials/000/timing.json"))
batch_timing = json.load(open(batch + "/timing.json"))
trims = [t for t in result["trims"] if t["cut"]]
check(len(trims) > 0, "the trial cut at least one bush")
check(len(trial_timing.get("trims", [])) == len(trims),
      "trials/000/timing.json: one timing per trim that ran (%d)" % len(trims))
check(len(batch_timing.get("trims", [])) == len(trial_timing.get("trims", [])), "timing.json: the trial's trims")
for timing, outcome, summed in zip(trial_timing.get("trims", []), trims, batch_timing.get("trims", [])):
    what = "goal %d: " % outcome["goal"]
    check(timing["goal"] == outcome["goal"] and timing["bush"] == outcome["bush"], what + "goal and bush")
    check(timing["simulated_seconds"] == outcome["trim_seconds"], what + "simulated span = result's trim_seconds")
    check(0.0 < timing["planning_seconds"] < timing["wall_seconds"], what + "0 < planning < wall seconds")
    check(abs(summed["real_time_factor"] - timing["simulated_seconds"] / timing["wall_seconds"]) < 1e-12,
          what + "real-time factor = simulated / wall (%.3f)" % summed["real_time_factor"])
text = open(batch + "/summary.json").read() + open(batch + "/trials/000/result.json").read()
check("wall_seconds" not in text, "no wall clock in summary.json or result.json")
sys.exit(1 if failures else 0)
