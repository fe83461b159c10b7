#include <cmath>
#include <cstdint>
#include <cstring>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "breast_tumour_registration/geometry/box_mesh.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/io/index_io.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "test_util.h"

using namespace btr;
using btr::test::expect_throw_with;
using btr::test::temp_dir;
using btr::test::write_text;

class SurfaceRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(SurfaceRoundTrip, MillimetreFileKeepsGeometryAndConnectivity) {
  const std::string dir = temp_dir();
  const SurfaceMesh s = make_icosphere(Vec3(0.01, -0.02, 0.03), 0.05, 2);
  const std::string path = dir + "/sphere" + GetParam();
  write_surface(path, s, LengthUnit::Millimetre);
  const SurfaceMesh r = read_surface(path, LengthUnit::Millimetre);
  ASSERT_EQ(r.V.rows(), s.V.rows());
  ASSERT_EQ(r.F.rows(), s.F.rows());
  // STL stores float32 and renumbers vertices in first-seen order: compare face corners.
  const double tol = GetParam() == ".stl" ? 1e-8 : 1e-15;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      EXPECT_LT((r.V.row(r.F(f, k)) - s.V.row(s.F(f, k))).norm(), tol + 1e-15);
}

INSTANTIATE_TEST_SUITE_P(Formats, SurfaceRoundTrip, ::testing::Values(".obj", ".ply", ".stl", ".off"));

TEST(MeshIo, UnitsAreAppliedOnceAtTheBoundary) {
  const std::string dir = temp_dir();
  write_text(dir + "/tri.obj", "v 0 0 0\nv 10 0 0\nv 0 20 0\nf 1 2 3\n");
  const SurfaceMesh mm = read_surface(dir + "/tri.obj", LengthUnit::Millimetre);
  EXPECT_DOUBLE_EQ(mm.V(1, 0), 0.010);
  EXPECT_DOUBLE_EQ(mm.V(2, 1), 0.020);
  const SurfaceMesh m = read_surface(dir + "/tri.obj", LengthUnit::Metre);
  EXPECT_DOUBLE_EQ(m.V(2, 1), 20.0);
  write_surface(dir + "/out.obj", mm, LengthUnit::Millimetre);
  EXPECT_DOUBLE_EQ(read_surface(dir + "/out.obj", LengthUnit::Millimetre).V(2, 1), 0.020);
}

TEST(MeshIo, ObjPolygonsAreFanTriangulatedAndSlashIndicesRead) {
  const std::string dir = temp_dir();
  write_text(dir + "/quad.obj", "# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n");
  const SurfaceMesh s = read_surface(dir + "/quad.obj", LengthUnit::Metre);
  ASSERT_EQ(s.F.rows(), 2);
  EXPECT_EQ(s.F(1, 0), 0);
  EXPECT_EQ(s.F(1, 2), 3);
}

TEST(MeshIo, BinaryLittleEndianPlyIsRead) {
  const std::string dir = temp_dir();
  std::string hdr = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  std::string body;
  const float v[9] = {0, 0, 0, 2, 0, 0, 0, 3, 0};
  body.append(reinterpret_cast<const char*>(v), sizeof(v));
  const uint8_t n = 3;
  const int32_t idx[3] = {0, 1, 2};
  body.append(reinterpret_cast<const char*>(&n), 1);
  body.append(reinterpret_cast<const char*>(idx), sizeof(idx));
  write_text(dir + "/b.ply", hdr + body);
  const SurfaceMesh s = read_surface(dir + "/b.ply", LengthUnit::Millimetre);
  ASSERT_EQ(s.V.rows(), 3);
  EXPECT_DOUBLE_EQ(s.V(2, 1), 0.003);
  EXPECT_EQ(s.F(0, 2), 2);
}

TEST(MeshIo, AsciiStlCornersAreMerged) {
  const std::string dir = temp_dir();
  write_text(dir + "/t.stl",
             "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
             "facet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n");
  const SurfaceMesh s = read_surface(dir + "/t.stl", LengthUnit::Metre);
  EXPECT_EQ(s.V.rows(), 4);
  EXPECT_EQ(s.F.rows(), 2);
}

class TetRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(TetRoundTrip, GeometryAndIndicesSurvive) {
  const std::string dir = temp_dir();
  const TetMesh m = make_box_tet_mesh(3, 2, 2, Vec3(0.03, 0.02, 0.02), Vec3(-0.01, 0, 0.005));
  const std::string path = dir + "/box" + GetParam();
  write_tet_mesh(path, m, LengthUnit::Millimetre);
  const TetMesh r = read_tet_mesh(path, LengthUnit::Millimetre);
  ASSERT_EQ(r.T, m.T);
  EXPECT_LT((r.V - m.V).cwiseAbs().maxCoeff(), 1e-15);
}

INSTANTIATE_TEST_SUITE_P(Formats, TetRoundTrip, ::testing::Values(".vtk", ".mesh"));

TEST(MeshIoErrors, MissingFileSaysSo) {
  expect_throw_with<InputError>([] { read_surface("/nonexistent/breast.obj", LengthUnit::Millimetre); }, "cannot open");
  expect_throw_with<InputError>([] { read_tet_mesh("/nonexistent/breast.vtk", LengthUnit::Millimetre); }, "cannot open");
}

TEST(MeshIoErrors, UnparsableLineNamesFileAndLine) {
  const std::string dir = temp_dir();
  write_text(dir + "/bad.obj", "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
  expect_throw_with<InputError>([&] { read_surface(dir + "/bad.obj", LengthUnit::Metre); }, "bad.obj:2: cannot parse number 'zero'");
}

TEST(MeshIoErrors, IndexOutOfRangeIsReported) {
  const std::string dir = temp_dir();
  write_text(dir + "/bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
  expect_throw_with<InputError>([&] { read_surface(dir + "/bad.obj", LengthUnit::Metre); }, "references vertex 6");
  write_text(dir + "/bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
  expect_throw_with<InputError>([&] { read_surface(dir + "/bad.off", LengthUnit::Metre); }, "references vertex 3");
}

TEST(MeshIoErrors, UnknownFormatAndNonTetCells) {
  const std::string dir = temp_dir();
  expect_throw_with<InputError>([&] { read_surface(dir + "/x.xyz", LengthUnit::Metre); }, "unknown surface format");
  write_text(dir + "/hex.vtk",
             "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 8 float\n"
             "0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1\nCELLS 1 9\n8 0 1 2 3 4 5 6 7\nCELL_TYPES 1\n12\n");
  expect_throw_with<InputError>([&] { read_tet_mesh(dir + "/hex.vtk", LengthUnit::Metre); }, "only tetrahedra");
  write_text(dir + "/trunc.mesh", "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n");
  // Refused at the count, before the vertices are read (issue 11: counts are checked first).
  expect_throw_with<InputError>([&] { read_tet_mesh(dir + "/trunc.mesh", LengthUnit::Metre); },
                                "trunc.mesh:4: vertex count 4 needs at least 16 values, the file holds 8 more");
}

TEST(IndexIo, IndexListAcceptsCommasWhitespaceAndComments) {
  const std::string dir = temp_dir();
  write_text(dir + "/chest.txt", "# chest wall\n1, 2,3\n4 5\t6 # tail\n\n7\n");
  EXPECT_EQ(read_index_list(dir + "/chest.txt"), (std::vector<int>{1, 2, 3, 4, 5, 6, 7}));
  write_text(dir + "/bad.txt", "1 2\n3 x\n");
  expect_throw_with<InputError>([&] { read_index_list(dir + "/bad.txt"); }, "bad.txt:2: 'x' is not a vertex index");
  expect_throw_with<InputError>([] { check_index_range({0, 5, 12}, 10, "chest wall"); }, "entry 2 is vertex 12");
}

TEST(IndexIo, LandmarkPairsWithVertexOrPointTargets) {
  const std::string dir = temp_dir();
  write_text(dir + "/lm.csv", "prone,supine\n3,7\n# comment\n4,9\n");
  auto p = read_landmark_pairs(dir + "/lm.csv", LengthUnit::Millimetre);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[1].prone_vertex, 4);
  EXPECT_EQ(p[1].supine_vertex, 9);
  write_text(dir + "/pts.csv", "prone_index,x,y,z\n3,10,20,30\n");
  p = read_landmark_pairs(dir + "/pts.csv", LengthUnit::Millimetre);
  EXPECT_EQ(p[0].supine_vertex, -1);
  EXPECT_DOUBLE_EQ(p[0].supine_point.z(), 0.030);
  write_landmark_pairs(dir + "/out.csv", p, LengthUnit::Millimetre);
  EXPECT_DOUBLE_EQ(read_landmark_pairs(dir + "/out.csv", LengthUnit::Millimetre)[0].supine_point.y(), 0.020);
  write_text(dir + "/bad.csv", "3,7\n4,9,1\n");
  expect_throw_with<InputError>([&] { read_landmark_pairs(dir + "/bad.csv", LengthUnit::Metre); }, "bad.csv:2: expected");
}

TEST(PointCloudIo, VertexOnlyPlyAndObjAreCloudsButNotSurfaces) {
  const std::string dir = temp_dir();
  write_text(dir + "/pts.obj", "v 0 0 0\nv 10 0 0\nv 0 20 0\nv 0 0 30\n");
  write_text(dir + "/pts.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                               "property float z\nend_header\n1 2 3\n4 5 6\n");
  const Points a = read_point_cloud(dir + "/pts.obj", LengthUnit::Millimetre);
  ASSERT_EQ(a.rows(), 4);
  EXPECT_DOUBLE_EQ(a(3, 2), 0.030);
  const Points b = read_point_cloud(dir + "/pts.ply", LengthUnit::Metre);
  ASSERT_EQ(b.rows(), 2);
  EXPECT_DOUBLE_EQ(b(1, 0), 4.0);
  expect_throw_with<InputError>([&] { read_surface(dir + "/pts.obj", LengthUnit::Millimetre); }, "no faces");
}

// Issue 11: indices of 2^31 and above no longer wrap to valid vertices, a header's counts are
// checked against what the file holds before anything is allocated, and a malformed first
// landmark row is an error instead of a skipped header.
TEST(MeshIoErrors, HostileCountsAndIndicesAreRefusedBeforeAllocating) {
  const std::string dir = btr::test::temp_dir();
  btr::test::write_text(dir + "/wrap.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4294967299\n");
  expect_throw_with<InputError>([&] { read_surface(dir + "/wrap.obj", LengthUnit::Metre); }, "out of range (at most 2^31 - 1)");
  btr::test::write_text(dir + "/huge.vtk", "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                                            "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 200000000 1000000000\n4 0 1 2 3\n");
  expect_throw_with<InputError>([&] { read_tet_mesh(dir + "/huge.vtk", LengthUnit::Metre); },
                                "cell count 200000000 needs at least 400000000 values, the file holds");
  btr::test::write_text(dir + "/negative.vtk", "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS -5 double\n");
  expect_throw_with<InputError>([&] { read_tet_mesh(dir + "/negative.vtk", LengthUnit::Metre); }, "point count -5 is negative");
  btr::test::write_text(dir + "/huge.off", "OFF\n100000000 1 0\n0 0 0\n");
  expect_throw_with<InputError>([&] { read_surface(dir + "/huge.off", LengthUnit::Metre); }, "more than the file holds");
  btr::test::write_text(dir + "/wrap.txt", "1 2 4294967296\n");
  expect_throw_with<InputError>([&] { read_index_list(dir + "/wrap.txt"); }, "is not a vertex index (0 to 2^31 - 1)");
  btr::test::write_text(dir + "/wrap.csv", "prone_index,x,y,z\n4294967296,1,2,3\n");
  expect_throw_with<InputError>([&] { read_landmark_pairs(dir + "/wrap.csv", LengthUnit::Metre); }, "is not a prone vertex index");
  btr::test::write_text(dir + "/first_row.csv", "12a,1,2,3\n5,1,2,3\n");
  expect_throw_with<InputError>([&] { read_landmark_pairs(dir + "/first_row.csv", LengthUnit::Metre); },
                                "first_row.csv:1: '12a' is not a prone vertex index");
  btr::test::write_text(dir + "/header.csv", "prone_index,x,y,z\n5,1,2,3\n");
  EXPECT_EQ(read_landmark_pairs(dir + "/header.csv", LengthUnit::Metre).size(), 1u);
}

// Issue 13: tissue labels travel with the tetrahedral mesh (VTK cell data, Medit references).
class TetLabelRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(TetLabelRoundTrip, LabelsSurvive) {
  const TetMesh m = make_box_tet_mesh(2, 1, 1, Vec3(0.02, 0.01, 0.01));
  std::vector<int> labels(m.T.rows());
  for (Eigen::Index t = 0; t < m.T.rows(); ++t) labels[t] = 1 + static_cast<int>(t % 3);
  const std::string path = temp_dir() + "/labelled" + GetParam();
  write_tet_mesh(path, m, LengthUnit::Millimetre, labels);
  const TetMeshFile f = read_tet_mesh_file(path, LengthUnit::Millimetre);
  EXPECT_EQ(f.mesh.T, m.T);
  EXPECT_EQ(cell_labels(f, "", path), labels);
}

INSTANTIATE_TEST_SUITE_P(Formats, TetLabelRoundTrip, ::testing::Values(".vtk", ".mesh"));

TEST(MeshIo, VtkCellDataOfOtherToolsIsRead) {
  // As meshio and TetGen write it: point data first, a FIELD block, SCALARS with a lookup
  // table, and triangle cells (skipped, with their cell data) before the tetrahedra.
  const std::string dir = temp_dir();
  write_text(dir + "/two.vtk",
             "# vtk DataFile Version 4.2\ntitle\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n"
             "0 0 0\n10 0 0\n0 10 0\n0 0 10\n10 10 10\nCELLS 3 13\n3 0 1 2\n4 0 1 2 3\n4 1 2 3 4\n"
             "CELL_TYPES 3\n5\n10\n10\n"
             "POINT_DATA 5\nVECTORS disp double\n0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n"
             "CELL_DATA 3\nFIELD FieldData 2\ntissue 1 3 int\n9 1 2\nstrain 3 3 double\n0 0 0 0 0 0 0 0 0\n"
             "SCALARS quality float 1\nLOOKUP_TABLE default\n0.5 0.7 0.8\n");
  const TetMeshFile f = read_tet_mesh_file(dir + "/two.vtk", LengthUnit::Millimetre);
  ASSERT_EQ(f.mesh.T.rows(), 2);
  EXPECT_EQ(cell_labels(f, "tissue", dir + "/two.vtk"), (std::vector<int>{1, 2}));
  expect_throw_with<InputError>([&] { cell_labels(f, "", dir + "/two.vtk"); }, "name the labels with prone.cell_labels");
  expect_throw_with<InputError>([&] { cell_labels(f, "gland", dir + "/two.vtk"); }, "no one-component cell array 'gland'");
  expect_throw_with<InputError>([&] { cell_labels(f, "quality", dir + "/two.vtk"); }, "not an integer");
}

TEST(MeshIoErrors, CellDataThatDoesNotFitTheCellsIsRefused) {
  const std::string dir = temp_dir();
  const std::string head = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n"
                           "0 0 0\n10 0 0\n0 10 0\n0 0 10\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n";
  write_text(dir + "/count.vtk", head + "CELL_DATA 2\nSCALARS label int 1\nLOOKUP_TABLE default\n1 2\n");
  expect_throw_with<InputError>([&] { read_tet_mesh_file(dir + "/count.vtk", LengthUnit::Millimetre); },
                                "CELL_DATA 2 does not match the 1 cells");
  write_text(dir + "/short.vtk", head + "CELL_DATA 1\nSCALARS label int 1\nLOOKUP_TABLE default\n");
  expect_throw_with<InputError>([&] { read_tet_mesh_file(dir + "/short.vtk", LengthUnit::Millimetre); }, "needs 1 values");
  write_text(dir + "/none.vtk", head);
  const TetMeshFile f = read_tet_mesh_file(dir + "/none.vtk", LengthUnit::Millimetre);
  expect_throw_with<InputError>([&] { cell_labels(f, "", dir + "/none.vtk"); }, "no cell labels");
  expect_throw_with<InputError>([&] { write_tet_mesh(dir + "/bad.vtk", f.mesh, LengthUnit::Millimetre, {1, 2}); },
                                "2 cell labels for 1 tetrahedra");
}

// The one number parser every reader uses (std::from_chars, no locale, no wrap-around).
TEST(NumberParsing, WholeTokenOrNothing) {
  EXPECT_EQ(parse_number("1.5e-3").value(), 1.5e-3);
  EXPECT_EQ(parse_number("+2").value(), 2.0);
  EXPECT_EQ(parse_number("-0.25").value(), -0.25);
  EXPECT_TRUE(std::isinf(parse_number("inf").value()));
  for (const char* bad : {"", "+", "1.5mm", " 1", "1 ", "--1", "+-1", "1e999", "zero", "0x10"})
    EXPECT_FALSE(parse_number(bad).has_value()) << bad;
  EXPECT_EQ(parse_integer("2147483647").value(), 2147483647);
  EXPECT_EQ(parse_integer("-7").value(), -7);
  EXPECT_EQ(parse_integer("+7").value(), 7);
  for (const char* bad : {"2147483648", "1.0", "7a", "", "4294967296"}) EXPECT_FALSE(parse_integer(bad).has_value()) << bad;
}

TEST(CsvField, SeparatorsQuotesAndLineBreaksCannotSplitARow) {
  EXPECT_EQ(csv_field("stalled: a, b \"c\"\r\nd"), "stalled: a; b ;c;;;d");
  EXPECT_EQ(csv_field("plain"), "plain");
}
