// floesim: the runner. `floesim run cases/<name>` runs a case's stages in order, make-style.
#include <iostream>

#include "pipeline/runner/runner.h"
#include "pipeline/runner/sweep.h"
#include "pipeline/stage_main.h"

int main(int argc, char** argv) {
  CLI::App app{"floesim: ship transit through broken sea ice, from a helicopter image to a rendered video.\n"
               "Stages (each also runs alone): floesim-synth, floesim-digitise, floesim-hull, floesim-simulate,\n"
               "floesim-render, floesim-plot.",
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
