#pragma once
// Shared helpers for the tests: project paths and a simulator configured for a test.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace trimbot::testing {

inline std::string SourcePath(const std::string& relative) { return std::string(TRIMBOT_SOURCE_DIR) + "/" + relative; }

inline std::string TempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("trimbot_test_" + name);
  std::filesystem::create_directories(dir);
  return dir.string();
}

inline std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

inline std::string WriteTempFile(const std::string& name, const std::string& contents) {
  const std::string path = TempDir("files") + "/" + name;
  std::ofstream(path) << contents;
  return path;
}

}  // namespace trimbot::testing
