// The format of a mesh or cloud file follows its extension; each format's reader and writer is in
// formats/. The file's length unit is applied here, once.
#include "breast_tumour_registration/io/mesh_io.h"

#include <cmath>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "formats/formats.h"

namespace btr {

using namespace mesh_format;

std::string file_extension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return lower_case(path.substr(dot));
}

SurfaceMesh read_surface(const std::string& path, LengthUnit unit) {
  const std::string ext = file_extension(path);
  const double s = metres_per_unit(unit);
  if (ext == ".obj") return read_obj(path, s, true);
  if (ext == ".off") return read_off(path, s, true);
  if (ext == ".stl") return read_stl(path, s, true);
  if (ext == ".ply") return read_ply(path, s, true);
  throw InputError("'" + path + "': unknown surface format '" + ext + "' (expected .obj, .ply, .stl or .off)");
}

void write_surface(const std::string& path, const SurfaceMesh& mesh, LengthUnit unit) {
  const std::string ext = file_extension(path);
  const double inv = 1.0 / metres_per_unit(unit);
  if (ext == ".obj") return write_obj(path, mesh, inv);
  if (ext == ".off") return write_off(path, mesh, inv);
  if (ext == ".stl") return write_stl(path, mesh, inv);
  if (ext == ".ply") return write_ply(path, mesh, inv);
  throw InputError("'" + path + "': unknown surface format '" + ext + "' (expected .obj, .ply, .stl or .off)");
}

Points read_point_cloud(const std::string& path, LengthUnit unit) {
  const std::string ext = file_extension(path);
  Points P;
  if (ext == ".xyz" || ext == ".txt") {
    P = read_xyz(path, metres_per_unit(unit));
  } else if (ext == ".ply") {
    P = read_ply(path, metres_per_unit(unit), false).V;
  } else if (ext == ".obj") {
    P = read_obj(path, metres_per_unit(unit), false).V;
  } else {
    throw InputError("'" + path + "': unknown point cloud format '" + ext + "' (expected .xyz, .txt, .ply or .obj)");
  }
  if (P.rows() == 0) throw InputError(path + ": no points");
  if (!P.allFinite()) throw InputError(path + ": NaN or infinite coordinates");
  return P;
}

TetMeshFile read_tet_mesh_file(const std::string& path, LengthUnit unit) {
  const std::string ext = file_extension(path);
  const double s = metres_per_unit(unit);
  if (ext == ".vtk") return read_vtk(path, s);
  if (ext == ".mesh") return read_medit(path, s);
  throw InputError("'" + path + "': unknown tetrahedral mesh format '" + ext + "' (expected .vtk or .mesh)");
}

TetMesh read_tet_mesh(const std::string& path, LengthUnit unit) { return read_tet_mesh_file(path, unit).mesh; }

std::vector<int> cell_labels(const TetMeshFile& file, const std::string& array, const std::string& path) {
  std::string names;
  for (const auto& [n, v] : file.cell_arrays) names += (names.empty() ? "'" : ", '") + n + "'";
  if (names.empty()) names = "none";
  const std::vector<double>* values = nullptr;
  if (!array.empty()) {
    const auto it = file.cell_arrays.find(array);
    if (it == file.cell_arrays.end())
      throw InputError(path + ": no one-component cell array '" + array + "' (the file has: " + names + ")");
    values = &it->second;
  } else if (file.cell_arrays.size() == 1) {
    values = &file.cell_arrays.begin()->second;
  } else {
    throw InputError(path + ": " + (file.cell_arrays.empty() ? std::string("no cell labels (no one-component CELL_DATA array)")
                                                             : "several cell arrays (" + names + "): name the labels with prone.cell_labels"));
  }
  std::vector<int> labels(values->size());
  for (size_t t = 0; t < values->size(); ++t) {
    const double v = (*values)[t];
    if (!(std::abs(v) < 1e9) || v != std::round(v))
      throw InputError(path + ": cell label of tetrahedron " + std::to_string(t) + " is " + std::to_string(v) + ", not an integer");
    labels[t] = static_cast<int>(v);
  }
  return labels;
}

void write_tet_mesh(const std::string& path, const TetMesh& mesh, LengthUnit unit, const std::vector<int>& labels,
                    const std::string& title) {
  if (!labels.empty() && static_cast<Eigen::Index>(labels.size()) != mesh.T.rows())
    throw InputError("'" + path + "': " + std::to_string(labels.size()) + " cell labels for " + std::to_string(mesh.T.rows()) + " tetrahedra");
  const std::string ext = file_extension(path);
  const double inv = 1.0 / metres_per_unit(unit);
  if (title.find('\n') != std::string::npos) throw InputError(path + ": a VTK title is one line");
  if (ext == ".vtk") return write_vtk(path, mesh, inv, labels, title);
  if (ext == ".mesh") return write_medit(path, mesh, inv, labels);
  throw InputError("'" + path + "': unknown tetrahedral mesh format '" + ext + "' (expected .vtk or .mesh)");
}

}  // namespace btr
