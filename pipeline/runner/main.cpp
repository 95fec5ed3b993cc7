// floesim: the runner. `floesim run cases/<name>` runs a case's stages in order, make-style.
#include <iostream>

#include "pipeline/runner/runner.h"
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
  return floesim::run_stage(app, argc, argv, [&] {
    std::filesystem::path cd = o.case_dir;
    if (run_dir.empty()) {
      std::string name = std::filesystem::absolute(cd).lexically_normal().filename().string();
      if (name.empty()) name = std::filesystem::absolute(cd).lexically_normal().parent_path().filename().string();
      run_dir = "runs/" + name;
    }
    o.run_dir = run_dir;
    const int code = floesim::runner::run_case(o);
    if (code != 0) std::exit(code);
  });
}
