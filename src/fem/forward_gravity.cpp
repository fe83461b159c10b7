#include "breast_tumour_registration/fem/forward_gravity.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/quadratic_elastic_energy.h"

namespace btr {

ForwardGravity::ForwardGravity(const Tetrahedra& T, Eigen::Index vertices, const std::vector<int>& fixed,
                               std::vector<StableNeoHookean> materials, std::vector<int> material_of,
                               VolumeForm volume_form, double nodal_element_share, double density,
                               ForwardGravityOptions options,
                               NewtonSolver* shared)
    : rest_{Points::Zero(vertices, 3), T},
      fixed_(static_cast<size_t>(vertices), false),
      materials_(std::move(materials)),
      material_of_(std::move(material_of)),
      volume_form_(volume_form),
      nodal_element_share_(nodal_element_share),
      density_(density),
      opt_(std::move(options)) {
  if (volume_form_ == VolumeForm::Auto) throw InputError("forward gravity: resolve the volume form first");
  if (!(opt_.first_load_fraction > 0 && opt_.first_load_fraction <= 1) || !(opt_.min_load_fraction > 0))
    throw InputError("forward gravity: load fractions must lie in (0, 1]");
  for (int v : fixed) {
    if (v < 0 || v >= vertices) throw InputError("forward gravity: fixed vertex " + std::to_string(v) + " out of range");
    fixed_[static_cast<size_t>(v)] = true;
  }
  if (opt_.element_order == ElementOrder::Quadratic) {
    quadratic_ = make_quadratic_tets(T, vertices);
    quadratic_fixed_ = quadratic_fixed_nodes(quadratic_, fixed_);
    bulge_ = Points::Zero(static_cast<Eigen::Index>(quadratic_.edges.size()), 3);
    (void)tet_quadrature(opt_.quadrature_degree);  // throws for a degree without a rule
    return;
  }
  if (shared) {
    const HessianAssembler& a = shared->assembler();
    bool same = a.num_vertices() == vertices;
    for (Eigen::Index v = 0; same && v < vertices; ++v) same = a.is_fixed(static_cast<int>(v)) == fixed_[static_cast<size_t>(v)];
    if (!same) throw InputError("forward gravity: the shared solver is bound to another mesh or fixed set");
    shared->forget_factor();
    solver_ = shared;
  }
}

NewtonResult ForwardGravity::solve_once(const Points& X, const Vec3& gravity, Points& x) {
  if (opt_.element_order == ElementOrder::Quadratic) return solve_once_quadratic(X, gravity, x);
  rest_.V = X;
  TotalEnergy energy;
  add_elastic_energy(energy, rest_, materials_, material_of_, volume_form_, nodal_element_share_);
  auto g = std::make_shared<GravityEnergy>(rest_, density_, gravity);
  energy.add(g);
  if (!solver_) {  // the pattern does not depend on the rest positions
    own_ = std::make_unique<NewtonSolver>(
        std::make_shared<HessianAssembler>(static_cast<int>(X.rows()), rest_.T, fixed_, energy.hessian_cliques()), rest_.T);
    solver_ = own_.get();
  }
  NewtonOptions nopt = opt_.newton;
  if (nopt.force_scale <= 0) nopt.force_scale = g->total_weight();
  for (Eigen::Index v = 0; v < X.rows(); ++v)
    if (fixed_[static_cast<size_t>(v)]) x.row(v) = X.row(v);
  NewtonResult nr = solver_->solve(energy, x, nopt);
  newton_iterations_ += nr.iterations;
  nr.history.clear();
  last_ = nr;
  return nr;
}

NewtonResult ForwardGravity::solve_once_quadratic(const Points& X, const Vec3& gravity, Points& x) {
  const Eigen::Index nc = quadratic_.corners;
  TotalEnergy energy;
  auto elastic = std::make_shared<QuadraticElasticEnergy>(quadratic_, X, materials_, material_of_, opt_.quadrature_degree,
                                                          opt_.quadratic_volume);
  auto g = std::make_shared<GravityEnergy>(elastic->consistent_masses(density_), gravity);
  energy.add(elastic);
  energy.add(g);
  if (!solver_) {  // the pattern couples each element's 10 nodes; inversions are its Jacobian's (inversion_check.h)
    own_ = std::make_unique<NewtonSolver>(
        std::make_shared<HessianAssembler>(static_cast<int>(quadratic_.nodes()), rest_.T, quadratic_fixed_,
                                           energy.hessian_cliques()),
        InversionCheck::quadratic(quadratic_, opt_.quadrature_degree));
    solver_ = own_.get();
  }
  const Points X2 = straight_sided_positions(quadratic_, X);
  Points x2 = straight_sided_positions(quadratic_, x);
  x2.bottomRows(bulge_.rows()) += bulge_;
  for (Eigen::Index v = 0; v < x2.rows(); ++v)
    if (quadratic_fixed_[static_cast<size_t>(v)]) x2.row(v) = X2.row(v);
  NewtonOptions nopt = opt_.newton;
  if (nopt.force_scale <= 0) nopt.force_scale = g->total_weight();
  NewtonResult nr = solver_->solve(energy, x2, nopt);
  newton_iterations_ += nr.iterations;
  nr.history.clear();
  last_ = nr;
  x = x2.topRows(nc);
  if (nr.converged) {
    bulge_ = x2.bottomRows(bulge_.rows()) - straight_sided_positions(quadratic_, x).bottomRows(bulge_.rows());
    quadratic_x_ = x2;
  }
  return nr;
}

int ForwardGravity::solve(const Points& X, const Vec3& gravity, Points& x) {
  if (X.rows() != static_cast<Eigen::Index>(fixed_.size()) || x.rows() != X.rows())
    throw InputError("forward gravity: " + std::to_string(X.rows()) + " rest and " + std::to_string(x.rows()) +
                     " start positions for a mesh of " + std::to_string(fixed_.size()) + " vertices");
  const Points start = x;
  const Points start_bulge = bulge_;
  NewtonResult nr = solve_once(X, gravity, x);
  if (nr.converged) return nr.iterations;
  int n = nr.iterations;
  x = X;  // continuation from the unloaded state
  bulge_.setZero();
  double s = 0, ds = opt_.first_load_fraction;
  while (s < 1) {
    const double next = std::min(1.0, s + ds);
    Points xs = x;
    nr = solve_once(X, next * gravity, xs);
    n += nr.iterations;
    continuation_steps_.emplace_back(next, nr.converged);
    if (nr.converged) {
      x = xs;
      s = next;
      ++load_steps_;
      ds *= 1.5;
    } else {
      ds = 0.5 * (next - s);  // half the step that failed (ds may reach past the full load)
      if (ds < opt_.min_load_fraction) {
        x = start;
        bulge_ = start_bulge;
        throw SolverError("forward gravity solve stopped without converging at " +
                          std::to_string(static_cast<int>(std::lround(next * 100))) + " % of the load (" +
                          to_string(nr.reason) + ")");
      }
    }
  }
  return n;
}

}  // namespace btr
