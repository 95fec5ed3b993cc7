#include "imaging/stats.h"

#include <algorithm>
#include <cmath>

namespace floesim::imaging {

namespace {
constexpr double kPi = 3.14159265358979323846;

// Mean and variance of u = ln(D / d_min) under p(D) ~ D^-alpha on [d_min, d_max], U = ln(d_max / d_min):
// u follows a truncated exponential of rate beta = alpha - 1 on [0, U].
void log_moments(double beta, double U, double& mean, double& var) {
  if (std::abs(beta * U) < 1e-6) {
    mean = U / 2;
    var = U * U / 12;
    return;
  }
  const double e = std::exp(-beta * U);
  mean = 1 / beta - U * e / (1 - e);
  var = 1 / (beta * beta) - U * U * e / ((1 - e) * (1 - e));
}
}  // namespace

PowerLawFit fit_power_law(const std::vector<double>& diameters, double d_min, double d_max) {
  PowerLawFit f;
  f.d_min = d_min;
  f.d_max = d_max;
  double sum_log = 0;
  for (double d : diameters)
    if (d >= d_min && d <= d_max) {
      ++f.n;
      sum_log += std::log(d / d_min);
    }
  if (f.n < 2 || sum_log <= 0) return f;
  const double mean = sum_log / f.n;
  if (!std::isfinite(d_max)) {
    f.alpha = 1 + 1 / mean;
    f.alpha_stderr = (f.alpha - 1) / std::sqrt(double(f.n));
    return f;
  }
  // E[u] decreases with beta: bisection.
  const double U = std::log(d_max / d_min);
  double lo = -20, hi = 20, m = 0, v = 0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    log_moments(mid, U, m, v);
    (m > mean ? lo : hi) = mid;
  }
  const double beta = 0.5 * (lo + hi);
  log_moments(beta, U, m, v);
  f.alpha = 1 + beta;
  f.alpha_stderr = v > 0 ? 1 / std::sqrt(f.n * v) : std::numeric_limits<double>::quiet_NaN();
  return f;
}

nlohmann::json floe_statistics(const std::vector<double>& areas_m2, double ice_area_m2, double valid_area_m2,
                               int bins_per_decade, double fit_min_diameter_m) {
  nlohmann::json j;
  const size_t n = areas_m2.size();
  j["floe_count"] = n;
  j["valid_area_m2"] = valid_area_m2;
  j["ice_area_m2"] = ice_area_m2;
  j["ice_concentration"] = valid_area_m2 > 0 ? ice_area_m2 / valid_area_m2 : 0.0;
  j["ice_concentration_definition"] = "floe area (label pixels) / valid image area (non-zero pixels)";
  std::vector<double> a = areas_m2;
  std::sort(a.begin(), a.end());
  std::vector<double> d;
  for (double x : a) d.push_back(std::sqrt(4 * x / kPi));
  double total = 0;
  for (double x : a) total += x;
  j["mean_area_m2"] = n ? total / n : 0.0;
  j["median_area_m2"] = n == 0 ? 0.0 : (n % 2 ? a[n / 2] : 0.5 * (a[n / 2 - 1] + a[n / 2]));
  j["min_area_m2"] = n ? a.front() : 0.0;
  j["max_area_m2"] = n ? a.back() : 0.0;

  nlohmann::json bins = nlohmann::json::array();
  if (n) {
    const int k0 = static_cast<int>(std::floor(std::log10(d.front()) * bins_per_decade));
    const int k1 = static_cast<int>(std::floor(std::log10(d.back()) * bins_per_decade));
    size_t i = 0;
    for (int k = k0; k <= k1; ++k) {
      const double lo = std::pow(10.0, double(k) / bins_per_decade),
                   hi = std::pow(10.0, double(k + 1) / bins_per_decade);
      int count = 0;
      while (i < n && (d[i] < hi || k == k1)) ++count, ++i;
      bins.push_back({{"d_min_m", lo},
                      {"d_max_m", hi},
                      {"count", count},
                      {"number_density_per_m3", valid_area_m2 > 0 ? count / ((hi - lo) * valid_area_m2) : 0.0}});
    }
  }
  j["size_distribution"] = {
      {"diameter", "equivalent diameter D = sqrt(4 A / pi) of the floe outline"},
      {"number_density", "count / (bin width in m * valid area in m^2): floes per m^2 of sea per m of diameter"},
      {"bins", bins}};

  const double dmin = fit_min_diameter_m > 0 ? fit_min_diameter_m : (n ? d.front() : 0.0);
  auto fit_json = [](const PowerLawFit& f) {
    return nlohmann::json{
        {"n", f.n},
        {"d_min_m", f.d_min},
        {"d_max_m", std::isfinite(f.d_max) ? nlohmann::json(f.d_max) : nlohmann::json(nullptr)},
        {"alpha", std::isfinite(f.alpha) ? nlohmann::json(f.alpha) : nlohmann::json(nullptr)},
        {"alpha_stderr", std::isfinite(f.alpha_stderr) ? nlohmann::json(f.alpha_stderr) : nlohmann::json(nullptr)}};
  };
  nlohmann::json pl;
  pl["model"] = "n(D) ~ D^-alpha for the equivalent diameter D";
  pl["mle"] = fit_json(fit_power_law(d, dmin));
  pl["mle"]["method"] =
      "continuous power-law maximum likelihood above d_min (Clauset, Shalizi & Newman 2009): "
      "alpha = 1 + n / sum ln(D_i / d_min), stderr = (alpha - 1) / sqrt(n)";
  pl["truncated_mle"] = fit_json(fit_power_law(d, dmin, n ? d.back() : dmin));
  pl["truncated_mle"]["method"] =
      "maximum likelihood of the power law truncated to [d_min, largest floe]: solves E[ln D] = mean ln D_i; "
      "use it when the largest floes are limited by the image (the untruncated fit is then biased high)";
  j["power_law"] = pl;
  return j;
}

}  // namespace floesim::imaging
