// Hull meshes through the loader (sim/vessel/hull.h load_hull: assimp, welding, orientation, convexity, slicing) and the
// measurement of their particulars for the ice-resistance formulas (sim/vessel/particulars.h). The
// input is written to a file with the extension FUZZ_HULL_EXT (".obj", ".stl", ".ply"), as a user's mesh would be.
#include "fuzz_util.h"
#include "sim/vessel/hull.h"
#include "sim/vessel/particulars.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const auto file = floesim::fuzz::temp_file(FUZZ_HULL_EXT);
  floesim::fuzz::write_input(file, data, size);
  floesim::fuzz::expect_ok_or_error([&] {
    floesim::sim::HullLoadOptions o;
    o.slices = 6;  // fewer sections than the default 24: faster per input, the same code paths
    const floesim::sim::HullModel h = floesim::sim::load_hull(file, o);
    (void)floesim::sim::measure_particulars(h.mesh, "fuzz input");
  });
  return 0;
}
