#include "breast_tumour_registration/simulation/given_truth_io.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>

#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "breast_tumour_registration/io/yaml_fields.h"

namespace btr {

namespace fs = std::filesystem;

namespace {
const std::vector<std::string> kTruthKeys = {"units",
                                             "configurations",
                                             "configurations[]",
                                             "configurations[].youngs_modulus",
                                             "configurations[].prone",
                                             "configurations[].supine",
                                             "configurations[].tumours.*"};

std::array<int, 4> sorted_tet(const TetMesh& m, long t) {
  std::array<int, 4> v{m.T(t, 0), m.T(t, 1), m.T(t, 2), m.T(t, 3)};
  std::sort(v.begin(), v.end());
  return v;
}

/// The vertices of a volume that must be `model`'s mesh, deformed.
Points deformed_vertices(const std::string& file, LengthUnit unit, const PhantomModel& model) {
  const TetMesh m = read_tet_mesh(file, unit);
  if (m.V.rows() != model.rest.V.rows() || m.T.rows() != model.rest.T.rows())
    throw InputError(std::to_string(m.V.rows()) + " vertices and " + std::to_string(m.T.rows()) +
                     " tetrahedra, the rest model has " + std::to_string(model.rest.V.rows()) + " and " +
                     std::to_string(model.rest.T.rows()) + ": a configuration is the rest mesh with its vertices moved");
  for (long t = 0; t < m.T.rows(); ++t)
    if (sorted_tet(m, t) != sorted_tet(model.rest, t))
      throw InputError("tetrahedron " + std::to_string(t) + " joins other vertices than the rest model's");
  if (!m.V.allFinite()) throw InputError("a vertex position is not finite");
  return m.V;
}

std::map<double, PhantomConfigurations> load_fields(const std::string& path, const PhantomModel& model) {
  const YamlFields c{path, fs::path(path).parent_path()};
  const YAML::Node root = YamlFields::load_mapping(path, "truth file");
  c.check_keys(root, kTruthKeys);
  const LengthUnit unit = c.length_unit(root);
  const YAML::Node list = root["configurations"];
  if (!list || !list.IsSequence() || list.size() == 0)
    c.fail("configurations", "expected a list of {youngs_modulus, prone, supine, tumours}");
  std::map<double, PhantomConfigurations> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node item = list[i];
    const std::string at = "configurations[" + std::to_string(i) + "]";
    if (!item.IsMap()) c.fail(at, "expected a mapping {youngs_modulus, prone, supine, tumours}");
    for (const char* f : {"youngs_modulus", "prone", "supine", "tumours"})
      if (!item[f]) c.fail(at + "." + f, "missing");
    const double e = c.number(item["youngs_modulus"], at + ".youngs_modulus");
    if (!(e > 0) || !std::isfinite(e)) c.fail(at + ".youngs_modulus", "must be a positive number of pascals");
    if (out.count(e)) c.fail(at + ".youngs_modulus", "given twice: one configuration per modulus");
    PhantomConfigurations conf;
    for (const char* pose : {"prone", "supine"}) {
      const std::string field = at + "." + pose;
      (pose[0] == 'p' ? conf.prone : conf.supine) =
          c.load(field, [&] { return deformed_vertices(c.path_of(item[pose], field), unit, model); });
    }
    const YAML::Node tumours = item["tumours"];
    if (!tumours.IsMap()) c.fail(at + ".tumours", "expected a mapping name: {prone: file, supine: file}");
    for (const auto& kv : tumours) {
      const std::string name = kv.first.as<std::string>(), field = at + ".tumours." + name;
      if (!model.tumours.count(name)) c.fail(field, "the rest model has no tumour of that name");
      if (!kv.second.IsMap() || kv.second.size() != 2 || !kv.second["prone"] || !kv.second["supine"])
        c.fail(field, "expected {prone: file, supine: file}");
      for (const char* pose : {"prone", "supine"}) {
        SurfaceMesh s = c.load(field + "." + pose, [&] {
          SurfaceMesh m = read_surface(c.path_of(kv.second[pose], field + "." + pose), unit);
          validate_surface(m, field + "." + pose);
          return m;
        });
        (pose[0] == 'p' ? conf.tumour_prone : conf.tumour_supine)[name] = std::move(s);
      }
    }
    for (const auto& [name, t] : model.tumours)
      if (!conf.tumour_prone.count(name)) c.fail(at + ".tumours", "tumour '" + name + "' of the rest model is missing");
    out.emplace(e, std::move(conf));
  }
  return out;
}
}  // namespace

std::map<double, PhantomConfigurations> load_given_configurations(const std::string& path, const PhantomModel& model) {
  try {
    return load_fields(path, model);
  } catch (const YAML::Exception& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace btr
