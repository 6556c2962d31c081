#include "reports/run_timing.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "reports/drawing.h"
#include "reports/output_files.h"

namespace trimbot::scenarios {

RunTiming MakeRunTiming(double wall_seconds, double simulated_seconds, const sim::SimulatorTimings& sim,
                        const stack::StackTimings* stack, double setup_seconds, double report_seconds) {
  RunTiming t;
  t.wall_seconds = wall_seconds;
  t.simulated_seconds = simulated_seconds;
  const long images = sim.camera_images;
  t.stages = {{"physics", "simulator", sim.physics, sim.physics_steps, "physics step"},
              {"render_draw", "simulator", sim.render_draw, images, "camera image"},
              {"render_readback", "simulator", sim.render_readback, images, "camera image"},
              {"distortion", "simulator", sim.distortion, images, "camera image"},
              {"exposure_noise", "simulator", sim.exposure_noise, images, "camera image"},
              {"depth_images", "simulator", sim.depth, 0, ""},
              {"ground_truth_images", "simulator", sim.ground_truth, 0, ""},
              {"motion_blur", "simulator", sim.motion_blur, images, "camera image"},
              {"wind", "simulator", sim.wind, sim.ring_frames, "ring frame"}};
  if (stack != nullptr) {
    visual_localization::LocalizationTimings v;
    for (const auto& f : stack->visual_frames) {
      v.features += f.features;
      v.retrieval += f.retrieval;
      v.matching += f.matching;
      v.pose += f.pose;
    }
    const auto frames = static_cast<long>(stack->visual_frames.size());
    const double visual_rest =
        std::max(0.0, stack->visual_localization - (v.features + v.retrieval + v.matching + v.pose));
    const std::vector<StageTime> stack_stages = {
        {"ekf", "stack", stack->ekf, 0, ""},
        {"visual_features", "stack", v.features, frames, "localized frame"},
        {"visual_retrieval", "stack", v.retrieval, frames, "localized frame"},
        {"visual_matching", "stack", v.matching, frames, "localized frame"},
        {"visual_pose", "stack", v.pose, frames, "localized frame"},
        {"visual_other", "stack", visual_rest, frames, "localized frame"},
        {"stereo_fusion", "stack", stack->perception, 0, ""},
        {"obstacles", "stack", stack->obstacles, stack->obstacle_pairs, "stereo pair"},
        {"bush_approach", "stack", stack->bush, stack->bush_frames, "bush frame"},
        {"planning", "stack", stack->planning, 0, ""},
        {"control", "stack", stack->control, 0, ""}};
    t.stages.insert(t.stages.end(), stack_stages.begin(), stack_stages.end());
  }
  t.stages.push_back({"setup", "runner", setup_seconds, 0, ""});
  t.stages.push_back({"report_writing", "runner", report_seconds, 0, ""});
  double accounted = 0.0;
  for (const auto& s : t.stages) accounted += s.seconds;
  // The loop itself, evaluation, logging, progress: what no stage timed.
  t.stages.push_back({"other", "runner", std::max(0.0, wall_seconds - accounted), 0, ""});
  return t;
}

nlohmann::json ToJson(const RunTiming& t) {
  nlohmann::json stages = nlohmann::json::array();
  for (const auto& s : t.stages) {
    nlohmann::json row = {{"name", s.name},       {"group", s.group},
                          {"seconds", s.seconds}, {"share", t.wall_seconds > 0 ? s.seconds / t.wall_seconds : 0.0},
                          {"count", s.count},     {"per", s.per}};
    if (s.count > 0) row["ms_per"] = 1000.0 * s.seconds / static_cast<double>(s.count);
    stages.push_back(row);
  }
  return {{"wall_seconds", t.wall_seconds},
          {"simulated_seconds", t.simulated_seconds},
          {"real_time_factor", t.wall_seconds > 0 ? t.simulated_seconds / t.wall_seconds : 0.0},
          {"stages", stages}};
}

RunTiming RunTimingFromJson(const nlohmann::json& json) {
  if (!json.is_object() || !json.contains("stages") || !json["stages"].is_array()) {
    throw std::runtime_error("not a run timing (no stages)");
  }
  RunTiming t;
  t.wall_seconds = json.value("wall_seconds", 0.0);
  t.simulated_seconds = json.value("simulated_seconds", 0.0);
  for (const auto& row : json["stages"]) {
    t.stages.push_back({row.at("name").get<std::string>(), row.at("group").get<std::string>(),
                        row.at("seconds").get<double>(), row.value("count", 0L), row.value("per", std::string())});
  }
  return t;
}

RunTiming Sum(const std::vector<RunTiming>& runs) {
  RunTiming total;
  for (const auto& run : runs) {
    total.wall_seconds += run.wall_seconds;
    total.simulated_seconds += run.simulated_seconds;
    for (const auto& s : run.stages) {
      auto found =
          std::find_if(total.stages.begin(), total.stages.end(), [&](const StageTime& t) { return t.name == s.name; });
      if (found == total.stages.end()) {
        total.stages.push_back(s);
      } else {
        found->seconds += s.seconds;
        found->count += s.count;
      }
    }
  }
  // "other" stays last.
  std::stable_partition(total.stages.begin(), total.stages.end(), [](const StageTime& s) { return s.name != "other"; });
  return total;
}

std::string FormatRunTiming(const RunTiming& t) {
  std::string out;
  char line[200];
  std::snprintf(line, sizeof line, "time by stage: %.1f s wall for %.1f s simulated (real-time factor %.2f)\n",
                t.wall_seconds, t.simulated_seconds, t.wall_seconds > 0 ? t.simulated_seconds / t.wall_seconds : 0.0);
  out += line;
  for (const auto& s : t.stages) {
    if (s.seconds <= 0.0 && s.count == 0) continue;
    std::snprintf(line, sizeof line, "  %-10s %-20s %9.2f s %5.1f %%", s.group.c_str(), s.name.c_str(), s.seconds,
                  t.wall_seconds > 0 ? 100.0 * s.seconds / t.wall_seconds : 0.0);
    out += line;
    if (s.count > 0) {
      std::snprintf(line, sizeof line, "  %8.2f ms per %s (%ld)", 1000.0 * s.seconds / static_cast<double>(s.count),
                    s.per.c_str(), s.count);
      out += line;
    }
    out += "\n";
  }
  return out;
}

void WriteRunTimingChart(const std::string& path, const std::string& title, const RunTiming& t) {
  std::vector<const StageTime*> rows;
  for (const auto& s : t.stages) {
    if (s.seconds > 0.0) rows.push_back(&s);
  }
  constexpr int kWidth = 1000, kRow = 26, kLabel = 190, kBarWidth = 420;
  const int height = 90 + kRow * static_cast<int>(rows.size()) + 30;
  cv::Mat image(height, kWidth, CV_8UC3, kWhite);
  PutText(image, title, {16, 30}, 0.6, kInk, 2);
  char line[160];
  std::snprintf(line, sizeof line, "%.1f s wall for %.1f s simulated: real-time factor %.2f", t.wall_seconds,
                t.simulated_seconds, t.wall_seconds > 0 ? t.simulated_seconds / t.wall_seconds : 0.0);
  PutText(image, line, {16, 56}, 0.45, kInk);
  double longest = 0.0;
  for (const auto* s : rows) longest = std::max(longest, s->seconds);
  const auto colour = [](const std::string& group) {
    if (group == "simulator") return HsvToRgb(210, 0.6, 0.85);
    if (group == "stack") return HsvToRgb(30, 0.7, 0.9);
    return HsvToRgb(0, 0.0, 0.6);
  };
  int y = 80;
  for (const auto* s : rows) {
    PutText(image, s->name, {16, y + 17}, 0.45, kInk);
    const int w = longest > 0 ? static_cast<int>(std::lround(kBarWidth * s->seconds / longest)) : 0;
    cv::rectangle(image, cv::Rect(kLabel, y + 4, std::max(w, 1), kRow - 8), colour(s->group), cv::FILLED);
    std::string text = FormatFixed(s->seconds, 1) + " s  " +
                       FormatFixed(t.wall_seconds > 0 ? 100.0 * s->seconds / t.wall_seconds : 0.0, 1) + " %";
    if (s->count > 0) {
      text += "  " + FormatFixed(1000.0 * s->seconds / static_cast<double>(s->count), 2) + " ms per " + s->per;
    }
    PutText(image, text, {kLabel + w + 10, y + 17}, 0.42, kInk);
    y += kRow;
  }
  int x = 16;
  for (const char* group : {"simulator", "stack", "runner"}) {
    cv::rectangle(image, cv::Rect(x, height - 26, 14, 14), colour(group), cv::FILLED);
    PutText(image, group, {x + 20, height - 14}, 0.42, kInk);
    x += 130;
  }
  WritePng(path, image);
}

}  // namespace trimbot::scenarios
