#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/tetrahedralize.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "test_util.h"

#include <cstdio>

using namespace btr;

namespace {

double enclosed_volume(const TetMesh& m) {
  double v = 0;
  for (Eigen::Index t = 0; t < m.T.rows(); ++t) v += tet_signed_volume(m.V, m.T, t);
  return v;
}

}  // namespace

TEST(Tetrahedralize, SphereIsFilledWithPositiveWellShapedTetrahedra) {
  const double r = 0.05;
  const SurfaceMesh s = make_icosphere(Vec3(0.01, 0.0, 0.02), r, 4);
  TetrahedralizeOptions opt;
  opt.cell_size = 0.012;
  const TetMesh m = tetrahedralize(s, opt);
  EXPECT_NO_THROW(validate_tet_mesh(m, "sphere"));
  EXPECT_GT(m.T.rows(), 100);
  EXPECT_NEAR(enclosed_volume(m), 4.0 / 3.0 * M_PI * r * r * r, 0.04 * 4.0 / 3.0 * M_PI * r * r * r);
  const TetQuality q = tet_quality(m);
  EXPECT_LT(q.median_radius_edge, 1.0);
  EXPECT_GT(q.min_dihedral_deg, 1.0);  // sliver exudation
  const TetMesh finer = tetrahedralize(s, TetrahedralizeOptions{0.006});
  EXPECT_GT(finer.T.rows(), 4 * m.T.rows());
}

// A stiff tumour on a 9 mm mesh holds a few tetrahedra and strains with the tissue around it;
// a refinement ball gives it finer cells (tumour_refinements in simulation_mesh.h).
TEST(Tetrahedralize, ARefinementBallHasFinerCellsInsideAndTheSkinKeepsItsSize) {
  const SurfaceMesh s = make_icosphere(Vec3::Zero(), 0.05, 4);
  TetrahedralizeOptions opt;
  opt.cell_size = 0.012;
  const TetMesh plain = tetrahedralize(s, opt);
  MeshRefinement ball;
  ball.centre = Vec3(0.01, 0.0, 0.0);
  ball.radius = 0.008;
  ball.cell_size = 0.004;
  opt.refinements = {ball};
  const TetMesh refined = tetrahedralize(s, opt);
  EXPECT_NO_THROW(validate_tet_mesh(refined, "refined sphere"));
  // Mean edge length of the tetrahedra whose centroid lies within `r` of the ball's centre.
  auto mean_edge_near = [&](const TetMesh& m, double r) {
    double sum = 0;
    int n = 0;
    for (Eigen::Index t = 0; t < m.T.rows(); ++t) {
      Vec3 c = Vec3::Zero();
      for (int k = 0; k < 4; ++k) c += m.V.row(m.T(t, k)).transpose() / 4;
      if ((c - ball.centre).norm() > r) continue;
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) sum += (m.V.row(m.T(t, a)) - m.V.row(m.T(t, b))).norm(), ++n;
    }
    return n ? sum / n : 0.0;
  };
  std::printf("mean edge in the ball: %.2f mm plain, %.2f mm refined; %ld -> %ld tetrahedra\n", 1e3 * mean_edge_near(plain, ball.radius),
              1e3 * mean_edge_near(refined, ball.radius), static_cast<long>(plain.T.rows()), static_cast<long>(refined.T.rows()));
  EXPECT_LT(mean_edge_near(refined, ball.radius), 0.6 * mean_edge_near(plain, ball.radius));
  EXPECT_GT(refined.T.rows(), plain.T.rows());
  EXPECT_LT(refined.T.rows(), 3 * plain.T.rows());  // graded back to 12 mm within (12 - 4) / 0.5 = 16 mm
  // A ball finer than nothing, or coarser than the mesh, is refused.
  opt.refinements[0].cell_size = 0.02;
  btr::test::expect_throw_with<InputError>([&] { tetrahedralize(s, opt); }, "a refinement needs");
}

TEST(Tetrahedralize, ACellSizeBeyondTheMemoryBudgetIsRefusedBeforeMeshing) {
  const SurfaceMesh s = make_icosphere(Vec3::Zero(), 0.07, 3);  // about the phantom's volume
  TetrahedralizeOptions opt;
  opt.cell_size = 0.0005;
  btr::test::expect_throw_with<InputError>([&] { tetrahedralize(s, opt); }, "this package budgets");
  // Where the refinement balls make it, the error says so, not "use a larger cell size".
  opt.cell_size = 0.01;
  opt.refinements = {MeshRefinement{Vec3::Zero(), 0.01, 1e-5}};
  btr::test::expect_throw_with<InputError>([&] { tetrahedralize(s, opt); },
                                           "refinement balls with cells of 0.010000 mm (1 ball, graded to 10.000000 mm)");
}

TEST(Tetrahedralize, BadOptionsAreRejected) {
  const SurfaceMesh s = make_icosphere(Vec3::Zero(), 0.05, 1);
  TetrahedralizeOptions opt;
  opt.cell_size = -1;
  btr::test::expect_throw_with<InputError>([&] { tetrahedralize(s, opt); }, "cell_size must be positive");
  opt.cell_size = 0.01;
  opt.radius_edge_ratio = 0.5;
  btr::test::expect_throw_with<InputError>([&] { tetrahedralize(s, opt); }, "radius_edge_ratio");
  opt.radius_edge_ratio = 2;
  // No surface at all (CGAL's domain crashed on it, e.g. an unmeshed scene's empty prone model)
  btr::test::expect_throw_with<InputError>([&] { tetrahedralize(SurfaceMesh{}, opt); }, "the surface has 0 faces");
}

// Landmarks are given as vertex indices of the input surface; Mesh_3 remeshes the boundary,
// so each is re-attached as an exact barycentric point on the tet boundary.
TEST(Tetrahedralize, LandmarkVerticesSurviveAsBoundaryAnchors) {
  const double a = 0.0745, c = 0.072;
  const SurfaceMesh s = make_half_ellipsoid(a, a, c, 12);
  TetrahedralizeOptions opt;
  opt.cell_size = 0.01;
  const TetMesh m = tetrahedralize(s, opt);
  const std::vector<int> landmark_vertices = {0, 5, 40, 100, 200};
  Points P(landmark_vertices.size(), 3);
  for (size_t i = 0; i < landmark_vertices.size(); ++i) P.row(i) = s.V.row(landmark_vertices[i]);
  const BoundaryAttachment att = attach_to_boundary(m, P);
  EXPECT_LE(att.max_distance, opt.facet_distance_ratio * opt.cell_size);
  // The anchors are material points: they follow any deformation of the mesh exactly,
  // e.g. an affine one.
  Mat3 A;
  A << 1.1, 0.1, 0, -0.05, 0.9, 0.2, 0, 0.1, 1.2;
  const Vec3 b(0.01, 0.02, -0.01);
  Points x = m.V;
  for (Eigen::Index i = 0; i < x.rows(); ++i) x.row(i) = (A * m.V.row(i).transpose() + b).transpose();
  for (size_t i = 0; i < att.anchors.size(); ++i) {
    const Vec3 rest = att.anchors[i].position(m.V);
    EXPECT_NEAR((rest - P.row(i).transpose()).norm(), att.distances[i], 1e-12);
    EXPECT_LT((att.anchors[i].position(x) - (A * rest + b)).norm(), 1e-12);
  }
}

TEST(Tetrahedralize, ChestWallVerticesSurviveAsTheFlatBase) {
  const double a = 0.0745, c = 0.072;
  const SurfaceMesh s = make_half_ellipsoid(a, a, c, 12);
  std::vector<int> chest;
  for (Eigen::Index i = 0; i < s.V.rows(); ++i)
    if (s.V(i, 2) == 0.0) chest.push_back(static_cast<int>(i));
  const TetMesh m = tetrahedralize(s, TetrahedralizeOptions{0.01});
  const std::vector<int> wall = boundary_vertices_near_region(m, s, chest, 1e-9);
  ASSERT_GT(wall.size(), 20u);
  int on_base = 0;
  for (int v : boundary_vertices(m)) on_base += std::abs(m.V(v, 2)) < 1e-9;
  EXPECT_EQ(static_cast<int>(wall.size()), on_base);
  for (int v : wall) EXPECT_LT(std::abs(m.V(v, 2)), 1e-9);
  btr::test::expect_throw_with<InputError>([&] { boundary_vertices_near_region(m, s, {0, 1}, 1e-9); },
                                           "contains no complete face");
}

// Issue 11: one input, one mesh. CGAL bounded its optimisers by the measured refinement time,
// so the same surface gave different meshes from run to run (10 640 to 10 647 tets).
TEST(Tetrahedralize, TheSameInputGivesTheSameMeshBitForBit) {
  const SurfaceMesh s = make_icosphere(Vec3(0.0, 0.01, 0.02), 0.06, 4);
  TetrahedralizeOptions opt;
  opt.cell_size = 0.007;
  const TetMesh a = tetrahedralize(s, opt), b = tetrahedralize(s, opt);
  ASSERT_EQ(a.T.rows(), b.T.rows());
  ASSERT_EQ(a.V.rows(), b.V.rows());
  EXPECT_TRUE(a.T == b.T);
  EXPECT_TRUE(a.V == b.V);  // bit-identical coordinates
}
