// floesim-identify: measured ship data (CSV) -> the ice load by the Fossen-type model of Kjerstad et al. (2018),
// DIR/identified.csv and DIR/identified.json.
#include <iostream>

#include <CLI/CLI.hpp>

#include "pipeline/options.h"
#include "pipeline/options_describe.h"
#include "pipeline/stage_main.h"
#include "sim/analysis/identify.h"

int main(int argc, char** argv) {
  CLI::App app{"Identifies the ice load on a ship from measured data: M nu_dot = tau_thr + tau_hyd + tau_wind + "
               "tau_ice in surge, sway and yaw, solved for tau_ice (PHYSICS.md §4.4). Writes DIR/identified.csv "
               "and DIR/identified.json.",
               "floesim-identify"};
  std::string measured, config, out;
  bool help_config = false, check_config = false;
  app.add_option("--measured", measured, "measured-data CSV (time_s,u_mps,v_mps,r_radps,thrust_n,wind_speed_mps,"
                                         "wind_angle_deg[,du_mps2,dv_mps2,dr_radps2])");
  app.add_option("--config", config, "JSON object of identify options (see --help-config); default: Oden's");
  app.add_option("--out", out, "output directory");
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_flag("--help-config", help_config, "print the identify options as a Markdown table and exit");
  floesim::add_describe_config(app, [] {
    const floesim::sim::IdentifyOptions defaults;
    return floesim::options_description(defaults);
  });
  return floesim::run_stage(app, argc, argv, [&] {
    if (help_config) {
      const floesim::sim::IdentifyOptions defaults;
      std::cout << floesim::options_doc(defaults);
      return;
    }
    if (check_config) {
      if (config.empty()) throw floesim::Error("--check-config needs --config FILE");
      floesim::read_options<floesim::sim::IdentifyOptions>(floesim::load_json_file(config), config);
      return;
    }
    if (measured.empty() || out.empty()) throw floesim::Error("--measured and --out are required (see --help)");
    std::cout << floesim::sim::run_identify(measured, config, out);
  });
}
