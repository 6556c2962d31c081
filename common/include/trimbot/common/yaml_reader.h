#pragma once
// Strict reading of YAML configuration: every key must be known, every value must have the right
// type, and each error names the file, the line and the key. Unknown keys are errors because a
// misspelt key silently falling back to a default is how simulations quietly test the wrong thing.
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <set>
#include <string>
#include <vector>

#include "trimbot/common/input_error.h"

namespace trimbot {

class YamlMap {
 public:
  // Loads a YAML file whose top level is a map.
  static YamlMap LoadFile(const std::string& path);
  YamlMap(YAML::Node node, std::string file, std::string path_in_file);

  bool Has(const std::string& key) const;
  // Required values. Numbers are always finite (NaN and infinity are refused).
  double Double(const std::string& key) const;
  int Int(const std::string& key) const;
  bool Bool(const std::string& key) const;
  std::string String(const std::string& key) const;
  std::vector<double> Doubles(const std::string& key, int expected_size = -1) const;
  Eigen::Vector3d Vector3(const std::string& key) const;
  YamlMap Map(const std::string& key) const;
  std::vector<YamlMap> MapList(const std::string& key) const;
  // Optional values with a default.
  double Double(const std::string& key, double fallback) const;
  int Int(const std::string& key, int fallback) const;
  bool Bool(const std::string& key, bool fallback) const;
  std::string String(const std::string& key, const std::string& fallback) const;

  // Checked numbers: finite and within [lo, hi] (`unit` is named in the message, e.g. "m").
  double Number(const std::string& key, double lo, double hi, const std::string& unit = "") const;
  double NumberOr(const std::string& key, double fallback, double lo, double hi, const std::string& unit = "") const;
  int Integer(const std::string& key, int lo, int hi) const;
  // A list of exactly `expected_size` finite numbers, each within [lo, hi].
  std::vector<double> Numbers(const std::string& key, int expected_size, double lo, double hi,
                              const std::string& unit = "") const;
  // A list of whole numbers (ids, indices), each within [lo, hi].
  std::vector<int> Integers(const std::string& key, int lo, int hi) const;
  // A name that can become a file name: letters, digits, '_', '-', '.', not starting with '.'
  // (so never "..", a path or a hidden file), at most 100 characters.
  std::string Name(const std::string& key) const;

  // Throws InputError naming the first key that was never read. Call after reading all keys.
  void RejectUnknownKeys() const;
  // Error about this map or one of its keys, with file and line.
  [[noreturn]] void Fail(const std::string& key, const std::string& problem) const;

  const std::string& file() const { return file_; }
  const YAML::Node& node() const { return node_; }

 private:
  YAML::Node Get(const std::string& key) const;
  template <typename T>
  T As(const std::string& key, const char* type_name) const;

  YAML::Node node_;
  std::string file_;
  std::string path_;  // dotted key path of this map inside the file, for messages
  mutable std::set<std::string> read_keys_;
};

}  // namespace trimbot
