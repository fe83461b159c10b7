#include "breast_tumour_registration/io/label_volume_io.h"

#include <nifti2_io.h>
#include <teem/nrrd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"

namespace btr {
namespace {

enum class Format { Nifti, Nrrd };

Format format_of(const std::string& path) {
  const std::string p = lower_case(path);
  if (ends_with(p, ".nii") || ends_with(p, ".nii.gz")) return Format::Nifti;
  if (ends_with(p, ".nrrd") || ends_with(p, ".nhdr")) return Format::Nrrd;
  throw InputError(path + ": unknown label map format (expected .nii, .nii.gz, .nrrd, .nhdr or .seg.nrrd)");
}

void check_size(const std::string& path, long nx, long ny, long nz) {
  if (nx < 2 || ny < 2 || nz < 2)
    throw InputError(path + ": a label map needs at least 2 voxels along each axis, got " + std::to_string(nx) + " x " +
                     std::to_string(ny) + " x " + std::to_string(nz));
  const double n = static_cast<double>(nx) * ny * nz;
  if (n > static_cast<double>(kMaxLabelVoxels))
    throw InputError(path + ": " + std::to_string(nx) + " x " + std::to_string(ny) + " x " + std::to_string(nz) + " = " +
                     std::to_string(static_cast<long>(n / 1e6)) + "M voxels, more than the " +
                     std::to_string(kMaxLabelVoxels >> 20) +
                     "M this reader takes (memory); crop the volume to the breast, or resample it to coarser voxels "
                     "(e.g. Slicer's Crop Volume)");
}

// The grid's voxel steps must be orthogonal and non-degenerate: meshing places voxels by them.
void check_grid(const std::string& path, const Mat3& M) {
  for (int a = 0; a < 3; ++a)
    if (!(M.col(a).norm() > 0) || !M.col(a).allFinite())
      throw InputError(path + ": voxel axis " + std::to_string(a) + " has no length or direction (a degenerate orientation)");
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b) {
      const double c = std::abs(M.col(a).dot(M.col(b))) / (M.col(a).norm() * M.col(b).norm());
      if (c > 1e-3)
        throw InputError(path + ": voxel axes " + std::to_string(a) + " and " + std::to_string(b) +
                         " are not orthogonal (a sheared grid, cosine " + std::to_string(c) +
                         "); resample the label map onto an orthogonal grid");
    }
}

// Converts the file's values to labels; a value that is not an integer in [0, 255] is an error.
template <typename Get>
void fill_labels(const std::string& path, LabelVolume& v, Get&& value_at) {
  v.labels.resize(static_cast<size_t>(v.voxel_count()));
  long bad = 0;
  double first_bad = 0;
  for (long i = 0; i < v.voxel_count(); ++i) {
    const double x = value_at(i);
    if (!(x >= 0 && x <= 255 && x == std::floor(x))) {
      if (bad++ == 0) first_bad = x;
      continue;
    }
    v.labels[static_cast<size_t>(i)] = static_cast<std::uint8_t>(x);
  }
  if (bad > 0) {
    std::ostringstream os;
    os << path << ": " << bad << " voxels hold values that are not labels (integers 0 to 255), e.g. " << first_bad
       << "; is this an intensity image rather than a segmentation?";
    throw InputError(os.str());
  }
}

// ---------------------------------------------------------------------------- NIfTI
struct NiftiFree {
  void operator()(nifti_image* p) const { nifti_image_free(p); }
};

double nifti_unit(const nifti_image& h) {
  switch (XYZT_TO_SPACE(h.xyz_units)) {
    case NIFTI_UNITS_METER: return 1.0;
    case NIFTI_UNITS_MICRON: return 1e-6;
    default: return 1e-3;  // millimetres, and "unknown", which every tool reads as millimetres
  }
}

LabelVolume read_nifti(const std::string& path) {
  nifti_set_debug_level(0);
  std::unique_ptr<nifti_image, NiftiFree> h(nifti_image_read(path.c_str(), 0));
  if (!h) throw InputError(path + ": not a readable NIfTI file");
  for (int d = 4; d <= 7; ++d)
    if (h->dim[0] >= d && h->dim[d] > 1)
      throw InputError(path + ": the image has " + std::to_string(h->dim[0]) + " dimensions (dim[" + std::to_string(d) +
                       "] = " + std::to_string(h->dim[d]) + "); a label map has one value per voxel of a 3-D grid");
  check_size(path, h->nx, h->ny, h->nz);
  const nifti_dmat44* m = nullptr;
  if (h->sform_code > 0) m = &h->sto_xyz;
  else if (h->qform_code > 0) m = &h->qto_xyz;
  else
    throw InputError(path + ": no orientation (sform_code and qform_code are 0), so the voxels cannot be placed on the "
                        "patient; save the segmentation from a tool that keeps the image geometry (e.g. 3D Slicer)");
  LabelVolume v;
  v.nx = static_cast<int>(h->nx);
  v.ny = static_cast<int>(h->ny);
  v.nz = static_cast<int>(h->nz);
  const double u = nifti_unit(*h);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) v.ijk_to_ras(r, c) = m->m[r][c] * u;
    v.origin[r] = m->m[r][3] * u;
  }
  check_grid(path, v.ijk_to_ras);
  if (nifti_image_load(h.get()) != 0 || !h->data) throw InputError(path + ": the voxel data could not be read (truncated file?)");
  const double slope = (h->scl_slope != 0 && std::isfinite(h->scl_slope)) ? h->scl_slope : 1.0;
  const double inter = std::isfinite(h->scl_inter) ? h->scl_inter : 0.0;
  const void* d = h->data;
  auto scaled = [&](double x) { return slope * x + inter; };
  switch (h->datatype) {
    case DT_UINT8: fill_labels(path, v, [&](long i) { return scaled(static_cast<const std::uint8_t*>(d)[i]); }); break;
    case DT_INT8: fill_labels(path, v, [&](long i) { return scaled(static_cast<const std::int8_t*>(d)[i]); }); break;
    case DT_UINT16: fill_labels(path, v, [&](long i) { return scaled(static_cast<const std::uint16_t*>(d)[i]); }); break;
    case DT_INT16: fill_labels(path, v, [&](long i) { return scaled(static_cast<const std::int16_t*>(d)[i]); }); break;
    case DT_UINT32: fill_labels(path, v, [&](long i) { return scaled(static_cast<const std::uint32_t*>(d)[i]); }); break;
    case DT_INT32: fill_labels(path, v, [&](long i) { return scaled(static_cast<const std::int32_t*>(d)[i]); }); break;
    case DT_UINT64: fill_labels(path, v, [&](long i) { return scaled(static_cast<double>(static_cast<const std::uint64_t*>(d)[i])); }); break;
    case DT_INT64: fill_labels(path, v, [&](long i) { return scaled(static_cast<double>(static_cast<const std::int64_t*>(d)[i])); }); break;
    case DT_FLOAT32: fill_labels(path, v, [&](long i) { return scaled(static_cast<const float*>(d)[i]); }); break;
    case DT_FLOAT64: fill_labels(path, v, [&](long i) { return scaled(static_cast<const double*>(d)[i]); }); break;
    default:
      throw InputError(path + ": voxel type " + std::string(nifti_datatype_string(h->datatype)) +
                       " is not a label type (use an integer type)");
  }
  return v;
}

void write_nifti(const std::string& path, const LabelVolume& v) {
  const int64_t dims[8] = {3, v.nx, v.ny, v.nz, 1, 1, 1, 1};
  std::unique_ptr<nifti_image, NiftiFree> h(nifti_make_new_nim(dims, DT_UINT8, 0));
  if (!h) throw InputError(path + ": could not create a NIfTI image");
  std::free(h->data);
  h->data = std::malloc(v.labels.size());
  if (!h->data) throw InputError(path + ": out of memory");
  std::copy(v.labels.begin(), v.labels.end(), static_cast<std::uint8_t*>(h->data));
  h->xyz_units = NIFTI_UNITS_MM;
  nifti_dmat44 m{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.m[r][c] = v.ijk_to_ras(r, c) * 1e3;
    m.m[r][3] = v.origin[r] * 1e3;
  }
  m.m[3][3] = 1;
  h->sform_code = h->qform_code = NIFTI_XFORM_SCANNER_ANAT;
  h->sto_xyz = h->qto_xyz = m;
  double dx, dy, dz, qfac;
  nifti_dmat44_to_quatern(m, &h->quatern_b, &h->quatern_c, &h->quatern_d, &h->qoffset_x, &h->qoffset_y, &h->qoffset_z, &dx, &dy,
                          &dz, &qfac);
  h->qfac = qfac;
  h->dx = h->pixdim[1] = dx;
  h->dy = h->pixdim[2] = dy;
  h->dz = h->pixdim[3] = dz;
  h->pixdim[0] = qfac;
  if (nifti_set_filenames(h.get(), path.c_str(), 0, 1) != 0) throw InputError(path + ": not a NIfTI file name");
  nifti_image_write(h.get());
  if (!std::filesystem::exists(path)) throw InputError(path + ": could not be written");
}

// ---------------------------------------------------------------------------- NRRD
struct NrrdNuke {
  void operator()(Nrrd* p) const { nrrdNuke(p); }
};

std::string biff_message() {
  char* e = biffGetDone(NRRD);
  std::string s = e ? e : "";
  std::free(e);
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

double nrrd_unit(const Nrrd& n, const std::string& path) {
  double u = 1e-3;  // NRRD's space units are optional; Slicer and ITK mean millimetres
  for (unsigned a = 0; a < n.spaceDim; ++a) {
    if (!n.spaceUnits[a] || !*n.spaceUnits[a]) continue;
    const std::string s = lower_case(n.spaceUnits[a]);
    if (s == "mm") u = 1e-3;
    else if (s == "m") u = 1.0;
    else if (s == "cm") u = 1e-2;
    else if (s == "um" || s == "micron") u = 1e-6;
    else throw InputError(path + ": space unit '" + s + "' is not a length unit this reader knows (mm, cm, m, um)");
  }
  return u;
}

std::string key_value(const Nrrd& n, const std::string& key) {
  char* v = nrrdKeyValueGet(&n, key.c_str());
  std::string s = v ? v : "";
  std::free(v);
  return s;
}

LabelVolume read_nrrd(const std::string& path) {
  // The header first: its size and geometry are checked before the data is read.
  std::unique_ptr<Nrrd, NrrdNuke> n(nrrdNew());
  NrrdIoState* nio = nrrdIoStateNew();
  nrrdIoStateSet(nio, nrrdIoStateSkipData, AIR_TRUE);
  const int failed = nrrdLoad(n.get(), path.c_str(), nio);
  nrrdIoStateNix(nio);
  if (failed) throw InputError(path + ": not a readable NRRD file (" + biff_message() + ")");
  unsigned first = 0;  // a Slicer segmentation with one layer may carry a leading axis of size 1
  if (n->dim == 4 && n->axis[0].size == 1) first = 1;
  else if (n->dim == 4)
    throw InputError(path + ": " + std::to_string(n->axis[0].size) +
                     " layers (a segmentation whose segments overlap); a label map needs one label per voxel: "
                     "export it as a labelmap volume (Slicer: Segmentations, Export to labelmap)");
  else if (n->dim != 3)
    throw InputError(path + ": " + std::to_string(n->dim) + " dimensions; a label map is a 3-D grid");
  check_size(path, static_cast<long>(n->axis[first].size), static_cast<long>(n->axis[first + 1].size),
             static_cast<long>(n->axis[first + 2].size));
  double flip_x = 1, flip_y = 1;
  switch (n->space) {
    case nrrdSpaceRightAnteriorSuperior: break;
    case nrrdSpaceLeftPosteriorSuperior:
    case nrrdSpaceScannerXYZ: flip_x = flip_y = -1; break;
    case nrrdSpaceLeftAnteriorSuperior: flip_x = -1; break;
    default:
      throw InputError(path + ": no patient space (the header needs 'space: left-posterior-superior' or "
                          "'right-anterior-superior' with 'space directions' and 'space origin'), so the voxels cannot be "
                          "placed on the patient");
  }
  if (n->spaceDim != 3) throw InputError(path + ": the space is not 3-D");
  const double u = nrrd_unit(*n, path);
  LabelVolume v;
  v.nx = static_cast<int>(n->axis[first].size);
  v.ny = static_cast<int>(n->axis[first + 1].size);
  v.nz = static_cast<int>(n->axis[first + 2].size);
  const Vec3 flip(flip_x, flip_y, 1);
  for (int a = 0; a < 3; ++a) {
    const double* d = n->axis[first + a].spaceDirection;
    if (!std::isfinite(d[0])) throw InputError(path + ": axis " + std::to_string(a) + " has no space direction");
    v.ijk_to_ras.col(a) = Vec3(d[0], d[1], d[2]).cwiseProduct(flip) * u;
  }
  Vec3 o(n->spaceOrigin[0], n->spaceOrigin[1], n->spaceOrigin[2]);
  if (!o.allFinite()) o.setZero();
  v.origin = o.cwiseProduct(flip) * u;
  check_grid(path, v.ijk_to_ras);
  for (int k = 0;; ++k) {
    const std::string prefix = "Segment" + std::to_string(k) + "_";
    const std::string name = key_value(*n, prefix + "Name");
    if (name.empty()) break;
    const std::string value = key_value(*n, prefix + "LabelValue");
    if (!value.empty()) v.names[std::atoi(value.c_str())] = name;
  }
  // Now the data.
  std::unique_ptr<Nrrd, NrrdNuke> full(nrrdNew());
  if (nrrdLoad(full.get(), path.c_str(), nullptr)) throw InputError(path + ": the voxel data could not be read (" + biff_message() + ")");
  if (full->type == nrrdTypeBlock) throw InputError(path + ": block-typed voxels are not labels");
  const auto lookup = nrrdDLookup[full->type];
  const void* data = full->data;
  fill_labels(path, v, [&](long i) { return lookup(data, static_cast<size_t>(i)); });
  return v;
}

void write_nrrd(const std::string& path, const LabelVolume& v, PatientFrame frame) {
  std::vector<std::uint8_t> data = v.labels;
  std::unique_ptr<Nrrd, void (*)(Nrrd*)> n(nrrdNew(), [](Nrrd* p) { nrrdNix(p); });  // the data is ours
  const size_t sizes[3] = {static_cast<size_t>(v.nx), static_cast<size_t>(v.ny), static_cast<size_t>(v.nz)};
  if (nrrdWrap_nva(n.get(), data.data(), nrrdTypeUChar, 3, sizes)) throw InputError(path + ": " + biff_message());
  nrrdSpaceSet(n.get(), frame == PatientFrame::LPS ? nrrdSpaceLeftPosteriorSuperior : nrrdSpaceRightAnteriorSuperior);
  const Vec3 flip = frame == PatientFrame::LPS ? Vec3(-1, -1, 1) : Vec3(1, 1, 1);
  const Vec3 o = v.origin.cwiseProduct(flip) * 1e3;
  nrrdSpaceOriginSet(n.get(), o.data());
  double dirs[NRRD_DIM_MAX][NRRD_SPACE_DIM_MAX];
  int kinds[NRRD_DIM_MAX];
  for (int a = 0; a < 3; ++a) {
    const Vec3 d = v.ijk_to_ras.col(a).cwiseProduct(flip) * 1e3;
    for (int c = 0; c < 3; ++c) dirs[a][c] = d[c];
    kinds[a] = nrrdKindDomain;
  }
  nrrdAxisInfoSet_nva(n.get(), nrrdAxisInfoSpaceDirection, dirs);
  nrrdAxisInfoSet_nva(n.get(), nrrdAxisInfoKind, kinds);
  for (int a = 0; a < 3; ++a) n->spaceUnits[a] = airStrdup("mm");
  int segment = 0;
  for (const auto& [label, name] : v.names) {
    const std::string prefix = "Segment" + std::to_string(segment++) + "_";
    nrrdKeyValueAdd(n.get(), (prefix + "Name").c_str(), name.c_str());
    nrrdKeyValueAdd(n.get(), (prefix + "LabelValue").c_str(), std::to_string(label).c_str());
  }
  NrrdIoState* nio = nrrdIoStateNew();
  if (nrrdEncodingGzip->available()) nio->encoding = nrrdEncodingGzip;
  const int failed = nrrdSave(path.c_str(), n.get(), nio);
  nrrdIoStateNix(nio);
  if (failed) throw InputError(path + ": could not be written (" + biff_message() + ")");
}

}  // namespace

LabelVolume read_label_volume(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(path + ": no such file");
  return format_of(path) == Format::Nifti ? read_nifti(path) : read_nrrd(path);
}

void write_label_volume(const std::string& path, const LabelVolume& v, PatientFrame nrrd_frame) {
  if (static_cast<long>(v.labels.size()) != v.voxel_count())
    throw InputError(path + ": the label map holds " + std::to_string(v.labels.size()) + " labels for " +
                     std::to_string(v.voxel_count()) + " voxels");
  if (format_of(path) == Format::Nifti) write_nifti(path, v);
  else write_nrrd(path, v, nrrd_frame);
}

}  // namespace btr
