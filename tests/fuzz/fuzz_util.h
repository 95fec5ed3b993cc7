// Shared helpers of the libFuzzer harnesses (tests/fuzz/README in the top-level README, "Fuzzing and sanitizers").
// The contract every harness checks: a parser or loader given any bytes either returns or throws floesim::Error
// (the clear message is the correct outcome for bad input). Anything else is a finding: another exception type
// escaping (std::terminate aborts), a crash, a sanitizer report, a hang or an allocation beyond libFuzzer's limit.
#pragma once
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "pipeline/error.h"

namespace floesim::fuzz {

// A per-process temporary file with the given extension (".obj", ".csv"...), overwritten with each input: loaders
// that take a path read the fuzz input through it, as they read a user's file.
inline std::filesystem::path temp_file(const std::string& ext) {
  const char* dir = std::getenv("TMPDIR");
  return std::filesystem::path(dir && *dir ? dir : "/tmp") /
         ("floesim-fuzz-" + std::to_string(::getpid()) + ext);
}

inline const std::filesystem::path& write_input(const std::filesystem::path& file, const uint8_t* data,
                                                size_t size) {
  FILE* f = std::fopen(file.c_str(), "wb");
  if (!f) std::abort();  // the harness's own environment is broken: not a finding in the code under test
  if (size) std::fwrite(data, 1, size, f);
  std::fclose(f);
  return file;
}

// Runs f; floesim::Error is the expected refusal of bad input and is swallowed, anything else propagates.
template <class F>
void expect_ok_or_error(F&& f) {
  try {
    f();
  } catch (const floesim::Error&) {
  }
}

}  // namespace floesim::fuzz
