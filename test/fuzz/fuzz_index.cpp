// Index lists (chest wall), landmark pair CSVs and named index files.
#include "breast_tumour_registration/io/index_io.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = btr::fuzz::write_input("input.txt", data, size);
  btr::fuzz::expect_contract([&] { btr::check_index_range(btr::read_index_list(path), 1000, "fuzz"); });
  btr::fuzz::expect_contract([&] { btr::read_landmark_pairs(path, btr::LengthUnit::Millimetre); });
  btr::fuzz::expect_contract([&] { btr::read_named_indices(path); });
  return 0;
}
