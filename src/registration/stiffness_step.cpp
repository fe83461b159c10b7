#include "breast_tumour_registration/registration/stiffness_step.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/fem/forward_gravity.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"
#include "breast_tumour_registration/geometry/rigid_transform.h"
#include "breast_tumour_registration/registration/step_solvers.h"
#include "breast_tumour_registration/registration/stiffness_grid_walk.h"
#include "breast_tumour_registration/registration/unload_step.h"

namespace btr {
namespace {
std::string pascal(double e) {
  char b[48];
  std::snprintf(b, sizeof b, "%.0f Pa", e);
  return b;
}
double sq(double v) { return v * v; }

// |dr/du| at u0 from the residuals evaluated nearest it on each side (the three-point
// derivative on uneven spacing; one-sided where the estimate has candidates on one side only).
// 0 where no other candidate was simulated.
double residual_slope(const std::vector<std::pair<double, Eigen::VectorXd>>& residuals, double u0) {
  const Eigen::VectorXd* r0 = nullptr;
  const std::pair<double, Eigen::VectorXd>*left = nullptr, *right = nullptr;
  for (const auto& e : residuals) {
    const double d = e.first - u0;
    if (std::abs(d) < 1e-12) r0 = &e.second;
    else if (d < 0 && (!left || e.first > left->first)) left = &e;
    else if (d > 0 && (!right || e.first < right->first)) right = &e;
  }
  if (!r0) return 0;
  if (left && right) {
    const double hl = u0 - left->first, hr = right->first - u0;
    return ((hl * hl * (right->second - *r0) + hr * hr * (*r0 - left->second)) / (hl * hr * (hl + hr))).norm();
  }
  const auto* one = left ? left : right;
  return one ? ((one->second - *r0) / (one->first - u0)).norm() : 0;
}
}  // namespace

double StiffnessEstimate::log_sd(double landmark_sd) const {
  if (!(landmark_sensitivity > 0) || at_bound || landmarks < 3) return 0;
  // Gauss-Newton: var(ln E) = sigma^2 / |dr/d ln E|^2. sigma: the landmarks' own sd, or the
  // misfit per residual degree of freedom (3n coordinates less the rigid fit's 6 and E) where
  // that is larger: the model does not fit the landmarks as well as their noise would let it.
  const double dof = 3.0 * landmarks - 7.0;
  const double sigma2 = std::max(landmark_sd * landmark_sd, landmarks * misfit * misfit / dof);
  return std::sqrt(sigma2) / landmark_sensitivity;
}

void scale_stiffness(RegistrationModel& model, double scale) {
  if (!(scale > 0) || !std::isfinite(scale)) throw InputError("stiffness: the scale must be positive");
  // lambda() is the SNH volume stiffness lambda_L + mu; from_lame takes the classical lambda_L.
  for (auto& m : model.materials) m = StableNeoHookean::from_lame(m.mu() * scale, (m.lambda() - m.mu()) * scale);
  model.material.youngs_modulus *= scale;
}

void set_poisson_ratio(RegistrationModel& model, double nu) {
  if (!(nu >= 0 && nu < 0.5)) throw InputError("Poisson's ratio must be in [0, 0.5), got " + std::to_string(nu));
  for (auto& m : model.materials) m = StableNeoHookean(m.youngs_modulus(), nu);
  model.material.poisson_ratio = nu;
}

StiffnessEstimate estimate_stiffness(const RegistrationModel& model, const Vec3& prone_gravity,
                                     const std::vector<Anchor>& anchors, const Points& supine,
                                     const StiffnessOptions& opt, StepSolvers* cache) {
  const auto t0 = std::chrono::steady_clock::now();
  if (anchors.size() < 3 || supine.rows() != static_cast<Eigen::Index>(anchors.size()))
    throw InputError("stiffness: estimating the Young's modulus needs >= 3 landmark pairs, got " +
                     std::to_string(std::min<size_t>(anchors.size(), static_cast<size_t>(supine.rows()))));
  const double E0 = model.material.youngs_modulus;
  const TetMesh prone{model.prone, model.rest.T};
  StiffnessEstimate est;
  NewtonSolver* shared = cache ? &cache->gravity(model) : nullptr;
  if (!(opt.candidate_tolerance > 0) || !std::isfinite(opt.candidate_tolerance))
    throw InputError("stiffness: the candidates' unload tolerance must be positive");
  if (!(opt.candidate_budget_factor >= 0) || opt.min_candidate_forward_solves < 1)
    throw InputError("stiffness: the candidates' forward-solve budget needs a factor >= 0 and a minimum >= 1");
  UnloadOptions candidate_unload = opt.unload;
  candidate_unload.tolerance = std::max(opt.unload.tolerance, opt.candidate_tolerance);
  int most_forward_solves = 0;  // by a candidate that was simulated: the budget's scale

  // Every converged candidate's (log E, unloaded shape): the next one starts from the two
  // nearest it in log E (interpolated between them when it lies between, else extrapolated),
  // which saves most of the cost of a soft candidate and of the refinement's.
  std::vector<std::pair<double, Points>> known;
  // Every simulated candidate's log E and supine displacement: the next candidate's supine
  // solve starts from the nearest one's, scaled by the stiffness ratio (in the linear range
  // displacement goes as 1/E), rather than from rest (a start that inverts an element falls
  // back to rest).
  std::vector<std::pair<double, Points>> supine_displacements;
  // The entry of `list` nearest to u in log E, and the second nearest (null when absent).
  auto nearest_two = [](const std::vector<std::pair<double, Points>>& list, double u) {
    const std::pair<double, Points>*a = nullptr, *b = nullptr;
    for (const auto& e : list) {
      if (!a || std::abs(e.first - u) < std::abs(a->first - u)) {
        b = a;
        a = &e;
      } else if (!b || std::abs(e.first - u) < std::abs(b->first - u)) {
        b = &e;
      }
    }
    return std::make_pair(a, b);
  };
  struct Candidate {
    double misfit = std::numeric_limits<double>::infinity();
    Points rest;
    UnloadResult unload;
    Points supine;  ///< its gravity-only supine equilibrium
  };
  // Every simulated candidate's log E and Kabsch-fitted landmark residual (3n): the residual's
  // slope at the estimate says how well the landmarks fix E (StiffnessEstimate::log_sd).
  std::vector<std::pair<double, Eigen::VectorXd>> residuals;
  auto evaluate = [&](double E) {
    const auto tc = std::chrono::steady_clock::now();
    Candidate c;
    StiffnessCandidate record;
    record.youngs_modulus = E;
    UnloadOptions uo = candidate_unload;
    if (opt.candidate_budget_factor > 0)
      uo.max_forward_solves = std::max(opt.min_candidate_forward_solves,
                                       static_cast<int>(std::ceil(opt.candidate_budget_factor * most_forward_solves)));
    // Every return: the record, its cost, and the budget's scale where it was simulated.
    auto done = [&](std::string failure) {
      record.misfit = c.misfit;
      record.failure = std::move(failure);
      record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
      if (record.failure.empty()) most_forward_solves = std::max(most_forward_solves, record.forward_solves);
      est.evaluations.push_back(record);
      return std::move(c);
    };
    const double k = E / E0;  // the material scaled by k == the gravities divided by k
    UnloadProblem pb = unload_problem(model, prone, prone_gravity / k);
    pb.solver = shared;
    const double u = std::log(E);
    Points guess;
    const auto [n1, n0] = nearest_two(known, u);
    if (n1 && n0) {
      const auto& [u1, X1] = *n1;
      const auto& [u0, X0] = *n0;
      guess = X1 + ((u - u1) / (u1 - u0)) * (X1 - X0);
      if (count_inverted(guess, model.rest.T) > 0) guess = X1;
      pb.initial_rest = &guess;
    } else if (n1) {
      guess = n1->second;
      pb.initial_rest = &guess;
    }
    c.unload = estimate_unloaded_shape(pb, uo);
    record.forward_solves = c.unload.iterations;
    // The extrapolation misled it: from inverse gravity, on what is left of the budget.
    if (pb.initial_rest && !c.unload.converged && (uo.max_forward_solves == 0 || record.forward_solves < uo.max_forward_solves)) {
      pb.initial_rest = nullptr;
      if (uo.max_forward_solves > 0) uo.max_forward_solves -= record.forward_solves;
      UnloadResult fresh = estimate_unloaded_shape(pb, uo);
      record.forward_solves += fresh.iterations;
      if (fresh.max_mismatch < c.unload.max_mismatch) c.unload = std::move(fresh);
    }
    if (c.unload.converged) known.emplace_back(u, c.unload.rest);
    // A candidate whose unloaded shape does not reproduce the prone shape is not a candidate.
    if (!(c.unload.max_mismatch < std::max({10 * opt.unload.tolerance, opt.unload.stage_tolerance, candidate_unload.tolerance})))
      return done("unload: " + c.unload.stop_reason);
    c.rest = c.unload.rest;
    ForwardGravity phi(model.rest.T, model.prone.rows(), model.chest_wall, model.materials, model.material_of,
                       model.volume_form, model.material.nodal_element_share, model.material.density,
                       opt.unload.forward, shared);
    Points x = c.rest;
    if (const auto* near = nearest_two(supine_displacements, u).first) {
      x = c.rest + std::exp(near->first - u) * near->second;
      if (count_inverted(x, model.rest.T) > 0) x = c.rest;
    }
    ++record.forward_solves;
    try {
      phi.solve(c.rest, model.gravity / k, x);
    } catch (const SolverError& e) {
      return done(std::string("supine solve: ") + e.what());
    }
    supine_displacements.emplace_back(u, x - c.rest);
    c.supine = x;
    Points predicted(static_cast<Eigen::Index>(anchors.size()), 3);
    for (size_t i = 0; i < anchors.size(); ++i) predicted.row(static_cast<Eigen::Index>(i)) = anchors[i].position(x).transpose();
    const Rigid T = kabsch(supine, predicted);
    const Points fitted = transform_points(T, supine);
    const Points r = fitted - predicted;
    c.misfit = std::sqrt(r.rowwise().squaredNorm().mean());
    residuals.emplace_back(u, Eigen::Map<const Eigen::VectorXd>(r.data(), r.size()));
    return done("");
  };

  // The grid walk (stiffness_grid_walk.h): the candidates before the refinement, stiff to soft.
  const double lo = std::log(opt.min_youngs_modulus), hi = std::log(opt.max_youngs_modulus);
  std::vector<Candidate> grid;
  const StiffnessGridWalk walk = walk_stiffness_grid(opt.min_youngs_modulus, opt.max_youngs_modulus, opt.grid_points, [&](double u) {
    grid.push_back(evaluate(std::exp(u)));
    return grid.back().misfit;
  });
  const std::vector<double>& grid_u = walk.log_youngs_modulus;
  const int best = walk.best;
  if (best < 0 || !std::isfinite(grid[best].misfit))
    throw SolverError("stiffness: no candidate Young's modulus from " + pascal(opt.min_youngs_modulus) + " to " +
                      pascal(opt.max_youngs_modulus) + " could be unloaded and simulated");
  double u_best = grid_u[best];
  Candidate c_best = grid[best];
  const int n = static_cast<int>(grid.size());
  est.at_bound = (best == 0 && grid_u[0] >= hi - 1e-12) || (best == n - 1 && grid_u[n - 1] <= lo + 1e-12);
  // At an end of the range: the point halfway (in log E) to its neighbour tells a minimum
  // just inside from one beyond the end.
  std::array<std::pair<double, double>, 3> bracket;  // (u, misfit) of three points, u ascending (not at a bound)
  if (est.at_bound && n >= 2) {
    const int nb = best == 0 ? 1 : n - 2;
    const double um = 0.5 * (grid_u[best] + grid_u[nb]);
    Candidate c = evaluate(std::exp(um));
    if (c.misfit < grid[best].misfit) {
      est.at_bound = false;
      bracket = {{{grid_u[best], grid[best].misfit}, {um, c.misfit}, {grid_u[nb], grid[nb].misfit}}};
      u_best = um;
      c_best = std::move(c);
    }
  } else if (!est.at_bound) {
    bracket = {{{grid_u[best + 1], grid[best + 1].misfit}, {grid_u[best], grid[best].misfit},
                {grid_u[best - 1], grid[best - 1].misfit}}};
  }
  // A bracket end that could not be simulated moves halfway towards the best point
  // (close_stiffness_bracket), which may become the best.
  if (!est.at_bound) {
    std::sort(bracket.begin(), bracket.end());
    std::vector<std::pair<double, Candidate>> halfway;
    close_stiffness_bracket(bracket, opt.max_end_halvings, [&](double u) {
      halfway.emplace_back(u, evaluate(std::exp(u)));
      return halfway.back().second.misfit;
    });
    for (auto& [u, c] : halfway)
      if (u == bracket[1].first) {
        u_best = u;
        c_best = std::move(c);
      }
  }
  if (est.at_bound) {
    est.stop_reason = "the best misfit is at the end of the range (" + pascal(std::exp(u_best)) +
                      "): the estimate is a bound; widen the range";
  } else {  // the grid stops only after a minimum, and its soft end is lo: best has both neighbours
    // Parabolic refinement in log E through the best point and its neighbours (grid order is
    // stiff -> soft, so u decreases with the index).
    double ua = bracket[0].first, ub = bracket[1].first, uc = bracket[2].first;
    // On the squared misfit: near an exact fit the misfit grows like |log E - log E*|, its
    // square like a parabola.
    double fa = sq(bracket[0].second), fb = sq(bracket[1].second), fc = sq(bracket[2].second);
    est.stop_reason = "refinement cap (" + std::to_string(opt.max_refinements) + ") reached";
    for (int it = 0; it < opt.max_refinements; ++it) {
      if (!std::isfinite(fa) || !std::isfinite(fc)) {
        est.stop_reason = "a neighbour of the best candidate could not be simulated; the grid point is kept";
        break;
      }
      const double num = (ub - ua) * (ub - ua) * (fb - fc) - (ub - uc) * (ub - uc) * (fb - fa);
      const double den = (ub - ua) * (fb - fc) - (ub - uc) * (fb - fa);
      double u = den != 0 ? ub - 0.5 * num / den : ub;
      u = std::clamp(u, ua + 0.05 * (uc - ua), uc - 0.05 * (uc - ua));  // strictly inside the bracket
      if (std::abs(u - ub) < std::log1p(opt.relative_tolerance)) {
        est.converged = true;
        est.stop_reason = "the refinement moved E by less than " + std::to_string(static_cast<int>(std::lround(opt.relative_tolerance * 100))) + " %";
        break;
      }
      Candidate c = evaluate(std::exp(u));
      const double fu = sq(c.misfit);
      if (fu < fb) {  // u becomes the middle point
        if (u < ub) { uc = ub; fc = fb; } else { ua = ub; fa = fb; }
        ub = u;
        fb = fu;
        c_best = std::move(c);
        u_best = u;
      } else {  // u narrows the bracket
        if (u < ub) { ua = u; fa = fu; } else { uc = u; fc = fu; }
      }
    }
  }
  est.youngs_modulus = std::exp(u_best);
  est.scale = est.youngs_modulus / E0;
  // A candidate is accepted once its unloaded shape reproduces the prone shape within
  // candidate_tolerance; the chosen one is finished from there to unload.tolerance, so that the
  // unload step's "converged" means the unload's own criterion held.
  if (!c_best.unload.converged || c_best.unload.max_mismatch > opt.unload.tolerance) {
    UnloadProblem pb = unload_problem(model, prone, prone_gravity / est.scale);
    pb.solver = shared;
    pb.initial_rest = &c_best.rest;
    UnloadResult polished = estimate_unloaded_shape(pb, opt.unload);
    if (polished.converged || polished.max_mismatch < c_best.unload.max_mismatch) {
      polished.seconds += c_best.unload.seconds;
      c_best.unload = std::move(polished);
      c_best.rest = c_best.unload.rest;
    }
    if (c_best.unload.max_mismatch > opt.unload.tolerance && c_best.unload.converged) {  // met only the candidates' bound
      c_best.unload.converged = false;
      char b[160];
      std::snprintf(b, sizeof b, "re-simulating reproduces the prone shape within %.3g mm, not %.3g mm: finishing the chosen candidate did not get there",
                    c_best.unload.max_mismatch * 1e3, opt.unload.tolerance * 1e3);
      c_best.unload.stop_reason = b;
    }
  }
  // The candidates are compared with linear elements. Where the model unloads with quadratic
  // ones (MaterialParameters::unload_element_order), the chosen E's unloaded shape is found again
  // with them, from the linear one: on SfePy's second body at fat 1000 Pa a search with quadratic
  // candidates chose 972 Pa where the linear one chose 968, at 25 times the time (BENCHMARKS.md,
  // "A quadratic forward model for the unload").
  refine_with_model_elements(model, prone, prone_gravity / est.scale, opt.unload, c_best.unload);
  c_best.rest = c_best.unload.rest;
  est.misfit = c_best.misfit;
  est.landmarks = static_cast<int>(anchors.size());
  est.landmark_sensitivity = residual_slope(residuals, u_best);
  est.rest = c_best.rest;
  est.supine_prediction = c_best.supine;
  est.unload = c_best.unload;
  est.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return est;
}

}  // namespace btr
