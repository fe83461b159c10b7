#include "breast_tumour_registration/registration/tumour_uncertainty.h"

#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/blas_threads.h"
#include "breast_tumour_registration/fem/heap_retention.h"
#include "breast_tumour_registration/fem/gmres.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/hessian_pattern.h"
#include "breast_tumour_registration/fem/spring_energy.h"
#include "breast_tumour_registration/fem/total_energy.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/geometry/metrics.h"

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

using Llt = Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;

/// Factorizes the Hessian of `energy` at x into llt: the exact one, or, when it is not positive
/// definite there, the projected one (returns true then). Throws SolverError naming `what` when
/// neither factorizes.
bool factorize_exact_or_projected(const TotalEnergy& energy, const Points& x, HessianAssembler& H, Llt& llt,
                                  const std::string& what) {
  llt.cholmod().print = 0;
  energy.hessian(x, false, H);
  llt.compute(H.matrix());
  if (llt.info() == Eigen::Success) return false;
  energy.hessian(x, true, H);
  llt.compute(H.matrix());
  if (llt.info() != Eigen::Success) throw SolverError("uncertainty: " + what + " cannot be factorized");
  return true;
}

/// The model's materials with every tissue's Poisson's ratio set to `nu`, each keeping its
/// Young's modulus (as set_poisson_ratio does).
std::vector<StableNeoHookean> materials_at(const RegistrationModel& m, double nu) {
  std::vector<StableNeoHookean> out;
  for (const auto& mat : m.materials) out.emplace_back(mat.youngs_modulus(), nu);
  return out;
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
  auto nu_of = [](double q) { return 1.0 / (2.0 * (1.0 + q)); };
  return (body_gradient(m, m.rest.V, materials_at(m, nu_of(q0 + h)), x, Vec3::Zero()) -
          body_gradient(m, m.rest.V, materials_at(m, nu_of(q0 - h)), x, Vec3::Zero())) /
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
struct RestResponse {
  std::vector<Eigen::VectorXd> dX;  ///< per input, every vertex (zero on the chest wall)
  int iterations = 0;               ///< products with D_X G_p, over the inputs
  double worst_residual = 0;        ///< the largest relative residual
  bool converged = true;
};

RestResponse rest_shape_response(const RegistrationModel& m, const TotalEnergy& elastic,
                                 const std::vector<Eigen::VectorXd>& dGp_dp) {
  const int nv = static_cast<int>(m.rest.V.rows());
  HessianAssembler Hp(nv, m.rest.T, m.fixed, elastic.hessian_cliques());
  Llt llt;  // only the preconditioner: the projected one serves too
  factorize_exact_or_projected(elastic, m.prone, Hp, llt, "the prone Hessian");
  auto scatter = [&](const Eigen::VectorXd& reduced) {
    Eigen::VectorXd full = Eigen::VectorXd::Zero(3 * nv);
    Hp.scatter_add(reduced, 1.0, full);
    return full;
  };
  auto apply_A = [&](const Eigen::VectorXd& v) {
    return Eigen::VectorXd(Hp.gather(gradient_d_rest(m, m.prone, scatter(v), m.unloaded_under)));
  };
  auto apply_Minv = [&](const Eigen::VectorXd& r) { return Eigen::VectorXd(-llt.solve(r)); };
  RestResponse out;
  for (const Eigen::VectorXd& b : dGp_dp) {
    Eigen::VectorXd y;
    const GmresResult g = gmres(apply_A, apply_Minv, Eigen::VectorXd(-Hp.gather(b)), 1e-6, 60, y);
    out.iterations += g.iterations;
    out.worst_residual = std::max(out.worst_residual, g.relative_residual);
    out.converged = out.converged && g.converged;
    out.dX.push_back(scatter(y));
  }
  return out;
}

/// The unloaded rest shape's response to ln E and (with_q) to q: the prone gradient's partials
/// at the imaged shape (dG_p/d ln E = G_elastic there), the q column zero without q.
RestResponse rest_response_to_material(const RegistrationModel& m, const TotalEnergy& elastic, bool with_q) {
  return rest_shape_response(m, elastic,
                             {elastic.gradient(m.prone), with_q ? elastic_gradient_d_compliance(m, m.prone)
                                                                : Eigen::VectorXd::Zero(3 * m.rest.V.rows())});
}

bool fit_usable(const LandmarkStiffnessFit& fit, int nv) {
  return fit.anchors.size() >= 3 && fit.supine_prediction.rows() == nv && fit.supine_prediction.allFinite();
}

/// d ln E / d q of the stiffness step's landmark fit (LandmarkStiffnessFit): the supine
/// gravity-only prediction's response to ln E and to q (the rest shape's part included: dX_rest,
/// empty when the rest shape is the prone one), its landmarks' motion, the part of it no rigid
/// motion of the landmarks explains (the fit re-fits the pose: Kabsch), and the Gauss-Newton
/// step of ln E that fits them again.
double per_compliance(const RegistrationModel& m, const TotalEnergy& elastic, const LandmarkStiffnessFit& fit,
                      const std::vector<Eigen::VectorXd>& dX_rest) {
  const int nv = static_cast<int>(m.rest.V.rows());
  const Points& xg = fit.supine_prediction;
  HessianAssembler Hg(nv, m.rest.T, m.fixed, elastic.hessian_cliques());
  Llt llt;
  factorize_exact_or_projected(elastic, xg, Hg, llt, "the stiffness prediction's Hessian");
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
  Eigen::VectorXd l_E = landmark_motion(elastic.gradient(xg), 0);
  Eigen::VectorXd l_q = landmark_motion(elastic_gradient_d_compliance(m, xg), 1);
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
  l_E -= Q * (Q.transpose() * l_E);
  l_q -= Q * (Q.transpose() * l_q);
  if (!(l_E.squaredNorm() > 0)) return 0;
  return -l_E.dot(l_q) / l_E.squaredNorm();
}

}  // namespace

double volume_compliance(double nu) { return (1.0 - 2.0 * nu) / (2.0 * nu); }

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
  return per_compliance(model, elastic, fit, dX_rest);
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
                                                const LandmarkStiffnessFit* stiffness_fit) {
  std::vector<HeldSkinVertex> held;
  const Mat3 R_p = model_to_projector.linear();
  const Rigid to_model = model_to_projector.inverse();
  for (int v : model.skin) {
    const Projection c = supine.project(model_to_projector * Vec3(x.row(v).transpose()));
    if (!holds_projection(c, surface)) continue;
    held.push_back({v, to_model * c.point, (R_p.transpose() * c.normal).normalized()});
  }
  return linearised_tumour_uncertainty(model, x, held, model_to_supine, surface, opt, pose_covariance, stiffness_fit);
}

UncertaintyResult linearised_tumour_uncertainty(const RegistrationModel& model, const Points& x,
                                                const std::vector<HeldSkinVertex>& held, const Rigid& model_to_supine,
                                                const SurfaceStepOptions& surface, const UncertaintyOptions& opt,
                                                const std::optional<Mat6>& pose_covariance,
                                                const LandmarkStiffnessFit* stiffness_fit) {
  validate_uncertainty_options(opt);
  const auto t0 = std::chrono::steady_clock::now();
  UncertaintyResult out;
  const int nv = static_cast<int>(x.rows());

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
  auto springs = std::make_shared<SpringEnergy>("held skin");
  for (const HeldSkinVertex& h : held)
    springs->add_point_and_plane(Anchor::vertex(h.vertex), h.point, h.normal, w_point, w_plane);
  if (held.empty()) throw InputError("uncertainty: no skin vertex is held by the supine surface");
  TotalEnergy jac;
  for (const auto& t : elastic.terms()) jac.add(t);
  jac.add(springs);
  HessianAssembler H(nv, model.rest.T, model.fixed, jac.hessian_cliques());
  use_single_threaded_blas();
  keep_freed_heap_memory();
  Llt llt;
  // An element compressed past its stable range makes the exact Hessian indefinite there; the
  // projected one is a bound on the stiffness, so the spread it gives is a lower bound.
  if (factorize_exact_or_projected(jac, x, H, llt, "the fixed point's Jacobian"))
    out.note = "the exact Hessian is not positive definite at the result; linearised on the projected one (a lower bound)";

  // Inputs' dG/dp on the free DOFs. G_elastic is linear in E: dG/d ln E = G_elastic. Poisson's
  // ratio enters through the volume compliance q = (1 - 2 nu) / (2 nu), in which the response
  // is near linear (the volume stiffness is ~ mu / q), unlike in nu itself near 0.5.
  const double sd_log_e = !opt.sources.samples_youngs_modulus() ? 0.0
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
    const RestResponse rr = rest_response_to_material(model, elastic, sd_q > 0);
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
  // E estimated from the landmarks follows a true nu other than the method's.
  if (stiffness_fit && sd_q > 0 && fit_usable(*stiffness_fit, nv)) {
    out.log_youngs_modulus_per_compliance = per_compliance(model, elastic, *stiffness_fit, dX_rest);
    out.estimate_follows_poisson_ratio = true;
    full_q += out.log_youngs_modulus_per_compliance * full_E;
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
    Eigen::MatrixXd R(H.num_free_dofs(), 3);
    for (int k = 0; k < 3; ++k) R.col(k) = H.gather(Jx.col(k));
    const Eigen::MatrixXd lambda = llt.solve(R);  // free DOFs x 3
    TumourUncertainty u;
    u.d_log_youngs_modulus = R_s * Vec3(-lambda.transpose() * b_E);
    const Mat3 cov_E = sd_log_e * sd_log_e * u.d_log_youngs_modulus * u.d_log_youngs_modulus.transpose();
    u.d_volume_compliance = R_s * Vec3(-lambda.transpose() * b_q);
    const Mat3 cov_q = sd_q * sd_q * u.d_volume_compliance * u.d_volume_compliance.transpose();
    Mat3 cov_g = Mat3::Zero();
    if (gravity)
      for (int k = 0; k < 2; ++k) {
        u.d_gravity_tilt[k] = R_s * Vec3(-lambda.transpose() * b_g[k]);
        cov_g += sd_theta * sd_theta * u.d_gravity_tilt[k] * u.d_gravity_tilt[k].transpose();
      }
    // Depth noise: the held target of vertex v moves by delta along n, dG_v/d delta = -spring n.
    Mat3 cov_d = Mat3::Zero();
    for (const HeldSkinVertex& h : held) {
      const int f = H.free_index(h.vertex);
      if (f < 0) continue;
      const Vec3 d = R_s * Vec3(spring * lambda.middleRows<3>(3 * f).transpose() * h.normal);
      cov_d += opt.sources.depth_noise * opt.sources.depth_noise * d * d.transpose();
    }
    // The rigid pose: the centroid in the model frame moves by dc_m = -lambda^T b, and the moved
    // pose maps it back, c_s = R_s (c_m + dc_m - omega x c_m - tau).
    const Vec3 c_m = volume_centroid(s);
    for (int k = 0; k < 6; ++k) {
      const Vec3 e = Vec3::Unit(k % 3);
      const Vec3 moved_back = k < 3 ? Vec3(e.cross(c_m)) : e;
      u.d_pose.col(k) = R_s * (Vec3(-lambda.transpose() * b_pose[k]) - moved_back);
    }
    const Mat3 cov_p = pose_covariance ? Mat3(u.d_pose * *pose_covariance * u.d_pose.transpose()) : Mat3::Zero();
    u.covariance = cov_E + cov_q + cov_g + cov_d + cov_p;
    u.sources = {{"youngs_modulus", cov_E}, {"poisson_ratio", cov_q}, {"gravity_direction", cov_g}, {"depth_noise", cov_d}};
    if (pose_covariance) u.sources.emplace_back("rigid_pose", cov_p);
    u.radius_95 = radius_95(u.covariance);
    out.tumours.push_back(u);
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace btr
