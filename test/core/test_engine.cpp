// The registration engine: prepared once, solved many times, with the answer of a fresh call.
#include <filesystem>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"
#include "test_util.h"

using namespace btr;
using btr::test::expect_throw_with;
using btr::test::make_rigid;

namespace {


double largest_difference(const Points& a, const Points& b) {
  EXPECT_EQ(a.rows(), b.rows());
  return a.rows() == b.rows() ? (a - b).cwiseAbs().maxCoeff() : 1.0;
}

RegistrationResult fresh(const Scene& s, const RegistrationOptions& opt) {
  std::vector<std::string> warnings;
  const RegistrationModel m = prepare_model(s, warnings);
  return run_registration(s, m, opt);
}

}  // namespace

TEST(Engine, RepeatedSolvesGiveTheFreshAnswerAndReuseEveryStepsSolver) {
  const Scene& s = btr::test::coarse_phantom_scene();
  const RegistrationOptions opt = preset_options("balanced");
  const RegistrationResult reference = fresh(s, opt);
  ASSERT_TRUE(reference.converged);
  RegistrationEngine engine(s);
  const RegistrationResult first = engine.solve(opt);
  const int built = engine.solvers_built();
  EXPECT_GE(built, 3);  // the landmark step's pattern and subspace, the surface step's pattern
  const int reused = engine.solvers_reused();  // within the call: the joint-pose check's subspace
  const RegistrationResult second = engine.solve(opt);
  EXPECT_EQ(engine.solvers_built(), built);  // nothing rebuilt
  EXPECT_GE(engine.solvers_reused() - reused, built);
  // The cache changes no answer: a reused solver starts without an earlier problem's factor.
  EXPECT_EQ(largest_difference(first.x, reference.x), 0.0);
  EXPECT_EQ(largest_difference(second.x, reference.x), 0.0);
  ASSERT_EQ(second.tumours.size(), reference.tumours.size());
  for (size_t i = 0; i < second.tumours.size(); ++i)
    EXPECT_EQ(second.tumours[i].centroid_distance, reference.tumours[i].centroid_distance);
  EXPECT_EQ(second.converged, reference.converged);
}

TEST(Engine, EachSimulationMeshIsPreparedOnceAndKept) {
  const Scene& s = btr::test::coarse_phantom_scene();
  RegistrationEngine engine(s);
  RegistrationOptions own = preset_options("balanced");  // 7 mm: coarser than this 12 mm mesh, so no remeshing
  const PreparedScene& a = engine.prepare(own);
  EXPECT_EQ(&engine.prepare(own), &a);
  EXPECT_TRUE(a.mesh_note.empty());
  EXPECT_EQ(a.model.rest.T.rows(), s.prone.T.rows());
  RegistrationOptions coarse = own;
  coarse.simulation_cell_size = 0.025;  // clearly coarser than the scene's mesh: re-tetrahedralized
  const PreparedScene& b = engine.prepare(coarse);
  EXPECT_NE(&b, &a);
  EXPECT_NE(b.mesh_note.find("re-tetrahedralized"), std::string::npos) << b.mesh_note;
  EXPECT_LT(b.model.rest.T.rows(), a.model.rest.T.rows());
  EXPECT_EQ(&engine.prepare(coarse), &b);
  EXPECT_EQ(b.model.tumours.size(), s.tumours.size());
}

TEST(Engine, AnotherSupineSideIsRegisteredOnThePreparedProneSide) {
  const Scene& s = btr::test::coarse_phantom_scene();
  const RegistrationOptions opt = preset_options("balanced");
  RegistrationEngine engine(s);
  engine.solve(opt);
  // The supine scan taken misaligned by 10 deg and 5 mm: the same as preparing that scene afresh.
  Scene turned = s;
  apply_misalignment(turned, misalignment_from_degrees_mm(Vec3(0, 0, 10), Vec3(5, 0, 0)));
  const RegistrationResult a = engine.solve(turned, opt), b = fresh(turned, opt);
  EXPECT_EQ(largest_difference(a.x, b.x), 0.0);
  EXPECT_TRUE((a.supine_to_model.matrix() - b.supine_to_model.matrix()).isZero(0.0));
  for (const auto& t : a.tumours) EXPECT_LT(t.centroid_distance, 1e-3) << t.name;
  // A supine side that does not belong to this prone side is refused, naming what differs.
  Scene fewer = s;
  fewer.landmark_supine = s.landmark_supine.topRows(2);
  expect_throw_with<InputError>([&] { engine.solve(fewer, opt); }, "landmark positions");
}

TEST(Engine, AnAdoptedModelIsSolvedAsGivenWhateverThePresetsMesh) {
  const Scene& s = btr::test::coarse_phantom_scene();
  std::vector<std::string> warnings;
  RegistrationModel m = prepare_model(s, warnings);
  const long tets = m.rest.T.rows();
  RegistrationEngine engine(s, std::move(m), warnings);
  RegistrationOptions coarse = preset_options("fast");
  coarse.simulation_cell_size = 0.025;
  EXPECT_EQ(engine.prepare(coarse).model.rest.T.rows(), tets);
  EXPECT_EQ(largest_difference(engine.solve(coarse).x, fresh(s, coarse).x), 0.0);
}
