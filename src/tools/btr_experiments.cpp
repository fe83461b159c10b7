// btr_experiments: the synthetic experiments of the thesis (Sec. 5.2, Table 5.1) on the
// built-in phantom or on a user's rest model; one CSV row per run and tumour. Plots and the
// comparison table with the thesis come from scripts/plot_experiments.py.
#include <CLI/CLI.hpp>

#include "breast_tumour_registration/cli_checks.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/simulation/experiment_shards.h"
#include "breast_tumour_registration/simulation/experiment_suite.h"
#include "breast_tumour_registration/simulation/given_truth_io.h"
#include "breast_tumour_registration/simulation/rest_model_io.h"

namespace fs = std::filesystem;
using namespace btr;

int main(int argc, char** argv) {
  CLI::App app{
      "Run the thesis's synthetic experiments (practical settings, rest shape, rotated gravity, misalignment with and\n"
      "without the rigid step, material, landmark weight, landmark sets) over the generating Young's moduli and\n"
      "write results.csv: one row per run and tumour. Exit codes: 0 done, 2 invalid input, 1 other error."};
  std::string out_dir = "experiments", model_path, preset = "balanced";
  std::vector<std::string> experiments;
  std::vector<double> moduli;
  double cell_mm = 6.0;
  bool quick = false, quiet = false;
  app.add_option("-o,--out", out_dir, "output folder (created): results.csv")->capture_default_str();
  app.add_option("-e,--experiments", experiments,
                 "experiments to run (default all): practical rest_shape rotated_gravity misalignment material "
                 "landmark_weight landmark_set");
  app.add_option("-E,--youngs-moduli", moduli, "generating Young's moduli [Pa] (default: the thesis's 16, 200-12000)")
      ->check(btr::cli::positive());
  app.add_option("--model", model_path, "a rest model file (YAML; its fields: README.md, \"The rest model file\") instead of the built-in phantom");
  std::string truth_path;
  app.add_option("--truth", truth_path,
                 "with --model: a truth file (YAML; its fields: README.md, \"The truth file\") of prone and supine configurations made "
                 "elsewhere (another FEM code), run instead of generating them; -E picks among its moduli (default: "
                 "all of them)")
      ->needs(app.get_option("--model"));
  double simulation_cell_mm = 0;
  app.add_option("--simulation-cell-size", simulation_cell_mm,
                 "re-tetrahedralize every run's prone model at this size [mm], as btr_register meshes a prone surface "
                 "(0: simulate on the model's own mesh; with --truth, the mesh the truth was computed on)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  std::string volume_form = "auto";
  app.add_option("--volume-form", volume_form,
                 "the method's volume term: auto (element below nu = 0.495; the suite simulates its own meshes, so it does "
                 "not take the balanced preset's nodal form on 9 mm, which btr_register does where a scene unloads), "
                 "element or nodal (no locking, slower); the generated truth keeps its own")
      ->check(CLI::IsMember({"auto", "element", "nodal"}))
      ->capture_default_str();
  ElementOrder unload_elements = ElementOrder::Linear, truth_elements = ElementOrder::Linear;
  btr::cli::element_order_option(app, "--unload-element-order", unload_elements,
                                 "the elements of the method's unloaded-shape estimate: linear or quadratic "
                                 "(material.unload_element_order; with E estimated the search compares its candidates "
                                 "with linear elements; the registration steps stay linear)");
  btr::cli::element_order_option(app, "--truth-element-order", truth_elements,
                                 "the elements the suite's own truth is generated with: linear (the method's kind) or "
                                 "quadratic (10-node tetrahedra on the same mesh, nearer the converged answer; not with "
                                 "--truth)");
  double nodal_element_share = 0;
  app.add_option("--nodal-element-share", nodal_element_share,
                 "with the nodal volume term: the volume stiffness each tetrahedron keeps on its own volume "
                 "change, in units of its shear modulus (material.nodal_element_share)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  std::string nodal_fallback = "on";
  app.add_option("--nodal-fallback", nodal_fallback,
                 "with the nodal volume term: a run that ends not converged is run again with the element form "
                 "(material.nodal_fallback)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  double stiffness_budget = ExperimentSuiteOptions().method_stiffness_budget;
  app.add_option("--stiffness-budget", stiffness_budget,
                 "with E estimated: a stiffness candidate's unload may take this many times the forward solves of the "
                 "costliest candidate simulated so far (at least 30); 0: no budget")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--cell-size", cell_mm, "built-in phantom: tetrahedron size bound [mm] (8: ~6k tets, 4.7: ~35k)")
      ->capture_default_str();
  app.add_option("-p,--preset", preset, "registration preset: fast, balanced, accurate")->capture_default_str();
  app.add_flag("--quick", quick, "a few values per experiment and two generating moduli (1000, 4000 Pa) unless -E");
  app.add_flag("-q,--quiet", quiet, "no progress lines");
  std::string shard;
  std::vector<std::string> merge;
  app.add_option("--shard", shard,
                 "K/N: run share K of N of the plan (contiguous blocks of its modulus x run items); the output folder "
                 "gets shard.txt beside results.csv. Join the shares with --merge");
  app.add_option("--merge", merge,
                 "join the output folders of shares 1..N of one study into OUT/results.csv (checks that they belong "
                 "together and that none is missing) and exit; runs nothing");
  std::string rest_shape = "prone";
  app.add_option("--rest-shape", rest_shape,
                 "the method's rest shape in every experiment but rest_shape (which runs all four): prone (the "
                 "thesis), unloaded (estimated from the prone shape at the method's E), estimated (unloaded at an E "
                 "estimated from the landmarks; the material experiment keeps its E)")
      ->check(CLI::IsMember({"prone", "unloaded", "estimated"}))
      ->capture_default_str();
  if (const int rc = btr::cli::parse(app, argc, argv); rc >= 0) return rc;

  const auto t0 = std::chrono::steady_clock::now();
  try {
    if (!merge.empty()) {
      fs::create_directories(out_dir);
      const std::string merged = (fs::path(out_dir) / "results.csv").string();
      const long n = merge_experiment_shards(merge, merged);
      std::printf("[experiments] merged %zu shares, %ld rows, into %s\n", merge.size(), n,
                  fs::absolute(merged).string().c_str());
      return 0;
    }
    ExperimentSuiteOptions opt;
    if (!shard.empty()) parse_shard(shard, opt.shard, opt.shards);
    opt.experiments = experiments;
    opt.generating_youngs_moduli = moduli;
    opt.quick = quick;
    opt.preset = preset;
    opt.rest_shape = rest_shape;
    opt.simulation_cell_size = mm_to_m(simulation_cell_mm);
    opt.method_volume_form = parse_volume_form(volume_form);
    opt.method_nodal_element_share = nodal_element_share;
    opt.method_unload_element_order = unload_elements;
    opt.truth_element_order = truth_elements;
    opt.method_nodal_fallback = nodal_fallback == "on";
    opt.method_stiffness_budget = stiffness_budget;
    if (quick && moduli.empty()) opt.generating_youngs_moduli = {1000, 4000};
    preset_options(preset);  // validates the name before the expensive steps
    const std::vector<ExperimentRun> runs = plan_experiments(opt);
    PhantomModel model;
    if (!model_path.empty()) {
      model = load_rest_model(model_path);
      for (const auto& w : model.warnings) std::printf("[experiments] warning: %s\n", w.c_str());
      if (!truth_path.empty()) {
        opt.given_configurations = std::make_shared<const std::map<double, PhantomConfigurations>>(
            load_given_configurations(truth_path, model));
        if (moduli.empty()) {  // every configuration of the truth (--quick's two moduli are the phantom's)
          opt.generating_youngs_moduli.clear();
          for (const auto& [e, conf] : *opt.given_configurations) opt.generating_youngs_moduli.push_back(e);
        }
      }
    } else {
      PhantomOptions po;
      po.tet.cell_size = mm_to_m(cell_mm);
      model = make_phantom_model(po);
    }
    const size_t n_moduli = opt.generating_youngs_moduli.empty() ? thesis_youngs_moduli().size() : opt.generating_youngs_moduli.size();
    std::printf("[experiments] %s%s: %ld vertices, %ld tetrahedra, %zu tumours, %zu landmarks; %zu runs x %zu generating "
                "moduli, preset %s\n",
                model_path.empty() ? "built-in phantom" : model_path.c_str(),
                truth_path.empty() ? "" : (" with the configurations of " + truth_path).c_str(), static_cast<long>(model.rest.V.rows()),
                static_cast<long>(model.rest.T.rows()), model.tumours.size(), model.landmarks.size(), runs.size(), n_moduli,
                preset.c_str());
    std::fflush(stdout);
    fs::create_directories(out_dir);
    const std::string csv_path = (fs::path(out_dir) / "results.csv").string();
    std::ofstream csv(csv_path);
    if (!csv) throw InputError("cannot write '" + csv_path + "'");
    write_experiment_csv_header(csv);
    if (opt.shards > 1)
      write_shard_info(out_dir, opt.shard, opt.shards,
                       plan_fingerprint(opt, runs, model));
    long rows = 0, failed = 0;
    run_experiments(
        model, opt, runs,
        [&](const ExperimentRow& r) {
          write_experiment_csv_row(csv, r);
          csv.flush();
          ++rows;
          if (r.status.rfind("failed", 0) == 0) ++failed;
        },
        [&](const std::string& line) {
          if (!quiet) {
            std::printf("[experiments] %s\n", line.c_str());
            std::fflush(stdout);
          }
        });
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[experiments] wrote %ld rows (%ld failed) to %s in %.0f s\n", rows, failed,
                fs::absolute(csv_path).string().c_str(), secs);
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "btr_experiments: invalid input: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_experiments: error: %s\n", e.what());
    return 1;
  }
}
