// The Hessian of J = det F, d2J/dvec(F)2, projected to positive semi-definite in closed form.
// In the frame of the rotation-variant SVD F = U diag(S) V^T its eigensystem is known
// (Smith, de Goes & Kim 2019, "Analytic eigensystems for isotropic distortion energies"): per
// pair (j, k) with third index i a twist U (e_j e_k^T - e_k e_j^T) V^T / sqrt 2 with eigenvalue
// +S_i and a flip U (e_j e_k^T + e_k e_j^T) V^T / sqrt 2 with -S_i, and on the scaling modes
// U diag(w) V^T the 3 x 3 block [[0, S_2, S_1], [S_2, 0, S_0], [S_1, S_0, 0]]. The nodal form
// projects mu I + (s - mu) d2J/dF2 for every tetrahedron at every Newton step; the numerical
// 9 x 9 eigen-solve this replaced took 23 of the 32 ms of its volume term's Hessian on SfePy's
// 8.3k-tet body (bench/probes/nodal_assembly.cpp).
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// shift * I + scale * d2J/dvec(F)2 (vec column-major, as determinant_hessian) with its
/// negative eigenvalues set to zero (I shares every eigenvector: the eigenvalues are shifted).
/// Equal, to round-off, to clamp_to_psd(shift * I + scale * determinant_hessian(F)). With
/// shift = mu and scale = p - mu it is the projected Hessian of the shear part of the stable
/// Neo-Hookean energy, mu/2 (I_C - 3) - mu (J - 1), plus a pressure p (J - 1).
Mat9 projected_determinant_hessian(const Mat3& F, double scale, double shift = 0);

}  // namespace btr
