// Errors that reach the user. Every stage catches floesim::Error in its main, prints what() and exits non-zero.
#pragma once
#include <sstream>
#include <stdexcept>
#include <string>

namespace floesim {

// A problem with the user's input (file, key, value) or the environment: reported, never asserted.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {
template <class... Args>
std::string concat(const Args&... args) {
  std::ostringstream os;
  (os << ... << args);
  return os.str();
}
}  // namespace detail

// Always-on check (unlike assert): throws floesim::Error with the message pieces concatenated.
#define FLOESIM_REQUIRE(cond, ...)                                          \
  do {                                                                      \
    if (!(cond)) throw ::floesim::Error(::floesim::detail::concat(__VA_ARGS__)); \
  } while (0)

}  // namespace floesim
