// What a re-mesh from a tetrahedral scene's boundary does with its chest wall: the normal angle
// across each boundary edge (within the chest wall, across its rim, on the skin), and the
// re-mesh's vertices on the chest wall at CGAL feature angles (tetrahedralize's feature_angle;
// 60 deg is the package's). A label mesh's chest wall (the muscle interface) is bumpy, and its
// sharp edges become protected features of the re-mesh. A face is the chest wall's where its
// three vertices are.
// Usage: remesh_chest_wall_features SCENE.yaml CELL_MM [ANGLE_DEG...]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/tetrahedralize.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/io/scene.h"

using namespace btr;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s SCENE.yaml CELL_MM [ANGLE_DEG...]\n", argv[0]);
    return 2;
  }
  const Scene s = load_scene(argv[1]);
  std::vector<int> index;
  const SurfaceMesh S = boundary_surface(s.prone, nullptr, &index);
  std::vector<int> wall;
  std::vector<char> on_wall(static_cast<size_t>(S.V.rows()), 0);
  for (int v : s.chest_wall)
    if (index[v] >= 0) wall.push_back(index[v]), on_wall[static_cast<size_t>(index[v])] = 1;
  std::map<std::pair<int, int>, std::vector<int>> faces_of_edge;
  std::vector<Vec3> normal(static_cast<size_t>(S.F.rows()));
  for (int f = 0; f < S.F.rows(); ++f) {
    const Vec3 a = S.V.row(S.F(f, 0)), b = S.V.row(S.F(f, 1)), c = S.V.row(S.F(f, 2));
    normal[static_cast<size_t>(f)] = (b - a).cross(c - a).normalized();
    for (int k = 0; k < 3; ++k) {
      const int i = S.F(f, k), j = S.F(f, (k + 1) % 3);
      faces_of_edge[{std::min(i, j), std::max(i, j)}].push_back(f);
    }
  }
  const char* kind[3] = {"between two wall faces", "a wall and a skin face", "between two skin faces"};
  int hist[3][7] = {};
  for (const auto& [e, fs] : faces_of_edge) {
    if (fs.size() != 2) continue;
    const double angle = std::acos(std::clamp(normal[fs[0]].dot(normal[fs[1]]), -1.0, 1.0)) * 180 / M_PI;
    auto wall_face = [&](int f) { return on_wall[S.F(f, 0)] && on_wall[S.F(f, 1)] && on_wall[S.F(f, 2)]; };
    const int walls = wall_face(fs[0]) + wall_face(fs[1]);
    const int k = walls == 2 ? 0 : walls == 1 ? 1 : 2;
    ++hist[k][std::min(6, static_cast<int>(angle / 20))];
  }
  std::printf("%ld boundary vertices, %zu on the chest wall; edges by normal angle 0-20-40-60-80-100-120-180 deg:\n",
              static_cast<long>(S.V.rows()), wall.size());
  for (int k = 0; k < 3; ++k) {
    std::printf("  %-22s", kind[k]);
    for (int b = 0; b < 7; ++b) std::printf(" %5d", hist[k][b]);
    std::printf("\n");
  }
  for (int i = 3; i < argc; ++i) {
    TetrahedralizeOptions o;
    o.cell_size = std::atof(argv[2]) * 1e-3;
    o.feature_angle = std::atof(argv[i]);
    const TetMesh m = tetrahedralize(S, o);
    const auto cw = boundary_vertices_near_region(m, S, wall, 1e-6 + o.facet_distance_ratio * o.cell_size);
    std::printf("re-mesh at %s mm, features at %s deg: %ld vertices, %ld tetrahedra, %zu on the boundary, %zu on the chest "
                "wall, mean edge %.2f mm\n",
                argv[2], argv[i], static_cast<long>(m.V.rows()), static_cast<long>(m.T.rows()), boundary_vertices(m).size(),
                cw.size(), mean_edge_length(m) * 1e3);
  }
}
