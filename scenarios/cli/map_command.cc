#include "cli/map_command.h"

#include <memory>

#include "runner/mapping.h"

namespace trimbot::scenarios {

void AddMapCommands(CLI::App& app, const std::string& data_root, int& exit_code) {
  auto* map = app.add_subcommand("map", "visual localization maps");
  map->require_subcommand(1);
  auto options = std::make_shared<MapBuildOptions>();
  auto seed = std::make_shared<std::uint64_t>(0);
  auto seconds = std::make_shared<double>(0.0);
  auto* build = map->add_subcommand("build", "render a mapping drive and build a map (Upright-SIFT, Ceres bundle adjustment)");
  build->add_option("plan", options->plan_path, "drive plan (YAML) of the mapping drive")->required();
  build->add_option("--out", options->out_dir, "output folder (map.sqlite, map_stats.json, map_top_view.png)")->required();
  auto* seed_option = build->add_option("--seed", *seed, "seed of the drive and of the survey noise (default: the plan's)");
  auto* seconds_option = build->add_option("--seconds", *seconds, "stop the drive after this much simulated time")
                             ->check(CLI::PositiveNumber);
  build->add_option("--survey-position-sigma", options->survey_position_sigma, "survey noise per axis (m)")
      ->check(CLI::Range(0.0, 1.0));
  build->add_option("--survey-rotation-sigma-deg", options->survey_rotation_sigma_deg, "survey rotation noise (deg)")
      ->check(CLI::Range(0.0, 10.0));
  build->callback([options, seed, seconds, seed_option, seconds_option, &data_root, &exit_code]() {
    options->paths = {data_root};
    if (seed_option->count() > 0) options->seed = *seed;
    if (seconds_option->count() > 0) options->seconds = *seconds;
    exit_code = RunMapBuild(*options);
  });
}

}  // namespace trimbot::scenarios
