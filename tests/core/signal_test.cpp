#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "pipeline/error.h"
#include "pipeline/signal.h"
#include "pipeline/units.h"

using namespace floesim;

namespace {
std::vector<double> ramp(size_t n, double a, double b) {
  std::vector<double> x(n);
  for (size_t i = 0; i < n; ++i) x[i] = a + b * static_cast<double>(i);
  return x;
}

// Load cycles of a structure (issue #34). An ISO-like sawtooth (PHYSICS.md §8.2.4: rises over 80 % of its period from
// 0.1 to 1.0 and drops at once), 4 s period at 0.01 s: every whole cycle peaks at exactly 1.0 and the up-crossings of
// the mean are exactly 400 samples apart, so the mean peak is 1.0 and the period 4 s to round-off; the autocorrelation
// peaks at 4 s.
TEST(LoadCycles, SawtoothPeaksAndPeriodAreItsOwn) {
  const double dt = 0.01;
  std::vector<double> x;
  for (int cycle = 0; cycle < 25; ++cycle) {
    for (int i = 0; i < 320; ++i) x.push_back(0.1 + 0.9 * i / 319.0);  // 0.1 .. 1.0 in 320 samples
    for (int i = 0; i < 80; ++i) x.push_back(0.1);
  }
  const LoadCycles c = load_cycles(x, dt);
  ASSERT_EQ(c.crossings.size(), 25u);  // one per cycle (the first rise crosses too)
  EXPECT_EQ(c.peak.size(), 24u);
  EXPECT_DOUBLE_EQ(c.mean_peak, 1.0);
  EXPECT_NEAR(c.mean_period_s, 4.0, 1e-12);
  for (size_t k = 0; k + 1 < c.crossings.size(); ++k) EXPECT_EQ(c.crossings[k + 1] - c.crossings[k], 400u);
  EXPECT_NEAR(dominant_period_s(x, dt, 1.0, 10.0), 4.0, dt);
}

// A sine of period 7.3 s and amplitude 1 with uniform noise of +-0.3 (a fixed linear congruential sequence): the
// autocorrelation finds 7.3 s within two samples; a hysteresis band of one standard deviation (0.73, more than twice
// the noise's reach) keeps one cycle per period (the noise makes many spurious crossings of the mean without it),
// and each cycle's peak is the sine's 1 give or take the noise.
TEST(LoadCycles, HysteresisKeepsNoisyCyclesWhole) {
  const double dt = 0.01, period = 7.3, duration = 73.0 * 2;
  uint64_t state = 12345;
  auto noise = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return 0.6 * (static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5);
  };
  std::vector<double> x;
  for (int i = 0; i < static_cast<int>(duration / dt); ++i)
    x.push_back(std::sin(2 * 3.14159265358979323846 * i * dt / period) + noise());
  EXPECT_NEAR(dominant_period_s(x, dt, 2.0, 20.0), period, 2 * dt);
  const LoadCycles c = load_cycles(x, dt, 1.0);
  EXPECT_EQ(c.peak.size(), 19u);  // 20 periods: 20 up-crossings, 19 whole cycles between them
  EXPECT_NEAR(c.mean_period_s, period, 0.05);
  for (double p : c.peak) {
    EXPECT_GT(p, 1.0 - 0.3);
    EXPECT_LE(p, 1.0 + 0.3);
  }
  EXPECT_GT(load_cycles(x, dt, 0.0).peak.size(), 40u);  // without the band the noise splits the cycles
  // A constant series has no period and no cycle.
  EXPECT_TRUE(std::isnan(dominant_period_s(std::vector<double>(5000, 2.0), dt, 1.0, 10.0)));
  // Nor has a slow ramp in a band of short lags: its autocorrelation only falls across the band (its largest value
  // at the band's lower end is no period). The sine above, searched from a tenth of its period, still has its own.
  std::vector<double> ramp;
  for (int i = 0; i < 20000; ++i) ramp.push_back(i * dt);
  EXPECT_TRUE(std::isnan(dominant_period_s(ramp, dt, 1.0, 10.0)));
  EXPECT_NEAR(dominant_period_s(x, dt, 0.73, 20.0), period, 2 * dt);
  EXPECT_TRUE(std::isnan(load_cycles(std::vector<double>(5000, 2.0), dt).mean_peak));
}

}  // namespace

TEST(Signal, WindowSamplesRoundsAndIsAtLeastOne) {
  EXPECT_EQ(window_samples(20.0, 0.01), 2000u);
  EXPECT_EQ(window_samples(0.5, 0.05), 10u);
  EXPECT_EQ(window_samples(0.5, 0.3), 2u);    // 1.67 rounds to 2
  EXPECT_EQ(window_samples(0.001, 0.01), 1u);
  EXPECT_EQ(window_samples(0.0, 0.01), 1u);
  EXPECT_THROW(window_samples(1.0, 0.0), Error);
}

TEST(Signal, MovingAverageOfAConstantIsTheConstantEverywhere) {
  const std::vector<double> x(101, 973.25);
  for (size_t n : {1u, 2u, 7u, 10u, 50u, 101u, 500u}) {
    for (const auto& y : {moving_average_centred(x, n), moving_average_causal(x, n)}) {
      ASSERT_EQ(y.size(), x.size());
      for (double v : y) EXPECT_NEAR(v, 973.25, 1e-9) << "window " << n;
    }
  }
}

TEST(Signal, WindowOneIsTheIdentity) {
  const std::vector<double> x = {3, -1, 4, 1, -5, 9, 2, 6};
  EXPECT_EQ(moving_average_centred(x, 1), x);
  EXPECT_EQ(moving_average_causal(x, 1), x);
}

TEST(Signal, CentredAverageOfARampIsTheRampInTheInterior) {
  const auto x = ramp(200, -3.0, 0.25);
  for (size_t n : {3u, 4u, 9u, 10u, 51u}) {  // odd and even windows: both centred, no lag
    const auto y = moving_average_centred(x, n);
    const auto [first, last] = full_window_range(x.size(), n);
    EXPECT_EQ(first, n / 2);
    EXPECT_EQ(last, x.size() - n / 2);
    for (size_t i = first; i < last; ++i) EXPECT_NEAR(y[i], x[i], 1e-9) << "window " << n << " i " << i;
    // At the ends the window is cut short on one side, so the average is pulled inwards.
    EXPECT_GT(y.front(), x.front());
    EXPECT_LT(y.back(), x.back());
  }
}

TEST(Signal, FullWindowRange) {
  EXPECT_EQ(full_window_range(10, 1), std::make_pair(size_t(0), size_t(10)));
  EXPECT_EQ(full_window_range(10, 3), std::make_pair(size_t(1), size_t(9)));
  EXPECT_EQ(full_window_range(10, 4), std::make_pair(size_t(2), size_t(8)));  // 5 taps: 2 each side
  EXPECT_EQ(full_window_range(11, 10), std::make_pair(size_t(5), size_t(6)));
  const auto none = full_window_range(10, 10);  // 11 taps do not fit in 10 samples
  EXPECT_GE(none.first, none.second);
}

TEST(Signal, CausalAverageOfARampLagsByHalfTheWindow) {
  const auto x = ramp(100, 0.0, 2.0);
  const size_t n = 10;
  const auto y = moving_average_causal(x, n);
  for (size_t i = n - 1; i < x.size(); ++i) EXPECT_NEAR(y[i], x[i] - 2.0 * (n - 1) / 2.0, 1e-9);
  EXPECT_DOUBLE_EQ(y[0], x[0]);
  EXPECT_NEAR(y[3], (0 + 2 + 4 + 6) / 4.0, 1e-12);  // first samples: mean of what exists
}

TEST(Signal, FullWindowAverageOfARampAndOfZerosAfterLoads) {
  // Whole windows only: size - N + 1 values, y_k the mean of x_k .. x_{k+N-1} (a ramp 2k: 2k + N - 1); a window of
  // zeros after large values averages to exactly 0 (a running or prefix sum would leave its residue).
  const auto x = ramp(100, 0.0, 2.0);
  const auto y = moving_average_full_windows(x, 10);
  ASSERT_EQ(y.size(), 91u);
  for (size_t k = 0; k < y.size(); ++k) EXPECT_NEAR(y[k], 2.0 * k + 9.0, 1e-12);
  std::vector<double> z = {1e17, -3e16, 7.1e15, 0, 0, 0, 0};
  EXPECT_EQ(moving_average_full_windows(z, 4).back(), 0.0);
  EXPECT_TRUE(moving_average_full_windows(z, 8).empty());
  EXPECT_TRUE(moving_average_full_windows(z, 0).empty());
}

TEST(Signal, EvenCentredWindowRemovesAnAlternationExactly) {
  // +-1 alternation: the half-weighted end samples make an even window cancel it (an odd one leaves 1/N).
  std::vector<double> x(60);
  for (size_t i = 0; i < x.size(); ++i) x[i] = 5.0 + (i % 2 ? 1.0 : -1.0);
  const auto y = moving_average_centred(x, 10);
  for (size_t i = 5; i + 5 < x.size(); ++i) EXPECT_NEAR(y[i], 5.0, 1e-12);
  const auto z = moving_average_centred(x, 9);
  for (size_t i = 4; i + 4 < x.size(); ++i) EXPECT_NEAR(std::abs(z[i] - 5.0), 1.0 / 9.0, 1e-12);
}

TEST(Signal, MeanOverTheSteadyPart) {
  std::vector<double> t, x;
  for (int i = 0; i < 10; ++i) t.push_back(i), x.push_back(i * i);
  const SteadyMean m = mean_from(t, x, 6.0);  // 36, 49, 64, 81
  EXPECT_EQ(m.samples, 4u);
  EXPECT_DOUBLE_EQ(m.mean, (36 + 49 + 64 + 81) / 4.0);
  EXPECT_DOUBLE_EQ(mean_from(t, x, 0.0).mean, 28.5);
  EXPECT_THROW(mean_from(t, x, 10.5), Error);
}

TEST(Signal, UniformStepChecksTheTimeColumn) {
  EXPECT_NEAR(uniform_step({0.01, 0.02, 0.03, 0.04}, "t"), 0.01, 1e-15);
  EXPECT_THROW(uniform_step({0.0}, "t"), Error);
  EXPECT_THROW(uniform_step({0.0, 0.1, 0.3}, "t"), Error);
  EXPECT_THROW(uniform_step({0.3, 0.2, 0.1}, "t"), Error);
}

// Loads read in the unit that suits their size (pipeline/units.h): a tank model's in N, a ship's in kN.
TEST(Units, ForceUnitSuitsTheMagnitude) {
  EXPECT_STREQ(force_unit_for(0.175).name, "N");      // a 7 m model in small floes
  EXPECT_STREQ(force_unit_for(-37.4).name, "N");
  EXPECT_STREQ(force_unit_for(999.0).name, "N");
  EXPECT_STREQ(force_unit_for(1000.0).name, "kN");
  EXPECT_STREQ(force_unit_for(1.038e6).name, "kN");   // Oden's 1038 kN stays in kN, as its references are given
  EXPECT_STREQ(force_unit_for(2.5e7).name, "MN");
  EXPECT_STREQ(force_unit_for(std::nan("")).name, "N");
  EXPECT_EQ(load_text(37.4, force_unit_for(37.4)), "37.4 N");
  EXPECT_EQ(load_text(1.038e6, force_unit_for(1.038e6)), "1038 kN");
  EXPECT_EQ(load_text(0.7, {"kN", 1e3}), "0.0007 kN");  // what the issue complained of: hence the choice above
  EXPECT_EQ(load_number(-0.0001), "0");
}
