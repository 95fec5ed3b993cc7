// The runner: a case folder -> a Ninja file over the stage executables -> ninja, which reruns only what is stale.
// Each stage's slice of case.json is written to RUN/config/<stage>.json only when its content changes, so a changed
// parameter makes exactly the stages downstream of it stale (ninja compares modification times).
#pragma once
#include <sys/types.h>

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
  bool resume = false;              // the simulation continues from its last checkpoint (FLOESIM_RESUME)
  bool check_only = false;          // plan the case and check every stage's settings; run and write nothing
};

// Every stage checks its settings (`--check-config`) before anything of the run is written; the problems of all
// stages at once, as key paths of the case file, in one Error.
void check_case_settings(const CasePlan& plan, const std::filesystem::path& case_file);

// One writer at a time in a run folder: an exclusive lock (flock) on RUN/.floesim.lock, taken before anything is
// written and held by the runner, ninja and every stage it starts (they inherit the descriptor), so it is free only
// when every process of a run has ended, even of a run whose runner was killed (its stages may still be stopping).
// A second run into the same folder waits for it, saying so. Returns the descriptor (kept open for the process's
// life); Error if the folder cannot hold the lock file; Interrupted if a stop signal arrives while waiting.
int lock_run_folder(const std::filesystem::path& run_dir);

// Runs ninja (argv) as a child of this process and waits. A stop signal is passed on to ninja, which passes it to
// the running stages and waits for them; if this process is killed outright, ninja gets SIGTERM (PR_SET_PDEATHSIG)
// and does the same. `env` is set in ninja's environment. Returns ninja's exit status (128 + signal if it was killed),
// and in `running` the planned stages that were running when the first stop signal arrived (from /proc).
int run_ninja_child(const std::vector<std::string>& argv, const std::vector<std::pair<std::string, std::string>>& env,
                    const std::vector<PlannedStage>& stages, std::vector<std::string>* running);


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

// The planned stages that descendants of `ninja` (ninja -> sh -> stage) are running, by executable and folder.
std::vector<const PlannedStage*> running_stages(pid_t ninja, const std::vector<PlannedStage>& stages);

// prepare_run + ninja. Returns ninja's exit status (0 = all stages up to date or rebuilt).
int run_case(const RunOptions& o);

}  // namespace floesim::runner
