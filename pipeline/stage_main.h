// The frame of every stage executable: parse options with CLI11, call the stage's library function, turn any
// error into a clear message on stderr and a non-zero exit (1 = failed, 2 = bad command line).
#pragma once
#include <functional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace floesim {

// Adds --version to `app`, runs `parse` and then `body`; returns the process exit code.
int run_stage(CLI::App& app, int argc, char** argv, const std::function<void()>& body);

// Adds --describe-config: prints `describe()` (options_description of the stage's options: each key's unit and
// meaning) as JSON and exits. The sweep runner labels its axes with it.
void add_describe_config(CLI::App& app, std::function<nlohmann::json()> describe);

}  // namespace floesim
