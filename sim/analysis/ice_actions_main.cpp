// floesim-ice-actions: the closed-form ice actions on a fixed structure (ISO 19906 crushing on a vertical face;
// Croasdale's and Ralston's methods on a cone; PHYSICS.md §8.1-8.2) over ice thicknesses, and the station keeping of
// a floating one (mooring catenaries, stiffness and offsets, DP gains; §8.4).
#include <iostream>

#include <CLI/CLI.hpp>

#include "pipeline/options.h"
#include "pipeline/stage_main.h"
#include "sim/analysis/ice_actions.h"

int main(int argc, char** argv) {
  CLI::App app{"Ice actions on a structure by the design formulas: ISO 19906 global crushing on a vertical\n"
               "structure, Croasdale's five terms and Ralston's method on a cone (PHYSICS.md 8.1-8.2), over ice\n"
               "thicknesses; and for a floating structure its mooring lines' catenaries, the spread's stiffness and\n"
               "offsets under steady loads, or the DP controller's gains (8.4); a ridge's keel by Dolgopolov with its\n"
               "surcharge bound and its consolidated layer as level ice (9.3). The references a simulated structure\n"
               "is held against.",
               "floesim-ice-actions"};
  std::string config, out, kind;
  std::vector<double> thicknesses;
  double width = 0, slope = 0;
  bool help_config = false, check_config = false;
  app.add_option("--config", config, "JSON object of options (see --help-config); defaults if omitted");
  app.add_option("--kind", kind, "cone or vertical (replaces structure.kind)");
  app.add_option("--width", width, "waterline width in m (replaces structure.waterline_width_m)");
  app.add_option("--slope", slope, "cone slope in deg from the horizontal (replaces structure.slope_deg)");
  app.add_option("--thicknesses", thicknesses, "ice thicknesses in m, e.g. 0.5,1 (replaces thicknesses_m)")
      ->delimiter(',');
  app.add_option("--out", out, "FILE.json (everything, with the provenance) or FILE.csv (the table; FILE.json beside)");
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_flag("--help-config", help_config, "print the options as a Markdown table and exit");
  return floesim::run_stage(app, argc, argv, [&] {
    namespace sim = floesim::sim;
    if (help_config) {
      std::cout << floesim::options_doc(sim::IceActionsOptions{});
      return;
    }
    floesim::Json j = config.empty() ? floesim::Json::object() : floesim::load_json_file(config);
    // Command-line values go through the same reader (and its checks) as the config's.
    if (!kind.empty()) j["structure"]["kind"] = kind;
    if (width != 0) j["structure"]["waterline_width_m"] = width;
    if (slope != 0) j["structure"]["slope_deg"] = slope;
    if (!thicknesses.empty()) j["thicknesses_m"] = thicknesses;
    const auto o = floesim::read_options<sim::IceActionsOptions>(j, config.empty() ? "the options" : config);
    if (check_config) return;
    if (out.empty()) throw floesim::Error("--out FILE.json or FILE.csv is required (see --help)");
    std::cout << sim::run_ice_actions(o, config, out);
  });
}
