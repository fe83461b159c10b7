// Probe (issue 13): where the nodal volume term's time goes. On a scene's simulation mesh
// (balanced preset) it times, per Hessian assembly, the element form's elastic Hessian, the
// nodal form's two terms (shear ElasticEnergy + NodalVolumeEnergy), and one numeric Cholesky
// factorization of each pattern (CHOLMOD through NewtonSolver's path is internal, so this
// uses Eigen's SimplicialLLT on the assembled matrix: a ratio, not the solver's own time).
//   nodal_assembly SCENE.yaml [repeats]
// Build as bench/probes/suite_run_trace.cpp (same libraries).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <Eigen/SparseCholesky>

#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/hessian_pattern.h"
#include "breast_tumour_registration/fem/nodal_volume_energy.h"
#include "breast_tumour_registration/registration/registration_engine.h"

using namespace btr;
using Clock = std::chrono::steady_clock;

template <class F>
double median_seconds(int repeats, F f) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = Clock::now();
    f();
    t.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: nodal_assembly SCENE.yaml [repeats]\n");
    return 2;
  }
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 21;
  RegistrationEngine engine(load_scene(argv[1]));
  const RegistrationModel& m = engine.prepare(preset_options("balanced")).model;
  const int nv = static_cast<int>(m.rest.V.rows());
  // A deformed state: the rest shape sagged a little, so the pressures are not zero.
  Points x = m.rest.V;
  for (int v = 0; v < nv; ++v) x(v, 2) -= 1e-3 * std::sin(40 * x(v, 0)) * std::cos(30 * x(v, 1));

  std::vector<StableNeoHookean> shear;
  for (const auto& mat : m.materials) shear.push_back(mat.shear_part());
  std::vector<double> lambda(m.rest.T.rows());
  for (Eigen::Index t = 0; t < m.rest.T.rows(); ++t) lambda[t] = m.materials[m.material_of[t]].lambda();
  const ElasticEnergy element(m.rest, m.materials, m.material_of), shear_only(m.rest, shear, m.material_of);
  const NodalVolumeEnergy nodal(m.rest, lambda), combined(m.rest, lambda, shear, m.material_of);

  HessianAssembler He(nv, m.rest.T, m.fixed), Hn(nv, m.rest.T, m.fixed, nodal.hessian_cliques());
  const double t_el = median_seconds(repeats, [&] { He.set_zero(); element.add_hessian(x, true, He); });
  const double t_sh = median_seconds(repeats, [&] { Hn.set_zero(); shear_only.add_hessian(x, true, Hn); });
  const double t_nv = median_seconds(repeats, [&] { nodal.add_hessian(x, true, Hn); });
  const double t_co = median_seconds(repeats, [&] { Hn.set_zero(); combined.add_hessian(x, true, Hn); });
  Hn.set_zero();
  shear_only.add_hessian(x, true, Hn);
  nodal.add_hessian(x, true, Hn);
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> lle, lln;
  lle.analyzePattern(He.matrix());
  lln.analyzePattern(Hn.matrix());
  const int fr = std::max(3, repeats / 4);
  const double f_el = median_seconds(fr, [&] { lle.factorize(He.matrix()); });
  const double f_nv = median_seconds(fr, [&] { lln.factorize(Hn.matrix()); });
  std::printf("mesh: %d vertices, %ld tetrahedra, %d free DOFs\n", nv, static_cast<long>(m.rest.T.rows()), He.num_free_dofs());
  std::printf("nonzeros: element %ld, nodal %ld (%.2fx)\n", static_cast<long>(He.matrix().nonZeros()),
              static_cast<long>(Hn.matrix().nonZeros()), double(Hn.matrix().nonZeros()) / He.matrix().nonZeros());
  std::printf("assembly [ms, median of %d]: element %.2f; nodal: shear %.2f + volume %.2f = %.2f (%.2fx)\n", repeats,
              1e3 * t_el, 1e3 * t_sh, 1e3 * t_nv, 1e3 * (t_sh + t_nv), (t_sh + t_nv) / t_el);
  std::printf("assembly [ms, median of %d]: nodal as one term (shear part included) %.2f (%.2fx)\n", repeats, 1e3 * t_co,
              t_co / t_el);
  std::printf("factorization (Eigen SimplicialLLT) [ms, median of %d]: element %.1f, nodal %.1f (%.2fx)\n", fr, 1e3 * f_el,
              1e3 * f_nv, f_nv / f_el);
}
