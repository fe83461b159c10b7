#include "breast_tumour_registration/registration/quadratic_unload_equation.h"

#include <cmath>
#include <string>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/inversion_check.h"
#include "breast_tumour_registration/fem/newton_solver.h"
#include "breast_tumour_registration/fem/quadratic_elastic_energy.h"
#include "breast_tumour_registration/fem/total_energy.h"
#include "breast_tumour_registration/registration/tumour_uncertainty.h"

namespace btr {
namespace {

/// The quadratic model's energy (elastic + gravity with consistent masses) at rest corners X.
TotalEnergy quadratic_energy(const RegistrationModel& m, const QuadraticTetMesh& q, const Points& X,
                             const std::vector<StableNeoHookean>& materials, int degree) {
  auto elastic = std::make_shared<QuadraticElasticEnergy>(q, X, materials, m.material_of, degree);
  TotalEnergy e;
  e.add(std::make_shared<GravityEnergy>(elastic->consistent_masses(m.material.density), m.unloaded_under));
  e.add(elastic);
  return e;
}

std::vector<StableNeoHookean> scaled(const std::vector<StableNeoHookean>& materials, double factor, double nu) {
  std::vector<StableNeoHookean> out;
  for (const auto& mat : materials) out.emplace_back(mat.youngs_modulus() * factor, nu);
  return out;
}

}  // namespace

QuadraticUnloadEquation::QuadraticUnloadEquation(const RegistrationModel& model, int quadrature_degree)
    : model_(model), degree_(quadrature_degree) {
  if (!(model.unloaded_under.norm() > 0)) throw InputError("quadratic unload equation: the model was not unloaded");
  mesh_ = make_quadratic_tets(model.rest.T, model.rest.V.rows());
  std::vector<bool> fixed(static_cast<size_t>(mesh_.nodes()), true);  // the corners held at the imaged shape
  for (size_t e = 0; e < mesh_.edges.size(); ++e)
    fixed[static_cast<size_t>(mesh_.corners) + e] = model.fixed[mesh_.edges[e][0]] && model.fixed[mesh_.edges[e][1]];
  TotalEnergy energy = quadratic_energy(model, mesh_, model.rest.V, model.materials, degree_);
  auto assembler = std::make_shared<HessianAssembler>(static_cast<int>(mesh_.nodes()), model.rest.T, fixed,
                                                      energy.hessian_cliques());
  // The edge nodes from straight edges between the imaged corners (the chest wall's at rest, where
  // the imaged shape is the rest shape), balanced with the corners held.
  balanced_ = straight_sided_positions(mesh_, model.prone);
  NewtonSolver solver(assembler, InversionCheck::quadratic(mesh_, degree_));
  NewtonOptions o;
  o.gradient_rel_tolerance = 1e-10;
  o.max_iterations = 50;
  o.force_scale = model.unloaded_under.norm() * model.material.density * model.volume;
  const NewtonResult r = solver.solve(energy, balanced_, o);
  if (!r.converged)
    throw SolverError("quadratic unload equation: the edge nodes at the imaged shape did not balance (" + to_string(r.reason) + ")");
  // The exact Hessian at the balanced state, else the PSD-projected one.
  auto factorize = [&](HessianAssembler& H, const char* what) {
    auto llt = std::make_unique<Llt>();
    llt->cholmod().print = 0;
    for (bool project : {false, true}) {
      energy.hessian(balanced_, project, H);
      llt->compute(H.matrix());
      if (llt->info() == Eigen::Success) return llt;
    }
    throw SolverError(std::string("quadratic unload equation: ") + what + " cannot be factorized");
  };
  k_mm_ = factorize(*assembler, "the edge nodes' Hessian");
  edges_ = assembler;
  std::vector<bool> wall(fixed.size());  // the preconditioner's: every node free but the chest wall's
  for (size_t v = 0; v < wall.size(); ++v)
    wall[v] = v < static_cast<size_t>(mesh_.corners) ? model.fixed[v] : fixed[v];
  nodes_ = std::make_shared<HessianAssembler>(static_cast<int>(mesh_.nodes()), model.rest.T, wall, energy.hessian_cliques());
  k_ = factorize(*nodes_, "the prone Hessian");
}

Eigen::VectorXd QuadraticUnloadEquation::precondition(const Eigen::VectorXd& r) const {
  Eigen::VectorXd full = Eigen::VectorXd::Zero(3 * mesh_.nodes());
  full.head(r.size()) = r;
  Eigen::VectorXd y = Eigen::VectorXd::Zero(full.size());
  nodes_->scatter_add(k_->solve(nodes_->gather(full)), -1.0, y);
  return y.head(r.size());
}

QuadraticUnloadEquation::~QuadraticUnloadEquation() = default;

Eigen::VectorXd QuadraticUnloadEquation::corner_gradient(const Points& X, const std::vector<StableNeoHookean>& materials) const {
  const TotalEnergy e = quadratic_energy(model_, mesh_, X, materials, degree_);
  Eigen::VectorXd full = e.gradient(balanced_);
  Eigen::VectorXd move = Eigen::VectorXd::Zero(full.size());
  edges_->scatter_add(k_mm_->solve(edges_->gather(full)), -1.0, move);  // the edge nodes to first order
  const Points x = balanced_ + as_points(move);
  return e.gradient(x).head(3 * model_.rest.V.rows());
}

Eigen::VectorXd QuadraticUnloadEquation::d_rest(const Eigen::VectorXd& dX) const {
  const double largest = dX.cwiseAbs().maxCoeff();
  if (!(largest > 0)) return Eigen::VectorXd::Zero(dX.size());
  const double eps = 1e-6 / largest;  // no vertex moved by more than 1 um
  const auto D = as_points(dX);
  return (corner_gradient(model_.rest.V + eps * D, model_.materials) - corner_gradient(model_.rest.V - eps * D, model_.materials)) /
         (2 * eps);
}

Eigen::VectorXd QuadraticUnloadEquation::d_log_youngs_modulus() const {
  const double h = 1e-3, nu = model_.material.poisson_ratio;
  return (corner_gradient(model_.rest.V, scaled(model_.materials, std::exp(h), nu)) -
          corner_gradient(model_.rest.V, scaled(model_.materials, std::exp(-h), nu))) /
         (2 * h);
}

Eigen::VectorXd QuadraticUnloadEquation::d_compliance() const {
  const double q0 = volume_compliance(model_.material.poisson_ratio), h = 1e-3 * q0;
  return (corner_gradient(model_.rest.V, scaled(model_.materials, 1.0, poisson_ratio_of_compliance(q0 + h))) -
          corner_gradient(model_.rest.V, scaled(model_.materials, 1.0, poisson_ratio_of_compliance(q0 - h)))) /
         (2 * h);
}

}  // namespace btr
