#include "breast_tumour_registration/simulation/rest_model_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/tetrahedralize.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/io/index_io.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/io/yaml_fields.h"

namespace btr {

namespace fs = std::filesystem;

namespace {
const std::vector<std::string> kModelKeys = {"units",      "rest",       "surface",      "cell_size_mm", "chest_wall",
                                             "landmarks",  "chest_ring", "tumours.*",    "gravity",      "gravity.prone",
                                             "gravity.supine", "regions", "regions[].name", "regions[].label",
                                             "regions[].relative_stiffness", "cell_labels"};

PhantomModel load_rest_model_fields(const std::string& path) {
  const YamlFields c{path, fs::path(path).parent_path()};
  const YAML::Node root = YamlFields::load_mapping(path, "rest model");
  c.check_keys(root, kModelKeys);
  const LengthUnit unit = c.length_unit(root);
  for (const char* f : {"chest_wall", "landmarks", "tumours", "gravity"})
    if (!root[f]) c.fail(f, "missing (a rest model needs rest or surface, chest_wall, landmarks, tumours and gravity)");
  if (!root["gravity"].IsMap() || !root["gravity"]["prone"] || !root["gravity"]["supine"])
    c.fail("gravity", "expected {prone: [gx, gy, gz], supine: [gx, gy, gz]} in the model's frame [m/s^2]");
  if (root["rest"] && root["surface"]) c.fail("surface", "give rest (a tetrahedral mesh) or surface (to tetrahedralize), not both");
  if (!root["rest"] && !root["surface"]) c.fail("rest", "missing: give rest (a tetrahedral mesh) or surface (a closed surface)");
  if (root["cell_size_mm"] && !root["surface"]) c.fail("cell_size_mm", "only with surface (the size it is tetrahedralized at)");
  if (root["regions"] && !root["rest"]) c.fail("regions", "only with rest (a tetrahedral mesh whose cell labels they select)");
  if (root["cell_labels"] && !root["regions"]) c.fail("cell_labels", "only with regions (it names the cell array they select by)");

  PhantomModel m;
  m.prone_gravity = c.vec3(root["gravity"]["prone"], "gravity.prone");
  m.supine_gravity = c.vec3(root["gravity"]["supine"], "gravity.supine");
  if (!(m.prone_gravity.norm() > 0) || !(m.supine_gravity.norm() > 0)) c.fail("gravity", "must not be zero");
  // Index files refer to `rest` or, with `surface`, to the surface's vertices; the latter are
  // re-attached to the tetrahedral mesh after meshing (chest wall: boundary vertices on the
  // region; landmarks: the nearest boundary vertex).
  // Every file is read and checked before the surface (if any) is tetrahedralized: a typo in
  // the last field must not cost a meshing first (fuzz finding: 10 s of CGAL, then the error).
  SurfaceMesh input_surface;
  if (root["rest"]) {
    m.rest = c.load("rest", [&] {
      const std::string rest_path = c.path_of(root["rest"], "rest");
      TetMeshFile file = read_tet_mesh_file(rest_path, unit);
      if (root["regions"]) {
        const std::string array = root["cell_labels"] ? c.text(root["cell_labels"], "cell_labels") : "";
        m.rest_labels = cell_labels(file, array, rest_path);
      }
      TetMesh t = std::move(file.mesh);
      orient_tets_positive(t);
      validate_tet_mesh(t, "rest");
      return t;
    });
    check_length_scale(m.rest.V, unit, path, "rest");
  } else {
    input_surface = c.load("surface", [&] { return read_surface(c.path_of(root["surface"], "surface"), unit); });
    check_length_scale(input_surface.V, unit, path, "surface");
    c.load("surface", [&] {
      repair_orientation(input_surface, "surface", m.warnings);
      validate_surface(input_surface, "surface");
      return 0;
    });
  }
  const long n_in = root["rest"] ? m.rest.V.rows() : input_surface.V.rows();
  std::vector<int> wall = c.load("chest_wall", [&] {
    auto w = read_index_list(c.path_of(root["chest_wall"], "chest_wall"));
    check_index_range(w, n_in, "chest_wall");
    if (w.size() < 3) throw InputError("at least 3 fixed vertices are needed");
    return w;
  });
  const auto named = c.load("landmarks", [&] {
    auto l = read_named_indices(c.path_of(root["landmarks"], "landmarks"));
    for (const auto& [name, v] : l) check_index_range({v}, n_in, "landmark " + name);
    return l;
  });
  if (root["chest_ring"])
    m.chest_ring = c.load("chest_ring", [&] { return read_surface(c.path_of(root["chest_ring"], "chest_ring"), unit); });
  if (const YAML::Node rs = root["regions"]) {
    if (!rs.IsSequence()) c.fail("regions", "expected a list of {name, label, relative_stiffness}");
    int i = 0;
    for (const auto& r : rs) {
      const std::string f = "regions[" + std::to_string(i++) + "]";
      if (!r.IsMap() || !r["name"] || !r["label"] || !r["relative_stiffness"])
        c.fail(f, "expected {name, label, relative_stiffness}: a cell label of rest and its stiffness relative to the method's E");
      PhantomModel::MethodRegion mr;
      mr.name = c.text(r["name"], f + ".name");
      mr.label = c.cell_label(r["label"], f + ".label");
      if (std::find(m.rest_labels.begin(), m.rest_labels.end(), mr.label) == m.rest_labels.end())
        c.fail(f + ".label", "no tetrahedron of rest carries the label " + std::to_string(mr.label));
      mr.relative_stiffness = c.number(r["relative_stiffness"], f + ".relative_stiffness");
      if (!(mr.relative_stiffness > 0) || !std::isfinite(mr.relative_stiffness))
        c.fail(f + ".relative_stiffness", "must be a positive number");
      m.method_regions.push_back(mr);
    }
  }
  const YAML::Node tumours = root["tumours"];
  if (!tumours.IsMap() || tumours.size() == 0) c.fail("tumours", "expected a mapping of name: surface file");
  for (const auto& kv : tumours) {
    const std::string name = kv.first.as<std::string>(), field = "tumours." + name;
    m.tumours[name] = c.load(field, [&] {
      SurfaceMesh s = read_surface(c.path_of(kv.second, field), unit);
      repair_orientation(s, field, m.warnings);
      validate_surface(s, field);
      return s;
    });
  }
  if (!root["rest"]) {
    TetrahedralizeOptions topt;
    topt.cell_size = root["cell_size_mm"] ? mm_to_m(c.number(root["cell_size_mm"], "cell_size_mm")) : kDefaultCellSize;
    if (!(topt.cell_size > 0)) c.fail("cell_size_mm", "must be positive");
    m.rest = c.load("cell_size_mm", [&] { return tetrahedralize(input_surface, topt); });
  }
  // Index files refer to `rest` or, with `surface`, to the surface's vertices; the latter are
  // re-attached to the tetrahedral mesh (chest wall: boundary vertices on the region;
  // landmarks: the nearest boundary vertex).
  std::vector<int> boundary;  // tet vertex of every surface vertex
  m.surface = boundary_surface(m.rest, &boundary);
  const long n = m.rest.V.rows();
  m.chest_wall = root["rest"] ? wall : c.load("chest_wall", [&] {
    return boundary_vertices_near_region(m.rest, input_surface, wall, 1e-6 + 0.1 * 6e-3);
  });
  c.load("landmarks", [&] {
    std::vector<char> on_boundary(n, 0);
    for (int v : boundary) on_boundary[v] = 1;
    for (const auto& [name, v] : named) {
      int tv = v;
      if (!root["rest"]) {  // nearest boundary vertex of the tetrahedralization
        double best = 1e300;
        for (int b : boundary) {
          const double d = (m.rest.V.row(b) - input_surface.V.row(v)).squaredNorm();
          if (d < best) best = d, tv = b;
        }
      }
      if (!on_boundary[tv]) throw InputError("landmark " + name + ": vertex " + std::to_string(v) + " is not on the surface");
      m.landmarks[name] = tv;
    }
    return 0;
  });
  for (const auto& tumour : m.tumours)  // every tumour point inside the rest mesh
    c.load("tumours." + tumour.first, [&] {
      embed_points(m.rest, tumour.second.V, OutsidePolicy::Error);
      return 0;
    });
  return m;
}
}  // namespace

PhantomModel load_rest_model(const std::string& path) {
  try {
    return load_rest_model_fields(path);
  } catch (const YAML::Exception& e) {
    throw InputError(path + ": " + e.what());
  }
}

void write_rest_model(const std::string& dir, const PhantomModel& model, LengthUnit unit) {
  fs::create_directories(dir);
  auto path = [&](const std::string& f) { return (fs::path(dir) / f).string(); };
  write_tet_mesh(path("rest.vtk"), model.rest, unit, model.method_regions.empty() ? std::vector<int>{} : model.rest_labels);
  write_surface(path("rest_surface.obj"), model.surface, unit);
  write_index_list(path("chest_wall.txt"), model.chest_wall);
  std::vector<std::pair<std::string, int>> named(model.landmarks.begin(), model.landmarks.end());
  write_named_indices(path("landmark_vertices.txt"), named);
  YAML::Node y;
  y["units"] = to_string(unit);
  y["rest"] = "rest.vtk";
  y["chest_wall"] = "chest_wall.txt";
  y["landmarks"] = "landmark_vertices.txt";
  y["gravity"]["prone"] = std::vector<double>{model.prone_gravity.x(), model.prone_gravity.y(), model.prone_gravity.z()};
  y["gravity"]["supine"] = std::vector<double>{model.supine_gravity.x(), model.supine_gravity.y(), model.supine_gravity.z()};
  if (model.chest_ring.V.rows()) {
    write_surface(path("chest_ring.obj"), model.chest_ring, unit);
    y["chest_ring"] = "chest_ring.obj";
  }
  for (const auto& [name, t] : model.tumours) {
    write_surface(path("tumour_" + name + "_rest.obj"), t, unit);
    y["tumours"][name] = "tumour_" + name + "_rest.obj";
  }
  for (const auto& r : model.method_regions) {
    YAML::Node n;
    n["name"] = r.name;
    n["label"] = r.label;
    n["relative_stiffness"] = r.relative_stiffness;
    y["regions"].push_back(n);
  }
  YAML::Emitter e;
  e << y;
  std::ofstream out(path("model.yaml"));
  if (!out) throw InputError("cannot write '" + path("model.yaml") + "'");
  out << "# Rest model (input of btr_experiments --model)\n" << e.c_str() << "\n";
}

}  // namespace btr
