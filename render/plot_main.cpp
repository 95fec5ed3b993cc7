// floesim-plot: results HDF5 -> surge ice load plot (PNG, SVG) with fracture events marked, CSVs and the numbers
// (plot.json).
#include <iostream>

#include "pipeline/options_describe.h"
#include "pipeline/stage_main.h"
#include "render/plot.h"

int main(int argc, char** argv) {
  CLI::App app{"Plot the surge ice load of a simulated transit: raw, moving average and steady-state mean",
               "floesim-plot"};
  std::string results, config, out, identified;
  bool check_config = false;
  app.add_option("--results", results, "simulation results (HDF5, from floesim-simulate)");
  app.add_option("--config", config, "plot options (JSON; see --help-config)")->required();
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_option("--out", out, "output directory");
  app.add_option("--identified", identified,
                 "also plot the ice load floesim-identify found (its output folder: identified.csv and "
                 "identified.json) as identified_load.{png,svg}");
  app.add_flag_callback("--help-config", [] {
    std::cout << floesim::options_doc(floesim::render::PlotOptions{});
    throw CLI::Success();
  }, "print the plot options (key, default, unit, meaning) and exit");
  floesim::add_describe_config(app, [] { return floesim::options_description(floesim::render::PlotOptions{}); });
  return floesim::run_stage(app, argc, argv, [&] {
    if (check_config) {
      floesim::render::read_plot_options(config);
      return;
    }
    if (results.empty() || out.empty()) throw floesim::Error("--results and --out are required (see --help)");
    const auto s = floesim::render::plot_surge_load(results, config, out);
    std::cout << "wrote " << out << "/surge_ice_load.{png,svg,csv}, fracture_events.csv and plot.json: mean ice "
              << "resistance " << floesim::load_text(1000.0 * s.mean_kN, s.display_unit)
              << (std::isfinite(s.interval.half_width)
                      ? " ± " + floesim::load_text(1000.0 * s.interval.half_width, s.display_unit) + " (95 %)"
                      : std::string())
              << " over t >= " << s.steady_start_s << " s (" << s.contact_model
              << " contacts, " << s.window_s << " s moving average); " << s.fracture_events << " fracture events, "
              << s.vessel_splitting_events + s.vessel_bending_radial_events << " at the vessel\n";
    for (const std::string& stem : floesim::render::plot_structure_loads(results, config, out))
      std::cout << "wrote " << out << "/" << stem << ".{png,svg}\n";
    if (!identified.empty()) {
      const auto p = floesim::render::plot_identified_load(identified, floesim::render::read_plot_options(config),
                                                           out);
      std::cout << "wrote " << out << "/identified_load.{png,svg}: identified mean resistance "
                << p.mean_identified_kN << " kN" << (p.known ? ", simulated " + std::to_string(p.mean_known_kN) +
                                                                   " kN over the same window"
                                                             : std::string())
                << "\n";
    }
  });
}
