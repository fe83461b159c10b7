// The scene loader (YAML): keys, types, units, gravity, steps, and the files it names
// (a small valid body is on disk beside the input, see fuzz_fixture.h). The loader meshes
// nothing, so a run costs parsing and checks, not CGAL.
#include "breast_tumour_registration/io/scene.h"
#include "fuzz_fixture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  btr::fuzz::write_fixture();
  const std::string path = btr::fuzz::write_input("scene.yaml", data, size);
  btr::fuzz::expect_contract([&] { btr::load_scene(path); });
  return 0;
}
