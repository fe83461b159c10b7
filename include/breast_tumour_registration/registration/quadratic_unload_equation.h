// The quadratic unload's equation, linearised (MaterialParameters::unload_element_order:
// quadratic; unload_step.h). Its rest corners X make the quadratic model balanced at its corners
// when those are at the imaged (prone) shape x_p and its edge nodes m are in equilibrium:
//   G(X, p) = R_c(X, m*(X, p), p) = 0,   R_m(X, m*, p) = 0,
// R the gradient of the quadratic elastic energy plus gravity at the nodes (x_p, m), p the
// material (ln E, the volume compliance q). The linearised tumour region needs how X moves with
// p (tumour_uncertainty.cpp: D_X G [dX/dp] = -dG/dp, by GMRES); the linear unload's equation
// has no edge nodes, and with a quadratic unload it was 30 to 40 % off re-solves.
//
// The edge nodes are eliminated to first order: from the balanced m*, a change of X or p moves
// them by dm = -K_mm^-1 R_m (K_mm the edge-node block of the quadratic Hessian, factorized once),
// and G's change is R_c's at (X, m* + dm). Central differences of that give the products.
#pragma once

#include <Eigen/CholmodSupport>
#include <memory>

#include "breast_tumour_registration/fem/forward_gravity.h"
#include "breast_tumour_registration/fem/hessian_pattern.h"
#include "breast_tumour_registration/fem/quadratic_tetrahedra.h"
#include "breast_tumour_registration/fem/stable_neo_hookean.h"
#include "breast_tumour_registration/registration/registration_model.h"

namespace btr {

class QuadraticUnloadEquation {
 public:
  /// At the model's rest shape (its unloaded corners) under model.unloaded_under, its corners at
  /// model.prone: balances the edge nodes (Newton). Throws SolverError where they cannot be
  /// balanced or their Hessian cannot be factorized, InputError on a model not unloaded.
  /// quadrature_degree: the unload's forward model's (ForwardGravityOptions).
  explicit QuadraticUnloadEquation(const RegistrationModel& model,
                                   int quadrature_degree = ForwardGravityOptions{}.quadrature_degree);
  ~QuadraticUnloadEquation();

  /// D_X G [dX]: every vertex, 3 rows each (dX zero on the chest wall).
  Eigen::VectorXd d_rest(const Eigen::VectorXd& dX) const;
  /// dG / d ln E, every material's Young's modulus scaled alike.
  Eigen::VectorXd d_log_youngs_modulus() const;
  /// dG / dq, q = (1 - 2 nu) / (2 nu) of every material.
  Eigen::VectorXd d_compliance() const;
  /// A preconditioner for D_X G: minus the inverse of the Schur complement of the quadratic
  /// Hessian on the corners (moving the rest shape is moving the deformed one backwards, for
  /// small strains), from one factorization of the whole Hessian with the chest wall held. r and
  /// the result: every vertex, 3 rows each. With the linear Hessian instead, GMRES took 86
  /// products on the 12 mm phantom where the linear unload's took 11.
  Eigen::VectorXd precondition(const Eigen::VectorXd& r) const;

 private:
  /// G at rest corners X with `materials`, the edge nodes moved to first order from m*.
  Eigen::VectorXd corner_gradient(const Points& X, const std::vector<StableNeoHookean>& materials) const;

  const RegistrationModel& model_;
  int degree_;
  QuadraticTetMesh mesh_;
  Points balanced_;  ///< every node: the corners at model.prone, the edge nodes at m*
  std::shared_ptr<HessianAssembler> edges_;  ///< the edge nodes free, the corners held
  using Llt = Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;
  std::unique_ptr<Llt> k_mm_;
  std::shared_ptr<HessianAssembler> nodes_;  ///< every node free but the chest wall's
  std::unique_ptr<Llt> k_;
};

}  // namespace btr
