// The runner: a case folder -> a Ninja file over the stage executables -> ninja, which reruns only what is stale.
// Each stage's slice of case.json is written to RUN/config/<stage>.json only when its content changes, so a changed
// parameter makes exactly the stages downstream of it stale (ninja compares modification times).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace floesim::runner {

struct RunOptions {
  std::filesystem::path case_dir;   // folder holding case.json and the inputs it owns
  std::filesystem::path run_dir;    // outputs; default runs/<case folder name>
  std::filesystem::path bin_dir;    // where the stage executables live (default: beside the runner)
  int jobs = 0;                     // ninja -j; 0 = ninja's default
  bool dry_run = false;             // write the Ninja file, show what would run (ninja -n)
};

struct Artefact {
  std::string stage, file, content;
};

// Builds RUN/build.ninja and RUN/config/*.json from CASE/case.json (strictly validated at the top level).
// Returns the artefacts the run produces (for the closing table).
std::vector<Artefact> prepare_run(const RunOptions& o);

// prepare_run + ninja. Returns ninja's exit status (0 = all stages up to date or rebuilt).
int run_case(const RunOptions& o);

}  // namespace floesim::runner
