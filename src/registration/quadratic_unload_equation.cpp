#include "breast_tumour_registration/registration/quadratic_unload_equation.h"

#include <algorithm>
#include <cmath>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/hessian_factor.h"
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

/// The quadratic model's equilibrium from the model's rest shape, solved: every node.
Points solve_equilibrium(const RegistrationModel& model, int degree) {
  ForwardGravityOptions o;
  o.element_order = ElementOrder::Quadratic;
  o.quadrature_degree = degree;
  ForwardGravity phi(model.rest.T, model.rest.V.rows(), model.chest_wall, model.materials, model.material_of,
                     model.volume_form, model.material.nodal_element_share, model.material.density, o);
  Points x = model.prone;
  phi.solve(model.rest.V, model.unloaded_under, x);
  return phi.quadratic_nodes();
}

}  // namespace

struct QuadraticUnloadEquation::Factor {
  HessianLlt llt;
};

void RestShapeResponse::add(const GmresResult& g, Eigen::VectorXd dX_input) {
  iterations += g.iterations;
  worst_residual = std::max(worst_residual, g.relative_residual);
  converged = converged && g.converged;
  dX.push_back(std::move(dX_input));
}

QuadraticUnloadEquation::QuadraticUnloadEquation(const RegistrationModel& model, int quadrature_degree)
    : model_(model), degree_(quadrature_degree) {
  if (!(model.unloaded_under.norm() > 0)) throw InputError("quadratic unload equation: the model was not unloaded");
  mesh_ = make_quadratic_tets(model.rest.T, model.rest.V.rows());
  x_ = model.unloaded_nodes.rows() == mesh_.nodes() ? model.unloaded_nodes : solve_equilibrium(model, degree_);
  const std::vector<bool> wall = quadratic_fixed_nodes(mesh_, model.fixed);  // the forward model's fixed nodes
  const TotalEnergy energy = quadratic_energy(model, mesh_, model.rest.V, model.materials, degree_);
  free_ = std::make_unique<HessianAssembler>(static_cast<int>(mesh_.nodes()), model.rest.T, wall, energy.hessian_cliques());
  k_ = std::make_unique<Factor>();
  factorize_exact_or_projected(energy, x_, *free_, k_->llt, "quadratic unload equation: the Hessian at its equilibrium");
}

QuadraticUnloadEquation::~QuadraticUnloadEquation() = default;

Eigen::VectorXd QuadraticUnloadEquation::residual(const Points& X, const std::vector<StableNeoHookean>& materials,
                                                  const Points& x) const {
  return quadratic_energy(model_, mesh_, X, materials, degree_).gradient(x);
}

Eigen::VectorXd QuadraticUnloadEquation::apply(const Eigen::VectorXd& d) const {
  const double largest = d.cwiseAbs().maxCoeff();
  if (!(largest > 0)) return Eigen::VectorXd::Zero(d.size());
  const double eps = 1e-6 / largest;  // no node moved by more than 1 um
  const Points D = as_points(d);
  const Points dX = D.topRows(mesh_.corners);
  Points dm = D;
  dm.topRows(mesh_.corners).setZero();
  return (residual(model_.rest.V + eps * dX, model_.materials, x_ + eps * dm) -
          residual(model_.rest.V - eps * dX, model_.materials, x_ - eps * dm)) /
         (2 * eps);
}

Eigen::VectorXd QuadraticUnloadEquation::d_log_youngs_modulus() const {
  const double h = 1e-3, nu = model_.material.poisson_ratio;
  return (residual(model_.rest.V, materials_at(model_, nu, std::exp(h)), x_) -
          residual(model_.rest.V, materials_at(model_, nu, std::exp(-h)), x_)) /
         (2 * h);
}

Eigen::VectorXd QuadraticUnloadEquation::d_compliance() const {
  const double q0 = volume_compliance(model_.material.poisson_ratio), h = 1e-3 * q0;
  return (residual(model_.rest.V, materials_at(model_, poisson_ratio_of_compliance(q0 + h)), x_) -
          residual(model_.rest.V, materials_at(model_, poisson_ratio_of_compliance(q0 - h)), x_)) /
         (2 * h);
}

RestShapeResponse QuadraticUnloadEquation::rest_response(bool with_q) const {
  // On the 8 mm phantom at 1000 Pa 1e-4 gave the radii of 1e-6 to 0.01 mm in fewer products.
  constexpr double kTolerance = 1e-4;
  const Eigen::Index nodes = mesh_.nodes(), nc = mesh_.corners;
  const HessianAssembler& free = *free_;
  auto scatter = [&](const Eigen::VectorXd& reduced) {
    Eigen::VectorXd full = Eigen::VectorXd::Zero(3 * nodes);
    free.scatter_add(reduced, 1.0, full);
    return full;
  };
  auto apply_A = [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(free.gather(apply(scatter(v)))); };
  auto apply_Minv = [&](const Eigen::VectorXd& r) {  // L K^-1 r
    const Eigen::VectorXd y = scatter(k_->llt.solve(r));
    Eigen::VectorXd out = y;
    out.head(3 * nc) = -y.head(3 * nc);
    for (size_t e = 0; e < mesh_.edges.size(); ++e)
      out.segment<3>(3 * (nc + static_cast<Eigen::Index>(e))) -=
          0.5 * (y.segment<3>(3 * mesh_.edges[e][0]) + y.segment<3>(3 * mesh_.edges[e][1]));
    return Eigen::VectorXd(free.gather(out));
  };
  RestShapeResponse out;
  for (const Eigen::VectorXd& dR : {d_log_youngs_modulus(), with_q ? d_compliance() : Eigen::VectorXd::Zero(3 * nodes)}) {
    Eigen::VectorXd y;
    const GmresResult g = gmres(apply_A, apply_Minv, Eigen::VectorXd(-free.gather(dR)), kTolerance, 60, y);
    out.add(g, scatter(y).head(3 * nc));
  }
  return out;
}

}  // namespace btr
