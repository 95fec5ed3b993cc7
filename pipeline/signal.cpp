#include "pipeline/signal.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <boost/math/distributions/students_t.hpp>

#include "pipeline/error.h"

namespace floesim {

size_t window_samples(double window_s, double dt_s) {
  FLOESIM_REQUIRE(std::isfinite(window_s) && window_s >= 0, "moving-average window must be >= 0 s, got ", window_s);
  FLOESIM_REQUIRE(std::isfinite(dt_s) && dt_s > 0, "sample step must be > 0 s, got ", dt_s);
  const double n = std::round(window_s / dt_s);
  return n < 1 ? 1 : static_cast<size_t>(n);
}

namespace {

// Prefix sums in long double: series of 1e6 samples keep ~1e-13 relative error in window sums.
std::vector<long double> prefix_sums(const std::vector<double>& x) {
  std::vector<long double> s(x.size() + 1, 0.0L);
  for (size_t i = 0; i < x.size(); ++i) s[i + 1] = s[i] + x[i];
  return s;
}

}  // namespace

std::vector<double> moving_average_centred(const std::vector<double>& x, size_t n_win) {
  FLOESIM_REQUIRE(n_win >= 1, "moving-average window must be at least 1 sample");
  if (n_win == 1 || x.empty()) return x;  // exact identity (prefix-sum differences would round)
  const auto s = prefix_sums(x);
  const long n = static_cast<long>(x.size());
  const long h = static_cast<long>(n_win / 2);
  const bool even = n_win % 2 == 0;
  std::vector<double> y(x.size());
  for (long i = 0; i < n; ++i) {
    const long lo = i - h, hi = i + h;
    const long a = std::max(lo, 0L), b = std::min(hi, n - 1);
    long double sum = s[b + 1] - s[a];
    long double weight = static_cast<long double>(b - a + 1);
    if (even) {
      // Half weights on the two end samples of the N+1-sample window, when they exist.
      if (a == lo) sum -= 0.5L * x[a], weight -= 0.5L;
      if (b == hi) sum -= 0.5L * x[b], weight -= 0.5L;
    }
    y[i] = static_cast<double>(sum / weight);
  }
  return y;
}

std::pair<size_t, size_t> full_window_range(size_t n, size_t n_win) {
  const size_t h = n_win / 2;  // odd N: (N-1)/2 each side; even N: N/2 each side (half-weighted ends)
  return n > 2 * h ? std::make_pair(h, n - h) : std::make_pair(size_t(0), size_t(0));
}

std::vector<double> moving_average_causal(const std::vector<double>& x, size_t n_win) {
  FLOESIM_REQUIRE(n_win >= 1, "moving-average window must be at least 1 sample");
  if (n_win == 1 || x.empty()) return x;
  const auto s = prefix_sums(x);
  std::vector<double> y(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    const size_t a = i + 1 >= n_win ? i + 1 - n_win : 0;
    y[i] = static_cast<double>((s[i + 1] - s[a]) / static_cast<long double>(i + 1 - a));
  }
  return y;
}

std::vector<double> moving_average_full_windows(const std::vector<double>& x, size_t n) {
  std::vector<double> y;
  if (n == 0 || x.size() < n) return y;
  y.reserve(x.size() - n + 1);
  for (size_t i = 0; i + n <= x.size(); ++i) {
    double s = 0;
    for (size_t k = i; k < i + n; ++k) s += x[k];
    y.push_back(s / static_cast<double>(n));
  }
  return y;
}

SteadyMean mean_from(const std::vector<double>& t, const std::vector<double>& x, double t_start) {
  FLOESIM_REQUIRE(t.size() == x.size(), "internal: time and value series differ in length");
  long double sum = 0;
  SteadyMean m;
  for (size_t i = 0; i < t.size(); ++i)
    if (t[i] >= t_start) sum += x[i], ++m.samples;
  FLOESIM_REQUIRE(m.samples > 0, "no samples at or after the steady start ", t_start, " s (the series ends at ",
                  t.empty() ? 0.0 : t.back(), " s): lower steady_start_s");
  m.mean = static_cast<double>(sum / static_cast<long double>(m.samples));
  return m;
}

std::vector<double> running_mean(const std::vector<double>& x) {
  std::vector<double> y(x.size());
  long double sum = 0;  // long double: a 1e6-sample running sum keeps ~1e-13 relative error
  for (size_t i = 0; i < x.size(); ++i) {
    sum += x[i];
    y[i] = static_cast<double>(sum / static_cast<long double>(i + 1));
  }
  return y;
}

double batch_means_standard_error(const std::vector<double>& x, size_t batches) {
  FLOESIM_REQUIRE(batches >= 2, "batch means need at least 2 batches, got ", batches);
  FLOESIM_REQUIRE(x.size() >= batches, "batch means: ", x.size(), " samples cannot fill ", batches,
                  " batches; a longer steady part is needed");
  return mean_interval(x, 1.0, batches).standard_error;
}

MeanInterval mean_interval(const std::vector<double>& x, double dt_s, size_t batches, double level) {
  FLOESIM_REQUIRE(dt_s > 0, "mean interval: the sample step must be positive, got ", dt_s);
  FLOESIM_REQUIRE(!x.empty(), "mean interval: no samples");
  FLOESIM_REQUIRE(batches >= 2, "mean interval: at least 2 batches, got ", batches);
  MeanInterval m;
  m.samples = x.size();
  m.batches = batches;
  m.level = level;
  const ConfidenceInterval all = student_t_interval(x, level);  // checks every sample is finite
  m.mean = all.mean;
  const double nan = std::nan("");
  m.standard_error = m.t_quantile = m.half_width = m.batch_lag1 = nan;
  m.batch_samples = x.size() / batches;
  m.dropped_samples = x.size() - batches * m.batch_samples;
  m.batch_s = static_cast<double>(m.batch_samples) * dt_s;
  if (m.batch_samples == 0) {
    m.note = "the steady part holds " + std::to_string(x.size()) + " samples, fewer than the " +
             std::to_string(batches) + " batches: no interval";
    return m;
  }
  std::vector<double> means(batches);
  for (size_t b = 0; b < batches; ++b) {
    long double sum = 0;
    for (size_t i = m.dropped_samples + b * m.batch_samples; i < m.dropped_samples + (b + 1) * m.batch_samples; ++i)
      sum += x[i];
    means[b] = static_cast<double>(sum / static_cast<long double>(m.batch_samples));
  }
  const ConfidenceInterval ci = student_t_interval(means, level);
  m.standard_error = ci.std / std::sqrt(static_cast<double>(batches));
  m.t_quantile = ci.t_quantile;
  m.half_width = ci.t_quantile * m.standard_error;
  long double num = 0, den = 0;
  for (size_t b = 0; b < batches; ++b) {
    den += (means[b] - ci.mean) * static_cast<long double>(means[b] - ci.mean);
    if (b > 0) num += (means[b] - ci.mean) * static_cast<long double>(means[b - 1] - ci.mean);
  }
  m.batch_lag1 = den > 0 ? static_cast<double>(num / den) : 0.0;
  const double limit = 1.645 / std::sqrt(static_cast<double>(batches));
  if (m.batch_samples < 2) {
    m.note = "the steady part holds " + std::to_string(x.size()) + " samples, fewer than 2 per batch: the run is " +
             "too short for its interval to mean anything";
  } else if (m.batch_lag1 > limit) {
    char buf[1024];
    std::snprintf(buf, sizeof buf,
                  "the batch means are correlated (lag-1 autocorrelation %.2f above 1.645 / sqrt(%zu) = %.2f): "
                  "batches of %.3g s are shorter than the load's correlation time, the run too short for its "
                  "interval to mean anything",
                  m.batch_lag1, batches, limit, m.batch_s);
    m.note = buf;
  } else {
    m.meaningful = true;
  }
  return m;
}

ConfidenceInterval student_t_interval(const std::vector<double>& x, double level) {
  FLOESIM_REQUIRE(level > 0 && level < 1, "confidence level must be in (0, 1), got ", level);
  ConfidenceInterval c;
  c.n = x.size();
  const double nan = std::nan("");
  c.mean = c.std = c.t_quantile = c.half_width = nan;
  if (c.n == 0) return c;
  long double sum = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    FLOESIM_REQUIRE(std::isfinite(x[i]), "confidence interval: sample ", i, " is not finite (", x[i], ")");
    sum += x[i];
  }
  c.mean = static_cast<double>(sum / static_cast<long double>(c.n));
  if (c.n < 2) return c;
  // Two passes (deviations from the mean): no cancellation when the spread is small against the mean.
  long double ss = 0;
  for (double v : x) ss += (v - c.mean) * static_cast<long double>(v - c.mean);
  c.std = std::sqrt(static_cast<double>(ss / static_cast<long double>(c.n - 1)));
  const boost::math::students_t dist(static_cast<double>(c.n - 1));
  c.t_quantile = boost::math::quantile(dist, 0.5 + 0.5 * level);
  c.half_width = c.t_quantile * c.std / std::sqrt(static_cast<double>(c.n));
  return c;
}

double uniform_step(const std::vector<double>& t, const char* what) {
  FLOESIM_REQUIRE(t.size() >= 2, what, " has ", t.size(), " samples; at least 2 are needed");
  const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  FLOESIM_REQUIRE(std::isfinite(dt) && dt > 0, what, " is not increasing");
  for (size_t i = 1; i < t.size(); ++i) {
    const double d = t[i] - t[i - 1];
    FLOESIM_REQUIRE(std::abs(d - dt) <= 0.01 * dt, what, " is not uniformly sampled: step ", d, " s at sample ", i,
                    " against a mean step of ", dt, " s");
  }
  return dt;
}

LoadCycles load_cycles(const std::vector<double>& x, double dt_s, double band_std) {
  FLOESIM_REQUIRE(dt_s > 0, "load_cycles: the sample step must be > 0, got ", dt_s);
  FLOESIM_REQUIRE(band_std >= 0, "load_cycles: the hysteresis band must be >= 0 standard deviations, got ", band_std);
  LoadCycles c;
  c.mean_peak = c.mean_period_s = std::numeric_limits<double>::quiet_NaN();
  const size_t n = x.size();
  if (n < 3) return c;
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  double var = 0;
  for (double v : x) var += (v - mean) * (v - mean);
  const double band = band_std * std::sqrt(var / static_cast<double>(n));
  // Armed once the series is below mean - band; an up-crossing of the mean while armed starts a cycle.
  bool armed = x[0] < mean - band;
  for (size_t i = 1; i < n; ++i) {
    if (x[i] < mean - band) armed = true;
    if (armed && x[i - 1] < mean && x[i] >= mean) {
      c.crossings.push_back(i);
      armed = x[i] < mean - band;
    }
  }
  for (size_t k = 0; k + 1 < c.crossings.size(); ++k) {
    size_t best = c.crossings[k];
    for (size_t i = c.crossings[k]; i < c.crossings[k + 1]; ++i)
      if (x[i] > x[best]) best = i;
    c.peak_index.push_back(best);
    c.peak.push_back(x[best]);
  }
  if (!c.peak.empty()) {
    double sum = 0;
    for (double p : c.peak) sum += p;
    c.mean_peak = sum / static_cast<double>(c.peak.size());
    c.mean_period_s = dt_s * static_cast<double>(c.crossings.back() - c.crossings.front()) /
                      static_cast<double>(c.peak.size());
  }
  return c;
}

double dominant_period_s(const std::vector<double>& x, double dt_s, double min_period_s, double max_period_s) {
  FLOESIM_REQUIRE(dt_s > 0 && min_period_s > 0 && max_period_s > min_period_s,
                  "dominant_period_s: needs dt > 0 and 0 < min_period_s < max_period_s, got dt ", dt_s, ", ",
                  min_period_s, " .. ", max_period_s, " s");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const size_t n = x.size();
  const size_t lo = std::max<size_t>(1, static_cast<size_t>(std::floor(min_period_s / dt_s)));
  const size_t hi = static_cast<size_t>(std::ceil(max_period_s / dt_s));
  if (n < 2 * (hi + 1)) return nan;
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  // The autocorrelation r(k) = sum (x_i - m)(x_{i+k} - m) / n (the biased estimate: it tapers with the lag, so of
  // a period's multiples, equal in a periodic signal, the shortest wins), one lag beyond each end for the parabola.
  auto r = [&](size_t k) {
    double s = 0;
    for (size_t i = 0; i + k < n; ++i) s += (x[i] - mean) * (x[i + k] - mean);
    return s / static_cast<double>(n);
  };
  if (!(r(0) > 0)) return nan;
  std::vector<double> rk(hi + 2);
  for (size_t k = lo - 1; k <= hi + 1; ++k) rk[k] = r(k);
  // The largest peak inside the band: a lag whose autocorrelation is positive and at least its neighbours'. A
  // series without a period there has none (its autocorrelation falls across the band, its largest value at an end).
  size_t best = 0;
  for (size_t k = lo; k <= hi; ++k)
    if (rk[k] > 0 && rk[k] >= rk[k - 1] && rk[k] >= rk[k + 1] && (best == 0 || rk[k] > rk[best])) best = k;
  if (best == 0) return nan;
  const double a = rk[best - 1], b = rk[best], c = rk[best + 1], d = a - 2 * b + c;
  const double shift = d < 0 ? 0.5 * (a - c) / d : 0.0;
  return dt_s * (static_cast<double>(best) + std::clamp(shift, -0.5, 0.5));
}

}  // namespace floesim
