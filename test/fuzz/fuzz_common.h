// Shared by the libFuzzer harnesses: the input is written to a file (the readers take
// paths), and the contract every reader must keep is checked: it returns, or it throws
// InputError with a message. Anything else (another exception, a crash, a sanitizer
// report, an out-of-memory) is a finding; libFuzzer keeps the input that caused it.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "breast_tumour_registration/base/errors.h"

namespace btr::fuzz {

/// A per-process scratch folder (several fuzzing jobs may run at once), removed when the
/// process exits normally (a crash leaves it, with the input that caused it).
inline const std::string& scratch() {
  struct Folder {
    std::string path;
    Folder() : path((std::filesystem::temp_directory_path() / ("btr_fuzz_" + std::to_string(getpid()))).string()) {
      std::filesystem::create_directories(path);
    }
    ~Folder() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Folder dir;
  return dir.path;
}

inline std::string write_input(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = scratch() + "/" + name;
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

/// Runs f; an InputError is the documented answer to bad input, anything else aborts.
template <class F>
void expect_contract(F&& f) {
  try {
    f();
  } catch (const InputError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: an exception outside the contract (not InputError): %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: a non-standard exception\n");
    std::abort();
  }
}

}  // namespace btr::fuzz
