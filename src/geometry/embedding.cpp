#include "breast_tumour_registration/geometry/embedding.h"

#include <algorithm>
#include <array>
#include <limits>
#include <cmath>
#include <string>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/closest_point.h"
#include "breast_tumour_registration/geometry/validation.h"

namespace btr {
namespace {

Eigen::Vector4d barycentric(const Points& V, const Tetrahedra& T, Eigen::Index t, const Vec3& p) {
  const Vec3 a = V.row(T(t, 0));
  Mat3 D;
  for (int k = 0; k < 3; ++k) D.col(k) = V.row(T(t, k + 1)).transpose() - a;
  const Vec3 l = D.inverse() * (p - a);
  return Eigen::Vector4d(1.0 - l.sum(), l[0], l[1], l[2]);
}

// Uniform grid over tetrahedron bounding boxes: each cell lists the tets overlapping it.
struct TetGrid {
  Vec3 lo, cell;
  Eigen::Vector3i n;
  std::vector<std::vector<int>> bins;

  TetGrid(const TetMesh& m) {
    lo = m.V.colwise().minCoeff().transpose();
    const Vec3 hi = m.V.colwise().maxCoeff().transpose();
    const Vec3 ext = (hi - lo).cwiseMax(1e-12);
    const double target = std::cbrt(ext.prod() / std::max<Eigen::Index>(1, m.T.rows() / 4));
    for (int c = 0; c < 3; ++c) n[c] = std::clamp(static_cast<int>(std::ceil(ext[c] / target)), 1, 256);
    cell = ext.cwiseQuotient(n.cast<double>());
    bins.resize(static_cast<size_t>(n.prod()));
    for (Eigen::Index t = 0; t < m.T.rows(); ++t) {
      Vec3 bmin = m.V.row(m.T(t, 0)), bmax = bmin;
      for (int k = 1; k < 4; ++k) {
        bmin = bmin.cwiseMin(m.V.row(m.T(t, k)).transpose());
        bmax = bmax.cwiseMax(m.V.row(m.T(t, k)).transpose());
      }
      const Eigen::Vector3i a = index(bmin), b = index(bmax);
      for (int z = a.z(); z <= b.z(); ++z)
        for (int y = a.y(); y <= b.y(); ++y)
          for (int x = a.x(); x <= b.x(); ++x) bins[x + n.x() * (y + n.y() * z)].push_back(static_cast<int>(t));
    }
  }
  Eigen::Vector3i index(const Vec3& p) const {
    Eigen::Vector3i i;
    for (int c = 0; c < 3; ++c) i[c] = std::clamp(static_cast<int>(std::floor((p[c] - lo[c]) / cell[c])), 0, n[c] - 1);
    return i;
  }
  const std::vector<int>& at(const Vec3& p) const {
    const Eigen::Vector3i i = index(p);
    return bins[i.x() + n.x() * (i.y() + n.y() * i.z())];
  }
};

}  // namespace

Embedding embed_points(const TetMesh& mesh, const Points& P, OutsidePolicy policy, double tolerance) {
  if (!P.allFinite()) throw InputError("embedding: points contain NaN or infinite coordinates");
  Embedding e;
  e.tet.resize(P.rows());
  e.weights.resize(P.rows(), 4);
  const TetGrid grid(mesh);
  std::vector<int> outside;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Vec3 p = P.row(i);
    int best = -1;
    double best_min = -std::numeric_limits<double>::infinity();
    Eigen::Vector4d best_w;
    for (int t : grid.at(p)) {
      const Eigen::Vector4d w = barycentric(mesh.V, mesh.T, t, p);
      if (w.minCoeff() > best_min) {
        best_min = w.minCoeff();
        best = t;
        best_w = w;
      }
    }
    if (best >= 0 && best_min >= -tolerance) {
      e.tet[i] = best;
      e.weights.row(i) = best_w.transpose();
    } else {
      outside.push_back(static_cast<int>(i));
      e.tet[i] = -1;
    }
  }
  if (!outside.empty()) {
    if (policy == OutsidePolicy::Error)
      throw InputError("embedding: " + std::to_string(outside.size()) + " of " + std::to_string(P.rows()) +
                       " points lie outside the tetrahedral mesh (first: point " + std::to_string(outside[0]) + ")");
    // Nearest policy: the tetrahedron owning the closest boundary face.
    const Triangles F = boundary_faces(mesh);
    std::vector<int> face_tet(F.rows(), -1);
    {
      std::vector<std::pair<std::array<int, 3>, int>> keys;
      keys.reserve(mesh.T.rows() * 4);
      for (Eigen::Index t = 0; t < mesh.T.rows(); ++t)
        for (int k = 0; k < 4; ++k) {
          std::array<int, 3> f;
          int n = 0;
          for (int j = 0; j < 4; ++j)
            if (j != k) f[n++] = mesh.T(t, j);
          std::sort(f.begin(), f.end());
          keys.push_back({f, static_cast<int>(t)});
        }
      std::sort(keys.begin(), keys.end());
      for (Eigen::Index f = 0; f < F.rows(); ++f) {
        std::array<int, 3> k{F(f, 0), F(f, 1), F(f, 2)};
        std::sort(k.begin(), k.end());
        auto it = std::lower_bound(keys.begin(), keys.end(), std::make_pair(k, -1));
        face_tet[f] = it->second;
      }
    }
    const SurfaceClosestPoint cp(mesh.V, F);
    for (int i : outside) {
      const ClosestPoint c = cp.query(P.row(i).transpose());
      e.tet[i] = face_tet[c.face];
      e.weights.row(i) = barycentric(mesh.V, mesh.T, e.tet[i], P.row(i).transpose()).transpose();
      e.max_outside_distance = std::max(e.max_outside_distance, c.distance);
    }
  }
  e.outside = std::move(outside);
  return e;
}

bool inside_closed_surface(const SurfaceMesh& s, const Vec3& p) {
  double w = 0;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const Vec3 a = Vec3(s.V.row(s.F(f, 0))) - p, b = Vec3(s.V.row(s.F(f, 1))) - p, c = Vec3(s.V.row(s.F(f, 2))) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    w += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return w / (4 * M_PI) > 0.5;
}

std::vector<int> tetrahedra_inside(const TetMesh& mesh, const std::vector<const SurfaceMesh*>& surfaces) {
  std::vector<int> out;
  for (Eigen::Index e = 0; e < mesh.T.rows(); ++e) {
    const Vec3 c = tet_centroid(mesh.V, mesh.T, e);
    for (const SurfaceMesh* s : surfaces) {
      const Vec3 lo = s->V.colwise().minCoeff().transpose(), hi = s->V.colwise().maxCoeff().transpose();
      if ((c.array() < lo.array()).any() || (c.array() > hi.array()).any()) continue;
      if (inside_closed_surface(*s, c)) {
        out.push_back(static_cast<int>(e));
        break;
      }
    }
  }
  return out;
}

Points apply_embedding(const Embedding& e, const Tetrahedra& T, const Points& x) {
  Points out(e.tet.size(), 3);
  for (Eigen::Index i = 0; i < e.tet.size(); ++i) {
    Vec3 p = Vec3::Zero();
    for (int k = 0; k < 4; ++k) p += e.weights(i, k) * x.row(T(e.tet[i], k)).transpose();
    out.row(i) = p.transpose();
  }
  return out;
}

}  // namespace btr
