#pragma once
// Top view of a visual map: its points (coloured by height) over the garden's objects, and the
// keyframe poses (PNG, written atomically).
#include <string>

#include "trimbot/garden/garden_tools.h"
#include "trimbot/visual_localization/visual_map.h"

namespace trimbot::scenarios {

void WriteMapTopView(const std::string& path, const visual_localization::VisualMap& map,
                     const garden::OccupancyMap& objects, const std::string& title);

}  // namespace trimbot::scenarios
