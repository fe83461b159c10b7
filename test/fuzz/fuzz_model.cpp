// The rest-model loader (model.yaml of btr_experiments --model) and the files it names
// (a small valid body is on disk beside the input, see fuzz_fixture.h).
#include "breast_tumour_registration/simulation/rest_model_io.h"
#include "fuzz_fixture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  btr::fuzz::write_fixture();
  const std::string path = btr::fuzz::write_input("model.yaml", data, size);
  btr::fuzz::expect_contract([&] { btr::load_rest_model(path); });
  return 0;
}
