// btr_bench_tradeoff: the speed/accuracy trade of the registration on a phantom scene whose
// ground truth was generated on its own (fine) mesh. It sweeps what a user can turn: the
// simulation mesh (the prone model re-tetrahedralized at a cell size), the subspace size,
// the landmark step's tolerance, the surface step's projection budget, and the presets; for
// each point it writes one CSV row: median registration seconds over the repeats (the cost
// of a service call once the model is prepared), the one-off preparation seconds, and the
// worst and mean tumour centroid error. Plot with bench/plot_tradeoff.py.
// A mesh is one draw: a 1 % change of cell size moves the worst tumour by up to 0.28 mm on
// SfePy's bodies (BENCHMARKS.md, "One mesh is one draw"). --mesh-draws N runs each point with a
// cell size at N sizes spread evenly over +-(--mesh-jitter) of it and reports the medians and
// the worst error's range over them.
//   btr_bench_tradeoff SCENE.yaml --repeats 3 --out tradeoff.csv [--mesh-draws 5]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <vector>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"

using namespace btr;

namespace {

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

struct Point {
  std::string knob, value, base;  // what was turned, to what, from which preset
  double cell_mm = 0;             // 0: the scene's own mesh
  RegistrationOptions opt;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Sweep the registration's speed/accuracy knobs on a phantom scene; one CSV row per setting."};
  std::string scene_path, out_path = "tradeoff.csv";
  int repeats = 3;
  std::vector<double> cells = {14, 11, 9, 7, 5.5, 4.5};
  app.add_option("scene", scene_path, "scene with ground-truth tumours (btr_phantom)")->required();
  app.add_option("--repeats", repeats, "timed registrations per setting (median)")->capture_default_str();
  app.add_option("--cell-sizes", cells, "simulation mesh cell sizes to sweep [mm]");
  app.add_option("-o,--out", out_path, "CSV file")->capture_default_str();
  int mesh_draws = 1;
  double mesh_jitter = 0.01;
  app.add_option("--mesh-draws", mesh_draws, "meshes per point with a cell size (sizes spread over +-jitter)")
      ->check(CLI::Range(1, 99))
      ->capture_default_str();
  app.add_option("--mesh-jitter", mesh_jitter, "relative spread of the draws' cell sizes")
      ->check(CLI::Range(0.0, 0.2))
      ->capture_default_str();
  std::vector<std::string> base_presets = {"fast", "balanced", "accurate"};
  app.add_option("--base-presets", base_presets, "the presets whose cell_size_mm and preset points are swept")
      ->check(CLI::IsMember({"fast", "balanced", "accurate"}))
      ->capture_default_str();
  std::vector<std::string> knobs;
  app.add_option("--knobs", knobs, "sweep only these: cell_size_mm preset subspace_handles landmark_tolerance max_projections anderson_depth projection_tolerance target_normals");
  CLI11_PARSE(app, argc, argv);
  try {
    // A prone surface is meshed once per cell size, at that size, as btr_register and the engine
    // mesh it (before 2026-12-06, eighth session, it was meshed at its own size first and then
    // re-tetrahedralized: another mesh than a user's call simulates); a tetrahedral prone model
    // is re-tetrahedralized at each size.
    const Scene scene = load_scene(scene_path);
    const auto simulation_scene = [&scene](double cell_mm, double tumour_cells) {
      Scene s = scene;
      if (s.prone_source)
        mesh_prone(s, cell_mm > 0 ? mm_to_m(cell_mm) : s.prone_source->cell_size.value_or(kDefaultCellSize), tumour_cells);
      else if (cell_mm > 0)
        s = with_simulation_mesh(s, mm_to_m(cell_mm), tumour_cells);
      return s;
    };
    std::vector<Point> points;
    for (const std::string& preset : base_presets) {
      for (double c : cells) points.push_back({"cell_size_mm", fmt(c), preset, c, preset_options(preset)});
      // The preset as a user gets it: with its own simulation mesh (the scene's when 0).
      const RegistrationOptions po = preset_options(preset);
      points.push_back({"preset", preset, preset, po.simulation_cell_size * 1e3, po});
    }
    for (double c : {0.0, 7.0}) {  // solver knobs on the scene's mesh and on a coarse one
      for (int h : {10, 20, 40, 60, 100, 160}) {
        Point p{"subspace_handles", std::to_string(h), "balanced", c, preset_options("balanced")};
        p.opt.landmark.subspace.handles = h;
        points.push_back(p);
      }
      for (double tol : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6}) {
        Point p{"landmark_tolerance", fmt(tol), "balanced", c, preset_options("balanced")};
        p.opt.landmark.newton.gradient_rel_tolerance = tol;
        p.opt.landmark.newton.max_iterations = 50;
        points.push_back(p);
      }
      for (int k : {1, 2, 3, 4, 6, 10, 20, 40}) {
        Point p{"max_projections", std::to_string(k), "balanced", c, preset_options("balanced")};
        p.opt.surface.max_projections = k;
        points.push_back(p);
      }
      for (int d : {0, 2, 5, 8}) {  // 0: the thesis's plain projection/Newton alternation
        Point p{"anderson_depth", std::to_string(d), "balanced", c, preset_options("balanced")};
        p.opt.surface.anderson_depth = d;
        points.push_back(p);
      }
      for (const MeshNormals n : {MeshNormals::Face, MeshNormals::Interpolated}) {  // the point-to-plane springs' normal
        Point p{"target_normals", n == MeshNormals::Face ? "face" : "interpolated", "balanced", c, preset_options("balanced")};
        p.opt.surface.target_normals = n;
        points.push_back(p);
      }
      for (double tol : {4e-4, 2e-4, 1e-4, 5e-5, 2e-5}) {  // the surface step's distance to its fixed point [m]
        Point p{"projection_tolerance", fmt(tol * 1e3), "balanced", c, preset_options("balanced")};
        p.opt.surface.projection_tolerance = tol;
        points.push_back(p);
      }
    }
    if (!knobs.empty())
      points.erase(std::remove_if(points.begin(), points.end(),
                                  [&](const Point& p) { return std::find(knobs.begin(), knobs.end(), p.knob) == knobs.end(); }),
                   points.end());
    std::ofstream csv(out_path);
    if (!csv) throw InputError("cannot write '" + out_path + "'");
    csv << "knob,value,base_preset,cell_size_mm,tetrahedra,prepare_seconds,seconds_median,worst_error_mm,mean_error_mm,"
           "converged,volume_form,mesh_draws,worst_error_min_mm,worst_error_max_mm\n";
    // One engine per simulation mesh (cell size, and the preset's tumour cells; as the node keeps
    // it): prepared once, solved repeatedly.
    std::map<std::pair<double, double>, std::unique_ptr<RegistrationEngine>> engines;
    std::map<std::pair<double, double>, double> prepare_seconds;
    for (const Point& p : points) {
      // The point's cell sizes: its own, or mesh_draws sizes over +-mesh_jitter of it.
      std::vector<double> sizes{p.cell_mm};
      if (p.cell_mm > 0 && mesh_draws > 1) {
        sizes.clear();
        for (int k = 0; k < mesh_draws; ++k)
          sizes.push_back(p.cell_mm * (1 + mesh_jitter * (2.0 * k / (mesh_draws - 1) - 1)));
      }
      std::vector<double> secs, worsts, means, tets, prepares;
      int converged = 0;
      std::string forms;
      for (double c : sizes) {
        const std::pair<double, double> mesh{c, tumour_cell_size_for(scene, p.opt)};
        if (!engines.count(mesh)) {
          const auto t0 = std::chrono::steady_clock::now();
          Scene s = simulation_scene(mesh.first, mesh.second);
          std::vector<std::string> warnings;
          RegistrationModel m = prepare_model(s, warnings);
          prepare_seconds[mesh] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          engines.emplace(mesh, std::make_unique<RegistrationEngine>(std::move(s), std::move(m), std::move(warnings)));
        }
        RegistrationEngine& engine = *engines.at(mesh);
        tets.push_back(static_cast<double>(engine.prepare(p.opt).model.rest.T.rows()));
        prepares.push_back(prepare_seconds[mesh]);
        std::vector<double> draw_secs;
        RegistrationResult r;
        for (int i = 0; i < repeats; ++i) {
          r = engine.solve(p.opt);
          draw_secs.push_back(r.seconds);
        }
        secs.push_back(median(draw_secs));
        double worst = 0, mean = 0;
        for (const auto& t : r.tumours) {
          worst = std::max(worst, t.centroid_distance * 1e3);
          mean += t.centroid_distance * 1e3 / static_cast<double>(r.tumours.size());
        }
        worsts.push_back(worst);
        means.push_back(mean);
        converged += r.converged ? 1 : 0;
        const std::string form = r.volume_form_fallback ? "element_fallback" : to_string(r.volume_form);
        if (forms.find(form) == std::string::npos) forms += (forms.empty() ? "" : "+") + form;
        if (sizes.size() > 1)
          std::printf("  draw at %.3f mm: %.0f tets, %.3f s, worst %.3f mm%s\n", c, tets.back(), secs.back(), worst,
                      r.converged ? "" : " (not converged)");
        if (r.volume_form_fallback) std::printf("  (the nodal form did not converge: the element form's result)\n");
      }
      const int n = static_cast<int>(sizes.size());
      csv << p.knob << ',' << p.value << ',' << p.base << ',' << p.cell_mm << ',' << median(tets) << ','
          << median(prepares) << ',' << median(secs) << ',' << median(worsts) << ',' << median(means) << ','
          << (converged == n ? 1 : 0) << ',' << forms << ',' << n << ','
          << *std::min_element(worsts.begin(), worsts.end()) << ',' << *std::max_element(worsts.begin(), worsts.end()) << '\n';
      csv.flush();
      std::printf("%-18s %-10s %-8s cell %4.1f mm %6.0f tets: %.3f s, worst %.3f mm, mean %.3f mm%s\n", p.knob.c_str(),
                  p.value.c_str(), p.base.c_str(), p.cell_mm, median(tets), median(secs), median(worsts), median(means),
                  converged == n ? "" : (" (" + std::to_string(n - converged) + " of " + std::to_string(n) + " not converged)").c_str());
      std::fflush(stdout);
    }
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "btr_bench_tradeoff: invalid input: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_bench_tradeoff: error: %s\n", e.what());
    return 1;
  }
}
