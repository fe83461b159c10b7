#include "breast_tumour_registration/core/gravity_simulation.h"

#include <memory>

#include "breast_tumour_registration/core/elastic_energy.h"
#include "breast_tumour_registration/core/errors.h"
#include "breast_tumour_registration/core/gravity_energy.h"

namespace btr {

GravityResult solve_gravity(const GravityProblem& pb, const NewtonOptions& options) {
  if (!pb.rest) throw InputError("solve_gravity: no rest mesh");
  const TetMesh& rest = *pb.rest;
  std::vector<bool> fixed(rest.V.rows(), false);
  for (int v : pb.fixed) {
    if (v < 0 || v >= rest.V.rows()) throw InputError("solve_gravity: fixed vertex " + std::to_string(v) + " out of range");
    fixed[v] = true;
  }
  TotalEnergy energy;
  std::vector<StableNeoHookean> materials{StableNeoHookean(pb.youngs_modulus, pb.poisson_ratio)};
  std::vector<int> material_of;
  if (!pb.inclusion.empty()) {
    materials.push_back(StableNeoHookean(pb.inclusion_youngs_modulus, pb.poisson_ratio));
    material_of.assign(rest.T.rows(), 0);
    for (int t : pb.inclusion) {
      if (t < 0 || t >= rest.T.rows()) throw InputError("solve_gravity: inclusion tetrahedron out of range");
      material_of[t] = 1;
    }
  }
  add_elastic_energy(energy, rest, materials, material_of, resolve_volume_form(pb.volume_form, pb.poisson_ratio));
  auto gravity = std::make_shared<GravityEnergy>(rest, pb.density, pb.gravity);
  energy.add(gravity);
  auto assembler =
      std::make_shared<HessianAssembler>(static_cast<int>(rest.V.rows()), rest.T, fixed, energy.hessian_cliques());
  NewtonSolver solver(assembler, rest.T);
  GravityResult r;
  r.x = rest.V;
  NewtonOptions opt = options;
  if (opt.force_scale <= 0) opt.force_scale = gravity->total_weight();
  r.newton = solver.solve(energy, r.x, opt);
  return r;
}

}  // namespace btr
