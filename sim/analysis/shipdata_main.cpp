// floesim-shipdata: a simulated transit (results.h5, summary.json) -> the measured-data CSV floesim-identify reads,
// with a sidecar identify config describing the simulated ship (the round trip of issue #11).
#include <iostream>

#include <CLI/CLI.hpp>

#include "pipeline/options.h"
#include "pipeline/options_describe.h"
#include "pipeline/stage_main.h"
#include "sim/analysis/shipdata.h"

int main(int argc, char** argv) {
  CLI::App app{"Turns a simulated transit into the data a ship would record (body velocities through the water, "
               "accelerations with IMU noise and bias, thrust, relative wind) as floesim-identify's CSV, and writes "
               "beside it FILE.json, the identify config of the simulated ship.",
               "floesim-shipdata"};
  std::string results, summary, config, out;
  bool help_config = false, check_config = false;
  app.add_option("--results", results, "results.h5 of floesim-simulate");
  app.add_option("--summary", summary, "its summary.json (default: beside --results)");
  app.add_option("--config", config, "JSON object of shipdata options (see --help-config); default: no noise");
  app.add_option("--out", out, "the CSV to write (FILE.csv; FILE.json and FILE.provenance.json beside it)");
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_flag("--help-config", help_config, "print the shipdata options as a Markdown table and exit");
  floesim::add_describe_config(app, [] {
    const floesim::sim::ShipDataOptions defaults;
    return floesim::options_description(defaults);
  });
  return floesim::run_stage(app, argc, argv, [&] {
    if (help_config) {
      const floesim::sim::ShipDataOptions defaults;
      std::cout << floesim::options_doc(defaults);
      return;
    }
    if (check_config) {
      if (config.empty()) throw floesim::Error("--check-config needs --config FILE");
      floesim::read_options<floesim::sim::ShipDataOptions>(floesim::load_json_file(config), config);
      return;
    }
    if (results.empty() || out.empty()) throw floesim::Error("--results and --out are required (see --help)");
    std::cout << floesim::sim::run_shipdata(results, summary, config, out);
  });
}
