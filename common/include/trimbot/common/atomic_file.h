#pragma once
// Results are written atomically (write to a temporary file beside the target, then rename), so an
// interrupted run never leaves a truncated file in place of a good one.
#include <string>

namespace trimbot {

void WriteFileAtomically(const std::string& path, const std::string& contents);

}  // namespace trimbot
