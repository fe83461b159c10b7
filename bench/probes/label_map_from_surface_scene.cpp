// A label map from a surface scene (e.g. SfePy's independent truth, bench/make_independent_truth.py),
// to run btr_scene_from_labels on a body whose truth our solver did not make. The prone surface is
// meshed at CELL mm only to carry the landmarks and the tissue labels: a tetrahedron is gland (2)
// where its centroid lies inside the region named `gland`, else fat (1); voxel centres inside a
// tumour's prone surface are tumour (3); a muscle slab (4) lies behind the chest wall (z = 0).
// Usage: label_map_from_surface_scene SCENE.yaml OUT_DIR [CELL_MM=3] [VOXEL_MM=1]
#include <cstdio>
#include <cstdlib>

#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/simulation/label_phantom.h"

int main(int argc, char** argv) {
  using namespace btr;
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s SCENE.yaml OUT_DIR [CELL_MM=3] [VOXEL_MM=1]\n", argv[0]);
    return 2;
  }
  const double cell = (argc > 3 ? std::atof(argv[3]) : 3.0) * 1e-3;
  const double voxel = (argc > 4 ? std::atof(argv[4]) : 1.0) * 1e-3;
  const Scene surface_scene = load_scene(argv[1]);
  Scene s = with_simulation_mesh(surface_scene, cell, 0);
  const SurfaceMesh* gland = nullptr;
  for (const auto& r : surface_scene.regions)
    if (r.name == "gland" && r.surface) gland = &*r.surface;
  s.prone_labels.assign(static_cast<size_t>(s.prone.T.rows()), 1);
  long glandular = 0;
  if (gland)
    for (Eigen::Index t = 0; t < s.prone.T.rows(); ++t)
      if (inside_closed_surface(*gland, tet_centroid(s.prone.V, s.prone.T, t))) {
        s.prone_labels[static_cast<size_t>(t)] = 2;
        ++glandular;
      }
  LabelPhantomOptions opt;
  opt.voxel_size = Vec3::Constant(voxel);
  const LabelPhantomFiles f = write_label_phantom(s, argv[2], opt);
  std::printf("%ld tetrahedra (%ld gland); label map %s: %d x %d x %d voxels\n", static_cast<long>(s.prone.T.rows()), glandular,
              f.label_map.c_str(), f.volume.nx, f.volume.ny, f.volume.nz);
  return 0;
}
