#include "reports/html_report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <vector>

#include "evaluation/comparison.h"
#include "reports/batch_report.h"
#include "trimbot/common/atomic_file.h"
#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Laptop-screen sizes; pass/fail and verdicts in colour and in words (colour alone is not read by all).
constexpr const char* kStyle = R"(
body { font-family: system-ui, sans-serif; margin: 0 auto; max-width: 1400px; padding: 0 1.5em 3em; color: #1d2327; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 2px solid #d0d7de; padding-bottom: 0.2em; margin-top: 1.6em; }
nav { position: sticky; top: 0; background: #fff; padding: 0.5em 0; border-bottom: 1px solid #d0d7de; z-index: 1; }
nav a { margin-right: 1.2em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.92em; }
th, td { border: 1px solid #d0d7de; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f6f8fa; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
tr.pass td.verdict, span.pass { background: #dafbe1; color: #116329; font-weight: bold; }
tr.fail td.verdict, span.fail { background: #ffebe9; color: #a40e26; font-weight: bold; }
span.pass, span.fail { padding: 0.1em 0.5em; border-radius: 0.3em; }
.meta { color: #57606a; } .wall { color: #8c959f; font-style: italic; }
figure { display: inline-block; margin: 0.5em 1em 0.5em 0; max-width: 100%; vertical-align: top; }
figure img { max-width: 100%; max-height: 720px; border: 1px solid #d0d7de; }
figcaption { font-size: 0.85em; color: #57606a; }
section.trial { border-left: 4px solid #d0d7de; padding-left: 1em; margin-top: 1.5em; }
section.trial.failed { border-left-color: #cf222e; } section.trial.succeeded { border-left-color: #2da44e; }
details > summary { cursor: pointer; color: #0969da; }
div.wide { overflow-x: auto; max-width: 100%; }
)";

// Marks images that did not load: a console error each and the count on <body> (a browser test
// reads both).
constexpr const char* kImageCheck = R"(<script>
window.addEventListener('load', function () {
  var broken = 0;
  document.querySelectorAll('img').forEach(function (img) {
    if (!img.complete || img.naturalWidth === 0) {
      broken += 1;
      console.error('image did not load: ' + img.getAttribute('src'));
    }
  });
  document.body.setAttribute('data-broken-images', String(broken));
});
</script>
)";

std::string Number(double value) {
  if (!std::isfinite(value)) return "&ndash;";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", value);
  return buffer;
}

// A JSON scalar as table text; arrays and objects as compact JSON.
std::string Cell(const json& value) {
  // Seeds and counts exactly (a seed printed as 2.024e+07 names no trial).
  if (value.is_number_unsigned()) return std::to_string(value.get<std::uint64_t>());
  if (value.is_number_integer()) return std::to_string(value.get<std::int64_t>());
  if (value.is_number()) return Number(value.get<double>());
  if (value.is_boolean()) return value.get<bool>() ? "yes" : "no";
  if (value.is_string()) return XmlEscape(value.get<std::string>());
  if (value.is_null()) return "&ndash;";
  return "<code>" + XmlEscape(value.dump()) + "</code>";
}

std::string NumberCell(const json& value) {
  return std::string("<td") + (value.is_number() ? " class=\"num\"" : "") + ">" + Cell(value) + "</td>";
}

json ReadJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot be read");
  try {
    return json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(path, std::string("is not valid JSON (truncated or damaged?): ") + e.what());
  }
}

// `render` of the JSON in `path`; a field it needs that is missing or of another type is an
// InputError naming the file: "<path>: is not <what>: <the field>".
template <typename Render>
std::string RenderJsonFile(const std::string& path, const std::string& what, Render render) {
  const json content = ReadJson(path);
  try {
    return render(content);
  } catch (const json::exception& e) {
    throw InputError(path, "is not " + what + ": " + e.what());
  }
}

// The PNG files directly in `dir`, by name (relative to the page: `prefix` + name).
std::vector<std::string> Pictures(const std::string& dir, const std::string& prefix) {
  std::vector<std::string> names;
  if (!fs::is_directory(dir)) return names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().extension() == ".png")
      names.push_back(prefix + entry.path().filename().string());
  }
  // The batch's main plots first (trajectories over the map, the errors), then the rest by name.
  const std::vector<std::string> first = {"trajectories.png", "localization_errors.png", "localization_map.png",
                                          "bush_errors.png",  "bush_frames.png",         "arm_reach.png"};
  const auto rank = [&](const std::string& name) {
    const auto at = std::find(first.begin(), first.end(), fs::path(name).filename().string());
    return std::make_pair(at - first.begin(), name);
  };
  std::sort(names.begin(), names.end(), [&](const auto& a, const auto& b) { return rank(a) < rank(b); });
  return names;
}

// `pictures` without the one named `name` (a picture shown in a section of its own).
std::vector<std::string> Without(std::vector<std::string> pictures, const std::string& name) {
  pictures.erase(std::remove(pictures.begin(), pictures.end(), name), pictures.end());
  return pictures;
}

// A relative path as a link's URL: every byte but RFC 3986's unreserved characters and '/'
// percent-encoded (a file named "a #1.png" would otherwise link to "a ").
std::string UrlPath(const std::string& path) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string url;
  for (const unsigned char c : path) {
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
      url += static_cast<char>(c);
    } else {
      url += {'%', kHex[c >> 4], kHex[c & 15]};
    }
  }
  return url;
}

std::string Figures(const std::vector<std::string>& pictures) {
  std::string html;
  for (const auto& src : pictures) {
    const std::string name = fs::path(src).filename().string(), url = UrlPath(src);
    html += "<figure><a href=\"" + url + "\"><img src=\"" + url + "\" alt=\"" + XmlEscape(name) +
            "\"></a><figcaption>" + XmlEscape(name) + "</figcaption></figure>\n";
  }
  return html;
}

// Rows of objects as one table: the columns are the scalar keys, in order of first appearance.
std::string ObjectsTable(const json& rows) {
  std::vector<std::string> columns;
  std::set<std::string> seen;
  for (const auto& row : rows) {
    if (!row.is_object()) continue;
    for (const auto& [key, value] : row.items()) {
      if (!value.is_structured() && seen.insert(key).second) columns.push_back(key);
    }
  }
  if (columns.empty()) return "";
  std::string html = "<div class=\"wide\"><table><tr>";
  for (const auto& c : columns) html += "<th>" + XmlEscape(c) + "</th>";
  html += "</tr>\n";
  for (const auto& row : rows) {
    html += "<tr>";
    for (const auto& c : columns) html += row.is_object() && row.contains(c) ? NumberCell(row[c]) : "<td></td>";
    html += "</tr>\n";
  }
  return html + "</table></div>\n";
}

// An object's scalar members as a two-column table.
std::string KeyValueTable(const json& object) {
  std::string html = "<table>";
  for (const auto& [key, value] : object.items()) {
    if (!value.is_structured()) html += "<tr><th>" + XmlEscape(key) + "</th>" + NumberCell(value) + "</tr>\n";
  }
  return html + "</table>\n";
}

// Any JSON document, as tables: scalars together, arrays of objects as tables, objects nested.
std::string AnyJson(const json& value, int depth) {
  if (!value.is_object()) return value.is_array() ? ObjectsTable(value) : "<p>" + Cell(value) + "</p>";
  std::string html = KeyValueTable(value);
  for (const auto& [key, member] : value.items()) {
    if (!member.is_structured() || member.empty()) continue;
    const bool rows = member.is_array() && member.front().is_object();
    const std::string inner = rows                ? ObjectsTable(member)
                              : member.is_array() ? "<p>" + Cell(member) + "</p>"
                                                  : AnyJson(member, depth + 1);
    html += "<details" + std::string(depth == 0 ? " open" : "") + "><summary>" + XmlEscape(key) + "</summary>\n" +
            inner + "</details>\n";
  }
  return html;
}

std::string Page(const std::string& title, const std::string& nav, const std::string& body) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
         XmlEscape(title) + "</title>\n<style>" + kStyle +
         "</style>\n</head>\n<body data-broken-images=\"unknown\">\n" +
         (nav.empty() ? "" : "<nav>" + nav + "</nav>\n") + body + kImageCheck + "</body>\n</html>\n";
}

std::string Verdict(bool pass, const std::string& yes = "PASS", const std::string& no = "FAIL") {
  return pass ? "<span class=\"pass\">" + yes + "</span>" : "<span class=\"fail\">" + no + "</span>";
}

std::string TrialName(int index) {
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "%03d", index);
  return buffer;
}

// events.csv as a table (the first `limit` events; the file has them all).
std::string EventsTable(const std::string& path, std::size_t limit) {
  std::ifstream in(path);
  if (!in) return "";
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  if (lines.size() < 2) return "<p class=\"meta\">no events</p>\n";
  std::string html = "<details><summary>events (" + std::to_string(lines.size() - 1) + ")</summary><table>";
  for (std::size_t i = 0; i < lines.size() && i <= limit; ++i) {
    html += "<tr>";
    std::istringstream fields(lines[i]);
    // t,event,goal,detail: the detail is the rest of the line (it may hold commas).
    std::string field;
    for (int column = 0; column < 3 && std::getline(fields, field, ','); ++column)
      html += (i == 0 ? "<th>" : "<td>") + XmlEscape(field) + (i == 0 ? "</th>" : "</td>");
    std::getline(fields, field);
    html += (i == 0 ? "<th>" : "<td>") + XmlEscape(field) + (i == 0 ? "</th>" : "</td>");
    html += "</tr>\n";
  }
  if (lines.size() - 1 > limit)
    html += "</table><p class=\"meta\">first " + std::to_string(limit) + " shown</p>";
  else
    html += "</table>";
  return html + "</details>\n";
}

const json* Estimate(const json& trial, const std::string& name) {
  if (!trial.contains("estimates")) return nullptr;
  for (const auto& e : trial["estimates"]) {
    if (e.value("name", "") == name) return &e;
  }
  return nullptr;
}

std::string TrialSection(const std::string& dir, const json& trial) {
  const int index = trial.at("index").get<int>();
  const std::string name = TrialName(index);
  const std::string trial_dir = dir + "/trials/" + name;
  const bool success = trial.value("success", false);
  std::string html = "<section class=\"trial " + std::string(success ? "succeeded" : "failed") + "\" id=\"trial-" +
                     name + "\">\n<h3>Trial " + std::to_string(index) + " (seed " + Cell(trial.at("seed")) +
                     "): " + Verdict(success, "succeeded", "failed") + " " + Cell(trial.value("status", json("?"))) +
                     "</h3>\n";
  if (!trial.value("message", std::string()).empty())
    html += "<p><b>Reason:</b> " + XmlEscape(trial["message"].get<std::string>()) + "</p>\n";
  html += "<details open><summary>figures</summary>" + KeyValueTable(trial) + "</details>\n";
  if (trial.contains("goals") && !trial["goals"].empty())
    html += "<details open><summary>goals</summary>" + ObjectsTable(trial["goals"]) + "</details>\n";
  if (trial.contains("trims") && !trial["trims"].empty())
    html += "<details open><summary>trims</summary>" + ObjectsTable(trial["trims"]) + "</details>\n";
  if (trial.contains("estimates")) {
    json stats = json::array();
    for (const auto& e : trial["estimates"]) {
      json row{{"estimate", e.value("name", "")}};
      // Named: items() of a temporary would outlive it in the range-for.
      const json position = e.value("position_stats_m", json::object());
      const json heading = e.value("heading_stats_deg", json::object());
      for (const auto& [key, value] : position.items()) row["position " + key + " (m)"] = value;
      for (const auto& [key, value] : heading.items()) row["heading " + key + " (deg)"] = value;
      stats.push_back(row);
    }
    if (!stats.empty())
      html += "<details open><summary>errors against ground truth</summary>" + ObjectsTable(stats) + "</details>\n";
  }
  if (fs::exists(trial_dir + "/trial.mp4"))
    html += "<figure><video controls preload=\"metadata\" src=\"trials/" + name +
            "/trial.mp4\" width=\"1016\"></video><figcaption>trial.mp4</figcaption></figure>\n";
  html += Figures(Pictures(trial_dir, "trials/" + name + "/"));
  html += EventsTable(trial_dir + "/events.csv", 300);
  if (fs::is_directory(trial_dir)) {
    std::vector<std::string> files;
    for (const auto& entry : fs::directory_iterator(trial_dir)) {
      if (entry.is_regular_file() && entry.path().extension() != ".png")
        files.push_back(entry.path().filename().string());
    }
    std::sort(files.begin(), files.end());
    html += "<p class=\"meta\">files:";
    for (const auto& f : files)
      html += " <a href=\"" + UrlPath("trials/" + name + "/" + f) + "\">" + XmlEscape(f) + "</a>";
    html += "</p>\n";
  }
  return html + "</section>\n";
}

// The timing section: wall-clock figures, which differ from run to run.
std::string TimingTables(const std::string& dir, const json& timing) {
  std::string html = "<h2 id=\"timing\">Timing <span class=\"wall\">(wall clock: differs run to run)</span></h2>\n";
  if (timing.contains("mean_wall_seconds"))
    html += "<p>Mean wall time per trial: " + Number(timing["mean_wall_seconds"].get<double>()) + " s";
  if (timing.contains("stages_summed_over_trials")) {
    const json& summed = timing["stages_summed_over_trials"];
    html += "; real-time factor " + Cell(summed.value("real_time_factor", json())) + " over " +
            Cell(summed.value("simulated_seconds", json())) + " simulated seconds</p>\n";
    if (summed.contains("stages")) html += ObjectsTable(summed["stages"]);
  } else {
    html += "</p>\n";
  }
  if (fs::exists(dir + "/timing.png")) html += Figures({"timing.png"});
  for (const char* plans : {"navigation_planning_ms", "arm_planning_ms"}) {
    if (timing.contains(plans)) html += "<p>" + std::string(plans) + "</p>" + KeyValueTable(timing[plans]);
  }
  return html;
}

std::string TimingSection(const std::string& dir) {
  const std::string path = dir + "/timing.json";
  if (!fs::exists(path)) return "";
  return RenderJsonFile(path, "a batch's timing", [&](const json& timing) { return TimingTables(dir, timing); });
}

// The criteria of a batch summary (summary.json), pass/fail coloured.
std::string CriteriaSection(const json& summary) {
  std::string body;
  body += "<h2 id=\"criteria\">Criteria</h2>\n";
  if (summary.at("criteria").empty()) {
    body += "<p class=\"meta\">the scenario states no criteria</p>\n";
  } else {
    body += "<table><tr><th>criterion</th><th>required</th><th>actual</th><th>verdict</th></tr>\n";
    for (const auto& c : summary["criteria"]) {
      const bool ok = c.at("pass").get<bool>();
      body += "<tr class=\"" + std::string(ok ? "pass" : "fail") + "\"><td>" + Cell(c.at("name")) + "</td><td>" +
              Cell(c.at("comparison")) + " " + Cell(c.at("expected")) + "</td>" + NumberCell(c.at("actual")) +
              "<td class=\"verdict\">" + (ok ? "pass" : "FAIL") + "</td></tr>\n";
    }
    body += "</table>\n";
  }

  return body;
}

std::string BatchPage(const std::string& dir) {
  return RenderJsonFile(dir + "/summary.json", "a batch summary", [&](const json& summary) {
    const std::string scenario = summary.at("scenario").get<std::string>();
    const bool pass = summary.at("pass").get<bool>();
    const json& trials = summary.at("trials");
    std::string body = "<h1>" + XmlEscape(scenario) + " " + Verdict(pass) + "</h1>\n<p class=\"meta\">batch of " +
                       std::to_string(trials.size()) + " of " + Cell(summary.at("trials_planned")) +
                       " planned trials; scenario file " + Cell(summary.value("scenario_file", json(""))) +
                       "; batch seed " + Cell(summary.at("seed")) + " (trial i runs with seed + i)";
    if (summary.contains("overrides") && !summary["overrides"].empty())
      body += "; overrides " + Cell(summary["overrides"]);
    body += "</p>\n";

    body += CriteriaSection(summary);

    body +=
        "<h2 id=\"metrics\">Metrics</h2>\n<table><tr><th>metric</th><th>value</th><th>95 % "
        "interval</th><th>trials</th><th>unit</th></tr>\n";
    for (const MetricEstimate& e : BatchEstimates(summary)) {
      const std::string interval =
          e.n > 0 ? "[" + Number(e.interval.low) + ", " + Number(e.interval.high) + "]" : "&ndash;";
      body += "<tr><td>" + XmlEscape(e.metric) + "</td><td class=\"num\">" + Number(e.value) +
              "</td><td class=\"num\">" + interval + "</td><td class=\"num\">" + std::to_string(e.n) + "</td><td>" +
              XmlEscape(e.unit) + "</td></tr>\n";
    }
    body += "</table>\n<details><summary>all batch metrics</summary>" + KeyValueTable(summary.at("metrics")) +
            "</details>\n";

    body += "<h2 id=\"plots\">Plots</h2>\n" + Figures(Without(Pictures(dir, ""), "timing.png"));

    body +=
        "<h2 id=\"trials\">Trials</h2>\n<table><tr><th>trial</th><th>seed</th><th>verdict</th><th>status</th>"
        "<th>reason</th><th>simulated s</th><th>path m</th><th>collisions</th><th>EKF error mean / max m</th></tr>\n";
    for (const auto& t : trials) {
      const std::string name = TrialName(t.at("index").get<int>());
      const bool ok = t.value("success", false);
      const json* ekf = Estimate(t, "ekf");
      std::string ekf_error = "&ndash;";
      if (ekf != nullptr && ekf->contains("position_stats_m"))
        ekf_error = Number((*ekf)["position_stats_m"].value("mean", NAN)) + " / " +
                    Number((*ekf)["position_stats_m"].value("max", NAN));
      body += "<tr class=\"" + std::string(ok ? "pass" : "fail") + "\"><td><a href=\"#trial-" + name + "\">" + name +
              "</a></td>" + NumberCell(t.at("seed")) + "<td class=\"verdict\">" + (ok ? "succeeded" : "failed") +
              "</td><td>" + Cell(t.value("status", json("?"))) + "</td><td>" + Cell(t.value("message", json(""))) +
              "</td>" + NumberCell(t.value("simulated_seconds", json())) +
              NumberCell(t.value("path_length_m", json())) + NumberCell(t.value("collisions", json())) +
              "<td class=\"num\">" + ekf_error + "</td></tr>\n";
    }
    body += "</table>\n";
    body += TimingSection(dir);
    body += "<h2 id=\"trial-sections\">Each trial</h2>\n";
    for (const auto& t : trials) body += TrialSection(dir, t);
    const std::string nav =
        "<a href=\"#criteria\">criteria</a><a href=\"#metrics\">metrics</a><a href=\"#plots\">plots</a>"
        "<a href=\"#trials\">trials</a><a href=\"#timing\">timing</a>";
    return Page(scenario + ": batch report", nav, body);
  });
}

std::string SweepPage(const std::string& dir) {
  return RenderJsonFile(dir + "/sweep.json", "a sweep result", [&](const json& sweep) {
    const std::string scenario = sweep.at("scenario").get<std::string>();
    std::string body = "<h1>" + XmlEscape(scenario) + ": sweep</h1>\n<p class=\"meta\">scenario file " +
                       Cell(sweep.value("scenario_file", json(""))) + "; grids " + Cell(sweep.at("grids")) + "</p>\n";
    std::vector<std::string> keys, metrics;
    for (const auto& [key, values] : sweep["grids"].items()) keys.push_back(key);
    for (const auto& point : sweep.at("points")) {
      for (const auto& [metric, value] : point.at("metrics").items()) {
        if (std::find(metrics.begin(), metrics.end(), metric) == metrics.end()) metrics.push_back(metric);
      }
    }
    body +=
        "<h2 id=\"points\">Points</h2>\n<p class=\"meta\">value [95 % interval] over the point's "
        "trials</p>\n<div class=\"wide\"><table><tr><th>point</th>";
    for (const auto& k : keys) body += "<th>" + XmlEscape(k) + "</th>";
    for (const auto& m : metrics) body += "<th>" + XmlEscape(m) + "</th>";
    body += "</tr>\n";
    for (const auto& point : sweep["points"]) {
      const std::string name = TrialName(point.at("index").get<int>());
      // The point's own batch report, where its batch wrote one.
      std::string link = name;
      if (fs::exists(dir + "/points/" + name + "/report.html"))
        link = "<a href=\"points/" + name + "/report.html\">" + name + "</a>";
      body += "<tr><td>" + link + "</td>";
      for (const auto& k : keys) body += "<td>" + Cell(point.at("values").value(k, json())) + "</td>";
      for (const auto& m : metrics) {
        const json e = point["metrics"].value(m, json::object());
        body += "<td class=\"num\">" + Cell(e.value("value", json()));
        if (e.value("n", 0) > 0)
          body += " [" + Cell(e.value("low", json())) + ", " + Cell(e.value("high", json())) + "]";
        body += "</td>";
      }
      body += "</tr>\n";
    }
    body += "</table></div>\n<h2 id=\"plots\">Plots</h2>\n" + Figures(Pictures(dir, "")) +
            Figures(Pictures(dir + "/plots", "plots/"));
    return Page(scenario + ": sweep", "<a href=\"#points\">points</a><a href=\"#plots\">plots</a>", body);
  });
}

std::string ComparisonPage(const std::string& dir) {
  return RenderJsonFile(dir + "/comparison.json", "a comparison", [&](const json& comparison) {
    const bool regressed = comparison.at("verdict").get<std::string>() == "regressed";
    std::string body =
        "<h1>" + Cell(comparison.at("scenario")) + ": comparison " + Verdict(!regressed, "no regression", "REGRESSED") +
        "</h1>\n<p class=\"meta\">baseline " + Cell(comparison.at("baseline_trials")) + " trials, candidate " +
        Cell(comparison.at("candidate_trials")) + " trials; one-sided tests at " + Cell(comparison.at("alpha")) +
        " over all metrics (" + Cell(comparison.at("alpha_per_metric")) +
        " each)</p>\n<h2 id=\"metrics\">Metrics</h2>\n<table><tr><th>metric</th><th>unit</th><th>baseline</th>"
        "<th>candidate</th><th>delta [95 %]</th><th>p worse</th><th>p better</th><th>test</th><th>verdict</th></tr>\n";
    for (const auto& m : comparison.at("metrics")) {
      const std::string verdict = m.at("verdict").get<std::string>();
      const bool worse = verdict == "regressed";
      const json& interval = m.at("delta_95");
      body += "<tr class=\"" + std::string(worse ? "fail" : "pass") + "\"><td>" + Cell(m.at("metric")) + "</td><td>" +
              Cell(m.value("unit", json(""))) + "</td>" + NumberCell(m.at("baseline")) + NumberCell(m.at("candidate")) +
              "<td class=\"num\">" + Cell(m.at("delta")) + " [" + Cell(interval.at(0)) + ", " + Cell(interval.at(1)) +
              "]</td>" + NumberCell(m.at("p_worse")) + NumberCell(m.at("p_better")) + "<td>" +
              Cell(m.value("test", json(""))) + "</td><td class=\"verdict\">" + XmlEscape(verdict) + "</td></tr>\n";
    }
    body += "</table>\n";
    if (comparison.contains("power") && !comparison["power"].empty())
      body += "<h2 id=\"power\">Trials needed to see a change</h2>\n" + ObjectsTable(comparison["power"]);
    body += Figures(Pictures(dir, ""));
    return Page(comparison["scenario"].get<std::string>() + ": comparison", "", body);
  });
}

// A suite: its criteria (summary.json: the suite as one batch), the gardens' table (suite.json)
// with each garden's own batch report, and the rest of suite.json as it stands.
std::string SuitePage(const std::string& dir) {
  return RenderJsonFile(dir + "/suite.json", "a suite result", [&](const json& suite) {
    const std::string name = suite.at("suite").get<std::string>();
    std::string body = "<h1>" + XmlEscape(name) + ": suite";
    if (fs::exists(dir + "/summary.json")) {
      body += RenderJsonFile(dir + "/summary.json", "a batch summary", [](const json& summary) {
        return " " + Verdict(summary.at("pass").get<bool>()) + "</h1>\n" + CriteriaSection(summary);
      });
    } else {
      body += "</h1>\n";
    }
    const json& gardens = suite.at("gardens");
    body += "<h2 id=\"gardens\">Gardens</h2>\n" + ObjectsTable(gardens);
    std::string links;
    for (std::size_t i = 0; i < gardens.size(); ++i) {
      const std::string report = "gardens/" + TrialName(static_cast<int>(i)) + "/batch/report.html";
      if (fs::exists(dir + "/" + report))
        links += " <a href=\"" + report + "\">" + TrialName(static_cast<int>(i)) + "</a>";
    }
    if (!links.empty()) body += "<p>Each garden's batch report:" + links + "</p>\n";
    json rest = suite;
    rest.erase("gardens");
    const json planning = rest.value("navigation_planning_ms", json());  // wall clock: its own section
    rest.erase("navigation_planning_ms");
    body += "<h2>Figures</h2>\n" + AnyJson(rest, 0) + Figures(Pictures(dir, ""));
    if (!planning.is_null())
      body +=
          "<h2 id=\"timing\">Timing <span class=\"wall\">(wall clock: differs run to run)</span></h2>\n"
          "<p>navigation_planning_ms</p>" +
          KeyValueTable(planning);
    return Page(name + ": suite", "", body);
  });
}

// tune.json: its tables as they stand, and the folder's plots.
std::string GenericPage(const std::string& dir, const std::string& file, const std::string& what) {
  const json result = ReadJson(dir + "/" + file);
  if (!result.is_object()) throw InputError(dir + "/" + file, "is not a JSON object");
  std::string title;
  try {
    title = result.value("scenario", result.value("name", fs::path(dir).filename().string())) + ": " + what;
  } catch (const json::exception& e) {
    throw InputError(dir + "/" + file, std::string("names its scenario with no string: ") + e.what());
  }
  return Page(
      title, "",
      "<h1>" + XmlEscape(title) + "</h1>\n" + AnyJson(result, 0) + "<h2>Plots</h2>\n" + Figures(Pictures(dir, "")));
}

}  // namespace

std::string HtmlReport(const std::string& dir) {
  if (!fs::is_directory(dir)) throw InputError(dir, "is not a folder");
  if (fs::exists(dir + "/suite.json")) return SuitePage(dir);  // beside its summary.json
  if (fs::exists(dir + "/summary.json")) return BatchPage(dir);
  if (fs::exists(dir + "/sweep.json")) return SweepPage(dir);
  if (fs::exists(dir + "/comparison.json")) return ComparisonPage(dir);
  if (fs::exists(dir + "/tune.json")) return GenericPage(dir, "tune.json", "tuning");
  throw InputError(dir,
                   "is not a result folder: no summary.json, sweep.json, comparison.json, tune.json or suite.json");
}

void WriteHtmlReport(const std::string& dir) { WriteFileAtomically(dir + "/report.html", HtmlReport(dir)); }

}  // namespace trimbot::scenarios
