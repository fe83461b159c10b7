#include "breast_tumour_registration/geometry/box_mesh.h"

#include <algorithm>
#include <array>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

TetMesh make_box_tet_mesh(int nx, int ny, int nz, const Vec3& size, const Vec3& origin) {
  if (nx < 1 || ny < 1 || nz < 1 || !(size.minCoeff() > 0))
    throw InputError("box mesh needs at least one cell per axis and a positive size");
  TetMesh m;
  const auto idx = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  m.V.resize((nx + 1) * (ny + 1) * (nz + 1), 3);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        m.V.row(idx(i, j, k)) = origin.transpose() + Vec3(size.x() * i / nx, size.y() * j / ny, size.z() * k / nz).transpose();
  m.T.resize(6 * nx * ny * nz, 4);
  // Kuhn split: one tetrahedron per axis order, all sharing the cell diagonal (0,0,0)-(1,1,1).
  const std::array<std::array<int, 3>, 6> orders{{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  Eigen::Index t = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& o : orders) {
          int c[3] = {0, 0, 0};
          int v[4];
          v[0] = idx(i, j, k);
          for (int s = 0; s < 3; ++s) {
            c[o[s]] = 1;
            v[s + 1] = idx(i + c[0], j + c[1], k + c[2]);
          }
          const Vec3 a = m.V.row(v[0]);
          const double vol = (m.V.row(v[1]).transpose() - a).dot((m.V.row(v[2]).transpose() - a).cross(m.V.row(v[3]).transpose() - a));
          if (vol < 0) std::swap(v[2], v[3]);
          m.T.row(t++) << v[0], v[1], v[2], v[3];
        }
  return m;
}

}  // namespace btr
