// What the registration steps keep between calls on one prepared model (RegistrationEngine):
// one Newton solver per step and pose mode, each bound to its Hessian pattern with CHOLMOD's
// symbolic analysis done once, and the landmark step's skinning subspace. A cached piece is
// handed out only while what it was built from is unchanged (the mesh, the fixed vertices and
// the constraint cliques; for the subspace the rest shape, the seeds and the options), and is
// rebuilt otherwise, so a cache can never change an answer: a reused solver starts without the
// numeric factor of an earlier problem, as a new one would.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "breast_tumour_registration/fem/newton_solver.h"
#include "breast_tumour_registration/fem/skinning_subspace.h"
#include "breast_tumour_registration/registration/registration_model.h"

namespace btr {

class StepSolvers {
 public:
  /// The solver for `key` (a step and pose mode, e.g. "surface (pose free)") on the model's
  /// mesh and fixed vertices with these extra cliques: the cached one when its pattern is the
  /// same (its symbolic analysis is kept, its numeric factor dropped), otherwise a new one.
  NewtonSolver& newton(const std::string& key, const RegistrationModel& model,
                       const std::vector<std::vector<int>>& cliques);
  /// The solver of the model's elastic energy plus gravity (key "gravity"): the gravity step's,
  /// and every forward gravity solve of the unload and stiffness estimates.
  NewtonSolver& gravity(const RegistrationModel& model);
  /// The same, for a caller that has built that energy already: `cliques` are its Hessian cliques.
  NewtonSolver& gravity(const RegistrationModel& model, const std::vector<std::vector<int>>& cliques);
  /// The subspace of build_skinning_subspace(model.rest.V, model.volume, seeds, model.fixed, opt),
  /// cached while those inputs are unchanged.
  const SkinningSubspace& subspace(const RegistrationModel& model, const std::vector<int>& seeds,
                                   const SubspaceOptions& opt);

  int built() const { return built_; }    ///< solvers and subspaces built
  int reused() const { return reused_; }  ///< handed out from the cache

 private:
  struct Pattern {
    long vertices = 0;
    Tetrahedra T;
    std::vector<bool> fixed;
    std::vector<std::vector<int>> cliques;
    std::unique_ptr<NewtonSolver> solver;
  };
  struct Subspace {
    Points rest;
    double volume = 0;
    std::vector<int> seeds;
    std::vector<bool> fixed;
    int handles = 0;
    double sigma = 0;
    SkinningSubspace subspace;
  };
  std::map<std::string, Pattern> solvers_;
  std::unique_ptr<Subspace> subspace_;
  int built_ = 0, reused_ = 0;
};

}  // namespace btr
