// Every stage's options struct read strictly from any JSON (pipeline/options.h read_options), then echoed
// (options_to_json) and re-read: the echo of a resolved configuration must read back. Input: a JSON file (a stage's
// settings file, or a case file: then each stage's section is read too).
#include <fstream>

#include "fuzz_util.h"
#include "imaging/digitise_options.h"
#include "imaging/synth.h"
#include "pipeline/options.h"
#include "render/plot.h"
#include "render/render_options.h"
#include "render/report.h"
#include "sim/vessel/hull.h"
#include "sim/analysis/identify.h"
#include "sim/analysis/resistance.h"
#include "sim/analysis/shipdata.h"
#include "sim/simulate/options.h"

namespace {

template <class S>
void read_one(const floesim::Json& j, const std::string& file, const std::string& path) {
  floesim::fuzz::expect_ok_or_error([&] {
    const S s = floesim::read_options<S>(j, file, path);
    // The echo (recorded in every artefact's provenance) is what a rerun reads: it must be accepted again.
    const floesim::Json echo = floesim::options_to_json(s);
    (void)echo.dump();
    try {
      (void)floesim::read_options<S>(echo, file + " (echo)", path);
    } catch (const floesim::Error& e) {
      std::fprintf(stderr, "echo of accepted options is refused: %s\n", e.what());
      std::abort();
    }
  });
}

void read_all(const floesim::Json& j, const std::string& file, const std::string& path) {
  using namespace floesim;
  read_one<imaging::DigitiseOptions>(j, file, path);
  read_one<imaging::SynthOptions>(j, file, path);
  read_one<sim::SimulateOptions>(j, file, path);
  read_one<sim::HullGeneratorOptions>(j, file, path);
  read_one<sim::HullLoadOptions>(j, file, path);
  read_one<sim::HullImportOptions>(j, file, path);  // a case's hull section: file, placement, decomposition
  read_one<sim::IdentifyOptions>(j, file, path);
  read_one<sim::ShipDataOptions>(j, file, path);
  read_one<sim::IceResistanceOptions>(j, file, path);
  read_one<render::RenderOptions>(j, file, path);
  read_one<render::PlotOptions>(j, file, path);
  read_one<render::ReportOptions>(j, file, path);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const auto file = floesim::fuzz::temp_file(".json");
  floesim::fuzz::write_input(file, data, size);
  floesim::Json j;
  try {
    j = floesim::load_json_file(file);
  } catch (const floesim::Error&) {
    return 0;
  }
  read_all(j, file.string(), "");
  // A case file: each section through every struct (a wrong struct is refused with Error, which is fine).
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it)
      if (it->is_object()) read_all(*it, file.string(), it.key());
  return 0;
}
