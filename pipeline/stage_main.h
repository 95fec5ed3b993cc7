// The frame of every stage executable: parse options with CLI11, call the stage's library function, turn any
// error into a clear message on stderr and a non-zero exit (1 = failed, 2 = bad command line).
#pragma once
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace floesim {

// Adds --version to `app`, runs `parse` and then `body`; returns the process exit code.
int run_stage(CLI::App& app, int argc, char** argv, const std::function<void()>& body);

}  // namespace floesim
