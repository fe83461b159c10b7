// Where the tumour may be (issue 14): the linearised centroid uncertainty against full re-solves.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <random>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/newton_solver.h"
#include "breast_tumour_registration/fem/rigid_free_surface_energy.h"
#include "breast_tumour_registration/fem/spring_energy.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/geometry/margin_shell.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/registration/quadratic_unload_equation.h"
#include "breast_tumour_registration/registration/stiffness_step.h"
#include "breast_tumour_registration/registration/unload_step.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/geometry/vertex_normals.h"
#include "breast_tumour_registration/simulation/registration_report.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "test_util.h"

using namespace btr;
using btr::test::expect_throw_with;

namespace {

/// The minimum of `energy` on m's mesh (chest wall fixed), solved to round-off from `start`.
Points minimum_to_round_off(const RegistrationModel& m, const TotalEnergy& energy, const Points& start) {
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(m.rest.V.rows()), m.rest.T, m.fixed,
                                                         energy.hessian_cliques()),
                      m.rest.T);
  NewtonOptions n;
  n.gradient_rel_tolerance = 1e-13;
  n.gradient_abs_tolerance = 1e-13;
  n.step_tolerance = 1e-15;
  n.reuse_factorization = false;
  Points x = start;
  const NewtonResult nr = solver.solve(energy, x, n);
  // Tolerances far below round-off: a stall at 1e-8 N of a 3 N weight is the minimum too.
  EXPECT_TRUE(nr.converged || nr.gradient_norm < 1e-6) << to_string(nr.reason) << ", gradient " << nr.gradient_norm << " N after " << nr.iterations;
  return x;
}

/// The minimum of the surface step's last Newton problem with these held skin targets (moved
/// rigidly by `move`), the model's material and rest shape, and `gravity`: solved to round-off
/// from `start`.
Points held_energy_minimum(const RegistrationModel& m, const std::vector<HeldSkinVertex>& held, const Rigid& move,
                           const Vec3& gravity, const SurfaceStepOptions& surface, const Points& start) {
  TotalEnergy energy;
  add_model_elastic_energy(energy, m);
  energy.add(std::make_shared<GravityEnergy>(m.rest, m.material.density, gravity));
  auto springs = std::make_shared<SpringEnergy>();
  for (const HeldSkinVertex& k : held)
    springs->add_point_and_plane(Anchor::vertex(k.vertex), move * k.point, move.linear() * k.normal, surface.point_weight,
                                 surface.plane_weight);
  energy.add(springs);
  return minimum_to_round_off(m, energy, start);
}

/// The tumours' volume centroids at x, model frame.
std::vector<Vec3> tumour_centroids(const RegistrationModel& m, const Points& x) {
  std::vector<Vec3> c;
  for (const auto& t : m.tumours) c.push_back(volume_centroid({apply_embedding(t.embedding, m.rest.T, x), t.prone.F}));
  return c;
}

/// The skin vertices the supine surface (in the model frame) holds at x, as the linearisation takes them.
std::vector<HeldSkinVertex> held_skin(const RegistrationModel& model, const Points& x, const SurfaceProjector& supine,
                                      const SurfaceStepOptions& surface) {
  std::vector<HeldSkinVertex> held;
  for (int v : model.skin) {
    const Projection c = supine.project(Vec3(x.row(v).transpose()));
    if (!holds_projection(c, surface)) continue;
    held.push_back({v, c.point, c.normal.normalized()});
  }
  return held;
}

/// The linear sensitivities to ln E and to the first gravity tilt against re-solved ones (within 3 %).
void expect_e_and_tilt_match(const std::string& name, const TumourUncertainty& u, const Vec3& fd_e, const Vec3& fd_g) {
  std::printf("%-7s dc/dlnE linear (%.5f %.5f %.5f) re-solved (%.5f %.5f %.5f) mm; dc/dtilt linear (%.4f %.4f %.4f) re-solved (%.4f %.4f %.4f) mm/rad\n",
              name.c_str(), 1e3 * u.d_log_youngs_modulus.x(), 1e3 * u.d_log_youngs_modulus.y(), 1e3 * u.d_log_youngs_modulus.z(),
              1e3 * fd_e.x(), 1e3 * fd_e.y(), 1e3 * fd_e.z(), 1e3 * u.d_gravity_tilt[0].x(), 1e3 * u.d_gravity_tilt[0].y(),
              1e3 * u.d_gravity_tilt[0].z(), 1e3 * fd_g.x(), 1e3 * fd_g.y(), 1e3 * fd_g.z());
  EXPECT_LT((u.d_log_youngs_modulus - fd_e).norm(), 0.03 * fd_e.norm()) << name;
  EXPECT_LT((u.d_gravity_tilt[0] - fd_g).norm(), 0.03 * fd_g.norm()) << name;
}

/// Writes `nominal` with `sampled` into a new folder (returned through `dir`), as btr_register
/// does, and parses its report.json.
nlohmann::json sampled_report(RegistrationEngine& engine, const RegistrationOptions& o, RegistrationResult nominal,
                              const SampledUncertainty& sampled, std::string& dir) {
  nominal.sampled_uncertainty = sampled;
  const PreparedScene& prep = engine.prepare(o);
  dir = btr::test::temp_dir();
  write_registration_outputs(dir, prep.scene, prep.model, nominal, 0);
  std::ifstream report(dir + "/report.json");
  return nlohmann::json::parse(report);
}

}  // namespace

TEST(Uncertainty, VolumeCentroidJacobianMatchesFiniteDifferences) {
  SurfaceMesh s = make_icosphere(Vec3::Zero(), 0.01, 2);
  for (Eigen::Index v = 0; v < s.V.rows(); ++v) s.V.row(v) = s.V.row(v).cwiseProduct(Eigen::RowVector3d(1.0, 0.7, 1.3)) +
                                                              Eigen::RowVector3d(0.03, -0.02, 0.05) + 0.001 * std::sin(7.0 * v) * Eigen::RowVector3d(1, 1, 1);
  const Eigen::MatrixXd J = volume_centroid_jacobian(s);
  const double h = 1e-7;
  double worst = 0, largest = 0;
  for (Eigen::Index v = 0; v < s.V.rows(); v += 7)
    for (int k = 0; k < 3; ++k) {
      SurfaceMesh p = s, m = s;
      p.V(v, k) += h;
      m.V(v, k) -= h;
      const Vec3 fd = (volume_centroid(p) - volume_centroid(m)) / (2 * h);
      worst = std::max(worst, (fd - J.col(3 * v + k)).norm());
      largest = std::max(largest, fd.norm());
    }
  EXPECT_LT(worst, 1e-6 * largest + 1e-9) << "largest " << largest;
}

TEST(Uncertainty, The95PercentRadiusOfKnownDistributions) {
  const double sd = 0.002;
  EXPECT_NEAR(radius_95(sd * sd * Mat3::Identity()), 2.7955 * sd, 2e-4 * sd);  // sqrt(chi2_3(0.95) = 7.8147)
  Mat3 line = Mat3::Zero();
  line(1, 1) = sd * sd;
  EXPECT_NEAR(radius_95(line), 1.95996 * sd, 2e-4 * sd);
  Mat3 plane = Mat3::Zero();
  plane(0, 0) = plane(2, 2) = sd * sd;
  EXPECT_NEAR(radius_95(plane), 2.44775 * sd, 2e-4 * sd);  // sqrt(chi2_2(0.95) = 5.9915)
  EXPECT_EQ(radius_95(Mat3::Zero()), 0.0);
}

// The linearised result's structure on a converged registration (its agreement with re-solves
// is not yet established: tumour_uncertainty.h).
TEST(Uncertainty, TheCovarianceIsTheSumOfItsSourcesAndTheRadiusCoversItsLargestAxis) {
  const Scene& s = btr::test::coarse_phantom_scene();
  RegistrationOptions o = preset_options("balanced");
  o.uncertainty.enabled = true;
  const RegistrationResult r = RegistrationEngine(s).solve(o);
  ASSERT_TRUE(r.converged);
  EXPECT_TRUE(r.uncertainty_note.empty()) << r.uncertainty_note;
  EXPECT_GT(r.uncertainty_seconds, 0.0);
  for (const auto& t : r.tumours) {
    ASSERT_TRUE(t.uncertainty) << t.name;
    const TumourUncertainty& u = *t.uncertainty;
    Mat3 sum = Mat3::Zero();
    for (const auto& [name, c] : u.sources) {
      sum += c;
      EXPECT_GE(Eigen::SelfAdjointEigenSolver<Mat3>(c).eigenvalues()(0), -1e-18) << name;
    }
    EXPECT_LT((sum - u.covariance).norm(), 1e-15);
    const double largest = Eigen::SelfAdjointEigenSolver<Mat3>(u.covariance).eigenvalues()(2);
    EXPECT_GT(largest, 0.0) << t.name;
    EXPECT_GE(u.radius_95, 1.959 * std::sqrt(largest));
    EXPECT_LE(u.radius_95, 1.961 * std::sqrt(u.covariance.trace()));
    EXPECT_GT(u.d_log_youngs_modulus.norm(), 0.0);
  }
  // With no source, no spread.
  o.uncertainty.sources = UncertaintySources::none();
  for (const auto& t : RegistrationEngine(s).solve(o).tumours) EXPECT_EQ(t.uncertainty->radius_95, 0.0);
}

// The machinery (adjoint solves, centroid Jacobian, the inputs' dG/dp, frames) against re-solves
// of the very energy it differentiates: the surface step's last Newton problem with its
// projections held, re-solved to round-off at perturbed E and gravity.
TEST(Uncertainty, HeldProjectionSensitivitiesMatchReSolvesOfThatEnergy) {
  const Scene& s = btr::test::coarse_phantom_scene();
  RegistrationOptions o = preset_options("balanced");
  o.uncertainty.enabled = true;
  o.uncertainty.held_projections = true;
  RegistrationEngine engine(s);
  const RegistrationResult r = engine.solve(o);
  ASSERT_TRUE(r.converged);
  ASSERT_FALSE(r.pose_solved_with_surface);  // the chest ring decides the pose
  const RegistrationModel& model = engine.prepare(o).model;
  const Rigid& T = r.supine_to_model;
  const auto supine = make_mesh_projector(transform_surface(T, *s.supine_surface));
  // The held targets at the result, as the linearisation takes them.
  const std::vector<HeldSkinVertex> held = held_skin(model, r.x, *supine, o.surface);
  // move: a rigid motion of the supine data in the model frame (the pose supine -> model becomes
  // move * T); the centroids come back through that pose.
  auto resolve = [&](double log_e, const Vec3& gravity, const Rigid& move = Rigid::Identity()) {
    RegistrationModel m = model;
    scale_stiffness(m, std::exp(log_e));
    const Points x = held_energy_minimum(m, held, move, gravity, o.surface, r.x);
    std::vector<Vec3> c = tumour_centroids(m, x);
    for (Vec3& ci : c) ci = (move * T).inverse() * ci;
    return std::make_pair(x, c);
  };
  // The balanced result is near, not at, this energy's minimum (its held projections are those
  // of the last iterate, not of the minimum): linearise at the minimum, with the same held
  // targets, so that both sides describe one equilibrium.
  const Points x0 = resolve(0, model.gravity).first;
  std::printf("balanced result to the minimum of its held energy: %.3f mm at most\n", 1e3 * (x0 - r.x).rowwise().norm().maxCoeff());
  const UncertaintyResult lin = linearised_tumour_uncertainty(model, x0, held, T.inverse(), o.surface, o.uncertainty);
  const double h = 1e-3;
  const Vec3 axis = model.gravity.normalized().unitOrthogonal();
  const auto e_up = resolve(h, model.gravity).second, e_down = resolve(-h, model.gravity).second;
  const auto g_up = resolve(0, Eigen::AngleAxisd(h, axis) * model.gravity).second;
  const auto g_down = resolve(0, Eigen::AngleAxisd(-h, axis) * model.gravity).second;
  ASSERT_EQ(lin.tumours.size(), r.tumours.size());
  for (size_t i = 0; i < r.tumours.size(); ++i) {
    const TumourUncertainty& u = lin.tumours[i];
    const Vec3 fd_e = (e_up[i] - e_down[i]) / (2 * h), fd_g = (g_up[i] - g_down[i]) / (2 * h);
    expect_e_and_tilt_match(r.tumours[i].name, u, fd_e, fd_g);
  }
  // The rigid pose: the supine data turned about each model axis and shifted along it, by +-h
  // (rad, or h * 1 cm).
  for (int k = 0; k < 6; ++k) {
    const double step = k < 3 ? h : 0.01 * h;
    auto motion = [&](double sign) {
      Rigid m = Rigid::Identity();
      if (k < 3) m.linear() = Eigen::AngleAxisd(sign * step, Vec3::Unit(k)).toRotationMatrix();
      else m.translation() = sign * step * Vec3::Unit(k - 3);
      return m;
    };
    const auto up = resolve(0, model.gravity, motion(1)).second, down = resolve(0, model.gravity, motion(-1)).second;
    for (size_t i = 0; i < r.tumours.size(); ++i) {
      const Vec3 fd = (up[i] - down[i]) / (2 * step), lin_k = lin.tumours[i].d_pose.col(k);
      std::printf("%-7s dc/dpose[%d] linear (%.4f %.4f %.4f) re-solved (%.4f %.4f %.4f) mm/%s\n", r.tumours[i].name.c_str(), k,
                  1e3 * lin_k.x(), 1e3 * lin_k.y(), 1e3 * lin_k.z(), 1e3 * fd.x(), 1e3 * fd.y(), 1e3 * fd.z(), k < 3 ? "rad" : "m");
      EXPECT_LT((lin_k - fd).norm(), 0.03 * fd.norm() + 1e-6) << r.tumours[i].name << " pose " << k;
    }
  }
}

// Without a rigid region the pose is solved with the deformation and the landmarks share it
// (RigidFreeSurfaceEnergy): the linearisation keeps the pose free and the landmarks are a
// source. On the ring-free phantom, the minimum of that energy with its correspondences held
// is re-solved with a landmark target moved, E scaled and gravity tilted; the centroids, mapped
// out through the pose the energy finds, must move as the linearisation says, and differently
// from a linearisation that holds the pose (else this test could not see the pose's part).
TEST(Uncertainty, AFreePoseAndItsLandmarksAreLinearisedAsTheirEnergyReSolves) {
  Scene s = btr::test::coarse_phantom_scene();
  s.prone_rigid.reset();
  s.supine_rigid.reset();
  RegistrationOptions o = preset_options("balanced");
  o.uncertainty.enabled = true;
  o.uncertainty.held_projections = true;
  RegistrationEngine engine(s);
  const RegistrationResult r = engine.solve(o);
  ASSERT_TRUE(r.pose_solved_with_surface && !r.icp_used);
  const RegistrationModel& model = engine.prepare(o).model;
  const Scene& ps = engine.prepare(o).scene;
  // The projector's frame is the model frame here (pose at the result: the identity).
  const Rigid& T = r.supine_to_model;
  const auto supine = make_mesh_projector(transform_surface(T, *ps.supine_surface));
  const std::vector<HeldSkinVertex> held = held_skin(model, r.x, *supine, o.surface);
  const Points targets = transform_points(T, ps.landmark_supine);
  ASSERT_GE(targets.rows(), 3);
  auto energy_with = [&](const RegistrationModel& m, const Points& lm, const Vec3& gravity) {
    auto e = std::make_shared<TotalEnergy>();
    add_model_elastic_energy(*e, m);
    e->add(std::make_shared<GravityEnergy>(m.rest, m.material.density, gravity));
    auto fs = std::make_shared<RigidFreeSurfaceEnergy>(o.surface.point_weight, o.surface.plane_weight);
    Points y(static_cast<Eigen::Index>(held.size()), 3), n(static_cast<Eigen::Index>(held.size()), 3);
    std::vector<int> verts;
    for (size_t k = 0; k < held.size(); ++k) {
      y.row(static_cast<Eigen::Index>(k)) = held[k].point.transpose();
      n.row(static_cast<Eigen::Index>(k)) = held[k].normal.transpose();
      verts.push_back(held[k].vertex);
    }
    fs->set(verts, y, n);
    fs->set_points(ps.landmark_anchors, lm, o.surface.pose_points_weight);
    e->add(fs);
    return std::make_pair(e, fs);
  };
  // The centroids in the supine frame: out through the pose the energy finds at its minimum.
  auto resolve = [&](double log_e, const Vec3& gravity, const Points& lm, const Points& start) {
    RegistrationModel m = model;
    scale_stiffness(m, std::exp(log_e));
    auto [e, fs] = energy_with(m, lm, gravity);
    const Points x = minimum_to_round_off(m, *e, start);
    const Rigid to_supine = T.inverse() * fs->pose(x);
    std::vector<Vec3> c = tumour_centroids(m, x);
    for (Vec3& ci : c) ci = to_supine * ci;
    return std::make_pair(x, c);
  };
  const Points x0 = resolve(0, model.gravity, targets, r.x).first;
  // Linearised at that minimum, with its pose (the projector's frame is the model frame).
  auto [e0, fs0] = energy_with(model, targets, model.gravity);
  const Rigid P0 = fs0->pose(x0);
  // As the pipeline gives them: held targets in the model frame (the pose maps them onto the
  // correspondences), landmark targets in the projector's.
  std::vector<HeldSkinVertex> held_m = held;
  for (HeldSkinVertex& k : held_m) {
    k.point = P0.inverse() * k.point;
    k.normal = P0.linear().transpose() * k.normal;
  }
  const FreePoseLinearisation free{P0, ps.landmark_anchors, targets, o.surface.pose_points_weight, Points(0, 3)};
  const UncertaintyResult lin =
      linearised_tumour_uncertainty(model, x0, held_m, T.inverse() * P0, o.surface, o.uncertainty, std::nullopt, nullptr, &free);
  const UncertaintyResult held_pose = linearised_tumour_uncertainty(model, x0, held, T.inverse(), o.surface, o.uncertainty);
  ASSERT_EQ(lin.tumours.size(), r.tumours.size());
  const double h = 1e-3;
  const Vec3 axis = model.gravity.normalized().unitOrthogonal();
  const auto e_up = resolve(h, model.gravity, targets, x0).second, e_down = resolve(-h, model.gravity, targets, x0).second;
  const auto g_up = resolve(0, Eigen::AngleAxisd(h, axis) * model.gravity, targets, x0).second;
  const auto g_down = resolve(0, Eigen::AngleAxisd(-h, axis) * model.gravity, targets, x0).second;
  double pose_part = 0;
  for (size_t i = 0; i < r.tumours.size(); ++i) {
    const TumourUncertainty& u = lin.tumours[i];
    ASSERT_EQ(u.d_landmarks.cols(), 3 * targets.rows());
    const Vec3 fd_e = (e_up[i] - e_down[i]) / (2 * h), fd_g = (g_up[i] - g_down[i]) / (2 * h);
    expect_e_and_tilt_match(r.tumours[i].name, u, fd_e, fd_g);
    pose_part = std::max(pose_part, (u.d_gravity_tilt[0] - held_pose.tumours[i].d_gravity_tilt[0]).norm() / fd_g.norm());
  }
  // Each coordinate of the first and the last landmark's target, moved by +-0.1 mm.
  const double step = 1e-4;
  double err2 = 0, fd2 = 0;
  for (Eigen::Index l : {Eigen::Index(0), targets.rows() - 1})
    for (int d = 0; d < 3; ++d) {
      Points up = targets, down = targets;
      up(l, d) += step;
      down(l, d) -= step;
      const auto c_up = resolve(0, model.gravity, up, x0).second, c_down = resolve(0, model.gravity, down, x0).second;
      for (size_t i = 0; i < r.tumours.size(); ++i) {
        const Vec3 fd = (c_up[i] - c_down[i]) / (2 * step), lin_k = lin.tumours[i].d_landmarks.col(3 * l + d);
        std::printf("%-7s dc/dlandmark[%ld].%d linear (%.4f %.4f %.4f) re-solved (%.4f %.4f %.4f)\n", r.tumours[i].name.c_str(),
                    static_cast<long>(l), d, lin_k.x(), lin_k.y(), lin_k.z(), fd.x(), fd.y(), fd.z());
        // The pose-free springs' Hessian is the Gauss-Newton one (exact where the residuals
        // vanish); the landmarks' are millimetres on this coarse mesh, and the linear response
        // differs from the re-solved one by up to 5 % of it or 1e-3 (1.5 um for a 1.5 mm landmark
        // error), mostly as a common shift of the tumours: the pose's turn.
        EXPECT_LT((lin_k - fd).norm(), 0.06 * fd.norm() + 1e-3) << r.tumours[i].name << " landmark " << l << "." << d;
        err2 += (lin_k - fd).squaredNorm();
        fd2 += fd.squaredNorm();
      }
    }
  std::printf("landmark sensitivities: RMS difference %.1f %% of the re-solved\n", 100 * std::sqrt(err2 / fd2));
  EXPECT_LT(err2, 0.06 * 0.06 * fd2);
  // The free pose is a visible part of the response, and the landmarks a named source.
  EXPECT_GT(pose_part, 0.1);
  for (const auto& [name, cov] : lin.tumours[0].sources) {
    if (name == "landmarks") {
      EXPECT_GT(cov.trace(), 0);
    }
  }
  EXPECT_EQ(lin.tumours[0].sources.back().first, "landmarks");
  // Landmarks moved onto the scan first (SurfaceStepOptions::landmarks_on_scan), as the surface
  // step takes them. Only their motion along the surface moves the tumours, and the
  // linearisation with the normals must follow re-solves whose landmarks are moved and then
  // projected. Each is given 1 mm off the scan, above a point inside a face next to its target
  // (a sixth of the way to the face's middle), so that it projects inside that face: the
  // linearisation takes the surface's tangent plane, and onto an edge or a corner of the
  // polyhedral scan a projection moves less. (Near the targets, as the pose-free springs'
  // Hessian is the Gauss-Newton one: 8 mm away it differed from re-solves by 21 %.)
  const SurfaceMesh scan = transform_surface(T, *ps.supine_surface);
  Points given = targets;
  for (Eigen::Index l = 0; l < given.rows(); ++l) {
    const Vec3 t = targets.row(l).transpose();
    double best = std::numeric_limits<double>::infinity();
    for (Eigen::Index f = 0; f < scan.F.rows(); ++f) {
      const Vec3 a = scan.V.row(scan.F(f, 0)), b = scan.V.row(scan.F(f, 1)), c = scan.V.row(scan.F(f, 2));
      const Vec3 mid = (a + b + c) / 3;
      if ((mid - t).norm() >= best) continue;
      const Vec3 inside = t + (mid - t) / 6, n = (b - a).cross(c - a).normalized();
      for (const double side : {1.0, -1.0})  // the side from which it projects inside the face
        if ((supine->project(inside + side * 1e-3 * n).point - inside).norm() < 1e-9) {
          best = (mid - t).norm();
          given.row(l) = (inside + side * 1e-3 * n).transpose();
        }
    }
    ASSERT_LT(best, 0.02) << "landmark " << l;
  }
  const LandmarksOnScan on = landmarks_on_scan(*supine, given, o.surface);
  ASSERT_EQ(on.moved, given.rows());
  const Points x_on = resolve(0, model.gravity, on.targets, x0).first;
  const Rigid P_on = energy_with(model, on.targets, model.gravity).second->pose(x_on);
  std::vector<HeldSkinVertex> held_on = held;
  for (HeldSkinVertex& k : held_on) {
    k.point = P_on.inverse() * k.point;
    k.normal = P_on.linear().transpose() * k.normal;
  }
  const FreePoseLinearisation free_on{P_on, ps.landmark_anchors, on.targets, o.surface.pose_points_weight, on.normals};
  const UncertaintyResult lin_on = linearised_tumour_uncertainty(model, x_on, held_on, T.inverse() * P_on, o.surface,
                                                                 o.uncertainty, std::nullopt, nullptr, &free_on);
  // The control: the targets themselves moved, linearised without the normals. Its difference
  // is the Gauss-Newton Hessian's at this state (the landmark residuals are a millimetre or two).
  FreePoseLinearisation as_given = free_on;
  as_given.landmark_normals.resize(0, 3);
  const UncertaintyResult lin_given = linearised_tumour_uncertainty(model, x_on, held_on, T.inverse() * P_on, o.surface,
                                                                    o.uncertainty, std::nullopt, nullptr, &as_given);
  double err_on = 0, fd_on = 0, err_given = 0, fd_given = 0, along_normal = 0;
  for (int d = 0; d < 3; ++d) {
    Points up = given, down = given, t_up = on.targets, t_down = on.targets;
    up(0, d) += step;
    down(0, d) -= step;
    t_up(0, d) += step;
    t_down(0, d) -= step;
    const auto c_up = resolve(0, model.gravity, landmarks_on_scan(*supine, up, o.surface).targets, x_on).second;
    const auto c_down = resolve(0, model.gravity, landmarks_on_scan(*supine, down, o.surface).targets, x_on).second;
    const auto g_up = resolve(0, model.gravity, t_up, x_on).second, g_down = resolve(0, model.gravity, t_down, x_on).second;
    for (size_t i = 0; i < r.tumours.size(); ++i) {
      const Vec3 fd = (c_up[i] - c_down[i]) / (2 * step), fd_g = (g_up[i] - g_down[i]) / (2 * step);
      err_on += (lin_on.tumours[i].d_landmarks.col(d) - fd).squaredNorm();
      fd_on += fd.squaredNorm();
      err_given += (lin_given.tumours[i].d_landmarks.col(d) - fd_g).squaredNorm();
      fd_given += fd_g.squaredNorm();
    }
  }
  const Vec3 n0 = on.normals.row(0).transpose();
  for (size_t i = 0; i < r.tumours.size(); ++i) along_normal = std::max(along_normal, (lin_on.tumours[i].d_landmarks.leftCols<3>() * n0).norm());
  const double rel_on = std::sqrt(err_on / fd_on), rel_given = std::sqrt(err_given / fd_given);
  std::printf("landmarks on the scan: RMS difference %.1f %% of the re-solved (the targets as given: %.1f %%); largest "
              "response along the normal %.2e\n", 100 * rel_on, 100 * rel_given, along_normal);
  EXPECT_LT(rel_on, rel_given + 0.02);  // the tangent plane adds little to the Gauss-Newton Hessian's difference
  EXPECT_LT(rel_on, 0.1);
  EXPECT_GT(fd_on, 0.1 * fd_given);  // the tangential response is there, of the order of the full one
  EXPECT_LT(fd_on, 0.9 * fd_given);  // and the normal part is gone
  EXPECT_LT(along_normal, 1e-9);
  // Along the normal such a target carries the scan's depth noise: the depth-noise share grows by
  // each target's response along its normal (checked above as the targets' own response).
  for (size_t i = 0; i < r.tumours.size(); ++i) {
    double expected = 0;
    for (Eigen::Index l = 0; l < on.targets.rows(); ++l)
      expected += (lin_given.tumours[i].d_landmarks.middleCols<3>(3 * l) * Vec3(on.normals.row(l).transpose())).squaredNorm();
    expected *= o.uncertainty.sources.depth_noise * o.uncertainty.sources.depth_noise;
    const auto depth_share = [](const TumourUncertainty& u) {
      for (const auto& [name, cov] : u.sources)
        if (name == "depth_noise") return cov.trace();
      return -1.0;
    };
    EXPECT_GT(expected, 0);
    EXPECT_NEAR(depth_share(lin_on.tumours[i]) - depth_share(lin_given.tumours[i]), expected, 1e-9 * expected + 1e-18) << r.tumours[i].name;
  }
  // The pipeline linearises so where it solved the pose with the deformation, and says so.
  o.uncertainty.held_projections = false;
  const RegistrationResult p = engine.solve(o);
  ASSERT_TRUE(p.pose_solved_with_surface);
  for (const auto& t : p.tumours) {
    ASSERT_TRUE(t.uncertainty) << t.name;
    EXPECT_EQ(t.uncertainty->d_landmarks.cols(), 3 * targets.rows()) << t.name;
  }
  EXPECT_NE(p.uncertainty_note.find("linearised free, the skin free to slide; the landmarks that share it are a source"),
            std::string::npos) << p.uncertainty_note;
  // Its landmarks lie on the scan (the phantom's skin vertices): each was moved onto it.
  EXPECT_EQ(p.landmarks_moved_onto_scan, targets.rows());
  const std::string d = btr::test::temp_dir();
  write_registration_outputs(d, engine.prepare(o).scene, engine.prepare(o).model, p, 0);
  std::ifstream report(d + "/report.json");
  const nlohmann::json j = nlohmann::json::parse(report);
  EXPECT_EQ(j.at("rigid_transform_supine_to_model").at("landmarks_moved_onto_scan").get<int>(), targets.rows());
}

// Poisson's ratio, and an unloaded rest shape moving with the material. On a model unloaded
// under the prone gravity, E and nu are perturbed, the prone image unloaded again (to 1e-9 m)
// and the held energy re-solved: the linearised sensitivities (the rest shape's response from
// the unload's own equation, by GMRES) must match, and must differ from the response with the
// rest shape held (else this test could not see the rest shape's part).
namespace {
void expect_the_linearisation_follows_the_unloaded_rest_shape(ElementOrder unload_elements) {
  Scene s = btr::test::coarse_phantom_scene();
  s.prone_gravity = Vec3(0, 0, 9.81);  // the phantom's prone gravity (its scene's `frame`)
  s.material.unload_element_order = unload_elements;
  s.unload_element_order_stated = true;  // else the balanced preset chooses them
  RegistrationOptions o = preset_options("balanced");
  o.uncertainty.enabled = true;
  o.uncertainty.held_projections = true;
  RegistrationEngine engine(s);
  const RegistrationResult r = engine.solve(o);
  ASSERT_TRUE(r.converged) << btr::test::step_stops(r);
  const RegistrationModel& model = engine.prepare(o).model;
  ASSERT_GT(model.unloaded_under.norm(), 0.0) << "the model was not unloaded";
  const Rigid& T = r.supine_to_model;
  const auto supine = make_mesh_projector(transform_surface(T, *s.supine_surface));
  const std::vector<HeldSkinVertex> held = held_skin(model, r.x, *supine, o.surface);
  const Points x0 = held_energy_minimum(model, held, Rigid::Identity(), model.gravity, o.surface, r.x);
  const UncertaintyResult lin = linearised_tumour_uncertainty(model, x0, held, T.inverse(), o.surface, o.uncertainty);
  EXPECT_TRUE(lin.rest_shape_follows);
  EXPECT_TRUE(lin.note.empty()) << lin.note;
  std::printf("rest shape's response: %d GMRES products, %.2f s of %.2f s\n", lin.rest_response_iterations,
              lin.rest_response_seconds, lin.seconds);
  const double q0 = volume_compliance(model.material.poisson_ratio);
  auto resolve = [&](double log_e, double dq, bool unload) {
    RegistrationModel m = model;
    scale_stiffness(m, std::exp(log_e));
    set_poisson_ratio(m, 1.0 / (2.0 * (1.0 + q0 + dq)));
    if (unload) {
      const TetMesh loaded{m.prone, m.rest.T};
      UnloadProblem pb = unload_problem(m, loaded, model.unloaded_under);
      pb.initial_rest = &model.rest.V;
      UnloadOptions uo;
      uo.forward.element_order = unload_elements;
      uo.tolerance = 1e-9;
      uo.max_iterations = 80;
      uo.forward.newton.gradient_rel_tolerance = 1e-12;
      uo.forward.newton.gradient_abs_tolerance = 1e-12;
      uo.forward.newton.step_tolerance = 1e-14;
      const UnloadResult u = estimate_unloaded_shape(pb, uo);
      EXPECT_TRUE(u.converged) << u.stop_reason;
      set_rest_shape(m, u.rest, unload_report(u, m.prone), model.unloaded_under);
    }
    std::vector<Vec3> c = tumour_centroids(m, held_energy_minimum(m, held, Rigid::Identity(), model.gravity, o.surface, x0));
    for (Vec3& ci : c) ci = T.inverse() * ci;
    return c;
  };
  const double h_e = 0.02, h_q = 0.05 * q0;
  const auto e_up = resolve(h_e, 0, true), e_down = resolve(-h_e, 0, true);
  const auto q_up = resolve(0, h_q, true), q_down = resolve(0, -h_q, true);
  const auto e_up_held = resolve(h_e, 0, false), e_down_held = resolve(-h_e, 0, false);
  const auto q_up_held = resolve(0, h_q, false), q_down_held = resolve(0, -h_q, false);
  ASSERT_EQ(lin.tumours.size(), r.tumours.size());
  for (size_t i = 0; i < r.tumours.size(); ++i) {
    const TumourUncertainty& u = lin.tumours[i];
    const Vec3 fd_e = (e_up[i] - e_down[i]) / (2 * h_e), fd_q = (q_up[i] - q_down[i]) / (2 * h_q);
    const Vec3 held_e = (e_up_held[i] - e_down_held[i]) / (2 * h_e), held_q = (q_up_held[i] - q_down_held[i]) / (2 * h_q);
    std::printf("%-7s dc/dlnE linear (%.4f %.4f %.4f) re-solved (%.4f %.4f %.4f) rest held (%.4f %.4f %.4f) mm\n",
                r.tumours[i].name.c_str(), 1e3 * u.d_log_youngs_modulus.x(), 1e3 * u.d_log_youngs_modulus.y(),
                1e3 * u.d_log_youngs_modulus.z(), 1e3 * fd_e.x(), 1e3 * fd_e.y(), 1e3 * fd_e.z(), 1e3 * held_e.x(),
                1e3 * held_e.y(), 1e3 * held_e.z());
    std::printf("%-7s dc/dq    linear (%.4f %.4f %.4f) re-solved (%.4f %.4f %.4f) rest held (%.4f %.4f %.4f) mm\n",
                r.tumours[i].name.c_str(), 1e3 * u.d_volume_compliance.x(), 1e3 * u.d_volume_compliance.y(),
                1e3 * u.d_volume_compliance.z(), 1e3 * fd_q.x(), 1e3 * fd_q.y(), 1e3 * fd_q.z(), 1e3 * held_q.x(),
                1e3 * held_q.y(), 1e3 * held_q.z());
    EXPECT_LT((u.d_log_youngs_modulus - fd_e).norm(), 0.03 * fd_e.norm()) << r.tumours[i].name;
    EXPECT_LT((u.d_volume_compliance - fd_q).norm(), 0.05 * fd_q.norm()) << r.tumours[i].name;
    EXPECT_GT((fd_e - held_e).norm(), 0.2 * fd_e.norm()) << r.tumours[i].name << ": the rest shape's part is not seen";
  }
}
}  // namespace

TEST(Uncertainty, AnUnloadedRestShapeMovesWithTheMaterialAndTheLinearisationFollowsIt) {
  expect_the_linearisation_follows_the_unloaded_rest_shape(ElementOrder::Linear);
}

// With quadratic elements the unload solves another equation (rest corners and edge nodes:
// quadratic_unload_equation.h); the linear unload's response was 30 to 40 % off the re-solves here.
TEST(Uncertainty, AQuadraticallyUnloadedRestShapeMovesWithTheMaterialAndTheLinearisationFollowsIt) {
  expect_the_linearisation_follows_the_unloaded_rest_shape(ElementOrder::Quadratic);
}

// The quadratic unload's equation is linearised at the equilibrium its last forward solve found
// (RegistrationModel::unloaded_nodes); where a model does not keep it (e.g. a rest shape set
// without it) one forward solve finds it again. Both give the same response.
TEST(Uncertainty, TheQuadraticUnloadsEquationIsTheSameFromAKeptOrARefoundEquilibrium) {
  Scene s = btr::test::coarse_phantom_scene();
  s.prone_gravity = Vec3(0, 0, 9.81);
  s.material.unload_element_order = ElementOrder::Quadratic;
  std::vector<std::string> w;
  const RegistrationModel kept = prepare_model(s, w);
  ASSERT_TRUE(kept.unload && kept.unload->unload.elements == ElementOrder::Quadratic) << "not unloaded quadratically";
  ASSERT_GT(kept.unloaded_nodes.rows(), kept.rest.V.rows());  // corners and edge nodes
  RegistrationModel refound = kept;
  refound.unloaded_nodes = Points();
  const RestShapeResponse a = QuadraticUnloadEquation(kept).rest_response(true);
  const RestShapeResponse b = QuadraticUnloadEquation(refound).rest_response(true);
  ASSERT_TRUE(a.converged && b.converged);
  std::printf("GMRES products: %d at the kept equilibrium, %d at the one found again\n", a.iterations, b.iterations);
  for (int input = 0; input < 2; ++input) {
    const double size = a.dX[input].cwiseAbs().maxCoeff();
    EXPECT_GT(size, 0.0);
    EXPECT_LT((a.dX[input] - b.dX[input]).cwiseAbs().maxCoeff(), 1e-3 * size) << "input " << input;
  }
}

// Where E is estimated from the landmarks, a true Poisson's ratio other than the method's moves
// the estimate: the landmarks' gravity-only prediction moves with nu, and the search re-fits E.
// The linearisation's d ln E / d q against stiffness searches re-run (tightly) at nu on either
// side, on the coarse phantom unloaded at its estimate.
TEST(Uncertainty, TheEstimatedStiffnessFollowsPoissonsRatioAsTheLandmarksAreRefitted) {
  const Scene& s = btr::test::coarse_phantom_scene();
  std::vector<std::string> w;
  const RegistrationModel model = prepare_model(s, w);
  const Vec3 g(0, 0, 9.81);  // the phantom's prone gravity
  StiffnessOptions so;
  so.min_youngs_modulus = 500;
  so.max_youngs_modulus = 20000;
  so.relative_tolerance = 1e-5;
  so.max_refinements = 60;
  so.candidate_tolerance = 1e-8;
  so.unload.tolerance = 1e-8;
  auto estimate = [&](const RegistrationModel& m) { return estimate_stiffness(m, g, s.landmark_anchors, s.landmark_supine, so); };
  const StiffnessEstimate est = estimate(model);
  ASSERT_FALSE(est.at_bound) << est.stop_reason;
  RegistrationModel at_estimate = model;
  scale_stiffness(at_estimate, est.scale);
  set_rest_shape(at_estimate, est.rest, unload_report(est.unload, model.prone), g);
  const double linear = log_youngs_modulus_per_compliance(at_estimate, {s.landmark_anchors, est.supine_prediction});
  const double q0 = volume_compliance(model.material.poisson_ratio), h = 0.2 * q0;
  auto log_e_at = [&](double q) {
    RegistrationModel m = model;
    set_poisson_ratio(m, 1.0 / (2.0 * (1.0 + q)));
    const StiffnessEstimate e = estimate(m);
    EXPECT_FALSE(e.at_bound) << e.stop_reason;
    return std::log(e.youngs_modulus);
  };
  const double fd = (log_e_at(q0 + h) - log_e_at(q0 - h)) / (2 * h);
  std::printf("E estimated at %.0f Pa (nu %.3f); d ln E / d q linear %.3f, re-estimated %.3f\n", est.youngs_modulus,
              model.material.poisson_ratio, linear, fd);
  EXPECT_GT(std::abs(fd), 0.5);  // the estimate does move with nu: else this test sees nothing
  EXPECT_NEAR(linear, fd, 0.1 * std::abs(fd));
  expect_throw_with<InputError>([&] { log_youngs_modulus_per_compliance(at_estimate, {{}, est.supine_prediction}); }, "3 landmarks");
}

// Where ICP on the rigid regions sets the pose, its fit's covariance is a source of the linear
// region (and with uncertainty.rigid_pose false it is held); the report states the fit's sd.
TEST(Uncertainty, TheRigidPoseIsASourceWhereIcpSetsIt) {
  Scene s = btr::test::coarse_phantom_scene();
  std::mt19937 rng(11);
  std::normal_distribution<double> z(0.0, 1.0);
  displace_along_normals(*s.supine_rigid, 0.001, [&] { return z(rng); });  // the ring as a camera sees it
  RegistrationOptions o = preset_options("balanced");
  o.uncertainty.enabled = true;
  RegistrationEngine engine(s);
  const RegistrationResult r = engine.solve(o);
  ASSERT_TRUE(r.icp_used);
  ASSERT_TRUE(r.icp.pose_covariance) << r.icp.pose_covariance_note;
  const auto share = [](const TumourUncertainty& u, const std::string& name) {
    for (const auto& [n, c] : u.sources)
      if (n == name) return std::optional<Mat3>(c);
    return std::optional<Mat3>();
  };
  for (const auto& t : r.tumours) {
    const auto pose = share(*t.uncertainty, "rigid_pose");
    ASSERT_TRUE(pose) << t.name;
    const Mat3 expected = t.uncertainty->d_pose * *r.icp.pose_covariance * t.uncertainty->d_pose.transpose();
    EXPECT_LT((*pose - expected).norm(), 1e-12 * expected.norm()) << t.name;
    EXPECT_GT(pose->trace(), 1e-10) << t.name;  // 1 mm of noise on the ring moves the pose by more than 10 um
    std::printf("%-7s rigid pose %.2f mm of %.2f mm (RMS)\n", t.name.c_str(), 1e3 * std::sqrt(pose->trace()),
                1e3 * std::sqrt(t.uncertainty->covariance.trace()));
  }
  const std::string d = btr::test::temp_dir();
  write_registration_outputs(d, engine.prepare(o).scene, engine.prepare(o).model, r, 0);
  std::ifstream report(d + "/report.json");
  const nlohmann::json j = nlohmann::json::parse(report);
  const auto& icp = j.at("rigid_transform_supine_to_model").at("icp");
  ASSERT_EQ(icp.at("pose_sd_deg").size(), 3u);
  EXPECT_NEAR(icp.at("pose_sd_mm")[2].get<double>(), 1e3 * std::sqrt((*r.icp.pose_covariance)(5, 5)), 1e-9);
  EXPECT_TRUE(j.at("uncertainty_sources").at("rigid_pose").get<bool>());
  // The report says what the linear region leaves out: the landmarks' direct effect, and the
  // element form's discretisation error (which only sampling estimates).
  ASSERT_EQ(j.at("uncertainty").at("not_propagated").size(), 3u);
  EXPECT_NE(j.at("uncertainty").at("not_propagated")[0].get<std::string>().find("landmark_sd_mm"), std::string::npos);
  EXPECT_NE(j.at("uncertainty").at("not_propagated")[1].get<std::string>().find("uncertainty.discretisation"), std::string::npos);
  o.uncertainty.sources.rigid_pose = false;
  for (const auto& t : engine.solve(o).tumours) EXPECT_FALSE(share(*t.uncertainty, "rigid_pose")) << t.name;
}

// A pose given by the caller (the node's tracking) with its covariance: the linear region takes
// it, sampling draws the pose from it, and the two agree where the response is nearly linear;
// without a covariance the note says the pose is held.
TEST(Uncertainty, AGivenPoseWithItsCovarianceIsLinearisedAndSampled) {
  const Scene& s = btr::test::coarse_phantom_scene();
  RegistrationOptions o = preset_options("accurate");
  o.uncertainty.enabled = true;
  o.uncertainty.sources = UncertaintySources::none();
  o.uncertainty.sources.rigid_pose = true;
  RegistrationEngine engine(s);
  o.known_supine_to_model = engine.solve(o).supine_to_model;  // as a tracker would have it
  const RegistrationResult held = engine.solve(o);
  EXPECT_NE(held.uncertainty_note.find("held: the caller (tracking) gave it without a covariance"), std::string::npos)
      << held.uncertainty_note;
  Mat6 cov = Mat6::Zero();
  cov.diagonal() << std::pow(0.3 * M_PI / 180, 2), std::pow(0.3 * M_PI / 180, 2), std::pow(0.5 * M_PI / 180, 2), 0.3e-6,
      0.3e-6, 0.5e-6;  // 0.3 / 0.3 / 0.5 deg, 0.55 / 0.55 / 0.71 mm
  o.known_pose_covariance = cov;
  const RegistrationResult r = engine.solve(o);
  ASSERT_TRUE(r.converged);
  EXPECT_TRUE(r.uncertainty_note.empty()) << r.uncertainty_note;
  const SampledUncertainty su = engine.sample_uncertainty(o, o.uncertainty, 24, 9, r);
  ASSERT_EQ(su.samples, 24);
  for (size_t i = 0; i < r.tumours.size(); ++i) {
    const TumourUncertainty& u = *r.tumours[i].uncertainty;
    ASSERT_EQ(u.sources.size(), 5u);
    EXPECT_EQ(u.sources.back().first, "rigid_pose");
    const double linear = std::sqrt(u.covariance.trace()), sampled = std::sqrt(su.tumours[i].covariance.trace());
    std::printf("%-7s pose alone: RMS spread linear %.3f mm, sampled %.3f mm (24 samples), ratio %.2f\n",
                r.tumours[i].name.c_str(), 1e3 * linear, 1e3 * sampled, linear / sampled);
    EXPECT_GT(linear / sampled, 0.6) << r.tumours[i].name;
    EXPECT_LT(linear / sampled, 1.6) << r.tumours[i].name;
  }
}

TEST(Uncertainty, OptionsOutOfRangeAreRefusedAndNoSurfaceStepIsSaid) {
  UncertaintyOptions u;
  u.sources.depth_noise = -1;
  expect_throw_with<InputError>([&] { validate_uncertainty_options(u); }, "depth_noise");
  u = {};
  u.sources.youngs_modulus_range = {3000, 200};
  expect_throw_with<InputError>([&] { validate_uncertainty_options(u); }, "youngs_modulus_range");
  u = {};
  u.sources.poisson_ratio_range = {0.45, 0.5};
  expect_throw_with<InputError>([&] { validate_uncertainty_options(u); }, "poisson_ratio_range");
  u = {};
  u.sources.landmark_sd = std::nan("");
  expect_throw_with<InputError>([&] { validate_uncertainty_options(u); }, "landmark_sd_mm");
  u.sources = UncertaintySources::none();
  validate_uncertainty_options(u);  // every source held is valid
  Scene s = btr::test::coarse_phantom_scene();
  s.steps = {"rigid", "landmarks"};
  RegistrationOptions o = preset_options("fast");
  o.uncertainty.enabled = true;
  const RegistrationResult r = RegistrationEngine(s).solve(o);
  EXPECT_NE(r.uncertainty_note.find("surface step did not run"), std::string::npos) << r.uncertainty_note;
  for (const auto& t : r.tumours) EXPECT_FALSE(t.uncertainty);
}

TEST(Uncertainty, SamplingIsReproducibleAndWithoutSourcesHasNoSpread) {
  const Scene& s = btr::test::coarse_phantom_scene();
  RegistrationOptions o = preset_options("fast");
  RegistrationEngine engine(s);
  const RegistrationResult nominal = engine.solve(o);
  UncertaintyOptions u;
  u.sources.discretisation = false;  // its own test below
  const SampledUncertainty a = engine.sample_uncertainty(o, u, 4, 3, nominal), b = engine.sample_uncertainty(o, u, 4, 3, nominal);
  ASSERT_EQ(a.samples, 4);
  EXPECT_EQ(a.failed, 0);
  // Every source sampled, nothing failed: the note only counts the samples that stopped
  // unconverged, by kind, and says so for each of them.
  EXPECT_EQ(a.note.find("not sampled"), std::string::npos) << a.note;
  EXPECT_EQ(a.note.find("failed"), std::string::npos) << a.note;
  EXPECT_EQ(a.note.empty(), a.not_converged == 0) << a.note;
  ASSERT_EQ(a.tumours.size(), nominal.tumours.size());
  for (size_t i = 0; i < a.tumours.size(); ++i) {
    EXPECT_EQ(a.tumours[i].radius_95, b.tumours[i].radius_95);  // the seed fixes every input
    EXPECT_GT(a.tumours[i].radius_95, 0.0);
    EXPECT_GT(a.tumours[i].covariance.trace(), 0.0);
  }
  // The per-vertex bound of the margin shell: one per tumour vertex, the same seed the same
  // values, some spread where the sources move the tumour, and millimetres, not centimetres.
  for (size_t i = 0; i < a.tumours.size(); ++i) {
    ASSERT_EQ(a.tumours[i].vertex_radius_95.size(), static_cast<size_t>(nominal.tumours[i].registered.V.rows()));
    EXPECT_EQ(a.tumours[i].vertex_radius_95, b.tumours[i].vertex_radius_95);
    const double most = *std::max_element(a.tumours[i].vertex_radius_95.begin(), a.tumours[i].vertex_radius_95.end());
    EXPECT_GT(most, 0.0);
    EXPECT_LT(most, 0.02);  // metres: a bound of centimetres on the coarse phantom would be a unit slip
  }
  // The outputs: each tumour's margin shell, its vertices that far from the registered ones,
  // and the report's figures.
  {
    std::string d;
    const nlohmann::json j = sampled_report(engine, o, nominal, a, d);
    const PreparedScene& prep = engine.prepare(o);
    EXPECT_DOUBLE_EQ(j.at("uncertainty_sources").at("landmark_sd_mm").get<double>(), 1.5);  // the defaults, stated
    EXPECT_DOUBLE_EQ(j.at("uncertainty_sources").at("youngs_modulus_range_Pa")[1].get<double>(), 3000);
    for (size_t i = 0; i < a.tumours.size(); ++i) {
      const TumourResult& t = nominal.tumours[i];
      const SurfaceMesh shell = read_surface(d + "/tumour_" + t.name + "_margin95.obj", prep.scene.units);
      ASSERT_EQ(shell.V.rows(), t.registered.V.rows());
      for (Eigen::Index v = 0; v < shell.V.rows(); ++v)
        EXPECT_NEAR((shell.V.row(v) - t.registered.V.row(v)).norm(), a.tumours[i].vertex_radius_95[static_cast<size_t>(v)], 1e-6);
      const double most = *std::max_element(a.tumours[i].vertex_radius_95.begin(), a.tumours[i].vertex_radius_95.end());
      EXPECT_NEAR(j.at("tumours")[i].at("uncertainty_sampled").at("margin_95_mm").at("max").get<double>(), most * 1e3, 1e-9);
    }
  }
  // No source: every sample is the nominal registration.
  UncertaintyOptions none;
  none.sources = UncertaintySources::none();
  const SampledUncertainty z = engine.sample_uncertainty(o, none, 3, 3, nominal);
  for (const auto& t : z.tumours) {
    EXPECT_LT(t.radius_95, 1e-12);
    EXPECT_LT(t.covariance.norm(), 1e-20);
    for (double r : t.vertex_radius_95) EXPECT_LT(r, 1e-12);
  }
  expect_throw_with<InputError>([&] { engine.sample_uncertainty(o, u, 1, 3, nominal); }, "at least 2 samples");
  EXPECT_EQ(percentile_95({3, 1, 2}), 3.0);
  EXPECT_EQ(percentile_95({}), 0.0);
}

// The element form's discretisation error as a source of the sampled region: the nominal inputs
// registered again with the nodal volume form on the same mesh, and every sample moved by its
// shift of each tumour.
TEST(Uncertainty, SamplingTakesTheNodalReferencesShiftAsTheElementFormsDiscretisationError) {
  // sampled_distances: each offset moved by the shift (no shift: the offsets' norms).
  const std::vector<Vec3> offsets = {Vec3(0.001, 0, 0), Vec3(0, 0.002, 0)};
  EXPECT_EQ(sampled_distances(offsets, Vec3::Zero()), (std::vector<double>{0.001, 0.002}));
  const std::vector<double> moved = sampled_distances(offsets, Vec3(-0.001, 0, 0));
  ASSERT_EQ(moved.size(), 2u);
  EXPECT_NEAR(moved[0], 0.0, 1e-15);
  EXPECT_NEAR(moved[1], std::sqrt(5.0) * 0.001, 1e-15);

  const Scene& s = btr::test::coarse_phantom_scene();
  const RegistrationOptions o = preset_options("fast");
  RegistrationEngine engine(s);
  const RegistrationResult nominal = engine.solve(o);
  ASSERT_EQ(nominal.volume_form, VolumeForm::Element);  // auto at nu 0.49
  Scene ns = s;
  ns.material.volume_form = VolumeForm::Nodal;
  RegistrationEngine nodal_engine(ns);
  const RegistrationResult nodal = nodal_engine.solve(o);
  ASSERT_TRUE(nominal.converged && nodal.converged);
  ASSERT_FALSE(nodal.volume_form_fallback);
  UncertaintyOptions u;
  u.sources = UncertaintySources::none();
  u.sources.landmark_sd = 0.0015;  // one source is enough here
  u.sources.discretisation = true;
  const SampledUncertainty a = engine.sample_uncertainty(o, u, 4, 3, nominal);
  ASSERT_TRUE(a.discretisation_estimated) << a.note;
  EXPECT_GT(a.discretisation_seconds, 0.0);
  EXPECT_NE(a.note.find("nodal volume form"), std::string::npos) << a.note;
  ASSERT_EQ(a.tumours.size(), nominal.tumours.size());
  for (size_t i = 0; i < a.tumours.size(); ++i) {
    const auto& t = a.tumours[i];
    const Vec3 shift = nodal.tumours[i].centroid - nominal.tumours[i].centroid;
    EXPECT_GT(shift.norm(), 1e-5) << "the two forms must differ for this test to mean anything";
    EXPECT_LT((t.discretisation - shift).norm(), 1e-3 * shift.norm()) << nominal.tumours[i].name;
    // The radius is the samples' moved by that shift, and the sources' alone beside it.
    std::vector<Vec3> offsets_i;
    for (const Vec3& c : t.centroids) offsets_i.push_back(c - nominal.tumours[i].centroid);
    EXPECT_DOUBLE_EQ(t.radius_95, percentile_95(sampled_distances(offsets_i, t.discretisation)));
    EXPECT_DOUBLE_EQ(t.radius_95_sources, percentile_95(sampled_distances(offsets_i, Vec3::Zero())));
    Vec3 mean = Vec3::Zero();
    for (const Vec3& c : t.centroids) mean += c / static_cast<double>(t.centroids.size());
    Mat3 sampled = Mat3::Zero();
    for (const Vec3& c : t.centroids) sampled += (c - mean) * (c - mean).transpose() / static_cast<double>(t.centroids.size() - 1);
    EXPECT_LT((t.covariance - sampled).norm(), 1e-12);  // the samples' own, about their mean
    ASSERT_EQ(t.vertex_radius_95.size(), static_cast<size_t>(nominal.tumours[i].registered.V.rows()));
  }
  // With no other source every sample is the nominal registration: the region is the shift
  // itself, at the centroid and at every vertex of the margin shell.
  UncertaintyOptions only;
  only.sources = UncertaintySources::none();
  only.sources.discretisation = true;
  const SampledUncertainty z = engine.sample_uncertainty(o, only, 2, 3, nominal);
  ASSERT_TRUE(z.discretisation_estimated) << z.note;
  for (size_t i = 0; i < z.tumours.size(); ++i) {
    EXPECT_NEAR(z.tumours[i].radius_95, (nodal.tumours[i].centroid - nominal.tumours[i].centroid).norm(), 1e-9);
    EXPECT_LT(z.tumours[i].radius_95_sources, 1e-12);
    const Points& V = nodal.tumours[i].registered.V;
    ASSERT_EQ(z.tumours[i].vertex_radius_95.size(), static_cast<size_t>(V.rows()));
    for (Eigen::Index v = 0; v < V.rows(); ++v)
      EXPECT_NEAR(z.tumours[i].vertex_radius_95[static_cast<size_t>(v)], (V.row(v) - nominal.tumours[i].registered.V.row(v)).norm(), 1e-9);
  }
  // Left out: the radius is the sources' alone, and no reference is run.
  u.sources.discretisation = false;
  const SampledUncertainty b = engine.sample_uncertainty(o, u, 4, 3, nominal);
  EXPECT_FALSE(b.discretisation_estimated);
  EXPECT_EQ(b.discretisation_seconds, 0.0);
  for (size_t i = 0; i < b.tumours.size(); ++i) {
    EXPECT_EQ(b.tumours[i].radius_95, b.tumours[i].radius_95_sources);
    EXPECT_EQ(b.tumours[i].radius_95_sources, a.tumours[i].radius_95_sources);  // the same samples
    EXPECT_TRUE(b.tumours[i].discretisation.isZero(0.0));
  }
  // A registration already nodal has no finer form to compare with: said, not estimated.
  u.sources.discretisation = true;
  const SampledUncertainty c = nodal_engine.sample_uncertainty(o, u, 2, 3, nodal);
  EXPECT_FALSE(c.discretisation_estimated);
  EXPECT_NE(c.note.find("discretisation not estimated: the registration used the nodal volume form"), std::string::npos) << c.note;
  // The report states both radii, the shift and the source.
  std::string d;
  const nlohmann::json j = sampled_report(engine, o, nominal, a, d);
  EXPECT_TRUE(j.at("uncertainty_sampled").at("discretisation_estimated").get<bool>());
  const auto& t0 = j.at("tumours")[0].at("uncertainty_sampled");
  EXPECT_NEAR(t0.at("radius_95_sources_mm").get<double>(), a.tumours[0].radius_95_sources * 1e3, 1e-9);
  EXPECT_NEAR(t0.at("discretisation_mm")[2].get<double>(), a.tumours[0].discretisation.z() * 1e3, 1e-9);
}

TEST(MarginShell, GrowsASphereOutwardsByTheBoundAtEveryVertexWhateverItsOrientation) {
  const Vec3 c(0.01, -0.02, 0.03);
  const double R = 0.01;
  SurfaceMesh sphere = make_icosphere(c, R, 3);
  std::vector<double> grow(static_cast<size_t>(sphere.V.rows()));
  for (Eigen::Index v = 0; v < sphere.V.rows(); ++v) grow[static_cast<size_t>(v)] = 0.001 + 0.002 * (sphere.V(v, 2) > c.z());
  SurfaceMesh inward = sphere;
  inward.F.col(1).swap(inward.F.col(2));
  for (const SurfaceMesh* s : {&sphere, &inward}) {
    const SurfaceMesh shell = margin_shell(*s, grow);
    ASSERT_EQ(shell.F, s->F);
    for (Eigen::Index v = 0; v < shell.V.rows(); ++v) {
      const double want = R + grow[static_cast<size_t>(v)];
      EXPECT_NEAR((shell.V.row(v).transpose() - c).norm(), want, 1e-3 * want) << v;  // vertex normals of an icosphere are radial
    }
    EXPECT_GT(std::abs(enclosed_volume(shell)), std::abs(enclosed_volume(*s)));
  }
  EXPECT_EQ(margin_shell(sphere, std::vector<double>(grow.size(), 0.0)).V, sphere.V);
  expect_throw_with<InputError>([&] { margin_shell(sphere, {0.001}); }, "grow values for");
  grow[3] = -1e-3;
  expect_throw_with<InputError>([&] { margin_shell(sphere, grow); }, ">= 0");
  grow[3] = std::nan("");
  expect_throw_with<InputError>([&] { margin_shell(sphere, grow); }, "finite");
  SurfaceMesh open = sphere;
  open.F.conservativeResize(1, 3);
  expect_throw_with<InputError>([&] { margin_shell(open, std::vector<double>(grow.size(), 0.0)); }, "margin shell");
}

TEST(UncertaintyPicture, TheRegionDrawnIsTheCovariances95PercentEllipsoid) {
  // Standard deviations 1, 2, 3 mm along turned axes: semi-axes sqrt(7.8147) times those.
  const Mat3 R = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 sd(0.001, 0.002, 0.003), c(0.01, -0.02, 0.05);
  const SurfaceMesh e = uncertainty_ellipsoid(c, R * sd.cwiseAbs2().asDiagonal() * R.transpose());
  const double k = std::sqrt(7.8147);
  // An icosphere of 320 faces holds 0.966 of its sphere's volume; the surface stays outward.
  const double expected = 4.0 / 3.0 * M_PI * k * sd[0] * k * sd[1] * k * sd[2];
  EXPECT_NEAR(enclosed_volume(e) / expected, 0.966, 0.005);
  EXPECT_LT((volume_centroid(e) - c).norm(), 1e-9);
  double longest = 0;
  for (Eigen::Index i = 0; i < e.V.rows(); ++i) longest = std::max(longest, (e.V.row(i).transpose() - c).norm());
  EXPECT_LE(longest, k * sd[2] * (1 + 1e-9));  // no vertex beyond the major semi-axis,
  EXPECT_GT(longest, 0.97 * k * sd[2]);         // and one near it
}
