#include <filesystem>
#include <set>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/gravity_simulation.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/tetrahedralize.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/simulation/phantom.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"
#include "test_util.h"

using namespace btr;

namespace {

const PhantomModel& coarse_phantom() {
  static const PhantomModel m = [] {
    PhantomOptions o;
    o.tet.cell_size = 0.012;
    o.surface_rings = 12;
    return make_phantom_model(o);
  }();
  return m;
}

}  // namespace

TEST(Phantom, HalfEllipsoidHasTheThesisSizeAndVolume) {
  const SurfaceMesh s = make_half_ellipsoid(0.0745, 0.0745, 0.072, 24);
  validate_surface(s, "half ellipsoid");
  const Vec3 ext = (s.V.colwise().maxCoeff() - s.V.colwise().minCoeff()).transpose();
  EXPECT_NEAR(ext.x(), 0.149, 1e-9);
  EXPECT_NEAR(ext.y(), 0.149, 1e-3);  // rings sample y at 6k azimuths
  EXPECT_NEAR(ext.z(), 0.072, 1e-12);
  double vol = 0;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f)
    vol += Vec3(s.V.row(s.F(f, 0))).dot(Vec3(s.V.row(s.F(f, 1))).cross(Vec3(s.V.row(s.F(f, 2))))) / 6.0;
  EXPECT_NEAR(vol, 2.0 / 3.0 * M_PI * 0.0745 * 0.0745 * 0.072, 0.01 * vol);
}

TEST(Phantom, ModelHasChestWallLandmarksAndTumoursInside) {
  const PhantomModel& m = coarse_phantom();
  EXPECT_NO_THROW(validate_tet_mesh(m.rest, "phantom"));
  for (int v : m.chest_wall) EXPECT_LT(std::abs(m.rest.V(v, 2)), 1e-9);
  EXPECT_EQ(m.landmarks.size(), 13u);
  std::set<int> distinct;
  for (const auto& [name, v] : m.landmarks) {
    distinct.insert(v);
    EXPECT_GT(m.rest.V(v, 2), 0.005) << name << " should be on the skin, not the chest wall";
  }
  EXPECT_EQ(distinct.size(), 13u);
  EXPECT_EQ(m.rest.V(m.landmarks.at("C"), 2), m.rest.V.col(2).maxCoeff());
  for (const auto& name : phantom_tumour_names()) {
    const Embedding e = embed_points(m.rest, m.tumours.at(name).V);
    EXPECT_TRUE(e.outside.empty()) << name;
  }
  EXPECT_EQ(phantom_landmark_set("C+O").size(), 5u);
  EXPECT_EQ(phantom_landmark_set("O+Oa+I").size(), 12u);
  btr::test::expect_throw_with<InputError>([] { phantom_landmark_set("C,X9"); }, "unknown landmark");
}

TEST(Phantom, ProneHangsAndSupineFlattensWithTheChestWallFixed) {
  const PhantomModel& m = coarse_phantom();
  GravityProblem pb;
  pb.rest = &m.rest;
  pb.fixed = m.chest_wall;
  pb.youngs_modulus = 3400;
  const int apex = m.landmarks.at("C");
  pb.gravity = Vec3(0, 0, 9.81);
  const GravityResult prone = solve_gravity(pb, NewtonOptions{});
  pb.gravity = Vec3(0, 0, -9.81);
  const GravityResult supine = solve_gravity(pb, NewtonOptions{});
  ASSERT_TRUE(prone.newton.converged);
  ASSERT_TRUE(supine.newton.converged);
  const double up = prone.x(apex, 2) - m.rest.V(apex, 2), down = supine.x(apex, 2) - m.rest.V(apex, 2);
  std::printf("apex: prone %+.1f mm, supine %+.1f mm (%d + %d Newton iterations)\n", up * 1e3, down * 1e3,
              prone.newton.iterations, supine.newton.iterations);
  EXPECT_GT(up, 0.002);
  EXPECT_LT(down, -0.002);
  for (int v : m.chest_wall) {
    EXPECT_EQ((prone.x.row(v) - m.rest.V.row(v)).norm(), 0.0);
    EXPECT_EQ((supine.x.row(v) - m.rest.V.row(v)).norm(), 0.0);
  }
  // Stiffer tissue deforms less.
  pb.youngs_modulus = 12000;
  const GravityResult stiff = solve_gravity(pb, NewtonOptions{});
  EXPECT_GT(stiff.x(apex, 2) - m.rest.V(apex, 2), down);
}

TEST(Phantom, ATruthWithFoldedElementsIsRefusedWithItsCause) {
  // The nodal volume term keeps patches, not single tetrahedra, from inverting: at 600 Pa on the
  // coarse 12 mm phantom one element folds in the prone sag. Before, that truth was written and
  // only refused later, as a prone mesh, by the registration.
  PhantomOptions po;  // btr_phantom -E 600 --cell-size 12 --volume-form nodal
  po.tet.cell_size = 0.012;
  const PhantomModel model = make_phantom_model(po);
  PhantomSceneOptions so;
  so.youngs_modulus = 600;
  so.volume_form = VolumeForm::Nodal;
  btr::test::expect_throw_with<SolverError>([&] { simulate_phantom(model, so); }, "inverted tetrahedra under this load");
  // With an element share of 5 mu (nodal_volume_energy.h) the same truth holds; it folds two
  // elements from 300 Pa down, where the element form still holds.
  so.nodal_element_share = 5;
  EXPECT_EQ(count_inverted(simulate_phantom(model, so).prone, model.rest.T), 0);
  so.youngs_modulus = 300;
  btr::test::expect_throw_with<SolverError>([&] { simulate_phantom(model, so); }, "inverted tetrahedra under this load");
  so.volume_form = VolumeForm::Element;
  const PhantomConfigurations c = simulate_phantom(model, so);
  EXPECT_EQ(count_inverted(c.prone, model.rest.T), 0);
}

TEST(Phantom, AQuadraticTruthSagsAsTheLinearOneDoesOnlyOnAFinerMesh) {
  // A truth made with the method's own linear tetrahedra flatters it: on the 12 mm mesh at
  // nu = 0.49 they lock and the tumours move 5 mm prone to supine at 1000 Pa, 7.3 mm at 6 mm
  // and 8.1 mm at 4 mm (btr_phantom, 2026-12-06); quadratic elements move them about 8.8 mm on
  // either mesh. The linear answer converges towards the quadratic one from below.
  auto middle_displacement = [](const PhantomModel& m, ElementOrder order) {
    PhantomSceneOptions so;
    so.youngs_modulus = 1000;
    so.element_order = order;
    const PhantomConfigurations c = simulate_phantom(m, so);
    EXPECT_TRUE(c.prone_newton.converged && c.supine_newton.converged);
    for (int v : m.chest_wall) {
      EXPECT_EQ((c.prone.row(v) - m.rest.V.row(v)).norm(), 0.0);
      EXPECT_EQ((c.supine.row(v) - m.rest.V.row(v)).norm(), 0.0);
    }
    return (volume_centroid(c.tumour_supine.at("middle")) - volume_centroid(c.tumour_prone.at("middle"))).norm();
  };
  PhantomOptions fine;
  fine.tet.cell_size = 0.006;
  const double linear12 = middle_displacement(coarse_phantom(), ElementOrder::Linear);
  const double linear6 = middle_displacement(make_phantom_model(fine), ElementOrder::Linear);
  const double quadratic12 = middle_displacement(coarse_phantom(), ElementOrder::Quadratic);
  std::printf("middle tumour prone -> supine: linear 12 mm %.2f, linear 6 mm %.2f, quadratic 12 mm %.2f mm\n", linear12 * 1e3,
              linear6 * 1e3, quadratic12 * 1e3);
  EXPECT_LT(linear12, linear6);
  EXPECT_LT(linear6, quadratic12);
  EXPECT_GT(quadratic12, 1.5 * linear12);

  // A heterogeneous quadratic truth carries the gland too, and a soft one is made: of the kind
  // the old sub-tetrahedron check refused (homogeneous at 400 Pa: 124 inverted sub-tetrahedra,
  // no non-positive Jacobian; inversion_check.h).
  PhantomSceneOptions so;
  so.youngs_modulus = 400;
  so.gland_youngs_modulus = 800;
  so.element_order = ElementOrder::Quadratic;
  const PhantomConfigurations soft = simulate_phantom(coarse_phantom(), so);
  EXPECT_EQ(soft.gland_prone.V.rows(), coarse_phantom().gland.V.rows());
  EXPECT_EQ(soft.labels.size(), static_cast<size_t>(coarse_phantom().rest.T.rows()));
}

TEST(Phantom, AQuadraticTruthWhoseCornersInvertIsWrittenAsItsSkin) {
  // Soft quadratic truth on a coarse mesh: the curved elements hold, the straight tetrahedra
  // between their corners do not (a prone.vtk no reader accepts). The scene then gives the prone
  // model as its skin, tetrahedralized by the method, with the chest wall and landmarks
  // numbered on that skin and the regions as the closed surfaces the labels were made from.
  PhantomSceneOptions o = btr::test::coarse_phantom_options(350, ElementOrder::Quadratic);
  o.gland_youngs_modulus = 700;
  o.tumour_youngs_modulus = 3500;
  const std::string d = btr::test::temp_dir();
  const PhantomSceneSummary sum = write_phantom_scene(d, o);
  ASSERT_TRUE(sum.prone_written_as_surface);
  EXPECT_FALSE(std::filesystem::exists(d + "/prone.vtk"));
  const PhantomModel model = make_phantom_model(o.phantom);
  const PhantomConfigurations c = simulate_phantom(model, o);
  EXPECT_GT(c.prone_corner_inversions, 0);

  const Scene s = load_meshed_scene(d + "/scene.yaml");
  ASSERT_TRUE(s.prone_source.has_value());
  EXPECT_GT(s.prone.T.rows(), 500);
  EXPECT_EQ(count_inverted(s.prone.V, s.prone.T), 0);
  // The chest wall is the plane z = 0 of the phantom, prone as at rest.
  ASSERT_GT(s.chest_wall.size(), 10u);
  for (int v : s.chest_wall) EXPECT_NEAR(s.prone.V(v, 2), 0.0, 1e-9) << v;
  // Each landmark sits where the truth's skin vertex is and pairs with that vertex supine.
  const auto names = phantom_landmark_set(o.landmark_set);
  ASSERT_EQ(s.landmark_anchors.size(), names.size());
  // Prone, within the re-meshed skin's approximation of the written one (tetrahedralize.h).
  const double skin_tolerance = TetrahedralizeOptions{}.facet_distance_ratio * o.phantom.tet.cell_size;
  for (size_t i = 0; i < names.size(); ++i) {
    const int v = model.landmarks.at(names[i]);
    EXPECT_LT((s.landmark_anchors[i].position(s.prone.V) - c.prone.row(v).transpose()).norm(), skin_tolerance) << names[i];
    EXPECT_NEAR((s.landmark_supine.row(static_cast<Eigen::Index>(i)) - c.supine.row(v)).norm(), 0.0, 1e-6) << names[i];
  }
  // The regions: the gland and each tumour by its prone surface, at the generating ratios.
  ASSERT_EQ(s.regions.size(), 1u + phantom_tumour_names().size());
  EXPECT_EQ(s.regions[0].name, "gland");
  EXPECT_NEAR(s.regions[0].youngs_modulus, 2 * s.material.youngs_modulus, 1e-9);
  for (size_t k = 1; k < s.regions.size(); ++k) {
    EXPECT_TRUE(s.regions[k].surface.has_value()) << s.regions[k].name;
    EXPECT_NEAR(s.regions[k].youngs_modulus, 10 * s.material.youngs_modulus, 1e-9);
  }
}
