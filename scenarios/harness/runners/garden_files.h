#pragma once
// `trimbot garden ...`: gardens imported from GardenUI object maps, generated from a seed, and
// exported as an occupancy map and a ground-truth point cloud.
#include <string>

#include "loop/setting.h"
#include "trimbot/garden/garden_tools.h"

namespace trimbot::scenarios {

// A GardenUI object map (CSV) as a garden file named `name` at `output` ("" or "-": standard output).
int ImportGardenCsv(const std::string& csv, const std::string& name, double ground_z, const std::string& output);

// "WxH" in metres, both in (2, garden::kMaxGardenExtent]; InputError naming --size otherwise.
Eigen::Vector2d ParseGardenSize(const std::string& text);
// The `trimbot garden generate` options that make the garden of `parameters` (all of them, so the
// command still makes it when the defaults change).
std::string GeneratorArguments(const garden::GeneratorParameters& parameters);
// A garden made from `parameters` at `output` ("" or "-": standard output); its first comment
// quotes the command that makes it again.
int GenerateGardenFile(const garden::GeneratorParameters& parameters, const std::string& output);

struct GardenExport {
  std::string garden;  // name or file
  std::string output_dir;
  double resolution = 0.05;      // m per occupancy cell
  double clearance = 1.0;        // m: objects starting higher (tree crowns) are not obstacles
  double growth = 0.0;           // seasonal growth 0..1 of the point cloud's foliage
  double point_density = 400.0;  // PLY points per m^2
};
// Writes <garden>_occupancy.{png,yaml} (map_server) and <garden>_ground_truth.ply.
int ExportGarden(const GardenExport& options, const ProjectPaths& paths);

}  // namespace trimbot::scenarios
