#pragma once
// Bad input (a scene, URDF, calibration or scenario file) is reported with the file and the
// problem; callers at the top (the CLI) print it and exit non-zero instead of crashing.
#include <algorithm>
#include <cctype>
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

// A name that can become a file name inside an output folder: letters, digits, '_', '-', '.', not
// starting with '.' (so never "..", a path or a hidden file), 1 to 100 characters.
inline bool IsPlainName(const std::string& name) {
  return !name.empty() && name.size() <= 100 && name[0] != '.' && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

}  // namespace trimbot
