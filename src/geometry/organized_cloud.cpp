#include "breast_tumour_registration/geometry/organized_cloud.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
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

bool is_organized(const Points& cloud, int width, int height) {
  return width > 0 && height > 0 && cloud.rows() == static_cast<Eigen::Index>(width) * height;
}

namespace {

void require_organized(const Points& cloud, int width, int height, const std::string& what) {
  if (!is_organized(cloud, width, height))
    throw InputError(what + ": " + std::to_string(cloud.rows()) + " points are not " + std::to_string(width) + " x " +
                     std::to_string(height) + " pixels");
}

}  // namespace

Points smooth_organized(const Points& cloud, int width, int height, double sigma_pixels, double max_edge) {
  require_organized(cloud, width, height, "smoothing an organized cloud");
  if (!(sigma_pixels > 0)) return cloud;
  const int radius = static_cast<int>(std::ceil(3 * sigma_pixels));
  std::vector<double> w(static_cast<size_t>(radius) + 1);
  for (int d = 0; d <= radius; ++d) w[static_cast<size_t>(d)] = std::exp(-0.5 * d * d / (sigma_pixels * sigma_pixels));
  const double edge_sq = max_edge * max_edge;
  std::vector<char> valid(static_cast<size_t>(cloud.rows()));  // once, not per neighbour
  for (Eigen::Index i = 0; i < cloud.rows(); ++i) valid[static_cast<size_t>(i)] = cloud.row(i).allFinite();
  Points out = cloud;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const Eigen::Index i = static_cast<Eigen::Index>(v) * width + u;
      if (!valid[static_cast<size_t>(i)]) continue;
      const Eigen::RowVector3d p = cloud.row(i);
      Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
      double total = 0;
      for (int dv = -radius; dv <= radius; ++dv) {
        const int vv = v + dv;
        if (vv < 0 || vv >= height) continue;
        for (int du = -radius; du <= radius; ++du) {
          const int uu = u + du;
          if (uu < 0 || uu >= width) continue;
          const Eigen::Index j = static_cast<Eigen::Index>(vv) * width + uu;
          if (!valid[static_cast<size_t>(j)] || (cloud.row(j) - p).squaredNorm() > edge_sq) continue;
          const double wj = w[static_cast<size_t>(std::abs(du))] * w[static_cast<size_t>(std::abs(dv))];
          sum += wj * (cloud.row(j) - p);  // about p: no cancellation far from the origin
          total += wj;
        }
      }
      out.row(i) = p + sum / total;
    }
  }
  return out;
}

double estimate_organized_noise(const Points& cloud, int width, int height, double max_edge) {
  require_organized(cloud, width, height, "estimating an organized cloud's noise");
  std::vector<double> r;
  const double edge_sq = max_edge * max_edge;
  for (int v = 0; v < height; ++v)
    for (int u = 1; u + 1 < width; ++u) {
      const Eigen::Index i = static_cast<Eigen::Index>(v) * width + u;
      const auto a = cloud.row(i - 1), b = cloud.row(i), c = cloud.row(i + 1);
      if (!a.allFinite() || !b.allFinite() || !c.allFinite() || (a - b).squaredNorm() > edge_sq || (c - b).squaredNorm() > edge_sq)
        continue;
      r.push_back((b - 0.5 * (a + c)).norm());
    }
  if (r.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
  return 1.4826 * r[r.size() / 2] / std::sqrt(1.5);
}

}  // namespace btr
