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

/// E drawn over a narrow range and every other source off (the discretisation too): the
/// samples then show which model and mesh drew them.
UncertaintyOptions stiffness_only_sources() {
  UncertaintyOptions sources;
  sources.sources.youngs_modulus_range = {3000, 3800};
  sources.sources.gravity_direction_deg = 0;
  sources.sources.landmark_sd = 0;
  sources.sources.depth_noise = 0;
  sources.sources.discretisation = false;
  return sources;
}

/// Two samples each, with the same centroids to the bit.
void expect_same_samples(const SampledUncertainty& a, const SampledUncertainty& b) {
  ASSERT_EQ(a.samples, 2) << a.note;
  ASSERT_EQ(a.tumours.size(), b.tumours.size());
  for (size_t i = 0; i < a.tumours.size(); ++i) {
    ASSERT_EQ(a.tumours[i].centroids.size(), b.tumours[i].centroids.size());
    for (size_t k = 0; k < a.tumours[i].centroids.size(); ++k)
      EXPECT_EQ((a.tumours[i].centroids[k] - b.tumours[i].centroids[k]).norm(), 0.0);
  }
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

// A preset may ask for the nodal volume form (RegistrationOptions::volume_form; balanced does).
// The engine takes it where the scene's material leaves the form to `auto` and the scene plans
// the unloaded shape, on the preset's mesh for that form, prepared once and kept beside the
// element form's; a form the scene states, or a scene that keeps the prone shape as its rest
// shape, keeps the element form.
TEST(Engine, APresetsNodalFormIsTakenWhereTheSceneUnloadsAndLeavesTheFormToAuto) {
  Scene s = btr::test::coarse_phantom_scene();
  ASSERT_EQ(s.material.volume_form, VolumeForm::Auto);
  ASSERT_EQ(resolve_volume_form(s.material.volume_form, s.material.poisson_ratio), VolumeForm::Element);
  s.prone_gravity = Vec3(0, 0, 9.81);
  const RegistrationOptions balanced = preset_options("balanced");
  ASSERT_EQ(balanced.volume_form, VolumeForm::Nodal);
  RegistrationOptions by_poisson = balanced;
  by_poisson.volume_form = VolumeForm::Auto;
  RegistrationOptions nodal = balanced;
  nodal.nodal_simulation_cell_size = 0.025;  // coarser than this 12 mm mesh: re-tetrahedralized
  EXPECT_TRUE(takes_preset_volume_form(s, nodal));
  // The mesh a call asks for is the nodal form's where the preset takes it (a mesh made at that
  // size, e.g. by btr_scene_from_labels, is simulated as it is), else the preset's element mesh.
  EXPECT_EQ(simulation_cell_size_for(s, nodal), 0.025);
  EXPECT_EQ(simulation_cell_size_for(s, by_poisson), balanced.simulation_cell_size);
  Scene not_unloading = s;
  not_unloading.prone_gravity.reset();
  EXPECT_EQ(simulation_cell_size_for(not_unloading, nodal), balanced.simulation_cell_size);

  RegistrationEngine engine(s);
  const RegistrationResult r = engine.solve(nodal);
  EXPECT_TRUE(r.converged) << btr::test::step_stops(r);
  EXPECT_EQ(r.volume_form, VolumeForm::Nodal);
  const PreparedScene& pn = engine.prepare(nodal);
  EXPECT_NE(pn.mesh_note.find("re-tetrahedralized"), std::string::npos) << pn.mesh_note;
  Scene stated = with_simulation_mesh(s, 0.025, 0);
  stated.material.volume_form = VolumeForm::Nodal;
  stated.material.unload_element_order = nodal.unload_element_order;  // the preset's with its nodal form
  EXPECT_EQ(largest_difference(r.x, fresh(stated, nodal).x), 0.0);  // as if the scene had said nodal, on that mesh

  const PreparedScene& pe = engine.prepare(by_poisson);
  EXPECT_NE(&pn, &pe);
  EXPECT_EQ(pn.model.volume_form, VolumeForm::Nodal);
  EXPECT_EQ(pe.model.volume_form, VolumeForm::Element);
  EXPECT_EQ(pe.model.rest.T.rows(), s.prone.T.rows());  // the element form on the scene's mesh
  EXPECT_LT(pn.model.rest.T.rows(), pe.model.rest.T.rows());
  EXPECT_EQ(&engine.prepare(nodal), &pn);  // each kept
  EXPECT_EQ(&engine.prepare(by_poisson), &pe);
  const RegistrationResult e = engine.solve(by_poisson);
  EXPECT_EQ(e.volume_form, VolumeForm::Element);
  EXPECT_EQ(largest_difference(e.x, fresh(s, by_poisson).x), 0.0);
  // On one mesh the two forms are one entry and its twin.
  const PreparedScene& own = engine.prepare(balanced);
  EXPECT_EQ(own.model.volume_form, VolumeForm::Nodal);
  EXPECT_EQ(own.model.rest.T.rows(), s.prone.T.rows());

  Scene told = s;  // the scene's explicit form wins
  told.material.volume_form = VolumeForm::Element;
  EXPECT_FALSE(takes_preset_volume_form(told, balanced));
  EXPECT_EQ(RegistrationEngine(told).prepare(balanced).model.volume_form, VolumeForm::Element);
  Scene prone_rest = s;  // the thesis's model: the prone shape as the rest shape
  prone_rest.prone_gravity.reset();
  EXPECT_FALSE(takes_preset_volume_form(prone_rest, balanced));
  EXPECT_EQ(RegistrationEngine(prone_rest).prepare(balanced).model.volume_form, VolumeForm::Element);
}

// A preset's tumour cells (RegistrationOptions::tumour_cell_size; accurate's 4 mm) apply where a
// call meshes the prone model and the scene states none; the engine keeps the mesh made with
// them apart from the one made without, and a scene's stated 0 means none.
TEST(Engine, APresetsTumourCellsRefineTheMeshItMakesUnlessTheSceneStatesItsOwn) {
  const Scene s = btr::test::coarse_phantom_scene();  // 12 mm, keeps the prone shape as rest
  ASSERT_FALSE(s.tumour_cell_size.has_value());
  RegistrationOptions coarse = preset_options("balanced");
  coarse.simulation_cell_size = 0.025;  // coarser than the scene's mesh: re-tetrahedralized
  RegistrationOptions cells = coarse;
  cells.tumour_cell_size = 0.008;
  RegistrationEngine engine(s);
  const PreparedScene& plain = engine.prepare(coarse);
  const PreparedScene& refined = engine.prepare(cells);
  EXPECT_NE(&plain, &refined);
  EXPECT_EQ(plain.mesh_note.find("tumours"), std::string::npos) << plain.mesh_note;
  EXPECT_NE(refined.mesh_note.find("8.0 mm in the tumours' balls"), std::string::npos) << refined.mesh_note;
  EXPECT_GT(refined.model.rest.T.rows(), plain.model.rest.T.rows());
  EXPECT_EQ(refined.model.rest.T.rows(), with_simulation_mesh(s, 0.025, 0.008).prone.T.rows());
  EXPECT_EQ(&engine.prepare(cells), &refined);  // kept
  Scene none = s;  // prone.tumour_cell_size_mm: 0
  none.tumour_cell_size = 0.0;
  EXPECT_EQ(RegistrationEngine(none).prepare(cells).model.rest.T.rows(), plain.model.rest.T.rows());
  RegistrationOptions at_scene_mesh = cells;  // the scene's mesh as given: nothing is meshed, nothing refined
  at_scene_mesh.simulation_cell_size = 0;
  EXPECT_EQ(RegistrationEngine(s).prepare(at_scene_mesh).model.rest.T.rows(), s.prone.T.rows());
}

// With their nodal form the balanced and accurate presets unload with quadratic elements, where
// the scene does not state the unload's elements; a stated order wins, and a preset without the
// nodal form (fast, or a scene that keeps the prone shape) unloads as the scene says. The engine
// keeps one entry per mesh and unload order, so a call's model does not depend on which preset
// asked first.
TEST(Engine, APresetsNodalFormUnloadsWithQuadraticElementsWhereTheSceneLeavesItOpen) {
  Scene s = btr::test::coarse_phantom_scene();
  s.prone_gravity = Vec3(0, 0, 9.81);
  ASSERT_FALSE(s.unload_element_order_stated);
  const RegistrationOptions balanced = preset_options("balanced"), fast = preset_options("fast");
  EXPECT_EQ(preset_unload_elements(s, balanced), ElementOrder::Quadratic);
  EXPECT_EQ(preset_unload_elements(s, fast), ElementOrder::Linear);
  EXPECT_EQ(preset_unload_elements(s, preset_options("accurate")), ElementOrder::Quadratic);
  Scene stated = s;
  stated.unload_element_order_stated = true;  // material.unload_element_order: linear
  EXPECT_EQ(preset_unload_elements(stated, balanced), ElementOrder::Linear);
  Scene element = s;
  element.material.volume_form = VolumeForm::Element;  // the scene's own form: not the preset's choice
  EXPECT_EQ(preset_unload_elements(element, balanced), ElementOrder::Linear);

  auto unloaded_with = [](const PreparedScene& p) {
    EXPECT_TRUE(p.model.unload.has_value());
    return p.model.unload ? p.model.unload->unload.elements : ElementOrder::Linear;
  };
  RegistrationEngine fast_first(s), balanced_first(s);
  const PreparedScene& f1 = fast_first.prepare(fast);
  const PreparedScene& b1 = fast_first.prepare(balanced);
  const PreparedScene& b2 = balanced_first.prepare(balanced);
  const PreparedScene& f2 = balanced_first.prepare(fast);
  EXPECT_EQ(unloaded_with(f1), ElementOrder::Linear);
  EXPECT_EQ(unloaded_with(f2), ElementOrder::Linear);
  EXPECT_EQ(unloaded_with(b1), ElementOrder::Quadratic);
  EXPECT_EQ(unloaded_with(b2), ElementOrder::Quadratic);
  EXPECT_EQ(largest_difference(f1.model.rest.V, f2.model.rest.V), 0.0);  // whichever preset came first
  EXPECT_EQ(largest_difference(b1.model.rest.V, b2.model.rest.V), 0.0);
  EXPECT_GT(largest_difference(b1.model.rest.V, f1.model.rest.V), 1e-4);  // the two unloads differ here
  EXPECT_EQ(unloaded_with(RegistrationEngine(stated).prepare(balanced)), ElementOrder::Linear);
}

// Where the nodal form was the preset's choice (balanced: nodal on a 9 mm mesh where a scene
// unloads), a nodal registration that does not converge falls back to the call as it would be
// without that choice: the element form on the preset's element mesh (7 mm), not on the nodal
// form's coarser mesh. The result, its prepared scene and its samples are that call's. Case: the
// fallback case below, unloaded; the element form on the scene's 12 mm mesh, the nodal on a
// coarser one.
TEST(Engine, APresetsNodalFormFallsBackToTheElementFormOnThePresetsElementMesh) {
  const std::string d = btr::test::write_coarse_phantom("phantom12_400_fallback", 400);
  Scene s = load_meshed_scene(d + "/scene.yaml");
  s.steps = {"landmarks", "surface"};
  s.prone_gravity = Vec3(0, 0, 9.81);
  apply_misalignment(s, misalignment_from_degrees_mm(Vec3::Zero(), Vec3(0, 0, 10)));
  RegistrationOptions opt = preset_options("balanced");
  opt.simulation_cell_size = 0;  // the element form on the scene's mesh
  opt.nodal_simulation_cell_size = 0.02;  // coarser: re-tetrahedralized
  ASSERT_TRUE(takes_preset_volume_form(s, opt));
  RegistrationOptions own = opt;  // the call without the preset's nodal form
  own.volume_form = VolumeForm::Auto;

  Scene kept_scene = s;
  kept_scene.nodal_fallback = false;
  RegistrationEngine kept_engine(kept_scene);
  const RegistrationResult kept = kept_engine.solve(opt);
  ASSERT_FALSE(kept.converged) << "the case no longer needs the fallback";
  EXPECT_EQ(kept.volume_form, VolumeForm::Nodal);
  EXPECT_LT(kept.x.rows(), s.prone.V.rows());  // on the nodal form's coarser mesh
  const RegistrationResult reference = fresh(s, own);
  ASSERT_TRUE(reference.converged) << btr::test::step_stops(reference);

  RegistrationEngine engine(s);
  const RegistrationResult r = engine.solve(opt);
  EXPECT_TRUE(r.converged) << btr::test::step_stops(r);
  EXPECT_EQ(r.volume_form, VolumeForm::Element);
  ASSERT_TRUE(r.volume_form_fallback);
  EXPECT_EQ(r.volume_form_fallback->mesh_note, "the scene's mesh");
  EXPECT_GT(r.volume_form_fallback->prepare_seconds, 0.0);
  EXPECT_TRUE(btr::test::has_warning(r, "registered again with the element form on the preset's mesh for it (the scene's mesh), which converged"));
  EXPECT_EQ(largest_difference(r.x, reference.x), 0.0);  // the element form's own call, bit for bit
  const PreparedScene& computed = engine.prepared_for(opt, r);
  EXPECT_EQ(&computed, &engine.prepare(own));
  EXPECT_NE(&computed, &engine.prepare(opt));
  EXPECT_EQ(computed.model.rest.V.rows(), r.x.rows());
  EXPECT_EQ(computed.model.volume_form, VolumeForm::Element);
  const RegistrationResult again = engine.solve(opt);  // prepared once
  ASSERT_TRUE(again.volume_form_fallback);
  EXPECT_EQ(again.volume_form_fallback->prepare_seconds, 0.0);
  EXPECT_EQ(largest_difference(again.x, reference.x), 0.0);

  // The samples are drawn on the element form's mesh: as an engine that registers `own` draws them.
  const UncertaintyOptions sources = stiffness_only_sources();
  RegistrationEngine element_engine(s);
  expect_same_samples(engine.sample_uncertainty(opt, sources, 2, 1, r),
                      element_engine.sample_uncertainty(own, sources, 2, 1, element_engine.solve(own)));
}

// The nodal volume form folds coarse soft meshes where the element form's locking holds them
// together (BENCHMARKS.md, "The nodal volume term as the default"). Where a nodal registration
// ends not converged the engine registers again with the element form, returns that result and
// says so; where the nodal form converges, nothing changes. Case: the 12 mm phantom made at
// 400 Pa, the thesis's method (3400 Pa, prone shape as rest) on a scan shifted 10 mm along z
// without the rigid step, a run the experiment suite's nodal form does not converge.
TEST(Engine, ANodalRegistrationThatDoesNotConvergeFallsBackToTheElementForm) {
  const std::string d = btr::test::write_coarse_phantom("phantom12_400_fallback", 400);
  Scene s = load_meshed_scene(d + "/scene.yaml");
  s.steps = {"landmarks", "surface"};
  apply_misalignment(s, misalignment_from_degrees_mm(Vec3::Zero(), Vec3(0, 0, 10)));
  const RegistrationOptions opt = preset_options("balanced");

  Scene element = s;
  element.material.volume_form = VolumeForm::Element;
  const RegistrationResult reference = fresh(element, opt);
  ASSERT_TRUE(reference.converged) << btr::test::step_stops(reference);

  Scene nodal = s;
  nodal.material.volume_form = VolumeForm::Nodal;
  nodal.nodal_fallback = false;
  const RegistrationResult kept = RegistrationEngine(nodal).solve(opt);
  ASSERT_FALSE(kept.converged) << "the case no longer needs the fallback";
  EXPECT_EQ(kept.volume_form, VolumeForm::Nodal);
  EXPECT_FALSE(kept.volume_form_fallback);

  nodal.nodal_fallback = true;
  RegistrationEngine engine(nodal);
  const RegistrationResult r = engine.solve(opt);
  EXPECT_TRUE(r.converged) << btr::test::step_stops(r);
  EXPECT_EQ(r.volume_form, VolumeForm::Element);
  ASSERT_TRUE(r.volume_form_fallback);
  EXPECT_FALSE(r.volume_form_fallback->nodal_stop.empty());
  EXPECT_GT(r.volume_form_fallback->nodal_seconds, 0.0);
  EXPECT_GT(r.volume_form_fallback->prepare_seconds, 0.0);
  EXPECT_GE(r.seconds, r.volume_form_fallback->nodal_seconds + r.volume_form_fallback->prepare_seconds);
  EXPECT_TRUE(btr::test::has_warning(r, "registered again with the element form, which converged"));
  // The element form's own answer, whatever the nodal attempt left behind.
  EXPECT_EQ(largest_difference(r.x, reference.x), 0.0);
  ASSERT_EQ(r.tumours.size(), reference.tumours.size());
  for (size_t i = 0; i < r.tumours.size(); ++i)
    EXPECT_EQ(r.tumours[i].centroid_distance, reference.tumours[i].centroid_distance);

  // A second call reuses the element form's prepared model; sampling follows the nominal's form.
  const RegistrationResult again = engine.solve(opt);
  ASSERT_TRUE(again.volume_form_fallback);
  EXPECT_EQ(again.volume_form_fallback->prepare_seconds, 0.0);
  EXPECT_EQ(largest_difference(again.x, reference.x), 0.0);
  // The samples are the element form's: the same draws on an element-form engine give the same
  // centroids, to the bit.
  const UncertaintyOptions sources = stiffness_only_sources();
  const SampledUncertainty su = engine.sample_uncertainty(opt, sources, 2, 1, r);
  EXPECT_NE(su.note.find("sampled with the element volume form"), std::string::npos) << su.note;
  RegistrationEngine element_engine(element);
  expect_same_samples(su, element_engine.sample_uncertainty(opt, sources, 2, 1, element_engine.solve(opt)));

  // Where the nodal form converges (the aligned scan with the rigid step), it is the answer.
  Scene aligned = load_meshed_scene(d + "/scene.yaml");
  aligned.material.volume_form = VolumeForm::Nodal;
  const RegistrationResult n = RegistrationEngine(aligned).solve(opt);
  ASSERT_TRUE(n.converged) << btr::test::step_stops(n);
  EXPECT_EQ(n.volume_form, VolumeForm::Nodal);
  EXPECT_FALSE(n.volume_form_fallback);
}
