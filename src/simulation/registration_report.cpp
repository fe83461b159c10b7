#include "breast_tumour_registration/simulation/registration_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/volume_form.h"
#include "breast_tumour_registration/geometry/confidence_ellipsoid.h"
#include "breast_tumour_registration/geometry/margin_shell.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/io/cross_section_image.h"
#include "breast_tumour_registration/io/markups_io.h"
#include "breast_tumour_registration/io/mesh_io.h"

namespace btr {
namespace {

using Json = nlohmann::ordered_json;  // keys in the order written, for a reader's eye

// Non-finite numbers become null (JSON has no NaN).
Json num(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }
Json vec_mm(const Vec3& v) { return Json::array({num(v.x() * 1e3), num(v.y() * 1e3), num(v.z() * 1e3)}); }
Json mat(const Mat3& M, double scale) {
  Json rows = Json::array();
  for (int i = 0; i < 3; ++i) rows.push_back({num(M(i, 0) * scale), num(M(i, 1) * scale), num(M(i, 2) * scale)});
  return rows;
}

Json step_report(const StepReport& s) {
  Json changes = Json::array();
  for (double c : s.projection_residuals) changes.push_back(num(c * 1e3));
  Json j = {{"step", s.name},
            {"converged", s.converged},
            {"stop", s.stop_reason},
            {"newton_iterations", s.iterations},
            {"projections", s.outer_iterations},
            {"seconds", num(s.seconds)},
            {"energy_J", num(s.energy)},
            {"gradient_norm_N", num(s.gradient_norm)},
            {"projection_rms_change_mm", num(s.projection_rms_change() * 1e3)},
            {"fixed_point_distance_mm", num(s.fixed_point_distance * 1e3)},
            {"contraction", num(s.contraction)},
            {"accelerated_projections", s.accelerated_projections},
            {"sliding_held_from_projection", s.sliding_held_from},
            {"projection_rms_changes_mm", changes},
            {"constrained_skin_vertices", s.constrained_skin},
            {"skin_vertices", s.skin_vertices},
            {"inverted_tetrahedra", s.inverted},
            {"inversions_allowed", s.inversions_allowed},
            {"profile_seconds",
             {{"setup", num(s.t_setup)},
              {"assembly", num(s.t_assembly)},
              {"factorization", num(s.t_factorization)},
              {"solve", num(s.t_solve)},
              {"line_search", num(s.t_line_search)},
              {"projection", num(s.t_projection)}}},
            {"factorizations", s.factorizations},
            {"pcg_iterations", s.pcg_iterations}};
  if (s.free_limit_checked_at > 0)
    j["free_limit_check"] = {{"projection", s.free_limit_checked_at},
                             {"distance_mm", num(s.free_limit_distance * 1e3)},
                             {"beyond_tolerance", s.free_limit_missed}};
  if (s.name == "unload")
    j["unload"] = {{"resimulated_prone_mismatch_mm", num(s.unload.mismatch * 1e3)},
                   {"rest_shape_change_mm", num(s.unload.rest_change * 1e3)},
                   {"forward_solves", s.outer_iterations},
                   {"forward_solve_equivalents", num(s.unload.forward_solve_equivalents)},
                   {"load_steps", s.unload.load_steps},
                   {"elements", to_string(s.unload.elements)},  // whose forward model the rest shape inverts
                   {"note", s.note}};
  return j;
}

Json tumour_report(const TumourResult& t, const SampledUncertainty* sampled, size_t i) {
  Json j = {{"name", t.name},
            {"centroid_supine_mm", vec_mm(t.centroid)},
            {"volume_ratio_to_prone", num(t.volume_ratio)},
            {"axis_ratio", num(t.axis_ratio)},
            {"prone_axis_ratio", num(t.prone_axis_ratio)}};
  if (t.has_ground_truth) {
    j["centroid_distance_mm"] = num(t.centroid_distance * 1e3);
    j["hausdorff_mm"] = num(t.hausdorff * 1e3);
    j["volume_ratio_to_truth"] = num(t.volume_ratio_to_truth);
    j["truth_axis_ratio"] = num(t.truth_axis_ratio);
    j["rigid_only_centroid_distance_mm"] = num(t.rigid_centroid_distance * 1e3);
  }
  if (t.uncertainty) {
    const TumourUncertainty& u = *t.uncertainty;
    Json by_source = Json::object();
    for (const auto& [name, cov] : u.sources) by_source[name] = num(std::sqrt(std::max(0.0, cov.trace())) * 1e3);
    j["uncertainty"] = {{"method", "linear"},
                        {"radius_95_mm", num(u.radius_95 * 1e3)},
                        {"covariance_mm2", mat(u.covariance, 1e6)},
                        {"rms_mm_by_source", by_source},
                        {"d_centroid_d_ln_youngs_modulus_mm", vec_mm(u.d_log_youngs_modulus)},
                        // q = (1 - 2 nu) / (2 nu), the variable Poisson's ratio is linearised in
                        {"d_centroid_d_volume_compliance_mm", vec_mm(u.d_volume_compliance)}};
  }
  if (sampled && i < sampled->tumours.size()) {
    const auto& u = sampled->tumours[i];
    j["uncertainty_sampled"] = {
        {"radius_95_mm", num(u.radius_95 * 1e3)},
        {"radius_95_sources_mm", num(u.radius_95_sources * 1e3)},  // without the discretisation
        {"covariance_mm2", mat(u.covariance, 1e6)},
        {"mean_shift_mm", vec_mm(u.mean_shift)},
        {"discretisation_mm", vec_mm(u.discretisation)}};
    if (!u.vertex_radius_95.empty()) {
      std::vector<double> m = u.vertex_radius_95;
      std::sort(m.begin(), m.end());
      j["uncertainty_sampled"]["margin_95_mm"] = {{"median", num(m[m.size() / 2] * 1e3)}, {"max", num(m.back() * 1e3)}};
    }
  }
  return j;
}

}  // namespace

std::string registration_report_json(const Scene& scene, const RegistrationModel& model, const RegistrationResult& r,
                                     double prepare_seconds) {
  Json j = {{"scene", scene.path},
            {"preset", scene.preset},
            {"steps", r.steps.describe()},
            {"converged", r.converged},
            {"implausible", r.implausible},
            {"mesh",
             {{"vertices", model.rest.V.rows()},
              {"tetrahedra", model.rest.T.rows()},
              {"chest_wall_vertices", model.chest_wall.size()},
              {"skin_vertices", model.skin.size()},
              {"stiff_tumour_tetrahedra", model.stiff_tetrahedra}}}};
  // The prepared model's materials; the stiffness step scales them all by one factor.
  const double scale = r.steps.stiffness && r.estimated_youngs_modulus > 0
                           ? r.estimated_youngs_modulus / model.material.youngs_modulus
                           : 1.0;
  Json materials = Json::array();
  for (size_t i = 0; i < model.materials.size(); ++i) {
    materials.push_back({{"name", i < model.material_names.size() ? model.material_names[i] : ""},
                         {"youngs_modulus_Pa", num(scale * model.materials[i].youngs_modulus())},
                         {"tetrahedra", i < model.material_tetrahedra.size() ? model.material_tetrahedra[i] : 0}});
  }
  j["materials"] = materials;
  // Which material model ran: the volume term's form (resolved from the scene's `auto`) and
  // Poisson's ratio, which set how far the same E lets the tissue sag.
  // Where the nodal form did not converge and the engine fell back, the element form's.
  j["material_model"] = {{"volume_form", to_string(r.volume_form)}, {"poisson_ratio", num(model.material.poisson_ratio)}};
  if (model.material.unload_element_order != ElementOrder::Linear)
    j["material_model"]["unload_element_order"] = to_string(model.material.unload_element_order);
  if (r.volume_form == VolumeForm::Nodal)
    j["material_model"]["nodal_element_share"] = num(model.material.nodal_element_share);
  if (const auto& f = r.volume_form_fallback) {
    j["material_model"]["fallback_from_nodal"] = {{"nodal_stop", f->nodal_stop},
                                                  {"nodal_seconds", num(f->nodal_seconds)},
                                                  {"element_prepare_seconds", num(f->prepare_seconds)}};
    if (!f->mesh_note.empty()) j["material_model"]["fallback_from_nodal"]["element_mesh"] = f->mesh_note;
  }
  if (r.steps.stiffness) {
    Json evaluations = Json::array();
    for (const auto& c : r.stiffness_evaluations) {
      Json e = {{"youngs_modulus_Pa", num(c.youngs_modulus)}, {"landmark_misfit_mm", num(c.misfit * 1e3)},
                {"forward_solves", c.forward_solves}, {"seconds", num(c.seconds)}};
      if (!c.failure.empty()) e["not_simulated"] = c.failure;
      evaluations.push_back(e);
    }
    j["stiffness"] = {{"estimated_youngs_modulus_Pa", num(r.estimated_youngs_modulus)},
                      {"log_sd", num(r.estimated_youngs_modulus_log_sd)},  // sd of ln E the landmarks leave (0: not known)
                      {"evaluations", evaluations}};
  }
  Json seconds = {{"tetrahedralization", num(scene.tetrahedralize_seconds)}, {"prepare", num(prepare_seconds)}, {"rigid", num(r.rigid_seconds)}};
  for (const auto& s : r.reports) seconds[s.name] = num(s.seconds);
  seconds["registration_total"] = num(r.seconds);
  j["seconds"] = seconds;
  j["rigid_transform_supine_to_model"] = {
      {"rotation", mat(r.supine_to_model.linear(), 1.0)},
      {"translation_mm", vec_mm(r.supine_to_model.translation())},
      {"rotation_deg", num(rotation_angle(r.supine_to_model) * 180 / M_PI)},
      {"icp_used", r.icp_used},
      {"pose_solved_with_landmarks", r.pose_solved_with_landmarks},
      {"pose_solved_with_surface", r.pose_solved_with_surface},
      {"landmarks_moved_onto_scan", r.landmarks_moved_onto_scan},
      {"icp_vs_landmark_pose_mm", num(r.pose_disagreement * 1e3)},
      {"rigid_regions",
       {{"distinct_poses", r.rigid_distinct_poses},
        {"decided_by_landmarks", r.rigid_decided_by_landmarks},
        {"undecided", r.rigid_pose_undecided},
        {"note", r.rigid_note}}},
      {"icp",
       {{"accepted", r.icp.accepted},
        {"converged", r.icp.converged},
        {"inlier_rms_mm", num(r.icp.inlier_rms * 1e3)},
        {"overlap", num(r.icp.overlap)},
        {"iterations", r.icp.iterations},
        {"message", r.icp.message}}}};
  if (r.icp.pose_covariance) {  // how well the fit determines the pose: sd about the model frame's axes
    const Mat6& c = *r.icp.pose_covariance;
    j["rigid_transform_supine_to_model"]["icp"]["pose_sd_deg"] = {num(std::sqrt(c(0, 0)) * 180 / M_PI), num(std::sqrt(c(1, 1)) * 180 / M_PI),
                                                                  num(std::sqrt(c(2, 2)) * 180 / M_PI)};
    j["rigid_transform_supine_to_model"]["icp"]["pose_sd_mm"] = {num(std::sqrt(c(3, 3)) * 1e3), num(std::sqrt(c(4, 4)) * 1e3),
                                                                 num(std::sqrt(c(5, 5)) * 1e3)};
  } else if (!r.icp.pose_covariance_note.empty()) {
    j["rigid_transform_supine_to_model"]["icp"]["pose_covariance_note"] = r.icp.pose_covariance_note;
  }
  Json steps = Json::array();
  for (const auto& s : r.reports) steps.push_back(step_report(s));
  j["step_reports"] = steps;
  Json tumours = Json::array();
  for (size_t i = 0; i < r.tumours.size(); ++i) tumours.push_back(tumour_report(r.tumours[i], r.sampled_uncertainty ? &*r.sampled_uncertainty : nullptr, i));
  j["tumours"] = tumours;
  // What the linear region leaves out, stated where it is read. With the pose solved with the
  // deformation the landmarks share it and hold the skin, and they are a source (on ring-free
  // independent truth their noise was most of the error: BENCHMARKS.md, issue 14); where ICP or
  // the caller set the pose, they reach the result only as the surface step's start.
  const bool landmarks_linearised = !r.tumours.empty() && r.tumours[0].uncertainty &&
                                    r.tumours[0].uncertainty->d_landmarks.cols() > 0;
  if (!r.uncertainty_note.empty() || (!r.tumours.empty() && r.tumours[0].uncertainty))
    j["uncertainty"] = {{"method", "linear"},
                        {"validated", false},
                        {"seconds", num(r.uncertainty_seconds)},
                        {"note", r.uncertainty_note},
                        {"not_propagated",
                         {landmarks_linearised
                              ? "the landmark step's influence on where the surface step began (its start, not an input "
                                "of the equilibrium): drawn by --uncertainty sampling"
                              : "the supine landmarks' localisation (landmark_sd_mm), except through an estimated "
                                "Young's modulus: its effect through the surface step's start is drawn by "
                                "--uncertainty sampling",
                          "the element form's discretisation error: estimated by --uncertainty sampling "
                          "(uncertainty.discretisation)",
                          "model error beyond the listed sources"}}};
  if (r.sampled_uncertainty)
    j["uncertainty_sampled"] = {{"samples", r.sampled_uncertainty->samples},
                                {"not_converged", r.sampled_uncertainty->not_converged},
                                {"failed", r.sampled_uncertainty->failed},
                                {"seconds_per_sample", num(r.sampled_uncertainty->seconds_per_sample)},
                                {"discretisation_estimated", r.sampled_uncertainty->discretisation_estimated},
                                {"discretisation_seconds", num(r.sampled_uncertainty->discretisation_seconds)},
                                {"note", r.sampled_uncertainty->note}};
  if (j.contains("uncertainty") || j.contains("uncertainty_sampled")) {  // the distributions propagated
    const UncertaintySources& u = scene.uncertainty;
    j["uncertainty_sources"] = {{"youngs_modulus_range_Pa", {num(u.youngs_modulus_range[0]), num(u.youngs_modulus_range[1])}},
                                {"poisson_ratio_range", {num(u.poisson_ratio_range[0]), num(u.poisson_ratio_range[1])}},
                                {"gravity_direction_deg", num(u.gravity_direction_deg)},
                                {"landmark_sd_mm", num(u.landmark_sd * 1e3)},
                                {"depth_noise_mm", num(u.depth_noise * 1e3)},
                                {"rigid_pose", u.rigid_pose},
                                {"discretisation", u.discretisation}};
  }
  j["landmark_residual_mm"] = {{"mean", num(r.landmark_residual_mean * 1e3)}, {"max", num(r.landmark_residual_max * 1e3)}};
  j["skin_to_supine_surface_mm"] = {{"mean", num(r.skin_distance_mean * 1e3)}, {"max", num(r.skin_distance_max * 1e3)}};
  if (r.supine_noise > 0)  // the surface step's scan: its noise along its normals, and whether it was denoised
    j["supine_surface"] = {{"estimated_noise_mm", num(r.supine_noise * 1e3)}, {"denoised", r.supine_denoised}};
  j["warnings"] = r.warnings;
  j["figure"] =
      "cross_section.png: the x-z cut through the first tumour's registered centroid in the supine frame, axes in mm; "
      "grey prone (rigidly moved), blue supine surface, thick red registered, green tumour truth, orange the 95 % region "
      "of each centroid when the uncertainty ran";
  // Invalid UTF-8 in a path or message is replaced, not thrown: the report is always written.
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

void prepare_output_folder(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw InputError("--out '" + dir + "': cannot create the output folder (" + ec.message() + ")");
  const fs::path probe = fs::path(dir) / ".btr_write_test";
  {
    std::ofstream out(probe);
    if (!out || !(out << "x")) throw InputError("--out '" + dir + "': the output folder is not writable");
  }
  fs::remove(probe, ec);
}

SurfaceMesh uncertainty_ellipsoid(const Vec3& centre, const Mat3& covariance) {
  const Ellipsoid95 e = ellipsoid_95(covariance);
  SurfaceMesh s = make_icosphere(Vec3::Zero(), 1.0, 2);
  for (Eigen::Index i = 0; i < s.V.rows(); ++i)
    s.V.row(i) = (centre + e.axes * e.semi_axes.cwiseProduct(s.V.row(i).transpose())).transpose();
  return s;
}

std::vector<std::string> write_registration_outputs(const std::string& dir, const Scene& scene,
                                                    const RegistrationModel& model, const RegistrationResult& r,
                                                    double prepare_seconds) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  std::vector<std::string> files;
  auto path = [&](const std::string& f) {
    files.push_back((fs::path(dir) / f).string());
    return files.back();
  };
  const Rigid to_supine = r.supine_to_model.inverse();
  TetMesh deformed{transform_points(to_supine, r.x), model.rest.T};
  write_tet_mesh(path("registered.vtk"), deformed, scene.units);
  const SurfaceMesh skin = boundary_surface(deformed);
  write_surface(path("registered_surface.obj"), skin, scene.units);
  write_surface(path("registered_surface.ply"), skin, scene.units);
  for (size_t i = 0; i < r.tumours.size(); ++i) {
    const TumourResult& t = r.tumours[i];
    write_surface(path("tumour_" + t.name + "_registered.obj"), t.registered, scene.units);
    write_surface(path("tumour_" + t.name + "_registered.ply"), t.registered, scene.units);
    // The margin shell: the surface grown by each vertex's sampled 95 % displacement bound.
    if (r.sampled_uncertainty && i < r.sampled_uncertainty->tumours.size() &&
        r.sampled_uncertainty->tumours[i].vertex_radius_95.size() == static_cast<size_t>(t.registered.V.rows()))
      write_surface(path("tumour_" + t.name + "_margin95.obj"),
                    margin_shell(t.registered, r.sampled_uncertainty->tumours[i].vertex_radius_95), scene.units);
  }
  std::ofstream(path("report.json")) << registration_report_json(scene, model, r, prepare_seconds);
  // For 3D Slicer, when the scene says its patient frame: LPS millimetres (Slicer's file
  // convention), the tissue labels on the mesh, the tumour centroids as a point list.
  if (scene.patient_frame) {
    fs::create_directories(fs::path(dir) / "slicer");
    auto lps = [&](const Points& P) {
      Points Q = P;
      for (Eigen::Index i = 0; i < Q.rows(); ++i)
        Q.row(i) = convert_patient_frame(P.row(i).transpose(), *scene.patient_frame, PatientFrame::LPS).transpose();
      return Q;
    };
    const bool labelled = static_cast<Eigen::Index>(scene.prone_labels.size()) == deformed.T.rows();
    write_tet_mesh(path("slicer/registered.vtk"), TetMesh{lps(deformed.V), deformed.T}, LengthUnit::Millimetre,
                   labelled ? scene.prone_labels : std::vector<int>{}, "breast_tumour_registration registered breast SPACE=LPS");
    std::vector<NamedPoint> centroids;
    std::vector<std::string> notes;
    for (const auto& t : r.tumours) {
      write_surface(path("slicer/tumour_" + t.name + ".ply"), SurfaceMesh{lps(t.registered.V), t.registered.F}, LengthUnit::Millimetre);
      centroids.push_back({t.name, t.centroid});
      char buf[160] = "";
      if (t.uncertainty)
        std::snprintf(buf, sizeof buf, "95 %% radius %.2f mm (experimental, not validated)", t.uncertainty->radius_95 * 1e3);
      notes.push_back(buf);
    }
    if (!centroids.empty()) {
      write_markups(path("slicer/tumour_centroids.mrk.json"), centroids, *scene.patient_frame, PatientFrame::LPS, notes);
    }
  }

  // Cross-section through the first tumour (or the model centre).
  const SurfaceMesh prone_skin = transform_surface(to_supine, boundary_surface(TetMesh{model.prone, model.rest.T}));
  // Registered outlines thick underneath, supine and ground truth thin on top, so that
  // both stay visible where they coincide.
  std::vector<Outline> outlines = {{&prone_skin, {150, 150, 150}, 2, "prone (rigidly moved)"},
                                   {&skin, {220, 40, 40}, 3.5, "registered"}};
  if (scene.supine_surface) outlines.push_back({&*scene.supine_surface, {40, 110, 230}, 1.5, "supine surface"});
  std::vector<SurfaceMesh> prone_tumours;
  for (const auto& t : model.tumours) prone_tumours.push_back(transform_surface(to_supine, t.prone));
  for (size_t i = 0; i < r.tumours.size(); ++i) {
    outlines.push_back({&prone_tumours[i], {150, 150, 150}, 1, "prone (rigidly moved)"});
    outlines.push_back({&r.tumours[i].registered, {220, 40, 40}, 3.5, "registered"});
    if (scene.tumours[i].supine_ground_truth)
      outlines.push_back({&*scene.tumours[i].supine_ground_truth, {20, 160, 60}, 1.5, "tumour truth"});
  }
  // The 95 % region of each centroid (when the uncertainty ran): the ellipsoid of its covariance.
  std::vector<SurfaceMesh> regions;
  regions.reserve(r.tumours.size());
  for (const auto& t : r.tumours)
    if (t.uncertainty) regions.push_back(uncertainty_ellipsoid(t.centroid, t.uncertainty->covariance));
  for (const auto& e : regions) outlines.push_back({&e, {235, 150, 0}, 2, "95 % region of the centroid"});
  const double y0 = r.tumours.empty() ? skin.V.col(1).mean() : r.tumours[0].centroid.y();
  char title[160];
  std::snprintf(title, sizeof title, "Cut at y = %.1f mm (supine frame)%s", y0 * 1e3,
                r.tumours.empty() ? "" : ", through the first tumour's centroid");
  write_cross_section_png(path("cross_section.png"), outlines, y0, title);
  return files;
}

}  // namespace btr
