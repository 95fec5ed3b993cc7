#include "imaging/stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include "pipeline/geometry2d.h"

namespace floesim::imaging {

namespace {

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

double choose_fit_min_diameter(const std::vector<double>& d, int min_tail, double* ks_out) {
  const int n = static_cast<int>(d.size());
  if (n == 0) return 0.0;
  if (n < min_tail || min_tail < 2) {
    if (ks_out) *ks_out = std::numeric_limits<double>::quiet_NaN();
    return d.front();
  }
  const int last = n - min_tail;  // candidates d[0..last]
  const int step = std::max(1, (last + 1) / 100);
  double best_ks = HUGE_VAL, best = d.front();
  const double dmax = d.back();
  for (int i = 0; i <= last; i += step) {
    if (i > 0 && d[i] == d[i - 1]) continue;
    const double a = d[i];
    if (!(dmax > a)) break;
    const PowerLawFit f = fit_power_law(d, a, dmax);
    if (!std::isfinite(f.alpha)) continue;
    const double e = 1 - f.alpha, ua = std::abs(e) < 1e-9 ? std::log(a) : std::pow(a, e),
                 ub = std::abs(e) < 1e-9 ? std::log(dmax) : std::pow(dmax, e);
    auto cdf = [&](double x) { return ((std::abs(e) < 1e-9 ? std::log(x) : std::pow(x, e)) - ua) / (ub - ua); };
    const int m = n - i;
    double ks = 0;
    for (int k = i; k < n; ++k) {
      const double F = cdf(d[k]);
      ks = std::max({ks, std::abs(F - double(k - i + 1) / m), std::abs(F - double(k - i) / m)});
    }
    if (ks < best_ks) best_ks = ks, best = a;
  }
  if (ks_out) *ks_out = best_ks;
  return best;
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

  double fit_ks = std::numeric_limits<double>::quiet_NaN();
  const double dmin = fit_min_diameter_m > 0 ? fit_min_diameter_m : choose_fit_min_diameter(d, 30, &fit_ks);
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
  pl["d_min_choice"] = fit_min_diameter_m > 0
                          ? "fit_min_diameter_m of the options"
                          : "Kolmogorov-Smirnov-minimising d_min of the truncated fit (Clauset, Shalizi & Newman "
                            "2009; at least 30 floes above it)";
  if (std::isfinite(fit_ks)) pl["d_min_ks_distance"] = fit_ks;
  j["power_law"] = pl;
  return j;
}

namespace {
std::string fmt_num(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
// Tick label of 10^k: plain for -2..3, else 1e<k>.
std::string decade_label(int k) {
  if (k >= 0 && k <= 3) return fmt_num("%.0f", std::pow(10.0, k));
  if (k < 0 && k >= -2) return fmt_num(k == -1 ? "%.1f" : "%.2f", std::pow(10.0, k));
  return "1e" + std::to_string(k);
}
}  // namespace

cv::Mat plot_size_distribution(const nlohmann::json& st, const std::string& title) {
  const int W = 720, H = 540, x0 = 90, x1 = W - 30, y0 = 60, y1 = H - 70;  // plot box
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Scalar black(0, 0, 0), grey(200, 200, 200), blue(180, 90, 20), red(40, 40, 220);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(img, title, cv::Point(x0, 25), font, 0.5, black, 1, cv::LINE_AA);
  struct Pt {
    double d, n;
  };
  std::vector<Pt> pts;
  for (const auto& b : st["size_distribution"]["bins"])
    if (b["count"].get<int>() > 0)
      pts.push_back({std::sqrt(b["d_min_m"].get<double>() * b["d_max_m"].get<double>()),
                     b["number_density_per_m3"].get<double>()});
  const auto& fit = st["power_law"]["truncated_mle"];
  const bool has_fit = fit["alpha"].is_number() && fit["d_max_m"].is_number() && fit["n"].get<int>() >= 2;
  if (pts.empty()) {
    cv::putText(img, "no floes", cv::Point(W / 2 - 50, H / 2), font, 0.8, black, 1, cv::LINE_AA);
    return img;
  }
  // Axis ranges: whole decades around the data.
  double dlo = pts.front().d, dhi = pts.front().d, nlo = pts.front().n, nhi = pts.front().n;
  for (const Pt& p : pts) {
    dlo = std::min(dlo, p.d), dhi = std::max(dhi, p.d), nlo = std::min(nlo, p.n), nhi = std::max(nhi, p.n);
  }
  double c_fit = 0, a_fit = 0, dmin_fit = 0, dmax_fit = 0;
  if (has_fit) {
    // n(D) = C D^-alpha on [d_min, d_max] holding the fitted floes per unit area:
    // C = (n_fit / A) (1 - alpha) / (d_max^(1-alpha) - d_min^(1-alpha)) (alpha -> 1: 1 / ln(d_max / d_min)).
    a_fit = fit["alpha"].get<double>(), dmin_fit = fit["d_min_m"].get<double>(), dmax_fit = fit["d_max_m"].get<double>();
    const double per_area = fit["n"].get<int>() / std::max(st["valid_area_m2"].get<double>(), 1e-300);
    c_fit = std::abs(a_fit - 1) < 1e-9
                ? per_area / std::log(dmax_fit / dmin_fit)
                : per_area * (1 - a_fit) / (std::pow(dmax_fit, 1 - a_fit) - std::pow(dmin_fit, 1 - a_fit));
    for (double d : {dmin_fit, dmax_fit}) {
      const double v = c_fit * std::pow(d, -a_fit);
      if (v > 0 && std::isfinite(v)) nlo = std::min(nlo, v), nhi = std::max(nhi, v);
    }
  }
  const int kx0 = static_cast<int>(std::floor(std::log10(dlo))), kx1 = std::max(kx0 + 1, static_cast<int>(std::ceil(std::log10(dhi))));
  const int ky0 = static_cast<int>(std::floor(std::log10(nlo))), ky1 = std::max(ky0 + 1, static_cast<int>(std::ceil(std::log10(nhi))));
  auto X = [&](double d) { return x0 + (std::log10(d) - kx0) / (kx1 - kx0) * (x1 - x0); };
  auto Y = [&](double n) { return y1 - (std::log10(n) - ky0) / (ky1 - ky0) * (y1 - y0); };
  for (int k = kx0; k <= kx1; ++k) {
    const int x = static_cast<int>(std::lround(X(std::pow(10.0, k))));
    cv::line(img, {x, y0}, {x, y1}, grey, 1);
    const std::string l = decade_label(k);
    cv::putText(img, l, cv::Point(x - 4 * static_cast<int>(l.size()), y1 + 20), font, 0.45, black, 1, cv::LINE_AA);
  }
  for (int k = ky0; k <= ky1; ++k) {
    const int y = static_cast<int>(std::lround(Y(std::pow(10.0, k))));
    cv::line(img, {x0, y}, {x1, y}, grey, 1);
    cv::putText(img, "1e" + std::to_string(k), cv::Point(x0 - 55, y + 5), font, 0.45, black, 1, cv::LINE_AA);
  }
  cv::rectangle(img, {x0, y0}, {x1, y1}, black, 1);
  cv::putText(img, "equivalent diameter D = sqrt(4A/pi) (m)", cv::Point(x0 + 150, H - 25), font, 0.5, black, 1,
              cv::LINE_AA);
  cv::putText(img, "n(D) (floes per m^2 per m)", cv::Point(x0 + 5, y0 - 8), font, 0.45, black, 1, cv::LINE_AA);
  if (has_fit) {
    const double a = a_fit, dmin = dmin_fit, dmax = dmax_fit, c = c_fit;
    std::vector<cv::Point> line;
    for (int i = 0; i <= 50; ++i) {
      const double d = dmin * std::pow(dmax / dmin, i / 50.0), n = c * std::pow(d, -a);
      if (n <= 0 || !std::isfinite(n)) continue;
      line.emplace_back(static_cast<int>(std::lround(X(d))), static_cast<int>(std::lround(std::clamp(Y(n), double(y0), double(y1)))));
    }
    if (line.size() >= 2) cv::polylines(img, std::vector<std::vector<cv::Point>>{line}, false, red, 2, cv::LINE_AA);
    const std::string legend = "truncated power-law fit: alpha = " + fmt_num("%.2f", a) + " +- " +
                               fmt_num("%.2f", fit["alpha_stderr"].is_number() ? fit["alpha_stderr"].get<double>() : NAN) +
                               " (D " + fmt_num("%.3g", dmin) + "-" + fmt_num("%.3g", dmax) + " m, " +
                               std::to_string(fit["n"].get<int>()) + " floes)";
    cv::line(img, {x0 + 10, y1 - 15}, {x0 + 40, y1 - 15}, red, 2, cv::LINE_AA);
    cv::putText(img, legend, cv::Point(x0 + 48, y1 - 10), font, 0.42, black, 1, cv::LINE_AA);
  }
  for (const Pt& p : pts)
    cv::circle(img, cv::Point(static_cast<int>(std::lround(X(p.d))), static_cast<int>(std::lround(Y(p.n)))), 5, blue,
               cv::FILLED, cv::LINE_AA);
  return img;
}

std::string size_distribution_csv(const nlohmann::json& st) {
  std::ostringstream out;
  out << "d_min_m,d_max_m,count,number_density_per_m3\n";
  for (const auto& b : st["size_distribution"]["bins"])
    out << fmt_num("%.6g", b["d_min_m"].get<double>()) << "," << fmt_num("%.6g", b["d_max_m"].get<double>()) << ","
        << b["count"].get<int>() << "," << fmt_num("%.6g", b["number_density_per_m3"].get<double>()) << "\n";
  return out.str();
}

}  // namespace floesim::imaging
