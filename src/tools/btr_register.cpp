// btr_register: runs the prone-to-supine registration of a scene file (YAML) and writes the
// registered meshes, tumours, report.json and cross_section.png.
#include <CLI/CLI.hpp>

#include "breast_tumour_registration/cli_checks.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <unistd.h>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/simulation/registration_report.h"

using namespace btr;

int main(int argc, char** argv) {
  CLI::App app{
      "Deform the prone breast model of a scene into the supine position (Yeh 2023: rigid alignment, landmark-guided\n"
      "subspace step, surface-guided step) and write the registered tumour(s), meshes, report.json and a PNG.\n"
      "Exit codes: 0 converged, 2 invalid input, 3 numerical failure, 4 finished without converging (outputs written),\n"
      "5 converged but implausible: a landmark or the skin ends far from its data, or the rigid pose was undecided\n"
      "(outputs written; the warnings say which)."};
  std::string scene_path, out_dir = "registration", preset, steps, uncertainty = "none";
  int samples = 32;
  unsigned seed = 1;
  double tumour_E = 0, cell_mm = -1;
  bool quiet = false;
  app.add_option("scene", scene_path, "scene file (YAML), e.g. written by btr_phantom")->required();
  app.add_option("-o,--out", out_dir, "output folder (created)")->capture_default_str();
  app.add_option("-p,--preset", preset, "fast, balanced or accurate (default: the scene's, else balanced)");
  app.add_option("-s,--steps", steps, "override the scene's steps: auto, or a comma list of rigid,gravity,landmarks,surface");
  app.add_option("--tumour-youngs-modulus", tumour_E, "give tumour elements this Young's modulus [Pa] (stiffer tumour)")
      ->check(btr::cli::positive());
  app.add_option("--cell-size", cell_mm,
                 "simulate on the prone model (re-)tetrahedralized at this cell size [mm] (default: a prone surface's "
                 "prone.cell_size_mm, else the preset's; 0: the scene's mesh as given)")
      ->check(btr::cli::non_negative());
  app.add_option("--uncertainty", uncertainty,
                 "none; linear (calibrated where the pose is solved with the deformation, over-wide where a chest ring sets it: README.md, issue 14): each tumour centroid's covariance and 95 % radius "
                 "from the Young's modulus, Poisson's ratio, the gravity direction, the depth noise, the rigid pose where "
                 "ICP sets it and the landmarks where the pose is solved with the deformation; "
                 "sampling: "
                 "the same from re-registrations with every source sampled (Young's modulus, Poisson's ratio, gravity "
                 "direction, landmarks, depth noise), beside the linear figures. The distributions are the scene's "
                 "`uncertainty:` section, else the defaults (README.md, \"The scene file\")")
      ->check(CLI::IsMember({"none", "linear", "sampling"}))
      ->capture_default_str();
  app.add_option("--samples", samples, "with --uncertainty sampling: re-registrations with sampled inputs (the linear "
                                       "figures are computed too, for comparison)")
      ->check(CLI::Range(2, 100000))
      ->capture_default_str();
  app.add_option("--seed", seed, "with --uncertainty sampling: random seed")->capture_default_str();
  app.add_flag("-q,--quiet", quiet, "no progress display");
  if (const int rc = btr::cli::parse(app, argc, argv); rc >= 0) return rc;

  const bool tty = isatty(fileno(stdout));
  try {
    auto t0 = std::chrono::steady_clock::now();
    prepare_output_folder(out_dir);
    Scene scene = load_scene(scene_path);  // a prone surface is meshed once, by the engine, at the size the call simulates
    if (!preset.empty()) scene.preset = preset;
    if (!steps.empty()) {
      scene.steps.clear();
      if (steps != "auto") {
        std::stringstream ss(steps);
        std::string s;
        while (std::getline(ss, s, ','))
          if (s == "rigid" || s == "gravity" || s == "landmarks" || s == "surface") scene.steps.push_back(s);
          else throw InputError("--steps: unknown step '" + s + "' (rigid, gravity, landmarks, surface)");
      }
    }
    if (tumour_E > 0) scene.tumour_youngs_modulus = tumour_E;
    RegistrationOptions opt = preset_options(scene.preset);
    if (cell_mm >= 0) opt.simulation_cell_size = opt.nodal_simulation_cell_size = mm_to_m(cell_mm);  // whatever the form
    opt.uncertainty.enabled = uncertainty != "none";
    opt.uncertainty.sources = scene.uncertainty;  // the defaults unless the scene's `uncertainty:` says otherwise
    // --cell-size, else prone.cell_size_mm, else the preset's simulation mesh (the engine meshes once).
    if (scene.prone_source && cell_mm > 0) scene.prone_source->cell_size = mm_to_m(cell_mm);
    RegistrationEngine engine(std::move(scene));
    const PreparedScene& prepared = engine.prepare(opt);
    const Scene& sim = prepared.scene;
    const RegistrationModel& model = prepared.model;
    const std::vector<std::string>& warnings = prepared.warnings;
    if (!prepared.mesh_note.empty())
      std::printf("[register] %s (%.2f s%s)\n", prepared.mesh_note.c_str(), prepared.mesh_seconds,
                  sim.prone_source ? "" : "; --cell-size 0 keeps the scene's mesh");
    const PlannedSteps plan = plan_steps(sim);
    const double prepare = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[register] %s: %ld vertices, %ld tetrahedra%s; steps: %s; preset %s, %s volume form%s\n",
                scene_path.c_str(), static_cast<long>(model.rest.V.rows()), static_cast<long>(model.rest.T.rows()),
                sim.tetrahedralized ? " (tetrahedralized)" : "", plan.describe().c_str(), opt.preset.c_str(),
                to_string(model.volume_form),
                takes_preset_volume_form(engine.scene(), opt)
                    ? " (the preset's for a scene that unloads; material.volume_form: element keeps the element form)"
                    : "");
    if (model.material.unload_element_order != ElementOrder::Linear && !engine.scene().unload_element_order_stated)
      std::printf("[register] unloaded with %s elements (the preset's with its nodal form; material.unload_element_order: "
                  "linear keeps linear ones)\n",
                  to_string(model.material.unload_element_order));
    if (model.materials.size() > 1) {
      std::string mats;
      for (size_t i = 0; i < model.materials.size(); ++i)
        mats += (i ? ", " : "") + model.material_names[i] + " " + std::to_string(model.material_tetrahedra[i]) + " tetrahedra";
      std::printf("[register] materials: %s\n", mats.c_str());
    }
    for (const auto& w : warnings) std::printf("[register] warning: %s\n", w.c_str());

    StepCallback progress;
    if (!quiet)
      progress = [&](const std::string& step, const IterationInfo& it) {
        std::printf("%s[%-8s] iteration %3d  energy %+.6e J  |grad| %.2e N  step %.3f mm  %.2f s%s", tty ? "\r" : "",
                    step.c_str(), it.iteration, it.energy, it.gradient_norm, it.step_norm * 1e3, it.elapsed, tty ? "" : "\n");
        std::fflush(stdout);
        return true;
      };
    RegistrationResult r = engine.solve(opt, progress);
    if (uncertainty == "sampling") {
      std::printf("%s[uncert  ] sampling %d re-registrations...\n", tty && !quiet ? "\n" : "", samples);
      r.sampled_uncertainty = engine.sample_uncertainty(opt, opt.uncertainty, samples, seed, r);
    }
    if (tty && !quiet) std::printf("\n");
    if (plan.rigid_landmarks || plan.rigid_icp)
      std::printf("[rigid   ] %.2f deg, %.2f mm (%s) in %.3f s\n", rotation_angle(r.supine_to_model) * 180 / M_PI,
                  r.supine_to_model.translation().norm() * 1e3, r.icp_used ? "landmarks + ICP" : r.icp.message.empty() ? "landmarks" : r.icp.message.c_str(),
                  r.rigid_seconds);
    if (!r.rigid_note.empty() && !r.rigid_pose_undecided) std::printf("[rigid   ] %s\n", r.rigid_note.c_str());
    for (const auto& s : r.reports) {
      if (s.name == "stiffness") {
        std::printf("[%-8s] E = %.0f Pa from %d candidates (landmark misfit of the gravity-only prediction %.3f mm): %s, in "
                    "%.3f s\n",
                    s.name.c_str(), s.stiffness_youngs_modulus, s.outer_iterations, s.stiffness_misfit * 1e3,
                    s.stop_reason.c_str(), s.seconds);
        for (const auto& c : r.stiffness_evaluations)
          if (!c.failure.empty())
            std::printf("[%-8s]   %.0f Pa not simulated (%d forward solves, %.2f s): %s\n", s.name.c_str(), c.youngs_modulus,
                        c.forward_solves, c.seconds, c.failure.c_str());
        continue;
      }
      const char* outer = s.name == "unload" ? " forward solves" : " projections";
      std::printf("[%-8s] %s: %d Newton iterations%s in %.3f s\n", s.name.c_str(), s.stop_reason.c_str(), s.iterations,
                  s.outer_iterations ? (", " + std::to_string(s.outer_iterations) + outer).c_str() : "", s.seconds);
      if (s.name == "unload")
        std::printf("[%-8s]   rest shape moved up to %.2f mm from the prone shape; re-simulated prone within %.4f mm\n",
                    s.name.c_str(), s.unload.rest_change * 1e3, s.unload.mismatch * 1e3);
      if (s.name == "unload") continue;  // its solves are not profiled step by step
      std::printf("[%-8s]   setup %.3f, assembly %.3f, factorization %.3f (%d), solve %.3f (%d PCG iterations), "
                  "line search %.3f, projection %.3f s\n",
                  s.name.c_str(), s.t_setup, s.t_assembly, s.t_factorization, s.factorizations, s.t_solve, s.pcg_iterations,
                  s.t_line_search, s.t_projection);
    }
    for (const auto& w : r.warnings)
      if (std::find(warnings.begin(), warnings.end(), w) == warnings.end()) std::printf("[register] warning: %s\n", w.c_str());
    for (const auto& t : r.tumours) {
      std::printf("[tumour  ] %-8s centroid (%.2f, %.2f, %.2f) mm, volume ratio %.3f, axis ratio %.3f (prone %.3f)",
                  t.name.c_str(), t.centroid.x() * 1e3, t.centroid.y() * 1e3, t.centroid.z() * 1e3, t.volume_ratio,
                  t.axis_ratio, t.prone_axis_ratio);
      if (t.has_ground_truth)
        std::printf(", centroid error %.3f mm (rigid only %.2f mm), Hausdorff %.2f mm", t.centroid_distance * 1e3,
                    t.rigid_centroid_distance * 1e3, t.hausdorff * 1e3);
      std::printf("\n");
      if (t.uncertainty) {
        const TumourUncertainty& u = *t.uncertainty;
        std::printf("[uncert  ] %-8s 95 %% radius %.2f mm (rms by source:", t.name.c_str(), u.radius_95 * 1e3);
        for (const auto& [name, cov] : u.sources) std::printf(" %s %.2f", name.c_str(), std::sqrt(std::max(0.0, cov.trace())) * 1e3);
        std::printf(" mm)%s\n", t.has_ground_truth ? (t.centroid_distance <= u.radius_95 ? "; holds the true centroid"
                                                                                      : "; the true centroid lies outside")
                                                     : "");
      }
    }
    if (opt.uncertainty.enabled)
      std::printf("[uncert  ] linearised in %.3f s%s%s\n", r.uncertainty_seconds, r.uncertainty_note.empty() ? "" : ": ",
                  r.uncertainty_note.c_str());
    if (r.sampled_uncertainty) {
      const SampledUncertainty& su = *r.sampled_uncertainty;
      for (size_t i = 0; i < su.tumours.size() && i < r.tumours.size(); ++i) {
        char discretisation[48] = "not estimated";  // the note below says why
        if (su.discretisation_estimated)
          std::snprintf(discretisation, sizeof discretisation, "%.2f mm", su.tumours[i].discretisation.norm() * 1e3);
        std::printf("[sampled ] %-8s 95 %% radius %.2f mm (linear %.2f mm; sources alone %.2f mm, discretisation %s), "
                    "mean shift %.2f mm, margin shell up to %.2f mm%s\n",
                    r.tumours[i].name.c_str(), su.tumours[i].radius_95 * 1e3,
                    r.tumours[i].uncertainty ? r.tumours[i].uncertainty->radius_95 * 1e3 : 0.0,
                    su.tumours[i].radius_95_sources * 1e3, discretisation,
                    su.tumours[i].mean_shift.norm() * 1e3,
                    su.tumours[i].vertex_radius_95.empty()
                        ? 0.0
                        : *std::max_element(su.tumours[i].vertex_radius_95.begin(), su.tumours[i].vertex_radius_95.end()) * 1e3,
                    r.tumours[i].has_ground_truth ? (r.tumours[i].centroid_distance <= su.tumours[i].radius_95
                                                         ? "; holds the true centroid"
                                                         : "; the true centroid lies outside")
                                                  : "");
      }
      char reference[64] = "";
      if (su.discretisation_estimated)
        std::snprintf(reference, sizeof reference, ", the discretisation's nodal reference %.3f s", su.discretisation_seconds);
      std::printf("[sampled ] %d samples (%d not converged, %d failed), %.3f s each%s%s%s\n", su.samples, su.not_converged,
                  su.failed, su.seconds_per_sample, reference, su.note.empty() ? "" : ": ", su.note.c_str());
    }
    // The mesh and model the result was computed on (the element form's own mesh where a preset's
    // nodal form fell back to it).
    const PreparedScene& computed = engine.prepared_for(opt, r);
    if (r.volume_form_fallback && !r.volume_form_fallback->mesh_note.empty())
      std::printf("[register] the result is the element form's on %ld vertices, %ld tetrahedra (%s)\n",
                  static_cast<long>(computed.model.rest.V.rows()), static_cast<long>(computed.model.rest.T.rows()),
                  r.volume_form_fallback->mesh_note.c_str());
    const auto files = write_registration_outputs(out_dir, computed.scene, computed.model, r, prepare);
    std::printf("[register] registration %.3f s (tetrahedralization %.2f s, preparation %.2f s); wrote %zu files to %s "
                "(report.json, cross_section.png, registered.vtk, ...)\n",
                r.seconds, prepared.mesh_seconds, prepare, files.size(),
                std::filesystem::absolute(out_dir).string().c_str());
    if (!r.converged) {
      std::fprintf(stderr, "btr_register: a step stopped without converging (see report.json); try the accurate preset\n");
      return 4;
    }
    if (r.implausible) {
      std::fprintf(stderr, "btr_register: the result is implausible (see the warnings above and report.json)\n");
      return 5;
    }
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "%sbtr_register: invalid input: %s\n", tty ? "\n" : "", e.what());
    return 2;
  } catch (const SolverError& e) {
    std::fprintf(stderr, "%sbtr_register: numerical failure: %s\n", tty ? "\n" : "", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%sbtr_register: error: %s\n", tty ? "\n" : "", e.what());
    return 1;
  }
}
