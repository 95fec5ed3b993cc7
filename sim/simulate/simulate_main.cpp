// floesim-simulate: a vessel transit through a floe field -> DIR/results.h5 and DIR/summary.json.
#include <filesystem>
#include <iostream>

#include <CLI/CLI.hpp>

#include "pipeline/options.h"
#include "pipeline/results_io.h"
#include "pipeline/vtk_series.h"
#include "pipeline/options_describe.h"
#include "pipeline/stage_main.h"
#include "sim/simulate/simulate.h"

int main(int argc, char** argv) {
  CLI::App app{"Simulates a vessel transit through a floe field (rigid non-smooth contacts, buoyancy by clipping, "
               "drag, ITTC-57 resistance, propulsion) and writes DIR/results.h5 and DIR/summary.json.",
               "floesim-simulate"};
  std::string floes, hull, config, out, paraview_from;
  bool help_config = false, check_config = false, resume = false, results_layout = false;
  app.add_option("--floes", floes, "floe field GeoJSON (floesim-digitise output)");
  app.add_option("--hull", hull, "hull mesh (OBJ of convex parts, e.g. floesim-hull output)");
  app.add_option("--config", config, "JSON object of simulate options (see --help-config)");
  app.add_option("--out", out, "output directory");
  app.add_flag("--resume", resume,
               "continue from the checkpoint in DIR/checkpoint (checkpoint_interval_s) if it is of the same inputs "
               "and settings (else an error says what differs); without one, start from t = 0");
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_flag("--help-config", help_config, "print the simulate options as a Markdown table and exit");
  app.add_flag("--results-layout", results_layout,
               "print the layout of results.h5 as a Markdown table (pipeline/results-layout.md) and exit");
  app.add_option("--paraview-from", paraview_from,
                 "write the ParaView series (DIR/paraview/results.pvd, as simulate.paraview does) of this existing "
                 "results.h5 into --out DIR, and exit");
  floesim::add_describe_config(app, [] {
    const floesim::sim::SimulateOptions defaults;  // named, as for --help-config
    return floesim::options_description(defaults);
  });
  return floesim::run_stage(app, argc, argv, [&] {
    if (!paraview_from.empty()) {
      if (out.empty()) throw floesim::Error("--paraview-from needs --out DIR");
      const size_t bytes = floesim::write_vtk_series(floesim::read_results(paraview_from, true, {"ice_load"}),
                                                     std::filesystem::path(out) / "paraview", paraview_from);
      std::cout << "wrote " << (std::filesystem::path(out) / "paraview" / "results.pvd").string() << " ("
                << bytes / 1e6 << " MB)\n";
      return;
    }
    if (results_layout) {
      std::cout << floesim::results_layout_markdown();
      return;
    }
    if (help_config) {
      const floesim::sim::SimulateOptions defaults;  // named: GCC 12 misreads a temporary's strings as uninitialised
      std::cout << floesim::options_doc(defaults);
      return;
    }
    if (check_config) {
      if (config.empty()) throw floesim::Error("--check-config needs --config FILE");
      floesim::read_options<floesim::sim::SimulateOptions>(floesim::load_json_file(config), config);
      return;
    }
    if (floes.empty() || hull.empty() || config.empty() || out.empty())
      throw floesim::Error("--floes, --hull, --config and --out are all required (see --help)");
    std::cout << floesim::sim::run_simulate(floes, hull, config, out, resume);
  });
}
