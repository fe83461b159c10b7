#include "breast_tumour_registration/io/label_scene.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/io/index_io.h"
#include "breast_tumour_registration/io/markups_io.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "breast_tumour_registration/io/yaml_fields.h"

namespace btr {
namespace fs = std::filesystem;

namespace {
const std::vector<std::string> kTableKeys = {"fat",     "gland",        "tumour",          "muscle",        "skin", "ignore",
                                             "stiffness", "stiffness.gland", "stiffness.tumour", "stiffness.skin"};

// A label value, or a segment name of the volume.
int label_value(const YamlFields& c, const YAML::Node& n, const std::string& field, const LabelVolume& v) {
  const std::string s = c.text(n, field);
  if (const auto l = parse_integer(s)) {
    if (*l < 1 || *l > 255) c.fail(field, "label " + s + " is outside 1 to 255");
    return *l;
  }
  for (const auto& [l, name] : v.names)
    if (lower_case(name) == lower_case(s)) return l;
  std::string known;
  for (const auto& [l, name] : v.names) known += (known.empty() ? "" : ", ") + name;
  c.fail(field, "'" + s + "' is neither a label value nor a segment name of the label map" +
                    (known.empty() ? std::string(" (it has no segment names)") : " (segments: " + known + ")"));
}

std::vector<int> label_list(const YamlFields& c, const YAML::Node& n, const std::string& field, const LabelVolume& v) {
  std::vector<int> out;
  if (n.IsSequence())
    for (const auto& e : n) out.push_back(label_value(c, e, field, v));
  else if (n.IsScalar() && lower_case(n.as<std::string>()) != "none")
    out.push_back(label_value(c, n, field, v));
  return out;
}
}  // namespace

LabelTable read_label_table(const std::string& path, const LabelVolume& v) {
  const YamlFields c{path, fs::path(path).parent_path()};
  const YAML::Node root = YamlFields::load_mapping(path, "label table");
  c.check_keys(root, kTableKeys);
  LabelTable t;
  if (root["fat"]) t.fat = label_list(c, root["fat"], "fat", v);
  if (root["gland"]) t.gland = label_list(c, root["gland"], "gland", v);
  if (root["tumour"]) t.tumour = label_list(c, root["tumour"], "tumour", v);
  if (root["skin"]) t.skin = label_list(c, root["skin"], "skin", v);
  if (root["ignore"]) t.ignore = label_list(c, root["ignore"], "ignore", v);
  if (root["muscle"]) {
    const auto m = label_list(c, root["muscle"], "muscle", v);
    if (m.size() > 1) c.fail("muscle", "give one label (or none)");
    t.muscle = m.empty() ? -1 : m[0];
  }
  auto ratio = [&](const char* key, double& x) {
    if (root["stiffness"] && root["stiffness"][key]) {
      x = c.number(root["stiffness"][key], std::string("stiffness.") + key);
      if (!(x > 0) || !std::isfinite(x)) c.fail(std::string("stiffness.") + key, "must be positive (times the fat's Young's modulus)");
    }
  };
  ratio("gland", t.gland_stiffness);
  ratio("tumour", t.tumour_stiffness);
  ratio("skin", t.skin_stiffness);
  check_label_table(t, v, path);
  return t;
}

void check_label_table(const LabelTable& t, const LabelVolume& v, const std::string& source) {
  std::map<int, std::string> role;
  auto assign = [&](const std::vector<int>& labels, const char* name) {
    for (int l : labels) {
      auto [it, fresh] = role.emplace(l, name);
      if (!fresh) throw InputError(source + ": label " + std::to_string(l) + " is both " + it->second + " and " + name);
    }
  };
  assign(t.fat, "fat");
  assign(t.gland, "gland");
  assign(t.tumour, "tumour");
  assign(t.skin, "skin");
  assign(t.ignore, "ignore");
  if (t.muscle > 0) assign({t.muscle}, "muscle");
  const std::vector<long> hist = label_histogram(v);
  std::string unknown;
  for (int l = 1; l < 256; ++l)
    if (hist[l] > 0 && !role.count(l)) {
      auto it = v.names.find(l);
      unknown += (unknown.empty() ? "" : ", ") + std::to_string(l) + (it != v.names.end() ? " ('" + it->second + "')" : "") + ": " +
                 std::to_string(hist[l]) + " voxels";
    }
  if (!unknown.empty())
    throw InputError(source + ": labels not in the label table: " + unknown +
                     "; give each a tissue (fat, gland, tumour, skin, muscle) or list it under ignore");
  long tissue = 0;
  for (const auto* list : {&t.fat, &t.gland, &t.skin, &t.tumour})
    for (int l : *list) tissue += hist[l];
  if (tissue == 0) throw InputError(source + ": no voxel carries a fat, gland, skin or tumour label; check the label table");
}

LabelSceneSummary write_scene_from_labels(const std::string& dir, const LabelVolume& v, const LabelTable& table,
                                          const LabelSceneOptions& opt) {
  if (opt.prone_landmarks.empty() != opt.supine_landmarks.empty())
    throw InputError("landmarks: give both the prone and the supine point list, or neither");
  if (!opt.supine_surface.empty() && !opt.supine_cloud.empty())
    throw InputError("supine: give a surface or a cloud, not both");
  const LengthUnit supine_units = parse_length_unit(opt.supine_units);
  // Read the supine side before the (slow) meshing, so that a bad file fails fast.
  std::vector<NamedPoint> prone_pts, supine_pts;
  if (!opt.prone_landmarks.empty()) {
    prone_pts = read_markups(opt.prone_landmarks, PatientFrame::RAS);
    supine_pts = read_markups(opt.supine_landmarks, PatientFrame::RAS);
    if (match_by_label(prone_pts, supine_pts).labels.empty())
      throw InputError(opt.prone_landmarks + " and " + opt.supine_landmarks + ": no label is in both point lists");
  }
  std::optional<SurfaceMesh> supine_surface;
  std::optional<Points> supine_cloud;
  if (!opt.supine_surface.empty()) supine_surface = read_surface(opt.supine_surface, supine_units);
  if (!opt.supine_cloud.empty()) supine_cloud = read_point_cloud(opt.supine_cloud, supine_units);

  check_label_table(table, v, opt.mesh.source);
  LabelMeshOptions mo = opt.mesh;
  mo.tissue.clear();
  for (const auto* list : {&table.fat, &table.gland, &table.skin}) mo.tissue.insert(list->begin(), list->end());
  mo.tumour = std::set<int>(table.tumour.begin(), table.tumour.end());
  mo.muscle = table.muscle;
  const LabelledTetMesh m = mesh_label_volume(v, mo);

  fs::create_directories(dir);
  auto path = [&](const std::string& f) { return (fs::path(dir) / f).string(); };
  LabelSceneSummary sum;
  sum.tetrahedra = m.mesh.T.rows();
  sum.vertices = m.mesh.V.rows();
  sum.chest_wall_vertices = static_cast<long>(m.chest_wall.size());
  sum.chest_wall_from_muscle = m.chest_wall_from_muscle;
  sum.mesh_seconds = m.seconds;
  const LengthUnit mmu = LengthUnit::Millimetre;
  write_tet_mesh(path("prone.vtk"), m.mesh, mmu, m.labels);
  write_index_list(path("chest_wall.txt"), m.chest_wall);

  YAML::Node scene;
  scene["units"] = "mm";
  scene["patient_frame"] = "RAS";
  scene["frame"] = "RAS patient coordinates of the label map (+x right, +y anterior, +z superior)";
  scene["prone"]["tet_mesh"] = "prone.vtk";
  scene["prone"]["cell_size_mm"] = opt.mesh.cell_size * 1e3;  // made at: a call at this size keeps it
  scene["chest_wall"] = "chest_wall.txt";
  YAML::Node tumours;
  std::vector<Vec3> truth_centroids;
  for (const auto& t : opt.truth) truth_centroids.push_back(volume_centroid(read_surface(t.prone, mmu)));
  for (size_t i = 0; i < m.tumours.size(); ++i) {
    std::string name = "tumour_" + std::to_string(i + 1);
    const Vec3 c = volume_centroid(m.tumours[i].surface);
    int match = -1;
    for (size_t k = 0; k < truth_centroids.size(); ++k)
      if ((truth_centroids[k] - c).norm() < kTruthMatchDistance &&
          (match < 0 || (truth_centroids[k] - c).norm() < (truth_centroids[match] - c).norm()))
        match = static_cast<int>(k);
    if (match >= 0) name = opt.truth[match].name;
    else if (!opt.truth.empty()) sum.warnings.push_back(name + ": no known tumour within 5 mm of its centroid");
    write_surface(path(name + "_prone.obj"), m.tumours[i].surface, mmu);
    YAML::Node n;
    n["name"] = name;
    n["prone"] = name + "_prone.obj";
    if (match >= 0) {
      write_surface(path(name + "_supine_truth.obj"), read_surface(opt.truth[match].supine, mmu), mmu);
      n["supine_ground_truth"] = name + "_supine_truth.obj";
    }
    tumours.push_back(n);
    sum.tumour_centroids.emplace_back(name, c);
  }
  if (m.tumours.empty()) sum.warnings.push_back("no tumour label: the scene has no tumour to carry");
  if (tumours.size()) scene["tumours"] = tumours;
  auto copy = [&](const std::string& from, const std::string& as) {
    fs::copy_file(from, path(as), fs::copy_options::overwrite_existing);
    return as;
  };
  auto markups_ext = [](const std::string& f) {
    return ends_with(lower_case(f), ".mrk.json") ? std::string(".mrk.json") : fs::path(f).extension().string();
  };
  if (!prone_pts.empty()) {
    scene["landmarks"]["prone"] = copy(opt.prone_landmarks, "prone_landmarks" + markups_ext(opt.prone_landmarks));
    scene["landmarks"]["supine"] = copy(opt.supine_landmarks, "supine_landmarks" + markups_ext(opt.supine_landmarks));
  }
  if (supine_surface || supine_cloud) {
    // Supine files in another unit are rewritten in millimetres, the scene's unit.
    if (supine_surface) {
      const std::string as = "supine_surface" + file_extension(opt.supine_surface);
      write_surface(path(as), *supine_surface, mmu);
      scene["supine"]["surface"] = as;
    } else {
      const std::string as = "supine_cloud.xyz";
      const Points& c = *supine_cloud;
      std::ofstream out(path(as));
      for (Eigen::Index i = 0; i < c.rows(); ++i) out << c(i, 0) * 1e3 << " " << c(i, 1) * 1e3 << " " << c(i, 2) * 1e3 << "\n";
      scene["supine"]["cloud"] = as;
    }
  }
  scene["material"]["youngs_modulus"] = opt.youngs_modulus;
  scene["material"]["poisson_ratio"] = opt.poisson_ratio;
  scene["material"]["density"] = 1000.0;
  YAML::Node regions;
  // Every tissue other than fat is a region, its stiffness 1 or not: the scene then carries the
  // labels (the outputs to Slicer keep them).
  auto region = [&](const char* name, const std::vector<int>& labels, double ratio) {
    for (int l : labels) {
      YAML::Node r;
      r["name"] = std::string(name) + (labels.size() > 1 ? "_" + std::to_string(l) : "");
      r["label"] = l;
      r["relative_stiffness"] = ratio;
      regions.push_back(r);
    }
  };
  const std::set<int> meshed_labels(m.labels.begin(), m.labels.end());
  auto present = [&](const std::vector<int>& ls) {  // the labels some tetrahedron carries
    std::vector<int> out;
    for (int l : ls)
      if (meshed_labels.count(l)) out.push_back(l);
    return out;
  };
  region("gland", present(table.gland), table.gland_stiffness);
  region("skin", present(table.skin), table.skin_stiffness);
  region("tumour", present(table.tumour), table.tumour_stiffness);
  if (regions.size()) scene["regions"] = regions;
  const Vec3 posterior = opt.mesh.posterior.normalized();
  const Vec3 g = 9.81 * posterior;
  scene["gravity"] = std::vector<double>{g[0], g[1], g[2]};
  if (opt.prone_image) scene["prone_gravity"] = std::vector<double>{-g[0], -g[1], -g[2]};
  scene["steps"] = "auto";
  scene["preset"] = opt.preset;
  scene["generator"]["label_map"] = opt.mesh.source;
  scene["generator"]["cell_size_mm"] = opt.mesh.cell_size * 1e3;
  scene["generator"]["tumour_facet_size_mm"] = opt.mesh.tumour_facet_size * 1e3;
  scene["generator"]["chest_wall"] = m.chest_wall_from_muscle ? "interface with the muscle label" : "posterior-most skin";
  YAML::Emitter y;
  y << scene;
  std::ofstream(path("scene.yaml")) << "# Scene meshed from a segmented prone image by btr_scene_from_labels\n" << y.c_str() << "\n";
  return sum;
}

}  // namespace btr
