#include "breast_tumour_registration/fem/gravity_simulation.h"

#include <memory>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/gravity_energy.h"

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
  for (double E : pb.region_youngs_modulus) materials.push_back(StableNeoHookean(E, pb.poisson_ratio));
  // ElasticEnergy checks material_of's size and range.
  add_elastic_energy(energy, rest, materials, pb.material_of, resolve_volume_form(pb.volume_form, pb.poisson_ratio),
                     pb.nodal_element_share);
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
