// `trimbot garden import-csv | generate | export` (runners/garden_files.h).
#include <memory>

#include "cli/command.h"
#include "runners/garden_files.h"
#include "trimbot/common/input_error.h"

namespace trimbot::scenarios {
namespace {

struct GardenOptions {
  std::string input;
  std::string output;
  std::string name;
  double ground_z = 0.0;
  garden::GeneratorParameters generator;
  std::string size = "16x12";
  GardenExport exported;  // `garden export`'s options, as the runner takes them
};

}  // namespace

void AddGardenCommands(Commands& commands) {
  auto options = std::make_shared<GardenOptions>();
  auto* garden_cmd = commands.app().add_subcommand("garden", "import, generate and export gardens");
  garden_cmd->require_subcommand(1);

  auto* import_cmd = garden_cmd->add_subcommand("import-csv", "convert a GardenUI object map (CSV) to a garden file");
  import_cmd->add_option("csv", options->input, "object map")->required();
  import_cmd->add_option("--name", options->name, "garden name")
      ->required()
      ->check(CLI::Validator(
          [](std::string& name) { return IsPlainName(name) ? std::string() : "'" + name + "' is not a plain name"; },
          "NAME"));
  import_cmd->add_option("--ground-z", options->ground_z, "z of the ground in the CSV (Wageningen: -1.48)")
      ->check(CLI::Range(-1e4, 1e4));
  import_cmd->add_option("--out", options->output, "garden YAML (default: standard output)");
  commands.OnRun(import_cmd, [options] {
    return ImportGardenCsv(options->input, options->name, options->ground_z, options->output);
  });

  auto* generate_cmd = garden_cmd->add_subcommand("generate", "make a new garden from a seed and a few parameters");
  auto& g = options->generator;
  generate_cmd->add_option("--seed", g.seed, "seed (the same seed gives the same garden)")->required();
  generate_cmd->add_option("--size", options->size, "extent WxH in metres, e.g. 16x12");
  generate_cmd->add_option("--topiary", g.topiary, "number of topiary bushes")->check(CLI::Range(0, 1000));
  generate_cmd->add_option("--box-share", g.topiary_box_share, "share of the topiary shaped as boxes")
      ->check(CLI::Range(0.0, 1.0));
  generate_cmd->add_option("--cylinder-share", g.topiary_cylinder_share, "share of the topiary shaped as cylinders")
      ->check(CLI::Range(0.0, 1.0));
  generate_cmd->add_option("--roses", g.roses, "number of rose bushes")->check(CLI::Range(0, 1000));
  generate_cmd->add_option("--hedges", g.hedges, "number of hedges")->check(CLI::Range(0, 1000));
  generate_cmd->add_option("--trees", g.trees, "number of trees")->check(CLI::Range(0, 1000));
  generate_cmd->add_option("--obstacles", g.obstacles, "number of other obstacles")->check(CLI::Range(0, 1000));
  generate_cmd->add_option("--paths", g.paths, "number of paths (gravel, pavement, soil in turn)")
      ->check(CLI::Range(0, 100));
  generate_cmd
      ->add_option("--corridors", g.corridors, "number of hedge corridors (two parallel hedges, 1.0-1.2 m apart)")
      ->check(CLI::Range(0, 100));
  generate_cmd->add_option("--clearance", g.robot_clearance, "free space kept between objects (m)")
      ->check(CLI::Range(0.0, 10.0));
  generate_cmd->add_option("--fence-clearance", g.fence_clearance, "free space kept between objects and the edge (m)")
      ->check(CLI::Range(0.0, 10.0));
  generate_cmd->add_option("--out", options->output, "garden YAML (default: standard output)");
  commands.OnRun(generate_cmd, [options] {
    options->generator.size = ParseGardenSize(options->size);
    return GenerateGardenFile(options->generator, options->output);
  });

  auto* export_cmd = garden_cmd->add_subcommand("export", "write the occupancy map (map_server) and ground-truth PLY");
  GardenExport& exported = options->exported;
  export_cmd->add_option("garden", exported.garden, "garden name or file")->required();
  export_cmd->add_option("--out", exported.output_dir, "output folder")->required();
  export_cmd->add_option("--resolution", exported.resolution, "occupancy cell size (m)")
      ->check(CLI::Range(0.005, 10.0));
  export_cmd
      ->add_option("--clearance", exported.clearance,
                   "objects starting higher than this (tree crowns) are not obstacles (m)")
      ->check(CLI::Range(0.0, 100.0));
  export_cmd->add_option("--growth", exported.growth, "seasonal growth 0..1")->check(CLI::Range(0.0, 1.0));
  export_cmd->add_option("--points-per-m2", exported.point_density, "PLY sampling density")
      ->check(CLI::Range(1.0, 1e5));
  commands.OnRun(export_cmd, [options, &commands] { return ExportGarden(options->exported, commands.paths()); });
}

}  // namespace trimbot::scenarios
