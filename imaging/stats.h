// Floe statistics: the size distribution table and power-law fits of it.
#pragma once
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

namespace floesim::imaging {

// Maximum-likelihood fit of a continuous power law p(D) ~ D^-alpha to the diameters D >= d_min (Clauset, Shalizi
// & Newman 2009, eq. 3.1 and its standard error (alpha-1)/sqrt(n)) when d_max is infinite; with a finite d_max,
// the truncated power law on [d_min, d_max]: alpha solves E_alpha[ln D] = mean(ln D_i) (bisection), standard
// error 1/sqrt(n Var_alpha[ln D]) (Fisher information).
struct PowerLawFit {
  int n = 0;
  double d_min = 0, d_max = 0;
  double alpha = std::numeric_limits<double>::quiet_NaN();
  double alpha_stderr = std::numeric_limits<double>::quiet_NaN();
};
PowerLawFit fit_power_law(const std::vector<double>& diameters, double d_min,
                          double d_max = std::numeric_limits<double>::infinity());

// stats.json's content: count, concentration, areas, the size distribution table (log-spaced bins of equivalent
// diameter D = sqrt(4 A / pi), `bins_per_decade` per decade, counts and number density), and both power-law fits.
nlohmann::json floe_statistics(const std::vector<double>& areas_m2, double ice_area_m2, double valid_area_m2,
                               int bins_per_decade, double fit_min_diameter_m);

}  // namespace floesim::imaging
