// Newton's method in a linear subspace (thesis Algorithm 1): d = -(U^T H U)^-1 U^T g, then a
// line search on the full-space energy along U d. The reduced Hessian is dense (12k by 12k
// for k skinning handles) and factorized with LDLT; a tiny diagonal shift guards against the
// basis' redundancy.
#pragma once

#include <Eigen/SparseCore>

#include "breast_tumour_registration/fem/newton_solver.h"

namespace btr {

/// Minimizes `energy` over x = x_start + U q. `basis` is 3#V by m (rows of fixed vertices
/// zero); `assembler` must have the same fixed vertices (their blocks are dropped).
/// Convergence: |U^T g| <= abs_tol + rel_tol max(|U^T g0|, force_scale), or the step tolerance.
NewtonResult solve_subspace_newton(const TotalEnergy& energy, HessianAssembler& assembler,
                                   const Eigen::SparseMatrix<double>& basis, const Tetrahedra& tets, Points& x,
                                   const NewtonOptions& opt);

}  // namespace btr
