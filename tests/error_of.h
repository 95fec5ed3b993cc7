#pragma once
// The message of the floesim::Error a call throws, or "" if it throws none: what the bad-input tests compare with
// the message a user would read (the file, the key or row, the fix). Any other exception escapes and fails the test,
// as it would be a crash for the user.

#include <string>
#include <utility>

#include "pipeline/error.h"

namespace floesim::tests {

template <class F>
std::string error_of(F&& f) {
  try {
    std::forward<F>(f)();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace floesim::tests
