#include "breast_tumour_registration/io/yaml_fields.h"

#include <algorithm>
#include <set>

namespace btr {
namespace {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string leaf(const std::string& path) {
  const auto dot = path.find_last_of('.');
  return dot == std::string::npos ? path : path.substr(dot + 1);
}

/// The valid key nearest to an unknown one: the same name elsewhere (a misplaced key), else
/// the closest spelling when it is close.
std::string suggestion(const std::string& path, const std::vector<std::string>& valid) {
  for (const auto& v : valid)
    if (v.find('*') == std::string::npos && leaf(v) == leaf(path)) return v;
  // A key beside it that only adds a unit ("uncertainty.landmark_sd" for landmark_sd_mm).
  const auto parent = [](const std::string& p) { return p.substr(0, p.size() - leaf(p).size()); };
  for (const auto& v : valid)
    if (v.find('*') == std::string::npos && parent(v) == parent(path) && leaf(v).rfind(leaf(path) + "_", 0) == 0) return v;
  // Else the closest spelling; ties go to a key beside the unknown one.
  std::string best;
  std::size_t best_d = 4;
  bool best_beside = false;
  for (const auto& v : valid) {
    if (v.find('*') != std::string::npos) continue;
    const std::size_t d = std::min(edit_distance(path, v), edit_distance(leaf(path), leaf(v)));
    const bool beside = parent(v) == parent(path);
    if (d < best_d || (d == best_d && beside && !best_beside)) best = v, best_d = d, best_beside = beside;
  }
  return best;
}

void check_map(const YamlFields& c, const YAML::Node& node, const std::string& prefix, const std::set<std::string>& valid,
               const std::vector<std::string>& list) {
  for (const auto& kv : node) {
    if (!kv.first.IsScalar()) c.fail(prefix.empty() ? "(top level)" : prefix, "keys must be names");
    const std::string key = kv.first.as<std::string>(), path = prefix.empty() ? key : prefix + "." + key;
    if (valid.count(path + ".*")) continue;
    if (!valid.count(path)) {
      const std::string near = suggestion(path, list);
      c.fail(path, "unknown key" + (near.empty() ? std::string() : " (did you mean " + near + "?)"));
    }
    // A mapping where a value is expected is left to that field's type check.
    const bool has_children = std::any_of(list.begin(), list.end(), [&](const std::string& v) {
      return v.compare(0, path.size() + 1, path + ".") == 0;
    });
    if (kv.second.IsMap() && has_children) check_map(c, kv.second, path, valid, list);
    if (kv.second.IsSequence() && valid.count(path + "[]"))
      for (const auto& item : kv.second)
        if (item.IsMap()) check_map(c, item, path + "[]", valid, list);
  }
}

}  // namespace

LengthUnit YamlFields::length_unit(const YAML::Node& root) const {
  if (!root["units"]) fail("units", "missing: say in which unit the files' lengths are (units: mm or units: m)");
  const std::string units = text(root["units"], "units");
  return load("units", [&] { return parse_length_unit(units); });
}

void YamlFields::check_keys(const YAML::Node& root, const std::vector<std::string>& valid) const {
  check_map(*this, root, "", std::set<std::string>(valid.begin(), valid.end()), valid);
}

}  // namespace btr
