// Floe statistics: the size distribution table and power-law fits of it.
#pragma once
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
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

// Clauset, Shalizi & Newman's (2009) choice of d_min: the candidate (an observed diameter with at least min_tail
// floes at or above it; at most ~100 candidates spread over the sorted sample) whose truncated power-law fit on
// [d_min, largest] has the smallest Kolmogorov-Smirnov distance to the diameters it covers. Below d_min the
// image under-resolves floes, so the distribution bends over and a fit from the smallest floe is biased low.
// `diameters` sorted ascending; returns the smallest diameter if there are fewer than min_tail.
double choose_fit_min_diameter(const std::vector<double>& diameters, int min_tail = 30, double* ks = nullptr);

// stats.json's content: count, concentration, areas, the size distribution table (log-spaced bins of equivalent
// diameter D = sqrt(4 A / pi), `bins_per_decade` per decade, counts and number density), and both power-law fits
// above fit_min_diameter_m (0: chosen by choose_fit_min_diameter).
nlohmann::json floe_statistics(const std::vector<double>& areas_m2, double ice_area_m2, double valid_area_m2,
                               int bins_per_decade, double fit_min_diameter_m);

// The size distribution of floe_statistics' output as a log-log plot (BGR image, OpenCV drawing, so the same
// statistics give the same bytes): number density per bin against equivalent diameter, and the truncated
// power-law fit as a line over its range with its exponent in the title. An empty table gives a plot that says so.
cv::Mat plot_size_distribution(const nlohmann::json& stats, const std::string& title);

// The size distribution table as CSV (one row per bin: d_min_m, d_max_m, count, number_density_per_m3).
std::string size_distribution_csv(const nlohmann::json& stats);

}  // namespace floesim::imaging
