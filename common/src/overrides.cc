#include "trimbot/common/overrides.h"

#include <sstream>

#include "trimbot/common/input_error.h"

namespace trimbot {

Override ParseOverride(const std::string& text) {
  const auto equals = text.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw InputError("--set", "'" + text + "' is not key.path=value");
  }
  Override o;
  o.key = text.substr(0, equals);
  o.text = text;
  std::istringstream parts(o.key);
  for (std::string part; std::getline(parts, part, '.');) {
    if (part.empty()) throw InputError("--set", "'" + text + "': empty key in the path '" + o.key + "'");
  }
  if (o.key.back() == '.') throw InputError("--set", "'" + text + "': empty key in the path '" + o.key + "'");
  const std::string value = text.substr(equals + 1);
  if (value.empty()) throw InputError("--set", "'" + text + "': no value");
  try {
    o.value = YAML::Load(value);
    // A scalar without the position it had in its one-line document: messages must not point at
    // "line 1" of the scenario file for a value that came from the command line.
    if (o.value.IsScalar()) o.value = YAML::Node(o.value.Scalar());
  } catch (const YAML::Exception& e) {
    throw InputError("--set", "'" + text + "': the value is not YAML: " + e.msg);
  }
  return o;
}

std::vector<Override> ParseOverrides(const std::vector<std::string>& texts) {
  std::vector<Override> overrides;
  for (const auto& text : texts) overrides.push_back(ParseOverride(text));
  return overrides;
}

void ApplyOverrides(YAML::Node root, const std::vector<Override>& overrides, const std::string& file) {
  for (const Override& o : overrides) {
    std::vector<std::string> path;
    std::istringstream parts(o.key);
    for (std::string part; std::getline(parts, part, '.');) path.push_back(part);
    YAML::Node node = root;
    std::string walked;
    for (std::size_t i = 0; i + 1 < path.size(); ++i) {
      walked += (walked.empty() ? "" : ".") + path[i];
      const YAML::Node child = node[path[i]];
      if (!child.IsDefined() || child.IsNull()) {
        node[path[i]] = YAML::Node(YAML::NodeType::Map);
      } else if (!child.IsMap()) {
        throw InputError(file, "--set " + o.text + ": key '" + walked + "' is not a map");
      }
      const YAML::Node next = node[path[i]];
      node.reset(next);  // reset, not '=': assignment would overwrite the node's content
    }
    node[path.back()] = o.value;
  }
}

}  // namespace trimbot
