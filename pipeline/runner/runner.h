// The runner: a case folder -> a Ninja file over the stage executables -> ninja, which reruns only what is stale.
// Each stage's slice of case.json is written to RUN/config/<stage>.json only when its content changes, so a changed
// parameter makes exactly the stages downstream of it stale (ninja compares modification times).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/runner/plan.h"

namespace floesim::runner {

struct RunOptions {
  std::filesystem::path case_dir;   // folder holding case.json and the inputs it owns
  std::filesystem::path run_dir;    // outputs; default runs/<case folder name>
  std::filesystem::path bin_dir;    // where the stage executables live (default: beside the runner)
  int jobs = 0;                     // ninja -j; 0 = ninja's default
  bool dry_run = false;             // write the Ninja file, show what would run (ninja -n)
};


struct StageTiming {
  std::string stage;
  bool ran = false;       // ran in this invocation (else it was up to date)
  double wall_s = 0;      // from ninja's log
};

// Reads RUN/.ninja_log: the last recorded wall time of each of the planned stages (by its first output), and
// whether that output is newer than `since` (it ran in this invocation).
std::vector<StageTiming> stage_timings(const std::filesystem::path& run_dir, const std::vector<PlannedStage>& stages,
                                       std::filesystem::file_time_type since);

// Builds RUN/build.ninja and RUN/config/*.json from CASE/case.json (strictly validated at the top level).
// Returns the plan (its stages and the artefacts the run produces, for the closing tables).
CasePlan prepare_run(const RunOptions& o);

// prepare_run + ninja. Returns ninja's exit status (0 = all stages up to date or rebuilt).
int run_case(const RunOptions& o);

}  // namespace floesim::runner
