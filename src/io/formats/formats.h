// One reader and one writer per mesh format, internal to the io layer; mesh_io.cpp picks one by
// the file's extension. `scale` converts the file's unit to metres on reading, `inv` back on
// writing. Every reader throws InputError naming the file (and line, for text formats).
#pragma once

#include <string>
#include <vector>

#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/io/mesh_io.h"

namespace btr {
namespace mesh_format {

// Surfaces; require_faces is false only when a point cloud is read from a mesh format.
SurfaceMesh read_obj(const std::string& path, double scale, bool require_faces);
void write_obj(const std::string& path, const SurfaceMesh& m, double inv);
SurfaceMesh read_off(const std::string& path, double scale, bool require_faces);
void write_off(const std::string& path, const SurfaceMesh& m, double inv);
SurfaceMesh read_stl(const std::string& path, double scale, bool require_faces);
void write_stl(const std::string& path, const SurfaceMesh& m, double inv);
SurfaceMesh read_ply(const std::string& path, double scale, bool require_faces);
void write_ply(const std::string& path, const SurfaceMesh& m, double inv);

// Point clouds: x y z per line, '#' comments.
Points read_xyz(const std::string& path, double scale);

// Tetrahedral meshes with their cell data.
TetMeshFile read_vtk(const std::string& path, double scale);
void write_vtk(const std::string& path, const TetMesh& m, double inv, const std::vector<int>& labels,
               const std::string& title);
TetMeshFile read_medit(const std::string& path, double scale);
void write_medit(const std::string& path, const TetMesh& m, double inv, const std::vector<int>& labels);

}  // namespace mesh_format
}  // namespace btr
