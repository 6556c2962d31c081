#pragma once
// Bad input (a scene, URDF, calibration or scenario file) is reported with the file and the
// problem; callers at the top (the CLI) print it and exit non-zero instead of crashing.
#include <stdexcept>
#include <string>

namespace trimbot {

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& problem)
      : std::runtime_error(file + ": " + problem), file_(file), problem_(problem) {}
  const std::string& file() const { return file_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string file_;
  std::string problem_;
};

}  // namespace trimbot
