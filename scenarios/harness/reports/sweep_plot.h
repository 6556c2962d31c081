#pragma once
// A metric against one swept parameter, with 95 % intervals as error bars, one line per
// combination of the other parameters (PNG, written atomically).
#include <string>
#include <vector>

namespace trimbot::scenarios {

struct SweepSeries {
  std::string label;          // the other parameters' values, e.g. "planner.iterations=3000"
  std::vector<double> value;  // per x position (NaN: no value)
  std::vector<double> low, high;
};

void WriteSweepPlot(const std::string& path, const std::string& title, const std::string& x_label,
                    const std::vector<std::string>& x_values, const std::string& y_label,
                    const std::vector<SweepSeries>& series);

}  // namespace trimbot::scenarios
