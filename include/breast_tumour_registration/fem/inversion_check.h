// What the Newton solver counts as an inverted element: the no-new-inversion rule of its line
// search and the fold allowances of a stall read this count.
//
// Linear tetrahedra: a non-positive signed volume. Quadratic (10-node) tetrahedra: a
// non-positive Jacobian determinant of the element's map at any of its quadrature points or
// nodes, the points where its energy and its shape are evaluated. Until 2026-12-06 (fourth
// session) the check was the element's 8 straight sub-tetrahedra between its corner and edge
// nodes, which is no such test: a curved element whose Jacobian is positive everywhere still has
// inverted sub-tetrahedra once an edge bends by a fraction of its length. Measured on the 12 mm
// phantom hanging prone at 400 Pa: 79 of 2 270 elements had an inverted sub-tetrahedron, none a
// non-positive Jacobian at a quadrature point or node, and the sub-tetrahedra made the phantom's
// quadratic truth refuse itself (and held the unload's line searches back).
#pragma once

#include <vector>

#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/fem/quadratic_tetrahedra.h"

namespace btr {

class InversionCheck {
 public:
  /// No check: nothing counts as inverted.
  InversionCheck() = default;
  /// Linear tetrahedra (may be empty: no check). Implicit, as every linear caller has only T.
  InversionCheck(Tetrahedra T);  // NOLINT(google-explicit-constructor)
  /// Quadratic elements, at the points of tet_quadrature(degree) and the 10 nodes. Throws
  /// InputError for a degree without a rule.
  static InversionCheck quadratic(const QuadraticTetMesh& q, int quadrature_degree);

  /// Inverted elements at positions x (the linear mesh's vertices, or all quadratic nodes).
  long count(const Points& x) const;
  /// Elements checked (the denominator of the fold allowances).
  Eigen::Index elements() const { return linear_.rows() + quadratic_.rows(); }

 private:
  Tetrahedra linear_;
  QuadraticTets quadratic_;
  /// Quadratic: per checked point, the shape functions' derivatives along the three local
  /// coordinates (10 by 3), so the map's Jacobian is sum_a x_a D(a, :).
  std::vector<Eigen::Matrix<double, 10, 3>> derivatives_;
};

}  // namespace btr
