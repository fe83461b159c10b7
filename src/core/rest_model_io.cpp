#include "breast_tumour_registration/core/rest_model_io.h"

#include <filesystem>
#include <fstream>

#include "breast_tumour_registration/core/embedding.h"
#include "breast_tumour_registration/core/index_io.h"
#include "breast_tumour_registration/core/mesh_io.h"
#include "breast_tumour_registration/core/surface_attachment.h"
#include "breast_tumour_registration/core/validation.h"
#include "breast_tumour_registration/core/yaml_fields.h"

namespace btr {

namespace fs = std::filesystem;

PhantomModel load_rest_model(const std::string& path) {
  const YamlFields c{path, fs::path(path).parent_path()};
  const YAML::Node root = YamlFields::load_mapping(path, "rest model");
  LengthUnit unit = LengthUnit::Millimetre;
  if (root["units"]) unit = c.load("units", [&] { return parse_length_unit(root["units"].as<std::string>()); });
  for (const char* f : {"rest", "chest_wall", "landmarks", "tumours"})
    if (!root[f]) c.fail(f, "missing (a rest model needs rest, chest_wall, landmarks and tumours)");

  PhantomModel m;
  m.rest = c.load("rest", [&] {
    TetMesh t = read_tet_mesh(c.path_of(root["rest"], "rest"), unit);
    orient_tets_positive(t);
    validate_tet_mesh(t, "rest");
    return t;
  });
  std::vector<int> boundary;  // tet vertex of every surface vertex
  m.surface = boundary_surface(m.rest, &boundary);
  const long n = m.rest.V.rows();
  m.chest_wall = c.load("chest_wall", [&] {
    auto w = read_index_list(c.path_of(root["chest_wall"], "chest_wall"));
    check_index_range(w, n, "chest_wall");
    if (w.size() < 3) throw InputError("at least 3 fixed vertices are needed");
    return w;
  });
  c.load("landmarks", [&] {
    std::vector<char> on_boundary(n, 0);
    for (int v : boundary) on_boundary[v] = 1;
    for (const auto& [name, v] : read_named_indices(c.path_of(root["landmarks"], "landmarks"))) {
      check_index_range({v}, n, "landmark " + name);
      if (!on_boundary[v]) throw InputError("landmark " + name + ": vertex " + std::to_string(v) + " is not on the surface");
      m.landmarks[name] = v;
    }
    return 0;
  });
  if (root["chest_ring"])
    m.chest_ring = c.load("chest_ring", [&] { return read_surface(c.path_of(root["chest_ring"], "chest_ring"), unit); });
  const YAML::Node tumours = root["tumours"];
  if (!tumours.IsMap() || tumours.size() == 0) c.fail("tumours", "expected a mapping of name: surface file");
  for (const auto& kv : tumours) {
    const std::string name = kv.first.as<std::string>(), field = "tumours." + name;
    SurfaceMesh t = c.load(field, [&] {
      SurfaceMesh s = read_surface(c.path_of(kv.second, field), unit);
      validate_surface(s, field);
      embed_points(m.rest, s.V, OutsidePolicy::Error);  // every tumour point inside the rest mesh
      return s;
    });
    m.tumours[name] = std::move(t);
  }
  return m;
}

void write_rest_model(const std::string& dir, const PhantomModel& model, LengthUnit unit) {
  fs::create_directories(dir);
  auto path = [&](const std::string& f) { return (fs::path(dir) / f).string(); };
  write_tet_mesh(path("rest.vtk"), model.rest, unit);
  write_surface(path("rest_surface.obj"), model.surface, unit);
  write_index_list(path("chest_wall.txt"), model.chest_wall);
  std::vector<std::pair<std::string, int>> named(model.landmarks.begin(), model.landmarks.end());
  write_named_indices(path("landmark_vertices.txt"), named);
  YAML::Node y;
  y["units"] = to_string(unit);
  y["rest"] = "rest.vtk";
  y["chest_wall"] = "chest_wall.txt";
  y["landmarks"] = "landmark_vertices.txt";
  if (model.chest_ring.V.rows()) {
    write_surface(path("chest_ring.obj"), model.chest_ring, unit);
    y["chest_ring"] = "chest_ring.obj";
  }
  for (const auto& [name, t] : model.tumours) {
    write_surface(path("tumour_" + name + "_rest.obj"), t, unit);
    y["tumours"][name] = "tumour_" + name + "_rest.obj";
  }
  YAML::Emitter e;
  e << y;
  std::ofstream out(path("model.yaml"));
  if (!out) throw InputError("cannot write '" + path("model.yaml") + "'");
  out << "# Rest model (input of btr_experiments --model)\n" << e.c_str() << "\n";
}

}  // namespace btr
