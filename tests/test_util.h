#pragma once
// Helpers every test folder shares: the message of the Error a call throws, and a file's whole content.

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

}  // namespace floesim::tests
