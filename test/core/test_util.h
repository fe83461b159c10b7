// Helpers shared by the core tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/geometry/rigid_transform.h"
#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"

namespace btr::test {

/// A fresh temporary folder per test.
inline std::string temp_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto dir = std::filesystem::temp_directory_path() / "btr_tests" /
             (std::string(info->test_suite_name()) + "_" + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

/// The coarse phantom's options (12 mm cells, 12 surface rings, 2.2k tetrahedra), its truth made
/// by our FEM at `youngs_modulus` [Pa] with `truth_elements` (linear: the method's own kind).
inline PhantomSceneOptions coarse_phantom_options(double youngs_modulus, ElementOrder truth_elements = ElementOrder::Linear) {
  PhantomSceneOptions o;
  o.phantom.tet.cell_size = 0.012;
  o.phantom.surface_rings = 12;
  o.youngs_modulus = youngs_modulus;
  o.element_order = truth_elements;
  return o;
}

/// A coarse phantom scene (coarse_phantom_options) written afresh into folder `d`; returns d.
inline std::string write_coarse_phantom_in(const std::string& d, double youngs_modulus,
                                           ElementOrder truth_elements = ElementOrder::Linear) {
  std::filesystem::remove_all(d);
  write_phantom_scene(d, coarse_phantom_options(youngs_modulus, truth_elements));
  return d;
}
/// The same in the temporary folder btr_tests/`name`.
inline std::string write_coarse_phantom(const std::string& name, double youngs_modulus) {
  return write_coarse_phantom_in((std::filesystem::temp_directory_path() / "btr_tests" / name).string(), youngs_modulus);
}

/// One coarse phantom scene (write_coarse_phantom, E = 3400 Pa), written once per test process
/// and loaded; shared by the tests that only read it.
/// Its folder (tests may add scene variants beside scene.yaml, never change it) and the scene.
inline const std::string& coarse_phantom_dir() {
  static const std::string dir = write_coarse_phantom("phantom12", 3400);
  return dir;
}

inline const Scene& coarse_phantom_scene() {
  static const Scene s = load_meshed_scene(coarse_phantom_dir() + "/scene.yaml");
  return s;
}

/// Each step's name, converged flag and stop reason, for a failed expectation's message.
inline std::string step_stops(const RegistrationResult& r) {
  std::string s;
  for (const auto& rep : r.reports) s += rep.name + (rep.converged ? " (converged): " : " (not converged): ") + rep.stop_reason + "\n";
  return s;
}

/// Whether any of the registration's warnings contains `text`.
inline bool has_warning(const RegistrationResult& r, const std::string& text) {
  for (const auto& w : r.warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

/// The largest tumour centroid error of a registration [m].
inline double worst_error(const RegistrationResult& r) {
  double w = 0;
  for (const auto& t : r.tumours) w = std::max(w, t.centroid_distance);
  return w;
}

inline void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

/// A scene folder's scene.yaml as text.
inline std::string scene_text(const std::string& dir) {
  std::ifstream in(dir + "/scene.yaml");
  std::stringstream all;
  all << in.rdbuf();
  return all.str();
}

/// A YAML text without the lines (and their indented children) of a top-level key.
inline std::string without_key(const std::string& text, const std::string& key) {
  std::istringstream is(text);
  std::string out, l;
  bool skipping = false;
  while (std::getline(is, l)) {
    if (l.rfind(key + ":", 0) == 0) {
      skipping = true;
      continue;
    }
    if (skipping && !l.empty() && (l[0] == ' ' || l[0] == '-')) continue;
    skipping = false;
    out += l + "\n";
  }
  return out;
}

/// A phantom scene's text without its chest rings (the `chest_ring:` lines, top level and under
/// `supine`): no rigid region, so the pose is solved with the deformation.
inline std::string without_chest_ring(const std::string& text) {
  std::istringstream is(text);
  std::string out, l;
  while (std::getline(is, l))
    if (l.find("chest_ring:") == std::string::npos) out += l + "\n";
  return out;
}

/// Runs f and expects it to throw E whose message contains `needle`.
template <class E, class F>
void expect_throw_with(F&& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "expected an exception containing '" << needle << "'";
  } catch (const E& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << "message was: " << e.what();
  }
}

/// Rigid transform from rotations about x, y, z [deg] (applied in that order) and a translation [m].
inline Rigid make_rigid(const Vec3& rot_deg, const Vec3& trans) { return rigid_from_rpy(trans, rot_deg * M_PI / 180); }

inline Mat3 random_matrix(std::mt19937& rng, double scale = 1.0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat3 m;
  for (int i = 0; i < 9; ++i) m(i) = scale * u(rng);
  return m;
}

}  // namespace btr::test
