// A sparse Cholesky factor of an energy's Hessian at one state, for linearisations that only
// solve with it (implicit differentiation, preconditioners): the exact Hessian where it is
// positive definite there, else the PSD-projected one.
#pragma once

#include <Eigen/CholmodSupport>
#include <string>

#include "breast_tumour_registration/fem/hessian_pattern.h"
#include "breast_tumour_registration/fem/total_energy.h"

namespace btr {

using HessianLlt = Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;

/// Factorizes the Hessian of `energy` at x (H's free DOFs) into llt: the exact one, or, when it
/// is not positive definite there, the projected one (returns true then). Throws SolverError
/// "<what> cannot be factorized" when neither factorizes.
bool factorize_exact_or_projected(const TotalEnergy& energy, const Points& x, HessianAssembler& H, HessianLlt& llt,
                                  const std::string& what);

}  // namespace btr
