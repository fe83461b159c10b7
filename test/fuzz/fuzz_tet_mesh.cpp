// Tetrahedral mesh readers (legacy VTK unstructured grid, Medit .mesh): the first byte
// chooses the format, the rest is the file.
#include "breast_tumour_registration/io/mesh_io.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string path = btr::fuzz::write_input(data[0] % 2 ? "input.mesh" : "input.vtk", data + 1, size - 1);
  btr::fuzz::expect_contract([&] { btr::read_tet_mesh(path, btr::LengthUnit::Millimetre); });
  return 0;
}
