#include <cmath>
#include <limits>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/box_mesh.h"
#include "breast_tumour_registration/geometry/self_intersection.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "test_util.h"

using namespace btr;
using btr::test::expect_throw_with;

TEST(ValidateSurface, ClosedOrientedShapesPass) {
  EXPECT_NO_THROW(validate_surface(make_icosphere(Vec3::Zero(), 1.0, 2), "sphere"));
  EXPECT_NO_THROW(validate_surface(make_half_ellipsoid(0.0745, 0.0745, 0.072, 8), "phantom"));
}

TEST(ValidateSurface, OpenSurfaceIsRejectedUnlessAllowed) {
  SurfaceMesh s = make_icosphere(Vec3::Zero(), 1.0, 1);
  s.F.conservativeResize(s.F.rows() - 1, 3);
  expect_throw_with<InputError>([&] { validate_surface(s, "scan.ply"); }, "scan.ply: surface is open");
  SurfaceCheckOptions open;
  open.require_closed = false;
  EXPECT_NO_THROW(validate_surface(s, "scan.ply", open));
}

TEST(ValidateSurface, FlippedFaceIsInconsistentlyOriented) {
  SurfaceMesh s = make_icosphere(Vec3::Zero(), 1.0, 1);
  std::swap(s.F(3, 1), s.F(3, 2));
  expect_throw_with<InputError>([&] { validate_surface(s, "m"); }, "inconsistently oriented");
}

TEST(ValidateSurface, NonManifoldEdgeNaNAndDegenerateFaces) {
  SurfaceMesh s = make_icosphere(Vec3::Zero(), 1.0, 1);
  SurfaceMesh nm = s;
  nm.V.conservativeResize(nm.V.rows() + 1, 3);
  nm.V.row(nm.V.rows() - 1) << 5, 5, 5;
  nm.F.conservativeResize(nm.F.rows() + 1, 3);
  nm.F.row(nm.F.rows() - 1) << s.F(0, 0), s.F(0, 1), static_cast<int>(nm.V.rows() - 1);
  expect_throw_with<InputError>([&] { validate_surface(nm, "m"); }, "non-manifold edge");
  SurfaceMesh nan = s;
  nan.V(4, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_throw_with<InputError>([&] { validate_surface(nan, "m"); }, "vertex 4 has a NaN");
  SurfaceMesh deg = s;
  deg.V.row(deg.F(2, 1)) = deg.V.row(deg.F(2, 0));
  expect_throw_with<InputError>([&] { validate_surface(deg, "m"); }, "zero area");
}

TEST(SelfIntersection, ASkinPushedThroughItselfIsSeenWhereValidationIsBlind) {
  SurfaceMesh s = make_icosphere(Vec3::Zero(), 0.05, 2);
  EXPECT_EQ(self_intersecting_face_pairs(s), 0);
  // One vertex pushed through the far side: the connectivity and orientation are as before.
  s.V.row(0) *= -1.6;
  validate_surface(s, "folded sphere");
  EXPECT_GT(self_intersecting_face_pairs(s), 0);
  s.F(0, 1) = static_cast<int>(s.V.rows());
  EXPECT_THROW(self_intersecting_face_pairs(s), InputError);
}

TEST(ValidateTetMesh, BoxPassesAndBoundaryIsClosed) {
  const TetMesh m = make_box_tet_mesh(3, 2, 4, Vec3(3, 2, 4));
  EXPECT_NO_THROW(validate_tet_mesh(m, "box"));
  const Triangles B = boundary_faces(m);
  EXPECT_EQ(B.rows(), 2 * 2 * (3 * 2 + 2 * 4 + 3 * 4));
  SurfaceMesh s{m.V, B};
  SurfaceCheckOptions o;
  EXPECT_NO_THROW(validate_surface(s, "boundary", o));
  // Outward orientation: positive enclosed volume.
  double vol = 0;
  for (Eigen::Index f = 0; f < B.rows(); ++f)
    vol += Vec3(m.V.row(B(f, 0))).dot(Vec3(m.V.row(B(f, 1))).cross(Vec3(m.V.row(B(f, 2))))) / 6.0;
  EXPECT_NEAR(vol, 24.0, 1e-12);
}

TEST(ValidateTetMesh, InvertedDegenerateAndOutOfRange) {
  TetMesh m = make_box_tet_mesh(2, 2, 2, Vec3(1, 1, 1));
  TetMesh inv = m;
  std::swap(inv.T(5, 0), inv.T(5, 1));
  expect_throw_with<InputError>([&] { validate_tet_mesh(inv, "prone.vtk"); }, "1 of 48 tetrahedra are inverted (first: 5)");
  TetMesh all = m;
  all.T.col(0).swap(all.T.col(1));
  EXPECT_TRUE(orient_tets_positive(all));
  EXPECT_NO_THROW(validate_tet_mesh(all, "flipped convention"));
  TetMesh deg = m;
  deg.V.row(deg.T(0, 3)) = 0.5 * (deg.V.row(deg.T(0, 0)) + deg.V.row(deg.T(0, 1)));
  expect_throw_with<InputError>([&] { validate_tet_mesh(deg, "m"); }, "degenerate");
  TetMesh oor = m;
  oor.T(7, 2) = 1000;
  expect_throw_with<InputError>([&] { validate_tet_mesh(oor, "m"); }, "tetrahedron 7 references vertex 1000");
}
