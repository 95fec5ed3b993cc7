// floesim-hull: writes the parametric icebreaker (Oden's main particulars by default) as an OBJ of convex parts,
// with a JSON sidecar of particulars, hydrostatics and provenance.
#include <iostream>

#include <CLI/CLI.hpp>

#include "pipeline/options.h"
#include "pipeline/stage_main.h"
#include "sim/hull.h"

int main(int argc, char** argv) {
  CLI::App app{"Writes a parametric icebreaker hull as an OBJ of convex parts (one object per part) plus FILE.json "
               "with its hydrostatics.",
               "floesim-hull"};
  std::string config, out;
  bool help_config = false, check_config = false;
  app.add_option("--config", config, "JSON object of hull options (see --help-config); defaults if omitted");
  app.add_option("--out", out, "output OBJ file; the sidecar is written beside it with extension .json");
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_flag("--help-config", help_config, "print the hull options as a Markdown table and exit");
  return floesim::run_stage(app, argc, argv, [&] {
    if (help_config) {
      std::cout << floesim::options_doc(floesim::sim::HullGeneratorOptions{});
      return;
    }
    floesim::sim::HullGeneratorOptions o;
    if (!config.empty()) o = floesim::read_options<floesim::sim::HullGeneratorOptions>(floesim::load_json_file(config), config);
    if (check_config) return;
    if (out.empty()) throw floesim::Error("--out FILE.obj is required");
    std::cout << floesim::sim::write_generated_hull(o, out, config);
  });
}
