// Child processes of the runner: a program run with its output piped back (a stop signal passed on to it), and
// the check of a stage's settings by the stage itself.
#pragma once
#include <sys/types.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/runner/plan.h"

namespace floesim::runner {

struct Output {
  int code = 0;
  std::string text;  // stdout and stderr
};

// A program running with its stdout and stderr coming back through a pipe (argv[0] searched in PATH; `env` set in
// the child only).
struct Child {
  pid_t pid = -1;
  FILE* out = nullptr;
};
Child spawn_piped(const std::vector<std::string>& args,
                  const std::vector<std::pair<std::string, std::string>>& env = {});

// Closes the pipe and waits: the exit status (128 + the signal if killed).
int wait_child(Child& c);

// One line from a child's pipe; false at its end. A stop signal (EINTR) does not end it: the child is told too,
// and its last lines still come; `on_signal` (if any) runs at once, while the child's children are still stopping.
bool read_line(FILE* in, char* line, int size, const std::function<void()>& on_signal = {});

// Runs a program and collects its output.
Output run_capture(const std::vector<std::string>& args);

// Each stage checks its own settings (`--check-config`), from a copy in a temporary folder removed afterwards:
// per stage, "" when they are valid, else its problems with each key named by its path in the case
// (`simulate.duraton_s is not a known key; did you mean duration_s?`), without the stage's own prefix and the
// copy's name. Nothing else is written.
std::vector<std::string> stage_settings_problems(const std::vector<PlannedStage>& stages);

}  // namespace floesim::runner
