#include <Eigen/Eigenvalues>
#include <memory>
#include <random>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/determinant_eigensystem.h"
#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/small_matrices.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/newton_solver.h"
#include "breast_tumour_registration/fem/nodal_volume_energy.h"
#include "breast_tumour_registration/fem/spring_energy.h"
#include "breast_tumour_registration/fem/rigid_free_landmark_energy.h"
#include "breast_tumour_registration/fem/rigid_free_surface_energy.h"
#include "breast_tumour_registration/fem/total_energy.h"
#include "breast_tumour_registration/geometry/box_mesh.h"
#include "energy_checks.h"
#include "test_util.h"

using namespace btr;

namespace {

TetMesh small_mesh() { return make_box_tet_mesh(3, 2, 2, Vec3(0.06, 0.04, 0.04)); }

Points perturbed(const TetMesh& m, double amount, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, amount);
  Points x = m.V;
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] += n(rng);
  return x;
}

Anchor triangle_anchor(int a, int b, int c) {
  Anchor an;
  an.count = 3;
  an.v[0] = a; an.v[1] = b; an.v[2] = c;
  an.w[0] = 0.2; an.w[1] = 0.5; an.w[2] = 0.3;
  return an;
}

using btr::test::check_term;

}  // namespace

TEST(ElasticEnergy, ElementGradientAndHessianMatchFiniteDifferences) {
  const TetMesh m = small_mesh();
  const ElasticEnergy e(m, {StableNeoHookean(3400, 0.49)});
  const Points x = perturbed(m, 0.004, 1);
  for (Eigen::Index t : {0, 7, 23}) {
    const Vec12 g = e.element_gradient(x, t);
    const Mat12 H = e.element_hessian(x, t, false);
    double best_g = 1e300, best_h = 1e300;
    for (double h = 1e-4; h >= 1e-8; h *= 0.1) {
      Vec12 gn;
      Mat12 Hn;
      for (int k = 0; k < 12; ++k) {
        Points xp = x, xm = x;
        xp(m.T(t, k / 3), k % 3) += h;
        xm(m.T(t, k / 3), k % 3) -= h;
        gn[k] = (e.element_value(xp, t) - e.element_value(xm, t)) / (2 * h);
        Hn.col(k) = (e.element_gradient(xp, t) - e.element_gradient(xm, t)) / (2 * h);
      }
      best_g = std::min(best_g, (gn - g).norm() / g.norm());
      best_h = std::min(best_h, (Hn - H).norm() / H.norm());
    }
    EXPECT_LT(best_g, 1e-7);
    EXPECT_LT(best_h, 1e-7);
  }
}

TEST(ElasticEnergy, AssembledGradientAndHessianMatchFiniteDifferences) {
  const TetMesh m = small_mesh();
  // Two materials, as for a stiffer tumour region.
  std::vector<int> mat(m.T.rows(), 0);
  for (size_t t = 0; t < mat.size(); t += 3) mat[t] = 1;
  const ElasticEnergy e(m, {StableNeoHookean(3400, 0.49), StableNeoHookean(20000, 0.45)}, mat);
  check_term(e, m, perturbed(m, 0.004, 2));
}

TEST(ElasticEnergy, ProjectedHessianIsPositiveSemiDefiniteUnderInversion) {
  const TetMesh m = small_mesh();
  const ElasticEnergy e(m, {StableNeoHookean(3400, 0.49)});
  Points x = perturbed(m, 0.02, 3);  // large noise: many inverted elements
  HessianAssembler H(static_cast<int>(m.V.rows()), m.T, {});
  e.add_hessian(x, true, H);
  const Eigen::MatrixXd Hd(H.matrix());
  const double min_eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Hd).eigenvalues().minCoeff();
  EXPECT_GE(min_eig, -1e-9 * Hd.norm());
}

TEST(NodalVolumeEnergy, GradientAndHessianMatchFiniteDifferences) {
  const TetMesh m = small_mesh();
  std::vector<double> lambda(m.T.rows(), 5e4);
  for (Eigen::Index t = 0; t < m.T.rows(); t += 3) lambda[t] = 2e5;  // heterogeneous
  const NodalVolumeEnergy e(m, lambda);
  check_term(e, m, perturbed(m, 0.004, 11), e.hessian_cliques());
}

TEST(NodalVolumeEnergy, EqualsTheElementFormUnderUniformDeformationAndProjectsToPsd) {
  const TetMesh m = small_mesh();
  const StableNeoHookean mat(3400, 0.499);
  const std::vector<double> lambda(m.T.rows(), mat.lambda());
  const NodalVolumeEnergy nodal(m, lambda);
  const ElasticEnergy full(m, {mat}), shear(m, {mat.shear_part()});
  Mat3 A;
  A << 1.1, 0.05, 0.0, -0.02, 0.93, 0.04, 0.01, 0.0, 1.02;
  const Points x = (m.V * A.transpose()).eval();
  EXPECT_NEAR(shear.value(x) + nodal.value(x), full.value(x), 1e-9 * full.value(x));
  EXPECT_NEAR(nodal.value(m.V), 0.0, 1e-15);
  // Strongly compressed and partly inverted: the projected Hessian is PSD.
  Points y = perturbed(m, 0.02, 5);
  HessianAssembler H(static_cast<int>(m.V.rows()), m.T, {}, nodal.hessian_cliques());
  nodal.add_hessian(y, true, H);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(H.matrix()));
  EXPECT_GT(es.eigenvalues().minCoeff(), -1e-8 * es.eigenvalues().cwiseAbs().maxCoeff());
  EXPECT_GT(count_inverted(y, m.T), 0) << "the check should include inverted elements";
}

// The closed-form projection of s d2J/dF2 equals the numerical eigen-clamp it replaced, for
// stretched, compressed, nearly degenerate and inverted F and either sign of s; it is PSD and
// leaves a PSD matrix (s d2J/dF2 is never PSD unless zero, so that case is s = 0).
TEST(DeterminantEigensystem, TheClosedFormProjectionEqualsTheNumericalEigenClamp) {
  std::mt19937 rng(17);
  std::normal_distribution<double> n(0.0, 0.3);
  std::vector<Mat3> Fs;
  for (int k = 0; k < 40; ++k) Fs.push_back(Mat3::Identity() + n(rng) * Mat3::Random());
  Mat3 inverted = Mat3::Identity();
  inverted(2, 2) = -0.4;
  Fs.push_back(inverted);
  Fs.push_back(Vec3(1.0, 1.0, 1e-9).asDiagonal());          // nearly flat
  Fs.push_back(Vec3(1.2, 1.2, 1.2).asDiagonal());           // repeated singular values
  Fs.push_back(Mat3::Zero());
  int inverted_seen = 0;
  for (const Mat3& F : Fs) {
    inverted_seen += F.determinant() < 0;
    for (double s : {2.5e4, -3.0e3})
      for (double shift : {0.0, 1.5e3}) {  // shift: the shear part's mu I
        const Mat9 numeric = clamp_to_psd(shift * Mat9::Identity() + s * determinant_hessian(F));
        const Mat9 closed = projected_determinant_hessian(F, s, shift);
        EXPECT_LT((closed - numeric).norm(), 1e-9 * std::max(1.0, numeric.norm()))
            << "F =\n" << F << "\ns = " << s << ", shift " << shift;
        EXPECT_LT((closed - closed.transpose()).norm(), 1e-12 * std::max(1.0, closed.norm()));
      }
  }
  EXPECT_GT(inverted_seen, 0);
  EXPECT_EQ(projected_determinant_hessian(Fs[0], 0.0).norm(), 0.0);
  EXPECT_EQ(projected_determinant_hessian(Fs[0], 0.0, 2.0), Mat9(2.0 * Mat9::Identity()));
}

// The nodal form as add_elastic_energy builds it: one term with the shear part. Its energy and
// gradient equal the two-term split (ElasticEnergy on the shear parts + the volume term alone),
// its derivatives match finite differences, and its projected Hessian is PSD on a partly
// inverted state and no larger than the split's (the sum is projected, not each part).
TEST(NodalVolumeEnergy, WithTheShearPartItEqualsTheSplitFormAndProjectsTheSum) {
  const TetMesh m = small_mesh();
  const StableNeoHookean soft(800, 0.49), stiff(5000, 0.49);
  std::vector<int> material_of(m.T.rows(), 0);
  for (Eigen::Index t = 0; t < m.T.rows(); t += 3) material_of[t] = 1;  // heterogeneous
  std::vector<double> lambda;
  for (int k : material_of) lambda.push_back((k ? stiff : soft).lambda());
  const NodalVolumeEnergy combined(m, lambda, {soft.shear_part(), stiff.shear_part()}, material_of), volume(m, lambda);
  EXPECT_THROW(NodalVolumeEnergy(m, lambda, {soft}), InputError);  // a volume term of its own
  EXPECT_THROW(NodalVolumeEnergy(m, lambda, {}, material_of), InputError);  // materials with nothing to index
  const ElasticEnergy shear(m, {soft.shear_part(), stiff.shear_part()}, material_of);
  const Points x = perturbed(m, 0.004, 21);
  EXPECT_NEAR(combined.value(x), shear.value(x) + volume.value(x), 1e-12 * std::abs(combined.value(x)));
  Eigen::VectorXd g1 = Eigen::VectorXd::Zero(x.size()), g2 = g1;
  combined.add_gradient(x, g1);
  shear.add_gradient(x, g2);
  volume.add_gradient(x, g2);
  EXPECT_LT((g1 - g2).norm(), 1e-10 * g2.norm());
  check_term(combined, m, x, combined.hessian_cliques());

  const Points y = perturbed(m, 0.02, 5);
  ASSERT_GT(count_inverted(y, m.T), 0);
  HessianAssembler Hc(static_cast<int>(m.V.rows()), m.T, {}, combined.hessian_cliques()),
      Hs(static_cast<int>(m.V.rows()), m.T, {}, combined.hessian_cliques());
  combined.add_hessian(y, true, Hc);
  shear.add_hessian(y, true, Hs);
  volume.add_hessian(y, true, Hs);
  const Eigen::MatrixXd C(Hc.matrix()), S(Hs.matrix());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(C);
  EXPECT_GT(es.eigenvalues().minCoeff(), -1e-8 * es.eigenvalues().cwiseAbs().maxCoeff());
  // Projecting each part adds back the negative eigenvalues of each; projecting the sum only those
  // of the sum, so the split's matrix is the larger (in trace) where anything was clamped.
  EXPECT_LE(C.trace(), S.trace() * (1 + 1e-12));
  EXPECT_LT(C.trace(), S.trace());
}

// The element-share stabilisation: a part kappa of every lambda on the element's own J (here a
// fraction alpha). It equals the plain nodal term at (1 - alpha) lambda plus alpha times the
// element form's volume term (the full materials' energy less their shear parts': lambda/2
// (J - 1)^2 per element); it matches finite differences with and without the shear part, keeps
// the patch test, and projects to PSD.
TEST(NodalVolumeEnergy, TheElementShareIsTheNodalTermPlusTheElementVolumeTerm) {
  const TetMesh m = small_mesh();
  const StableNeoHookean soft(800, 0.49), stiff(5000, 0.49);
  std::vector<int> material_of(m.T.rows(), 0);
  for (Eigen::Index t = 0; t < m.T.rows(); t += 3) material_of[t] = 1;
  std::vector<double> lambda, kappa, rest_share;
  const double alpha = 0.2;
  for (int k : material_of) lambda.push_back((k ? stiff : soft).lambda());
  for (double l : lambda) kappa.push_back(alpha * l), rest_share.push_back((1 - alpha) * l);
  const NodalVolumeEnergy shared(m, lambda, {}, {}, kappa), nodal_part(m, rest_share);
  const NodalVolumeEnergy combined(m, lambda, {soft.shear_part(), stiff.shear_part()}, material_of, kappa);
  // alpha lambda/2 (J - 1)^2 per element: alpha times (full - shear) of the element form.
  const ElasticEnergy full(m, {soft, stiff}, material_of), shear(m, {soft.shear_part(), stiff.shear_part()}, material_of);
  const Points x = perturbed(m, 0.004, 31);
  const double element_part = alpha * (full.value(x) - shear.value(x));
  EXPECT_NEAR(shared.value(x), nodal_part.value(x) + element_part, 1e-10 * shared.value(x));
  EXPECT_NEAR(combined.value(x), shared.value(x) + shear.value(x), 1e-10 * combined.value(x));
  check_term(shared, m, x, shared.hessian_cliques());
  check_term(combined, m, x, combined.hessian_cliques());
  // Patch test: under a uniform deformation every form gives the element form's energy.
  Mat3 A;
  A << 1.1, 0.05, 0.0, -0.02, 0.93, 0.04, 0.01, 0.0, 1.02;
  const Points u = (m.V * A.transpose()).eval();
  EXPECT_NEAR(combined.value(u), full.value(u), 1e-9 * full.value(u));
  // Partly inverted: PSD.
  const Points y = perturbed(m, 0.02, 5);
  ASSERT_GT(count_inverted(y, m.T), 0);
  HessianAssembler H(static_cast<int>(m.V.rows()), m.T, {}, combined.hessian_cliques());
  combined.add_hessian(y, true, H);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(H.matrix()));
  EXPECT_GT(es.eigenvalues().minCoeff(), -1e-8 * es.eigenvalues().cwiseAbs().maxCoeff());
  std::vector<double> too_much = lambda;
  too_much[4] *= 1.01;
  EXPECT_THROW(NodalVolumeEnergy(m, lambda, {}, {}, too_much), InputError);
  EXPECT_THROW(NodalVolumeEnergy(m, lambda, {}, {}, std::vector<double>(3, 0.0)), InputError);
}

TEST(GravityEnergy, GradientMatchesFiniteDifferencesAndMassIsConserved) {
  const TetMesh m = small_mesh();
  const GravityEnergy e(m, 1000, Vec3(0, 0, -9.81));
  EXPECT_NEAR(e.masses().sum(), 1000 * 0.06 * 0.04 * 0.04, 1e-12);
  check_term(e, m, perturbed(m, 0.004, 4));
}

// One spring term, every metric: point (w I), plane (w n n^T), both, and a general SPD matrix,
// on vertex, triangle and tetrahedron anchors.
TEST(SpringEnergy, PointPlaneAndGeneralMetricsOnVertexTriangleAndTetAnchors) {
  const TetMesh m = small_mesh();
  SpringEnergy e;
  e.add_point(Anchor::vertex(5), Vec3(0.01, 0.02, 0.03), 1e4);
  e.add_point(triangle_anchor(m.T(4, 0), m.T(4, 1), m.T(4, 2)), Vec3(-0.01, 0.0, 0.05), 1e4);
  Anchor tet;
  tet.count = 4;
  for (int k = 0; k < 4; ++k) {
    tet.v[k] = m.T(9, k);
    tet.w[k] = 0.1 + 0.1 * k;
  }
  e.add_point(tet, Vec3(0.02, 0.02, 0.02), 1e4);
  e.add_plane(Anchor::vertex(3), Vec3(0.01, 0.02, 0.03), Vec3(1, 2, 2), 1e4);
  e.add_plane(triangle_anchor(m.T(2, 0), m.T(2, 1), m.T(2, 3)), Vec3(0.0, 0.01, 0.0), Vec3(0, 0, 3), 1e4);
  e.add_point_and_plane(Anchor::vertex(7), Vec3(0.0, 0.01, 0.02), Vec3(0, 1, 1), 3e3, 2e4);
  Mat3 A;
  A << 2, 0.5, 0, 0.5, 1, 0.3, 0, 0.3, 3;
  e.add(Anchor::vertex(11), Vec3(0.03, 0.0, 0.01), 1e4 * A);
  check_term(e, m, perturbed(m, 0.004, 5));
}

// The point-to-plane metric is the thesis's eq. 4.3: w/2 ((p - q) . n)^2, sliding in the plane free.
TEST(SpringEnergy, ThePlaneMetricIsTheSquaredDistanceToThePlane) {
  const TetMesh m = small_mesh();
  SpringEnergy e;
  const Vec3 q(0.01, 0.02, 0.03), n = Vec3(1, 2, 2) / 3.0;
  e.add_plane(Anchor::vertex(3), q, 3 * n, 5e3);
  Points x = m.V;
  x.row(3) = (q + 0.002 * n + 0.01 * Vec3(2, -1, 0).normalized()).transpose();  // 2 mm off the plane, slid along it
  EXPECT_NEAR(e.value(x), 0.5 * 5e3 * 0.002 * 0.002, 1e-15);
}

// The pose-free landmark term: exact derivatives (pose eliminated), with data that is a
// rotated, shifted and noisy copy of the anchors, so the residual is not zero.
TEST(RigidFreeLandmarkEnergy, GradientAndHessianMatchFiniteDifferences) {
  const TetMesh m = small_mesh();
  std::vector<Anchor> anchors = {Anchor::vertex(5), triangle_anchor(m.T(4, 0), m.T(4, 1), m.T(4, 2)), Anchor::vertex(17),
                                 Anchor::vertex(30), Anchor::vertex(2)};
  const Points x = perturbed(m, 0.004, 8);
  Points data(anchors.size(), 3);
  const Rigid T = btr::test::make_rigid(Vec3(20, -10, 30), Vec3(0.01, -0.02, 0.03));
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.003);
  for (size_t i = 0; i < anchors.size(); ++i)
    data.row(i) = (T * anchors[i].position(x) + Vec3(noise(rng), noise(rng), noise(rng))).transpose();
  const RigidFreeLandmarkEnergy e(1e4, anchors, data);
  check_term(e, m, x, {e.clique()});
}

TEST(RigidFreeLandmarkEnergy, PoseIsEliminatedAndProjectedHessianIsPsd) {
  const TetMesh m = small_mesh();
  std::vector<Anchor> anchors = {Anchor::vertex(5), Anchor::vertex(11), Anchor::vertex(17), Anchor::vertex(30)};
  Points data(anchors.size(), 3);
  const Rigid T = btr::test::make_rigid(Vec3(40, 15, -60), Vec3(0.1, 0.2, -0.3));
  for (size_t i = 0; i < anchors.size(); ++i) data.row(i) = (T * anchors[i].position(m.V)).transpose();
  const RigidFreeLandmarkEnergy e(1e4, anchors, data);
  EXPECT_LT(e.value(m.V), 1e-20);  // any rigid motion of the data costs nothing
  EXPECT_LT((e.pose(m.V).matrix() - T.inverse().matrix()).norm(), 1e-9);
  HessianAssembler H(static_cast<int>(m.V.rows()), m.T, {}, {e.clique()});
  e.add_hessian(perturbed(m, 0.004, 9), true, H);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es{Eigen::MatrixXd(H.matrix())};
  EXPECT_GT(es.eigenvalues().minCoeff(), -1e-8 * es.eigenvalues().maxCoeff());
  // Rigid motions of the anchors are in its null space: 4 landmarks leave 12 - 6 = 6 modes.
  int nonzero = 0;
  for (int k = 0; k < es.eigenvalues().size(); ++k) nonzero += es.eigenvalues()[k] > 1e-8 * es.eigenvalues().maxCoeff();
  EXPECT_EQ(nonzero, 6);
  btr::test::expect_throw_with<InputError>([&] { RigidFreeLandmarkEnergy(1, {anchors[0], anchors[1]}, data.topRows(2)); },
                                           "at least 3");
}

namespace {
// Surface springs on the box's top face (z = 0.04), scan points a rigid motion away.
RigidFreeSurfaceEnergy surface_springs(const TetMesh& m, const Points& x, const Rigid& P, double noise) {
  std::vector<int> verts;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 2) > 0.039) verts.push_back(static_cast<int>(i));
  Points y(verts.size(), 3), n(verts.size(), 3);
  std::mt19937 rng(11);
  std::normal_distribution<double> nd(0.0, noise);
  for (size_t j = 0; j < verts.size(); ++j) {
    y.row(j) = (P * Vec3(x.row(verts[j]).transpose()) + Vec3(nd(rng), nd(rng), nd(rng))).transpose();
    n.row(j) = (P.linear() * Vec3(0.1 * static_cast<double>(j % 3), 0.2, 1.0)).transpose();
  }
  RigidFreeSurfaceEnergy e(30, 3000);
  e.set(verts, y, n);
  return e;
}

Eigen::MatrixXd dense_hessian(const EnergyTerm& e, const TetMesh& m, const Points& x) {
  HessianAssembler H(static_cast<int>(x.rows()), m.T, {});
  H.set_zero();
  e.add_hessian(x, true, H);
  std::vector<LowRankHessian> parts;
  e.add_low_rank_hessian(x, parts);
  Eigen::MatrixXd D(H.matrix());
  for (const auto& p : parts) D -= p.W * p.M * p.W.transpose();
  return D;
}
}  // namespace

TEST(RigidFreeSurfaceEnergy, GradientMatchesFiniteDifferencesAwayFromTheScan) {
  const TetMesh m = small_mesh();
  const Points x = perturbed(m, 0.003, 12);
  RigidFreeSurfaceEnergy e = surface_springs(m, m.V, btr::test::make_rigid(Vec3(10, -5, 20), Vec3(0.01, 0, -0.02)), 0.002);
  Points targets(2, 3);
  targets << 0.01, 0.02, 0.03, -0.01, 0.0, 0.05;
  e.set_points({triangle_anchor(m.T(4, 0), m.T(4, 1), m.T(4, 2)), Anchor::vertex(3)}, targets, 1e4);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  e.add_gradient(x, g);
  double best = 1e300;
  for (double h = 1e-4; h >= 1e-8; h *= 0.1) {
    Eigen::VectorXd gn(x.size());
    for (Eigen::Index i = 0; i < x.size(); ++i) {
      Points xp = x, xm = x;
      xp.data()[i] += h;
      xm.data()[i] -= h;
      gn[i] = (e.value(xp) - e.value(xm)) / (2 * h);
    }
    best = std::min(best, (gn - g).norm() / g.norm());
  }
  EXPECT_LT(best, 1e-6);
}

TEST(RigidFreeSurfaceEnergy, HessianWithItsLowRankPartMatchesFiniteDifferencesOnTheScan) {
  const TetMesh m = small_mesh();
  const Points x = perturbed(m, 0.003, 13);
  const Rigid P = btr::test::make_rigid(Vec3(-15, 25, 40), Vec3(0.02, 0.01, 0));
  const RigidFreeSurfaceEnergy e = surface_springs(m, x, P, 0.0);  // zero residual: Gauss-Newton is exact
  EXPECT_LT(e.value(x), 1e-20);
  EXPECT_LT((e.pose(x).matrix() - P.matrix()).norm(), 1e-9);
  const Eigen::MatrixXd Hd = dense_hessian(e, m, x);
  double best = 1e300;
  for (double h = 1e-4; h >= 1e-7; h *= 0.1) {
    Eigen::MatrixXd Hn(x.size(), x.size());
    for (Eigen::Index i = 0; i < x.size(); ++i) {
      Points xp = x, xm = x;
      xp.data()[i] += h;
      xm.data()[i] -= h;
      Eigen::VectorXd gp = Eigen::VectorXd::Zero(x.size()), gm = Eigen::VectorXd::Zero(x.size());
      e.add_gradient(xp, gp);
      e.add_gradient(xm, gm);
      Hn.col(i) = (gp - gm) / (2 * h);
    }
    best = std::min(best, (Hn - Hd).norm() / Hd.norm());
  }
  EXPECT_LT(best, 1e-5);
  // Rigid motions of the constrained vertices cost nothing: PSD with a 6-dimensional null space among them.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Hd);
  EXPECT_GT(es.eigenvalues().minCoeff(), -1e-8 * es.eigenvalues().maxCoeff());
  int zero_on_springs = 0;
  for (Eigen::Index k = 0; k < es.eigenvalues().size(); ++k) zero_on_springs += es.eigenvalues()[k] < 1e-8 * es.eigenvalues().maxCoeff();
  EXPECT_EQ(zero_on_springs, static_cast<int>(x.size() - 3 * e.size() + 6));
}

// The solver applies the low-rank part (Woodbury on the factor, and in PCG): a mesh held only
// by pose-free springs to a moved copy of its own top face settles back onto its rest shape.
TEST(RigidFreeSurfaceEnergy, NewtonWithTheLowRankPartRecoversARigidlyMovedScan) {
  const TetMesh m = small_mesh();
  TotalEnergy total;
  total.add(std::make_shared<ElasticEnergy>(m, std::vector<StableNeoHookean>{StableNeoHookean(3400, 0.45)}));
  const Rigid P = btr::test::make_rigid(Vec3(5, -10, 30), Vec3(0.03, -0.01, 0.02));
  total.add(std::make_shared<RigidFreeSurfaceEnergy>(surface_springs(m, m.V, P, 0.0)));
  std::vector<bool> fixed(m.V.rows(), false);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) fixed[i] = m.V(i, 2) == 0.0;
  Points x = perturbed(m, 0.002, 14);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (fixed[i]) x.row(i) = m.V.row(i);
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(m.V.rows()), m.T, fixed), m.T);
  NewtonOptions opt;
  opt.force_scale = 1.0;
  const NewtonResult r = solver.solve(total, x, opt);
  EXPECT_TRUE(r.converged) << to_string(r.reason);
  EXPECT_LT((x - m.V).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LE(r.iterations, 12);
}

TEST(Constraints, BadWeightsAndNormalsAreRejected) {
  SpringEnergy p;
  btr::test::expect_throw_with<InputError>([&] { p.add_point(Anchor::vertex(0), Vec3::Zero(), -1); }, "weight must be finite and >= 0");
  btr::test::expect_throw_with<InputError>([&] { p.add_plane(Anchor::vertex(0), Vec3::Zero(), Vec3::UnitZ(), std::nan("")); },
                                           "weight must be finite");
  btr::test::expect_throw_with<InputError>([&] { p.add_plane(Anchor::vertex(0), Vec3::Zero(), Vec3::Zero(), 1); }, "non-zero");
  btr::test::expect_throw_with<InputError>([&] { p.add(Anchor::vertex(0), Vec3::Zero(), -Mat3::Identity()); }, "semi-definite");
  Mat3 skew = Mat3::Identity();
  skew(0, 1) = 1;
  btr::test::expect_throw_with<InputError>([&] { p.add(Anchor::vertex(0), Vec3::Zero(), skew); }, "symmetric");
  btr::test::expect_throw_with<InputError>([&] { p.add_point(Anchor::vertex(0), Vec3(0, std::nan(""), 0), 1); }, "not finite");
  EXPECT_EQ(p.size(), 0u);
}

TEST(TotalEnergy, SumOfTermsWithFixedVerticesEliminated) {
  const TetMesh m = small_mesh();
  TotalEnergy total;
  total.add(std::make_shared<ElasticEnergy>(m, std::vector<StableNeoHookean>{StableNeoHookean(3400, 0.49)}));
  total.add(std::make_shared<GravityEnergy>(m, 1000, Vec3(0, 0, -9.81)));
  const Points x = perturbed(m, 0.003, 7);
  std::vector<bool> fixed(m.V.rows(), false);
  for (int v = 0; v < 12; ++v) fixed[v] = true;
  HessianAssembler Hf(static_cast<int>(m.V.rows()), m.T, fixed), Ha(static_cast<int>(m.V.rows()), m.T, {});
  total.hessian(x, false, Hf);
  total.hessian(x, false, Ha);
  EXPECT_EQ(Hf.num_free_dofs(), 3 * (static_cast<int>(m.V.rows()) - 12));
  // The reduced matrix is the free-free block of the full one.
  const Eigen::MatrixXd full(Ha.matrix()), red(Hf.matrix());
  EXPECT_LT((full.bottomRightCorner(red.rows(), red.cols()) - red).norm(), 1e-9 * full.norm());
}
