#include "trimbot/common/yaml_reader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <sstream>

namespace trimbot {
namespace {

std::string LineOf(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.line < 0) return "";
  return "line " + std::to_string(mark.line + 1) + ": ";
}

}  // namespace

YamlMap YamlMap::LoadFile(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw InputError(path, "file not found");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw InputError(path, "line " + std::to_string(e.mark.line + 1) + ": malformed YAML: " + e.msg);
  }
  if (!root.IsMap()) throw InputError(path, "expected a YAML map at the top level");
  return YamlMap(root, path, "");
}

YamlMap::YamlMap(YAML::Node node, std::string file, std::string path_in_file)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path_in_file)) {
  if (!node_.IsMap()) throw InputError(file_, LineOf(node_) + "'" + path_ + "' must be a map");
}

void YamlMap::Fail(const std::string& key, const std::string& problem) const {
  const YAML::Node value = node_[key];
  const std::string where = value.IsDefined() ? LineOf(value) : LineOf(node_);
  const std::string full_key = path_.empty() ? key : path_ + "." + key;
  throw InputError(file_, where + "key '" + full_key + "': " + problem);
}

bool YamlMap::Has(const std::string& key) const {
  read_keys_.insert(key);
  return node_[key].IsDefined() && !node_[key].IsNull();
}

YAML::Node YamlMap::Get(const std::string& key) const {
  read_keys_.insert(key);
  const YAML::Node value = node_[key];
  if (!value.IsDefined() || value.IsNull()) Fail(key, "missing");
  return value;
}

template <typename T>
T YamlMap::As(const std::string& key, const char* type_name) const {
  const YAML::Node value = Get(key);
  if (!value.IsScalar()) Fail(key, std::string("expected a ") + type_name);
  try {
    return value.as<T>();
  } catch (const YAML::Exception&) {
    Fail(key, std::string("expected a ") + type_name + ", got '" + value.Scalar() + "'");
  }
}

double YamlMap::Double(const std::string& key) const {
  const double value = As<double>(key, "number");
  // No key takes NaN or infinity: both pass every range check unnoticed (NaN < lo is false).
  if (!std::isfinite(value)) Fail(key, "must be a finite number, got '" + node_[key].Scalar() + "'");
  return value;
}
int YamlMap::Int(const std::string& key) const { return As<int>(key, "integer"); }
bool YamlMap::Bool(const std::string& key) const { return As<bool>(key, "boolean"); }
std::string YamlMap::String(const std::string& key) const { return As<std::string>(key, "string"); }

double YamlMap::Double(const std::string& key, double fallback) const { return Has(key) ? Double(key) : fallback; }
int YamlMap::Int(const std::string& key, int fallback) const { return Has(key) ? Int(key) : fallback; }
bool YamlMap::Bool(const std::string& key, bool fallback) const { return Has(key) ? Bool(key) : fallback; }
std::string YamlMap::String(const std::string& key, const std::string& fallback) const {
  return Has(key) ? String(key) : fallback;
}

double YamlMap::Number(const std::string& key, double lo, double hi, const std::string& unit) const {
  const double value = Double(key);
  const std::string suffix = unit.empty() ? "" : " " + unit;
  if (value < lo || value > hi) {
    std::ostringstream range;
    range << "must be in [" << lo << ", " << hi << "]" << suffix << ", got " << value;
    Fail(key, range.str());
  }
  return value;
}

double YamlMap::NumberOr(const std::string& key, double fallback, double lo, double hi, const std::string& unit) const {
  return Has(key) ? Number(key, lo, hi, unit) : fallback;
}

int YamlMap::Integer(const std::string& key, int lo, int hi) const {
  const int value = Int(key);
  if (value < lo || value > hi) {
    Fail(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + std::to_string(value));
  }
  return value;
}

std::vector<double> YamlMap::Doubles(const std::string& key, int expected_size) const {
  const YAML::Node value = Get(key);
  if (!value.IsSequence()) Fail(key, "expected a list of numbers");
  std::vector<double> out;
  for (const auto& item : value) {
    try {
      out.push_back(item.as<double>());
    } catch (const YAML::Exception&) {
      Fail(key, "expected a list of numbers");
    }
    if (!std::isfinite(out.back())) Fail(key, "must hold finite numbers, got '" + item.Scalar() + "'");
  }
  if (expected_size >= 0 && static_cast<int>(out.size()) != expected_size) {
    Fail(key, "expected " + std::to_string(expected_size) + " numbers, got " + std::to_string(out.size()));
  }
  return out;
}

std::vector<double> YamlMap::Numbers(const std::string& key, int expected_size, double lo, double hi,
                                     const std::string& unit) const {
  const std::vector<double> values = Doubles(key, expected_size);
  for (double value : values) {
    if (value < lo || value > hi) {
      std::ostringstream range;
      range << "each must be in [" << lo << ", " << hi << "]" << (unit.empty() ? "" : " " + unit) << ", got " << value;
      Fail(key, range.str());
    }
  }
  return values;
}

std::vector<int> YamlMap::Integers(const std::string& key, int lo, int hi) const {
  std::vector<int> values;
  for (double value : Doubles(key)) {
    if (value != std::floor(value) || value < lo || value > hi) {
      std::ostringstream expected;
      expected << "each must be a whole number in [" << lo << ", " << hi << "], got " << value;
      Fail(key, expected.str());
    }
    values.push_back(static_cast<int>(value));
  }
  return values;
}

std::string YamlMap::Name(const std::string& key) const {
  const std::string name = String(key);
  if (!IsPlainName(name))
    Fail(key, "'" + name + "' is not a plain name (letters, digits, _ - . and not starting with .)");
  return name;
}

Eigen::Vector3d YamlMap::Vector3(const std::string& key) const {
  const std::vector<double> v = Doubles(key, 3);
  return {v[0], v[1], v[2]};
}

YamlMap YamlMap::Map(const std::string& key) const {
  const YAML::Node value = Get(key);
  if (!value.IsMap()) Fail(key, "expected a map");
  return YamlMap(value, file_, path_.empty() ? key : path_ + "." + key);
}

std::vector<YamlMap> YamlMap::MapList(const std::string& key) const {
  const YAML::Node value = Get(key);
  if (!value.IsSequence()) Fail(key, "expected a list");
  std::vector<YamlMap> out;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string item_path = (path_.empty() ? key : path_ + "." + key) + "[" + std::to_string(i) + "]";
    if (!value[i].IsMap()) throw InputError(file_, LineOf(value[i]) + "'" + item_path + "' must be a map");
    out.emplace_back(value[i], file_, item_path);
  }
  return out;
}

void YamlMap::RejectUnknownKeys() const {
  std::set<std::string> seen;
  for (const auto& entry : node_) {
    if (!entry.first.IsScalar()) throw InputError(file_, LineOf(entry.first) + "keys must be plain names");
    const std::string key = entry.first.as<std::string>();
    // yaml-cpp keeps one of two equal keys silently; a repeated key is a mistake in the file.
    if (!seen.insert(key).second) {
      throw InputError(file_,
                       LineOf(entry.first) + "key '" + (path_.empty() ? key : path_ + "." + key) + "' appears twice");
    }
    if (read_keys_.count(key) == 0) {
      const std::string full_key = path_.empty() ? key : path_ + "." + key;
      throw InputError(file_, LineOf(entry.first) + "unknown key '" + full_key + "'");
    }
  }
}

}  // namespace trimbot
