#include "runners/tune.h"

#include <nlohmann/json.hpp>
#include <nlopt.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "loop/prior_knowledge.h"
#include "loop/scenario.h"
#include "reports/html_report.h"
#include "reports/sweep_plot.h"
#include "runners/batch.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/yaml_reader.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::uint64_t kFreshSeedOffset = 1000000;
constexpr double kMissing = 1e6;  // objective of a batch where the metric has no samples

struct Evaluation {
  std::vector<std::string> overrides;  // the point's parameter overrides
  double objective = 0.0;
};

class Search {
 public:
  Search(const TuneOptions& options, const TuneSpace& space, int trials_per_point)
      : options_(options), space_(space), trials_(trials_per_point) {}

  // Unit-cube coordinates -> "key=value" overrides.
  std::vector<std::string> Point(const std::vector<double>& x) const {
    std::vector<std::string> overrides;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const TuneParameter& p = space_.parameters[i];
      double v = p.log ? std::exp(std::log(p.min) + x[i] * (std::log(p.max) - std::log(p.min)))
                       : p.min + x[i] * (p.max - p.min);
      std::ostringstream text;
      if (p.integer) {
        text << std::llround(v);
      } else {
        text << std::setprecision(6) << v;
      }
      overrides.push_back(p.key + "=" + text.str());
    }
    return overrides;
  }

  // The objective at a point, to be minimized (a batch per new point; repeats come from memory).
  double Evaluate(const std::vector<double>& x) {
    const std::vector<std::string> point = Point(x);
    const auto known = memory_.find(point);
    if (known != memory_.end()) return Sign() * known->second;
    const double objective =
        RunPoint(point, options_.out_dir + "/evaluations/" + Index(evaluations_.size()), options_.seed, nullptr);
    memory_[point] = objective;
    evaluations_.push_back({point, objective});
    const double best = Best().objective;
    std::cout << "[tune] " << std::setw(3) << evaluations_.size() << "/" << MaxEvaluations() << " ";
    for (const auto& o : point) std::cout << " " << o;
    std::cout << std::setprecision(5) << "  " << options_.objective << " " << objective << "  (best " << best << ")"
              << std::endl;
    return Sign() * objective;
  }

  // Runs one batch with the point's overrides; returns the objective (and the summary).
  double RunPoint(const std::vector<std::string>& point, const std::string& dir, std::optional<std::uint64_t> seed,
                  json* summary_out) const {
    BatchOptions batch;
    batch.scenario_path = options_.scenario_path;
    batch.out_dir = dir;
    batch.paths = options_.paths;
    batch.trials = trials_;
    batch.seed = seed;
    batch.jobs = options_.jobs;
    batch.overrides = options_.overrides;
    batch.overrides.insert(batch.overrides.end(), point.begin(), point.end());
    batch.quiet = true;
    RunBatches(options_.executor, {batch});
    std::ifstream in(dir + "/summary.json");
    const json summary = json::parse(in);
    if (summary_out != nullptr) *summary_out = summary;
    const json& metrics = summary["metrics"];
    return metrics.contains(options_.objective) && metrics[options_.objective].is_number()
               ? metrics[options_.objective].get<double>()
               : Sign() * kMissing;
  }

  const Evaluation& Best() const {
    const Evaluation* best = &evaluations_.front();
    for (const auto& e : evaluations_) {
      if (Sign() * e.objective < Sign() * best->objective) best = &e;
    }
    return *best;
  }
  int MaxEvaluations() const { return std::max(1, options_.budget_trials / trials_); }
  const std::vector<Evaluation>& evaluations() const { return evaluations_; }
  double Sign() const { return options_.maximize ? -1.0 : 1.0; }

 private:
  static std::string Index(std::size_t i) {
    std::ostringstream name;
    name << std::setw(3) << std::setfill('0') << i;
    return name.str();
  }

  const TuneOptions& options_;
  const TuneSpace& space_;
  int trials_;
  std::map<std::vector<std::string>, double> memory_;
  std::vector<Evaluation> evaluations_;
};

double NloptObjective(const std::vector<double>& x, std::vector<double>& /*gradient*/, void* data) {
  return static_cast<Search*>(data)->Evaluate(x);
}

void WriteConvergencePlot(const std::string& path, const TuneOptions& options, const Search& search) {
  SweepSeries objective{"objective", {}, {}, {}}, best{"best so far", {}, {}, {}};
  std::vector<std::string> labels;
  double best_value = 0.0;
  for (std::size_t i = 0; i < search.evaluations().size(); ++i) {
    const double v = search.evaluations()[i].objective;
    best_value = i == 0 || search.Sign() * v < search.Sign() * best_value ? v : best_value;
    labels.push_back(std::to_string(i + 1));
    for (auto [series, value] : {std::pair{&objective, v}, std::pair{&best, best_value}}) {
      series->value.push_back(value);
      series->low.push_back(value);
      series->high.push_back(value);
    }
  }
  WriteSweepPlot(path, "tune: " + options.objective + " per evaluation", "evaluation", labels, options.objective,
                 {objective, best});
}

}  // namespace

TuneSpace TuneSpace::Load(const std::string& path) {
  const YamlMap root = YamlMap::LoadFile(path);
  TuneSpace space;
  for (const YamlMap& item : root.MapList("parameters")) {
    TuneParameter p;
    p.key = item.String("key");
    p.min = item.Number("min", -1e12, 1e12);
    p.max = item.Number("max", -1e12, 1e12);
    p.log = item.Bool("log", false);
    p.integer = item.Bool("integer", false);
    item.RejectUnknownKeys();
    if (!(p.max > p.min)) item.Fail("max", "must be greater than min");
    if (p.log && p.min <= 0.0) item.Fail("min", "must be positive for a log-scale parameter");
    space.parameters.push_back(p);
  }
  root.RejectUnknownKeys();
  if (space.parameters.empty()) root.Fail("parameters", "needs at least one parameter");
  return space;
}

int RunTune(const TuneOptions& options) {
  const TuneSpace space = TuneSpace::Load(options.space_path);
  if (!IsKnownMetric(options.objective)) throw InputError("--objective", "unknown metric '" + options.objective + "'");
  if (options.method != "bobyqa" && options.method != "direct") {
    throw InputError("--method", "unknown method '" + options.method + "' (bobyqa, direct)");
  }
  const Scenario scenario = Scenario::Load(options.scenario_path, ParseOverrides(options.overrides));
  const int trials = options.trials.value_or(scenario.trials);
  Search search(options, space, trials);
  // Both ends of every parameter must be valid inputs before anything runs.
  for (const double corner : {0.0, 1.0}) {
    const auto point = search.Point(std::vector<double>(space.parameters.size(), corner));
    std::vector<std::string> all = options.overrides;
    all.insert(all.end(), point.begin(), point.end());
    StackParametersFor(Scenario::Load(options.scenario_path, ParseOverrides(all)), options.paths);
  }
  if (options.budget_trials < 2 * trials) throw InputError("--budget", "must allow at least two evaluations");
  fs::create_directories(options.out_dir);
  std::cout << "[tune] " << scenario.name << ": " << space.parameters.size() << " parameters, " << options.method
            << ", up to " << search.MaxEvaluations() << " evaluations of " << trials << " trials, "
            << (options.maximize ? "maximize " : "minimize ") << options.objective << std::endl;

  const std::size_t n = space.parameters.size();
  nlopt::opt optimizer(options.method == "bobyqa" ? nlopt::LN_BOBYQA : nlopt::GN_DIRECT_L, static_cast<unsigned>(n));
  optimizer.set_lower_bounds(std::vector<double>(n, 0.0));
  optimizer.set_upper_bounds(std::vector<double>(n, 1.0));
  optimizer.set_min_objective(NloptObjective, &search);
  optimizer.set_maxeval(search.MaxEvaluations());
  optimizer.set_xtol_abs(1e-3);
  if (options.method == "bobyqa") optimizer.set_initial_step(0.25);
  std::vector<double> x(n, 0.5);
  double minimum = 0.0;
  std::string stop = "budget used";
  try {
    const nlopt::result result = optimizer.optimize(x, minimum);
    if (result == nlopt::XTOL_REACHED) stop = "converged (step below 1e-3 of the range)";
  } catch (const nlopt::roundoff_limited&) {
    stop = "stopped by round-off";
  }

  // The honest figure: the best point and the scenario as it is, both on fresh seeds.
  const Evaluation best = search.Best();
  const std::uint64_t fresh = options.seed.value_or(scenario.setting.seed) + kFreshSeedOffset;
  json best_summary, default_summary;
  const double best_fresh = search.RunPoint(best.overrides, options.out_dir + "/fresh/best", fresh, &best_summary);
  const double default_fresh = search.RunPoint({}, options.out_dir + "/fresh/default", fresh, &default_summary);
  const bool better = search.Sign() * best_fresh < search.Sign() * default_fresh;

  json evaluations = json::array();
  for (const auto& e : search.evaluations())
    evaluations.push_back({{"overrides", e.overrides}, {"objective", e.objective}});
  const json report = {
      {"scenario", scenario.name},
      {"objective", options.objective},
      {"maximize", options.maximize},
      {"method", options.method},
      {"stop", stop},
      {"trials_per_evaluation", trials},
      {"evaluations", evaluations},
      {"best", {{"overrides", best.overrides}, {"tuned_seeds", best.objective}, {"fresh_seeds", best_fresh}}},
      {"default_fresh_seeds", default_fresh},
      {"fresh_seed", fresh},
      {"improved_on_fresh_seeds", better}};
  WriteFileAtomically(options.out_dir + "/tune.json", report.dump(2));
  WriteConvergencePlot(options.out_dir + "/convergence.png", options, search);
  WriteHtmlReport(options.out_dir);
  std::cout << std::setprecision(5) << "[tune] " << stop << " after " << search.evaluations().size()
            << " evaluations. Best:";
  for (const auto& o : best.overrides) std::cout << " " << o;
  std::cout << "\n[tune] " << options.objective << ": " << best.objective << " on the tuning seeds; on fresh seeds "
            << best_fresh << " tuned vs " << default_fresh << " as the scenario is ("
            << (better ? "better" : "NOT better") << "). Compare them: trimbot compare " << options.out_dir
            << "/fresh/default " << options.out_dir << "/fresh/best" << std::endl;
  return better ? 0 : 1;
}

}  // namespace trimbot::scenarios
