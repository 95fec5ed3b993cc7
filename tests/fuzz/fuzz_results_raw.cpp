// The results HDF5 reader on raw bytes: any file through libhdf5 and read_results. Mostly fuzzes libhdf5 itself, which
// is not memory-safe on damaged files (a heap overflow in H5Aexists within seconds, tests/fuzz/third-party/): its
// findings go to tests/fuzz/third-party/fuzz_results_raw/, it is not in the CI smoke, and fuzz_results (a valid HDF5
// container with fuzzed datasets and attributes) is the harness of our own reader's logic.
// FLOESIM_FUZZ_WRITE_SEED=FILE writes a small valid results file (the seed) and exits.
#include <hdf5.h>

#include <cmath>

#include "fuzz_util.h"
#include "small_results.h"
#include "pipeline/results_io.h"

namespace {

// The seed: a small valid results file (the one fuzz_results starts from).
void write_seed(const char* out) { floesim::write_results(out, floesim::fuzz::small_results()); }

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* out = std::getenv("FLOESIM_FUZZ_WRITE_SEED")) {
    write_seed(out);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const auto file = floesim::fuzz::temp_file(".h5");
  floesim::fuzz::write_input(file, data, size);
  floesim::fuzz::expect_ok_or_error([&] {
    const floesim::Results r = floesim::read_results(file);
    (void)r.steps();
  });
  // Every HDF5 id the reader opened is closed again, on success and on every error path (leaked ids keep the file
  // open in a long-running process). Leaks inside libhdf5 itself on a damaged file are not ours: suppressed in
  // tests/sanitize/lsan.supp.
  const ssize_t open_ids = H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL);
  if (open_ids != 0) {
    std::fprintf(stderr, "read_results left %zd HDF5 ids open\n", open_ids);
    std::abort();
  }
  return 0;
}
