// Numbers as the analysis stages print and write them in their tables (floesim-resistance, floesim-ice-actions).
#pragma once
#include <charconv>
#include <cstdio>
#include <string>

namespace floesim::sim {

// The shortest text that reads back as the same double (as floesim-gather writes its tables).
inline std::string shortest(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// v with a fixed number of decimals.
inline std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

inline double kn(double n) { return n / 1e3; }

}  // namespace floesim::sim
