#include "project_paths.h"

#include <cstdlib>

namespace trimbot::scenarios {

ProjectPaths ProjectPaths::Default() {
  if (const char* env = std::getenv("TRIMBOT_DATA_ROOT")) return {env};
  return {TRIMBOT_SOURCE_DIR};
}

}  // namespace trimbot::scenarios
