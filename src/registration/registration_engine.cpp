#include "breast_tumour_registration/registration/registration_engine.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <utility>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/fem/volume_form.h"
#include "breast_tumour_registration/geometry/vertex_normals.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/registration/stiffness_step.h"

namespace btr {
namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The prepared scene with the supine side of `supine`: everything run_registration reads from
/// the supine frame (surface or cloud, rigid region, landmark positions, ground truth) and the
/// call's own choices (steps, misalignment, warnings). The prone side stays the prepared one.
Scene with_supine_side(const Scene& prepared, const Scene& supine) {
  if (supine.landmark_supine.rows() != static_cast<Eigen::Index>(prepared.landmark_anchors.size()))
    throw InputError("registration engine: the supine side has " + std::to_string(supine.landmark_supine.rows()) +
                     " landmark positions, the prepared scene " + std::to_string(prepared.landmark_anchors.size()) +
                     " landmarks");
  if (supine.tumours.size() != prepared.tumours.size())
    throw InputError("registration engine: the supine side has " + std::to_string(supine.tumours.size()) +
                     " tumours, the prepared scene " + std::to_string(prepared.tumours.size()));
  Scene s = prepared;
  s.path = supine.path;
  s.landmark_supine = supine.landmark_supine;
  s.supine_surface = supine.supine_surface;
  s.supine_cloud = supine.supine_cloud;
  s.supine_rigid = supine.supine_rigid;
  for (size_t i = 0; i < s.tumours.size(); ++i) s.tumours[i].supine_ground_truth = supine.tumours[i].supine_ground_truth;
  s.steps = supine.steps;
  s.misalignment = supine.misalignment;
  s.warnings = supine.warnings;
  return s;
}

/// A stop reason without its parenthesized figures and with every number as '#', so that the
/// samples' stops can be counted by kind.
std::string without_figures(const std::string& reason) {
  std::string out;
  int depth = 0;
  for (char c : reason) {
    if (c == '(') ++depth;
    else if (c == ')') depth = std::max(0, depth - 1);
    else if (depth == 0) {
      if (std::isdigit(static_cast<unsigned char>(c)) || ((c == '.' || c == 'e') && !out.empty() && out.back() == '#')) {
        if (out.empty() || out.back() != '#') out += '#';
      } else {
        out += c;
      }
    }
  }
  return out;
}

/// The steps of `r` that did not converge, as "name: stop reason", joined by "; ".
std::string unconverged_steps(const RegistrationResult& r) {
  std::string out;
  for (const auto& rep : r.reports)
    if (!rep.converged) out += (out.empty() ? "" : "; ") + rep.name + ": " + rep.stop_reason;
  return out;
}

}  // namespace

RegistrationEngine::RegistrationEngine(Scene scene, UnloadOptions unload) : scene_(std::move(scene)), unload_(unload) {}

RegistrationEngine::RegistrationEngine(Scene simulated, RegistrationModel model, std::vector<std::string> warnings)
    : scene_(simulated), adopted_(true) {
  auto e = std::make_unique<Entry>();
  e->prepared.scene = std::move(simulated);
  e->prepared.model = std::move(model);
  e->prepared.warnings = std::move(warnings);
  entries_.emplace(std::make_tuple(0.0, 0.0, scene_.material.unload_element_order), std::move(e));
}

RegistrationEngine::Entry& RegistrationEngine::entry(const RegistrationOptions& opt) {
  if (adopted_) return *entries_.begin()->second;
  // The preset's nodal form where the scene leaves the form to `auto` and plans the unloaded
  // shape (an explicit element or nodal is the scene's choice); else the scene's form as
  // resolved (auto: by Poisson's ratio). RegistrationOptions::volume_form says why.
  const bool preset_form = takes_preset_volume_form(scene_, opt);
  const VolumeForm form =
      preset_form ? VolumeForm::Nodal : resolve_volume_form(scene_.material.volume_form, scene_.material.poisson_ratio);
  RegistrationOptions mesh_opt = opt;  // with the mesh the preset simulates its nodal form on
  mesh_opt.simulation_cell_size = simulation_cell_size_for(scene_, opt);
  // The key is the mesh the call simulates (the size a prone surface is meshed at, the preset's
  // size when the scene's mesh is re-tetrahedralized, or 0 for the scene's mesh as given; the
  // finer cells around the tumours it is meshed with) and the elements it is unloaded with. The
  // first call on a mesh prepares it with its form; the other form is the entry's twin.
  const ElementOrder unload_elements = preset_unload_elements(scene_, opt);
  const bool unmeshed = scene_.prone.T.rows() == 0 && scene_.prone_source;
  double key = 0;
  if (unmeshed)
    key = scene_.prone_source->cell_size.value_or(mesh_opt.simulation_cell_size > 0 ? mesh_opt.simulation_cell_size
                                                                                   : kDefaultCellSize);
  else if (needs_simulation_mesh(scene_, mesh_opt))
    key = mesh_opt.simulation_cell_size;
  const double tumour_cells = tumour_cell_size_for(scene_, opt);  // 0 in the key where it refines nothing
  const double tumour_key = key > 0 && !tumour_refinements(scene_, key, tumour_cells).empty() ? tumour_cells : 0;
  auto it = entries_.find({key, tumour_key, unload_elements});
  if (it != entries_.end()) return twin_entry(*it->second, form);

  const auto t0 = std::chrono::steady_clock::now();
  auto e = std::make_unique<Entry>();
  PreparedScene& p = e->prepared;
  if (key > 0) {  // with_simulation_mesh meshes an unmeshed prone surface, else re-meshes the model
    p.scene = with_simulation_mesh(scene_, key, tumour_key);
    p.mesh_note = (unmeshed ? "tetrahedralized the prone surface at " : "re-tetrahedralized the prone model at ") +
                  format_mm(key) + (tumour_key > 0 ? ", " + format_mm(tumour_key) + " in the tumours' balls" : "");
  } else {
    p.scene = scene_;
  }
  if (preset_form) p.scene.material.volume_form = form;
  p.scene.material.unload_element_order = unload_elements;
  p.mesh_seconds = key > 0 ? p.scene.tetrahedralize_seconds : 0;
  p.model = prepare_model(p.scene, p.warnings, unload_, &e->solvers);
  p.prepare_seconds = since(t0);
  return *entries_.emplace(std::make_tuple(key, tumour_key, unload_elements), std::move(e)).first->second;
}

const PreparedScene& RegistrationEngine::prepare(const RegistrationOptions& opt) { return entry(opt).prepared; }

RegistrationEngine::Entry& RegistrationEngine::twin_entry(Entry& e, VolumeForm form) {
  if (e.prepared.model.volume_form == form) return e;  // as resolved (auto: by Poisson's ratio)
  if (e.twin) return *e.twin;  // the one other form
  if (e.twin_of) return *e.twin_of;  // e is the twin
  const auto t0 = std::chrono::steady_clock::now();
  auto f = std::make_unique<Entry>();
  PreparedScene& p = f->prepared;
  p.scene = e.prepared.scene;  // the same simulation mesh, materials, regions and rest-shape plan
  p.scene.material.volume_form = form;
  p.mesh_note = e.prepared.mesh_note;
  p.mesh_seconds = e.prepared.mesh_seconds;
  p.model = prepare_model(p.scene, p.warnings, unload_, &f->solvers);
  p.prepare_seconds = since(t0);
  f->twin_of = &e;
  e.twin = std::move(f);
  return *e.twin;
}

RegistrationEngine::Entry& RegistrationEngine::fallback_entry(const RegistrationOptions& opt) {
  // The call without a preset's nodal form: where the preset chose it (on its own mesh), the
  // element form on the preset's element mesh, never a coarser element model; elsewhere (the
  // scene's own choice, or an adopted model) entry(own) is entry(opt), and this is its twin.
  RegistrationOptions own = opt;
  own.volume_form = VolumeForm::Auto;
  return twin_entry(entry(own), VolumeForm::Element);
}

int RegistrationEngine::prepared_entries() const {
  int n = 0;
  for (const auto& [k, e] : entries_) n += 1 + (e->twin ? 1 : 0);
  return n;
}

RegistrationResult RegistrationEngine::run(const SupineFor& supine_for, const RegistrationOptions& opt,
                                           const StepCallback& callback) {
  Entry& e = entry(opt);
  RegistrationOptions o = opt;
  const Scene supine = supine_for(e, o);
  RegistrationResult r = run_registration(supine, e.prepared.model, o, callback, &e.solvers);
  r.warnings.insert(r.warnings.begin(), e.prepared.warnings.begin(), e.prepared.warnings.end());
  if (r.converged || r.volume_form != VolumeForm::Nodal || !supine.nodal_fallback) return r;
  // The nodal form did not converge (on coarse soft meshes it folds where the element form's
  // locking holds the mesh together): the element form, from the start.
  RegistrationResult::VolumeFormFallback why;
  why.nodal_stop = unconverged_steps(r);
  why.nodal_seconds = r.seconds;
  const int before = prepared_entries();
  Entry& f = fallback_entry(opt);
  if (prepared_entries() > before) why.prepare_seconds = f.prepared.prepare_seconds;
  const auto root = [](const Entry& x) { return x.twin_of ? x.twin_of : &x; };
  if (root(f) != root(e)) why.mesh_note = f.prepared.mesh_note.empty() ? "the scene's mesh" : f.prepared.mesh_note;
  RegistrationOptions fo = opt;
  Scene s = supine_for(f, fo);
  s.material.volume_form = VolumeForm::Element;
  RegistrationResult fr = run_registration(s, f.prepared.model, fo, callback, &f.solvers);
  fr.warnings.insert(fr.warnings.begin(), f.prepared.warnings.begin(), f.prepared.warnings.end());
  fr.warnings.push_back("the nodal volume form did not converge (" + why.nodal_stop +
                        "); registered again with the element form" +
                        (why.mesh_note.empty() ? std::string() : " on the preset's mesh for it (" + why.mesh_note + ")") +
                        ", which " + (fr.converged ? "converged" : "did not converge either") +
                        ": this is its result (material.nodal_fallback: false keeps the nodal one)");
  fr.seconds += why.nodal_seconds + why.prepare_seconds;
  fr.volume_form_fallback = std::move(why);
  return fr;
}

RegistrationResult RegistrationEngine::solve(const RegistrationOptions& opt, const StepCallback& callback) {
  return run(
      [](const Entry& x, const RegistrationOptions& o) {
        Scene s = x.prepared.scene;
        s.preset = o.preset;
        return s;
      },
      opt, callback);
}

RegistrationResult RegistrationEngine::solve(const Scene& supine, const RegistrationOptions& opt,
                                             const StepCallback& callback) {
  return run(
      [&supine](const Entry& x, const RegistrationOptions& o) {
        Scene s = with_supine_side(x.prepared.scene, supine);
        s.preset = o.preset;
        return s;
      },
      opt, callback);
}

RegistrationResult RegistrationEngine::solve_live(const LiveScan& scan, const LiveSceneOptions& live, RegistrationOptions opt,
                                                  const StepCallback& callback) {
  return run([&](const Entry& x, RegistrationOptions& o) { return live_call(x, scan, live, o); }, opt, callback);
}

const PreparedScene& RegistrationEngine::prepared_for(const RegistrationOptions& opt, const RegistrationResult& r) {
  return nominal_entry(opt, r).prepared;
}

Scene RegistrationEngine::live_call(const Entry& e, const LiveScan& scan, const LiveSceneOptions& live,
                                    RegistrationOptions& opt) {
  LiveScene ls = live_scene(e.prepared.scene, scan, live);
  ls.scene.preset = opt.preset;
  // An organized scan's noise is the live path's own to filter (in its image grid, where the
  // depth camera's per-pixel noise is independent): the mesh denoising stays out of it.
  if (scan.width > 0) ls.scene.supine_denoise = false;
  opt.known_supine_to_model = ls.known_supine_to_model;
  opt.known_pose_covariance = ls.known_pose_covariance;
  return std::move(ls.scene);
}

SampledUncertainty RegistrationEngine::sample_uncertainty(const RegistrationOptions& opt, const UncertaintyOptions& sources,
                                                         int samples, unsigned seed, const RegistrationResult& nominal) {
  Entry& e = nominal_entry(opt, nominal);
  Scene s = e.prepared.scene;
  s.preset = opt.preset;
  return sample(e, s, opt, sources, samples, seed, nominal);
}

SampledUncertainty RegistrationEngine::sample_uncertainty_live(const LiveScan& scan, const LiveSceneOptions& live,
                                                              RegistrationOptions opt, const UncertaintyOptions& sources,
                                                              int samples, unsigned seed, const RegistrationResult& nominal) {
  Entry& e = nominal_entry(opt, nominal);
  const Scene s = live_call(e, scan, live, opt);
  return sample(e, s, opt, sources, samples, seed, nominal);
}

SampledUncertainty RegistrationEngine::sample(Entry& e, const Scene& scene, const RegistrationOptions& opt,
                                              const UncertaintyOptions& sources, int samples, unsigned seed,
                                              const RegistrationResult& nominal) {
  validate_uncertainty_options(sources);
  if (samples < 2) throw InputError("uncertainty sampling: at least 2 samples, got " + std::to_string(samples));
  const RegistrationModel& model = e.prepared.model;
  if (nominal.tumours.size() != model.tumours.size())
    throw InputError("uncertainty sampling: the nominal result has another tumour count than the prepared model");
  SampledUncertainty out;
  std::vector<std::string> notes;
  const UncertaintySources& src = sources.sources;
  // E is drawn over an absolute range, except where a stiffness step sets it from the
  // (sampled) landmarks in every sample. An unloaded rest shape depends on the material, so a
  // sample that draws E or Poisson's ratio unloads again (on the engine's gravity solver).
  const bool estimates_e = scene.youngs_modulus_range.has_value();
  const bool sample_e = src.samples_youngs_modulus() && !estimates_e;
  const bool unloaded = model.unload.has_value() && scene.prone_gravity.has_value();
  const bool unload_each = unloaded && (sample_e || src.samples_poisson_ratio());
  int unload_kept_prone = 0;
  std::map<std::string, int> stops, failures;  // why samples did not converge, or failed
  if (src.samples_youngs_modulus() && estimates_e)
    notes.push_back("E not sampled: the stiffness step estimates it from the (sampled) landmarks in every sample");
  if (nominal.volume_form_fallback)
    notes.push_back("sampled with the element volume form, which the nominal registration fell back to");
  const bool sample_noise = src.depth_noise > 0 && scene.supine_surface;
  if (src.depth_noise > 0 && !scene.supine_surface) notes.push_back("depth noise not sampled on a point cloud");
  // The camera that sees the skin sees the rigid region too: its noise moves the pose ICP fits.
  const bool sample_rigid_noise = src.depth_noise > 0 && src.rigid_pose && scene.supine_rigid;
  // A pose given with its covariance (tracking) is drawn from it: exp(L z) applied after it.
  const bool sample_known_pose = src.rigid_pose && opt.known_supine_to_model && opt.known_pose_covariance;
  Mat6 pose_factor = Mat6::Zero();
  if (sample_known_pose) {
    const Eigen::SelfAdjointEigenSolver<Mat6> es(*opt.known_pose_covariance);
    pose_factor = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  }
  const std::array<Vec3, 2> axes = gravity_tilt_axes(model.gravity);
  RegistrationOptions o = opt;
  o.uncertainty.enabled = false;
  std::mt19937 rng(seed);
  std::normal_distribution<double> z(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::vector<Vec3>> centroids(model.tumours.size());
  // Per tumour and sample: its surface vertices' offsets from their nominal positions.
  std::vector<std::vector<Points>> vertex_offsets(model.tumours.size());
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < samples; ++k) {
    // Every draw is made whether or not its source is used, so a seed gives the same inputs.
    const auto& er = src.youngs_modulus_range;
    const double u_e = unit(rng);
    const double youngs = er[0] > 0 ? er[0] * std::pow(er[1] / er[0], u_e) : 0.0;
    const auto& nr = src.poisson_ratio_range;
    const double nu = nr[0] + (nr[1] - nr[0]) * unit(rng);
    const double tilt[2] = {src.gravity_direction_deg * M_PI / 180 * z(rng), src.gravity_direction_deg * M_PI / 180 * z(rng)};
    Scene s = scene;
    for (Eigen::Index l = 0; l < s.landmark_supine.rows(); ++l)
      for (int c = 0; c < 3; ++c) s.landmark_supine(l, c) += src.landmark_sd * z(rng);
    const auto standard_normal = [&] { return z(rng); };
    if (sample_noise) displace_along_normals(*s.supine_surface, src.depth_noise, standard_normal);
    if (sample_rigid_noise) displace_along_normals(*s.supine_rigid, src.depth_noise, standard_normal);
    RegistrationOptions os = o;
    if (sample_known_pose) {
      Vec6 u;
      for (int k = 0; k < 6; ++k) u(k) = z(rng);
      os.known_supine_to_model = rigid_from_motion(pose_factor * u) * *opt.known_supine_to_model;
    }
    try {  // a sample whose material cannot be unloaded or registered is left out, not the sampling
      RegistrationModel m = model;
      if (sample_e) scale_stiffness(m, youngs / model.material.youngs_modulus);
      if (src.samples_poisson_ratio()) set_poisson_ratio(m, nu);
      if (unload_each) {
        set_rest_shape(m, m.prone, StepReport{}, Vec3::Zero());  // unload_model starts from (and may keep) the prone shape
        const StepReport u = unload_model(m, *scene.prone_gravity, unload_, &e.solvers);
        unload_kept_prone += !u.note.empty() && u.unload.rest_change == 0;
      }
      m.gravity = Eigen::AngleAxisd(tilt[1], axes[1]) * (Eigen::AngleAxisd(tilt[0], axes[0]) * model.gravity);
      const RegistrationResult r = run_registration(s, m, os, {}, &e.solvers);
      ++out.samples;
      if (!r.converged) {
        ++out.not_converged;
        for (const auto& rep : r.reports)  // the kind of stop, without its figures
          if (!rep.converged) ++stops[rep.name + ": " + without_figures(rep.stop_reason)];
      }
      for (size_t i = 0; i < r.tumours.size(); ++i) {
        centroids[i].push_back(r.tumours[i].centroid);
        const Points& V = r.tumours[i].registered.V;
        const Points& V0 = nominal.tumours[i].registered.V;
        if (V.rows() == V0.rows()) vertex_offsets[i].push_back(V - V0);  // the same embedding: vertex for vertex
      }
    } catch (const std::exception& err) {
      ++out.failed;
      ++failures[without_figures(err.what())];
    }
  }
  out.seconds_per_sample = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / samples;
  // The element form's own error, which none of the sources above draws (on a truth our
  // elements did not make it was as large as their spread: BENCHMARKS.md, issue 14).
  std::vector<Vec3> shift(centroids.size(), Vec3::Zero());
  std::vector<Points> vertex_shift(centroids.size());
  if (src.discretisation) {
    const auto t1 = std::chrono::steady_clock::now();
    const std::optional<RegistrationResult> ref = discretisation_reference(e, scene, opt, nominal, notes);
    out.discretisation_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    if (ref) {
      out.discretisation_estimated = true;
      for (size_t i = 0; i < shift.size(); ++i) {
        shift[i] = ref->tumours[i].centroid - nominal.tumours[i].centroid;
        const Points& V = ref->tumours[i].registered.V;
        if (V.rows() == nominal.tumours[i].registered.V.rows()) vertex_shift[i] = V - nominal.tumours[i].registered.V;
      }
    }
  }
  for (size_t i = 0; i < centroids.size(); ++i) {
    SampledUncertainty::Tumour t;
    const auto& c = centroids[i];
    if (c.size() >= 2) {
      Vec3 mean = Vec3::Zero();
      for (const Vec3& p : c) mean += p / static_cast<double>(c.size());
      std::vector<Vec3> offsets;
      for (const Vec3& p : c) {
        t.covariance += (p - mean) * (p - mean).transpose() / static_cast<double>(c.size() - 1);
        offsets.push_back(p - nominal.tumours[i].centroid);
      }
      t.mean_shift = mean - nominal.tumours[i].centroid;
      t.radius_95_sources = percentile_95(sampled_distances(offsets, Vec3::Zero()));
      t.discretisation = shift[i];
      t.radius_95 = percentile_95(sampled_distances(offsets, shift[i]));
      t.centroids = c;
      const Eigen::Index nv = nominal.tumours[i].registered.V.rows();
      if (!vertex_offsets[i].empty())
        for (Eigen::Index v = 0; v < nv; ++v) {
          std::vector<Vec3> o;
          for (const Points& P : vertex_offsets[i]) o.push_back(P.row(v).transpose());
          const Vec3 d = vertex_shift[i].rows() == nv ? Vec3(vertex_shift[i].row(v).transpose()) : Vec3::Zero();
          t.vertex_radius_95.push_back(percentile_95(sampled_distances(o, d)));
        }
    }
    out.tumours.push_back(t);
  }
  if (unload_each)
    notes.push_back("the unloaded shape estimated again in every sample" +
                    (unload_kept_prone ? " (" + std::to_string(unload_kept_prone) + " kept the prone shape: no better estimate)" : std::string()));
  for (const auto& [why, n] : stops) notes.push_back(std::to_string(n) + " not converged at '" + why + "'");
  for (const auto& [why, n] : failures) notes.push_back(std::to_string(n) + " failed and left out: '" + why + "'");
  for (const auto& n : notes) out.note += (out.note.empty() ? "" : "; ") + n;
  return out;
}

std::optional<RegistrationResult> RegistrationEngine::discretisation_reference(Entry& e, const Scene& scene,
                                                                              const RegistrationOptions& opt,
                                                                              const RegistrationResult& nominal,
                                                                              std::vector<std::string>& notes) {
  if (nominal.volume_form != VolumeForm::Element) {
    notes.push_back("discretisation not estimated: the registration used the nodal volume form, the finer of the two");
    return std::nullopt;
  }
  if (nominal.volume_form_fallback) {
    notes.push_back("discretisation not estimated: the nodal volume form did not converge on this scene");
    return std::nullopt;
  }
  Entry& n = twin_entry(e, VolumeForm::Nodal);
  Scene s = scene;
  s.material.volume_form = VolumeForm::Nodal;
  RegistrationOptions o = opt;
  o.uncertainty.enabled = false;
  try {
    RegistrationResult r = run_registration(s, n.prepared.model, o, {}, &n.solvers);
    if (!r.converged) {
      notes.push_back("discretisation not estimated: the nodal reference did not converge (" + unconverged_steps(r) + ")");
      return std::nullopt;
    }
    if (r.tumours.size() != nominal.tumours.size()) throw SolverError("the nodal reference has another tumour count");
    notes.push_back("discretisation: the nominal inputs registered again with the nodal volume form, whose shift is "
                    "taken as the element form's error: every sample moved by it");
    return r;
  } catch (const std::exception& err) {
    notes.push_back(std::string("discretisation not estimated: the nodal reference failed (") + err.what() + ")");
    return std::nullopt;
  }
}

RegistrationEngine::Entry& RegistrationEngine::nominal_entry(const RegistrationOptions& opt,
                                                             const RegistrationResult& nominal) {
  return nominal.volume_form_fallback ? fallback_entry(opt) : entry(opt);
}

int RegistrationEngine::solvers_built() const {
  int n = 0;
  for (const auto& [k, e] : entries_) n += e->solvers.built() + (e->twin ? e->twin->solvers.built() : 0);
  return n;
}

int RegistrationEngine::solvers_reused() const {
  int n = 0;
  for (const auto& [k, e] : entries_) n += e->solvers.reused() + (e->twin ? e->twin->solvers.reused() : 0);
  return n;
}

}  // namespace btr
