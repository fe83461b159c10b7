#include "breast_tumour_registration/fem/quadratic_tetrahedra.h"

#include <map>
#include <string>
#include <utility>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

QuadraticTetMesh make_quadratic_tets(const Tetrahedra& T, Eigen::Index vertices) {
  QuadraticTetMesh q;
  q.corners = vertices;
  q.T.resize(T.rows(), 10);
  std::map<std::pair<int, int>, int> node_of;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    for (int a = 0; a < 4; ++a) {
      if (T(t, a) < 0 || T(t, a) >= vertices)
        throw InputError("quadratic tetrahedra: tetrahedron " + std::to_string(t) + " has vertex " +
                         std::to_string(T(t, a)) + " of a mesh of " + std::to_string(vertices));
      q.T(t, a) = T(t, a);
    }
    for (int e = 0; e < 6; ++e) {
      int i = T(t, kQuadraticTetEdges[e][0]), j = T(t, kQuadraticTetEdges[e][1]);
      if (i > j) std::swap(i, j);
      const auto [it, added] = node_of.emplace(std::make_pair(i, j), static_cast<int>(vertices + q.edges.size()));
      if (added) q.edges.push_back({{i, j}});
      q.T(t, 4 + e) = it->second;
    }
  }
  return q;
}

std::vector<bool> quadratic_fixed_nodes(const QuadraticTetMesh& q, const std::vector<bool>& corner_fixed) {
  if (static_cast<Eigen::Index>(corner_fixed.size()) != q.corners)
    throw InputError("quadratic tetrahedra: " + std::to_string(corner_fixed.size()) + " fixed flags for " +
                     std::to_string(q.corners) + " vertices");
  std::vector<bool> fixed = corner_fixed;
  for (const auto& e : q.edges) fixed.push_back(corner_fixed[e[0]] && corner_fixed[e[1]]);
  return fixed;
}

Points straight_sided_positions(const QuadraticTetMesh& q, const Points& corners) {
  if (corners.rows() != q.corners)
    throw InputError("quadratic tetrahedra: " + std::to_string(corners.rows()) + " corner positions for " +
                     std::to_string(q.corners) + " vertices");
  Points x(q.nodes(), 3);
  x.topRows(q.corners) = corners;
  for (size_t e = 0; e < q.edges.size(); ++e)
    x.row(q.corners + static_cast<Eigen::Index>(e)) = 0.5 * (corners.row(q.edges[e][0]) + corners.row(q.edges[e][1]));
  return x;
}

Eigen::Matrix<double, 10, 1> quadratic_shape(const Vec4& b) {
  Eigen::Matrix<double, 10, 1> N;
  for (int i = 0; i < 4; ++i) N[i] = b[i] * (2 * b[i] - 1);
  for (int e = 0; e < 6; ++e) N[4 + e] = 4 * b[kQuadraticTetEdges[e][0]] * b[kQuadraticTetEdges[e][1]];
  return N;
}

Eigen::Matrix<double, 10, 4> quadratic_shape_barycentric_derivatives(const Vec4& b) {
  Eigen::Matrix<double, 10, 4> D = Eigen::Matrix<double, 10, 4>::Zero();
  for (int i = 0; i < 4; ++i) D(i, i) = 4 * b[i] - 1;
  for (int e = 0; e < 6; ++e) {
    const int i = kQuadraticTetEdges[e][0], j = kQuadraticTetEdges[e][1];
    D(4 + e, i) = 4 * b[j];
    D(4 + e, j) = 4 * b[i];
  }
  return D;
}

Vec3 quadratic_interpolate(const QuadraticTetMesh& q, const Points& x, Eigen::Index t, const Vec4& b) {
  const Eigen::Matrix<double, 10, 1> N = quadratic_shape(b);
  Vec3 p = Vec3::Zero();
  for (int a = 0; a < 10; ++a) p += N[a] * x.row(q.T(t, a)).transpose();
  return p;
}

Points apply_quadratic_embedding(const Embedding& e, const QuadraticTetMesh& q, const Points& x) {
  if (x.rows() != q.nodes())
    throw InputError("quadratic embedding: " + std::to_string(x.rows()) + " positions for " + std::to_string(q.nodes()) +
                     " nodes");
  Points p(e.tet.size(), 3);
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    if (e.tet[i] < 0 || e.tet[i] >= q.T.rows())
      throw InputError("quadratic embedding: point " + std::to_string(i) + " in element " + std::to_string(e.tet[i]) +
                       " of " + std::to_string(q.T.rows()));
    p.row(i) = quadratic_interpolate(q, x, e.tet[i], e.weights.row(i).transpose()).transpose();
  }
  return p;
}

namespace {

std::vector<TetQuadraturePoint> symmetric_rule(const std::vector<std::pair<double, double>>& orbits4,
                                               const std::vector<std::pair<double, double>>& orbits6) {
  std::vector<TetQuadraturePoint> rule;
  for (const auto& [a, w] : orbits4)  // (a, a, a, 1 - 3a) and its permutations
    for (int k = 0; k < 4; ++k) {
      Vec4 b = Vec4::Constant(a);
      b[k] = 1 - 3 * a;
      rule.push_back({b, w});
    }
  for (const auto& [a, w] : orbits6)  // (a, a, 1/2 - a, 1/2 - a) and its permutations
    for (const auto& e : kQuadraticTetEdges) {
      Vec4 b = Vec4::Constant(0.5 - a);
      b[e[0]] = b[e[1]] = a;
      rule.push_back({b, w});
    }
  return rule;
}

}  // namespace

const std::vector<TetQuadraturePoint>& tet_quadrature(int degree) {
  // Keast's 4-point rule and the 14-point degree-5 rule of Walkington (2000), weights scaled to
  // fractions of the volume (tested on every monomial up to their degree).
  static const std::vector<TetQuadraturePoint> two = symmetric_rule({{0.1381966011250105, 0.25}}, {});
  static const std::vector<TetQuadraturePoint> five =
      symmetric_rule({{0.0927352503108912, 6 * 0.01224884051939366}, {0.3108859192633006, 6 * 0.01878132095300264}},
                     {{0.4544962958743504, 6 * 0.007091003462846911}});
  if (degree <= 2) return two;
  if (degree <= 5) return five;
  throw InputError("tet quadrature: no rule of degree " + std::to_string(degree) + " (2 or 5)");
}

}  // namespace btr
