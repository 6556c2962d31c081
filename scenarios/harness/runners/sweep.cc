#include "runners/sweep.h"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>

#include "evaluation/comparison.h"
#include "loop/prior_knowledge.h"
#include "loop/scenario.h"
#include "reports/html_report.h"
#include "reports/sweep_plot.h"
#include "runners/batch_executor.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Index tuples of the grid product, the first grid varying slowest.
std::vector<std::vector<std::size_t>> Product(const std::vector<SweepGrid>& grids) {
  std::vector<std::vector<std::size_t>> points{{}};
  for (const auto& grid : grids) {
    std::vector<std::vector<std::size_t>> next;
    for (const auto& point : points) {
      for (std::size_t v = 0; v < grid.values.size(); ++v) {
        next.push_back(point);
        next.back().push_back(v);
      }
    }
    points = std::move(next);
  }
  return points;
}

std::vector<std::string> PointOverrides(const SweepOptions& options, const std::vector<SweepGrid>& grids,
                                        const std::vector<std::size_t>& point) {
  std::vector<std::string> overrides = options.overrides;
  for (std::size_t g = 0; g < grids.size(); ++g) overrides.push_back(grids[g].key + "=" + grids[g].values[point[g]]);
  return overrides;
}

std::string PointDir(const std::string& out, std::size_t index) {
  std::ostringstream name;
  name << out << "/points/" << std::setw(3) << std::setfill('0') << index;
  return name.str();
}

json PointJson(const std::vector<SweepGrid>& grids, const std::vector<std::size_t>& point, std::size_t index,
               const std::vector<MetricEstimate>& estimates) {
  json values, metrics;
  for (std::size_t g = 0; g < grids.size(); ++g) values[grids[g].key] = grids[g].values[point[g]];
  for (const auto& e : estimates) {
    metrics[e.metric] = {{"value", e.value}, {"low", e.interval.low}, {"high", e.interval.high}, {"n", e.n}};
  }
  return {{"index", index}, {"values", values}, {"metrics", metrics}};
}

std::string Csv(const std::vector<SweepGrid>& grids, const json& points) {
  std::ostringstream csv;
  csv << std::setprecision(8) << "point";
  for (const auto& grid : grids) csv << "," << grid.key;
  const json& first = points.front()["metrics"];
  for (const auto& [metric, unused] : first.items())
    csv << "," << metric << "," << metric << "_low," << metric << "_high";
  csv << "\n";
  for (const auto& p : points) {
    csv << p["index"].get<std::size_t>();
    for (const auto& grid : grids) csv << "," << p["values"][grid.key].get<std::string>();
    for (const auto& [metric, m] : p["metrics"].items()) {
      for (const char* field : {"value", "low", "high"}) {
        csv << ",";
        if (m[field].is_number()) csv << m[field].get<double>();  // empty: no trial had a value
      }
    }
    csv << "\n";
  }
  return csv.str();
}

// Plots of every metric against every grid key, one series per combination of the other keys.
void WritePlots(const std::string& out, const std::string& scenario, const std::vector<SweepGrid>& grids,
                const std::vector<std::vector<std::size_t>>& points, const json& results) {
  fs::create_directories(out + "/plots");
  for (const auto& [metric, unused] : results.front()["metrics"].items()) {
    for (std::size_t k = 0; k < grids.size(); ++k) {
      std::vector<SweepSeries> series;
      std::vector<std::string> labels;
      for (std::size_t i = 0; i < points.size(); ++i) {
        std::string label;
        for (std::size_t g = 0; g < grids.size(); ++g) {
          // The last part of the key keeps the legend short: "lookahead=0.4".
          const std::string short_key = grids[g].key.substr(grids[g].key.rfind('.') + 1);
          if (g != k) label += (label.empty() ? "" : ", ") + short_key + "=" + grids[g].values[points[i][g]];
        }
        auto it = std::find(labels.begin(), labels.end(), label);
        if (it == labels.end()) {
          labels.push_back(label);
          const std::size_t n = grids[k].values.size();
          series.push_back({label, std::vector<double>(n, std::nan("")), std::vector<double>(n, std::nan("")),
                            std::vector<double>(n, std::nan(""))});
          it = labels.end() - 1;
        }
        SweepSeries& s = series[static_cast<std::size_t>(it - labels.begin())];
        const json& m = results[i]["metrics"][metric];
        s.value[points[i][k]] = m["value"].is_number() ? m["value"].get<double>() : std::nan("");
        s.low[points[i][k]] = m["low"].get<double>();
        s.high[points[i][k]] = m["high"].get<double>();
      }
      WriteSweepPlot(out + "/plots/" + metric + "_vs_" + grids[k].key + ".png", scenario + ": " + metric, grids[k].key,
                     grids[k].values, metric, series);
    }
  }
}

}  // namespace

SweepGrid ParseGrid(const std::string& text) {
  const auto equals = text.find('=');
  if (equals == std::string::npos || equals == 0) throw InputError("--grid", "'" + text + "' is not key=v1,v2,...");
  SweepGrid grid;
  grid.key = text.substr(0, equals);
  std::istringstream values(text.substr(equals + 1));
  for (std::string value; std::getline(values, value, ',');) {
    if (value.empty()) throw InputError("--grid", "'" + text + "': an empty value");
    grid.values.push_back(value);
  }
  if (grid.values.empty()) throw InputError("--grid", "'" + text + "': no values");
  return grid;
}

int RunSweep(const SweepOptions& options) {
  if (options.grids.empty()) throw InputError("--grid", "a sweep needs at least one grid");
  std::vector<SweepGrid> grids;
  std::set<std::string> keys;
  for (const auto& text : options.grids) {
    grids.push_back(ParseGrid(text));
    if (!keys.insert(grids.back().key).second) throw InputError("--grid", "key '" + grids.back().key + "' given twice");
  }
  const auto points = Product(grids);
  // Every point's scenario and stack parameters are checked before anything runs.
  std::string name;
  for (const auto& point : points) {
    const Scenario s = Scenario::Load(options.scenario_path, ParseOverrides(PointOverrides(options, grids, point)));
    StackParametersFor(s, options.paths);
    name = s.name;
  }
  fs::create_directories(options.out_dir);
  std::cout << "[sweep] " << name << ": " << points.size() << " points -> " << options.out_dir << std::endl;
  std::vector<BatchOptions> batches;
  for (std::size_t i = 0; i < points.size(); ++i) {
    BatchOptions batch;
    batch.scenario_path = options.scenario_path;
    batch.out_dir = PointDir(options.out_dir, i);
    batch.paths = options.paths;
    batch.trials = options.trials;
    batch.seed = options.seed;
    batch.jobs = options.jobs;
    batch.overrides = PointOverrides(options, grids, points[i]);
    batch.quiet = true;
    batches.push_back(batch);
  }
  std::vector<json> point_results(points.size());
  RunBatches(options.executor, batches, [&](std::size_t i) {
    std::ifstream in(batches[i].out_dir + "/summary.json");
    const auto estimates = BatchEstimates(json::parse(in));
    point_results[i] = PointJson(grids, points[i], i, estimates);
    std::cout << "[sweep] point " << i;
    for (std::size_t g = 0; g < grids.size(); ++g)
      std::cout << " " << grids[g].key << "=" << grids[g].values[points[i][g]];
    std::cout << std::setprecision(4) << ": success " << estimates[0].value << " [" << estimates[0].interval.low << ", "
              << estimates[0].interval.high << "], EKF error " << estimates[2].value << " m" << std::endl;
  });
  const json results = point_results;
  json grids_json;
  for (const auto& g : grids) grids_json[g.key] = g.values;
  const json sweep = {{"scenario", name},
                      {"scenario_file", options.scenario_path},
                      {"overrides", options.overrides},
                      {"grids", grids_json},
                      {"points", results}};
  WriteFileAtomically(options.out_dir + "/sweep.json", sweep.dump(2));
  WriteFileAtomically(options.out_dir + "/sweep.csv", Csv(grids, results));
  WritePlots(options.out_dir, name, grids, points, results);
  WriteHtmlReport(options.out_dir);
  std::cout << "[sweep] outputs in " << options.out_dir << " (report.html, sweep.csv, sweep.json, plots/)" << std::endl;
  return 0;
}

}  // namespace trimbot::scenarios
