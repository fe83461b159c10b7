// A small valid body on disk for the scene and model harnesses: the YAML under test may
// name these files, so that mutations reach the loaders' checks past the first missing file.
// A 40 mm box (2x2x2 cells), chest wall at z = 0, a small tumour inside, three landmarks.
#pragma once

#include <string>

#include "breast_tumour_registration/geometry/box_mesh.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/io/index_io.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "fuzz_common.h"

namespace btr::fuzz {

inline void write_fixture() {
  static bool done = false;
  if (done) return;
  done = true;
  const std::string d = scratch() + "/";
  const TetMesh box = make_box_tet_mesh(2, 2, 2, Vec3(0.04, 0.04, 0.04));
  write_tet_mesh(d + "prone.vtk", box, LengthUnit::Millimetre);
  const SurfaceMesh skin = boundary_surface(box);
  write_surface(d + "surface.obj", skin, LengthUnit::Millimetre);
  std::vector<int> wall;
  for (Eigen::Index i = 0; i < box.V.rows(); ++i)
    if (box.V(i, 2) == 0) wall.push_back(static_cast<int>(i));
  write_index_list(d + "chest_wall.txt", wall);
  // An octahedron of 5 mm around the box's centre.
  SurfaceMesh t;
  t.V.resize(6, 3);
  t.V << 0.025, 0.02, 0.02, 0.015, 0.02, 0.02, 0.02, 0.025, 0.02, 0.02, 0.015, 0.02, 0.02, 0.02, 0.025, 0.02, 0.02, 0.015;
  t.F.resize(8, 3);
  t.F << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  write_surface(d + "tumour.obj", t, LengthUnit::Millimetre);
  std::vector<LandmarkPair> lm;
  for (int v : {24, 25, 26}) {  // top face vertices (z = 40 mm)
    LandmarkPair p;
    p.prone_vertex = v;
    p.supine_point = box.V.row(v).transpose() + Vec3(0, 0, -0.002);
    lm.push_back(p);
  }
  write_landmark_pairs(d + "landmarks.csv", lm, LengthUnit::Millimetre);
  write_named_indices(d + "landmark_vertices.txt", {{"C", 24}, {"O1", 25}, {"O2", 26}});
}

}  // namespace btr::fuzz
