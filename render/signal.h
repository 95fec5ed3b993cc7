// Ice-load post-processing (PHYSICS.md §5): moving averages and the steady-state mean. Plain functions on
// uniformly sampled series, so that tests can check them against closed-form answers.
#pragma once
#include <cstddef>
#include <utility>
#include <vector>

namespace floesim::render {

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

// Arithmetic mean of x[i] over the samples with t[i] >= t_start (the steady part). Error if there are none.
struct SteadyMean {
  double mean = 0;
  size_t samples = 0;
};
SteadyMean mean_from(const std::vector<double>& t, const std::vector<double>& x, double t_start);

// Sample step of a time column: (t_last - t_first) / (n - 1); Error if fewer than 2 samples, not increasing, or
// not uniform to 1 % (the averages above assume a fixed step).
double uniform_step(const std::vector<double>& t, const char* what);

}  // namespace floesim::render
