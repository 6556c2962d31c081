#include "runners/batch.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include "evaluation/trial_evaluator.h"
#include "loop/prior_knowledge.h"
#include "loop/scenario.h"
#include "reports/arm_plot.h"
#include "reports/batch_report.h"
#include "reports/bush_plot.h"
#include "reports/html_report.h"
#include "reports/localization_timing.h"
#include "reports/run_timing.h"
#include "runners/map_cache.h"
#include "runners/trial.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/random.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

// What a run was asked to do; written as batch.json, read back by merge.
struct BatchInfo {
  std::string scenario_file;  // the copy in the output folder is scenario.yaml
  std::uint64_t seed = 0;
  int trials = 0;
  int shard_index = 0, shard_count = 1;
  std::vector<std::string> overrides;  // --set, as given
  std::string build;                   // BuildFingerprint() of the executable that ran it
};

json ToJson(const BatchInfo& info) {
  return {{"scenario_file", info.scenario_file},
          {"seed", info.seed},
          {"trials", info.trials},
          {"overrides", info.overrides},
          {"shard", std::to_string(info.shard_index) + "/" + std::to_string(info.shard_count)},
          {"build", info.build}};
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "not found");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

BatchInfo ReadBatchInfo(const std::string& dir) {
  const std::string path = dir + "/batch.json";
  std::ifstream in(path);
  if (!in) throw InputError(path, "not found: is " + dir + " the output folder of `trimbot run`?");
  try {
    const json j = json::parse(in);
    BatchInfo info;
    info.scenario_file = j.at("scenario_file").get<std::string>();
    info.seed = j.at("seed").get<std::uint64_t>();
    info.trials = j.at("trials").get<int>();
    if (info.trials < 1 || info.trials > 100000) throw InputError(path, "'trials' must be in [1, 100000]");
    if (j.contains("overrides")) info.overrides = j.at("overrides").get<std::vector<std::string>>();
    if (j.contains("build")) info.build = j.at("build").get<std::string>();
    std::tie(info.shard_index, info.shard_count) = ParseShard(j.at("shard").get<std::string>(), path);
    return info;
  } catch (const json::exception& e) {
    throw InputError(path, std::string("malformed: ") + e.what());
  }
}

}  // namespace

std::string BuildFingerprint() {
  static const std::string fingerprint = [] {
    std::ifstream in("/proc/self/exe", std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    std::ostringstream hex;
    hex << std::hex << std::setw(16) << std::setfill('0') << Fnv1a(bytes.str());
    return hex.str();
  }();
  return fingerprint;
}

std::string TrialDir(const std::string& out, int index) {
  std::ostringstream name;
  name << out << "/trials/" << std::setw(3) << std::setfill('0') << index;
  return name.str();
}

namespace {

TrialResult Unfinished(int index, std::uint64_t seed, const std::string& status, const std::string& message) {
  TrialResult result;
  result.index = index;
  result.seed = seed;
  result.status = status;
  result.message = message;
  return result;
}

// The result a trial process left, or nullopt when it left none (or a broken one).
std::optional<TrialResult> ReadTrialResult(const std::string& dir) {
  std::ifstream in(dir + "/result.json");
  if (!in) return std::nullopt;
  try {
    return json::parse(in).get<TrialResult>();
  } catch (const json::exception&) {
    return std::nullopt;
  }
}

std::string OneLine(const TrialResult& r) {
  int reached = 0;
  for (const auto& g : r.goals) reached += g.reached ? 1 : 0;
  for (const auto& g : r.arm_goals) reached += g.reached ? 1 : 0;
  std::ostringstream line;
  line << std::fixed << std::setprecision(1) << "trial " << std::setw(3) << std::setfill('0') << r.index
       << std::setfill(' ') << " seed " << r.seed << ": " << (r.success ? "success" : "FAILED") << " (" << r.status
       << (r.message.empty() ? "" : ": " + r.message) << "), " << (r.arm_goals.empty() ? "goals " : "cutter poses ")
       << reached << "/" << r.goals.size() + r.arm_goals.size() << ", " << r.simulated_seconds << " s simulated, "
       << r.wall_seconds << " s wall";
  for (const auto& e : r.estimates) {
    if (e.name == "ekf" && !e.position_m.empty()) {
      line << std::setprecision(3) << ", EKF error mean " << e.position().mean << " m";
    }
  }
  if (r.collisions > 0) line << ", " << r.collisions << " collisions";
  return line.str();
}

// Wall-clock figures, kept out of summary.json so that the same scenario and seed give the same
// summary, byte for byte. Returns the trials' stage times summed (none without trial timings).
// What the batch's timing.json holds that the log reports too.
struct BatchTiming {
  std::optional<RunTiming> summed;  // stages summed over the trials that wrote them
  json arm_planning;                // {plans, median, p90, max} in ms; null without arm plans
  json navigation_planning;         // the same for the navigator's global plans
  json trims;                       // every trim's TrimTiming and real-time factor; null without trims
};

// Plans' wall-clock times (s) as milliseconds: count, median, 90th percentile, max.
json PlanTimeStats(std::vector<double> seconds) {
  std::sort(seconds.begin(), seconds.end());
  const auto at = [&](double q) { return 1e3 * seconds[static_cast<size_t>(q * (seconds.size() - 1))]; };
  return {{"plans", seconds.size()}, {"median", at(0.5)}, {"p90", at(0.9)}, {"max", at(1.0)}};
}

BatchTiming WriteTiming(const std::string& out, const std::vector<TrialResult>& results) {
  json trials = json::array();
  double total = 0.0;
  std::vector<visual_localization::LocalizationTimings> frames;  // of every trial's visual localization
  std::vector<RunTiming> runs;
  std::vector<double> arm_plans, navigation_plans;  // s, every plan of every trial
  json trims = json::array();                       // every trial's trims' timings
  for (const auto& r : results) {
    trials.push_back({{"index", r.index}, {"seed", r.seed}, {"wall_seconds", r.wall_seconds}});
    total += r.wall_seconds;
    const std::string trial_timing = TrialDir(out, r.index) + "/timing.json";
    if (!fs::exists(trial_timing)) continue;
    std::ifstream file(trial_timing);
    const json timing = json::parse(file, nullptr, false);
    try {
      runs.push_back(RunTimingFromJson(timing));
    } catch (const std::exception& e) {
      // A trial folder from an older version: its stages are left out of the sum, not guessed.
    }
    if (timing.is_object() && timing.contains("arm_planning_seconds")) {
      const auto plans = timing["arm_planning_seconds"].get<std::vector<double>>();
      arm_plans.insert(arm_plans.end(), plans.begin(), plans.end());
    }
    if (timing.is_object() && timing.contains("trims")) {
      for (json trim : timing["trims"]) {
        const double wall = trim.value("wall_seconds", 0.0);
        trim["trial"] = r.index;
        trim["real_time_factor"] = wall > 0.0 ? trim.value("simulated_seconds", 0.0) / wall : 0.0;
        trims.push_back(trim);
      }
    }
    if (timing.is_object() && timing.contains("navigation_planning_seconds")) {
      const auto plans = timing["navigation_planning_seconds"].get<std::vector<double>>();
      navigation_plans.insert(navigation_plans.end(), plans.begin(), plans.end());
    }
    if (timing.is_object() && timing.contains("visual_localization")) {
      const auto trial_frames = LocalizationTimesFromJson(timing["visual_localization"]);
      frames.insert(frames.end(), trial_frames.begin(), trial_frames.end());
    }
  }
  json report{{"trials", trials}, {"mean_wall_seconds", results.empty() ? 0.0 : total / results.size()}};
  if (!arm_plans.empty()) report["arm_planning_ms"] = PlanTimeStats(arm_plans);
  if (!navigation_plans.empty()) report["navigation_planning_ms"] = PlanTimeStats(navigation_plans);
  if (!trims.empty()) report["trims"] = trims;
  if (!frames.empty()) {
    report["visual_localization"] = LocalizationTimeStats(frames);
    report["visual_localization"].erase("frames_ms");  // in the trials' files
    WriteLocalizationTimeHistogram(out + "/localization_time.png",
                                   "visual localization time per frame, " + std::to_string(results.size()) + " trials",
                                   frames);
  }
  BatchTiming timing;
  if (report.contains("arm_planning_ms")) timing.arm_planning = report["arm_planning_ms"];
  if (report.contains("navigation_planning_ms")) timing.navigation_planning = report["navigation_planning_ms"];
  if (report.contains("trims")) timing.trims = report["trims"];
  if (!runs.empty()) {
    timing.summed = Sum(runs);
    report["stages_summed_over_trials"] = ToJson(*timing.summed);
    WriteRunTimingChart(out + "/timing.png",
                        "where the time went, summed over " + std::to_string(runs.size()) + " trials", *timing.summed);
  }
  WriteFileAtomically(out + "/timing.json", report.dump(2));
  return timing;
}

// "<what>: median M ms, 90th percentile P ms, max X ms over N plans" (nothing without plans).
void LogPlanTimes(std::ostream& log, const std::string& what, const json& plans) {
  if (plans.is_null()) return;
  log << what << ": median " << plans["median"].get<double>() << " ms, 90th percentile " << plans["p90"].get<double>()
      << " ms, max " << plans["max"].get<double>() << " ms over " << plans["plans"].get<int>() << " plans\n";
}

// One line per trim: its real-time factor (simulated / wall seconds) and what planning took of it.
void LogTrimTimes(std::ostream& log, const json& trims) {
  if (trims.is_null()) return;
  log << "trims (wall clock; real-time factor = simulated / wall seconds):\n";
  for (const json& t : trims) {
    log << "  trial " << t["trial"].get<int>() << " goal " << t["goal"].get<int>() << " bush " << t["bush"].get<int>()
        << ": " << t["simulated_seconds"].get<double>() << " s simulated in " << t["wall_seconds"].get<double>()
        << " s (real-time factor " << t["real_time_factor"].get<double>() << "), of which planning "
        << t["planning_seconds"].get<double>() << " s\n";
  }
}

// report.html of the batch in `out`. The batch's results stand without the page: a page that
// cannot be built is reported, and the exit code stays the criteria's.
void WriteReportPage(const std::string& out) {
  try {
    WriteHtmlReport(out);
  } catch (const std::exception& e) {
    std::cerr << "report.html not written: " << e.what() << "\n";
  }
}

// Summary, JUnit and plots of a set of trial results, written into `out`; returns the exit code.
// `goals`: the goals' positions as planned (a bush goal: its surveyed centre), for the plot.
// `final_out`: the folder the log names (merge builds the reports beside it and swaps them in).
int WriteReports(const std::string& out, const std::string& final_out, const Scenario& scenario,
                 const garden::OccupancyMap& map, const garden::OccupancyMap& true_map,
                 const std::vector<Eigen::Vector2d>& goals, const BatchInfo& info, std::vector<TrialResult> results,
                 int trials_planned, std::ostream& log) {
  std::sort(results.begin(), results.end(), [](const auto& a, const auto& b) { return a.index < b.index; });
  BatchSummary summary;
  summary.scenario = scenario.name;
  summary.scenario_file = info.scenario_file;
  summary.overrides = info.overrides;
  summary.seed = info.seed;
  summary.trials_planned = trials_planned;
  summary.trials = results;
  summary.metrics = ComputeBatchMetrics(results, trials_planned);
  summary.pass = true;
  for (const auto& criterion : scenario.criteria) {
    CriterionResult c;
    c.name = criterion.metric;
    c.comparison = criterion.comparison;
    c.expected = criterion.threshold;
    const bool measured = summary.metrics.contains(criterion.metric);
    c.actual = measured ? summary.metrics.at(criterion.metric).get<double>() : std::nan("");
    c.pass = measured && (criterion.comparison == ">=" ? c.actual >= c.expected : c.actual <= c.expected);
    summary.pass = summary.pass && c.pass;
    summary.criteria.push_back(c);
  }
  WriteFileAtomically(out + "/summary.json", json(summary).dump(2));
  WriteJunitXml(out + "/junit.xml", summary);

  const BatchTiming timing = WriteTiming(out, results);
  if (scenario.arm_reach) {
    WriteArmReachPlot(out + "/arm_reach.png", scenario.name + ": cutter poses reached (ground truth)", results);
  } else {
    std::vector<PlotTrajectory> trajectories;
    std::vector<LocalizationFrame> frames;
    for (const auto& r : results) {
      const std::string dir = TrialDir(out, r.index);
      if (fs::exists(dir + "/localization.csv")) {
        const auto trial_frames = ReadLocalizationCsv(dir + "/localization.csv");
        frames.insert(frames.end(), trial_frames.begin(), trial_frames.end());
      }
      if (!fs::exists(dir + "/ground_truth.tum") || !fs::exists(dir + "/ekf.tum")) continue;
      trajectories.push_back(
          {r.index, r.success, ReadTumPositions(dir + "/ground_truth.tum"), ReadTumPositions(dir + "/ekf.tum")});
    }
    WriteTrajectoryPlot(
        out + "/trajectories.png", map, true_map, trajectories, goals,
        scenario.name + ": ground truth (thick) and EKF (thin), " + std::to_string(results.size()) + " trials");
    if (!frames.empty()) {
      WriteLocalizationMap(out + "/localization_map.png", map, true_map, frames,
                           scenario.name + ": where visual localization broke, every frame at its true position");
    }
    WriteErrorHistograms(out + "/localization_errors.png", results,
                         scenario.name + ": localization error against ground truth");
    WriteBushFramePlot(out + "/bush_frames.png", scenario.name + ": the bush from stereo per frame", results);
    WriteBushErrorPlot(out + "/bush_errors.png", scenario.name + ": bush approach errors against ground truth",
                       results);
  }
  WriteReportPage(out);

  log << "\n" << scenario.name << ": " << results.size() << " of " << trials_planned << " trials\n";
  for (const auto& r : results) log << "  " << OneLine(r) << "\n";
  log << "criteria:\n";
  for (const auto& c : summary.criteria) {
    log << "  " << (c.pass ? "pass " : "FAIL ") << c.name << " " << c.comparison << " " << c.expected << " (actual "
        << c.actual << ")\n";
  }
  if (timing.summed) log << "summed over the trials' processes, " << FormatRunTiming(*timing.summed);
  LogPlanTimes(log, "navigation planning (wall clock, goal candidates included)", timing.navigation_planning);
  LogPlanTimes(log, "arm planning (wall clock, IK included)", timing.arm_planning);
  LogTrimTimes(log, timing.trims);
  log << "outputs in " << final_out << " (report.html, summary.json, junit.xml, timing.json, timing.png, "
      << (scenario.arm_reach
              ? "arm_reach.png; per trial arm_goals.csv, arm_pose_NN.png)\n"
              : "trajectories.png, localization_errors.png; with bush goals bush_frames.png, bush_errors.png)\n");
  return summary.pass ? 0 : 1;
}

struct RunningTrial {
  pid_t pid = 0;
  int index = 0;
  std::uint64_t seed = 0;
  std::string dir;
  Clock::time_point started;
};

// Body of a trial's child process. Never returns.
[[noreturn]] void RunTrialProcess(const TrialSetup& setup) {
  int code = 0;
  try {
    TrialSetup own = setup;
    PreparedTrial surveyed_for_trial;
    if (setup.scenario->survey.per_trial) {
      surveyed_for_trial = WithTrialSurvey(*setup.prepared, *setup.scenario, setup.seed);
      own.prepared = &surveyed_for_trial;
      own.map_yaml = WritePriorMap(surveyed_for_trial.prior_map, setup.dir + "/map");
    }
    RunTrial(own, [&](double t) { std::ofstream(setup.dir + "/progress") << t << "\n"; });
  } catch (const std::exception& e) {
    TrialResult result = Unfinished(setup.index, setup.seed, "error", e.what());
    try {
      WriteFileAtomically(setup.dir + "/result.json", json(result).dump(2));
    } catch (...) {
    }
    code = 3;
  }
  std::fflush(nullptr);
  _exit(code);
}

double ReadProgress(const std::string& dir) {
  double t = 0.0;
  std::ifstream(dir + "/progress") >> t;
  return t;
}

}  // namespace

std::pair<int, int> ParseShard(const std::string& text, const std::string& what) {
  int i = -1, n = 0;
  char slash = 0;
  std::istringstream in(text);
  if (!(in >> i >> slash >> n) || slash != '/' || !in.eof() || n < 1 || i < 0 || i >= n) {
    throw InputError(what, "shard '" + text + "' is not i/n with 0 <= i < n");
  }
  return {i, n};
}

namespace {

// Trials of this shard, in index order.
std::vector<int> ShardTrials(const BatchInfo& info) {
  std::vector<int> trials;
  for (int i = 0; i < info.trials; ++i) {
    if (i % info.shard_count == info.shard_index) trials.push_back(i);
  }
  return trials;
}

RunningTrial StartTrial(const BatchOptions& options, const Scenario& scenario, const PreparedTrial& prepared,
                        const BatchInfo& info, int index) {
  RunningTrial trial;
  trial.index = index;
  trial.seed = info.seed + static_cast<std::uint64_t>(index);
  trial.dir = TrialDir(options.out_dir, index);
  fs::remove_all(trial.dir);
  fs::create_directories(trial.dir);
  const TrialSetup setup{&scenario,  &prepared,     options.paths, options.out_dir + "/map/map.yaml", trial.dir, index,
                         trial.seed, options.video, options.bag};
  std::cout.flush();
  trial.started = Clock::now();
  trial.pid = fork();
  if (trial.pid < 0) throw std::runtime_error("fork failed");
  if (trial.pid == 0) RunTrialProcess(setup);
  return trial;
}

// The result of a trial process that has ended (or was killed for its wall-clock limit), else
// nullopt while it runs.
// `goals`: where the goals truly are (a crashed trial's result lists them unreached).
std::optional<TrialResult> PollTrial(const RunningTrial& trial, const Scenario& scenario,
                                     const std::vector<GoalTruth>& goals) {
  int status = 0;
  const pid_t done = waitpid(trial.pid, &status, WNOHANG);
  const double wall = std::chrono::duration<double>(Clock::now() - trial.started).count();
  std::optional<TrialResult> result;
  if (done < 0 && errno != EINTR) {
    // The child is gone without us reaping it: take whatever it left, never kill a reused pid.
    result = ReadTrialResult(trial.dir);
    if (!result) result = Unfinished(trial.index, trial.seed, "crashed", std::string("lost: ") + std::strerror(errno));
  } else if (done == trial.pid) {
    result = ReadTrialResult(trial.dir);
    if (WIFSIGNALED(status)) {
      result =
          Unfinished(trial.index, trial.seed, "crashed",
                     "killed by signal " + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")");
    } else if (!result) {
      result = Unfinished(trial.index, trial.seed, "crashed",
                          "exited with code " + std::to_string(WEXITSTATUS(status)) + " without a result");
    }
  } else if (wall > scenario.wall_time_limit) {
    kill(trial.pid, SIGKILL);
    waitpid(trial.pid, &status, 0);
    result = Unfinished(trial.index, trial.seed, "timeout",
                        "killed after the wall-clock limit of " + std::to_string(scenario.wall_time_limit) + " s");
  }
  if (!result) return std::nullopt;
  result->wall_seconds = wall;
  if (result->goals.empty()) result->goals = UnreachedGoals(goals);
  if (result->status == "crashed" || result->status == "timeout") {
    WriteFileAtomically(trial.dir + "/result.json", json(*result).dump(2));
  }
  return result;
}

void PrintProgress(const std::vector<RunningTrial>& running, std::size_t done, int planned, const Scenario& scenario,
                   Clock::time_point batch_start) {
  std::ostringstream line;
  line << "\r\033[K[run] " << done << "/" << planned << " done |";
  for (const auto& trial : running) {
    line << " trial " << trial.index << ": " << std::fixed << std::setprecision(0) << ReadProgress(trial.dir) << "/"
         << scenario.time_limit << " s";
  }
  line << " | " << std::setprecision(0) << std::chrono::duration<double>(Clock::now() - batch_start).count()
       << " s elapsed";
  std::cout << line.str() << std::flush;
}

}  // namespace

BatchInputs LoadBatchInputs(const BatchOptions& options) {
  Scenario scenario = Scenario::Load(options.scenario_path, ParseOverrides(options.overrides));
  PreparedTrial prepared = PrepareTrial(scenario, options.paths);
  return {std::move(scenario), std::move(prepared)};
}

int RunBatch(const BatchOptions& options) {
  // Every input is read and checked before the output folder is touched.
  BatchInputs inputs = LoadBatchInputs(options);
  Scenario& scenario = inputs.scenario;
  const PreparedTrial& prepared = inputs.prepared;
  const std::string& out = options.out_dir;
  BatchInfo info;
  info.scenario_file = fs::absolute(options.scenario_path).string();
  info.seed = options.seed.value_or(scenario.setting.seed);
  info.trials = options.trials.value_or(scenario.trials);
  info.shard_index = options.shard_index;
  info.shard_count = options.shard_count;
  info.overrides = scenario.overrides;
  info.build = BuildFingerprint();
  if (info.trials < 1) throw InputError(options.scenario_path, "--trials must be at least 1");
  if (options.jobs < 1) throw InputError(options.scenario_path, "--jobs must be at least 1");
  // A map the scenario builds from a mapping drive: from the cache, built there on first use.
  if (const auto map = ResolveVisualMap(scenario, options.paths); map && !options.quiet) {
    std::cout << "[map] " << (map->built ? "built" : "cached") << ": " << map->path
              << (map->built ? " in " + std::to_string(static_cast<int>(map->build_seconds)) + " s" : "") << std::endl;
  }

  fs::create_directories(out);
  WriteFileAtomically(out + "/batch.json", ToJson(info).dump(2));
  WriteFileAtomically(out + "/scenario.yaml", scenario.effective_yaml);
  WritePriorMap(prepared.prior_map, out + "/map");

  std::vector<int> queue = ShardTrials(info);
  const int planned = static_cast<int>(queue.size());
  std::reverse(queue.begin(), queue.end());  // pop from the back in index order

  // Children are reaped here: an inherited SIGCHLD=SIG_IGN would make the kernel reap them first.
  signal(SIGCHLD, SIG_DFL);
  std::ostream null_log(nullptr);  // writes nothing
  std::ostream& log = options.quiet ? null_log : std::cout;
  const bool interactive = !options.quiet && isatty(STDOUT_FILENO) != 0;
  log << "[run] " << scenario.name << ": " << planned << " trials (shard " << info.shard_index << "/"
      << info.shard_count << ", seeds " << info.seed << "+i), " << options.jobs << " at a time -> " << out << std::endl;
  const auto batch_start = Clock::now();
  std::vector<RunningTrial> running;
  // If the batch stops on an exception, no trial process is left running into the output folder.
  struct KillOnExit {
    std::vector<RunningTrial>& trials;
    ~KillOnExit() {
      for (const auto& trial : trials) {
        kill(trial.pid, SIGKILL);
        waitpid(trial.pid, nullptr, 0);
      }
    }
  } kill_on_exit{running};
  std::vector<TrialResult> results;
  while (!queue.empty() || !running.empty()) {
    while (static_cast<int>(running.size()) < options.jobs && !queue.empty()) {
      running.push_back(StartTrial(options, scenario, prepared, info, queue.back()));
      queue.pop_back();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    for (auto it = running.begin(); it != running.end();) {
      std::optional<TrialResult> result = PollTrial(*it, scenario, prepared.goal_truths);
      if (!result) {
        ++it;
        continue;
      }
      if (!options.keep_worlds) fs::remove_all(it->dir + "/world");
      fs::remove(it->dir + "/progress");
      results.push_back(*result);
      if (interactive) log << "\r\033[K";
      log << "[run] " << OneLine(results.back()) << std::endl;
      it = running.erase(it);
    }
    if (interactive && !running.empty()) PrintProgress(running, results.size(), planned, scenario, batch_start);
  }
  return WriteReports(out, out, scenario, prepared.prior_map, prepared.true_map, GoalPositions(prepared.mission), info,
                      results, planned, log);
}

// `staged` becomes `target`: the folder it replaces is removed only once the new one is in place.
void ReplaceFolder(const std::string& staged, const std::string& target) {
  const std::string replaced = target + ".replaced";
  fs::remove_all(replaced);
  if (fs::exists(target)) fs::rename(target, replaced);
  fs::rename(staged, target);
  fs::remove_all(replaced);
}

int MergeShards(const std::vector<std::string>& shard_dirs, const std::string& out_dir, const ProjectPaths& paths,
                bool quiet) {
  if (shard_dirs.empty()) throw InputError(out_dir, "merge needs at least one shard folder");
  // Every shard is read and checked before anything is written: a missing, broken or foreign shard
  // leaves out_dir as it was. The merge is built beside out_dir and swapped in at the end.
  struct Shard {
    std::string dir;
    BatchInfo info;
  };
  std::vector<Shard> shards;
  std::string scenario_text;
  for (const auto& dir : shard_dirs) {
    if (fs::exists(out_dir) && fs::exists(dir) && fs::equivalent(dir, out_dir)) {
      throw InputError(out_dir, "the merged output cannot be one of the shards");
    }
    const BatchInfo info = ReadBatchInfo(dir);
    const std::string text = ReadText(dir + "/scenario.yaml");
    if (shards.empty()) {
      scenario_text = text;
    } else if (info.seed != shards.front().info.seed || info.trials != shards.front().info.trials ||
               info.shard_count != shards.front().info.shard_count || text != scenario_text) {
      throw InputError(
          dir + "/batch.json",
          "belongs to another batch (scenario, seed, trials or shard count differ from " + shard_dirs.front() + ")");
    }
    shards.push_back({dir, info});
  }

  const std::string staging = out_dir + ".merging";
  fs::remove_all(staging);
  fs::create_directories(staging + "/trials");
  WriteFileAtomically(staging + "/scenario.yaml", scenario_text);
  fs::create_directories(staging + "/map");
  fs::copy(shards.front().dir + "/map", staging + "/map",
           fs::copy_options::overwrite_existing | fs::copy_options::recursive);
  std::map<int, TrialResult> results;
  for (const Shard& shard : shards) {
    for (int i = shard.info.shard_index; i < shard.info.trials; i += shard.info.shard_count) {
      const std::string trial_dir = TrialDir(shard.dir, i);
      std::optional<TrialResult> result = ReadTrialResult(trial_dir);
      if (!result) continue;
      fs::copy(trial_dir, TrialDir(staging, i), fs::copy_options::overwrite_existing | fs::copy_options::recursive);
      results[i] = *result;
    }
  }
  BatchInfo merged = shards.front().info;
  merged.shard_index = 0;
  merged.shard_count = 1;
  WriteFileAtomically(staging + "/batch.json", ToJson(merged).dump(2));
  // Trials missing from the shards count as failed through trials_planned, as in a single run.
  std::vector<TrialResult> found;
  for (const auto& [index, result] : results) found.push_back(result);
  if (static_cast<int>(found.size()) < merged.trials) {
    std::cerr << "merge: " << merged.trials - static_cast<int>(found.size()) << " of " << merged.trials
              << " trials have no result in the shards; they count as failed\n";
  }
  const Scenario scenario = Scenario::Load(staging + "/scenario.yaml");
  const PreparedTrial prepared = PrepareTrial(scenario, paths);
  std::ostream null_log(nullptr);  // writes nothing
  const int exit_code =
      WriteReports(staging, out_dir, scenario, prepared.prior_map, prepared.true_map, GoalPositions(prepared.mission),
                   merged, found, merged.trials, quiet ? null_log : std::cout);
  ReplaceFolder(staging, out_dir);
  return exit_code;
}

}  // namespace trimbot::scenarios
