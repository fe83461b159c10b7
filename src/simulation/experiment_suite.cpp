#include "breast_tumour_registration/simulation/experiment_suite.h"

#include <chrono>
#include <map>
#include <cmath>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/simulation/experiment_shards.h"

namespace btr {
namespace {

std::string format_value(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The landmark names of a run: "default" is the thesis's five (C+O) when the model has them,
// else every landmark of the model; "all" every landmark; otherwise a phantom_landmark_set.
std::vector<std::string> landmark_names(const PhantomModel& model, const std::string& set) {
  std::vector<std::string> all;
  for (const auto& [name, v] : model.landmarks) all.push_back(name);
  if (set == "all") return all;
  if (set == "default") {
    const auto five = phantom_landmark_set("C+O");
    for (const auto& n : five)
      if (!model.landmarks.count(n)) return all;
    return five;
  }
  const auto names = phantom_landmark_set(set);
  for (const auto& n : names)
    if (!model.landmarks.count(n)) throw InputError("landmark set " + set + ": the model has no landmark '" + n + "'");
  return names;
}

}  // namespace

const std::vector<double>& thesis_youngs_moduli() {
  static const std::vector<double> e = {200,  400,  600,  800,  1000, 2000,  3000,  4000,
                                        5000, 6000, 7000, 8000, 9000, 10000, 11000, 12000};
  return e;
}

const std::vector<std::string>& experiment_names() {
  static const std::vector<std::string> n = {"practical", "rest_shape",      "rotated_gravity", "misalignment",
                                             "material",  "landmark_weight", "landmark_set"};
  return n;
}

std::vector<ExperimentRun> plan_experiments(const ExperimentSuiteOptions& opt) {
  for (const auto& e : opt.experiments) {
    bool known = false;
    for (const auto& n : experiment_names()) known = known || n == e;
    if (!known) throw InputError("unknown experiment '" + e + "' (practical, rest_shape, rotated_gravity, misalignment, "
                                 "material, landmark_weight, landmark_set)");
  }
  auto wanted = [&](const std::string& e) {
    if (opt.experiments.empty()) return true;
    for (const auto& x : opt.experiments)
      if (x == e) return true;
    return false;
  };
  const bool q = opt.quick;
  std::vector<ExperimentRun> runs;
  auto base = [](const std::string& experiment, const std::string& setting, const std::string& variable,
                 const std::string& value) {
    ExperimentRun r;
    r.experiment = experiment;
    r.setting = setting;
    r.variable = variable;
    r.value = value;
    r.landmark_set = "default";
    return r;
  };

  if (wanted("practical")) {  // thesis Sec. 5.2.2, Fig. 5.4
    const std::vector<std::pair<std::string, std::vector<std::string>>> methods = {
        {"rigid", {"rigid"}},
        {"landmarks", {"rigid", "landmarks"}},
        {"surface", {"rigid", "surface"}},
        {"gravity+surface", {"rigid", "gravity", "surface"}},
        {"full", {}}};
    for (const auto& [name, steps] : methods) {
      ExperimentRun r = base("practical", name, "method", name);
      r.steps = steps;
      runs.push_back(r);
    }
  }
  if (wanted("rest_shape")) {  // Sec. 5.2.3, Fig. 5.5
    for (const char* shape : {"prone", "rest", "unloaded", "estimated"}) {
      ExperimentRun r = base("rest_shape", "full", "rest_shape", shape);
      r.rest_shape = shape;
      runs.push_back(r);
    }
  }
  const std::vector<double> angles = q ? std::vector<double>{0, 15} : std::vector<double>{0, 2, 4, 6, 8, 10, 15};
  if (wanted("rotated_gravity")) {  // Sec. 5.2.4, Fig. 5.7: the method's gravity turned about X
    for (double a : angles) {
      ExperimentRun r = base("rotated_gravity", "full", "gravity_rotation_x_deg", format_value(a));
      r.gravity_rotation_deg = Vec3(a, 0, 0);
      runs.push_back(r);
    }
  }
  if (wanted("misalignment")) {  // Sec. 5.2.5, Fig. 5.9; with and without our rigid step
    std::vector<double> shifts;
    if (q) shifts = {-10, 10};
    else for (int t = -10; t <= 10; t += 2) shifts.push_back(t);
    const std::vector<double> rot = q ? std::vector<double>{15} : angles;
    for (const std::string setting : {"with_rigid", "without_rigid"}) {
      auto add = [&](const std::string& variable, double v, const Vec3& rdeg, const Vec3& tmm) {
        ExperimentRun r = base("misalignment", setting, variable, format_value(v));
        r.misalignment_rotation_deg = rdeg;
        r.misalignment_translation_mm = tmm;
        if (setting == "without_rigid") r.steps = {"landmarks", "surface"};
        runs.push_back(r);
      };
      for (double a : rot) add("rotation_x_deg", a, Vec3(a, 0, 0), Vec3::Zero());
      for (double a : rot) add("rotation_z_deg", a, Vec3(0, 0, a), Vec3::Zero());
      for (double t : shifts) add("translation_x_mm", t, Vec3::Zero(), Vec3(t, 0, 0));
      for (double t : shifts) add("translation_z_mm", t, Vec3::Zero(), Vec3(0, 0, t));
    }
  }
  if (wanted("material")) {  // Sec. 5.2.6, Fig. 5.10 (heat map)
    const std::vector<double> es = q ? std::vector<double>{1000, 4000} : thesis_youngs_moduli();
    for (double e : es) {
      ExperimentRun r = base("material", "full", "method_youngs_modulus_Pa", format_value(e));
      r.method_youngs_modulus = e;
      r.fixed_material = true;
      runs.push_back(r);
    }
  }
  if (wanted("landmark_weight")) {  // Sec. 5.2.7, Fig. 5.11
    const std::vector<double> ws = q ? std::vector<double>{1e2, 1e4} : std::vector<double>{1e2, 1e3, 1e4, 1e5};
    for (double w : ws) {
      ExperimentRun r = base("landmark_weight", "full", "landmark_weight_N_per_m", format_value(w));
      r.landmark_weight = w;
      runs.push_back(r);
    }
  }
  if (wanted("landmark_set")) {  // Sec. 5.2.8, Fig. 5.12
    const std::vector<std::string> sets =
        q ? std::vector<std::string>{"C+O", "O+Oa"} : std::vector<std::string>{"C+O", "O+Oa+I", "O+I", "O+Oa", "Oa+I"};
    for (const auto& s : sets) {
      ExperimentRun r = base("landmark_set", "full", "landmarks", s);
      r.landmark_set = s;
      runs.push_back(r);
    }
  }
  return runs;
}

Scene experiment_scene(const PhantomModel& model, const PhantomConfigurations& conf, const ExperimentRun& run,
                       const std::string& preset, const std::string& default_rest_shape) {
  std::string shape = run.rest_shape.empty() ? default_rest_shape : run.rest_shape;
  if (shape == "estimated" && run.fixed_material) shape = "unloaded";
  if (shape != "prone" && shape != "rest" && shape != "unloaded" && shape != "estimated")
    throw InputError("experiment rest_shape '" + shape + "' (prone, rest, unloaded, estimated)");
  const bool true_rest = shape == "rest";
  Scene s;
  s.path = "experiment " + run.experiment + " (" + run.setting + ", " + run.variable + " = " + run.value + ")";
  s.units = LengthUnit::Metre;
  s.prone = model.rest;
  if (!true_rest) s.prone.V = conf.prone;
  if (shape == "unloaded" || shape == "estimated") s.prone_gravity = model.prone_gravity;
  s.chest_wall = model.chest_wall;
  const auto names = landmark_names(model, run.landmark_set);
  s.landmark_supine.resize(static_cast<long>(names.size()), 3);
  for (size_t i = 0; i < names.size(); ++i) {
    const int v = model.landmarks.at(names[i]);
    s.landmark_anchors.push_back(Anchor::vertex(v));
    s.landmark_supine.row(static_cast<long>(i)) = conf.supine.row(v);
  }
  TetMesh supine = model.rest;
  supine.V = conf.supine;
  s.supine_surface = boundary_surface(supine);
  if (model.chest_ring.V.rows()) {  // rigid skin: the same in both positions
    s.prone_rigid = model.chest_ring;
    s.supine_rigid = model.chest_ring;
  }
  for (const auto& [name, rest_tumour] : model.tumours) {
    SceneTumour t;
    t.name = name;
    t.prone = true_rest ? rest_tumour : conf.tumour_prone.at(name);
    t.supine_ground_truth = conf.tumour_supine.at(name);
    s.tumours.push_back(t);
  }
  s.material.youngs_modulus = run.method_youngs_modulus;
  if (!model.method_regions.empty()) {  // the tissue layout the model file gives, relative to the method's E
    s.prone_labels = model.rest_labels;
    for (const auto& r : model.method_regions) {
      MaterialRegion mr;
      mr.name = r.name;
      mr.label = r.label;
      mr.youngs_modulus = r.relative_stiffness * run.method_youngs_modulus;
      s.regions.push_back(std::move(mr));
    }
  }
  if (shape == "estimated") s.youngs_modulus_range = std::array<double, 2>{150, 24000};
  const Rigid g = misalignment_from_degrees_mm(run.gravity_rotation_deg, Vec3::Zero());
  s.gravity = g.linear() * model.supine_gravity;
  s.steps = run.steps;
  s.preset = preset;
  if (!run.misalignment_rotation_deg.isZero() || !run.misalignment_translation_mm.isZero())
    apply_misalignment(s, misalignment_from_degrees_mm(run.misalignment_rotation_deg, run.misalignment_translation_mm));
  return s;
}

void write_experiment_csv_header(std::ostream& out) {
  out << "experiment,setting,variable,value,generating_youngs_modulus_Pa,tumour,centroid_distance_mm,hausdorff_mm,"
         "volume_ratio,seconds,landmark_residual_max_mm,skin_distance_mean_mm,estimated_youngs_modulus_Pa,status\n";
}

void write_experiment_csv_row(std::ostream& out, const ExperimentRow& row) {
  const std::string status = csv_field(row.status);
  out << row.run->experiment << ',' << row.run->setting << ',' << row.run->variable << ',' << row.run->value << ','
      << row.generating_youngs_modulus << ',' << row.tumour << ',' << std::setprecision(6) << row.centroid_distance_mm
      << ',' << row.hausdorff_mm << ',' << row.volume_ratio << ',' << std::setprecision(4) << row.seconds << ','
      << row.landmark_residual_max_mm << ',' << row.skin_distance_mean_mm << ',' << std::setprecision(5)
      << row.estimated_youngs_modulus << ',' << status << '\n';
}

void run_experiments(const PhantomModel& model, const ExperimentSuiteOptions& opt, const std::vector<ExperimentRun>& runs,
                     const std::function<void(const ExperimentRow&)>& sink,
                     const std::function<void(const std::string&)>& progress) {
  const auto say = [&](const std::string& s) {
    if (progress) progress(s);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Landmark sets the model cannot give are skipped (a user's model has its own landmarks).
  std::vector<const ExperimentRun*> todo;
  for (const auto& r : runs) {
    try {
      landmark_names(model, r.landmark_set);
      todo.push_back(&r);
    } catch (const InputError& e) {
      say("skipped " + r.experiment + " " + r.value + ": " + e.what());
    }
  }
  const std::vector<double>& moduli = opt.generating_youngs_moduli.empty() ? thesis_youngs_moduli() : opt.generating_youngs_moduli;
  RegistrationOptions preset = preset_options(opt.preset);
  preset.stiffness.candidate_budget_factor = opt.method_stiffness_budget;
  if (opt.given_configurations && opt.truth_element_order != ElementOrder::Linear)
    throw InputError("the truth's element order applies to the suite's own truth, not to given configurations");
  if (opt.given_configurations)
    for (double e : moduli)
      if (!opt.given_configurations->count(e))
        throw InputError("generating Young's modulus " + format_value(e) + " Pa: the given truth has no configuration for it");
  // This share of the (modulus, run) items, in plan order.
  const ShardRange share = shard_range(moduli.size() * todo.size(), opt.shard, opt.shards);
  for (size_t ei = 0; ei < moduli.size(); ++ei) {
    const double e = moduli[ei];
    const size_t first_item = ei * todo.size();
    if (first_item + todo.size() <= share.first || first_item >= share.last) continue;  // nothing of this modulus here
    PhantomSceneOptions gen;
    gen.youngs_modulus = e;
    gen.poisson_ratio = opt.poisson_ratio;
    gen.density = opt.density;
    gen.element_order = opt.truth_element_order;
    const auto t0 = std::chrono::steady_clock::now();
    PhantomConfigurations conf;
    std::string generation_failure;
    if (opt.given_configurations) {
      conf = opt.given_configurations->at(e);
      say("given configuration for E = " + format_value(e) + " Pa");
    } else {
      try {
        conf = simulate_phantom(model, gen);
        // The method's prone mesh is the truth's corners unless it is re-meshed from its surface.
        if (opt.simulation_cell_size <= 0 && conf.prone_corner_inversions > 0)
          throw SolverError("the quadratic truth's prone corners invert " + std::to_string(conf.prone_corner_inversions) +
                            " of the model's tetrahedra, so that mesh cannot be the method's: re-mesh it "
                            "(--simulation-cell-size)");
      } catch (const std::exception& err) {
        generation_failure = std::string("failed: generating the configurations: ") + err.what();
      }
      say("generated E = " + format_value(e) + " Pa in " +
          format_value(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()) + " s" +
          (generation_failure.empty() ? "" : " (" + generation_failure + ")"));
    }
    struct Unloaded {
      Points rest, nodes;  // RegistrationModel::rest.V and unloaded_nodes
      StepReport report;
    };
    std::map<double, Unloaded> unloaded;  // per method Young's modulus, this configuration
    for (size_t ri = 0; ri < todo.size(); ++ri) {
      if (first_item + ri < share.first || first_item + ri >= share.last) continue;
      const ExperimentRun* run = todo[ri];
      ExperimentRow row;
      row.run = run;
      row.generating_youngs_modulus = e;
      std::vector<ExperimentRow> rows;
      std::string failure = generation_failure;
      if (failure.empty()) {
        try {
          Scene scene = experiment_scene(model, conf, *run, opt.preset, opt.rest_shape);
          scene.material.volume_form = opt.method_volume_form;
          scene.material.nodal_element_share = opt.method_nodal_element_share;
          scene.material.unload_element_order = opt.method_unload_element_order;
          scene.nodal_fallback = opt.method_nodal_fallback;
          if (opt.simulation_cell_size > 0)  // as btr_register meshes it, the preset's tumour cells included
            scene = with_simulation_mesh(scene, opt.simulation_cell_size, tumour_cell_size_for(scene, preset));
          std::vector<std::string> warnings;
          // The unloaded shape depends on the configuration and the method's material only:
          // estimated once per both, then reused (its time still counts in every run's seconds).
          Scene without_unload = scene;
          without_unload.prone_gravity.reset();
          RegistrationModel rm = prepare_model(without_unload, warnings);
          double unload_seconds = 0;
          if (unloads_in_preparation(scene)) {
            auto it = unloaded.find(run->method_youngs_modulus);
            if (it == unloaded.end()) {
              const StepReport u = unload_model(rm, *scene.prone_gravity);
              it = unloaded.emplace(run->method_youngs_modulus, Unloaded{rm.rest.V, rm.unloaded_nodes, u}).first;
              say("unloaded shape for method E = " + format_value(run->method_youngs_modulus) + " Pa: " +
                  (u.converged ? "converged" : "not converged") + " (" + u.stop_reason + "), rest shape moved up to " +
                  format_value(u.unload.rest_change * 1e3) + " mm, re-simulated prone within " +
                  format_value(u.unload.mismatch * 1e3) + " mm, " + format_value(u.seconds) + " s" +
                  (u.note.empty() ? "" : "; " + u.note));
            } else {
              set_rest_shape(rm, it->second.rest, it->second.report, *scene.prone_gravity, it->second.nodes);
            }
            unload_seconds = it->second.report.seconds;
          }
          RegistrationOptions ro = preset;
          ro.landmark.weight = run->landmark_weight;
          RegistrationEngine engine(scene, std::move(rm), std::move(warnings));
          const RegistrationResult r = engine.solve(ro);
          std::string status = "converged";
          if (!r.converged) {  // which step, and why: a cap, a stall or a failed line search
            status = "not_converged";
            for (const auto& rep : r.reports)
              if (!rep.converged) status += ": " + rep.name + ": " + rep.stop_reason;
          }
          if (r.volume_form_fallback) status += " (element form: the nodal did not converge)";
          if (r.implausible) status += " (implausible)";
          for (const auto& t : r.tumours) {
            row.tumour = t.name;
            row.centroid_distance_mm = t.centroid_distance * 1e3;
            row.hausdorff_mm = t.hausdorff * 1e3;
            row.landmark_residual_max_mm = r.landmark_residual_max * 1e3;
            row.skin_distance_mean_mm = r.skin_distance_mean * 1e3;
            row.volume_ratio = t.volume_ratio_to_truth;
            row.seconds = r.seconds + unload_seconds;
            row.estimated_youngs_modulus = r.estimated_youngs_modulus;
            row.status = status;
            rows.push_back(row);
          }
        } catch (const std::exception& err) {
          // A generated configuration the method cannot start from (e.g. a prone element
          // squashed flat at E = 200 Pa) fails this run only; the suite goes on.
          failure = std::string("failed: ") + err.what();
        }
      }
      if (rows.empty()) {  // a failed run still gives its rows, with NaN figures
        for (const auto& [name, t] : model.tumours) {
          row.tumour = name;
          row.centroid_distance_mm = row.hausdorff_mm = row.volume_ratio = row.seconds = nan;
          row.landmark_residual_max_mm = row.skin_distance_mean_mm = nan;
          row.status = failure;
          rows.push_back(row);
        }
      }
      for (const auto& rw : rows) sink(rw);
      say(run->experiment + " " + run->setting + " " + run->variable + "=" + run->value + " E=" + format_value(e) + ": " +
          rows.front().status);
    }
  }
}

}  // namespace btr
