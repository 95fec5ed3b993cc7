// floesim-resistance: Lindqvist's and Riska's level-ice resistance (PHYSICS.md §6.1-6.2) for a hull (the hull.json
// floesim-hull writes, or particulars given in the config) and an ice sheet, over thicknesses and speeds.
#include <iostream>

#include <CLI/CLI.hpp>

#include "pipeline/options.h"
#include "pipeline/stage_main.h"
#include "sim/analysis/resistance.h"

int main(int argc, char** argv) {
  CLI::App app{"Level-ice resistance by the empirical formulas of Lindqvist (1989: crushing R_c, bending R_b,\n"
               "submersion R_s) and Riska et al. (1997: C_1 + C_2 v), for the hull of --hull (the hull.json\n"
               "floesim-hull writes, with the angles it measured) and the ice of --config, over thicknesses and\n"
               "speeds. The reference a simulated level-ice resistance is held against.",
               "floesim-resistance"};
  std::string hull, config, out;
  std::vector<double> speeds, thicknesses;
  bool help_config = false, check_config = false;
  app.add_option("--hull", hull, "hull.json written by floesim-hull (its \"particulars\"); optional if the config's "
                                 "hull section gives them all");
  app.add_option("--config", config, "JSON object of resistance options (see --help-config); defaults if omitted");
  app.add_option("--speeds", speeds, "speeds in m/s, e.g. 1,2,3 (replaces the config's speeds_mps)")->delimiter(',');
  app.add_option("--thicknesses", thicknesses, "ice thicknesses in m, e.g. 0.5,1,1.5 (replaces thicknesses_m)")
      ->delimiter(',');
  app.add_option("--out", out, "FILE.json (the table, hull, ice, provenance) or FILE.csv (the table; FILE.json beside)");
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_flag("--help-config", help_config, "print the resistance options as a Markdown table and exit");
  return floesim::run_stage(app, argc, argv, [&] {
    namespace sim = floesim::sim;
    if (help_config) {
      std::cout << floesim::options_doc(sim::IceResistanceOptions{});
      return;
    }
    const floesim::Json j = config.empty() ? floesim::Json::object() : floesim::load_json_file(config);
    auto o = floesim::read_options<sim::IceResistanceOptions>(j, config.empty() ? "resistance options" : config);
    if (!speeds.empty()) o.speeds_mps = speeds;
    if (!thicknesses.empty()) o.thicknesses_m = thicknesses;
    if (check_config) {
      sim::resolve_ice_hull(o, hull, config, nullptr);  // the hull too: a missing particular is a config error
      return;
    }
    if (out.empty()) throw floesim::Error("--out FILE.json or FILE.csv is required (see --help)");
    std::cout << sim::run_resistance(o, hull, config, out);
  });
}
