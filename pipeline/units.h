// Units of force for people: plots, summaries and reports print loads in the unit that suits their size, so a
// 7 m tank model's loads read in newtons and a 108 m icebreaker's in kilonewtons (issue #13). Data files keep
// their fixed units (results in N, CSV and JSON columns in kN as named); only the text people read changes.
#pragma once
#include <cmath>
#include <cstdio>
#include <string>

namespace floesim {

// A number as printf's `format` writes one double ("%.4g", "%.1f"): the text people read in plots, videos, reports
// and printed tables.
inline std::string fmt(const char* format, double x) {
  char b[64];
  std::snprintf(b, sizeof b, format, x);
  return b;
}

struct ForceUnit {
  const char* name;  // "N", "kN" or "MN"
  double newtons;    // size of one unit in N
};

// The unit for loads of typical size `typical_n` (N; e.g. the mean or the peak of the series shown): N below
// 1 kN, kN up to 10 MN, MN from there. Full-scale ships keep kN (their references are given in kN).
inline ForceUnit force_unit_for(double typical_n) {
  const double a = std::isfinite(typical_n) ? std::abs(typical_n) : 0.0;
  if (a < 1e3) return {"N", 1.0};
  if (a < 1e7) return {"kN", 1e3};
  return {"MN", 1e6};
}

// A load already in some unit, as text: whole numbers from 100 up, three significant digits below; -0 and what
// rounds to it read as 0.
inline std::string load_number(double x) {
  char b[64];
  x += 0.0;
  if (std::abs(x) < 0.0005) x = 0;
  std::snprintf(b, sizeof b, std::abs(x) >= 100 ? "%.0f" : "%.3g", x);
  return b;
}

// A load in newtons as text in unit u: "37.4 N", "1038 kN".
inline std::string load_text(double newtons, const ForceUnit& u) {
  return load_number(newtons / u.newtons) + " " + u.name;
}

}  // namespace floesim
