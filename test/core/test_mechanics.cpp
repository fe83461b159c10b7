// Closed-form checks of the FEM against small-strain elasticity.
#include <memory>

#include "breast_tumour_registration/fem/gravity_simulation.h"
#include "breast_tumour_registration/geometry/box_mesh.h"
#include "test_util.h"

using namespace btr;

namespace {

struct Sag {
  double fem, exact;
};

// Cantilever of length L, square section h, clamped at x = 0, sagging under its own weight
// (g along -z). Timoshenko beam: delta = q L^4 / (8 E I) + q L^2 / (2 kappa G A).
Sag cantilever_tip_sag(int n_long, int n_section, double nu = 0.0, VolumeForm form = VolumeForm::Auto,
                       double nodal_element_share = 0) {
  const double L = 0.2, h = 0.02, E = 1e8, rho = 1000, g = 9.81;
  const TetMesh m = make_box_tet_mesh(n_long, n_section, n_section, Vec3(L, h, h), Vec3(0, -h / 2, -h / 2));
  GravityProblem pb;
  pb.rest = &m;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 0) == 0.0) pb.fixed.push_back(static_cast<int>(i));
  pb.youngs_modulus = E;
  pb.poisson_ratio = nu;
  pb.density = rho;
  pb.gravity = Vec3(0, 0, -g);
  pb.volume_form = form;
  pb.nodal_element_share = nodal_element_share;
  NewtonOptions opt;
  opt.gradient_rel_tolerance = 1e-10;
  // The sags are wanted to 1e-4 of themselves (0.1 to 0.6 mm): steps of 10 nm are below that.
  // At the default 1 nm the nodal form with an element share of 5 mu at nu = 0.49 halved a
  // 1.8 nm step, which the solver rightly calls a stall; the other solves here end on a full
  // step below the tolerance.
  opt.step_tolerance = 1e-8;
  const GravityResult r = solve_gravity(pb, opt);
  EXPECT_TRUE(r.newton.converged) << "nu " << nu << ", " << to_string(form) << " form: " << to_string(r.newton.reason)
                                  << " at |g| " << r.newton.gradient_norm << " of " << r.newton.initial_gradient_norm
                                  << " after " << r.newton.iterations << " iterations";
  double sum = 0;
  int n = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (std::abs(m.V(i, 0) - L) < 1e-12) {
      sum += r.x(i, 2) - m.V(i, 2);
      ++n;
    }
  const double A = h * h, I = h * h * h * h / 12.0, q = rho * g * A, G = E / (2 * (1 + nu));
  return {-sum / n, q * L * L * L * L / (8 * E * I) + q * L * L / (2 * (5.0 / 6.0) * G * A)};
}

}  // namespace

TEST(Mechanics, CantileverSagConvergesToBeamTheoryUnderRefinement) {
  // Linear tetrahedra are stiff in bending (locking); the error must shrink with h.
  double previous = 1e9;
  for (const auto& [nl, ns] : std::vector<std::pair<int, int>>{{10, 1}, {20, 2}, {40, 4}, {80, 8}}) {
    const Sag s = cantilever_tip_sag(nl, ns);
    const double err = std::abs(s.fem - s.exact) / s.exact;
    RecordProperty("cantilever_" + std::to_string(nl), std::to_string(err));
    std::printf("cantilever %dx%dx%d: FEM %.4f mm, beam theory %.4f mm, error %.1f%%\n", nl, ns, ns, s.fem * 1e3,
                s.exact * 1e3, 100 * err);
    EXPECT_LT(err, previous);
    EXPECT_LT(s.fem, s.exact * 1.02);  // locking makes linear tets too stiff, never softer
    previous = err;
  }
  EXPECT_LT(previous, 0.07);
}

// Issue 11: near incompressibility. Beam theory's bending sag depends on E alone (and on nu
// only through the small shear term), so a cantilever at nu -> 0.5 must sag about as much as
// at nu = 0. Linear tetrahedra with the element volume term lock (every element keeps its
// volume) and barely bend; the nodal-averaged volume term does not. With an element share
// (material.nodal_element_share, 5 mu per tetrahedron) this thin beam (4 elements through its
// height) is stiffer by a bounded amount that does not grow as nu -> 0.5, where a fixed
// fraction of lambda would lock.
TEST(Mechanics, NearIncompressibleCantileverDoesNotLockWithTheNodalVolumeTerm) {
  // On this mesh linear tetrahedra are too stiff in bending even at nu = 0 (17.5 %, the test
  // above); near incompressibility may add little to that.
  const Sag compressible = cantilever_tip_sag(40, 4, 0.0, VolumeForm::Element);
  const double e0 = std::abs(compressible.fem - compressible.exact) / compressible.exact;
  double shared_first = -1, shared_last = -1;
  for (const double nu : {0.45, 0.49, 0.499, 0.4999}) {
    const Sag element = cantilever_tip_sag(40, 4, nu, VolumeForm::Element);
    const Sag nodal = cantilever_tip_sag(40, 4, nu, VolumeForm::Nodal);
    const Sag shared = cantilever_tip_sag(40, 4, nu, VolumeForm::Nodal, 5);
    const double e_el = std::abs(element.fem - element.exact) / element.exact;
    const double e_no = std::abs(nodal.fem - nodal.exact) / nodal.exact;
    const double e_sh = std::abs(shared.fem - shared.exact) / shared.exact;
    std::printf("cantilever 40x4x4, nu %.4f: beam theory %.4f mm; element form %.4f mm (%.1f%%), nodal form %.4f mm "
                "(%.1f%%), with a share of 5 mu %.4f mm (%.1f%%)\n",
                nu, nodal.exact * 1e3, element.fem * 1e3, 100 * e_el, nodal.fem * 1e3, 100 * e_no, shared.fem * 1e3,
                100 * e_sh);
    EXPECT_LT(e_no, e0 + 0.05) << "nu " << nu;
    EXPECT_LT(e_no, e_el) << "nu " << nu;
    EXPECT_GT(e_sh, e_no) << "nu " << nu;  // the share stiffens
    EXPECT_LT(e_sh, e_el) << "nu " << nu;
    if (shared_first < 0) shared_first = e_sh;
    shared_last = e_sh;
  }
  // The element form's locking grows without bound as nu -> 0.5; the share's error grows by a
  // few percent from nu = 0.45 to 0.4999.
  EXPECT_LT(shared_last - shared_first, 0.1);
  const Sag locked = cantilever_tip_sag(40, 4, 0.4999, VolumeForm::Element);
  EXPECT_LT(locked.fem, 0.5 * locked.exact);
}

namespace {

// Column hanging from z = 0 with nu = 0 (no lateral contraction): u_z(d) = rho g (L d - d^2/2) / E
// at depth d. Returns the largest nodal error relative to the tip displacement.
double hanging_column_error(int n_section, int n_depth) {
  const double L = 0.1, a = 0.02, E = 1e7, rho = 1000, g = 9.81;
  const TetMesh m = make_box_tet_mesh(n_section, n_section, n_depth, Vec3(a, a, L), Vec3(0, 0, -L));
  GravityProblem pb;
  pb.rest = &m;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 2) == 0.0) pb.fixed.push_back(static_cast<int>(i));
  pb.youngs_modulus = E;
  pb.poisson_ratio = 0.0;
  pb.density = rho;
  pb.gravity = Vec3(0, 0, -g);
  NewtonOptions opt;
  opt.gradient_rel_tolerance = 1e-12;
  const GravityResult r = solve_gravity(pb, opt);
  EXPECT_TRUE(r.newton.converged);
  const double tip = rho * g * L * L / (2 * E);
  double worst = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    const double d = -m.V(i, 2);
    const double exact = rho * g * (L * d - d * d / 2) / E;
    worst = std::max(worst, std::abs(-(r.x(i, 2) - m.V(i, 2)) - exact) / tip);
  }
  return worst;
}

}  // namespace

TEST(Mechanics, HangingColumnConvergesToTheUniaxialSelfWeightSolution) {
  const double coarse = hanging_column_error(2, 10), fine = hanging_column_error(4, 20);
  std::printf("hanging column: max nodal error %.2f%% (h = 10 mm), %.2f%% (h = 5 mm) of the tip displacement\n",
              100 * coarse, 100 * fine);
  EXPECT_LT(coarse, 0.05);
  EXPECT_LT(fine, 0.5 * coarse);  // second order in h would give 0.25
}

namespace {

// Issue 13: per-element materials. The same column in two materials: E_top above depth L/2,
// E_bottom below (nu = 0 in both). The stress at depth d is still the weight below,
// rho g (L - d), so the exact displacement integrates it over the local compliance:
// u(d) = rho g (L s - s^2/2) / E_top for s = min(d, L/2), plus rho g [(L d - d^2/2) - 3 L^2/8] / E_bottom below L/2.
struct TwoMaterialColumn {
  double worst_error;   ///< largest nodal error relative to the exact tip displacement
  double tip_fem, tip_exact, tip_homogeneous;  ///< [m]
};
TwoMaterialColumn two_material_column(double E_top, double E_bottom, VolumeForm form) {
  const double L = 0.1, a = 0.02, rho = 1000, g = 9.81;
  const TetMesh m = make_box_tet_mesh(4, 4, 20, Vec3(a, a, L), Vec3(0, 0, -L));
  GravityProblem pb;
  pb.rest = &m;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 2) == 0.0) pb.fixed.push_back(static_cast<int>(i));
  pb.youngs_modulus = E_top;
  pb.region_youngs_modulus = {E_bottom};
  for (Eigen::Index t = 0; t < m.T.rows(); ++t) {
    double z = 0;
    for (int k = 0; k < 4; ++k) z += m.V(m.T(t, k), 2) / 4;
    pb.material_of.push_back(-z > L / 2 ? 1 : 0);
  }
  pb.poisson_ratio = 0.0;
  pb.density = rho;
  pb.gravity = Vec3(0, 0, -g);
  pb.volume_form = form;
  NewtonOptions opt;
  opt.gradient_rel_tolerance = 1e-12;
  const GravityResult r = solve_gravity(pb, opt);
  EXPECT_TRUE(r.newton.converged);
  auto exact = [&](double d) {
    const double s = std::min(d, L / 2);
    double u = rho * g * (L * s - s * s / 2) / E_top;
    if (d > L / 2) u += rho * g * ((L * d - d * d / 2) - 3 * L * L / 8) / E_bottom;
    return u;
  };
  TwoMaterialColumn c{0, 0, exact(L), rho * g * L * L / (2 * E_top)};
  int tips = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    const double d = -m.V(i, 2), u = -(r.x(i, 2) - m.V(i, 2));
    c.worst_error = std::max(c.worst_error, std::abs(u - exact(d)) / c.tip_exact);
    if (std::abs(d - L) < 1e-12) {
      c.tip_fem += u;
      ++tips;
    }
  }
  c.tip_fem /= tips;
  return c;
}

}  // namespace

TEST(Mechanics, TwoMaterialColumnMatchesTheLayeredSelfWeightSolution) {
  const double one_material = hanging_column_error(4, 20);  // the same mesh in one material
  for (const VolumeForm form : {VolumeForm::Element, VolumeForm::Nodal})
    for (const auto& [top, bottom] : std::vector<std::pair<double, double>>{{1e7, 2.5e6}, {1e7, 4e7}}) {
      const TwoMaterialColumn c = two_material_column(top, bottom, form);
      const double tip_error = std::abs(c.tip_fem - c.tip_exact) / c.tip_exact;
      std::printf("two-material column (%s form), E top %.1e, bottom %.1e Pa: tip %.5f mm, exact %.5f mm (%.2f%%), "
                  "homogeneous %.5f mm; max nodal error %.2f%% (one material: %.2f%%)\n",
                  to_string(form), top, bottom, c.tip_fem * 1e3, c.tip_exact * 1e3, 100 * tip_error,
                  c.tip_homogeneous * 1e3, 100 * c.worst_error, 100 * one_material);
      EXPECT_LT(tip_error, 0.02);
      EXPECT_LT(c.worst_error, 1.5 * one_material);  // the interface adds little to the discretization error
      // The second material matters: the homogeneous answer is off by far more than the error.
      EXPECT_GT(std::abs(c.tip_homogeneous - c.tip_exact) / c.tip_exact, 5 * c.worst_error);
    }
}
