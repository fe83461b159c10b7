#include "breast_tumour_registration/registration/registration_engine.h"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"

namespace btr {
namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
std::string millimetres(double m) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f mm", m * 1e3);
  return b;
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

}  // namespace

RegistrationEngine::RegistrationEngine(Scene scene, UnloadOptions unload) : scene_(std::move(scene)), unload_(unload) {}

RegistrationEngine::RegistrationEngine(Scene simulated, RegistrationModel model, std::vector<std::string> warnings)
    : scene_(simulated), adopted_(true) {
  auto e = std::make_unique<Entry>();
  e->prepared.scene = std::move(simulated);
  e->prepared.model = std::move(model);
  e->prepared.warnings = std::move(warnings);
  entries_.emplace(0.0, std::move(e));
}

RegistrationEngine::Entry& RegistrationEngine::entry(const RegistrationOptions& opt) {
  if (adopted_) return *entries_.begin()->second;
  // The key is the mesh the call simulates: the size a prone surface is meshed at, the preset's
  // size when the scene's mesh is re-tetrahedralized, or 0 for the scene's mesh as given.
  const bool unmeshed = scene_.prone.T.rows() == 0 && scene_.prone_source;
  double key = 0;
  if (unmeshed)
    key = scene_.prone_source->cell_size.value_or(opt.simulation_cell_size > 0 ? opt.simulation_cell_size : kDefaultCellSize);
  else if (needs_simulation_mesh(scene_, opt))
    key = opt.simulation_cell_size;
  auto it = entries_.find(key);
  if (it != entries_.end()) return *it->second;

  const auto t0 = std::chrono::steady_clock::now();
  auto e = std::make_unique<Entry>();
  PreparedScene& p = e->prepared;
  if (unmeshed) {
    p.scene = scene_;
    mesh_prone(p.scene, key);
    p.mesh_note = "tetrahedralized the prone surface at " + millimetres(key);
  } else if (key > 0) {
    p.scene = with_simulation_mesh(scene_, key);
    p.mesh_note = "re-tetrahedralized the prone model at " + millimetres(key);
  } else {
    p.scene = scene_;
  }
  p.mesh_seconds = key > 0 ? p.scene.tetrahedralize_seconds : 0;
  p.model = prepare_model(p.scene, p.warnings, unload_);
  p.prepare_seconds = since(t0);
  return *entries_.emplace(key, std::move(e)).first->second;
}

const PreparedScene& RegistrationEngine::prepare(const RegistrationOptions& opt) { return entry(opt).prepared; }

RegistrationResult RegistrationEngine::run(Entry& e, const Scene& supine, const RegistrationOptions& opt,
                                           const StepCallback& callback) {
  RegistrationResult r = run_registration(supine, e.prepared.model, opt, callback, &e.solvers);
  r.warnings.insert(r.warnings.begin(), e.prepared.warnings.begin(), e.prepared.warnings.end());
  return r;
}

RegistrationResult RegistrationEngine::solve(const RegistrationOptions& opt, const StepCallback& callback) {
  Entry& e = entry(opt);
  Scene s = e.prepared.scene;
  s.preset = opt.preset;
  return run(e, s, opt, callback);
}

RegistrationResult RegistrationEngine::solve(const Scene& supine, const RegistrationOptions& opt,
                                             const StepCallback& callback) {
  Entry& e = entry(opt);
  Scene s = with_supine_side(e.prepared.scene, supine);
  s.preset = opt.preset;
  return run(e, s, opt, callback);
}

RegistrationResult RegistrationEngine::solve_live(const LiveScan& scan, const LiveSceneOptions& live, RegistrationOptions opt,
                                                  const StepCallback& callback) {
  Entry& e = entry(opt);
  LiveScene ls = live_scene(e.prepared.scene, scan, live);
  ls.scene.preset = opt.preset;
  opt.known_supine_to_model = ls.known_supine_to_model;
  return run(e, ls.scene, opt, callback);
}

int RegistrationEngine::solvers_built() const {
  int n = 0;
  for (const auto& [k, e] : entries_) n += e->solvers.built();
  return n;
}

int RegistrationEngine::solvers_reused() const {
  int n = 0;
  for (const auto& [k, e] : entries_) n += e->solvers.reused();
  return n;
}

}  // namespace btr
