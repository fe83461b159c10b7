#include "breast_tumour_registration/registration/step_solvers.h"

#include "breast_tumour_registration/fem/total_energy.h"

namespace btr {
namespace {

bool same(const Tetrahedra& a, const Tetrahedra& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && (a.rows() == 0 || (a.array() == b.array()).all());
}
bool same(const Points& a, const Points& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && (a.rows() == 0 || (a.array() == b.array()).all());
}

}  // namespace

NewtonSolver& StepSolvers::newton(const std::string& key, const RegistrationModel& model,
                                  const std::vector<std::vector<int>>& cliques) {
  const long n = static_cast<long>(model.rest.V.rows());
  auto it = solvers_.find(key);
  if (it != solvers_.end()) {
    Pattern& p = it->second;
    if (p.vertices == n && same(p.T, model.rest.T) && p.fixed == model.fixed && p.cliques == cliques) {
      ++reused_;
      p.solver->forget_factor();
      return *p.solver;
    }
  }
  Pattern p;
  p.vertices = n;
  p.T = model.rest.T;
  p.fixed = model.fixed;
  p.cliques = cliques;
  p.solver = std::make_unique<NewtonSolver>(
      std::make_shared<HessianAssembler>(static_cast<int>(n), model.rest.T, model.fixed, cliques), model.rest.T);
  ++built_;
  Pattern& stored = solvers_[key] = std::move(p);
  return *stored.solver;
}

NewtonSolver& StepSolvers::gravity(const RegistrationModel& model) {
  TotalEnergy elastic;  // gravity adds no cliques
  add_model_elastic_energy(elastic, model);
  return gravity(model, elastic.hessian_cliques());
}

NewtonSolver& StepSolvers::gravity(const RegistrationModel& model, const std::vector<std::vector<int>>& cliques) {
  return newton("gravity", model, cliques);
}

const SkinningSubspace& StepSolvers::subspace(const RegistrationModel& model, const std::vector<int>& seeds,
                                              const SubspaceOptions& opt) {
  if (subspace_ && same(subspace_->rest, model.rest.V) && subspace_->volume == model.volume && subspace_->seeds == seeds &&
      subspace_->fixed == model.fixed && subspace_->handles == opt.handles && subspace_->sigma == opt.sigma) {
    ++reused_;
    return subspace_->subspace;
  }
  auto s = std::make_unique<Subspace>();
  s->rest = model.rest.V;
  s->volume = model.volume;
  s->seeds = seeds;
  s->fixed = model.fixed;
  s->handles = opt.handles;
  s->sigma = opt.sigma;
  s->subspace = build_skinning_subspace(model.rest.V, model.volume, seeds, model.fixed, opt);
  ++built_;
  subspace_ = std::move(s);
  return subspace_->subspace;
}

}  // namespace btr
