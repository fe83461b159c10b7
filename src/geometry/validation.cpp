#include "breast_tumour_registration/geometry/validation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "breast_tumour_registration/base/errors.h"

namespace btr {
namespace {

void check_finite(const Points& V, const std::string& name) {
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (!V.row(i).allFinite())
      throw InputError(name + ": vertex " + std::to_string(i) + " has a NaN or infinite coordinate");
}

std::string vec_str(const Vec3& p) {
  std::ostringstream s;
  s << "(" << p.x() << ", " << p.y() << ", " << p.z() << ") m";
  return s.str();
}

}  // namespace

void validate_surface(const SurfaceMesh& m, const std::string& name, const SurfaceCheckOptions& opt) {
  if (m.F.rows() == 0) throw InputError(name + ": surface has no faces");
  check_finite(m.V, name);
  const long nv = m.V.rows();
  double bbox = (m.V.colwise().maxCoeff() - m.V.colwise().minCoeff()).norm();
  std::map<std::pair<int, int>, std::vector<std::pair<int, bool>>> edges;  // undirected edge -> (face, forward)
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c)
      if (m.F(f, c) < 0 || m.F(f, c) >= nv)
        throw InputError(name + ": face " + std::to_string(f) + " references vertex " + std::to_string(m.F(f, c)) +
                         " but there are " + std::to_string(nv) + " vertices");
    const int a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
    if (a == b || b == c || a == c)
      throw InputError(name + ": face " + std::to_string(f) + " repeats a vertex (degenerate)");
    const Vec3 pa = m.V.row(a), pb = m.V.row(b), pc = m.V.row(c);
    const double area2 = (pb - pa).cross(pc - pa).norm();
    if (area2 <= 1e-14 * bbox * bbox)
      throw InputError(name + ": face " + std::to_string(f) + " has zero area (degenerate) near " + vec_str(pa));
    for (int k = 0; k < 3; ++k) {
      const int u = m.F(f, k), v = m.F(f, (k + 1) % 3);
      edges[{std::min(u, v), std::max(u, v)}].push_back({static_cast<int>(f), u < v});
    }
  }
  for (const auto& [e, uses] : edges) {
    if (uses.size() > 2)
      throw InputError(name + ": non-manifold edge between vertices " + std::to_string(e.first) + " and " +
                       std::to_string(e.second) + " (shared by " + std::to_string(uses.size()) + " faces)");
    if (uses.size() == 1 && opt.require_closed)
      throw InputError(name + ": surface is open: edge between vertices " + std::to_string(e.first) + " and " +
                       std::to_string(e.second) + " at " + vec_str(m.V.row(e.first)) +
                       " belongs to a single face; a closed surface is required");
    if (uses.size() == 2 && opt.require_consistent_orientation && uses[0].second == uses[1].second)
      throw InputError(name + ": faces " + std::to_string(uses[0].first) + " and " + std::to_string(uses[1].first) +
                       " are inconsistently oriented");
  }
}

double tet_signed_volume(const Points& V, const Tetrahedra& T, Eigen::Index t) {
  const Vec3 a = V.row(T(t, 0)), b = V.row(T(t, 1)), c = V.row(T(t, 2)), d = V.row(T(t, 3));
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

bool orient_tets_positive(TetMesh& m) {
  for (Eigen::Index t = 0; t < m.T.rows(); ++t) {
    for (int c = 0; c < 4; ++c)
      if (m.T(t, c) < 0 || m.T(t, c) >= m.V.rows()) return false;  // validate_tet_mesh reports it
    if (tet_signed_volume(m.V, m.T, t) >= 0) return false;
  }
  if (m.T.rows() == 0) return false;
  m.T.col(2).swap(m.T.col(3));
  return true;
}

Vec3 tet_centroid(const Points& V, const Tetrahedra& T, Eigen::Index t) {
  Vec3 c = Vec3::Zero();
  for (int k = 0; k < 4; ++k) c += V.row(T(t, k)).transpose() / 4.0;
  return c;
}

double mean_edge_length(const TetMesh& m) {
  return mean_edge_length(m, [](Eigen::Index) { return true; });
}

double mean_edge_length(const TetMesh& m, const std::function<bool(Eigen::Index)>& keep) {
  double sum = 0;
  long kept = 0;
  for (Eigen::Index t = 0; t < m.T.rows(); ++t) {
    if (!keep(t)) continue;
    ++kept;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) sum += (m.V.row(m.T(t, a)) - m.V.row(m.T(t, b))).norm();
  }
  return kept ? sum / (6.0 * static_cast<double>(kept)) : 0.0;
}

void validate_tet_mesh(const TetMesh& m, const std::string& name, double degenerate_rel) {
  if (m.T.rows() == 0) throw InputError(name + ": mesh has no tetrahedra");
  check_finite(m.V, name);
  const long nv = m.V.rows();
  for (Eigen::Index t = 0; t < m.T.rows(); ++t) {
    for (int c = 0; c < 4; ++c)
      if (m.T(t, c) < 0 || m.T(t, c) >= nv)
        throw InputError(name + ": tetrahedron " + std::to_string(t) + " references vertex " +
                         std::to_string(m.T(t, c)) + " but there are " + std::to_string(nv) + " vertices");
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        if (m.T(t, a) == m.T(t, b))
          throw InputError(name + ": tetrahedron " + std::to_string(t) + " repeats vertex " + std::to_string(m.T(t, a)));
  }
  const double h = mean_edge_length(m);
  const double vmin = degenerate_rel * h * h * h;
  long inverted = 0, first_inverted = -1;
  for (Eigen::Index t = 0; t < m.T.rows(); ++t) {
    const double v = tet_signed_volume(m.V, m.T, t);
    if (std::abs(v) <= vmin)
      throw InputError(name + ": tetrahedron " + std::to_string(t) + " is degenerate (volume " + std::to_string(v) +
                       " m^3, mean edge " + std::to_string(h) + " m) near " + vec_str(m.V.row(m.T(t, 0))));
    if (v < 0 && inverted++ == 0) first_inverted = t;
  }
  if (inverted > 0)
    throw InputError(name + ": " + std::to_string(inverted) + " of " + std::to_string(m.T.rows()) +
                     " tetrahedra are inverted (first: " + std::to_string(first_inverted) +
                     "); the rest mesh must be consistently, positively oriented");
}

Triangles boundary_faces(const TetMesh& m) {
  // Face opposite vertex k, oriented outwards for a positive tet (the opposite vertex
  // lies behind the face).
  static const int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  struct Key {
    std::array<int, 3> v;
    bool operator==(const Key& o) const { return v == o.v; }
  };
  struct Hash {
    size_t operator()(const Key& k) const {
      return (static_cast<size_t>(k.v[0]) * 73856093u) ^ (static_cast<size_t>(k.v[1]) * 19349663u) ^
             (static_cast<size_t>(k.v[2]) * 83492791u);
    }
  };
  std::unordered_map<Key, std::pair<int, std::array<int, 3>>, Hash> count;
  count.reserve(m.T.rows() * 3);
  for (Eigen::Index t = 0; t < m.T.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      std::array<int, 3> f{m.T(t, kFace[k][0]), m.T(t, kFace[k][1]), m.T(t, kFace[k][2])};
      Key key{f};
      std::sort(key.v.begin(), key.v.end());
      auto& e = count[key];
      e.first++;
      e.second = f;
    }
  std::vector<std::array<int, 3>> out;
  for (const auto& [k, e] : count)
    if (e.first == 1) out.push_back(e.second);
  std::sort(out.begin(), out.end());  // deterministic order
  Triangles F(out.size(), 3);
  for (size_t i = 0; i < out.size(); ++i) F.row(i) << out[i][0], out[i][1], out[i][2];
  return F;
}

}  // namespace btr
