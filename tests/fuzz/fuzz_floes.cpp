// The floes GeoJSON artefact (pipeline/floes_io.h read_floes), then written back and re-read: an accepted field
// must round-trip.
#include "fuzz_util.h"
#include "pipeline/floes_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const auto file = floesim::fuzz::temp_file(".geojson");
  static const auto back = floesim::fuzz::temp_file(".back.geojson");
  floesim::fuzz::write_input(file, data, size);
  floesim::fuzz::expect_ok_or_error([&] {
    const floesim::FloeField f = floesim::read_floes(file);
    floesim::write_floes(back, f);
    try {
      const floesim::FloeField g = floesim::read_floes(back);
      if (g.floes.size() != f.floes.size()) std::abort();
    } catch (const floesim::Error& e) {
      std::fprintf(stderr, "an accepted floe field does not read back: %s\n", e.what());
      std::abort();
    }
  });
  return 0;
}
