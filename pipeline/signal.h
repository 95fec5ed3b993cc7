// Ice-load post-processing (PHYSICS.md §5): moving averages and the steady-state mean. Plain functions on
// uniformly sampled series, so that tests can check them against closed-form answers.
#pragma once
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace floesim {

// Samples in a window of `window_s` seconds at sample step `dt_s`: N = round(T_w / dt), at least 1.
size_t window_samples(double window_s, double dt_s);

// Centred moving average over N = window_samples samples (PHYSICS.md §5, for offline comparison).
// Odd N: y_n = mean of x_{n-(N-1)/2} .. x_{n+(N-1)/2}. Even N: the N+1 samples x_{n-N/2} .. x_{n+N/2} with the two
// end samples weighted 1/2, so the window still spans N sample steps and stays centred (no half-sample lag).
// Near the ends the window is cut to the samples that exist and renormalised (like pandas' min_periods=1), so the
// output has the input's length; only the interior (>= N/2 samples from either end) is a full-window average.
std::vector<double> moving_average_centred(const std::vector<double>& x, size_t window_samples);

// Samples [first, last) of a series of n whose centred window of N samples lies wholly inside the series (the
// interior above); empty (first >= last) when the series is shorter than the window.
std::pair<size_t, size_t> full_window_range(size_t n, size_t window_samples);

// Causal moving average: y_n = mean of x_{n-N+1} .. x_n (fewer samples at the start).
std::vector<double> moving_average_causal(const std::vector<double>& x, size_t window_samples);

// The moving average over whole windows only: y_k = mean of x_k .. x_{k+N-1}, size - N + 1 values (none when the
// series is shorter than N or N = 0). Each window is summed afresh, so that a window of zeros averages to exactly 0
// (no residue of a running or prefix sum, as the two above have): for the peak of a load series in a summary,
// O(size x N) additions, a few tens of millions at most.
std::vector<double> moving_average_full_windows(const std::vector<double>& x, size_t window_samples);

// Arithmetic mean of x[i] over the samples with t[i] >= t_start (the steady part). Error if there are none.
struct SteadyMean {
  double mean = 0;
  size_t samples = 0;
};
SteadyMean mean_from(const std::vector<double>& t, const std::vector<double>& x, double t_start);

// Running (cumulative) mean: y_n = mean of x_0 .. x_n. Shows whether a run was long enough for its mean to settle.
std::vector<double> running_mean(const std::vector<double>& x);

// Standard error of the mean of a correlated, stationary series by batch means: the series is cut into `batches`
// consecutive batches of m = floor(n / batches) samples, and SE = s_b / sqrt(batches), where s_b is the sample
// standard deviation (n - 1 denominator) of the batch means. Batches much longer than the correlation time have
// nearly independent means, so unlike the naive s / sqrt(n) this does not understate the error of a correlated
// signal. The n - batches * m leftover samples are dropped at the START: in a steady part those are the samples
// nearest the start-up transient. Error if batches < 2 or there are fewer samples than batches.
double batch_means_standard_error(const std::vector<double>& x, size_t batches);

// The uncertainty of one run's steady mean (issue #37): batch means (above) with kMeanBatches batches, the interval
// mean +- t_{(1+level)/2, b-1} SE (the b batch means are taken as independent and normal, so Student's t with b - 1
// degrees of freedom; Schmeiser 1982). Whether the interval means anything: the batches must be longer than the
// series' correlation time, which the lag-1 autocorrelation r1 of the batch means tests (Fishman 1978: independent
// means give r1 about -1/b with a spread of 1/sqrt(b); r1 above 1.645 / sqrt(b) rejects independence at 5 %, one
// sided). A steady part of fewer than 2 b samples, or correlated batch means, makes `meaningful` false and `note`
// say why: the run is too short for its interval.
inline constexpr size_t kMeanBatches = 20;  // Schmeiser (1982): 10 to 30 batches
inline constexpr double kMeanConfidence = 0.95;
struct MeanInterval {
  size_t samples = 0;
  size_t batches = 0, batch_samples = 0, dropped_samples = 0;  // the remainder dropped at the start
  double batch_s = 0;                                          // one batch's length in time
  double mean = 0;                                             // of all the samples
  double level = kMeanConfidence;
  double standard_error = 0, t_quantile = 0, half_width = 0;   // NaN with fewer samples than batches
  double batch_lag1 = 0;                                       // r1 of the batch means; NaN as above
  bool meaningful = false;
  std::string note;  // "" when meaningful
};
// Error if dt_s <= 0, a sample is not finite or `x` is empty.
MeanInterval mean_interval(const std::vector<double>& x, double dt_s, size_t batches = kMeanBatches,
                           double level = kMeanConfidence);

// Student-t confidence interval of the mean of independent samples (e.g. the members of an ensemble):
// mean +- t_{(1+level)/2, n-1} s / sqrt(n), with s the sample standard deviation (n - 1 denominator).
struct ConfidenceInterval {
  size_t n = 0;
  double mean = 0;        // NaN if n = 0
  double std = 0;         // sample standard deviation; NaN if n < 2
  double t_quantile = 0;  // t_{(1+level)/2, n-1}; NaN if n < 2
  double half_width = 0;  // t_quantile * std / sqrt(n); NaN if n < 2
};
// Error if level is not in (0, 1) or a sample is not finite.
ConfidenceInterval student_t_interval(const std::vector<double>& x, double level = 0.95);

// Load cycles of a structure in ice (issue #34; PHYSICS.md §8.2.4-8.2.5): the series is cut into cycles at its
// up-crossings of its mean, with a hysteresis band of `band_std` standard deviations (a crossing counts once the
// series has been below mean - band since the last one, so that noise on a slow rise does not split a cycle). Each
// cycle from one up-crossing to the next holds one peak, its largest sample; the incomplete parts before the first
// and after the last crossing are left out. `mean_peak` is the mean of the cycles' peaks (NaN without a whole
// cycle), `mean_period_s` the mean cycle length.
struct LoadCycles {
  std::vector<size_t> crossings;  // samples of the up-crossings (a cycle is [crossings[k], crossings[k+1]))
  std::vector<size_t> peak_index;
  std::vector<double> peak;
  double mean_peak = 0;
  double mean_period_s = 0;
};
LoadCycles load_cycles(const std::vector<double>& x, double dt_s, double band_std = 0.1);

// The dominant period of a series: the lag in [min_period_s, max_period_s] at which its autocorrelation (about its
// mean; the biased estimate, which tapers with the lag so that a period wins over its multiples) has its largest
// peak (positive, at least its neighbours), refined by a parabola through that lag and its neighbours. NaN when the
// series is constant, shorter than two of the longest lag, or has no peak in the band (no period there: its
// autocorrelation only falls across it). O(n x lags).
double dominant_period_s(const std::vector<double>& x, double dt_s, double min_period_s, double max_period_s);

// Sample step of a time column: (t_last - t_first) / (n - 1); Error if fewer than 2 samples, not increasing, or
// not uniform to 1 % (the averages above assume a fixed step).
double uniform_step(const std::vector<double>& t, const char* what);

}  // namespace floesim
