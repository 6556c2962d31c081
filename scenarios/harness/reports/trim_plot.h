#pragma once
// Pictures of a trim: the foliage's distance to its target over the whole surface before and after
// (a map of the columns, rows the polar angle from the top, columns the azimuth from the target's x
// axis), beside rendered views of the bush.
#include <opencv2/core.hpp>
#include <string>

#include "trimbot/garden/foliage.h"

namespace trimbot::scenarios {

// Blue: cut more than 2 cm into the target; green: within 2 cm; yellow to red: overgrowth up to
// 10 cm and beyond. Before on the left, after on the right, with a legend.
void WriteTrimDistanceMap(const std::string& path, const garden::Foliage& before, const garden::Foliage& after);

// Two rendered views side by side with a caption each (before, after).
void WriteBeforeAfter(const std::string& path, const cv::Mat& before, const cv::Mat& after);

}  // namespace trimbot::scenarios
