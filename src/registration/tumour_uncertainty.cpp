#include "breast_tumour_registration/registration/tumour_uncertainty.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/blas_threads.h"
#include "breast_tumour_registration/fem/heap_retention.h"
#include "breast_tumour_registration/fem/hessian_factor.h"
#include "breast_tumour_registration/fem/gmres.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/hessian_pattern.h"
#include "breast_tumour_registration/fem/rigid_free_surface_energy.h"
#include "breast_tumour_registration/fem/spring_energy.h"
#include "breast_tumour_registration/fem/total_energy.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/registration/quadratic_unload_equation.h"

namespace btr {
namespace {

/// P(sum_i l_i z_i^2 <= r^2) for independent standard normal z, l sorted ascending.
double chi_square_mixture_cdf(const Vec3& l, double r) {
  if (l(2) <= 0) return r >= 0 ? 1.0 : 0.0;
  // Integrate P(z3^2 <= (r^2 - l1 z1^2 - l2 z2^2) / l3) over z1, z2 >= 0 (even integrand):
  // midpoint rule on [0, 8] with the normal density, folded.
  constexpr int n = 160;
  constexpr double top = 8.0;
  // Each integral runs to where its integrand's support ends (midpoint rule on that interval).
  auto limit = [&](double a, double l) { return l > 0 ? std::min(top, std::sqrt(std::max(0.0, a) / l)) : top; };
  auto normal = [](double z) { return std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI); };
  double p = 0;
  const double u1 = limit(r * r, l(0)), h1 = u1 / n;
  for (int i = 0; i < n; ++i) {
    const double z1 = (i + 0.5) * h1, a = r * r - l(0) * z1 * z1;
    if (a <= 0) continue;
    const double u2 = limit(a, l(1)), h2 = u2 / n;
    double inner = 0;
    for (int j = 0; j < n; ++j) {
      const double z2 = (j + 0.5) * h2, b = a - l(1) * z2 * z2;
      if (b > 0) inner += 2.0 * h2 * normal(z2) * std::erf(std::sqrt(b / (2.0 * l(2))));
    }
    p += 2.0 * h1 * normal(z1) * inner;
  }
  return p;
}

/// The body's gradient at x from rest positions `rest` with `materials` (elastic), plus that of
/// `gravity` when it is non-zero (its masses come from the rest volumes) [N], every vertex.
Eigen::VectorXd body_gradient(const RegistrationModel& m, const Points& rest, const std::vector<StableNeoHookean>& materials,
                              const Points& x, const Vec3& gravity) {
  TotalEnergy e;
  const TetMesh mesh{rest, m.rest.T};
  add_elastic_energy(e, mesh, materials, m.material_of, m.volume_form, m.material.nodal_element_share);
  if (gravity.norm() > 0) e.add(std::make_shared<GravityEnergy>(mesh, m.material.density, gravity));
  return e.gradient(x);
}

/// d/dq of the elastic gradient at x (rest shape the model's), q the volume compliance, by a
/// central difference in q kept inside (0, inf).
Eigen::VectorXd elastic_gradient_d_compliance(const RegistrationModel& m, const Points& x) {
  const double q0 = volume_compliance(m.material.poisson_ratio), h = 1e-3 * q0;
  return (body_gradient(m, m.rest.V, materials_at(m, poisson_ratio_of_compliance(q0 + h)), x, Vec3::Zero()) -
          body_gradient(m, m.rest.V, materials_at(m, poisson_ratio_of_compliance(q0 - h)), x, Vec3::Zero())) /
         (2 * h);
}

/// The directional derivative of the body's gradient at x in the rest positions, along dX
/// (every vertex; zero rows stay put): a central difference moving no vertex more than 1 um.
Eigen::VectorXd gradient_d_rest(const RegistrationModel& m, const Points& x, const Eigen::VectorXd& dX, const Vec3& gravity) {
  const double largest = dX.cwiseAbs().maxCoeff();
  if (!(largest > 0)) return Eigen::VectorXd::Zero(dX.size());
  const double eps = 1e-6 / largest;
  const auto D = as_points(dX);
  return (body_gradient(m, m.rest.V + eps * D, m.materials, x, gravity) -
          body_gradient(m, m.rest.V - eps * D, m.materials, x, gravity)) /
         (2 * eps);
}

/// How the unloaded rest shape X moves with each input p (its columns dG_p/dp: the prone
/// gradient's partials at the imaged shape x_p, rest X). X is defined by G_p(x_p; X, p) = 0, so
/// D_X G_p [dX/dp] = -dG_p/dp, with D_X G_p known only through differences of the gradient
/// (gradient_d_rest). GMRES solves it, preconditioned by minus the prone elastic Hessian: for small
/// strains moving the rest shape is moving the deformed one backwards, D_X G ~ -H, and the
/// preconditioned operator is near the identity (this is the unload's fixed point, linearised).
RestShapeResponse rest_shape_response(const RegistrationModel& m, const TotalEnergy& elastic,
                                      const std::vector<Eigen::VectorXd>& dGp_dp) {
  const int nv = static_cast<int>(m.rest.V.rows());
  HessianAssembler Hp(nv, m.rest.T, m.fixed, elastic.hessian_cliques());
  HessianLlt llt;  // only the preconditioner: the projected one serves too
  factorize_exact_or_projected(elastic, m.prone, Hp, llt, "uncertainty: the prone Hessian");
  auto scatter = [&](const Eigen::VectorXd& reduced) {
    Eigen::VectorXd full = Eigen::VectorXd::Zero(3 * nv);
    Hp.scatter_add(reduced, 1.0, full);
    return full;
  };
  auto apply_A = [&](const Eigen::VectorXd& v) {
    return Eigen::VectorXd(Hp.gather(gradient_d_rest(m, m.prone, scatter(v), m.unloaded_under)));
  };
  auto apply_Minv = [&](const Eigen::VectorXd& r) { return Eigen::VectorXd(-llt.solve(r)); };
  RestShapeResponse out;
  for (const Eigen::VectorXd& b : dGp_dp) {
    Eigen::VectorXd y;
    const GmresResult g = gmres(apply_A, apply_Minv, Eigen::VectorXd(-Hp.gather(b)), 1e-6, 60, y);
    out.add(g, scatter(y));
  }
  return out;
}

/// The unloaded rest shape's response to ln E and (with_q) to q: the prone gradient's partials
/// at the imaged shape (dG_p/d ln E = G_elastic there), the q column zero without q. Where the
/// rest shape inverts the quadratic model (its quadratic pass converged), that equation's
/// (quadratic_unload_equation.h); where that pass kept the linear shape, the linear one's.
RestShapeResponse rest_response_to_material(const RegistrationModel& m, const TotalEnergy& elastic, bool with_q) {
  if (m.unload && m.unload->unload.elements == ElementOrder::Quadratic) return QuadraticUnloadEquation(m).rest_response(with_q);
  return rest_shape_response(m, elastic,
                             {elastic.gradient(m.prone),
                              with_q ? elastic_gradient_d_compliance(m, m.prone) : Eigen::VectorXd::Zero(3 * m.rest.V.rows())});
}

bool fit_usable(const LandmarkStiffnessFit& fit, int nv) {
  return fit.anchors.size() >= 3 && fit.supine_prediction.rows() == nv && fit.supine_prediction.allFinite();
}

/// The stiffness step's landmark fit (LandmarkStiffnessFit) linearised: how its landmarks move
/// per unit ln E and per unit q (with_q; else zero) in the supine gravity-only prediction (the
/// rest shape's part included: dX_rest, empty when the rest shape is the prone one), less the
/// part any rigid motion of the landmarks explains (the fit re-fits the pose: Kabsch). Model
/// frame, 3 rows per landmark.
struct LandmarkFitMotion {
  Eigen::VectorXd per_log_e, per_q;
};

LandmarkFitMotion landmark_fit_motion(const RegistrationModel& m, const TotalEnergy& elastic, const LandmarkStiffnessFit& fit,
                                      const std::vector<Eigen::VectorXd>& dX_rest, bool with_q) {
  const int nv = static_cast<int>(m.rest.V.rows());
  const Points& xg = fit.supine_prediction;
  HessianAssembler Hg(nv, m.rest.T, m.fixed, elastic.hessian_cliques());
  HessianLlt llt;
  factorize_exact_or_projected(elastic, xg, Hg, llt, "uncertainty: the stiffness prediction's Hessian");
  const int n = static_cast<int>(fit.anchors.size());
  auto landmark_motion = [&](Eigen::VectorXd partial, int input) {
    if (!dX_rest.empty()) partial += gradient_d_rest(m, xg, dX_rest[input], m.gravity);
    Eigen::VectorXd full = Eigen::VectorXd::Zero(3 * nv);
    Hg.scatter_add(llt.solve(Hg.gather(partial)), -1.0, full);
    const Points d = as_points(full);
    Eigen::VectorXd l(3 * n);
    for (int i = 0; i < n; ++i) l.segment<3>(3 * i) = fit.anchors[i].position(d);
    return l;
  };
  LandmarkFitMotion out;
  out.per_log_e = landmark_motion(elastic.gradient(xg), 0);
  out.per_q = with_q ? landmark_motion(elastic_gradient_d_compliance(m, xg), 1) : Eigen::VectorXd::Zero(3 * n);
  // The landmarks' small rigid motions about their centroid: translations, and e_k x (p - c).
  Eigen::MatrixXd B(3 * n, 6);
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < n; ++i) c += fit.anchors[i].position(xg) / n;
  for (int i = 0; i < n; ++i) {
    const Vec3 r = fit.anchors[i].position(xg) - c;
    B.block<3, 3>(3 * i, 0) = Mat3::Identity();
    for (int k = 0; k < 3; ++k) B.block<3, 1>(3 * i, 3 + k) = Vec3::Unit(k).cross(r);
  }
  const Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(B).householderQ() * Eigen::MatrixXd::Identity(3 * n, 6);
  out.per_log_e -= Q * (Q.transpose() * out.per_log_e);
  out.per_q -= Q * (Q.transpose() * out.per_q);
  return out;
}

/// d ln E / d q of the fit: the Gauss-Newton step of ln E that fits the moved landmarks again.
double per_compliance(const LandmarkFitMotion& f) {
  if (!(f.per_log_e.squaredNorm() > 0)) return 0;
  return -f.per_log_e.dot(f.per_q) / f.per_log_e.squaredNorm();
}

}  // namespace

double volume_compliance(double nu) { return (1.0 - 2.0 * nu) / (2.0 * nu); }

double poisson_ratio_of_compliance(double q) { return 1.0 / (2.0 * (1.0 + q)); }

std::vector<StableNeoHookean> materials_at(const RegistrationModel& m, double nu, double youngs_factor) {
  std::vector<StableNeoHookean> out;
  for (const auto& mat : m.materials) out.emplace_back(mat.youngs_modulus() * youngs_factor, nu);
  return out;
}

double volume_compliance_rms(const std::array<double, 2>& range, double nominal_nu) {
  if (!(range[1] > 0)) return 0;
  // Midpoint rule over the uniform range: exact enough for a distribution's second moment.
  constexpr int n = 2000;
  const double q0 = volume_compliance(nominal_nu);
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double nu = range[0] + (range[1] - range[0]) * (i + 0.5) / n;
    sum += std::pow(volume_compliance(nu) - q0, 2);
  }
  return std::sqrt(sum / n);
}

double log_youngs_modulus_per_compliance(const RegistrationModel& model, const LandmarkStiffnessFit& fit) {
  const int nv = static_cast<int>(model.rest.V.rows());
  if (!fit_usable(fit, nv))
    throw InputError("uncertainty: the stiffness fit needs >= 3 landmarks and a finite prediction of every vertex");
  TotalEnergy elastic;
  add_model_elastic_energy(elastic, model);
  std::vector<Eigen::VectorXd> dX_rest;
  if (model.unloaded_under.norm() > 0)
    dX_rest = rest_response_to_material(model, elastic, true).dX;
  return per_compliance(landmark_fit_motion(model, elastic, fit, dX_rest, true));
}

void validate_uncertainty_options(const UncertaintyOptions& o) {
  validate_uncertainty_sources(o.sources);
  if (!(o.youngs_modulus_log_sd >= 0) || !std::isfinite(o.youngs_modulus_log_sd))
    throw InputError("uncertainty: the sd of ln E must be >= 0 and finite, got " + std::to_string(o.youngs_modulus_log_sd));
}

std::array<Vec3, 2> gravity_tilt_axes(const Vec3& gravity) {
  const Vec3 down = gravity.normalized();
  const Vec3 a0 = down.unitOrthogonal();
  return {a0, down.cross(a0)};
}

double probability_within(const Mat3& covariance, double r) {
  Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (covariance + covariance.transpose()));
  return chi_square_mixture_cdf(es.eigenvalues().cwiseMax(0.0), r);
}

double percentile_95(std::vector<double> d) {
  if (d.empty()) return 0;
  std::sort(d.begin(), d.end());
  const size_t rank = static_cast<size_t>(std::ceil(0.95 * static_cast<double>(d.size())));
  return d[std::max<size_t>(rank, 1) - 1];
}

std::vector<double> sampled_distances(const std::vector<Vec3>& offsets, const Vec3& shift) {
  std::vector<double> d;
  d.reserve(offsets.size());
  for (const Vec3& o : offsets) d.push_back((o + shift).norm());
  return d;
}

double radius_95(const Mat3& covariance) {
  Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (covariance + covariance.transpose()));
  Vec3 l = es.eigenvalues().cwiseMax(0.0);  // ascending
  if (l(2) <= 0) return 0;
  // Bracket: at least the largest axis' 1-D radius (1.96 sd); at most that of all the variance
  // on one axis (the 95 % quantile of a weighted sum of chi-square(1) is largest with one term).
  double lo = 1.959 * std::sqrt(l(2)), hi = 1.961 * std::sqrt(l.sum());
  for (int it = 0; it < 50 && hi - lo > 1e-6 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (chi_square_mixture_cdf(l, mid) < 0.95 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

UncertaintyResult linearised_tumour_uncertainty(const RegistrationModel& model, const Points& x,
                                                const SurfaceProjector& supine, const Rigid& model_to_projector,
                                                const Rigid& model_to_supine, const SurfaceStepOptions& surface,
                                                const UncertaintyOptions& opt, const std::optional<Mat6>& pose_covariance,
                                                const LandmarkStiffnessFit* stiffness_fit,
                                                const FreePoseLinearisation* free_pose) {
  std::vector<HeldSkinVertex> held;
  const Mat3 R_p = model_to_projector.linear();
  const Rigid to_model = model_to_projector.inverse();
  for (int v : model.skin) {
    const Projection c = supine.project(model_to_projector * Vec3(x.row(v).transpose()));
    if (!holds_projection(c, surface)) continue;
    held.push_back({v, to_model * c.point, (R_p.transpose() * c.normal).normalized()});
  }
  return linearised_tumour_uncertainty(model, x, held, model_to_supine, surface, opt, pose_covariance, stiffness_fit,
                                       free_pose);
}

UncertaintyResult linearised_tumour_uncertainty(const RegistrationModel& model, const Points& x,
                                                const std::vector<HeldSkinVertex>& held, const Rigid& model_to_supine,
                                                const SurfaceStepOptions& surface, const UncertaintyOptions& opt,
                                                const std::optional<Mat6>& pose_covariance,
                                                const LandmarkStiffnessFit* stiffness_fit,
                                                const FreePoseLinearisation* free_pose) {
  validate_uncertainty_options(opt);
  const auto t0 = std::chrono::steady_clock::now();
  UncertaintyResult out;
  const int nv = static_cast<int>(x.rows());
  if (held.empty()) throw InputError("uncertainty: no skin vertex is held by the supine surface");
  if (free_pose && pose_covariance)
    throw InputError("uncertainty: a pose solved with the deformation is not an input with a covariance");
  if (free_pose && static_cast<Eigen::Index>(free_pose->landmarks.size()) != free_pose->landmark_targets.rows())
    throw InputError("uncertainty: the landmarks sharing the pose and their targets differ in number");
  if (free_pose && free_pose->landmark_normals.rows() > 0 && free_pose->landmark_normals.rows() != free_pose->landmark_targets.rows())
    throw InputError("uncertainty: the landmarks sharing the pose and their normals differ in number");

  // The fixed point's Jacobian: elastic + held skin along its normals.
  TotalEnergy elastic;
  add_model_elastic_energy(elastic, model);
  // A held target moving by delta along n moves both springs' targets: dG/d delta = -spring n.
  const double spring = surface.point_weight + surface.plane_weight;
  // Held projections, or sliding held where the skin settled: the point spring holds the vertex
  // along the surface too (its anchor stays), the plane spring along the normal; with free
  // sliding, a projection that follows the vertex along the surface leaves only the normal
  // direction, with both springs' weight.
  const bool held_along = opt.held_projections || surface.sliding == SkinSliding::HeldWhereSettled;
  const double w_point = held_along ? surface.point_weight : 0, w_plane = held_along ? surface.plane_weight : spring;
  TotalEnergy jac;
  for (const auto& t : elastic.terms()) jac.add(t);
  // With the pose free the held springs are those of RigidFreeSurfaceEnergy, in the projector's
  // frame, the landmarks sharing the pose; Q is the rotation of the pose at x (model ->
  // projector) and cbar the centroid of the correspondences there, about which it turns.
  Mat3 Q = Mat3::Identity();
  Vec3 cbar = Vec3::Zero();
  Rigid P = Rigid::Identity();
  std::vector<Anchor> pose_anchors;  // the landmarks', with a free pose
  if (free_pose) {
    auto fs = std::make_shared<RigidFreeSurfaceEnergy>(w_point, w_plane);
    const Rigid& P0 = free_pose->model_to_projector;
    Points y(static_cast<Eigen::Index>(held.size()), 3), n(static_cast<Eigen::Index>(held.size()), 3);
    std::vector<int> verts;
    for (size_t k = 0; k < held.size(); ++k) {
      y.row(static_cast<Eigen::Index>(k)) = (P0 * held[k].point).transpose();
      n.row(static_cast<Eigen::Index>(k)) = (P0.linear() * held[k].normal).transpose();
      verts.push_back(held[k].vertex);
    }
    fs->set(verts, y, n);
    if (free_pose->landmark_targets.rows() > 0) {
      fs->set_points(free_pose->landmarks, free_pose->landmark_targets, free_pose->landmark_weight);
      pose_anchors = free_pose->landmarks;
    }
    P = fs->pose(x);
    Q = P.linear();
    cbar = fs->turning_centre(x, P);
    jac.add(fs);
  } else {
    auto springs = std::make_shared<SpringEnergy>("held skin");
    for (const HeldSkinVertex& h : held)
      springs->add_point_and_plane(Anchor::vertex(h.vertex), h.point, h.normal, w_point, w_plane);
    jac.add(springs);
  }
  HessianAssembler H(nv, model.rest.T, model.fixed, jac.hessian_cliques());
  use_single_threaded_blas();
  keep_freed_heap_memory();
  HessianLlt llt;
  // An element compressed past its stable range makes the exact Hessian indefinite there; the
  // projected one is a bound on the stiffness, so the spread it gives is a lower bound.
  if (factorize_exact_or_projected(jac, x, H, llt, "uncertainty: the fixed point's Jacobian"))
    out.note = "the exact Hessian is not positive definite at the result; linearised on the projected one (a lower bound)";
  // The pose's rank-6 part (H - W M W^T, free DOFs), by the Woodbury identity as the Newton
  // solver applies it; empty with a held pose.
  const LowRankHessian low = jac.low_rank_hessian(x, H);
  Eigen::MatrixXd Z;
  Eigen::FullPivLU<Eigen::MatrixXd> K;
  if (low.W.cols()) {
    Z = llt.solve(low.W);
    K.compute(Eigen::MatrixXd::Identity(low.M.rows(), low.M.rows()) - low.M * (low.W.transpose() * Z));
  }
  auto solve = [&](const Eigen::MatrixXd& rhs) {
    Eigen::MatrixXd d = llt.solve(rhs);
    if (low.W.cols()) d += Z * K.solve(low.M * (Z.transpose() * rhs));
    return d;
  };
  // The pose's motion xi = (omega about cbar, tau) per correspondence: d(P p) = J xi.
  auto pose_jacobian = [&](const Vec3& p_projector) { return RigidFreeSurfaceEnergy::twist_jacobian(p_projector, cbar); };

  // Inputs' dG/dp on the free DOFs. G_elastic is linear in E: dG/d ln E = G_elastic. Poisson's
  // ratio enters through the volume compliance q = (1 - 2 nu) / (2 nu), in which the response
  // is near linear (the volume stiffness is ~ mu / q), unlike in nu itself near 0.5.
  double sd_log_e = !opt.sources.samples_youngs_modulus() ? 0.0
                    : opt.youngs_modulus_log_sd > 0    ? opt.youngs_modulus_log_sd
                                                       : opt.sources.youngs_modulus_log_sd();
  const double sd_q = volume_compliance_rms(opt.sources.poisson_ratio_range, model.material.poisson_ratio);
  Eigen::VectorXd full_E = elastic.gradient(x);
  Eigen::VectorXd full_q = sd_q > 0 ? elastic_gradient_d_compliance(model, x) : Eigen::VectorXd::Zero(3 * nv);
  // An unloaded rest shape is the material's too: at another E or nu the prone image unloads to
  // another shape, and the supine equilibrium moves with it, dG/dp += D_X G [dX/dp].
  const bool gravity = surface.gravity && model.gravity.norm() > 0;
  std::vector<Eigen::VectorXd> dX_rest;  // per input (ln E, q); empty: the rest shape is the prone one
  if (model.unloaded_under.norm() > 0 && (sd_log_e > 0 || sd_q > 0)) {
    const auto t_rest = std::chrono::steady_clock::now();
    const RestShapeResponse rr = rest_response_to_material(model, elastic, sd_q > 0);
    dX_rest = rr.dX;
    const Vec3 g_s = gravity ? model.gravity : Vec3::Zero();
    full_E += gradient_d_rest(model, x, rr.dX[0], g_s);
    if (sd_q > 0) full_q += gradient_d_rest(model, x, rr.dX[1], g_s);
    out.rest_shape_follows = true;
    out.rest_response_iterations = rr.iterations;
    out.rest_response_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_rest).count();
    if (!rr.converged) {
      char b[200];
      std::snprintf(b, sizeof b, "the rest shape's response to the material stopped at a relative residual of %.2g", rr.worst_residual);
      out.note += (out.note.empty() ? "" : "; ") + std::string(b);
    }
  }
  // The landmark fit an estimated E came from: it follows a true nu other than the method's,
  // and (with a free pose) the landmarks that also hold the skin.
  const double sd_landmark = opt.sources.landmark_sd;
  const bool landmarks_source = free_pose && !pose_anchors.empty() && sd_landmark > 0;
  const bool fit_given = stiffness_fit && fit_usable(*stiffness_fit, nv);
  // The estimate's sd is the landmarks' (StiffnessEstimate::log_sd) when it was fitted on them:
  // with the landmarks a source, that part moves with them, jointly.
  const bool estimate_follows_landmarks = landmarks_source && fit_given && opt.youngs_modulus_log_sd > 0 &&
                                          stiffness_fit->anchors.size() == pose_anchors.size();
  LandmarkFitMotion fit_motion;
  if (fit_given && (sd_q > 0 || estimate_follows_landmarks))
    fit_motion = landmark_fit_motion(model, elastic, *stiffness_fit, dX_rest, sd_q > 0);
  if (fit_given && sd_q > 0) {
    out.log_youngs_modulus_per_compliance = per_compliance(fit_motion);
    out.estimate_follows_poisson_ratio = true;
    full_q += out.log_youngs_modulus_per_compliance * full_E;
  }
  if (estimate_follows_landmarks && fit_motion.per_log_e.squaredNorm() > 0) {
    // Gauss-Newton: d ln E / dy = l_E / |l_E|^2 per landmark coordinate (model frame); what of
    // the estimate's sd the landmarks' noise explains moves with them, the rest (a misfit above
    // the noise) stays an independent source.
    const double sd_from_landmarks = sd_landmark / fit_motion.per_log_e.norm();
    sd_log_e = std::sqrt(std::max(0.0, sd_log_e * sd_log_e - sd_from_landmarks * sd_from_landmarks));
    out.estimate_follows_landmarks = true;
    out.log_sd_from_landmarks = sd_from_landmarks;
    out.log_sd_independent = sd_log_e;
  }
  const Eigen::VectorXd b_E = H.gather(full_E), b_q = H.gather(full_q);
  Eigen::VectorXd b_g[2];
  std::array<Vec3, 2> axes = {Vec3::Zero(), Vec3::Zero()};
  if (gravity) {
    const GravityEnergy g(model.rest, model.material.density, model.gravity);
    axes = gravity_tilt_axes(model.gravity);
    for (int k = 0; k < 2; ++k) {
      const Vec3 dg = axes[k].cross(model.gravity);  // a tilt by d theta about axes[k]
      Eigen::VectorXd full(3 * nv);
      for (int v = 0; v < nv; ++v) full.segment<3>(3 * v) = -g.masses()(v) * dg;
      b_g[k] = H.gather(full);
    }
  }
  // A rigid motion xi = (omega, tau) of the supine data in the model frame moves each held
  // target p by omega x p + tau and turns its normal n by omega x n. With r = x_v - p the held
  // springs' force w_point r + w_plane n (n . r) changes by
  //   -(w_point dp + w_plane n (n . dp)) + w_plane (dn (n . r) + n (dn . r)).
  Eigen::VectorXd b_pose[6];
  if (!free_pose)
    for (int k = 0; k < 6; ++k) {
      Eigen::VectorXd full = Eigen::VectorXd::Zero(3 * nv);
      const Vec3 e = Vec3::Unit(k % 3);
      for (const HeldSkinVertex& h : held) {
        const Vec3 dp = k < 3 ? Vec3(e.cross(h.point)) : e;
        const Vec3 dn = k < 3 ? Vec3(e.cross(h.normal)) : Vec3::Zero();
        const Vec3 r = x.row(h.vertex).transpose() - h.point;
        full.segment<3>(3 * h.vertex) +=
            -(w_point * dp + w_plane * h.normal * h.normal.dot(dp)) + w_plane * (dn * h.normal.dot(r) + h.normal * dn.dot(r));
      }
      b_pose[k] = H.gather(full);
    }
  const Mat3 R_s = model_to_supine.linear();
  // Out to the supine frame: from the model frame with a held pose; with a free one from the
  // projector's frame (model_to_supine = S P, S fixed), the centroid moving with x and with P.
  const Mat3 R_out = free_pose ? Mat3(R_s * free_pose->model_to_projector.linear().transpose()) : R_s;
  const double sd_theta = opt.sources.gravity_direction_deg * M_PI / 180.0;
  for (const auto& mt : model.tumours) {
    const SurfaceMesh s{apply_embedding(mt.embedding, model.rest.T, x), mt.prone.F};
    const Eigen::MatrixXd Jp = volume_centroid_jacobian(s);  // 3 x 3#P, model frame
    Eigen::MatrixXd Jx = Eigen::MatrixXd::Zero(3 * nv, 3);   // (dc/dx)^T
    for (Eigen::Index p = 0; p < s.V.rows(); ++p) {
      const int t = mt.embedding.tet(p);
      for (int k = 0; k < 4; ++k)
        Jx.middleRows<3>(3 * model.rest.T(t, k)) += mt.embedding.weights(p, k) * Jp.middleCols<3>(3 * p).transpose();
    }
    const Vec3 c_m = volume_centroid(s);
    // The output's adjoint: dc_out = L^T dx (+ the pose's direct response to moved targets).
    // Held pose: L = dc/dx. Free pose: d(P c) = Q dc + Jc xi with xi = -M W^T dx + M sum J^T A dy.
    Eigen::MatrixXd L(H.num_free_dofs(), 3);
    for (int k = 0; k < 3; ++k) L.col(k) = H.gather(Jx.col(k));
    Eigen::Matrix<double, 3, 6> Jc = Eigen::Matrix<double, 3, 6>::Zero();
    if (free_pose) {
      Jc = pose_jacobian(P * c_m);
      L = Eigen::MatrixXd(L * Q.transpose()) - low.W * (low.M * Jc.transpose());
    }
    const Eigen::MatrixXd lambda = solve(L);  // free DOFs x 3
    // A target y_j moved by dy (projector frame) with metric A_j: dG = -B_j^T Q^T A_j dy +
    // W M J_j^T A_j dy, and xi moves by M J_j^T A_j dy. Per unit of J_j^T A_j dy the output moves
    // by G_pose = (Jc - lambda^T W) M.
    Eigen::Matrix<double, 3, 6> G_pose = Eigen::Matrix<double, 3, 6>::Zero();
    if (free_pose) G_pose = (Jc - lambda.transpose() * low.W) * low.M;
    TumourUncertainty u;
    u.d_log_youngs_modulus = R_out * Vec3(-lambda.transpose() * b_E);
    u.d_volume_compliance = R_out * Vec3(-lambda.transpose() * b_q);
    const Mat3 cov_q = sd_q * sd_q * u.d_volume_compliance * u.d_volume_compliance.transpose();
    Mat3 cov_g = Mat3::Zero();
    if (gravity)
      for (int k = 0; k < 2; ++k) {
        u.d_gravity_tilt[k] = R_out * Vec3(-lambda.transpose() * b_g[k]);
        cov_g += sd_theta * sd_theta * u.d_gravity_tilt[k] * u.d_gravity_tilt[k].transpose();
      }
    // The output's motion (supine frame) when the target of anchor a's spring moves by `moved`
    // (projector frame), where its metric A gives A moved = weight moved (an isotropic spring, or
    // a held skin spring moved along its normal): the local pull lambda^T B^T Q^T A moved (lambda
    // is the projector frame's adjoint with a free pose) and, with a free pose, the pose's motion
    // (G_pose; zero, and Q, P the identity, with a held one).
    auto target_response = [&](const Anchor& a, double weight, const Vec3& moved) {
      Vec3 local = Vec3::Zero();
      for (int k = 0; k < a.count; ++k) {
        const int f = H.free_index(a.v[k]);
        if (f >= 0) local += a.w[k] * lambda.middleRows<3>(3 * f).transpose() * (Q.transpose() * moved);
      }
      return Vec3(R_out * (weight * (local + G_pose * pose_jacobian(P * a.position(x)).transpose() * moved)));
    };
    // Depth noise: the held target of vertex v moves by delta along n, A n = spring n.
    Mat3 cov_d = Mat3::Zero();
    for (const HeldSkinVertex& h : held) {
      const Vec3 d = target_response(Anchor::vertex(h.vertex), spring, Q * h.normal);
      cov_d += opt.sources.depth_noise * opt.sources.depth_noise * d * d.transpose();
    }
    // The landmarks sharing a free pose, A = w I.
    const double w_landmark = free_pose ? free_pose->landmark_weight : 0.0;
    // A target the step moved onto the scan (landmarks_on_scan) follows its landmark along the
    // surface only, and the scan's depth noise there along the normal.
    const Points* normals = free_pose && free_pose->landmark_normals.rows() > 0 ? &free_pose->landmark_normals : nullptr;
    if (normals)
      for (size_t i = 0; i < pose_anchors.size(); ++i) {
        const Vec3 n = normals->row(static_cast<Eigen::Index>(i)).transpose();
        if (n.squaredNorm() == 0) continue;
        const Vec3 d = target_response(pose_anchors[i], w_landmark, n);
        cov_d += opt.sources.depth_noise * opt.sources.depth_noise * d * d.transpose();
      }
    Mat3 cov_l = Mat3::Zero();
    if (landmarks_source) {
      u.d_landmarks.setZero(3, 3 * static_cast<Eigen::Index>(pose_anchors.size()));
      for (size_t i = 0; i < pose_anchors.size(); ++i) {
        Mat3 follows = Mat3::Identity();
        if (normals) {
          const Vec3 n = normals->row(static_cast<Eigen::Index>(i)).transpose();
          follows -= n * n.transpose();
        }
        for (int d = 0; d < 3; ++d) {
          const Vec3 e = Vec3::Unit(d);
          Vec3 dc = target_response(pose_anchors[i], w_landmark, follows * e);
          if (out.estimate_follows_landmarks)  // d ln E / dy, the fit in the model frame (the landmarks as given)
            dc += fit_motion.per_log_e.segment<3>(3 * static_cast<Eigen::Index>(i)).dot(Q.transpose() * e) /
                  fit_motion.per_log_e.squaredNorm() * u.d_log_youngs_modulus;
          u.d_landmarks.col(3 * static_cast<Eigen::Index>(i) + d) = dc;
          cov_l += sd_landmark * sd_landmark * dc * dc.transpose();
        }
      }
    }
    const Mat3 cov_E = sd_log_e * sd_log_e * u.d_log_youngs_modulus * u.d_log_youngs_modulus.transpose();
    // The rigid pose: the centroid in the model frame moves by dc_m = -lambda^T b, and the moved
    // pose maps it back, c_s = R_s (c_m + dc_m - omega x c_m - tau).
    if (!free_pose)  // (a free pose is not an input: it is solved)
      for (int k = 0; k < 6; ++k) {
        const Vec3 e = Vec3::Unit(k % 3);
        const Vec3 moved_back = k < 3 ? Vec3(e.cross(c_m)) : e;
        u.d_pose.col(k) = R_s * (Vec3(-lambda.transpose() * b_pose[k]) - moved_back);
      }
    const Mat3 cov_p = pose_covariance ? Mat3(u.d_pose * *pose_covariance * u.d_pose.transpose()) : Mat3::Zero();
    u.covariance = cov_E + cov_q + cov_g + cov_d + cov_p + cov_l;
    u.sources = {{"youngs_modulus", cov_E}, {"poisson_ratio", cov_q}, {"gravity_direction", cov_g}, {"depth_noise", cov_d}};
    if (pose_covariance) u.sources.emplace_back("rigid_pose", cov_p);
    if (landmarks_source) u.sources.emplace_back("landmarks", cov_l);
    u.radius_95 = radius_95(u.covariance);
    out.tumours.push_back(u);
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace btr
