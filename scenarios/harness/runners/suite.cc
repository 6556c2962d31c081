#include "runners/suite.h"

#include <sys/wait.h>

#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "evaluation/trial_result.h"
#include "loop/prior_knowledge.h"
#include "loop/scenario.h"
#include "reports/batch_report.h"
#include "reports/html_report.h"
#include "runners/batch.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"
#include "trimbot/common/random.h"
#include "trimbot/common/yaml_reader.h"
#include "trimbot/garden/garden_tools.h"
#include "trimbot/robot/robot_description.h"

namespace trimbot::scenarios {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// An integer or real range [lo, hi] a garden's parameter is drawn from.
struct Range {
  double lo = 0.0, hi = 0.0;
};

struct SuiteSpec {
  std::string name, description, file;
  int gardens = 0;
  std::uint64_t seed = 0;
  Eigen::Vector2d size = Eigen::Vector2d(10, 8);
  std::map<std::string, Range> counts;  // topiary, roses, hedges, corridors, trees, obstacles, paths
  Range clearance{0.9, 1.5};            // m kept between objects
  int goals = 4;
  double goal_margin = 0.05;  // m beyond the outline's half-width
  YAML::Node scenario;        // what every garden's scenario file holds besides its garden, start, goals
  std::vector<PassCriterion> criteria;
};

const char* const kCountKeys[] = {"topiary", "roses", "hedges", "corridors", "trees", "obstacles", "paths"};

Range ReadRange(const YamlMap& map, const std::string& key, double lo, double hi) {
  const std::vector<double> values = map.Numbers(key, 2, lo, hi);
  if (values[0] > values[1]) map.Fail(key, "the range's first value is larger than its second");
  return {values[0], values[1]};
}

SuiteSpec LoadSuite(const std::string& path) {
  const YamlMap root = YamlMap::LoadFile(path);
  SuiteSpec spec;
  spec.file = path;
  spec.name = root.Name("name");
  spec.description = root.String("description", "");
  const YamlMap gardens = root.Map("gardens");
  spec.gardens = gardens.Integer("count", 1, 10000);
  spec.seed = static_cast<std::uint64_t>(gardens.Integer("seed", 0, 1 << 30));
  const std::vector<double> size = gardens.Numbers("size", 2, 3.0, garden::kMaxGardenExtent, "m");
  spec.size = {size[0], size[1]};
  for (const char* key : kCountKeys) spec.counts[key] = gardens.Has(key) ? ReadRange(gardens, key, 0, 1000) : Range{};
  if (gardens.Has("clearance")) spec.clearance = ReadRange(gardens, "clearance", 0.0, 10.0);
  gardens.RejectUnknownKeys();
  const YamlMap goals = root.Map("goals");
  spec.goals = goals.Integer("count", 1, 100);
  spec.goal_margin = goals.NumberOr("margin", spec.goal_margin, 0.0, 5.0, "m");
  goals.RejectUnknownKeys();
  spec.scenario = YAML::Clone(root.Map("scenario").node());
  for (const char* key : {"name", "garden", "start", "goals"}) {
    if (spec.scenario[key]) root.Map("scenario").Fail(key, "is set by the suite for each garden");
  }
  if (root.Has("criteria")) spec.criteria = ReadPassCriteria(root.Map("criteria"));
  root.RejectUnknownKeys();
  return spec;
}

std::string GardenDir(const std::string& out, int index) {
  std::ostringstream name;
  name << out << "/gardens/" << std::setw(3) << std::setfill('0') << index;
  return name.str();
}

// Garden `index`'s generator parameters, drawn from the suite's ranges by its own seed.
garden::GeneratorParameters DrawGarden(const SuiteSpec& spec, std::uint64_t seed) {
  Rng rng = MakeRng(seed, "suite_garden");
  const auto count = [&](const std::string& key) {
    const Range& r = spec.counts.at(key);
    const int lo = static_cast<int>(std::lround(r.lo)), hi = static_cast<int>(std::lround(r.hi));
    return lo + static_cast<int>(std::floor(UniformUnit(rng) * (hi - lo + 1 - 1e-12)));
  };
  garden::GeneratorParameters p;
  p.seed = seed;
  p.size = spec.size;
  p.topiary = count("topiary");
  p.roses = count("roses");
  p.hedges = count("hedges");
  p.corridors = count("corridors");
  p.trees = count("trees");
  p.obstacles = count("obstacles");
  p.paths = count("paths");
  p.robot_clearance = spec.clearance.lo + (spec.clearance.hi - spec.clearance.lo) * UniformUnit(rng);
  return p;
}

void WriteScenario(const SuiteSpec& spec, int index, const std::string& garden_file, const SuiteLayout& layout,
                   const std::string& path) {
  YAML::Node node = YAML::Clone(spec.scenario);
  node["name"] = spec.name + "_" + std::to_string(index);
  node["description"] = "garden " + std::to_string(index) + " of suite " + spec.name + " (" + spec.file + ")";
  node["garden"] = garden_file;
  YAML::Node start;
  start["x"] = layout.start.x;
  start["y"] = layout.start.y;
  start["yaw_deg"] = layout.start.yaw * 180.0 / M_PI;
  node["start"] = start;
  for (const Eigen::Vector2d& goal : layout.goals) {
    YAML::Node g;
    g["x"] = goal.x();
    g["y"] = goal.y();
    node["goals"].push_back(g);
  }
  YAML::Emitter out;
  out.SetDoublePrecision(6);
  out << node;
  WriteFileAtomically(path, std::string("# generated by trimbot suite ") + spec.file + "\n" + out.c_str() + "\n");
}

// Runs one garden's batch, here or with the suite's runner command; returns its exit code.
int RunGarden(const SuiteOptions& options, const std::string& scenario, const std::string& dir) {
  if (options.runner.empty()) {
    BatchOptions batch;
    batch.scenario_path = scenario;
    batch.out_dir = dir;
    batch.paths = options.paths;
    batch.jobs = options.jobs;
    batch.quiet = true;
    return RunBatch(batch);
  }
  const std::string command = options.runner + " run '" + scenario + "' --out '" + dir + "' --jobs " +
                              std::to_string(options.jobs) + " > '" + dir + "/run.log' 2>&1";
  fs::create_directories(dir);
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 3;
}

json ReadJson(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path, "missing (the garden's batch wrote no summary)");
  json j = json::parse(file, nullptr, false);
  if (j.is_discarded()) throw InputError(path, "not JSON");
  return j;
}

// The reasons goals were given up in a trial (events.csv's goal_failed details).
std::vector<std::string> GoalFailures(const std::string& trial_dir) {
  std::vector<std::string> reasons;
  std::ifstream events(trial_dir + "/events.csv");
  std::string line;
  while (std::getline(events, line)) {
    std::istringstream fields(line);
    std::string t, event, goal, detail;
    std::getline(fields, t, ',');
    std::getline(fields, event, ',');
    std::getline(fields, goal, ',');
    std::getline(fields, detail);
    if (event == "goal_failed") reasons.push_back(detail.substr(0, detail.find(" (")));
  }
  return reasons;
}

// How a trial failed, in a few words that count well across gardens.
std::string TrialFailure(const TrialResult& trial) {
  if (trial.success) return "";
  if (trial.collisions > 0) return "collided with the garden";
  if (trial.status == "timeout") return "time limit";
  if (trial.status != "completed" && trial.status != "failed") return trial.status;
  if (trial.message.rfind("navigation gave up", 0) == 0) return "navigation gave up a goal";
  return trial.message.empty() ? "goal not reached" : trial.message;
}

}  // namespace

SuiteLayout PlaceSuiteLayout(const garden::Garden& garden, double clearance_height, double min_distance,
                             double start_distance, int goals, std::uint64_t seed, const std::string& what) {
  const garden::OccupancyMap map = garden::MakeOccupancyMap(garden, 0.05, clearance_height);
  // Distance of each free cell's centre to the nearest occupied cell's square (the map's edge counts
  // as one): to its centre, less half a cell. The map's cells are those whose centre lies in a
  // footprint, so a square's edge is where the footprint's is, on average.
  cv::Mat free = 255 - map.occupied;
  cv::Mat padded;
  cv::copyMakeBorder(free, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::Mat distance;
  cv::distanceTransform(padded, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::Mat far_enough(map.occupied.size(), CV_8U, cv::Scalar(0));
  for (int r = 0; r < map.occupied.rows; ++r) {
    for (int c = 0; c < map.occupied.cols; ++c) {
      if ((distance.at<float>(r + 1, c + 1) - 0.5) * map.resolution >= min_distance) {
        far_enough.at<std::uint8_t>(r, c) = 255;
      }
    }
  }
  // The largest connected region of such cells: the garden inside its fence, not the strip outside
  // it or a pocket the base cannot reach even sideways.
  cv::Mat labels;
  const int regions = cv::connectedComponents(far_enough, labels, 8, CV_32S);
  std::vector<int> area(static_cast<std::size_t>(regions), 0);
  for (int r = 0; r < labels.rows; ++r) {
    for (int c = 0; c < labels.cols; ++c) {
      if (far_enough.at<std::uint8_t>(r, c) != 0) ++area[static_cast<std::size_t>(labels.at<int>(r, c))];
    }
  }
  const int largest = static_cast<int>(std::max_element(area.begin(), area.end()) - area.begin());
  std::vector<cv::Point> cells, start_cells;
  for (int r = 0; r < labels.rows; ++r) {
    for (int c = 0; c < labels.cols; ++c) {
      if (far_enough.at<std::uint8_t>(r, c) == 0 || labels.at<int>(r, c) != largest) continue;
      cells.emplace_back(c, r);
      if ((distance.at<float>(r + 1, c + 1) - 0.5) * map.resolution >= start_distance) start_cells.emplace_back(c, r);
    }
  }
  if (cells.empty() || start_cells.empty()) {
    throw InputError(what, "no free space: no cell is " +
                               std::to_string(cells.empty() ? min_distance : start_distance) +
                               " m from every obstacle");
  }
  Rng rng = MakeRng(seed, "suite_layout");
  const auto draw = [&](const std::vector<cv::Point>& from) {
    const cv::Point cell = from[static_cast<std::size_t>(UniformUnit(rng) * from.size())];
    return map.CellCentre(cell);
  };
  SuiteLayout layout;
  const Eigen::Vector2d start = draw(start_cells);
  layout.start = {start.x(), start.y(), (2.0 * UniformUnit(rng) - 1.0) * M_PI};
  for (int i = 0; i < goals; ++i) layout.goals.push_back(draw(cells));
  return layout;
}

namespace {

// What the gardens' batches came to: all their trials as one batch, a row per garden, failure
// reasons counted, every plan's wall time.
struct SuiteTally {
  std::vector<TrialResult> trials;
  int planned = 0;
  json rows = json::array();
  std::map<std::string, int> trial_failures, goal_failures;
  std::vector<double> plan_seconds;

  // Adds garden `g`'s batch (in `dir`/batch); returns its row.
  const json& AddGarden(int g, std::uint64_t seed, const std::string& dir, const garden::Garden& garden,
                        const garden::GeneratorParameters& parameters, int goals_per_trial) {
    const json summary = ReadJson(dir + "/batch/summary.json");
    planned += summary.value("trials_planned", 0);
    int reached = 0, contacts = 0;
    json reasons = json::array(), seeds = json::array();
    for (const json& j : summary["trials"]) {
      TrialResult trial = j.get<TrialResult>();
      const std::string trial_dir = TrialDir(dir + "/batch", trial.index);
      for (const GoalResult& goal : trial.goals) reached += goal.reached ? 1 : 0;
      contacts += trial.collisions;
      seeds.push_back(trial.seed);
      if (!trial.success) ++trial_failures[TrialFailure(trial)];
      for (const std::string& reason : GoalFailures(trial_dir)) {
        ++goal_failures[reason];
        reasons.push_back(reason);
      }
      std::ifstream timing_file(trial_dir + "/timing.json");
      const json timing = json::parse(timing_file, nullptr, false);
      if (timing.is_object() && timing.contains("navigation_planning_seconds")) {
        for (double s : timing["navigation_planning_seconds"]) plan_seconds.push_back(s);
      }
      trial.index = static_cast<int>(trials.size());
      trials.push_back(trial);
    }
    rows.push_back({{"garden", g},
                    {"seed", seed},
                    {"folder", dir},
                    {"objects", garden.objects.size()},
                    {"corridors", parameters.corridors},
                    {"clearance_m", parameters.robot_clearance},
                    {"goals", goals_per_trial * static_cast<int>(summary["trials"].size())},
                    {"goals_reached", reached},
                    {"collisions", contacts},
                    {"trial_seeds", seeds},
                    {"given_up", reasons}});
    return rows.back();
  }
};

// summary.json and junit.xml (the suite as one batch, against its criteria), suite.json, suite.md
// and the console report; returns the exit code.
int WriteSuiteReports(const SuiteSpec& spec, const SuiteOptions& options, const std::string& out,
                      const SuiteTally& tally, int gardens) {
  BatchSummary summary;
  summary.scenario = spec.name;
  summary.scenario_file = options.suite_path;
  summary.seed = spec.seed;
  summary.trials_planned = tally.planned;
  summary.trials = tally.trials;
  summary.metrics = ComputeBatchMetrics(tally.trials, tally.planned);
  summary.pass = true;
  for (const PassCriterion& criterion : spec.criteria) {
    CriterionResult c{criterion.metric, criterion.comparison, criterion.threshold, std::nan(""), false};
    if (summary.metrics.contains(criterion.metric)) c.actual = summary.metrics.at(criterion.metric).get<double>();
    c.pass = std::isfinite(c.actual) && (c.comparison == ">=" ? c.actual >= c.expected : c.actual <= c.expected);
    summary.pass = summary.pass && c.pass;
    summary.criteria.push_back(c);
  }
  WriteFileAtomically(out + "/summary.json", json(summary).dump(2));
  WriteJunitXml(out + "/junit.xml", summary);

  json report{{"suite", spec.name},
              {"file", options.suite_path},
              {"gardens", tally.rows},
              {"trial_failures", tally.trial_failures},
              {"goals_given_up", tally.goal_failures},
              {"goal_success_rate", summary.metrics.value("goal_success_rate", 0.0)},
              {"collisions", summary.metrics.value("collisions", 0.0)}};
  std::vector<double> plan_seconds = tally.plan_seconds;
  std::sort(plan_seconds.begin(), plan_seconds.end());
  if (!plan_seconds.empty()) {
    const auto at = [&](double q) {
      return 1e3 * plan_seconds[static_cast<std::size_t>(q * (plan_seconds.size() - 1))];
    };
    report["navigation_planning_ms"] = {
        {"plans", plan_seconds.size()}, {"median", at(0.5)}, {"p90", at(0.9)}, {"max", at(1.0)}};
  }
  WriteFileAtomically(out + "/suite.json", report.dump(2));

  std::ostringstream md;
  md << "# Suite " << spec.name << "\n\n"
     << spec.description
     << "\n\n| garden | seed | objects | corridors | clearance (m) | goals reached | contacts | given up "
        "|\n|---|---|---|---|---|---|---|---|\n";
  for (const json& row : tally.rows) {
    std::string given_up;
    for (const json& reason : row["given_up"]) given_up += (given_up.empty() ? "" : "; ") + reason.get<std::string>();
    md << "| " << row["garden"].get<int>() << " | " << row["seed"].get<std::uint64_t>() << " | "
       << row["objects"].get<std::size_t>() << " | " << row["corridors"].get<int>() << " | " << std::fixed
       << std::setprecision(2) << row["clearance_m"].get<double>() << " | " << row["goals_reached"].get<int>() << " / "
       << row["goals"].get<int>() << " | " << row["collisions"].get<int>() << " | " << given_up << " |\n";
  }
  md << "\nGoals reached: " << std::setprecision(1) << 100.0 * summary.metrics.value("goal_success_rate", 0.0)
     << " % (within the tolerance of the goal as asked, not moved by the robot: "
     << 100.0 * summary.metrics.value("goal_success_rate_as_asked", 0.0)
     << " %); contacts: " << summary.metrics.value("collisions", 0.0) << "\n";
  WriteFileAtomically(out + "/suite.md", md.str());
  WriteHtmlReport(out);

  std::cout << "\n"
            << spec.name << ": " << gardens << " gardens, goals reached "
            << 100.0 * summary.metrics.value("goal_success_rate", 0.0) << " % ("
            << 100.0 * summary.metrics.value("goal_success_rate_as_asked", 0.0) << " % as asked), contacts "
            << summary.metrics.value("collisions", 0.0) << "\n";
  for (const auto& [reason, n] : tally.trial_failures) std::cout << "  trials failed: " << reason << " x" << n << "\n";
  for (const auto& [reason, n] : tally.goal_failures) std::cout << "  goals given up: " << reason << " x" << n << "\n";
  if (report.contains("navigation_planning_ms")) {
    std::cout << "  plans: median " << report["navigation_planning_ms"]["median"].get<double>()
              << " ms, 90th percentile " << report["navigation_planning_ms"]["p90"].get<double>() << " ms over "
              << report["navigation_planning_ms"]["plans"].get<std::size_t>() << " plans\n";
  }
  for (const CriterionResult& c : summary.criteria) {
    std::cout << "  " << (c.pass ? "pass " : "FAIL ") << c.name << " " << c.comparison << " " << c.expected
              << " (actual " << c.actual << ")\n";
  }
  std::cout << "outputs in " << out
            << " (report.html, summary.json, junit.xml, suite.json, suite.md; per garden gardens/NNN/)\n";
  return summary.pass ? 0 : 1;
}

}  // namespace

int RunSuite(const SuiteOptions& options) {
  const SuiteSpec spec = LoadSuite(options.suite_path);
  const int gardens = std::min(spec.gardens, options.gardens.value_or(spec.gardens));
  const auto [outline_min, outline_max] = robot::RobotDescription::Load(options.paths.robot_files().urdf).BaseOutline();
  const double min_distance = 0.5 * (outline_max.y() - outline_min.y()) + spec.goal_margin;
  double reach = 0.0;  // the outline's farthest corner from base_link
  for (const double x : {outline_min.x(), outline_max.x()}) {
    for (const double y : {outline_min.y(), outline_max.y()}) reach = std::max(reach, std::hypot(x, y));
  }
  const double start_distance = reach + spec.goal_margin;
  const double clearance_height = RobotClearanceHeight(options.paths);
  const std::string out = fs::absolute(options.out_dir).lexically_normal().string();
  fs::create_directories(out + "/gardens");
  SuiteTally tally;
  for (int g = 0; g < gardens; ++g) {
    const std::uint64_t seed = spec.seed + static_cast<std::uint64_t>(g);
    const std::string dir = GardenDir(out, g);
    fs::create_directories(dir);
    const garden::GeneratorParameters parameters = DrawGarden(spec, seed);
    const garden::Garden garden = garden::GenerateGarden(parameters);
    WriteFileAtomically(dir + "/garden.yaml", garden.ToYaml());
    const SuiteLayout layout = PlaceSuiteLayout(garden, clearance_height, min_distance, start_distance, spec.goals,
                                                seed, dir + "/garden.yaml");
    WriteScenario(spec, g, dir + "/garden.yaml", layout, dir + "/scenario.yaml");
    const int code = RunGarden(options, dir + "/scenario.yaml", dir + "/batch");
    if (code != 0 && code != 1) {
      throw InputError(dir + "/scenario.yaml", "its batch ended with exit code " + std::to_string(code));
    }
    const json& row = tally.AddGarden(g, seed, dir, garden, parameters, spec.goals);
    std::printf("[suite] garden %03d (seed %llu): %d of %d goals, %d contacts%s\n", g,
                static_cast<unsigned long long>(seed), row["goals_reached"].get<int>(), row["goals"].get<int>(),
                row["collisions"].get<int>(), code == 0 ? "" : " - FAILED");
  }
  return WriteSuiteReports(spec, options, out, tally, gardens);
}

}  // namespace trimbot::scenarios
