#include "isoflex/io/model_overrides.hpp"

#include <cctype>
#include <stdexcept>

#include "isoflex/io/model_error.hpp"

namespace isoflex::io {

namespace {

struct Step {
  std::string key;    // a map key, or
  std::string entry;  // a list entry: its index or its name
  bool list = false;
};

std::vector<Step> split_path(const std::string& key, const std::string& file) {
  const auto bad = [&](const std::string& why) { throw ModelError(file, 0, key, "--set: " + why); };
  std::vector<Step> steps;
  std::size_t i = 0;
  while (i < key.size()) {
    if (key[i] == '[') {
      const std::size_t close = key.find(']', i);
      if (close == std::string::npos || close == i + 1 || steps.empty())
        bad("a list entry is written name[INDEX] or name[NAME]");
      steps.push_back({"", key.substr(i + 1, close - i - 1), true});
      i = close + 1;
      if (i < key.size() && key[i] != '.' && key[i] != '[') bad("expected '.' after ']'");
      if (i < key.size() && key[i] == '.') ++i;
      continue;
    }
    const std::size_t end = key.find_first_of(".[", i);
    const std::string part = key.substr(i, end == std::string::npos ? end : end - i);
    if (part.empty()) bad("an empty key in the path");
    steps.push_back({part, "", false});
    i = end == std::string::npos ? key.size() : end;
    if (i < key.size() && key[i] == '.') {
      ++i;
      if (i == key.size()) bad("the path ends with '.'");
    }
  }
  if (steps.empty()) bad("no key before '='");
  return steps;
}

bool is_index(const std::string& s) {
  if (s.empty()) return false;
  for (const char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  return true;
}

}  // namespace

ModelOverride parse_model_override(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument("--set \"" + text + "\": expected KEY=VALUE, e.g. solver.dt=1e-3");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

std::vector<std::string> apply_model_overrides(YAML::Node& root,
                                               const std::vector<ModelOverride>& overrides,
                                               const std::string& file) {
  std::vector<std::string> keys;
  for (const ModelOverride& o : overrides) {
    const auto fail = [&](const std::string& why) {
      throw ModelError(file, 0, o.key, "--set: " + why);
    };
    YAML::Node value;
    try {
      value = YAML::Load(o.value);
    } catch (const YAML::ParserException& e) {
      fail("the value \"" + o.value + "\" is not YAML: " + e.msg);
    }
    if (!root.IsDefined() || root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
    const std::vector<Step> steps = split_path(o.key, file);
    // yaml-cpp nodes are handles: assigning through `at` writes into the tree.
    YAML::Node at = root;
    std::string where;
    for (std::size_t k = 0; k < steps.size(); ++k) {
      const Step& s = steps[k];
      const bool last = k + 1 == steps.size();
      if (s.list) {
        if (!at.IsSequence()) fail(where + " is not a list");
        std::size_t i = at.size();
        if (is_index(s.entry)) {
          i = std::stoul(s.entry);
          if (i >= at.size())
            fail(where + " has " + std::to_string(at.size()) + " entries, no [" + s.entry + "]");
        } else {
          for (std::size_t j = 0; j < at.size() && i == at.size(); ++j)
            if (at[j].IsMap() && at[j]["name"] && at[j]["name"].IsScalar() &&
                at[j]["name"].Scalar() == s.entry)
              i = j;
          if (i == at.size()) fail(where + " has no entry named \"" + s.entry + "\"");
        }
        where += "[" + std::to_string(i) + "]";
        if (last) {
          at[i] = value;
        } else {
          YAML::Node next = at[i];
          at.reset(next);
        }
        continue;
      }
      if (!at.IsMap()) fail((where.empty() ? "the model" : where) + " is not a map");
      where += (where.empty() ? "" : ".") + s.key;
      if (last) {
        at[s.key] = value;
      } else {
        if (!at[s.key]) at[s.key] = YAML::Node(YAML::NodeType::Map);
        YAML::Node next = at[s.key];
        at.reset(next);
      }
    }
    keys.push_back(where);
  }
  return keys;
}

}  // namespace isoflex::io
