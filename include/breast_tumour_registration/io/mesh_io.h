// Readers and writers for surface meshes (OBJ, PLY, STL, OFF) and tetrahedral
// meshes (legacy VTK unstructured grid, Medit .mesh). The length unit of the file
// is applied here, once: everything returned is in metres.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/base/units.h"

namespace btr {

/// Reads a triangle surface; the format follows the extension (.obj .ply .stl .off).
/// Polygons are fan-triangulated; STL's duplicated corners are merged.
/// Throws InputError naming the file (and line, for text formats) on any problem.
/// Only syntax and index range are checked here; see validation.h for geometry.
SurfaceMesh read_surface(const std::string& path, LengthUnit unit);
/// Writes a triangle surface; the format follows the extension (.obj .ply .stl .off).
void write_surface(const std::string& path, const SurfaceMesh& mesh, LengthUnit unit);

/// Reads the points of a cloud: .xyz / .txt (x y z per line, '#' comments), or the vertices of
/// a .ply or .obj (faces, if any, are ignored). Throws InputError for no points or NaN.
Points read_point_cloud(const std::string& path, LengthUnit unit);

/// A tetrahedral mesh file with its one-component cell data, one value per tetrahedron:
/// legacy VTK CELL_DATA SCALARS and FIELD arrays by name, Medit's element references as "ref".
struct TetMeshFile {
  TetMesh mesh;
  std::map<std::string, std::vector<double>> cell_arrays;
};

/// Reads a tetrahedral mesh from legacy VTK (.vtk, ASCII unstructured grid,
/// cell type 10) or Medit (.mesh). Non-tetrahedral cells are an error (vertex, line and
/// triangle cells are skipped, with their cell data).
TetMeshFile read_tet_mesh_file(const std::string& path, LengthUnit unit);
/// The mesh of read_tet_mesh_file.
TetMesh read_tet_mesh(const std::string& path, LengthUnit unit);
/// Integer cell labels (e.g. tissue regions) from the cell array `array`; empty `array`: the
/// file's only cell array. InputError naming `path` when it is missing, ambiguous or not integer.
std::vector<int> cell_labels(const TetMeshFile& file, const std::string& array, const std::string& path);
/// Writes legacy VTK (.vtk) or Medit (.mesh); `labels` (one per tetrahedron, or empty) go to
/// CELL_DATA "label" or the Medit element references. `title`: VTK's second line (3D Slicer
/// reads the frame from it, e.g. "... SPACE=LPS"); empty: the package's own.
void write_tet_mesh(const std::string& path, const TetMesh& mesh, LengthUnit unit, const std::vector<int>& labels = {},
                    const std::string& title = {});

/// Lower-case extension including the dot (".obj"); empty when there is none.
std::string file_extension(const std::string& path);

}  // namespace btr
