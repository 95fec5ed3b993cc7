#pragma once
// Helpers every test folder shares: the message of the Error a call throws, a file's whole content, a command's
// exit code and output.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>

#include "pipeline/error.h"

namespace floesim::tests {

// The message of the floesim::Error a call throws, or "" if it throws none: what the bad-input tests compare with
// the message a user would read (the file, the key or row, the fix). Any other exception escapes and fails the test,
// as it would be a crash for the user.
template <class F>
std::string error_of(F&& f) {
  try {
    std::forward<F>(f)();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A file's bytes ("" if it cannot be read: the test's own check on the content then fails and says so).
inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A command's exit code and everything it printed (stdout and stderr).
struct CommandOutput {
  int code = 0;
  std::string text;
};

// Runs `command` in a POSIX shell with its stdout and stderr into `log` (kept for a failing test's message).
inline CommandOutput run_logged(const std::string& command, const std::filesystem::path& log) {
  const int status = std::system((command + " > '" + log.string() + "' 2>&1").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 1, read_text(log)};
}

}  // namespace floesim::tests
