// The truth-file loader (truth.yaml of btr_experiments --truth) against the fixture's box as the
// rest model (fuzz_fixture.h: its prone.vtk is that model's mesh, so a configuration may name it).
#include "breast_tumour_registration/simulation/given_truth_io.h"
#include "fuzz_fixture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  btr::fuzz::write_fixture();
  static const btr::PhantomModel model = [] {
    btr::PhantomModel m;
    m.rest = btr::read_tet_mesh(btr::fuzz::scratch() + "/prone.vtk", btr::LengthUnit::Millimetre);
    m.tumours["t"] = btr::read_surface(btr::fuzz::scratch() + "/tumour.obj", btr::LengthUnit::Millimetre);
    return m;
  }();
  const std::string path = btr::fuzz::write_input("truth.yaml", data, size);
  btr::fuzz::expect_contract([&] { btr::load_given_configurations(path, model); });
  return 0;
}
