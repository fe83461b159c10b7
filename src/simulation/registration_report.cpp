#include "breast_tumour_registration/simulation/registration_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/confidence_ellipsoid.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/io/cross_section_image.h"
#include "breast_tumour_registration/io/markups_io.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "breast_tumour_registration/io/markups_io.h"

namespace btr {
namespace {

std::string quote(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') { o += "\\n"; continue; }
    o += c;
  }
  return o + "\"";
}

std::string num(double x) {
  if (!std::isfinite(x)) return "null";
  std::ostringstream s;
  s << std::setprecision(6) << x;
  return s.str();
}

std::string vec_mm(const Vec3& v) { return "[" + num(v.x() * 1e3) + ", " + num(v.y() * 1e3) + ", " + num(v.z() * 1e3) + "]"; }

}  // namespace

std::string registration_report_json(const Scene& scene, const RegistrationModel& model, const RegistrationResult& r,
                                     double prepare_seconds) {
  std::ostringstream j;
  j << "{\n  \"scene\": " << quote(scene.path) << ",\n  \"preset\": " << quote(scene.preset)
    << ",\n  \"steps\": " << quote(r.steps.describe()) << ",\n  \"converged\": " << (r.converged ? "true" : "false")
    << ",\n  \"implausible\": " << (r.implausible ? "true" : "false")
    << ",\n  \"mesh\": {\"vertices\": " << model.rest.V.rows() << ", \"tetrahedra\": " << model.rest.T.rows()
    << ", \"chest_wall_vertices\": " << model.chest_wall.size() << ", \"skin_vertices\": " << model.skin.size()
    << ", \"stiff_tumour_tetrahedra\": " << model.stiff_tetrahedra << "},\n";
  // The prepared model's materials; the stiffness step scales them all by one factor.
  const double scale = r.steps.stiffness && r.estimated_youngs_modulus > 0
                           ? r.estimated_youngs_modulus / model.material.youngs_modulus
                           : 1.0;
  j << "  \"materials\": [";
  for (size_t i = 0; i < model.materials.size(); ++i) {
    const double mu = scale * model.materials[i].mu(), lambda_lame = scale * model.materials[i].lambda() - mu;
    j << (i ? ", " : "") << "{\"name\": " << quote(i < model.material_names.size() ? model.material_names[i] : "")
      << ", \"youngs_modulus_Pa\": " << num(mu * (3 * lambda_lame + 2 * mu) / (lambda_lame + mu))
      << ", \"tetrahedra\": " << (i < model.material_tetrahedra.size() ? model.material_tetrahedra[i] : 0) << "}";
  }
  j << "],\n";
  if (r.steps.stiffness) {
    j << "  \"stiffness\": {\"estimated_youngs_modulus_Pa\": " << num(r.estimated_youngs_modulus) << ", \"evaluations\": [";
    for (size_t i = 0; i < r.stiffness_evaluations.size(); ++i)
      j << (i ? ", " : "") << "{\"youngs_modulus_Pa\": " << num(r.stiffness_evaluations[i].first)
        << ", \"landmark_misfit_mm\": "
        << num(r.stiffness_evaluations[i].second * 1e3) << "}";
    j << "]},\n";
  }
  j << "  \"seconds\": {\"tetrahedralization\": " << num(scene.tetrahedralize_seconds)
    << ", \"prepare\": " << num(prepare_seconds) << ", \"rigid\": " << num(r.rigid_seconds);
  for (const auto& s : r.reports) j << ", " << quote(s.name) << ": " << num(s.seconds);
  j << ", \"registration_total\": " << num(r.seconds) << "},\n";
  const Mat3 R = r.supine_to_model.linear();
  j << "  \"rigid_transform_supine_to_model\": {\"rotation\": [";
  for (int i = 0; i < 3; ++i)
    j << (i ? ", " : "") << "[" << num(R(i, 0)) << ", " << num(R(i, 1)) << ", " << num(R(i, 2)) << "]";
  j << "], \"translation_mm\": " << vec_mm(r.supine_to_model.translation())
    << ", \"rotation_deg\": " << num(rotation_angle(r.supine_to_model) * 180 / M_PI) << ", \"icp_used\": "
    << (r.icp_used ? "true" : "false") << ", \"pose_solved_with_landmarks\": " << (r.pose_solved_with_landmarks ? "true" : "false")
    << ", \"pose_solved_with_surface\": " << (r.pose_solved_with_surface ? "true" : "false")
    << ", \"icp_vs_landmark_pose_mm\": " << num(r.pose_disagreement * 1e3)
    << ", \"rigid_regions\": {\"distinct_poses\": " << r.rigid_distinct_poses
    << ", \"decided_by_landmarks\": " << (r.rigid_decided_by_landmarks ? "true" : "false")
    << ", \"undecided\": " << (r.rigid_pose_undecided ? "true" : "false") << ", \"note\": " << quote(r.rigid_note) << "}" << ", \"icp\": {\"accepted\": " << (r.icp.accepted ? "true" : "false")
    << ", \"converged\": " << (r.icp.converged ? "true" : "false") << ", \"inlier_rms_mm\": " << num(r.icp.inlier_rms * 1e3)
    << ", \"overlap\": " << num(r.icp.overlap) << ", \"iterations\": " << r.icp.iterations
    << ", \"message\": " << quote(r.icp.message) << "}},\n";
  j << "  \"step_reports\": [";
  for (size_t i = 0; i < r.reports.size(); ++i) {
    const auto& s = r.reports[i];
    j << (i ? ", " : "") << "\n    {\"step\": " << quote(s.name) << ", \"converged\": " << (s.converged ? "true" : "false")
      << ", \"stop\": " << quote(s.stop_reason) << ", \"newton_iterations\": " << s.iterations
      << ", \"projections\": " << s.outer_iterations << ", \"seconds\": " << num(s.seconds)
      << ", \"energy_J\": " << num(s.energy) << ", \"gradient_norm_N\": " << num(s.gradient_norm)
      << ", \"projection_rms_change_mm\": " << num(s.projection_rms_change() * 1e3)
      << ", \"fixed_point_distance_mm\": " << num(s.fixed_point_distance * 1e3) << ", \"contraction\": " << num(s.contraction)
      << ", \"accelerated_projections\": " << s.accelerated_projections << ", \"projection_rms_changes_mm\": [";
    for (size_t k = 0; k < s.projection_residuals.size(); ++k) j << (k ? ", " : "") << num(s.projection_residuals[k] * 1e3);
    j << "]"
      << ", \"constrained_skin_vertices\": " << s.constrained_skin << ", \"skin_vertices\": " << s.skin_vertices
      << ", \"inverted_tetrahedra\": " << s.inverted << ", \"inversions_allowed\": " << (s.inversions_allowed ? "true" : "false")
      << ",\n     \"profile_seconds\": {\"setup\": "
      << num(s.t_setup) << ", \"assembly\": " << num(s.t_assembly) << ", \"factorization\": " << num(s.t_factorization)
      << ", \"solve\": " << num(s.t_solve) << ", \"line_search\": " << num(s.t_line_search)
      << ", \"projection\": " << num(s.t_projection) << "}, \"factorizations\": " << s.factorizations
      << ", \"pcg_iterations\": " << s.pcg_iterations;
    if (s.name == "unload")
      j << ", \"unload\": {\"resimulated_prone_mismatch_mm\": " << num(s.unload_mismatch * 1e3)
        << ", \"rest_shape_change_mm\": " << num(s.unload_rest_change * 1e3)
        << ", \"forward_solves\": " << s.outer_iterations
        << ", \"forward_solve_equivalents\": " << num(s.unload_forward_solve_equivalents)
        << ", \"load_steps\": " << s.unload_load_steps << ", \"note\": " << quote(s.note) << "}";
    j << "}";
  }
  j << "\n  ],\n  \"tumours\": [";
  for (size_t i = 0; i < r.tumours.size(); ++i) {
    const auto& t = r.tumours[i];
    j << (i ? ", " : "") << "\n    {\"name\": " << quote(t.name) << ", \"centroid_supine_mm\": " << vec_mm(t.centroid)
      << ", \"volume_ratio_to_prone\": " << num(t.volume_ratio) << ", \"axis_ratio\": " << num(t.axis_ratio)
      << ", \"prone_axis_ratio\": " << num(t.prone_axis_ratio);
    if (t.has_ground_truth)
      j << ", \"centroid_distance_mm\": " << num(t.centroid_distance * 1e3) << ", \"hausdorff_mm\": " << num(t.hausdorff * 1e3)
        << ", \"volume_ratio_to_truth\": " << num(t.volume_ratio_to_truth)
        << ", \"truth_axis_ratio\": " << num(t.truth_axis_ratio)
        << ", \"rigid_only_centroid_distance_mm\": " << num(t.rigid_centroid_distance * 1e3);
    if (t.uncertainty) {
      const TumourUncertainty& u = *t.uncertainty;
      j << ",\n     \"uncertainty\": {\"method\": \"linear\", \"radius_95_mm\": " << num(u.radius_95 * 1e3)
        << ", \"covariance_mm2\": [";
      for (int a = 0; a < 3; ++a)
        j << (a ? ", " : "") << "[" << num(u.covariance(a, 0) * 1e6) << ", " << num(u.covariance(a, 1) * 1e6) << ", "
          << num(u.covariance(a, 2) * 1e6) << "]";
      j << "], \"rms_mm_by_source\": {";
      for (size_t k = 0; k < u.sources.size(); ++k)
        j << (k ? ", " : "") << quote(u.sources[k].first) << ": " << num(std::sqrt(std::max(0.0, u.sources[k].second.trace())) * 1e3);
      j << "}, \"d_centroid_d_ln_youngs_modulus_mm\": " << vec_mm(u.d_log_youngs_modulus) << "}";
    }
    if (r.sampled_uncertainty && i < r.sampled_uncertainty->tumours.size()) {
      const auto& u = r.sampled_uncertainty->tumours[i];
      j << ",\n     \"uncertainty_sampled\": {\"radius_95_mm\": " << num(u.radius_95 * 1e3) << ", \"covariance_mm2\": [";
      for (int a = 0; a < 3; ++a)
        j << (a ? ", " : "") << "[" << num(u.covariance(a, 0) * 1e6) << ", " << num(u.covariance(a, 1) * 1e6) << ", "
          << num(u.covariance(a, 2) * 1e6) << "]";
      j << "], \"mean_shift_mm\": " << vec_mm(u.mean_shift) << "}";
    }
    j << "}";
  }
  j << "\n  ],\n";
  if (!r.uncertainty_note.empty() || (!r.tumours.empty() && r.tumours[0].uncertainty))
    j << "  \"uncertainty\": {\"method\": \"linear\", \"validated\": false, \"seconds\": " << num(r.uncertainty_seconds)
      << ", \"note\": " << quote(r.uncertainty_note) << "},\n";
  if (r.sampled_uncertainty)
    j << "  \"uncertainty_sampled\": {\"samples\": " << r.sampled_uncertainty->samples
      << ", \"not_converged\": " << r.sampled_uncertainty->not_converged << ", \"failed\": " << r.sampled_uncertainty->failed
      << ", \"seconds_per_sample\": " << num(r.sampled_uncertainty->seconds_per_sample)
      << ", \"note\": " << quote(r.sampled_uncertainty->note) << "},\n";
  j << "  \"landmark_residual_mm\": {\"mean\": " << num(r.landmark_residual_mean * 1e3)
    << ", \"max\": " << num(r.landmark_residual_max * 1e3) << "},\n  \"skin_to_supine_surface_mm\": {\"mean\": "
    << num(r.skin_distance_mean * 1e3) << ", \"max\": " << num(r.skin_distance_max * 1e3) << "},\n  \"warnings\": [";
  for (size_t i = 0; i < r.warnings.size(); ++i) j << (i ? ", " : "") << quote(r.warnings[i]);
  j << "],\n  \"figure\": \"cross_section.png: x-z slice through the first tumour's registered centroid; grey prone, "
       "thin blue supine, thick red registered; tumours: grey prone, thin green ground truth, thick red registered; bar 10 mm\"\n}\n";
  return j.str();
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
  for (const auto& t : r.tumours) {
    write_surface(path("tumour_" + t.name + "_registered.obj"), t.registered, scene.units);
    write_surface(path("tumour_" + t.name + "_registered.ply"), t.registered, scene.units);
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
  std::vector<Outline> outlines = {{&prone_skin, {130, 130, 130}, 2}, {&skin, {235, 60, 60}, 4}};
  if (scene.supine_surface) outlines.push_back({&*scene.supine_surface, {70, 140, 255}, 1});
  std::vector<SurfaceMesh> prone_tumours;
  for (const auto& t : model.tumours) prone_tumours.push_back(transform_surface(to_supine, t.prone));
  for (size_t i = 0; i < r.tumours.size(); ++i) {
    outlines.push_back({&prone_tumours[i], {130, 130, 130}, 1});
    outlines.push_back({&r.tumours[i].registered, {235, 60, 60}, 4});
    if (scene.tumours[i].supine_ground_truth) outlines.push_back({&*scene.tumours[i].supine_ground_truth, {60, 220, 90}, 1});
  }
  // The 95 % region of each centroid (when the uncertainty ran): the ellipsoid of its covariance.
  std::vector<SurfaceMesh> regions;
  regions.reserve(r.tumours.size());
  for (const auto& t : r.tumours)
    if (t.uncertainty) regions.push_back(uncertainty_ellipsoid(t.centroid, t.uncertainty->covariance));
  for (const auto& e : regions) outlines.push_back({&e, {250, 210, 40}, 2});
  const double y0 = r.tumours.empty() ? skin.V.col(1).mean() : r.tumours[0].centroid.y();
  write_cross_section_png(path("cross_section.png"), outlines, y0);
  return files;
}

}  // namespace btr
