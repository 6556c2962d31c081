// `trimbot map build | ensure | bench | retrieval-eval`: visual localization maps
// (runners/mapping.h, runners/map_cache.h, runners/localization_eval.h).
#include <memory>

#include "cli/command.h"

#include "runners/localization_eval.h"
#include "runners/map_cache.h"
#include "runners/mapping.h"
#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {
namespace {

// The options `map bench` and `map retrieval-eval` share: the map, the query drive, the stack's
// overrides; `run` is called with them once parsed.
void AddEvalCommand(Commands& commands, CLI::App* map, const std::string& name, const std::string& help,
                    int (*run)(const LocalizationEvalOptions&)) {
  auto options = std::make_shared<LocalizationEvalOptions>();
  auto seed = std::make_shared<std::uint64_t>(0);
  auto time_of_day = std::make_shared<double>(0.0);
  auto day = std::make_shared<int>(0);
  auto growth = std::make_shared<double>(0.0);
  auto* command = map->add_subcommand(name, help);
  command->add_option("map", options->map_path, "map file (map.sqlite)")->required();
  command->add_option("plan", options->drive.plan_path, "drive plan (YAML) of the query drive")->required();
  command->add_option("--out", options->out_dir, "output folder")->required();
  auto* seed_option = command->add_option("--seed", *seed, "seed of the query drive (default: the plan's + 2000)");
  auto* time_option =
      command->add_option("--time-of-day", *time_of_day, "h (default: the plan's)")->check(CLI::Range(0.0, 24.0));
  auto* day_option = command->add_option("--day-of-year", *day, "(default: the plan's)")->check(CLI::Range(1, 366));
  auto* growth_option =
      command->add_option("--growth", *growth, "0..1 (default: the plan's)")->check(CLI::Range(0.0, 1.0));
  command->add_option("--lateral-offset", options->drive.lateral_offset, "m: drive this far left of the plan's start")
      ->check(CLI::Range(-5.0, 5.0));
  command->add_option("--interval", options->drive.interval, "s between query frames")->check(CLI::Range(1e-3, 1e4));
  auto seconds = std::make_shared<double>(0.0);
  auto* seconds_option = command->add_option("--seconds", *seconds, "stop the drive after this much simulated time")
                             ->check(CLI::Range(1e-3, 1e6));
  command
      ->add_option("--resolution-scale", options->drive.resolution_scale,
                   "render at this fraction of 752x480 (default: the stack's visual_localization.image_scale)")
      ->check(CLI::Range(0.1, 1.0));
  command->add_option("--msaa", options->drive.msaa_samples, "the renderer's anti-aliasing samples (0: none)")
      ->check(CLI::Range(0, 16));
  command->add_option("--prior-sigma", options->prior_sigma, "m: noise of the position prior (truth + noise)")
      ->check(CLI::Range(0.0, 100.0));
  if (name == "retrieval-eval") {
    command->add_option("--top", options->retrieval_top, "keyframes retrieved per query frame")
        ->check(CLI::Range(1, 1000));
  }
  command->add_option("--set", options->stack_overrides,
                      "override a stack.yaml key, e.g. visual_localization.cameras=left");
  commands.OnRun(command, [=, &commands] {
    options->paths = commands.paths();
    if (seed_option->count() > 0) options->drive.seed = *seed;
    if (time_option->count() > 0) options->drive.time_of_day = *time_of_day;
    if (day_option->count() > 0) options->drive.day_of_year = *day;
    if (growth_option->count() > 0) options->drive.growth = *growth;
    if (seconds_option->count() > 0) options->drive.seconds = *seconds;
    return run(*options);
  });
}

}  // namespace

void AddMapCommands(Commands& commands) {
  auto* map = commands.app().add_subcommand("map", "visual localization maps");
  map->require_subcommand(1);
  auto options = std::make_shared<MapBuildOptions>();
  auto seed = std::make_shared<std::uint64_t>(0);
  auto seconds = std::make_shared<double>(0.0);
  auto* build =
      map->add_subcommand("build", "render a mapping drive and build a map (Upright-SIFT, Ceres bundle adjustment)");
  build
      ->add_option("plan", options->recipe.plan_path,
                   "the mapping drive: a drive plan or scenario (YAML) to drive, or a folder `trimbot drive` recorded "
                   "(its IMU, wheel ticks and saved ring frames)")
      ->required();
  build->add_option("--out", options->out_dir, "output folder (map.sqlite, map_stats.json, map_top_view.png)")
      ->required();
  auto* seed_option =
      build->add_option("--seed", *seed, "seed of the drive and of the survey noise (default: the plan's)");
  auto* seconds_option = build->add_option("--seconds", *seconds, "stop the drive after this much simulated time")
                             ->check(CLI::Range(1e-3, 1e6));
  build->add_option("--survey-position-sigma", options->recipe.survey_position_sigma, "survey noise per axis (m)")
      ->check(CLI::Range(0.0, 1.0));
  build
      ->add_option("--survey-rotation-sigma-deg", options->recipe.survey_rotation_sigma_deg,
                   "survey rotation noise (deg)")
      ->check(CLI::Range(0.0, 10.0));
  auto builder = std::make_shared<std::string>("log");
  build->add_option("--builder", *builder,
                    "log: from the robot's own odometry, loop closure and the surveyed outlines (default); "
                    "surveyed: from survey poses (truth plus the survey sigmas)");
  auto descriptor = std::make_shared<std::string>();
  build->add_option("--descriptor", *descriptor,
                    "upright_sift or sift (default: stack.yaml's visual_localization.descriptor)");
  commands.OnRun(build, [options, seed, seconds, seed_option, seconds_option, descriptor, builder, &commands] {
    try {
      if (!descriptor->empty()) options->recipe.descriptor = visual_localization::DescriptorFromString(*descriptor);
    } catch (const std::invalid_argument& e) {
      throw InputError("--descriptor", e.what());
    }
    try {
      options->recipe.builder = visual_localization::KeyframePosesFromString(*builder);
    } catch (const std::invalid_argument& e) {
      throw InputError("--builder", e.what());
    }
    options->paths = commands.paths();
    if (seed_option->count() > 0) options->recipe.seed = *seed;
    if (seconds_option->count() > 0) options->recipe.seconds = *seconds;
    return RunMapBuild(*options);
  });
  auto scenario_path = std::make_shared<std::string>();
  auto overrides = std::make_shared<std::vector<std::string>>();
  auto* ensure = map->add_subcommand(
      "ensure", "build a scenario's map (visual_map: {mapping_drive: ...}) into the map cache unless it is there");
  ensure->add_option("scenario", *scenario_path, "scenario file (YAML)")->required();
  ensure->add_option("--set", *overrides, "override a scenario key, key.path=value (repeatable)");
  commands.OnRun(ensure, [scenario_path, overrides, &commands] {
    return EnsureScenarioMap(*scenario_path, *overrides, commands.paths());
  });
  AddEvalCommand(commands, map, "bench",
                 "localize ring frames of a query drive: fixes, errors, time per stage (median) and its histogram",
                 RunLocalizationBench);
  AddEvalCommand(
      commands, map, "retrieval-eval",
      "D3.4 Table 4: top-5 retrieved keyframes with >= 50/100/200 verified matches (vocabulary, pose prior, combined)",
      RunRetrievalEval);
}

}  // namespace trimbot::scenarios
