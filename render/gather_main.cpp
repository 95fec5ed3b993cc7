// floesim-gather: a sweep's plan (RUN/plan.json, from floesim sweep) -> every member's numbers in one table
// (sweep.csv, sweep.json), ensemble statistics per grid point, and plots of the mean resistance against each axis.
#include <iostream>

#include "pipeline/stage_main.h"
#include "render/sweep_plots.h"

int main(int argc, char** argv) {
  CLI::App app{"Gather the members of a sweep: one row per member, ensemble means with 95 % confidence intervals "
               "per grid point, plots against each axis; failed members are listed, not fatal",
               "floesim-gather"};
  std::string plan, out;
  app.add_option("--plan", plan, "the sweep's plan (RUN/plan.json, written by floesim sweep)")->required();
  app.add_option("--out", out, "output directory (usually RUN)")->required();
  return floesim::run_stage(app, argc, argv, [&] {
    const floesim::sweep::SweepPlan p = floesim::sweep::read_sweep_plan(plan);
    const auto g = floesim::render::gather_sweep(p, plan, out);
    std::cout << floesim::sweep::gather_table(p, g) << "wrote";
    for (const auto& f : g.files) std::cout << " " << (std::filesystem::path(out) / f).string();
    std::cout << "\n";
  });
}
