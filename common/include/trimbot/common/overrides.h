#pragma once
// Command-line overrides of YAML files: `--set key.path=value`. The value is YAML (a number, a
// boolean, a string, [a, list] or {a: map}); the override is applied to the file's tree before the
// file's own strict reader runs, so an override is checked exactly like the file (unknown key,
// wrong type, out of range -> an error naming the key).
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace trimbot {

struct Override {
  std::string key;  // dotted path, e.g. stack.navigation.follower.cruise_speed
  YAML::Node value;
  std::string text;  // as given, for records
};

// Parses "key.path=value". Throws InputError naming `--set` when it is not of that form.
Override ParseOverride(const std::string& text);
std::vector<Override> ParseOverrides(const std::vector<std::string>& texts);

// Sets each override in `root` (a map), creating the maps along its path. Throws InputError naming
// `file` and the override when a key on the path is not a map.
void ApplyOverrides(YAML::Node root, const std::vector<Override>& overrides, const std::string& file);

}  // namespace trimbot
