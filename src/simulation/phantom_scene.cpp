#include "breast_tumour_registration/simulation/phantom_scene.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/forward_gravity.h"
#include "breast_tumour_registration/fem/gravity_simulation.h"
#include "breast_tumour_registration/fem/quadratic_tetrahedra.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/self_intersection.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/io/index_io.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "breast_tumour_registration/simulation/rest_model_io.h"

namespace btr {

std::vector<int> phantom_tissue_labels(const PhantomModel& model, const PhantomSceneOptions& opt) {
  if (opt.gland_youngs_modulus < 0 || opt.tumour_youngs_modulus < 0 || !std::isfinite(opt.gland_youngs_modulus) ||
      !std::isfinite(opt.tumour_youngs_modulus))
    throw InputError("phantom: gland and tumour Young's moduli must be >= 0 (0: the body's material)");
  if (opt.gland_youngs_modulus == 0 && opt.tumour_youngs_modulus == 0) return {};
  std::vector<int> labels(model.rest.T.rows(), kPhantomFatLabel);
  if (opt.gland_youngs_modulus > 0) {
    if (model.gland.F.rows() == 0) throw InputError("phantom: the rest model has no gland region to stiffen");
    for (int t : tetrahedra_inside(model.rest, {&model.gland})) labels[t] = kPhantomGlandLabel;
  }
  if (opt.tumour_youngs_modulus > 0) {
    std::vector<const SurfaceMesh*> tumours;
    for (const auto& [name, t] : model.tumours) tumours.push_back(&t);
    for (int t : tetrahedra_inside(model.rest, tumours)) labels[t] = kPhantomTumourLabel;
  }
  return labels;
}

PhantomConfigurations simulate_phantom(const PhantomModel& model, const PhantomSceneOptions& opt,
                                       const std::function<bool(const std::string&, const IterationInfo&)>& progress) {
  StableNeoHookean(opt.youngs_modulus, opt.poisson_ratio);  // validates before the expensive steps
  const std::vector<int> labels = phantom_tissue_labels(model, opt);
  std::vector<int> material_of;  // label 1, 2, 3 -> body, gland, tumour material
  std::vector<double> region_E;
  if (!labels.empty()) {
    std::vector<int> index_of(4, 0);
    if (opt.gland_youngs_modulus > 0) {
      region_E.push_back(opt.gland_youngs_modulus);
      index_of[kPhantomGlandLabel] = static_cast<int>(region_E.size());
    }
    if (opt.tumour_youngs_modulus > 0) {
      region_E.push_back(opt.tumour_youngs_modulus);
      index_of[kPhantomTumourLabel] = static_cast<int>(region_E.size());
    }
    for (int l : labels) material_of.push_back(index_of[l]);
  }
  std::vector<StableNeoHookean> materials{StableNeoHookean(opt.youngs_modulus, opt.poisson_ratio)};
  for (double E : region_E) materials.push_back(StableNeoHookean(E, opt.poisson_ratio));
  const VolumeForm form = resolve_volume_form(opt.volume_form, opt.poisson_ratio);
  auto inverted_error = [&](const std::string& name, long inverted, const std::string& elements) {
    return SolverError(name + " configuration has " + std::to_string(inverted) + " inverted " + elements +
                       " under this load (E " + std::to_string(static_cast<int>(opt.youngs_modulus)) + " Pa, " +
                       (opt.element_order == ElementOrder::Quadratic
                            ? std::string("quadratic elements): use a finer mesh or a stiffer material")
                            : std::string(to_string(form)) +
                                  " volume term): use a finer mesh, a stiffer material or the element volume term"));
  };
  // Linear elements: one Newton solve from the rest shape.
  auto solve_linear = [&](const std::string& name, const Vec3& g, NewtonResult& out) {
    GravityProblem pb;
    pb.rest = &model.rest;
    pb.fixed = model.chest_wall;
    pb.youngs_modulus = opt.youngs_modulus;
    pb.poisson_ratio = opt.poisson_ratio;
    pb.volume_form = opt.volume_form;
    pb.nodal_element_share = opt.nodal_element_share;
    pb.density = opt.density;
    pb.gravity = g;
    pb.material_of = material_of;
    pb.region_youngs_modulus = region_E;
    NewtonOptions newton;
    if (progress) newton.callback = [&](const IterationInfo& it) { return progress(name, it); };
    GravityResult r = solve_gravity(pb, newton);
    if (!r.newton.converged) throw SolverError(name + " solve did not converge: " + to_string(r.newton.reason));
    // A truth with folded elements is no truth (and no valid prone mesh): the element volume
    // term keeps each tetrahedron from inverting, the nodal one only their patches. The solve
    // counted them at its end state.
    if (r.newton.inverted > 0) throw inverted_error(name, r.newton.inverted, "tetrahedra");
    out = r.newton;
    return r.x;
  };
  // Quadratic elements: the forward solve with load continuation (a soft body's 10-node
  // elements may need it from the straight-sided start); each configuration its own solver, so
  // neither starts from the other's edge bulge.
  QuadraticTetMesh q;  // quadratic: the elements (the same for both solves)
  auto solve_quadratic = [&](const std::string& name, const Vec3& g, NewtonResult& out, Points& nodes) {
    ForwardGravityOptions fo;
    fo.element_order = ElementOrder::Quadratic;
    if (progress) fo.newton.callback = [&](const IterationInfo& it) { return progress(name, it); };
    ForwardGravity forward(model.rest.T, model.rest.V.rows(), model.chest_wall, materials, material_of, form,
                           opt.nodal_element_share, opt.density, fo);
    Points x = model.rest.V;
    const int iterations = forward.solve(model.rest.V, g, x);  // throws SolverError when it does not converge
    out = forward.last_newton();  // its inversions counted on every node (inversion_check.h)
    out.iterations = iterations;  // over the continuation's load fractions
    if (out.inverted > 0) throw inverted_error(name, out.inverted, "quadratic elements");
    nodes = forward.quadratic_nodes();
    q = forward.quadratic_mesh();
    return x;
  };
  PhantomConfigurations c;
  c.labels = labels;
  const bool quadratic = opt.element_order == ElementOrder::Quadratic;
  Points prone_nodes, supine_nodes;  // quadratic: every node of each configuration
  if (quadratic) {
    c.prone = solve_quadratic("prone", model.prone_gravity, c.prone_newton, prone_nodes);
    c.supine = solve_quadratic("supine", model.supine_gravity, c.supine_newton, supine_nodes);
    c.prone_corner_inversions = count_inverted(c.prone, model.rest.T);
    c.supine_corner_inversions = count_inverted(c.supine, model.rest.T);
  } else {
    c.prone = solve_linear("prone", model.prone_gravity, c.prone_newton);
    c.supine = solve_linear("supine", model.supine_gravity, c.supine_newton);
  }
  // Embedded points in the prone (false) or supine (true) truth.
  auto carry = [&](const Embedding& e, bool supine) {
    if (quadratic) return apply_quadratic_embedding(e, q, supine ? supine_nodes : prone_nodes);
    return apply_embedding(e, model.rest.T, supine ? c.supine : c.prone);
  };
  for (const auto& [name, t] : model.tumours) {
    const Embedding emb = embed_points(model.rest, t.V, OutsidePolicy::Error);
    c.tumour_prone[name] = SurfaceMesh{carry(emb, false), t.F};
    c.tumour_supine[name] = SurfaceMesh{carry(emb, true), t.F};
  }
  if (opt.gland_youngs_modulus > 0 && model.gland.F.rows() > 0)
    c.gland_prone = SurfaceMesh{carry(embed_points(model.rest, model.gland.V, OutsidePolicy::Error), false), model.gland.F};
  return c;
}

PhantomSceneSummary write_phantom_scene(const std::string& dir, const PhantomSceneOptions& opt,
                                        const std::function<bool(const std::string&, const IterationInfo&)>& progress) {
  namespace fs = std::filesystem;
  const auto landmark_names = phantom_landmark_set(opt.landmark_set);
  StableNeoHookean(opt.youngs_modulus, opt.poisson_ratio);  // validates before the expensive steps
  fs::create_directories(dir);
  const PhantomModel model = make_phantom_model(opt.phantom);
  PhantomSceneSummary sum;
  sum.vertices = model.rest.V.rows();
  sum.tetrahedra = model.rest.T.rows();
  sum.chest_wall_vertices = static_cast<long>(model.chest_wall.size());
  sum.quality = tet_quality(model.rest);
  const PhantomConfigurations conf = simulate_phantom(model, opt, progress);
  // Quadratic truth: its curved elements are sound, but the straight tetrahedra between their
  // corners may not be (a mesh no reader accepts). Then the prone model is written as its skin
  // surface, which the method tetrahedralizes at the generator's cell size (as a preset that
  // simulates on its own mesh would anyway), with the tissue regions as closed surfaces; a
  // supine mesh that inverts is not written (it is information only). The skin itself must hold.
  const bool prone_as_surface = conf.prone_corner_inversions > 0;
  sum.prone = conf.prone_newton;
  sum.supine = conf.supine_newton;
  sum.prone_written_as_surface = prone_as_surface;
  const Points& prone = conf.prone;
  const Points& supine = conf.supine;

  auto path = [&](const std::string& f) { return (fs::path(dir) / f).string(); };
  const LengthUnit unit = opt.units;
  write_rest_model(dir, model, unit);  // rest.vtk, chest_wall.txt, chest_ring.obj, tumours, model.yaml
  TetMesh m = model.rest;
  m.V = prone;
  std::vector<int> surface_index;  // the mesh's vertex -> prone_surface.obj's (-1 off the skin)
  const SurfaceMesh prone_surface = boundary_surface(m, nullptr, &surface_index);
  if (prone_as_surface) {
    validate_surface(prone_surface, "prone surface");  // a boundary of a tetrahedral mesh: closed and oriented
    const long crossings = self_intersecting_face_pairs(prone_surface);
    if (crossings > 0)
      throw SolverError("prone configuration: " + std::to_string(conf.prone_corner_inversions) +
                        " of the straight tetrahedra between the quadratic elements' corners are inverted, and the skin "
                        "between the corners crosses itself (" + std::to_string(crossings) +
                        " pairs of faces), so it cannot stand in for them: use a finer mesh or a stiffer material");
  } else {
    write_tet_mesh(path("prone.vtk"), m, unit, conf.labels);  // the tissue labels a segmentation would give
  }
  write_surface(path("prone_surface.obj"), prone_surface, unit);
  auto prone_index = [&](int v) {  // a vertex of the skin, numbered as the scene's prone model numbers it
    if (!prone_as_surface) return v;
    if (surface_index[static_cast<size_t>(v)] < 0) throw SolverError("phantom: vertex " + std::to_string(v) + " is not on the skin");
    return surface_index[static_cast<size_t>(v)];
  };
  if (prone_as_surface) {
    std::vector<int> wall;
    for (int v : model.chest_wall) wall.push_back(prone_index(v));
    write_index_list(path("chest_wall_prone_surface.txt"), wall);
  }
  m.V = supine;
  if (conf.supine_corner_inversions == 0) write_tet_mesh(path("supine.vtk"), m, unit);
  write_surface(path("supine_surface.obj"), boundary_surface(m), unit);

  std::vector<LandmarkPair> pairs;
  YAML::Node lm_vertices;
  for (const auto& [name, v] : model.landmarks) lm_vertices[name] = v;
  for (const auto& name : landmark_names) {
    LandmarkPair p;
    p.prone_vertex = prone_index(model.landmarks.at(name));
    p.supine_point = supine.row(model.landmarks.at(name)).transpose();
    pairs.push_back(p);
  }
  write_landmark_pairs(path("landmarks.csv"), pairs, unit);

  YAML::Node tumours;
  for (const auto& name : phantom_tumour_names()) {
    const SurfaceMesh& tp = conf.tumour_prone.at(name);
    const SurfaceMesh& ts = conf.tumour_supine.at(name);
    write_surface(path("tumour_" + name + "_prone.obj"), tp, unit);
    write_surface(path("tumour_" + name + "_supine.obj"), ts, unit);
    YAML::Node n;
    n["name"] = name;
    n["prone"] = "tumour_" + name + "_prone.obj";
    n["supine_ground_truth"] = "tumour_" + name + "_supine.obj";
    n["rest"] = "tumour_" + name + "_rest.obj";
    tumours.push_back(n);
    sum.tumour_displacement.emplace_back(name, (volume_centroid(ts) - volume_centroid(tp)).norm());
  }

  YAML::Node scene;
  scene["units"] = to_string(unit);
  scene["frame"] = "chest wall in z = 0, breast towards +z; prone gravity +z, supine gravity -z";
  if (prone_as_surface) {
    scene["prone"]["surface"] = "prone_surface.obj";
    scene["prone"]["cell_size_mm"] = opt.phantom.tet.cell_size * 1e3;
  } else {
    scene["prone"]["tet_mesh"] = "prone.vtk";
    scene["prone"]["surface"] = "prone_surface.obj";
  }
  scene["rest"]["tet_mesh"] = "rest.vtk";
  scene["rest"]["surface"] = "rest_surface.obj";
  scene["chest_wall"] = prone_as_surface ? "chest_wall_prone_surface.txt" : "chest_wall.txt";
  scene["chest_ring"] = "chest_ring.obj";
  scene["supine"]["surface"] = "supine_surface.obj";
  scene["supine"]["chest_ring"] = "chest_ring.obj";
  if (conf.supine_corner_inversions == 0) scene["supine"]["tet_mesh_ground_truth"] = "supine.vtk";
  scene["landmarks"] = "landmarks.csv";
  scene["landmark_set"] = opt.landmark_set;
  scene["landmark_vertices"] = lm_vertices;
  scene["tumours"] = tumours;
  // Heterogeneous truth: the method is told the tissue layout (the labels) and the stiffness
  // ratios, not the absolute moduli (its body material stays the thesis's, or is estimated).
  if (!conf.labels.empty()) {
    if (opt.gland_youngs_modulus > 0) {
      write_surface(path("gland_rest.obj"), model.gland, unit);
      write_surface(path("gland_prone.obj"), conf.gland_prone, unit);
    }
    // By cell label of prone.vtk; a prone model written as its surface has no cells, so there
    // each region is its closed prone surface (the labels were given by centroid inside them).
    YAML::Node regions;
    auto region = [&](const std::string& name, int label, const std::string& surface, double E) {
      if (E <= 0) return;
      YAML::Node r;
      r["name"] = name;
      if (prone_as_surface) r["surface"] = surface;
      else r["label"] = label;
      r["relative_stiffness"] = E / opt.youngs_modulus;
      regions.push_back(r);
    };
    region("gland", kPhantomGlandLabel, "gland_prone.obj", opt.gland_youngs_modulus);
    if (prone_as_surface)
      for (const auto& name : phantom_tumour_names())
        region("tumour_" + name, kPhantomTumourLabel, "tumour_" + name + "_prone.obj", opt.tumour_youngs_modulus);
    else
      region("tumour", kPhantomTumourLabel, "", opt.tumour_youngs_modulus);
    scene["regions"] = regions;
  }
  scene["material"]["youngs_modulus"] = 3400.0;
  scene["material"]["poisson_ratio"] = 0.49;
  scene["material"]["density"] = 1000.0;
  scene["gravity"] = std::vector<double>{0.0, 0.0, -9.81};
  scene["steps"] = "auto";
  scene["preset"] = "balanced";
  scene["generator"]["youngs_modulus"] = opt.youngs_modulus;
  scene["generator"]["poisson_ratio"] = opt.poisson_ratio;
  const VolumeForm generating_form = resolve_volume_form(opt.volume_form, opt.poisson_ratio);
  scene["generator"]["element_order"] = to_string(opt.element_order);
  if (opt.element_order == ElementOrder::Linear) scene["generator"]["volume_form"] = to_string(generating_form);
  if (opt.element_order == ElementOrder::Linear && generating_form == VolumeForm::Nodal) scene["generator"]["nodal_element_share"] = opt.nodal_element_share;
  scene["generator"]["density"] = opt.density;
  scene["generator"]["tumour_youngs_modulus"] = opt.tumour_youngs_modulus;
  scene["generator"]["gland_youngs_modulus"] = opt.gland_youngs_modulus;
  scene["generator"]["cell_size_mm"] = opt.phantom.tet.cell_size * 1e3;
  scene["generator"]["tetrahedra"] = sum.tetrahedra;
  YAML::Emitter y;
  y << scene;
  std::ofstream(path("scene.yaml")) << "# Synthetic breast phantom (thesis Sec. 5.2.1) written by btr_phantom\n"
                                    << "# The registration uses the thesis's fixed material (E = 3400 Pa), not the generator's.\n"
                                    << y.c_str() << "\n";
  return sum;
}

}  // namespace btr
