#include "breast_tumour_registration/registration/landmark_step.h"

#include <algorithm>
#include <chrono>

#include <memory>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/spring_energy.h"
#include "breast_tumour_registration/fem/rigid_free_landmark_energy.h"
#include "breast_tumour_registration/fem/subspace_solver.h"

namespace btr {

StepReport landmark_step(const RegistrationModel& model, const std::vector<Anchor>& anchors, const Points& targets,
                         const LandmarkStepOptions& opt, Points& x, const StepCallback& callback, Rigid* pose,
                         StepSolvers* cache) {
  const auto t0 = std::chrono::steady_clock::now();
  if (anchors.empty()) throw InputError("landmark step: no landmarks");
  if (static_cast<Eigen::Index>(anchors.size()) != targets.rows())
    throw InputError("landmark step: " + std::to_string(anchors.size()) + " prone landmarks but " +
                     std::to_string(targets.rows()) + " supine targets");
  TotalEnergy energy;
  add_model_elastic_energy(energy, model);
  auto gravity = std::make_shared<GravityEnergy>(model.rest, model.material.density, model.gravity);
  if (opt.gravity) energy.add(gravity);
  auto springs = std::make_shared<SpringEnergy>("landmarks");
  std::vector<int> seeds;
  std::vector<std::vector<int>> cliques;
  for (size_t i = 0; i < anchors.size(); ++i) {
    if (!pose) springs->add_point(anchors[i], targets.row(i).transpose(), opt.weight);
    // Seed the sampling with the anchor's dominant vertex (thesis: landmarks first).
    int best = 0;
    for (int k = 1; k < anchors[i].count; ++k)
      if (anchors[i].w[k] > anchors[i].w[best]) best = k;
    if (!model.fixed[anchors[i].v[best]]) seeds.push_back(anchors[i].v[best]);
    cliques.emplace_back(anchors[i].v, anchors[i].v + anchors[i].count);
  }
  // One handle per distinct vertex, and no more seeds than the subspace has handles: every
  // landmark row used to add a handle (500 rows: 83 s and 0.9 GB; 20 000: out of memory).
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  std::string note;
  if (static_cast<int>(seeds.size()) > opt.subspace.handles) {
    note = std::to_string(seeds.size()) + " landmark vertices, more than the subspace's " +
           std::to_string(opt.subspace.handles) + " handles: the first " + std::to_string(opt.subspace.handles) +
           " seed it (every landmark still pulls)";
    seeds.resize(static_cast<size_t>(opt.subspace.handles));
  }
  std::shared_ptr<RigidFreeLandmarkEnergy> free_springs;
  if (pose) {
    free_springs = std::make_shared<RigidFreeLandmarkEnergy>(opt.weight, anchors, targets);
    energy.add(free_springs);
    cliques = {free_springs->clique()};
  } else {
    energy.add(springs);
  }
  StepSolvers local;  // without an engine's cache: built for this call only
  StepSolvers& solvers = cache ? *cache : local;
  const SkinningSubspace& S = solvers.subspace(model, seeds, opt.subspace);
  HessianAssembler& H = solvers.newton(pose ? "landmark (pose free)" : "landmark", model, energy.hessian_cliques(cliques)).assembler();
  NewtonOptions nopt = opt.newton;
  if (nopt.force_scale <= 0) nopt.force_scale = gravity->total_weight();
  if (callback) nopt.callback = [&](const IterationInfo& it) { return callback("landmark", it); };
  const NewtonResult r = solve_subspace_newton(energy, H, S.basis, model.rest.T, x, nopt);
  if (pose) *pose = free_springs->pose(x);
  StepReport rep;
  rep.name = pose ? "landmark (pose free)" : "landmark";
  rep.note = note;
  rep.converged = r.converged;
  rep.stop_reason = to_string(r.reason);
  rep.iterations = r.iterations;
  rep.seconds = r.seconds;
  rep.add_newton_profile(r);
  rep.t_setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() - r.seconds;
  rep.energy = r.energy;
  rep.gradient_norm = r.gradient_norm;
  return rep;
}

}  // namespace btr
