// Issue 15: segmented images in (NIfTI, NRRD), Slicer point lists, the multi-material mesher and
// the phantom's label-map round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/label_mesher.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/io/label_scene.h"
#include "breast_tumour_registration/io/label_volume_io.h"
#include "breast_tumour_registration/io/markups_io.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/simulation/registration_report.h"
#include "breast_tumour_registration/simulation/label_phantom.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"
#include "test_util.h"

namespace btr {
namespace {

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// A synthetic breast on a 1 mm grid: a half ellipsoid of fat (label 1) on a muscle slab (4),
// a ball of tumour (3) inside; RAS, chest wall the plane y = 0, breast towards +y.
LabelVolume synthetic_breast(double voxel = 0.001, double tumour_radius = 0.008) {
  LabelVolume v;
  v.nx = v.nz = static_cast<int>(std::round(0.09 / voxel));
  v.ny = static_cast<int>(std::round(0.05 / voxel));
  v.ijk_to_ras = Mat3::Identity() * voxel;
  const int back = static_cast<int>(std::round(0.006 / voxel));
  v.origin = Vec3(-0.045, -(back - 0.5) * voxel, -0.045);
  v.labels.assign(static_cast<size_t>(v.voxel_count()), 0);
  const Vec3 tumour_centre(0.004, 0.015, -0.003);
  for (int k = 0; k < v.nz; ++k)
    for (int j = 0; j < v.ny; ++j)
      for (int i = 0; i < v.nx; ++i) {
        const Vec3 p = v.centre(i, j, k);
        const double r = std::pow(p.x() / 0.04, 2) + std::pow(p.y() / 0.035, 2) + std::pow(p.z() / 0.04, 2);
        std::uint8_t l = 0;
        if (p.y() > 0 && r < 1) l = (p - tumour_centre).norm() < tumour_radius ? 3 : 1;
        else if (p.y() < 0 && p.y() > -0.005 && std::pow(p.x() / 0.04, 2) + std::pow(p.z() / 0.04, 2) < 1) l = 4;
        v.labels[static_cast<size_t>(v.index(i, j, k))] = l;
      }
  return v;
}

// The synthetic breast's labels: fat tissue, the tumour, the muscle; 7 mm cells.
LabelMeshOptions synthetic_breast_options() {
  LabelMeshOptions o;
  o.tissue = {1};
  o.tumour = {3};
  o.muscle = 4;
  o.cell_size = 0.007;
  return o;
}

TEST(LabelVolumeIo, NiftiAndNrrdKeepTheGeometryTheLabelsAndTheSegmentNames) {
  const std::string dir = test::temp_dir();
  LabelVolume v;
  v.nx = 5, v.ny = 4, v.nz = 3;
  // A rotated, flipped, anisotropic grid: 30 deg about z, i reversed.
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  Mat3 R;
  R << c, -s, 0, s, c, 0, 0, 0, 1;
  v.ijk_to_ras = R * Vec3(-0.0008, 0.0009, 0.0012).asDiagonal();
  v.origin = Vec3(0.01, -0.02, 0.03);
  for (long i = 0; i < v.voxel_count(); ++i) v.labels.push_back(static_cast<std::uint8_t>(i % 7));
  v.names = {{1, "fat"}, {3, "tumour"}};
  for (const std::string f : {"v.nii.gz", "v.nii", "v.nrrd"}) {
    write_label_volume(dir + "/" + f, v);
    const LabelVolume r = read_label_volume(dir + "/" + f);
    EXPECT_EQ(r.nx, 5) << f;
    EXPECT_EQ(r.ny, 4) << f;
    EXPECT_EQ(r.nz, 3) << f;
    EXPECT_EQ(r.labels, v.labels) << f;
    EXPECT_LT((r.ijk_to_ras - v.ijk_to_ras).norm(), 1e-9) << f;  // NIfTI's float qform is not used: the sform is double
    EXPECT_LT((r.origin - v.origin).norm(), 1e-9) << f;
    if (f == "v.nrrd") {
      EXPECT_EQ(r.names, v.names);
    }
  }
  // An NRRD written in RAS reads the same as one in LPS.
  write_label_volume(dir + "/ras.nrrd", v, PatientFrame::RAS);
  EXPECT_LT((read_label_volume(dir + "/ras.nrrd").origin - v.origin).norm(), 1e-9);
}

TEST(LabelVolumeIo, FilesThatAreNoLabelMapSayWhatIsWrongAndWhatToDo) {
  const std::string dir = test::temp_dir();
  auto nrrd = [&](const std::string& name, const std::string& header, const std::string& data) {
    test::write_text(dir + "/" + name, "NRRD0004\n" + header + "encoding: ascii\n\n" + data);
    return dir + "/" + name;
  };
  const std::string geometry = "space: left-posterior-superior\nspace directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (0,0,0)\n";
  EXPECT_NE(message_of([&] { read_label_volume(nrrd("noorient.nrrd", "type: uchar\ndimension: 3\nsizes: 2 2 2\n", "0 1 0 1 0 1 0 1")); })
                .find("no patient space"),
            std::string::npos);
  EXPECT_NE(message_of([&] { read_label_volume(nrrd("float.nrrd", "type: float\ndimension: 3\nsizes: 2 2 2\n" + geometry, "0 0.5 0 1 0 1 0 1")); })
                .find("not labels"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              read_label_volume(nrrd("huge.nrrd", "type: uchar\ndimension: 3\nsizes: 2000 2000 2000\n" + geometry, "0"));
            }).find("crop the volume"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              read_label_volume(nrrd("layers.seg.nrrd",
                                     "type: uchar\ndimension: 4\nsizes: 3 2 2 2\nspace: left-posterior-superior\n"
                                     "space directions: none (1,0,0) (0,1,0) (0,0,1)\nspace origin: (0,0,0)\n",
                                     std::string(48, '0')));
            }).find("Export to labelmap"),
            std::string::npos);
  EXPECT_NE(message_of([&] { read_label_volume(dir + "/missing.nii.gz"); }).find("no such file"), std::string::npos);
  {  // A NIfTI-1 file whose qform and sform codes are 0: voxels without a place on the patient.
    std::vector<char> hdr(352, 0);
    auto put = [&](size_t at, const void* v, size_t n) { std::memcpy(hdr.data() + at, v, n); };
    const int32_t sizeof_hdr = 348;
    const int16_t dim[8] = {3, 2, 2, 2, 1, 1, 1, 1}, datatype = 2, bitpix = 8;
    const float pixdim[8] = {1, 1, 1, 1, 0, 0, 0, 0}, vox_offset = 352;
    put(0, &sizeof_hdr, 4);
    put(40, dim, sizeof dim);
    put(70, &datatype, 2);
    put(72, &bitpix, 2);
    put(76, pixdim, sizeof pixdim);
    put(108, &vox_offset, 4);
    put(344, "n+1", 4);
    std::ofstream out(dir + "/noorient.nii", std::ios::binary);
    out.write(hdr.data(), static_cast<std::streamsize>(hdr.size()));
    const char data[8] = {0, 1, 0, 1, 0, 1, 0, 1};
    out.write(data, 8);
  }
  EXPECT_NE(message_of([&] { read_label_volume(dir + "/noorient.nii"); }).find("no orientation (sform_code and qform_code are 0)"),
            std::string::npos);
  test::write_text(dir + "/x.mha", "x");
  EXPECT_NE(message_of([&] { read_label_volume(dir + "/x.mha"); }).find("unknown label map format"), std::string::npos);
  test::write_text(dir + "/bad.nii", "not a nifti file at all");
  EXPECT_NE(message_of([&] { read_label_volume(dir + "/bad.nii"); }).find("not a readable NIfTI"), std::string::npos);
}

TEST(LabelMesher, MeshesTissueAndTumourFixesTheMuscleInterfaceAndReturnsTheTumourSurface) {
  const LabelVolume v = synthetic_breast();
  const LabelMeshOptions o = synthetic_breast_options();
  const LabelledTetMesh m = mesh_label_volume(v, o);
  ASSERT_GT(m.mesh.T.rows(), 1000);
  std::map<int, long> count;
  for (int l : m.labels) ++count[l];
  EXPECT_GT(count[1], 0);
  EXPECT_GT(count[3], 0);
  EXPECT_EQ(count.size(), 2u);  // no muscle, no air
  for (Eigen::Index t = 0; t < m.mesh.T.rows(); ++t) ASSERT_GT(tet_signed_volume(m.mesh.V, m.mesh.T, t), 0);
  // The chest wall is the interface with the muscle: the plane y = 0, all of its disc.
  EXPECT_TRUE(m.chest_wall_from_muscle);
  // Mesh_3 puts a facet on the interface when its dual crosses it, so along the rim (where fat,
  // muscle and air meet) a few of their vertices sit on the skin, up to 2.5 mm above the plane
  // (measured, 7 mm cells; 90 % within 0.58 mm on 1 mm voxels): the bound is 0.4 cell sizes for
  // all, 3/4 of a voxel for 90 %.
  std::vector<double> off;
  double r_max = 0;
  for (int i : m.chest_wall) {
    off.push_back(std::abs(m.mesh.V(i, 1)));
    r_max = std::max(r_max, std::hypot(m.mesh.V(i, 0), m.mesh.V(i, 2)));
  }
  std::sort(off.begin(), off.end());
  EXPECT_LT(off.back(), 0.4 * o.cell_size) << "chest-wall vertices off the plane y = 0";
  EXPECT_LT(off[off.size() * 9 / 10], 0.00075) << "chest-wall vertices off the plane y = 0";
  EXPECT_GT(r_max, 0.036) << "the chest wall does not reach the rim";
  // The tumour: one closed surface, volume and centroid of the 8 mm ball.
  ASSERT_EQ(m.tumours.size(), 1u);
  const SurfaceMesh& t = m.tumours[0].surface;
  const double ball = 4.0 / 3.0 * M_PI * std::pow(0.008, 3);
  EXPECT_NEAR(enclosed_volume(t) / ball, 1.0, 0.05);
  EXPECT_LT((volume_centroid(t) - Vec3(0.004, 0.015, -0.003)).norm(), 0.0003);
  // Without a muscle label the posterior-most skin is fixed: the same plane.
  LabelMeshOptions flat = o;
  flat.muscle = -1;
  LabelVolume no_muscle = v;
  for (auto& l : no_muscle.labels)
    if (l == 4) l = 0;
  const LabelledTetMesh f = mesh_label_volume(no_muscle, flat);
  EXPECT_FALSE(f.chest_wall_from_muscle);
  ASSERT_GT(f.chest_wall.size(), 20u);
  for (int i : f.chest_wall) EXPECT_LT(f.mesh.V(i, 1), 0.0036);
}

// Two breasts side by side, as a bilateral MRI has them: the image's centre is in the air between
// them. The right one's tumour is half a ring (tube 3 mm, ring 12 mm), whose own box's centre is
// outside it. CGAL's make_mesh_3 starts from rays shot from a box's centre and never returned on
// either (the phantom's label map, whose centre is in the air, hung the same way).
TEST(LabelMesher, MeshesAMapWhoseCentreIsOutsideTheTissueAndATumourWhoseCentreIsOutsideIt) {
  const LabelVolume one = synthetic_breast(0.002);
  LabelVolume v = one;
  v.nx = 2 * one.nx;
  v.labels.assign(static_cast<size_t>(v.voxel_count()), 0);
  const Vec3 ball(0.004, 0.015, -0.003), ring = ball + Vec3(one.nx * 0.002, 0, 0);
  long ball_voxels = 0, ring_voxels = 0;
  Vec3 ring_sum = Vec3::Zero();
  for (int k = 0; k < v.nz; ++k)
    for (int j = 0; j < v.ny; ++j)
      for (int i = 0; i < v.nx; ++i) {
        std::uint8_t l = one.at(i < one.nx ? i : i - one.nx, j, k);
        const Vec3 d = v.centre(i, j, k) - ring;
        if (i >= one.nx && l == 3) l = 1;
        const double off_ring = std::hypot(std::hypot(d.x(), d.z()) - 0.012, d.y());
        if (i >= one.nx && d.z() >= 0 && off_ring < 0.003) {
          l = 3;
          ++ring_voxels;
          ring_sum += v.centre(i, j, k);
        }
        if (i < one.nx && l == 3) ++ball_voxels;
        v.labels[static_cast<size_t>(v.index(i, j, k))] = l;
      }
  ASSERT_GT(ring_voxels, 100);
  const Vec3 centre = v.centre(v.nx / 2, v.ny / 2, v.nz / 2);
  ASSERT_EQ(v.at(v.nx / 2, v.ny / 2, v.nz / 2), 0) << "the image's centre (" << centre.transpose() << ") is not in the air";
  const LabelMeshOptions o = synthetic_breast_options();
  const LabelledTetMesh m = mesh_label_volume(v, o);
  ASSERT_GT(m.mesh.T.rows(), 1000);
  double left = 0, right = 0;  // each breast's volume, by the x of its tetrahedra's first vertex
  for (Eigen::Index t = 0; t < m.mesh.T.rows(); ++t)
    (m.mesh.V(m.mesh.T(t, 0), 0) < 0.045 ? left : right) += tet_signed_volume(m.mesh.V, m.mesh.T, t);
  EXPECT_NEAR(left / right, 1.0, 0.02);
  EXPECT_TRUE(m.chest_wall_from_muscle);
  // The tumours, largest first: each closed, with the volume and centroid of its voxels.
  ASSERT_EQ(m.tumours.size(), 2u);
  const double voxel = std::pow(0.002, 3);
  EXPECT_NEAR(enclosed_volume(m.tumours[0].surface) / (static_cast<double>(ball_voxels) * voxel), 1.0, 0.1);
  EXPECT_LT((volume_centroid(m.tumours[0].surface) - ball).norm(), 0.0005);
  EXPECT_NEAR(enclosed_volume(m.tumours[1].surface) / (static_cast<double>(ring_voxels) * voxel), 1.0, 0.15);
  EXPECT_LT((volume_centroid(m.tumours[1].surface) - ring_sum / static_cast<double>(ring_voxels)).norm(), 0.001);
  // One input, one mesh.
  const LabelledTetMesh again = mesh_label_volume(v, o);
  ASSERT_EQ(again.mesh.V.rows(), m.mesh.V.rows());
  EXPECT_EQ((again.mesh.V - m.mesh.V).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((again.tumours[1].surface.V - m.tumours[1].surface.V).cwiseAbs().maxCoeff(), 0.0);
}

// Specks of a tissue label (single voxels of gland in the fat, as a blocky or noisy segmentation
// has them) are meshed where the refinement finds them, but do not start rays of their own: with
// every speck seeding, SfePy's body as a label map had twice the tetrahedra and one flat.
TEST(LabelMesher, SpecksOfATissueLabelDoNotSeedTheMesh) {
  const LabelVolume clean = synthetic_breast();
  LabelVolume v = clean;
  std::mt19937 rng(7);
  std::uniform_int_distribution<long> any(0, v.voxel_count() - 1);
  int specks = 0;
  while (specks < 300) {
    const long n = any(rng);
    if (v.labels[static_cast<size_t>(n)] == 1) {
      v.labels[static_cast<size_t>(n)] = 2;
      ++specks;
    }
  }
  LabelMeshOptions o = synthetic_breast_options();
  o.tissue = {1, 2};
  const LabelledTetMesh a = mesh_label_volume(clean, o), b = mesh_label_volume(v, o);
  EXPECT_NO_THROW(validate_tet_mesh(b.mesh, "speckled"));
  EXPECT_LT(static_cast<double>(b.mesh.T.rows()) / static_cast<double>(a.mesh.T.rows()), 1.2)
      << a.mesh.T.rows() << " tetrahedra without the specks, " << b.mesh.T.rows() << " with";
}

TEST(LabelMesher, RefusesEmptyTumoursMissingMusclesAnisotropicVoxelsAndUnknownLabels) {
  LabelVolume v = synthetic_breast(0.002);
  LabelMeshOptions o;
  o.tissue = {1};
  o.tumour = {5};
  o.muscle = 4;
  o.source = "breast.nii.gz";
  EXPECT_NE(message_of([&] { mesh_label_volume(v, o); }).find("breast.nii.gz: the tumour label 5 has no voxels"), std::string::npos);
  o.tumour = {3};
  o.muscle = 6;
  EXPECT_NE(message_of([&] { mesh_label_volume(v, o); }).find("muscle label 6 has no voxels"), std::string::npos);
  o.muscle = 4;
  LabelVolume thick = v;
  thick.ijk_to_ras(2, 2) = 0.012;
  o.cell_size = 0.02;
  EXPECT_NE(message_of([&] { mesh_label_volume(thick, o); }).find("too anisotropic"), std::string::npos);
  // The label table must account for every label in the image.
  LabelTable table;
  table.muscle = -1;
  EXPECT_NE(message_of([&] { check_label_table(table, v, "breast.nii.gz"); }).find("labels not in the label table: 4"), std::string::npos);
  table.muscle = 4;
  table.gland = {1};
  EXPECT_NE(message_of([&] { check_label_table(table, v, "breast.nii.gz"); }).find("label 1 is both fat and gland"), std::string::npos);
}

TEST(LabelTable, SegmentNamesStandForLabelValuesAndUnknownKeysOrNamesAreNamed) {
  const std::string dir = test::temp_dir();
  LabelVolume v = synthetic_breast(0.002);
  v.names = {{1, "Adipose"}, {3, "Lesion"}, {4, "Pectoralis"}};
  test::write_text(dir + "/t.yaml", "fat: [adipose]\ntumour: [Lesion]\nmuscle: Pectoralis\nstiffness: {tumour: 8}\n");
  const LabelTable t = read_label_table(dir + "/t.yaml", v);
  EXPECT_EQ(t.fat, std::vector<int>{1});
  EXPECT_EQ(t.tumour, std::vector<int>{3});
  EXPECT_EQ(t.muscle, 4);
  EXPECT_EQ(t.tumour_stiffness, 8);
  test::write_text(dir + "/u.yaml", "tumor: [3]\n");
  EXPECT_NE(message_of([&] { read_label_table(dir + "/u.yaml", v); }).find("did you mean tumour"), std::string::npos);
  test::write_text(dir + "/w.yaml", "tumour: [Cyst]\n");
  EXPECT_NE(message_of([&] { read_label_table(dir + "/w.yaml", v); }).find("segments: Adipose, Lesion, Pectoralis"), std::string::npos);
}

TEST(Markups, SlicerPointListsAreReadInTheFrameAskedForAndMatchedByLabel) {
  const std::string dir = test::temp_dir();
  const std::vector<NamedPoint> ras = {{"N1", Vec3(0.010, 0.020, 0.030)}, {"N2", Vec3(-0.005, 0.001, 0.002)}};
  write_markups(dir + "/p.mrk.json", ras, PatientFrame::RAS, PatientFrame::LPS);
  const auto lps = read_markups(dir + "/p.mrk.json", PatientFrame::LPS);
  ASSERT_EQ(lps.size(), 2u);
  EXPECT_LT((lps[0].position - Vec3(-0.010, -0.020, 0.030)).norm(), 1e-12);
  const auto back = read_markups(dir + "/p.mrk.json", PatientFrame::RAS);
  EXPECT_LT((back[1].position - ras[1].position).norm(), 1e-12);
  // .fcsv: with the coordinate system stated (LPS), and without (Slicer < 4.11: RAS).
  test::write_text(dir + "/a.fcsv",
                   "# Markups fiducial file version = 4.11\n# CoordinateSystem = LPS\n"
                   "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID\n"
                   "vtkMRMLMarkupsFiducialNode_0,10,20,30,0,0,0,1,1,1,0,N2,,\n"
                   "vtkMRMLMarkupsFiducialNode_1,1,2,3,0,0,0,1,1,1,0,\"N3, extra\",,\n");
  const auto a = read_markups(dir + "/a.fcsv", PatientFrame::RAS);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_LT((a[0].position - Vec3(-0.010, -0.020, 0.030)).norm(), 1e-12);
  EXPECT_EQ(a[1].label, "N3, extra");
  test::write_text(dir + "/old.fcsv", "# Markups fiducial file version = 4.6\nF_0,10,20,30,0,0,0,1,1,1,0,N1,,\n");
  EXPECT_LT((read_markups(dir + "/old.fcsv", PatientFrame::RAS)[0].position - Vec3(0.010, 0.020, 0.030)).norm(), 1e-12);
  const MatchedPoints m = match_by_label(back, a);
  ASSERT_EQ(m.labels, std::vector<std::string>{"N2"});
  EXPECT_EQ(m.unmatched.size(), 2u);  // N1 and "N3, extra"
  // Errors name the file and what is wrong.
  test::write_text(dir + "/bad.mrk.json", "{\"markups\": [");
  EXPECT_NE(message_of([&] { read_markups(dir + "/bad.mrk.json", PatientFrame::RAS); }).find("not valid JSON"), std::string::npos);
  test::write_text(dir + "/dup.fcsv", "F_0,1,2,3,0,0,0,1,1,1,0,N1,,\nF_1,1,2,3,0,0,0,1,1,1,0,N1,,\n");
  EXPECT_NE(message_of([&] { read_markups(dir + "/dup.fcsv", PatientFrame::RAS); }).find("'N1' is used twice"), std::string::npos);
  test::write_text(dir + "/sys.mrk.json",
                   "{\"markups\": [{\"coordinateSystem\": \"XYZ\", \"controlPoints\": [{\"label\": \"a\", \"position\": [1,2,3]}]}]}");
  EXPECT_NE(message_of([&] { read_markups(dir + "/sys.mrk.json", PatientFrame::RAS); }).find("coordinate system 'XYZ'"), std::string::npos);
}

// The phantom as a segmented image: label map (1 mm voxels) -> btr_scene_from_labels' scene ->
// registration, against the same registration on the phantom's own scene. Both with the pose
// given (landmarks, surface), the phantom's 8 mm mesh and the label scene's default 7 mm one.
TEST(LabelMapRoundTrip, ThePhantomFromItsLabelMapRegistersAsThePhantomWithin01mm) {
  const std::string dir = test::temp_dir();
  PhantomSceneOptions po;
  po.phantom.tet.cell_size = 0.008;
  write_phantom_scene(dir + "/phantom", po);
  const LabelPhantomFiles f = write_label_phantom(dir + "/phantom/scene.yaml", dir + "/labels");
  const LabelVolume v = read_label_volume(f.label_map);
  LabelTable table;  // the defaults, with the phantom's homogeneous material
  table.gland_stiffness = table.tumour_stiffness = 1;
  LabelSceneOptions o;
  o.mesh.source = f.label_map;
  o.prone_landmarks = f.prone_landmarks;
  o.supine_landmarks = f.supine_landmarks;
  o.supine_surface = f.supine_surface;
  o.prone_image = false;  // as the phantom's scene: the prone shape is the rest shape
  o.truth = f.tumour_truth;
  const LabelSceneSummary sum = write_scene_from_labels(dir + "/scene", v, table, o);
  EXPECT_TRUE(sum.chest_wall_from_muscle);
  ASSERT_EQ(sum.tumour_centroids.size(), 5u);

  auto register_scene = [](const std::string& path) {
    Scene s = load_meshed_scene(path);
    s.steps = {"landmarks", "surface"};
    RegistrationEngine engine(s);
    return engine.solve(preset_options("balanced"));
  };
  const RegistrationResult ph = register_scene(dir + "/phantom/scene.yaml");
  const RegistrationResult lb = register_scene(dir + "/scene/scene.yaml");
  std::map<std::string, double> phantom_error;
  for (const auto& t : ph.tumours) phantom_error[t.name] = t.centroid_distance;
  ASSERT_EQ(lb.tumours.size(), 5u);
  const Mat3 R = phantom_to_ras();
  for (const auto& t : lb.tumours) {
    ASSERT_TRUE(t.has_ground_truth) << t.name;
    ASSERT_TRUE(phantom_error.count(t.name)) << t.name;
    EXPECT_LT(t.centroid_distance, phantom_error[t.name] + 1e-4)
        << t.name << ": label scene " << t.centroid_distance * 1e3 << " mm, phantom " << phantom_error[t.name] * 1e3 << " mm";
    // And both end at the same place (the label scene in RAS).
    for (const auto& p : ph.tumours)
      if (p.name == t.name) {
        EXPECT_LT((R * p.centroid - t.centroid).norm(), 2e-4) << t.name;
      }
  }
  EXPECT_TRUE(lb.reports.back().converged) << test::step_stops(lb);
  // Results to Slicer: LPS files, the centroids as a point list that reads back where they are.
  Scene ls = load_meshed_scene(dir + "/scene/scene.yaml");
  RegistrationEngine engine(ls);
  const RegistrationResult r = engine.solve(preset_options("balanced"));
  const PreparedScene& prep = engine.prepare(preset_options("balanced"));
  write_registration_outputs(dir + "/out", prep.scene, prep.model, r, 0);
  const auto cps = read_markups(dir + "/out/slicer/tumour_centroids.mrk.json", PatientFrame::RAS);
  ASSERT_EQ(cps.size(), r.tumours.size());
  for (size_t i = 0; i < cps.size(); ++i) {
    EXPECT_EQ(cps[i].label, r.tumours[i].name);
    EXPECT_LT((cps[i].position - r.tumours[i].centroid).norm(), 1e-9);
  }
  const TetMeshFile vtk = read_tet_mesh_file(dir + "/out/slicer/registered.vtk", LengthUnit::Millimetre);
  EXPECT_EQ(cell_labels(vtk, "label", "registered.vtk").size(), static_cast<size_t>(vtk.mesh.T.rows()));
  EXPECT_TRUE(std::filesystem::exists(dir + "/out/slicer/tumour_" + r.tumours[0].name + ".ply"));
}

// A heterogeneous phantom's stiff tumour tetrahedra are every one whose centroid lies in a
// sphere, a blocky shell beyond it; in its label map the tumours are the spheres (15 tumour
// components had come out of the 8 mm phantom's map, 5 of them the tracked tumours).
TEST(LabelMapRoundTrip, AHeterogeneousPhantomsTumoursAreItsTumourSurfacesNotItsTumourTetrahedra) {
  const std::string dir = test::temp_dir();
  PhantomSceneOptions po = test::coarse_phantom_options(1000);
  po.gland_youngs_modulus = 2000;
  po.tumour_youngs_modulus = 10000;
  write_phantom_scene(dir + "/phantom", po);
  const Scene s = load_meshed_scene(dir + "/phantom/scene.yaml");
  ASSERT_FALSE(s.prone_labels.empty());
  const LabelPhantomFiles f = write_label_phantom(s, dir + "/labels");
  const LabelVolume v = read_label_volume(f.label_map);
  std::map<int, long> count;
  for (auto l : v.labels) ++count[l];
  double tumour_volume = 0;
  for (const auto& t : s.tumours) tumour_volume += std::abs(enclosed_volume(t.prone));
  const double voxel = std::abs(v.ijk_to_ras.determinant());
  std::printf("tumour voxels %ld (%.0f mm^3), the spheres %.0f mm^3; gland voxels %ld\n", count[3], count[3] * voxel * 1e9,
              tumour_volume * 1e9, count[2]);
  EXPECT_NEAR(count[3] * voxel, tumour_volume, 0.05 * tumour_volume);
  EXPECT_GT(count[2], 0);
}

// A label mesh's refinement along its tissue interfaces shortens its edges, so by its mean edge
// it reads as finer than the size it was made at, and the engine re-meshed it from its boundary
// (SfePy's bodies as label maps: ended 0.08 to 0.99 mm farther, BENCHMARKS.md, "A label scene
// keeps its mesh"). The scene states the size; a call at that size keeps the mesh.
TEST(LabelMapRoundTrip, ALabelSceneStatesItsCellSizeAndACallAtThatSizeKeepsItsMesh) {
  const std::string dir = test::temp_dir();
  LabelVolume v = synthetic_breast();
  // A gland (label 2): a flattened ellipsoid of the fat over the tumour.
  for (int k = 0; k < v.nz; ++k)
    for (int j = 0; j < v.ny; ++j)
      for (int i = 0; i < v.nx; ++i) {
        const Vec3 p = v.centre(i, j, k);
        auto& l = v.labels[static_cast<size_t>(v.index(i, j, k))];
        if (l == 1 && std::pow(p.x() / 0.028, 2) + std::pow((p.y() - 0.014) / 0.008, 2) + std::pow(p.z() / 0.028, 2) < 1) l = 2;
      }
  LabelTable table;
  table.gland_stiffness = 2;
  table.tumour_stiffness = 5;
  const RegistrationOptions balanced = preset_options("balanced");
  LabelSceneOptions o;
  o.mesh.source = "synthetic breast";
  o.mesh.cell_size = balanced.nodal_simulation_cell_size;  // the size btr_scene_from_labels meshes a prone image at
  write_scene_from_labels(dir, v, table, o);
  const Scene s = load_scene(dir + "/scene.yaml");
  ASSERT_TRUE(s.prone_mesh_cell_size.has_value());
  EXPECT_NEAR(*s.prone_mesh_cell_size, o.mesh.cell_size, 1e-12);
  RegistrationOptions at_own = balanced;
  at_own.simulation_cell_size = simulation_cell_size_for(s, balanced);
  ASSERT_EQ(at_own.simulation_cell_size, o.mesh.cell_size);
  // By its edges it reads as finer (the gland's and the tumour's interfaces) ...
  const double edge = mean_edge_length_away_from_tumours(s, at_own.simulation_cell_size, 0);
  std::printf("label mesh at %.1f mm: mean edge %.2f mm, %ld tetrahedra\n", o.mesh.cell_size * 1e3, edge * 1e3,
              static_cast<long>(s.prone.T.rows()));
  Scene unstated = s;
  unstated.prone_mesh_cell_size.reset();
  EXPECT_TRUE(needs_simulation_mesh(unstated, at_own));
  // ... but it states its size: kept at that size and anything finer, re-meshed clearly coarser.
  EXPECT_FALSE(needs_simulation_mesh(s, at_own));
  RegistrationOptions finer = balanced;
  finer.simulation_cell_size = 0.5 * o.mesh.cell_size;
  EXPECT_FALSE(needs_simulation_mesh(s, finer));
  RegistrationOptions coarser = balanced;
  coarser.simulation_cell_size = coarser.nodal_simulation_cell_size = 1.5 * o.mesh.cell_size;
  EXPECT_TRUE(needs_simulation_mesh(s, coarser));
  RegistrationEngine engine(s);
  const PreparedScene& kept = engine.prepare(balanced);
  EXPECT_TRUE(kept.mesh_note.empty()) << kept.mesh_note;
  EXPECT_EQ(kept.model.rest.T.rows(), s.prone.T.rows());
  // Re-meshed at 13.5 mm, no centroid falls in the 16 mm tumour's tetrahedra: the tetrahedron
  // holding it takes its share (before, the call refused the scene it had just re-meshed).
  const PreparedScene& coarse = engine.prepare(coarser);
  EXPECT_NE(coarse.mesh_note.find("re-tetrahedralized the prone model"), std::string::npos);
  ASSERT_EQ(coarse.scene.prone_label_remnants.size(), 1u);
  EXPECT_EQ(coarse.scene.prone_label_remnants[0].label, 3);
  EXPECT_NEAR(coarse.scene.prone_label_remnants[0].volume, 4.0 / 3 * M_PI * std::pow(0.008, 3), 0.3 * 4.0 / 3 * M_PI * std::pow(0.008, 3));
  EXPECT_LT((coarse.scene.prone_label_remnants[0].centroid - Vec3(0.004, 0.015, -0.003)).norm(), 0.002);
  EXPECT_EQ(std::count(coarse.model.material_names.begin(), coarse.model.material_names.end(), "tumour (partial volume)"), 1);
  EXPECT_TRUE(std::any_of(coarse.warnings.begin(), coarse.warnings.end(), [](const std::string& w) {
    return w.find("regions 'tumour': the re-meshed model's cells are coarser") != std::string::npos;
  })) << ::testing::PrintToString(coarse.warnings);
  // A stated size that is no size is named.
  std::string text = test::scene_text(dir);
  const size_t at = text.find("cell_size_mm: ");  // prone's, the first
  ASSERT_NE(at, std::string::npos);
  test::write_text(dir + "/bad.yaml", text.replace(at, text.find('\n', at) - at, "cell_size_mm: 0"));
  EXPECT_NE(message_of([&] { load_scene(dir + "/bad.yaml"); }).find("field 'prone.cell_size_mm': must be positive"),
            std::string::npos);
}

TEST(LabelMapRoundTrip, ScenesTakeSlicerPointListsAndNameAFiducialOffTheSkinAsAFrameMistake) {
  const std::string dir = test::temp_dir();
  const std::string src = test::coarse_phantom_dir();
  // The coarse phantom's landmarks as point lists (written in LPS, the scene's coordinates RAS).
  const Scene s = test::coarse_phantom_scene();
  std::vector<NamedPoint> pr, su;
  for (size_t i = 0; i < s.landmark_anchors.size(); ++i) {
    pr.push_back({"L" + std::to_string(i), s.landmark_anchors[i].position(s.prone.V)});
    su.push_back({"L" + std::to_string(i), s.landmark_supine.row(static_cast<Eigen::Index>(i)).transpose()});
  }
  write_markups(dir + "/prone.mrk.json", pr, PatientFrame::RAS, PatientFrame::LPS);
  write_markups(dir + "/supine.mrk.json", su, PatientFrame::RAS, PatientFrame::LPS);
  const std::string text = test::without_key(test::scene_text(src), "landmarks");
  const std::string lists = "landmarks: {prone: " + dir + "/prone.mrk.json, supine: " + dir + "/supine.mrk.json}\n";
  // Beside the phantom's files, whose paths are relative to its folder.
  test::write_text(src + "/scene_markups.yaml", text + lists + "patient_frame: RAS\n");
  const Scene ok = load_meshed_scene(src + "/scene_markups.yaml");
  ASSERT_EQ(ok.landmark_anchors.size(), s.landmark_anchors.size());
  for (size_t i = 0; i < s.landmark_anchors.size(); ++i) {
    EXPECT_LT((ok.landmark_anchors[i].position(ok.prone.V) - s.landmark_anchors[i].position(s.prone.V)).norm(), 1e-6);
    EXPECT_LT((ok.landmark_supine.row(static_cast<Eigen::Index>(i)) - s.landmark_supine.row(static_cast<Eigen::Index>(i))).norm(), 1e-9);
  }
  // patient_frame is read with or without point lists (the Slicer outputs need it); a bad one is named.
  test::write_text(src + "/scene_frame_only.yaml", test::scene_text(src) + "patient_frame: LPS\n");
  EXPECT_EQ(load_meshed_scene(src + "/scene_frame_only.yaml").patient_frame, PatientFrame::LPS);
  test::write_text(src + "/scene_frame_bad.yaml", test::scene_text(src) + "patient_frame: RAI\n");
  EXPECT_NE(message_of([&] { load_meshed_scene(src + "/scene_frame_bad.yaml"); }).find("field 'patient_frame'"), std::string::npos);
  test::write_text(src + "/scene_markups_noframe.yaml", text + lists);
  EXPECT_NE(message_of([&] { load_meshed_scene(src + "/scene_markups_noframe.yaml"); }).find("field 'patient_frame': missing"), std::string::npos);
  // A prone fiducial 30 mm off the skin: most often a list in another frame than it says.
  pr[1].position.z() += 0.03;
  write_markups(dir + "/prone.mrk.json", pr, PatientFrame::RAS, PatientFrame::LPS);
  const std::string msg = message_of([&] { load_meshed_scene(src + "/scene_markups.yaml"); });
  EXPECT_NE(msg.find("prone landmark 'L1' is "), std::string::npos) << msg;
  EXPECT_NE(msg.find("coordinate system (LPS/RAS)"), std::string::npos) << msg;
}

}  // namespace
}  // namespace btr
