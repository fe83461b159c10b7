// A segmented image (a label map): one small integer per voxel on a regular grid placed in a
// patient frame. Readers are in io/label_volume_io.h; meshing is in geometry/label_mesher.h.
//
// Frame: RAS (+x towards the patient's right, +y anterior, +z superior), the frame NIfTI
// uses; LPS files (NRRD as Slicer writes it, DICOM) are converted when read. Lengths in metres. Voxel (i, j, k) has its centre at
//   p = origin + ijk_to_ras * (i, j, k)^T,
// where the columns of ijk_to_ras are the voxel steps (direction times spacing).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// Patient coordinate conventions: RAS (NIfTI, Slicer's display) and LPS (DICOM, ITK, NRRD
/// as Slicer writes it). They differ by the sign of x and y.
enum class PatientFrame { RAS, LPS };
const char* to_string(PatientFrame f);
/// "RAS" / "LPS" (case-insensitive); InputError naming `what` otherwise.
PatientFrame parse_patient_frame(const std::string& s, const std::string& what);
/// The point `p` given in `from` expressed in `to` (x and y change sign between RAS and LPS).
Vec3 convert_patient_frame(const Vec3& p, PatientFrame from, PatientFrame to);

struct LabelVolume {
  int nx = 0, ny = 0, nz = 0;          ///< voxels along i, j, k
  Mat3 ijk_to_ras = Mat3::Identity();  ///< columns: voxel steps in RAS [m]
  Vec3 origin = Vec3::Zero();          ///< centre of voxel (0, 0, 0) in RAS [m]
  std::vector<std::uint8_t> labels;    ///< nx * ny * nz values, i fastest, then j, then k
  std::map<int, std::string> names;    ///< segment names by label value, when the file has them

  long voxel_count() const { return static_cast<long>(nx) * ny * nz; }
  long index(int i, int j, int k) const { return (static_cast<long>(k) * ny + j) * nx + i; }
  std::uint8_t at(int i, int j, int k) const { return labels[index(i, j, k)]; }
  Vec3 centre(int i, int j, int k) const { return origin + ijk_to_ras * Vec3(i, j, k); }
  /// Voxel spacing along i, j, k [m] (the column norms of ijk_to_ras).
  Vec3 spacing() const { return ijk_to_ras.colwise().norm().transpose(); }
};

/// Voxels of each label value present (index = value).
std::vector<long> label_histogram(const LabelVolume& v);

}  // namespace btr
