// floesim: the runner. `floesim run cases/<name>` runs a case's stages in order, make-style.
#include <iostream>

#include "pipeline/runner/runner.h"
#include "pipeline/runner/sweep.h"
#include "pipeline/stage_main.h"

int main(int argc, char** argv) {
  CLI::App app{"floesim: ships in sea ice, from a helicopter image to ice loads, a video and a report.\n"
               "`floesim run` runs a case's stages (only the stale ones), `floesim sweep` many variants of one.\n"
               "The stages, each an executable that also runs alone (--help; --help-config: every setting):\n"
               "  floesim-synth       synthetic helicopter image of known floes (a test image)\n"
               "  floesim-digitise    photo -> floe polygons (floes.geojson), labels, size distribution\n"
               "  floesim-score       digitised floes against hand-labelled ones (precision, recall, F1)\n"
               "  floesim-hull        parametric icebreaker, or a CAD mesh placed and cut into convex parts\n"
               "  floesim-simulate    the transit: floes + hull -> results.h5, summary.json\n"
               "  floesim-render      results -> off-screen H.264 video\n"
               "  floesim-plot        results -> surge ice load plot and CSVs\n"
               "  floesim-report      a run folder -> one self-contained HTML page\n"
               "  floesim-gather      a sweep's members -> sweep.csv, statistics and plots\n"
               "  floesim-identify    measured ship data -> identified ice loads\n"
               "  floesim-shipdata    a simulated transit -> the data a ship would have recorded\n"
               "  floesim-resistance  Lindqvist's and Riska's level-ice resistance for a hull\n"
               "  floesim-ice-actions structures by the design formulas (ISO 19906, Croasdale, Ralston; mooring, DP)",
               "floesim"};
  app.require_subcommand(1);
  floesim::runner::RunOptions o;
  std::string run_dir;
  auto* run = app.add_subcommand("run", "run a case (a folder with case.json); only stale stages rerun");
  run->add_option("case", o.case_dir, "case folder, e.g. cases/default")->required();
  run->add_option("--out", run_dir, "run folder for the artefacts (default: runs/<case folder name>)");
  run->add_option("--bin", o.bin_dir, "folder of the stage executables (default: beside floesim)");
  run->add_option("-j,--jobs", o.jobs, "stages run in parallel (default: ninja's choice)");
  run->add_flag("-n,--dry-run", o.dry_run, "show what would run, run nothing");
  run->add_flag("--check", o.check_only,
                "check the case and every stage's settings (each stage checks its own), run and write nothing; "
                "problems are named by their key in case.json");
  run->add_flag("--resume", o.resume,
                "continue the simulation from its last checkpoint (simulate.checkpoint_interval_s) if one of the same "
                "inputs exists; the results are byte-identical to a run never stopped");
  floesim::runner::SweepOptions so;
  std::string sweep_run_dir;
  auto* sweep = app.add_subcommand(
      "sweep", "run a sweep (a folder with sweep.json: axes x ensemble over a base case) here or on SLURM");
  sweep->add_option("sweep", so.sweep_dir, "sweep folder, e.g. cases/speed-concentration")->required();
  sweep->add_option("--out", sweep_run_dir, "run folder (default: runs/<sweep folder name>)");
  sweep->add_option("--bin", so.bin_dir, "folder of the stage executables (default: beside floesim)");
  sweep->add_option("-j,--jobs", so.jobs, "stages run in parallel here (default: ninja's choice)");
  sweep->add_flag("-n,--dry-run", so.dry_run, "plan and check every member's settings, show what would run");
  sweep->add_flag("--resume", so.resume, "members' simulations continue from their last checkpoints (as run --resume)");
  sweep->add_flag("--yes", so.yes, "run a sweep of more than 64 members");
  sweep->add_flag("--slurm", so.slurm, "submit to SLURM (sbatch job arrays, one per stage level) instead");
  sweep->add_flag("--wait", so.wait, "with --slurm: wait until the cluster has finished and gathered");
  // runs/<name of the folder>, also for a folder given with a trailing slash.
  auto default_run = [](const std::filesystem::path& dir) {
    const std::filesystem::path a = std::filesystem::absolute(dir).lexically_normal();
    const std::string name = a.filename().empty() ? a.parent_path().filename().string() : a.filename().string();
    return "runs/" + name;
  };
  return floesim::run_stage(app, argc, argv, [&] {
    int code = 0;
    if (*sweep) {
      so.run_dir = sweep_run_dir.empty() ? default_run(so.sweep_dir) : sweep_run_dir;
      code = floesim::runner::run_sweep(so);
    } else {
      o.run_dir = run_dir.empty() ? default_run(o.case_dir) : run_dir;
      code = floesim::runner::run_case(o);
    }
    if (code != 0) std::exit(code);
  });
}
