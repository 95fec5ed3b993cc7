// floesim-synth: writes a synthetic helicopter image of a known floe field and its truth (polygons and labels).
#include <iostream>

#include "imaging/synth.h"
#include "pipeline/options_describe.h"
#include "pipeline/stage_main.h"

int main(int argc, char** argv) {
  using namespace floesim;
  CLI::App app{"floesim-synth: synthetic helicopter image of a known floe field, with the true floe polygons"};
  app.name("floesim-synth");
  std::string config, out;
  bool check_config = false;
  app.add_option("--config", config, "JSON options (see --help-config); without it, the defaults");
  app.add_option("--out", out, "output directory (image.png, truth.geojson, truth_labels.png)");
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_flag_callback(
      "--help-config",
      [] {
        std::cout << options_doc(imaging::SynthOptions{});
        throw CLI::Success();
      },
      "print the options table and exit");
  add_describe_config(app, [] { return options_description(imaging::SynthOptions{}); });
  return run_stage(app, argc, argv, [&] {
    const auto opts =
        config.empty() ? imaging::SynthOptions{} : read_options<imaging::SynthOptions>(load_json_file(config), config);
    if (check_config) return;
    FLOESIM_REQUIRE(!out.empty(), "--out DIR is required (the directory that receives the image and its truth)");
    const auto res = imaging::run_synth(opts, out);
    for (const auto& w : res.warnings) std::cerr << "floesim-synth: warning: " << w << "\n";
    std::cout << "floesim-synth: " << res.truth.floes.size() << " floes, concentration " << res.concentration << ", "
              << res.brash_fragments << " brash fragments, " << res.ponds << " ponds -> " << out << "\n";
  });
}
