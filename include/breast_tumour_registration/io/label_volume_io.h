// Label map files: NIfTI (.nii, .nii.gz; read and written with libnifti2) and NRRD (.nrrd,
// .nhdr, Slicer's .seg.nrrd; read and written with Teem). The file's orientation (NIfTI's
// sform, else its qform; NRRD's space, space directions and space origin) places the grid in
// RAS (label_volume.h); lengths are converted to metres here, once.
#pragma once

#include <string>

#include "breast_tumour_registration/geometry/label_volume.h"

namespace btr {

/// The largest label map read: 2^28 voxels (256 MiB of labels, about 1 GiB while a 32-bit
/// file is converted). A bigger file is refused from its header, before any data is read.
constexpr long kMaxLabelVoxels = 1L << 28;

/// Reads a label map; the format follows the extension. InputError naming the file for: an
/// unknown extension, a file that does not read, no orientation (NIfTI sform and qform codes
/// 0, NRRD without a space), a sheared or degenerate voxel grid, more than 3 dimensions
/// (Slicer segmentations with overlapping layers included), more voxels than kMaxLabelVoxels,
/// and values that are not integers in [0, 255]. Segment names of a .seg.nrrd
/// (SegmentN_Name, SegmentN_LabelValue) go to LabelVolume::names.
LabelVolume read_label_volume(const std::string& path);

/// Writes a label map (.nii, .nii.gz, .nrrd) in millimetres: NIfTI with sform and qform in RAS,
/// NRRD in `nrrd_frame` (Slicer writes LPS), gzip-compressed.
void write_label_volume(const std::string& path, const LabelVolume& v, PatientFrame nrrd_frame = PatientFrame::LPS);

}  // namespace btr
