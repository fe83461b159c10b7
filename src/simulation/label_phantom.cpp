#include "breast_tumour_registration/simulation/label_phantom.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/io/label_volume_io.h"
#include "breast_tumour_registration/io/markups_io.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "breast_tumour_registration/io/scene.h"

namespace btr {

Mat3 phantom_to_ras() {
  Mat3 R;
  R << 1, 0, 0,  //
      0, 0, 1,   //
      0, -1, 0;
  return R;
}

namespace {
Points to_ras(const Points& P) { return P * phantom_to_ras().transpose(); }
SurfaceMesh to_ras(const SurfaceMesh& s) { return SurfaceMesh{to_ras(s.V), s.F}; }
}  // namespace

LabelPhantomFiles write_label_phantom(const std::string& scene_yaml, const std::string& dir, const LabelPhantomOptions& opt) {
  return write_label_phantom(load_scene(scene_yaml), dir, opt);
}

LabelPhantomFiles write_label_phantom(const Scene& s, const std::string& dir, const LabelPhantomOptions& opt) {
  namespace fs = std::filesystem;
  const std::string& scene_yaml = s.path;
  if (!(opt.muscle_thickness > 0) || !(opt.margin >= 0))
    throw InputError("label phantom: voxel size and muscle thickness must be positive, the margin >= 0");
  if (s.prone.T.rows() == 0)
    throw InputError(scene_yaml + ": the label phantom needs the prone tetrahedral mesh (prone.tet_mesh, or a meshed scene)");
  const Mat3 R = phantom_to_ras();
  TetMesh prone{to_ras(s.prone.V), s.prone.T};
  // The chest wall must be the plane y = 0 in RAS (z = 0 in the phantom): voxel centres lie
  // half a voxel either side of it, so that the labels' interface falls on it.
  for (int v : s.chest_wall)
    if (std::abs(prone.V(v, 1)) > 1e-6) throw InputError(scene_yaml + ": the chest wall is not the plane z = 0 of a phantom");
  const Vec3 h = opt.voxel_size;
  if (!(h.minCoeff() > 0) || (opt.min_voxels.array() < 0).any()) throw InputError("label phantom: voxel sizes must be positive");
  const Vec3 lo_ras = prone.V.colwise().minCoeff().transpose() - Vec3::Constant(opt.margin);
  const Vec3 hi_ras = prone.V.colwise().maxCoeff().transpose() + Vec3::Constant(opt.margin);
  const int n_muscle = static_cast<int>(std::ceil(opt.muscle_thickness / h.y()));
  // The breast's own box of voxels, then air around it up to opt.min_voxels.
  const int bx = static_cast<int>(std::ceil((hi_ras.x() - lo_ras.x()) / h.x())) + 1;
  const int bz = static_cast<int>(std::ceil((hi_ras.z() - lo_ras.z()) / h.z())) + 1;
  const int by_front = static_cast<int>(std::ceil(hi_ras.y() / h.y())) + 1;
  const int pad_x = std::max(0, opt.min_voxels.x() - bx) / 2, pad_z = std::max(0, opt.min_voxels.z() - bz) / 2;
  const int n_back = std::max(2, (opt.min_voxels.y() - n_muscle - by_front) / 2);
  LabelVolume v;
  v.nx = std::max(bx, opt.min_voxels.x());
  v.nz = std::max(bz, opt.min_voxels.z());
  v.ny = std::max(n_back + n_muscle + by_front, opt.min_voxels.y());
  const double voxels = static_cast<double>(v.nx) * v.ny * v.nz;
  if (voxels > static_cast<double>(kMaxLabelVoxels)) throw InputError("label phantom: more voxels than a label map may have");
  v.ijk_to_ras = h.asDiagonal();
  v.origin = Vec3(lo_ras.x() - pad_x * h.x(), -(n_back + n_muscle - 0.5) * h.y(), lo_ras.z() - pad_z * h.z());
  v.labels.assign(static_cast<size_t>(v.voxel_count()), 0);
  v.names = {{opt.fat, "fat"}, {opt.gland, "gland"}, {opt.tumour, "tumour"}, {opt.muscle, "muscle"}};
  const int first_tissue = n_back + n_muscle;  // the first voxel layer anterior of the chest wall
  const int j_end = std::min(v.ny, first_tissue + by_front);

  // Tissue: voxel centres inside the prone mesh take the label of their tetrahedron; a tumour's
  // tetrahedra (a heterogeneous phantom's stiff ones: every one whose centroid lies in a
  // sphere) are fat here, and the tumours are their surfaces (below), as a segmentation gives them.
  std::vector<long> ids;
  std::vector<Vec3> centres;
  for (int k = pad_z; k < std::min(v.nz, pad_z + bz); ++k)
    for (int j = first_tissue; j < j_end; ++j)
      for (int i = pad_x; i < std::min(v.nx, pad_x + bx); ++i) {
        ids.push_back(v.index(i, j, k));
        centres.push_back(v.centre(i, j, k));
      }
  Points P(static_cast<Eigen::Index>(centres.size()), 3);
  for (size_t r = 0; r < centres.size(); ++r) P.row(static_cast<Eigen::Index>(r)) = centres[r].transpose();
  const Embedding e = embed_points(prone, P, OutsidePolicy::NearestTetrahedron);
  std::vector<char> outside(centres.size(), 0);
  for (int o : e.outside) outside[static_cast<size_t>(o)] = 1;
  for (size_t r = 0; r < centres.size(); ++r) {
    if (outside[r]) continue;
    const int t = e.tet[static_cast<Eigen::Index>(r)];
    const int label = s.prone_labels.empty() ? opt.fat : s.prone_labels[t];
    v.labels[static_cast<size_t>(ids[r])] = static_cast<std::uint8_t>(label == opt.tumour ? opt.fat : label);
  }
  // Tumours: voxel centres inside a prone tumour surface.
  for (const auto& t : s.tumours) {
    const SurfaceMesh ts = to_ras(t.prone);
    const Vec3 lo = ts.V.colwise().minCoeff().transpose(), hi = ts.V.colwise().maxCoeff().transpose();
    for (size_t r = 0; r < centres.size(); ++r) {
      const Vec3& c = centres[r];
      if ((c.array() < lo.array()).any() || (c.array() > hi.array()).any()) continue;
      if (inside_closed_surface(ts, c)) v.labels[static_cast<size_t>(ids[r])] = static_cast<std::uint8_t>(opt.tumour);
    }
  }
  // Muscle: behind every voxel of the first tissue layer.
  for (int k = 0; k < v.nz; ++k)
    for (int i = 0; i < v.nx; ++i)
      if (v.at(i, first_tissue, k) != 0)
        for (int j = n_back; j < first_tissue; ++j) v.labels[static_cast<size_t>(v.index(i, j, k))] = static_cast<std::uint8_t>(opt.muscle);

  fs::create_directories(dir);
  auto path = [&](const std::string& f) { return (fs::path(dir) / f).string(); };
  LabelPhantomFiles out;
  out.label_map = path("prone_labels.nii.gz");
  write_label_volume(out.label_map, v);
  if (s.landmark_anchors.size()) {
    const Points prone_ras = prone.V;
    std::vector<NamedPoint> pr, su;
    for (size_t i = 0; i < s.landmark_anchors.size(); ++i) {
      const std::string label = "L" + std::to_string(i + 1);
      pr.push_back({label, s.landmark_anchors[i].position(prone_ras)});
      su.push_back({label, R * s.landmark_supine.row(static_cast<Eigen::Index>(i)).transpose()});
    }
    out.prone_landmarks = path("prone_landmarks.mrk.json");
    out.supine_landmarks = path("supine_landmarks.mrk.json");
    write_markups(out.prone_landmarks, pr, PatientFrame::RAS, opt.markups_frame);
    write_markups(out.supine_landmarks, su, PatientFrame::RAS, opt.markups_frame);
  }
  if (s.supine_surface) {
    out.supine_surface = path("supine_surface.obj");
    write_surface(out.supine_surface, to_ras(*s.supine_surface), LengthUnit::Millimetre);
  }
  for (const auto& t : s.tumours)
    if (t.supine_ground_truth) {
      TumourTruthFiles f{t.name, path("tumour_" + t.name + "_prone.obj"), path("tumour_" + t.name + "_supine.obj")};
      write_surface(f.prone, to_ras(t.prone), LengthUnit::Millimetre);
      write_surface(f.supine, to_ras(*t.supine_ground_truth), LengthUnit::Millimetre);
      out.tumour_truth.push_back(f);
    }
  out.volume = std::move(v);
  return out;
}

}  // namespace btr
