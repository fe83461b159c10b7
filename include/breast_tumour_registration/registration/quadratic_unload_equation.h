// The quadratic unload's equation, linearised (MaterialParameters::unload_element_order:
// quadratic; unload_step.h). Its rest corners X make the quadratic model's equilibrium from them
// put the corners at the imaged (prone) shape x_p: with the edge nodes m deformed,
//   R_c(X, x_p, m, p) = 0,   R_m(X, x_p, m, p) = 0,
// R the gradient of the quadratic elastic energy plus gravity at the free corners (c) and edge
// nodes (m), p the material (ln E, the volume compliance q). The linearised tumour region needs
// how X moves with p (tumour_uncertainty.cpp); the linear unload's equation has no edge nodes,
// and with a quadratic unload it was 30 to 40 % off re-solves.
//
// Solved jointly for (dX, dm): J [dX; dm] = -dR/dp, J = [dR/dX, dR/dm], by GMRES on products
// from central differences of R, at the equilibrium the unload's last forward solve found
// (RegistrationModel::unloaded_nodes; its corners within the unload's tolerance of x_p).
// Preconditioner: for small strains moving the rest shape is moving the deformed one backwards,
// dR/dX ~ -K [I; P] (K the Hessian in the deformed nodes, P the edge midpoints' interpolation),
// so J ~ K L with L [a; b] = [-a; b - P a], its own inverse: M^-1 = L K^-1, one factorization
// of K at that equilibrium. (Keeping the forward solver's own factor instead saved it but held
// 172 MB per prepared 7.3k-tet model for an optional output, and its age doubled the products.)
#pragma once

#include <memory>
#include <vector>

#include "breast_tumour_registration/fem/forward_gravity.h"
#include "breast_tumour_registration/fem/gmres.h"
#include "breast_tumour_registration/fem/hessian_pattern.h"
#include "breast_tumour_registration/fem/quadratic_tetrahedra.h"
#include "breast_tumour_registration/fem/stable_neo_hookean.h"
#include "breast_tumour_registration/registration/registration_model.h"
#include "breast_tumour_registration/registration/unload_step.h"

namespace btr {

/// How an unloaded rest shape moves with material inputs: dX per input.
struct RestShapeResponse {
  std::vector<Eigen::VectorXd> dX;  ///< per input, every vertex (zero on the chest wall)
  int iterations = 0;               ///< products with the linearised equation, over the inputs
  double worst_residual = 0;        ///< the largest relative residual
  bool converged = true;
  /// Records one input's GMRES solve and its dX.
  void add(const GmresResult& g, Eigen::VectorXd dX_input);
};

class QuadraticUnloadEquation {
 public:
  /// At the model's rest shape under model.unloaded_under: the quadratic model's equilibrium
  /// from it (model.unloaded_nodes; where they were not kept, one forward solve from the prone
  /// shape) and one factorization of its Hessian there. Throws SolverError where that solve or
  /// factorization fails, InputError on a model not unloaded.
  /// quadrature_degree: the unload's forward model's (with_model_elements).
  explicit QuadraticUnloadEquation(const RegistrationModel& model, int quadrature_degree = kUnloadQuadratureDegree);
  ~QuadraticUnloadEquation();

  /// dX/d ln E (every material's Young's modulus scaled alike) and, with_q, dX/dq
  /// (q = (1 - 2 nu) / (2 nu) of every material), by GMRES to a relative residual of 1e-4.
  RestShapeResponse rest_response(bool with_q) const;

 private:
  /// J [d], d every node's (corners: dX, edge nodes: dm; 3 rows each), every node's rows.
  Eigen::VectorXd apply(const Eigen::VectorXd& d) const;
  /// R at every node, the body's rest corners X with `materials`, its nodes at `x`.
  Eigen::VectorXd residual(const Points& X, const std::vector<StableNeoHookean>& materials, const Points& x) const;
  /// dR/dp by a central difference of the materials, scaled (ln E) or given a Poisson's ratio (q).
  Eigen::VectorXd d_log_youngs_modulus() const;
  Eigen::VectorXd d_compliance() const;

  const RegistrationModel& model_;
  int degree_;
  QuadraticTetMesh mesh_;
  Points x_;  ///< every node at the equilibrium
  std::unique_ptr<HessianAssembler> free_;  ///< every node free but the chest wall's
  struct Factor;  ///< K's Cholesky factor (hessian_factor.h)
  std::unique_ptr<Factor> k_;
};

}  // namespace btr
