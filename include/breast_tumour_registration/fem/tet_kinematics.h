// Per-tetrahedron rest data and the deformation gradient of a linear tetrahedron
// (F = Ds Dm^-1, Sifakis & Barbic 2012, Sec. 4).
#pragma once

#include <vector>

#include "breast_tumour_registration/base/types.h"

namespace btr {

struct TetRestData {
  Mat3 Dm_inv;    ///< inverse of the rest edge matrix [X1-X0, X2-X0, X3-X0]
  double volume;  ///< rest volume [m^3], positive
};

/// Rest data of every tetrahedron of `rest`. Throws InputError on a degenerate or
/// inverted rest tetrahedron (run validate_tet_mesh first for a fuller message).
std::vector<TetRestData> compute_rest_data(const TetMesh& rest);

/// Deformation gradient of tetrahedron `tet` (vertex indices) at positions x.
inline Mat3 deformation_gradient(const Points& x, const Eigen::Vector4i& tet, const Mat3& Dm_inv) {
  Mat3 Ds;
  const Vec3 x0 = x.row(tet[0]);
  Ds.col(0) = x.row(tet[1]).transpose() - x0;
  Ds.col(1) = x.row(tet[2]).transpose() - x0;
  Ds.col(2) = x.row(tet[3]).transpose() - x0;
  return Ds * Dm_inv;
}

/// d vec(F) / d x_tet, 9 by 12 (x_tet = [x0; x1; x2; x3]).
Mat9x12 deformation_gradient_jacobian(const Mat3& Dm_inv);

/// The 12-vector volume * B^T vec(P) of a stress P (4 vertices x 3): an element's gradient
/// from d psi/dF, without forming B (vertex k+1 gets column k of P Dm^-T, vertex 0 minus their sum).
Vec12 tet_gradient_from_stress(const Mat3& P, const Mat3& Dm_inv, double volume);
/// The 12x12 matrix volume * B^T H9 B of a 9x9 d2psi/dvec(F)2, in a third of the dense flops.
Mat12 tet_hessian_from_stress_hessian(const Mat9& H9, const Mat3& Dm_inv, double volume);
/// Whether tetrahedron t of T has a non-positive signed volume at positions x.
bool is_inverted(const Points& x, const Tetrahedra& T, Eigen::Index t);
/// Number of tetrahedra with non-positive signed volume at positions x.
long count_inverted(const Points& x, const Tetrahedra& T);

/// Lumped vertex masses [kg]: density times a quarter of each incident rest volume.
Eigen::VectorXd lumped_masses(const TetMesh& rest, double density);

}  // namespace btr
