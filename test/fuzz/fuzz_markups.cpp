// Slicer point lists: markups JSON (.mrk.json) and markups CSV (.fcsv).
#include "breast_tumour_registration/io/markups_io.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string json = btr::fuzz::write_input("input.mrk.json", data, size);
  btr::fuzz::expect_contract([&] { btr::read_markups(json, btr::PatientFrame::RAS); });
  const std::string csv = btr::fuzz::write_input("input.fcsv", data, size);
  btr::fuzz::expect_contract([&] { btr::read_markups(csv, btr::PatientFrame::LPS); });
  return 0;
}
