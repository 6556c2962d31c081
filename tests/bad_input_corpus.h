#pragma once
// The malformed-input corpus's machinery (issue 17): cases generated from a good file by replacing
// each YAML value in turn with values no key accepts (NaN, infinities, garbage, 1e308, wrong
// types) and giving each map an unknown key; and the check that a reader refuses every case with
// an InputError naming the file and the key. Used by bad_input_test (every reader) and
// reader_input_test (the readers that are also fuzzed and built with sanitizers, tests/fuzz).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.h"
#include "trimbot/common/input_error.h"

namespace trimbot::testing {

// One malformed input: the file's text, and what its error must name besides the file.
struct BadInput {
  std::string description;
  std::string text;
  std::string must_name;
};

// A scalar's place in a YAML tree: map keys and sequence indices from the root.
struct Step {
  std::string key;  // empty for a sequence index
  std::size_t index = 0;
};
using NodePath = std::vector<Step>;

inline YAML::Node At(YAML::Node node, const NodePath& path) {
  for (const Step& step : path) node.reset(step.key.empty() ? node[step.index] : node[step.key]);
  return node;
}

// The innermost map key on the path: what the error message must name.
inline std::string KeyOf(const NodePath& path) {
  for (auto it = path.rbegin(); it != path.rend(); ++it) {
    if (!it->key.empty()) return it->key;
  }
  return "";
}

inline std::string Describe(const NodePath& path) {
  std::string text;
  for (const Step& step : path) text += step.key.empty() ? "[" + std::to_string(step.index) + "]" : "." + step.key;
  return text;
}

inline void CollectLeaves(const YAML::Node& node, NodePath& path, const std::function<bool(const NodePath&)>& wanted,
                          std::vector<NodePath>* scalars, std::vector<NodePath>* maps) {
  if (node.IsMap()) {
    if (wanted(path)) maps->push_back(path);
    for (const auto& entry : node) {
      path.push_back({entry.first.as<std::string>(), 0});
      CollectLeaves(entry.second, path, wanted, scalars, maps);
      path.pop_back();
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      path.push_back({"", i});
      CollectLeaves(node[i], path, wanted, scalars, maps);
      path.pop_back();
    }
  } else if (node.IsScalar() && wanted(path)) {
    scalars->push_back(path);
  }
}

inline bool IsNumber(const std::string& text) {
  try {
    YAML::Node(text).as<double>();
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}

inline std::string Emit(const YAML::Node& root) {
  YAML::Emitter out;
  out << root;
  return std::string(out.c_str()) + "\n";
}

// Every scalar replaced by values no key accepts, and every map given an unknown key.
inline std::vector<BadInput> MutateYaml(const std::string& good_text,
                                        const std::function<bool(const NodePath&)>& wanted) {
  const YAML::Node good = YAML::Load(good_text);
  std::vector<NodePath> scalars, maps;
  NodePath path;
  CollectLeaves(good, path, wanted, &scalars, &maps);
  std::vector<BadInput> cases;
  for (const NodePath& leaf : scalars) {
    const std::string value = At(good, leaf).Scalar();
    std::vector<std::string> replacements = {"[1, 2]", "{a: 1}"};
    if (IsNumber(value)) {
      replacements.insert(replacements.end(), {".nan", ".inf", "-.inf", "1.5abc", "1.0e308", "-1.0e308"});
    } else if (value == "true" || value == "false") {
      replacements.push_back("maybe");
    }
    for (const std::string& replacement : replacements) {
      YAML::Node copy = YAML::Clone(good);
      At(copy, leaf) = YAML::Load(replacement);
      cases.push_back({Describe(leaf) + " = " + replacement, Emit(copy), KeyOf(leaf)});
    }
  }
  for (const NodePath& map : maps) {
    YAML::Node copy = YAML::Clone(good);
    At(copy, map)["bogus_key"] = 1;
    cases.push_back({Describe(map) + ".bogus_key", Emit(copy), "bogus_key"});
  }
  return cases;
}

inline std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Writes each case to a file and checks that `load` refuses it, naming the file and the key.
// The good file the cases were made from must load: otherwise every case would be refused for
// the good file's fault and the test would prove nothing.
inline int ExpectAllRefused(const std::string& kind, const std::string& good, const std::vector<BadInput>& cases,
                            const std::function<void(const std::string&)>& load,
                            const std::string& extension = ".yaml") {
  const std::string dir = TempDir("bad_input_" + kind);
  const std::string good_path = dir + "/good" + extension;
  std::ofstream(good_path) << good;
  try {
    load(good_path);
  } catch (const std::exception& e) {
    ADD_FAILURE() << kind << ": the good file is refused: " << e.what();
    return 0;
  }
  int index = 0;
  for (const BadInput& bad : cases) {
    const std::string path = dir + "/case_" + std::to_string(index++) + extension;
    std::ofstream(path) << bad.text;
    try {
      load(path);
      ADD_FAILURE() << kind << ": accepted " << bad.description;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << kind << " " << bad.description << ": " << message;
      EXPECT_NE(message.find(bad.must_name), std::string::npos)
          << kind << " " << bad.description << ": does not name '" << bad.must_name << "': " << message;
    } catch (const std::exception& e) {
      ADD_FAILURE() << kind << " " << bad.description << ": not an input error: " << e.what();
    }
  }
  return static_cast<int>(cases.size());
}

inline const auto kEverything = [](const NodePath&) { return true; };

}  // namespace trimbot::testing
