#include "breast_tumour_registration/geometry/shapes.h"

#include <cmath>
#include <map>
#include <vector>

#include "breast_tumour_registration/base/errors.h"

namespace btr {
namespace {

// Triangulates the band between two concentric rings given as vertex index lists whose
// angles are uniform (2 pi i / n); triangles are counter-clockwise seen from +z when the
// first ring is the inner one.
void zip_rings(const std::vector<int>& A, const std::vector<int>& B, std::vector<Eigen::Vector3i>& tris) {
  const size_t na = A.size(), nb = B.size();
  if (na == 1) {
    for (size_t j = 0; j < nb; ++j) tris.emplace_back(A[0], B[j], B[(j + 1) % nb]);
    return;
  }
  size_t i = 0, j = 0;
  while (i < na || j < nb) {
    const double next_a = static_cast<double>(i + 1) / na, next_b = static_cast<double>(j + 1) / nb;
    if (j < nb && (i >= na || next_b <= next_a)) {
      tris.emplace_back(A[i % na], B[j % nb], B[(j + 1) % nb]);
      ++j;
    } else {
      tris.emplace_back(A[i % na], B[j % nb], A[(i + 1) % na]);
      ++i;
    }
  }
}

SurfaceMesh assemble(const std::vector<Vec3>& v, const std::vector<Eigen::Vector3i>& f) {
  SurfaceMesh m;
  m.V.resize(v.size(), 3);
  for (size_t i = 0; i < v.size(); ++i) m.V.row(i) = v[i].transpose();
  m.F.resize(f.size(), 3);
  for (size_t i = 0; i < f.size(); ++i) m.F.row(i) = f[i].transpose();
  return m;
}

}  // namespace

Vec3 half_ellipsoid_point(double a, double b, double c, double theta, double phi) {
  return Vec3(a * std::sin(theta) * std::cos(phi), b * std::sin(theta) * std::sin(phi), c * std::cos(theta));
}

SurfaceMesh make_half_ellipsoid(double a, double b, double c, int rings) {
  if (!(a > 0 && b > 0 && c > 0) || rings < 2) throw InputError("half ellipsoid needs positive semi-axes and >= 2 rings");
  std::vector<Vec3> v;
  std::vector<Eigen::Vector3i> f;
  const int n = rings;
  // Dome: apex, then rings k = 1..n at polar angle (k/n) pi/2; ring n is the rim (z = 0).
  std::vector<std::vector<int>> dome(n + 1);
  dome[0] = {0};
  v.push_back(Vec3(0, 0, c));
  for (int k = 1; k <= n; ++k)
    for (int j = 0; j < 6 * k; ++j) {
      const double theta = (k == n) ? M_PI / 2 : (M_PI / 2) * k / n;
      Vec3 p = half_ellipsoid_point(a, b, c, theta, 2 * M_PI * j / (6 * k));
      if (k == n) p.z() = 0.0;
      dome[k].push_back(static_cast<int>(v.size()));
      v.push_back(p);
    }
  for (int k = 1; k <= n; ++k) zip_rings(dome[k - 1], dome[k], f);
  // Base: centre, rings 1..n-1 at radius fraction k/n, closing onto the rim; reversed orientation (-z).
  std::vector<std::vector<int>> base(n + 1);
  base[0] = {static_cast<int>(v.size())};
  v.push_back(Vec3(0, 0, 0));
  for (int k = 1; k < n; ++k)
    for (int j = 0; j < 6 * k; ++j) {
      const double phi = 2 * M_PI * j / (6 * k), r = static_cast<double>(k) / n;
      base[k].push_back(static_cast<int>(v.size()));
      v.emplace_back(a * r * std::cos(phi), b * r * std::sin(phi), 0.0);
    }
  base[n] = dome[n];
  std::vector<Eigen::Vector3i> bf;
  for (int k = 1; k <= n; ++k) zip_rings(base[k - 1], base[k], bf);
  for (auto& t : bf) f.emplace_back(t[0], t[2], t[1]);
  return assemble(v, f);
}

SurfaceMesh make_icosphere(const Vec3& centre, double radius, int subdivisions) {
  if (!(radius > 0) || subdivisions < 0) throw InputError("icosphere needs a positive radius");
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<Eigen::Vector3i> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int i, int j) {
      const auto key = std::make_pair(std::min(i, j), std::max(i, j));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[i] + v[j]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<Eigen::Vector3i> nf;
    for (const auto& tri : f) {
      const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), c = midpoint(tri[2], tri[0]);
      nf.emplace_back(tri[0], a, c);
      nf.emplace_back(tri[1], b, a);
      nf.emplace_back(tri[2], c, b);
      nf.emplace_back(a, b, c);
    }
    f.swap(nf);
  }
  for (auto& p : v) p = centre + radius * p;
  return assemble(v, f);
}

SurfaceMesh make_chest_ring(double a, double b, double width, int segments, double R) {
  if (!(a > 0 && b > 0 && width > 0 && R > 0) || segments < 3) throw InputError("chest ring needs positive sizes");
  const int radial = 6;
  std::vector<Vec3> v;
  std::vector<Eigen::Vector3i> f;
  for (int j = 0; j < segments; ++j) {
    const double phi = 2 * M_PI * j / segments;
    for (int r = 0; r <= radial; ++r) {
      const double d = width * r / radial;  // distance beyond the rim (along the ellipse normal, approx.)
      const double s = 1.0 + d / std::min(a, b);
      const double z = -d * d * (1.0 + 0.5 * std::cos(2 * phi)) / (2 * R);
      v.emplace_back(s * a * std::cos(phi), s * b * std::sin(phi), z);
    }
  }
  const auto id = [&](int j, int r) { return (j % segments) * (radial + 1) + r; };
  for (int j = 0; j < segments; ++j)
    for (int r = 0; r < radial; ++r) {
      f.emplace_back(id(j, r), id(j, r + 1), id(j + 1, r + 1));
      f.emplace_back(id(j, r), id(j + 1, r + 1), id(j + 1, r));
    }
  return assemble(v, f);
}

}  // namespace btr
