// btr_bench_gravity: times the quasi-static gravity solve of the phantom at one mesh
// resolution, repeated; prints medians over the repeats (per-iteration assembly, solve and
// line search; factorization as a total per solve, since later iterations reuse the factor
// through PCG) as one Markdown table row. Run under /usr/bin/time -v for peak memory.
//   btr_bench_gravity --cell-size 4 --repeats 5 [--youngs-modulus 3400] [--direction supine]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/fem/gravity_simulation.h"
#include "breast_tumour_registration/simulation/phantom.h"

using namespace btr;

static double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

int main(int argc, char** argv) {
  CLI::App app{"Benchmark the phantom gravity solve at one resolution (medians over repeats)."};
  double cell_mm = 4, E = 3400;
  int repeats = 5;
  std::string direction = "prone";
  bool header = false;
  app.add_option("--cell-size", cell_mm, "tetrahedron size bound [mm]")->capture_default_str();
  app.add_option("--repeats", repeats, "number of timed solves")->capture_default_str();
  app.add_option("-E,--youngs-modulus", E, "[Pa]")->capture_default_str();
  app.add_option("--direction", direction, "prone (+z gravity) or supine (-z)")->capture_default_str();
  bool no_reuse = false;
  app.add_flag("--no-reuse", no_reuse, "factorize every Newton iteration (no lagged-factor PCG)");
  app.add_flag("--header", header, "print the Markdown table header first");
  CLI11_PARSE(app, argc, argv);
  try {
    PhantomOptions po;
    po.tet.cell_size = mm_to_m(cell_mm);
    auto t0 = std::chrono::steady_clock::now();
    const PhantomModel model = make_phantom_model(po);
    const double t_mesh = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    GravityProblem pb;
    pb.rest = &model.rest;
    pb.fixed = model.chest_wall;
    pb.youngs_modulus = E;
    pb.gravity = Vec3(0, 0, direction == "supine" ? -9.81 : 9.81);
    std::vector<double> total, asm_it, fac, sol_it, ls_it;
    int iters = 0, factorizations = 0, pcg = 0;
    double gnorm = 0;
    for (int r = 0; r < repeats; ++r) {
      NewtonOptions opt;
      opt.reuse_factorization = !no_reuse;
      const GravityResult res = solve_gravity(pb, opt);
      if (!res.newton.converged) throw SolverError("did not converge: " + to_string(res.newton.reason));
      iters = res.newton.iterations;
      factorizations = res.newton.factorizations;
      pcg = res.newton.pcg_iterations;
      gnorm = res.newton.gradient_norm;
      total.push_back(res.newton.seconds);
      fac.push_back(res.newton.t_factorization);  // includes CHOLMOD's symbolic analysis
      for (const auto& it : res.newton.history) {
        asm_it.push_back(it.t_assembly);
        sol_it.push_back(it.t_solve);
        ls_it.push_back(it.t_line_search);
      }
    }
    if (header) {
      std::printf("| cell size [mm] | vertices | tets | mesh [s] | Newton its | factorizations | PCG its | assembly/it [ms] | "
                  "factorization total [ms] | solve/it [ms] | line search/it [ms] | total [s] | final grad [N] |\n");
      std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    }
    std::printf("| %.1f | %ld | %ld | %.2f | %d | %d | %d | %.1f | %.0f | %.1f | %.1f | %.3f | %.1e |\n", cell_mm,
                static_cast<long>(model.rest.V.rows()), static_cast<long>(model.rest.T.rows()), t_mesh, iters,
                factorizations, pcg, 1e3 * median(asm_it), 1e3 * median(fac), 1e3 * median(sol_it), 1e3 * median(ls_it),
                median(total), gnorm);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_bench_gravity: %s\n", e.what());
    return 1;
  }
}
