// Quadratic (10-node, P2) tetrahedra on a linear tetrahedral mesh: the corner vertices keep
// their indices and every edge gets a node after them. The rest shape is straight-sided (each
// edge node at its edge's midpoint), so the map from barycentric coordinates to the rest
// position is affine and the shape-function gradients are those of the barycentric
// coordinates, constant per element; deformed, the edges may curve.
//
// Why: a linear tetrahedron's displacement is piecewise affine, and on a breast mesh of 5 to
// 7 mm cells at Poisson's ratio 0.49 it sags 1 to 4 mm less than the converged answer (probe
// bench/probes/forward_discrepancy.cpp against SfePy's cubic truth); a quadratic field converges
// an order faster in the cell size.
//
// Node order per element (VTK's quadratic tetrahedron): corners 0..3, then the nodes of edges
// (0,1), (1,2), (0,2), (0,3), (1,3), (2,3).
#pragma once

#include <array>
#include <vector>

#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/fem/element_order.h"
#include "breast_tumour_registration/geometry/embedding.h"

namespace btr {

using QuadraticTets = Eigen::Matrix<int, Eigen::Dynamic, 10, Eigen::RowMajor>;
using Vec4 = Eigen::Vector4d;

/// The corner pairs of local edge nodes 4..9.
inline constexpr std::array<std::array<int, 2>, 6> kQuadraticTetEdges = {
    {{{0, 1}}, {{1, 2}}, {{0, 2}}, {{0, 3}}, {{1, 3}}, {{2, 3}}}};

struct QuadraticTetMesh {
  QuadraticTets T;                        ///< #T by 10 node indices
  Eigen::Index corners = 0;               ///< the linear mesh's vertex count: nodes [0, corners) are its vertices
  std::vector<std::array<int, 2>> edges;  ///< node corners + e sits on edge e (its two corner vertices)
  Eigen::Index nodes() const { return corners + static_cast<Eigen::Index>(edges.size()); }
};

/// Adds an edge node to every edge of T (vertices: the linear mesh's vertex count). Throws
/// InputError for an index out of range.
QuadraticTetMesh make_quadratic_tets(const Tetrahedra& T, Eigen::Index vertices);

/// All node positions from the corner positions: each edge node at its edge's midpoint.
Points straight_sided_positions(const QuadraticTetMesh& q, const Points& corners);

/// Every node's fixed flag from the corners': an edge node is fixed where both its ends are.
/// Throws InputError when corner_fixed does not have one flag per corner.
std::vector<bool> quadratic_fixed_nodes(const QuadraticTetMesh& q, const std::vector<bool>& corner_fixed);


/// The 10 shape functions at barycentric coordinates b (b sums to 1).
Eigen::Matrix<double, 10, 1> quadratic_shape(const Vec4& b);
/// Their derivatives with respect to the 4 barycentric coordinates (10 by 4).
Eigen::Matrix<double, 10, 4> quadratic_shape_barycentric_derivatives(const Vec4& b);

/// The position of the point with barycentric coordinates b in element t at node positions x.
Vec3 quadratic_interpolate(const QuadraticTetMesh& q, const Points& x, Eigen::Index t, const Vec4& b);
/// Points embedded in the linear mesh (their element and barycentric coordinates in the
/// straight-sided rest shape) carried by the quadratic field at node positions x: what
/// apply_embedding is for linear elements.
Points apply_quadratic_embedding(const Embedding& e, const QuadraticTetMesh& q, const Points& x);

struct TetQuadraturePoint {
  Vec4 barycentric;
  double weight;  ///< fraction of the element's volume (the weights sum to 1)
};
/// A symmetric rule with positive weights: 4 points, exact for polynomials of degree 2 (the
/// stiffness of a quadratic element in small strain), or 14 points, exact to degree 5.
const std::vector<TetQuadraturePoint>& tet_quadrature(int degree);

}  // namespace btr
