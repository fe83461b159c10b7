#include <random>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/box_mesh.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "test_util.h"

using namespace btr;

TEST(Embedding, InteriorPointsAreReconstructedExactlyAndFollowAffineMaps) {
  const TetMesh m = make_box_tet_mesh(5, 4, 3, Vec3(0.1, 0.08, 0.06));
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Points P(200, 3);
  for (Eigen::Index i = 0; i < P.rows(); ++i) P.row(i) << 0.1 * u(rng), 0.08 * u(rng), 0.06 * u(rng);
  const Embedding e = embed_points(m, P);
  EXPECT_TRUE(e.outside.empty());
  EXPECT_GE(e.weights.minCoeff(), -1e-9);
  EXPECT_LT((e.weights.rowwise().sum().array() - 1.0).abs().maxCoeff(), 1e-12);
  EXPECT_LT((apply_embedding(e, m.T, m.V) - P).cwiseAbs().maxCoeff(), 1e-14);
  Mat3 A;
  A << 0.9, 0.3, 0, 0, 1.2, -0.1, 0.2, 0, 0.7;
  Points x = m.V;
  for (Eigen::Index i = 0; i < x.rows(); ++i) x.row(i) = (A * m.V.row(i).transpose()).transpose();
  EXPECT_LT((apply_embedding(e, m.T, x) - P * A.transpose()).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(Embedding, OutsidePointsFollowThePolicy) {
  const TetMesh m = make_box_tet_mesh(2, 2, 2, Vec3(0.02, 0.02, 0.02));
  Points P(2, 3);
  P << 0.01, 0.01, 0.01, 0.01, 0.01, 0.023;  // second is 3 mm above the top face
  btr::test::expect_throw_with<InputError>([&] { embed_points(m, P, OutsidePolicy::Error); },
                                           "1 of 2 points lie outside the tetrahedral mesh (first: point 1)");
  const Embedding e = embed_points(m, P, OutsidePolicy::NearestTetrahedron);
  ASSERT_EQ(e.outside, std::vector<int>{1});
  EXPECT_NEAR(e.max_outside_distance, 0.003, 1e-12);
  EXPECT_LT((apply_embedding(e, m.T, m.V) - P).cwiseAbs().maxCoeff(), 1e-14);  // extrapolation is exact at rest
  Points bad = P;
  bad(0, 0) = std::numeric_limits<double>::quiet_NaN();
  btr::test::expect_throw_with<InputError>([&] { embed_points(m, bad); }, "NaN");
}
