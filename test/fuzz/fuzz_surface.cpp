// Surface and point-cloud readers (OBJ, PLY ASCII and binary, STL ASCII and binary, OFF,
// VTK): the first byte chooses the format, the rest is the file.
#include "breast_tumour_registration/io/mesh_io.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* kExt[] = {"obj", "ply", "stl", "off", "vtk"};
  const std::string path = btr::fuzz::write_input(std::string("input.") + kExt[data[0] % 5], data + 1, size - 1);
  btr::fuzz::expect_contract([&] { btr::read_surface(path, btr::LengthUnit::Millimetre); });
  btr::fuzz::expect_contract([&] { btr::read_point_cloud(path, btr::LengthUnit::Metre); });
  return 0;
}
