#include <Eigen/Eigenvalues>
#include <algorithm>
#include <random>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/stable_neo_hookean.h"
#include "test_util.h"

using namespace btr;
using btr::test::expect_throw_with;

namespace {

enum class Kind { Random, Compressed, Inverted, Stretched, NearIdentity, Rotation };

Mat3 make_F(Kind k, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::Quaterniond q1 = Eigen::Quaterniond::UnitRandom(), q2 = Eigen::Quaterniond::UnitRandom();
  auto usv = [&](double a, double b, double c) {
    return Mat3(q1.toRotationMatrix() * Vec3(a, b, c).asDiagonal() * q2.toRotationMatrix());
  };
  switch (k) {
    case Kind::Random: return Mat3::Identity() + btr::test::random_matrix(rng, 0.6);
    case Kind::Compressed: return usv(0.2 + 0.3 * u(rng), 0.3 + 0.3 * u(rng), 0.1 + 0.2 * u(rng));
    case Kind::Inverted: return usv(0.5 + u(rng), 0.4 + u(rng), -(0.1 + 0.5 * u(rng)));
    case Kind::Stretched: return usv(1.5 + u(rng), 2.0 + u(rng), 0.8 + u(rng));
    case Kind::NearIdentity: return Mat3::Identity() + btr::test::random_matrix(rng, 1e-3);
    case Kind::Rotation: return q1.toRotationMatrix();
  }
  return Mat3::Identity();
}

// Smallest relative central-difference error over shrinking steps (1e-2 .. 1e-7).
template <class F, class G>
double fd_error(F&& analytic, G&& numeric) {
  double best = 1e300;
  for (double h = 1e-2; h >= 1e-7; h *= 0.1) {
    const Eigen::VectorXd a = analytic(), n = numeric(h);
    best = std::min(best, (a - n).norm() / std::max(1.0, a.norm()));
  }
  return best;
}

struct Case {
  Kind kind;
  double E, nu;
};

class SnhDerivatives : public ::testing::TestWithParam<Case> {};

}  // namespace

TEST_P(SnhDerivatives, StressIsTheEnergyGradient) {
  std::mt19937 rng(7);
  const StableNeoHookean m(GetParam().E, GetParam().nu);
  for (int trial = 0; trial < 10; ++trial) {
    const Mat3 F = make_F(GetParam().kind, rng);
    const double err = fd_error(
        [&] { Mat3 P = m.pk1(F); return Eigen::VectorXd(Eigen::Map<Vec9>(P.data())); },
        [&](double h) {
          Eigen::VectorXd g(9);
          for (int i = 0; i < 9; ++i) {
            Mat3 Fp = F, Fm = F;
            Fp(i) += h;
            Fm(i) -= h;
            g[i] = (m.psi(Fp) - m.psi(Fm)) / (2 * h);
          }
          return g;
        });
    EXPECT_LT(err, 1e-7) << "F=\n" << F;
  }
}

TEST_P(SnhDerivatives, HessianIsTheStressGradient) {
  std::mt19937 rng(11);
  const StableNeoHookean m(GetParam().E, GetParam().nu);
  for (int trial = 0; trial < 10; ++trial) {
    const Mat3 F = make_F(GetParam().kind, rng);
    const double err = fd_error(
        [&] { Mat9 H = m.hessian(F); return Eigen::VectorXd(Eigen::Map<Eigen::VectorXd>(H.data(), 81)); },
        [&](double h) {
          Mat9 H;
          for (int i = 0; i < 9; ++i) {
            Mat3 Fp = F, Fm = F;
            Fp(i) += h;
            Fm(i) -= h;
            const Mat3 d = (m.pk1(Fp) - m.pk1(Fm)) / (2 * h);
            H.col(i) = Eigen::Map<const Vec9>(d.data());
          }
          return Eigen::VectorXd(Eigen::Map<Eigen::VectorXd>(H.data(), 81));
        });
    EXPECT_LT(err, 1e-7) << "F=\n" << F;
  }
}

TEST_P(SnhDerivatives, AnalyticProjectionMatchesNumericalEigenClamp) {
  std::mt19937 rng(13);
  const StableNeoHookean m(GetParam().E, GetParam().nu);
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 F = make_F(GetParam().kind, rng);
    const Mat9 H = m.hessian(F);
    Eigen::SelfAdjointEigenSolver<Mat9> es(H);
    const Vec9 clamped = es.eigenvalues().cwiseMax(0.0);
    const Mat9 numeric = es.eigenvectors() * clamped.asDiagonal() * es.eigenvectors().transpose();
    const Mat9 analytic = m.clamped_hessian(F);
    const double scale = std::max(1.0, H.norm());
    EXPECT_LT((analytic - numeric).norm() / scale, 1e-9) << "F=\n" << F;
    Vec9 ev = m.analytic_eigenvalues(F);
    std::sort(ev.data(), ev.data() + 9);
    EXPECT_LT((ev - es.eigenvalues()).norm() / scale, 1e-9);
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Mat9>(analytic).eigenvalues().minCoeff(), -1e-9 * scale);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Deformations, SnhDerivatives,
    ::testing::Values(Case{Kind::Random, 3400, 0.49}, Case{Kind::Compressed, 3400, 0.49}, Case{Kind::Inverted, 3400, 0.49},
                      Case{Kind::Stretched, 3400, 0.49}, Case{Kind::NearIdentity, 3400, 0.49},
                      Case{Kind::Rotation, 3400, 0.49}, Case{Kind::Random, 50, 0.0}, Case{Kind::Inverted, 1e6, 0.499},
                      Case{Kind::Compressed, 1e6, 0.3}));

TEST(StableNeoHookean, RestStateIsStressFreeAndRotationInvariant) {
  const StableNeoHookean m(3400, 0.49);
  EXPECT_NEAR(m.psi(Mat3::Identity()), 0.0, 1e-12);
  EXPECT_LT(m.pk1(Mat3::Identity()).norm(), 1e-10);
  std::mt19937 rng(3);
  const Mat3 F = Mat3::Identity() + btr::test::random_matrix(rng, 0.3);
  const Mat3 R = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
  EXPECT_NEAR(m.psi(R * F), m.psi(F), 1e-9 * m.psi(F));
  EXPECT_NEAR(m.psi(R), 0.0, 1e-9);
}

TEST(StableNeoHookean, LinearizationIsLinearElasticityWithTheGivenLameParameters) {
  // vec(H)^T d2psi(I) vec(H) = 2 mu |sym H|^2 + lambda_L (tr H)^2 for every H.
  const double E = 3400, nu = 0.45;
  const StableNeoHookean m(E, nu);
  const LameParameters l = lame_from_young_poisson(E, nu);
  const Mat9 H0 = m.hessian(Mat3::Identity());
  std::mt19937 rng(5);
  for (int t = 0; t < 10; ++t) {
    const Mat3 G = btr::test::random_matrix(rng);
    const Mat3 S = 0.5 * (G + G.transpose());
    const Vec9 g = Eigen::Map<const Vec9>(G.data());
    const double expected = 2 * l.mu * S.squaredNorm() + l.lambda * G.trace() * G.trace();
    EXPECT_NEAR(g.dot(H0 * g), expected, 1e-9 * expected);
  }
  // The Young's modulus it reports is the one it was made from, at any Poisson's ratio.
  for (double n : {0.0, 0.3, 0.45, 0.499}) EXPECT_NEAR(StableNeoHookean(E, n).youngs_modulus(), E, 1e-9 * E) << n;
}

TEST(StableNeoHookean, ParameterRangeErrors) {
  expect_throw_with<InputError>([] { StableNeoHookean(3400, 0.5); }, "Poisson's ratio must be in [0, 0.5)");
  expect_throw_with<InputError>([] { StableNeoHookean(-1, 0.3); }, "Young's modulus must be a positive");
  expect_throw_with<InputError>([] { StableNeoHookean(std::nan(""), 0.3); }, "Young's modulus");
  EXPECT_NO_THROW(StableNeoHookean(50, 0.0));
  EXPECT_NO_THROW(StableNeoHookean(1e6, 0.499));
}
