// Issue 13: heterogeneous tissue. Regions by cell label and by closed surface, carried to the
// simulation mesh, in the phantom generator's truth, and what they do to the tumour's shape.
#include <algorithm>
#include <filesystem>
#include <set>

#include <nlohmann/json.hpp>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "breast_tumour_registration/registration/material_regions.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/registration/stiffness_step.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"
#include "breast_tumour_registration/simulation/registration_report.h"
#include "test_util.h"

using namespace btr;
using btr::test::expect_throw_with;
using btr::test::scene_text;
using btr::test::without_key;
using btr::test::write_text;

namespace {

// A coarse heterogeneous phantom: fat 3400 Pa, gland 2x, tumours 6x (2.2k tetrahedra).
const std::string& labelled_phantom_dir() {
  static const std::string dir = [] {
    const std::string d = (std::filesystem::temp_directory_path() / "btr_tests" / "phantom_labelled").string();
    std::filesystem::remove_all(d);
    PhantomSceneOptions o = test::coarse_phantom_options(PhantomSceneOptions{}.youngs_modulus);
    o.gland_youngs_modulus = 6800;
    o.tumour_youngs_modulus = 20400;
    write_phantom_scene(d, o);
    return d;
  }();
  return dir;
}

std::string scene_variant(const std::string& name, const std::string& regions_yaml) {
  const std::string path = labelled_phantom_dir() + "/" + name + ".yaml";
  write_text(path, without_key(scene_text(labelled_phantom_dir()), "regions") + regions_yaml + "\n");
  return path;
}

double youngs_modulus(const StableNeoHookean& m) {
  const double mu = m.mu(), l = m.lambda() - mu;
  return mu * (3 * l + 2 * mu) / (l + mu);
}

}  // namespace

TEST(MaterialRegions, TheLabelledPhantomGivesEachTissueItsMaterial) {
  const std::string dir = labelled_phantom_dir();
  const std::vector<int> labels = cell_labels(read_tet_mesh_file(dir + "/prone.vtk", LengthUnit::Millimetre), "", "prone.vtk");
  const long gland = std::count(labels.begin(), labels.end(), kPhantomGlandLabel);
  const long tumour = std::count(labels.begin(), labels.end(), kPhantomTumourLabel);
  EXPECT_GT(gland, 100);
  EXPECT_GT(tumour, 10);
  const Scene s = load_meshed_scene(dir + "/scene.yaml");
  ASSERT_EQ(s.regions.size(), 2u);
  EXPECT_EQ(s.regions[0].name, "gland");
  EXPECT_NEAR(s.regions[0].youngs_modulus, 2 * s.material.youngs_modulus, 1e-9);  // the ratio, at the method's E
  EXPECT_NEAR(s.regions[1].youngs_modulus, 6 * s.material.youngs_modulus, 1e-9);
  std::vector<std::string> warnings;
  const RegistrationModel m = prepare_model(s, warnings);
  ASSERT_EQ(m.materials.size(), 3u);
  EXPECT_EQ(m.material_names, (std::vector<std::string>{"body", "gland", "tumour"}));
  EXPECT_EQ(m.material_tetrahedra[1], gland);
  EXPECT_EQ(m.material_tetrahedra[2], tumour);
  for (size_t t = 0; t < labels.size(); ++t) EXPECT_EQ(m.material_of[t], labels[t] - 1) << t;
  EXPECT_NEAR(youngs_modulus(m.materials[1]), 6800, 1e-6);
  const RegistrationResult r = run_registration(s, m, preset_options("balanced"));
  const nlohmann::json report = nlohmann::json::parse(registration_report_json(s, m, r, 0));
  const nlohmann::json& materials = report.at("materials");
  ASSERT_EQ(materials.size(), 3u);
  EXPECT_EQ(report.at("material_model").at("volume_form"), "element");  // auto at nu 0.49
  EXPECT_NEAR(report.at("material_model").at("poisson_ratio").get<double>(), 0.49, 1e-12);
  EXPECT_EQ(materials[1].at("name"), "gland");
  EXPECT_NEAR(materials[1].at("youngs_modulus_Pa").get<double>(), 6800, 1e-6);
  EXPECT_EQ(materials[1].at("tetrahedra").get<long>(), gland);
  EXPECT_TRUE(r.converged) << btr::test::step_stops(r);
  // Our own FEM made this truth with these materials: the method told them lands on it.
  for (const auto& t : r.tumours) EXPECT_LT(t.centroid_distance, 1e-4) << t.name;
}

TEST(MaterialRegions, ASurfaceRegionSelectsTheLabelledTetrahedra) {
  const Scene by_label = load_meshed_scene(labelled_phantom_dir() + "/scene.yaml");
  const Scene by_surface =
      load_meshed_scene(scene_variant("gland_surface", "regions: [{name: gland, surface: gland_prone.obj, youngs_modulus: 6800}]"));
  std::vector<std::string> w;
  const RegistrationModel a = prepare_model(by_label, w), b = prepare_model(by_surface, w);
  std::set<int> la, lb;
  for (size_t t = 0; t < a.material_of.size(); ++t) {
    if (a.material_names[a.material_of[t]] == "gland") la.insert(static_cast<int>(t));
    if (b.material_names[b.material_of[t]] == "gland") lb.insert(static_cast<int>(t));
  }
  std::vector<int> common;
  std::set_intersection(la.begin(), la.end(), lb.begin(), lb.end(), std::back_inserter(common));
  // The labels leave out the tumours' tetrahedra (tumour wins); the surface region has them.
  EXPECT_GT(static_cast<double>(common.size()), 0.97 * la.size());
  EXPECT_LT(lb.size(), la.size() + a.material_tetrahedra[2] + 0.03 * la.size());
}

TEST(MaterialRegions, TheSimulationMeshCarriesTheLabels) {
  const Scene s = load_meshed_scene(labelled_phantom_dir() + "/scene.yaml");
  const Scene coarse = with_simulation_mesh(s, 0.016, 0);
  ASSERT_EQ(static_cast<Eigen::Index>(coarse.prone_labels.size()), coarse.prone.T.rows());
  auto gland_fraction = [](const TetMesh& m, const std::vector<int>& labels) {
    double g = 0, all = 0;
    for (Eigen::Index t = 0; t < m.T.rows(); ++t) {
      const Vec3 a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)), d = m.V.row(m.T(t, 3));
      const double v = std::abs((b - a).cross(c - a).dot(d - a)) / 6;
      all += v;
      if (labels[t] == kPhantomGlandLabel) g += v;
    }
    return g / all;
  };
  const double fine = gland_fraction(s.prone, s.prone_labels), coarse_f = gland_fraction(coarse.prone, coarse.prone_labels);
  std::printf("gland volume fraction: %.3f on the scene mesh (%ld tets), %.3f on the 16 mm simulation mesh (%ld)\n", fine,
              static_cast<long>(s.prone.T.rows()), coarse_f, static_cast<long>(coarse.prone.T.rows()));
  EXPECT_NEAR(coarse_f, fine, 0.25 * fine);
  std::vector<std::string> w;
  EXPECT_EQ(prepare_model(coarse, w).material_names.size(), 3u);
}

TEST(MaterialRegions, BadRegionsAreClearErrors) {
  std::vector<std::string> w;
  expect_throw_with<InputError>(
      [&] { prepare_model(load_meshed_scene(scene_variant("r2", "regions: [{name: gland, label: 7, youngs_modulus: 6800}]")), w); },
      "no tetrahedron carries label 7");
  expect_throw_with<InputError>(
      [] { load_meshed_scene(scene_variant("r3", "regions: [{name: gland, label: 2, surface: gland_prone.obj, youngs_modulus: 1}]")); },
      "exactly one of 'label'");
  expect_throw_with<InputError>(
      [] { load_meshed_scene(scene_variant("r4", "regions: [{name: gland, label: 2, youngs_modulus: 1, relative_stiffness: 2}]")); },
      "exactly one of 'youngs_modulus'");
  expect_throw_with<InputError>([] { load_meshed_scene(scene_variant("r5", "regions: [{name: gland, label: 2, youngs_modulus: -5}]")); },
                                "youngs_modulus must be a positive");
  expect_throw_with<InputError>([] { load_meshed_scene(scene_variant("r6", "regions: [{label: 2, youngs_modulus: 5}]")); },
                                "regions[0].name");
  expect_throw_with<InputError>([] { load_meshed_scene(scene_variant("r7", "regions: [{name: g, labl: 2, youngs_modulus: 5}]")); },
                                "did you mean");
  // A surface prone model has no cells to carry labels.
  const std::string surf = labelled_phantom_dir() + "/surface_prone.yaml";
  write_text(labelled_phantom_dir() + "/three.txt", "0 1 2\n");
  write_text(surf, "units: mm\nprone: {surface: prone_surface.obj}\nchest_wall: three.txt\ngravity: [0, 0, -9.81]\n"
                   "supine: {surface: supine_surface.obj}\nregions: [{name: gland, label: 2, youngs_modulus: 5}]\n");
  expect_throw_with<InputError>([&] { load_meshed_scene(surf); }, "needs prone.tet_mesh");
}

// A region smaller than the mesh resolves (a small tumour on a preset's 9 or 11 mm mesh) used to
// fail the call ("no tetrahedron centroid lies inside its surface; refine the mesh"). Now the
// tetrahedron holding its centroid takes the partial-volume mixture, and a warning says so.
TEST(MaterialRegions, ARegionSmallerThanTheMeshStiffensTheTetrahedronHoldingItByItsShare) {
  EXPECT_EQ(partial_volume_youngs_modulus(1000, 8000, 0), 1000);
  EXPECT_NEAR(partial_volume_youngs_modulus(1000, 8000, 1), 8000, 1e-9);
  EXPECT_EQ(partial_volume_youngs_modulus(1000, 1000, 0.3), 1000);
  EXPECT_NEAR(partial_volume_youngs_modulus(1000, 1e15, 0.01), 1000 * (1 + 2.5 * 0.01 / 0.99), 1e-6);  // Einstein's dilute limit
  const double half = partial_volume_youngs_modulus(1000, 8000, 0.5);
  EXPECT_GT(half, 1000);
  EXPECT_LT(half, 0.5 * (1000 + 8000));  // below the volume average: a stiff inclusion in a soft matrix
  EXPECT_THROW(partial_volume_youngs_modulus(1000, 8000, 1.5), InputError);

  // A speck of 1 mm (a tumour's surface shrunk about its centroid) on the 12 mm phantom.
  SurfaceMesh speck = read_surface(labelled_phantom_dir() + "/tumour_top_prone.obj", LengthUnit::Millimetre);
  const Eigen::RowVector3d c = speck.V.colwise().mean();
  speck.V = (speck.V.rowwise() - c) * (1e-3 / (speck.V.colwise().maxCoeff() - speck.V.colwise().minCoeff()).maxCoeff());
  speck.V.rowwise() += c;
  write_surface(labelled_phantom_dir() + "/speck_prone.obj", speck, LengthUnit::Millimetre);
  const Scene s = load_meshed_scene(scene_variant("speck", "regions: [{name: speck, surface: speck_prone.obj, youngs_modulus: 34000}]"));
  std::vector<std::string> w;
  const RegistrationModel m = prepare_model(s, w);
  ASSERT_EQ(m.material_names.back(), "speck (partial volume)");
  EXPECT_EQ(m.material_tetrahedra.back(), 1);
  const double E = youngs_modulus(m.materials.back());
  EXPECT_GT(E, 3400);
  EXPECT_LT(E, 3400 * 1.05);  // 1 mm^3 of a tetrahedron of the 12 mm mesh
  ASSERT_FALSE(w.empty());
  EXPECT_NE(w.back().find("regions 'speck': no tetrahedron centroid lies inside its surface"), std::string::npos) << w.back();
  EXPECT_NE(w.back().find("A finer --cell-size resolves it"), std::string::npos) << w.back();
}

TEST(MaterialRegions, AnEstimatedStiffnessScalesEveryRegion) {
  // Relative stiffness: the estimate moves the body's E and the regions keep their ratios.
  const std::string path = labelled_phantom_dir() + "/estimate.yaml";
  write_text(path, without_key(scene_text(labelled_phantom_dir()), "material") +
                       "material: {youngs_modulus: estimate}\nprone_gravity: [0, 0, 9.81]\n");
  const Scene s = load_meshed_scene(path);
  std::vector<std::string> w;
  const RegistrationModel m = prepare_model(s, w);
  const RegistrationResult r = run_registration(s, m, preset_options("balanced"));
  std::printf("labelled 3400 Pa phantom, E estimated: %.0f Pa, worst tumour %.4f mm\n", r.estimated_youngs_modulus,
              btr::test::worst_error(r) * 1e3);
  EXPECT_NEAR(r.estimated_youngs_modulus, 3400, 340);
  const nlohmann::json j = nlohmann::json::parse(registration_report_json(s, m, r, 0));
  EXPECT_EQ(j.at("materials")[1].at("name"), "gland");
  const double gland_E = j.at("materials")[1].at("youngs_modulus_Pa").get<double>();
  EXPECT_NEAR(gland_E / r.estimated_youngs_modulus, 2.0, 1e-9);
  EXPECT_DOUBLE_EQ(j.at("stiffness").at("estimated_youngs_modulus_Pa").get<double>(), r.estimated_youngs_modulus);
  EXPECT_DOUBLE_EQ(j.at("stiffness").at("log_sd").get<double>(), r.estimated_youngs_modulus_log_sd);
}

// The uncertainty sampling and the stiffness search edit a prepared model's materials: scaling
// keeps Poisson's ratio (it used to add one shear modulus to the volume stiffness per call,
// because lambda() is the SNH lambda_L + mu and from_lame takes lambda_L), and a new Poisson's
// ratio keeps each material's Young's modulus.
TEST(MaterialRegions, ScalingKeepsPoissonsRatioAndANewRatioKeepsYoungsModulus) {
  RegistrationModel m;
  m.materials = {StableNeoHookean(1000, 0.49), StableNeoHookean(5000, 0.49)};
  m.material.youngs_modulus = 1000;
  auto expect_material = [](const StableNeoHookean& got, double e, double nu) {
    const StableNeoHookean want(e, nu);
    EXPECT_NEAR(got.mu(), want.mu(), 1e-9 * want.mu());
    EXPECT_NEAR(got.lambda(), want.lambda(), 1e-9 * want.lambda());
  };
  scale_stiffness(m, 3);
  scale_stiffness(m, 1);  // the identity, however often
  expect_material(m.materials[0], 3000, 0.49);
  expect_material(m.materials[1], 15000, 0.49);
  EXPECT_DOUBLE_EQ(m.material.youngs_modulus, 3000);
  set_poisson_ratio(m, 0.45);
  expect_material(m.materials[0], 3000, 0.45);
  expect_material(m.materials[1], 15000, 0.45);
  EXPECT_DOUBLE_EQ(m.material.poisson_ratio, 0.45);
  expect_throw_with<InputError>([&] { set_poisson_ratio(m, 0.5); }, "Poisson's ratio");
}
