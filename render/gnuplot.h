// Running gnuplot, shared by the plot stage and the sweep gather: without a shell (no quoting pitfalls), its
// output into a log, and checked (exit status, every image non-empty), so a broken plot is an error, never a
// silently empty file.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace floesim::render {

// A gnuplot single-quoted string: only the quote itself needs escaping (doubled).
std::string gnuplot_quoted(const std::string& s);

// Runs gnuplot on `script` with stdout and stderr into `log`. Error (quoting the log) if it exits non-zero or any
// of `images` is missing or empty; `what` names the plot in the message.
void run_gnuplot(const std::filesystem::path& script, const std::filesystem::path& log,
                 const std::vector<std::filesystem::path>& images, const std::string& what);

}  // namespace floesim::render
