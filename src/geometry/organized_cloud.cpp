#include "breast_tumour_registration/geometry/organized_cloud.h"

#include <vector>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

SurfaceMesh triangulate_organized(const Points& cloud, int width, int height, double max_edge) {
  if (width < 2 || height < 2 || cloud.rows() != static_cast<Eigen::Index>(width) * height)
    throw InputError("the depth cloud is not organized (" + std::to_string(cloud.rows()) + " points for " +
                     std::to_string(width) + " x " + std::to_string(height) +
                     "); the surface step needs an organized depth image");
  std::vector<int> index(cloud.rows(), -1);
  std::vector<Eigen::Vector3i> faces;
  auto ok = [&](int i) { return cloud.row(i).allFinite(); };
  auto short_edge = [&](int a, int b) { return (cloud.row(a) - cloud.row(b)).norm() <= max_edge; };
  for (int v = 0; v + 1 < height; ++v)
    for (int u = 0; u + 1 < width; ++u) {
      const int a = v * width + u, b = a + 1, c = a + width, d = c + 1;
      if (ok(a) && ok(c) && ok(b) && short_edge(a, c) && short_edge(c, b) && short_edge(b, a)) faces.emplace_back(a, c, b);
      if (ok(b) && ok(c) && ok(d) && short_edge(b, c) && short_edge(c, d) && short_edge(d, b)) faces.emplace_back(b, c, d);
    }
  if (faces.empty()) throw InputError("the depth cloud yields no surface (empty, all NaN, or too sparse)");
  SurfaceMesh s;
  std::vector<Vec3> verts;
  for (auto& f : faces)
    for (int k = 0; k < 3; ++k) {
      int& id = index[f[k]];
      if (id < 0) {
        id = static_cast<int>(verts.size());
        verts.push_back(cloud.row(f[k]).transpose());
      }
      f[k] = id;
    }
  s.V.resize(verts.size(), 3);
  for (size_t i = 0; i < verts.size(); ++i) s.V.row(i) = verts[i].transpose();
  s.F.resize(faces.size(), 3);
  for (size_t i = 0; i < faces.size(); ++i) s.F.row(i) = faces[i].transpose();
  return s;
}

Points finite_points(const Points& cloud) {
  Points out(cloud.rows(), 3);
  Eigen::Index k = 0;
  for (Eigen::Index i = 0; i < cloud.rows(); ++i)
    if (cloud.row(i).allFinite()) out.row(k++) = cloud.row(i);
  out.conservativeResize(k, 3);
  return out;
}

}  // namespace btr
