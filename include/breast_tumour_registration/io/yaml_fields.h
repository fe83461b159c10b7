// Reading fields of a YAML input file (scenes, rest models) with errors that name the file
// and the field at fault, and paths resolved relative to the file.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/base/units.h"

namespace btr {

struct YamlFields {
  std::string file;
  std::filesystem::path dir;

  /// Loads `path` as a YAML mapping; InputError for a missing file or bad syntax.
  static YAML::Node load_mapping(const std::string& path, const std::string& what) {
    YAML::Node root;
    try {
      root = YAML::LoadFile(path);
    } catch (const YAML::BadFile&) {
      throw InputError("cannot open " + what + " '" + path + "': file missing or unreadable");
    } catch (const YAML::Exception& e) {
      throw InputError(path + ": YAML syntax error: " + e.what());
    }
    if (!root.IsMap()) throw InputError(path + ": a " + what + " is a YAML mapping of fields");
    return root;
  }

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw InputError(file + ": field '" + field + "': " + what);
  }
  std::string path_of(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) fail(field, "expected a file name");
    const std::filesystem::path p(n.as<std::string>());
    return (p.is_absolute() ? p : dir / p).string();
  }
  /// A scalar as text (a name, a unit, a step); a list or mapping is an error naming the field.
  std::string text(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) fail(field, "expected a single value, not a list or mapping");
    return n.as<std::string>();
  }
  /// Every key of `root` (recursively) must be one of `valid`: dotted paths, "a[]" for the
  /// maps in a list, and "a.*" for a free-form mapping. An unknown key is an error that names
  /// the nearest valid key ("did you mean prone.cell_size_mm?").
  void check_keys(const YAML::Node& root, const std::vector<std::string>& valid) const;
  /// The file's required `units` field (m or mm): missing or unknown is an error naming it.
  LengthUnit length_unit(const YAML::Node& root) const;
  /// A scalar read as T; a list or mapping, or a value that is not a T, is an error naming the
  /// field and what was expected.
  template <class T>
  T scalar(const YAML::Node& n, const std::string& field, const std::string& expected) const {
    if (!n.IsScalar()) fail(field, "expected " + expected + ", not a list or mapping");
    try {
      return n.as<T>();
    } catch (const YAML::Exception&) {
      fail(field, "expected " + expected + ", got '" + n.as<std::string>() + "'");
    }
  }
  double number(const YAML::Node& n, const std::string& field) const { return scalar<double>(n, field, "a number"); }
  /// An integer cell label (a mesh's tissue label); a fraction or a value past 1e9 is an error
  /// naming the field.
  int cell_label(const YAML::Node& n, const std::string& field) const {
    const double l = number(n, field);
    if (l != std::round(l) || std::abs(l) > 1e9) fail(field, "expected an integer cell label");
    return static_cast<int>(l);
  }
  /// true or false (YAML's spellings of them); anything else is an error naming the field.
  bool boolean(const YAML::Node& n, const std::string& field) const { return scalar<bool>(n, field, "true or false"); }
  Vec3 vec3(const YAML::Node& n, const std::string& field) const {
    if (!n.IsSequence() || n.size() != 3) fail(field, "expected a list of 3 numbers");
    Vec3 v;
    for (int i = 0; i < 3; ++i) v[i] = number(n[i], field);
    if (!v.allFinite()) fail(field, "values must be finite");
    return v;
  }
  /// Runs a loader and prefixes its InputError with the field name.
  template <class F>
  auto load(const std::string& field, F&& f) const -> decltype(f()) {
    try {
      return f();
    } catch (const InputError& e) {
      fail(field, e.what());
    }
  }
};

}  // namespace btr
