// Label maps: NRRD (Teem: text header, inline or gzip data) and NIfTI (libnifti2) files.
#include "breast_tumour_registration/io/label_volume_io.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string nrrd = btr::fuzz::write_input("input.nrrd", data, size);
  btr::fuzz::expect_contract([&] { btr::read_label_volume(nrrd); });
  const std::string nii = btr::fuzz::write_input("input.nii", data, size);
  btr::fuzz::expect_contract([&] { btr::read_label_volume(nii); });
  return 0;
}
