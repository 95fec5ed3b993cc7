// The sweep gather and its statistics: confidence intervals and batch-means standard errors against hand-computed
// and closed-form numbers; the gather on synthetic members whose summaries and series have known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include <sys/wait.h>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"
#include "pipeline/results_io.h"
#include "render/sweep_plots.h"
#include "pipeline/signal.h"
#include "synthetic_results.h"
#include "tests/test_util.h"

using namespace floesim;
using namespace floesim::render;
using namespace floesim::sweep;
using namespace floesim::render::testing;
namespace fs = std::filesystem;
using floesim::tests::read_text;

namespace {

// RFC 4180 rows: quoted fields may hold commas and doubled quotes (no line breaks in these files).
std::vector<std::vector<std::string>> read_csv(const fs::path& p) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(read_text(p));
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> row(1);
    bool quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') row.back() += '"', ++i;
      else if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) row.emplace_back();
      else row.back() += c;
    }
    rows.push_back(row);
  }
  return rows;
}

// ---- Confidence intervals ----

TEST(Gather, StudentTIntervalOfFiveValuesMatchesTheHandComputation) {
  // mean 3; s^2 = (4 + 1 + 0 + 1 + 4) / 4 = 2.5; t_{0.975, 4} = 2.7764451 (tables); 2.7764451 * 1.5811388 / sqrt(5).
  const ConfidenceInterval c = student_t_interval({1, 2, 3, 4, 5});
  EXPECT_EQ(c.n, 5u);
  EXPECT_NEAR(c.mean, 3.0, 1e-12);
  EXPECT_NEAR(c.std, 1.5811388, 1e-6);
  EXPECT_NEAR(c.t_quantile, 2.7764451, 1e-6);
  EXPECT_NEAR(c.half_width, 1.9632432, 1e-6);
  // 90 %: t_{0.95, 4} = 2.1318468 (tables).
  EXPECT_NEAR(student_t_interval({1, 2, 3, 4, 5}, 0.90).t_quantile, 2.1318468, 1e-6);
}

TEST(Gather, StudentTIntervalOfTwoValuesIsTheCauchyQuantile) {
  // One degree of freedom is the Cauchy distribution: t_{p,1} = tan(pi (p - 1/2)). {10, 14}: mean 12,
  // s = sqrt(2^2 + 2^2) = sqrt(8), half width = t sqrt(8) / sqrt(2) = 2 t.
  const double t = std::tan(kPi * (0.975 - 0.5));
  EXPECT_NEAR(t, 12.7062047, 1e-6);
  const ConfidenceInterval c = student_t_interval({10, 14});
  EXPECT_NEAR(c.mean, 12.0, 1e-12);
  EXPECT_NEAR(c.std, std::sqrt(8.0), 1e-12);
  EXPECT_NEAR(c.t_quantile, t, 1e-9);
  EXPECT_NEAR(c.half_width, 2 * t, 1e-8);
}

TEST(Gather, StudentTIntervalNeedsTwoValuesForAnInterval) {
  const ConfidenceInterval one = student_t_interval({7.5});
  EXPECT_EQ(one.n, 1u);
  EXPECT_EQ(one.mean, 7.5);
  EXPECT_TRUE(std::isnan(one.std) && std::isnan(one.t_quantile) && std::isnan(one.half_width));
  const ConfidenceInterval none = student_t_interval({});
  EXPECT_EQ(none.n, 0u);
  EXPECT_TRUE(std::isnan(none.mean));
  EXPECT_THROW(student_t_interval({1, 2}, 1.0), Error);
  EXPECT_THROW(student_t_interval({1, std::nan("")}), Error);
}

// ---- Batch means ----

TEST(Gather, BatchMeansOnHandExamplesDropTheRemainderAtTheStart) {
  // {5,1 | 3,2 | 4,6}: batch means 3, 2.5, 5; mean 3.5; s^2 = (0.25 + 1 + 2.25) / 2 = 1.75; SE = sqrt(1.75 / 3).
  EXPECT_NEAR(batch_means_standard_error({5, 1, 3, 2, 4, 6}, 3), std::sqrt(1.75 / 3), 1e-12);
  // Five samples in two batches: the first (100) is dropped, leaving {1,1 | 3,3}: means 1 and 3, s = sqrt(2),
  // SE = sqrt(2) / sqrt(2) = 1. Dropped at the end instead, {100,1 | 1,3} would give 24.5.
  EXPECT_NEAR(batch_means_standard_error({100, 1, 1, 3, 3}, 2), 1.0, 1e-12);
  EXPECT_THROW(batch_means_standard_error({1, 2, 3}, 4), Error);  // fewer samples than batches
  EXPECT_THROW(batch_means_standard_error({1, 2, 3}, 1), Error);  // one batch has no spread
}

TEST(Gather, RunningMeanIsTheMeanSoFar) {
  EXPECT_EQ(running_mean({2, 4, 6, -4}), (std::vector<double>{2, 3, 4, 2}));
  EXPECT_TRUE(running_mean({}).empty());
}

// Standard normal deviates by Box-Muller from a 64-bit Mersenne twister: the same numbers on every standard
// library (std::normal_distribution's algorithm is implementation-defined).
class Normal {
 public:
  explicit Normal(uint64_t seed) : rng_(seed) {}
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform(), u2 = uniform();  // u1 in (0, 1]: log(u1) is finite
    const double r = std::sqrt(-2.0 * std::log(u1)), a = 2.0 * kPi * u2;
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return r * std::cos(a);
  }

 private:
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }  // [0, 1), 53 random bits
  std::mt19937_64 rng_;
  double spare_ = 0;
  bool has_spare_ = false;
};

// Variance of the mean of k consecutive samples of a stationary AR(1), x_t = phi x_{t-1} + e_t with unit-variance
// innovations: gamma_0 = 1 / (1 - phi^2), rho_j = phi^j, and
// Var = gamma_0 / k [1 + 2 sum_{j=1}^{k-1} (1 - j/k) phi^j]
//     = gamma_0 / k [(1+phi)/(1-phi) - 2 phi (1-phi^k) / (k (1-phi)^2)].
double ar1_variance_of_mean(double phi, double k) {
  const double g0 = 1.0 / (1.0 - phi * phi);
  return g0 / k * ((1 + phi) / (1 - phi) - 2 * phi * (1 - std::pow(phi, k)) / (k * (1 - phi) * (1 - phi)));
}

TEST(Gather, BatchMeansStandardErrorOfAnAr1SeriesMatchesTheClosedForm) {
  const double phi = 0.9;
  const size_t n = 100000, b = 20, m = n / b, replicates = 400;
  // Expected squared SE of the estimator, exactly: with batch means Y_j of m samples and their mean Ybar (= the
  // series mean), E[sum (Y_j - Ybar)^2] = b Var(Y) - b Var(Ybar), so E[SE^2] = (V(m) - V(n)) / (b - 1).
  const double v_n = ar1_variance_of_mean(phi, n), v_m = ar1_variance_of_mean(phi, m);
  const double expected_se2 = (v_m - v_n) / (b - 1);
  // The naive s^2 / n: E[s^2] = n / (n - 1) (gamma_0 - V(n)).
  const double g0 = 1 / (1 - phi * phi), expected_naive2 = (g0 - v_n) / (n - 1);
  // Sanity of the closed forms against the asymptote 1 / (n (1 - phi)^2) = 1e-3.
  EXPECT_NEAR(v_n, 1.0 / (n * (1 - phi) * (1 - phi)), 1e-3 * v_n);

  // Each replicate's SE^2 is about V(n) chi^2_{b-1} / (b-1): relative spread sqrt(2 / 19) = 32 %. Averaged over
  // 400 independent replicates it is 1.6 %, so 5 % is a 3-sigma test (and the seed is fixed: no flakiness).
  Normal normal(20240611);
  double se2 = 0, naive2 = 0, mean2 = 0;
  std::vector<double> x(n);
  for (size_t r = 0; r < replicates; ++r) {
    x[0] = normal() / std::sqrt(1 - phi * phi);  // stationary from the first sample
    for (size_t i = 1; i < n; ++i) x[i] = phi * x[i - 1] + normal();
    const double se = batch_means_standard_error(x, b);
    se2 += se * se;
    const ConfidenceInterval c = student_t_interval(x);
    naive2 += c.std * c.std / n;
    mean2 += c.mean * c.mean;
  }
  se2 /= replicates, naive2 /= replicates, mean2 /= replicates;
  // The generator has the variance of the mean the closed form says (spread of 400 squares: 7 %; 25 % is 3.5 sigma).
  EXPECT_NEAR(mean2 / v_n, 1.0, 0.25);
  EXPECT_NEAR(se2 / expected_se2, 1.0, 0.05);
  EXPECT_NEAR(se2 / v_n, 1.0, 0.05) << "batch means estimate the variance of the mean";
  EXPECT_NEAR(naive2 / expected_naive2, 1.0, 0.05);
  // The naive SE understates the variance of the mean by (1 + phi) / (1 - phi) = 19: why batch means are needed.
  EXPECT_NEAR((se2 / naive2) / ((1 + phi) / (1 - phi)), 1.0, 0.05);
}

// ---- The gather on synthetic members ----

// A member's results: time t_k = (k + 1) dt, steady start recorded as an attribute, and the surge ice resistance
// given per sample (kN) as -Fx.
void write_member_results(const fs::path& file, const std::vector<double>& resistance_kN, double dt,
                          double steady_start_s) {
  Synthetic syn = default_synthetic();
  syn.time_step_s = dt;
  syn.steps = static_cast<int>(resistance_kN.size());
  syn.frames = 2;
  Results r = make_results(syn);
  std::vector<double>& load = r.series["ice_load"];
  for (size_t k = 0; k < resistance_kN.size(); ++k) load[6 * k] = -1000.0 * resistance_kN[k];
  r.attributes["steady_start_s"] = steady_start_s;
  r.attributes["contact_model"] = "compliant";
  write_results(file, r);
}

struct FakeMember {
  std::string id;
  size_t grid_point, ensemble_index;
  Json axes, seeds;
};

// The plan entry of a member in `root`/members/<id>: synth (its image), simulate (summary, results), plot.
Json plan_member(const fs::path& root, const FakeMember& f) {
  const fs::path d = root / "members" / f.id;
  fs::create_directories(d / "logs");
  auto stage = [&](const std::string& name, const std::vector<fs::path>& outputs) {
    Json o = Json::array();
    for (const auto& p : outputs) o.push_back(p.string());
    return Json{{"name", name},
                {"outputs", o},
                {"log", (d / "logs" / (name + ".log")).string()},
                {"wall_ms", (d / "logs" / (name + ".wall_ms")).string()}};
  };
  return {{"id", f.id},
          {"grid_point", f.grid_point},
          {"ensemble_index", f.ensemble_index},
          {"axes", f.axes},
          {"seeds", f.seeds},
          {"dir", d.string()},
          {"summary", (d / "sim" / "summary.json").string()},
          {"results", (d / "sim" / "results.h5").string()},
          {"stages", Json::array({stage("synth", {d / "image" / "image.png"}),
                                  stage("simulate", {d / "sim" / "results.h5", d / "sim" / "summary.json"}),
                                  stage("plot", {d / "plots" / "surge_ice_load.png"})})}};
}

void write_summary(const fs::path& member_dir, const Json& s) {
  fs::create_directories(member_dir / "sim");
  std::ofstream(member_dir / "sim" / "summary.json") << s.dump(2);
}

void touch(const fs::path& p, const std::string& text = "x") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

const char* const kSpeed = "simulate.vessel.propulsion.speed_mps";

// Series (dt = 0.05 s, steady from t = 5 s, i.e. sample k >= 99; 50 kN of open water before):
//   A: 300 + 40 sin(2 pi 0.25 t) kN over 1600 steady samples = 20 periods of 80 samples. Mean 300; each of the
//      20 batches is one whole period, so every batch mean is 300 and the SE is 0. The 0.5 s window is N = 10
//      steps, 11 taps with half-weighted ends; for a sampled sinusoid of theta = 2 pi f dt per step its gain is
//      sin(N theta / 2) cot(theta / 2) / N, and the peak falls on a sample (t = 9 s): 300 + 40 x gain.
//   B: 7 samples of 170 kN (the remainder, dropped before batching), then 200 +- 30 kN alternating every batch of
//      80 samples (+ first). Batch means 230, 170, ...: SE = sqrt(20 x 30^2 / 19) / sqrt(20) = 30 / sqrt(19); mean
//      (7 x 170 + 1600 x 200) / 1607 = 321190 / 1607; 0.5 s peak 230 (a plateau is 80 samples).
//   C: 250 kN, constant.
std::vector<double> series_a() {
  std::vector<double> x(1699);
  for (size_t k = 0; k < x.size(); ++k)
    x[k] = k < 99 ? 50.0 : 300.0 + 40.0 * std::sin(2 * kPi * 0.25 * (k + 1) * 0.05);
  return x;
}
std::vector<double> series_b() {
  std::vector<double> x(99 + 1607, 50.0);
  for (size_t s = 0; s < 1607; ++s) x[99 + s] = s < 7 ? 170.0 : ((s - 7) / 80 % 2 == 0 ? 230.0 : 170.0);
  return x;
}
const double kMeanB = 321190.0 / 1607.0;

// Five members on a one-axis grid (speed 1 and 2 m/s), two seeds each way: A and B at 1 m/s (ok), C at 2 m/s
// (ok), D at 2 m/s (failed in simulate, with a log), E at 2 m/s (never ran).
fs::path write_sweep(const fs::path& root) {
  const FakeMember a{"g000-e00", 0, 0, {{kSpeed, 1}}, {{"image.synthetic.seed", 1}, {"simulate.vessel.y_m", 370.0}}},
      b{"g000-e01", 0, 1, {{kSpeed, 1}}, {{"image.synthetic.seed", 2}, {"simulate.vessel.y_m", 370.5}}},
      c{"g001-e00", 1, 0, {{kSpeed, 2}}, {{"image.synthetic.seed", 1}}},
      d{"g001-e01", 1, 1, {{kSpeed, 2}}, {{"image.synthetic.seed", 2}, {"simulate.vessel.y_m", 370.5}}},
      e{"g001-e02", 1, 2, {{kSpeed, 2}}, {{"image.synthetic.seed", 3}, {"simulate.vessel.y_m", 371.0}}};
  Json members = Json::array();
  for (const FakeMember* f : {&a, &b, &c, &d, &e}) members.push_back(plan_member(root, *f));
  const fs::path m = root / "members";

  // A: fracture on, with events; speed 0.1 + 0.2 (not 0.3: its shortest text has 17 digits).
  write_summary(m / a.id, {{"mean_surge_ice_resistance_N", 300000.0},
                           {"mean_vessel_speed_mps", 0.1 + 0.2},
                           {"fracture", {{"enabled", true}, {"events", {{"bending", 3}, {"radial", 1},
                                                                        {"splitting", 2}, {"total", 6}}}}}});
  write_member_results(m / a.id / "sim" / "results.h5", series_a(), 0.05, 5.0);
  touch(m / a.id / "logs" / "synth.wall_ms", "1500\n");
  touch(m / a.id / "logs" / "simulate.wall_ms", "2500\n");
  // B: fracture disabled (counts 0 whatever the events say).
  write_summary(m / b.id, {{"mean_surge_ice_resistance_N", 1000.0 * kMeanB},
                           {"mean_vessel_speed_mps", 0.98},
                           {"fracture", {{"enabled", false}, {"events", {{"bending", 9}}}}}});
  write_member_results(m / b.id / "sim" / "results.h5", series_b(), 0.05, 5.0);
  // C: no fracture section at all.
  write_summary(m / c.id, {{"mean_surge_ice_resistance_N", 250000.0}, {"mean_vessel_speed_mps", 2.0}});
  write_member_results(m / c.id / "sim" / "results.h5", std::vector<double>(400, 250.0), 0.05, 5.0);
  // D: synth finished; simulate failed; the log's last three non-empty lines are the error (one with a comma and
  // quotes, which CSV must quote).
  touch(m / d.id / "image" / "image.png");
  touch(m / d.id / "logs" / "synth.log", "floesim-synth: wrote image.png\n");
  touch(m / d.id / "logs" / "synth.wall_ms", "250");
  touch(m / d.id / "logs" / "simulate.log",
        "floesim-simulate: 12 floes in 30 convex parts\n\nstep 100 of 2000\n"
        "floesim-simulate: error: numerical failure at step 1234 (t = 12.34 s)\n"
        "  Try a smaller \"time_step_s\", or more solver.iterations\n   \n");
  // E: nothing at all.

  const Json plan = {{"format", kSweepPlanFormat},
                     {"name", "speed-test"},
                     {"sweep_file", (root / "sweep.json").string()},
                     {"axes", Json::array({{{"key", kSpeed}, {"values", {1, 2}}}})},
                     {"ensemble", {{"size", 3}, {"vary", {"field_seed", "start"}}}},
                     {"grid_points", Json::array({{{"index", 0}, {"axes", {{kSpeed, 1}}}},
                                                  {{"index", 1}, {"axes", {{kSpeed, 2}}}}})},
                     {"members", members}};
  std::ofstream(root / "plan.json") << plan.dump(2);
  return root / "plan.json";
}

TEST(Gather, SyntheticSweepGathersKnownNumbersAndListsFailedMembers) {
  const fs::path dir = fresh_dir("gather_sweep");
  const fs::path plan = write_sweep(dir);
  const GatherResult g = gather_sweep(plan, dir / "out");

  // 1. The CSV: header, then one row per member in plan order.
  const auto rows = read_csv(dir / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 6u);
  EXPECT_EQ(read_text(dir / "out" / "sweep.csv").substr(0, read_text(dir / "out" / "sweep.csv").find('\n')),
            "member,grid_point,ensemble_index,simulate.vessel.propulsion.speed_mps,image.synthetic.seed,"
            "simulate.vessel.y_m,mean_surge_ice_resistance_kN,batch_means_se_kN,mean_speed_mps,"
            "peak_0.5s_resistance_kN,fracture_bending,fracture_radial,fracture_splitting,wall_s,status,error");
  const auto& h = rows[0];
  auto col = [&](size_t row, const std::string& name) {
    const size_t c = std::find(h.begin(), h.end(), name) - h.begin();
    EXPECT_LT(c, h.size()) << name;
    EXPECT_EQ(rows[row].size(), h.size()) << "row " << row;
    return c < rows[row].size() ? rows[row][c] : std::string("?");
  };
  auto num = [&](size_t row, const std::string& name) { return std::strtod(col(row, name).c_str(), nullptr); };

  // A: numbers from its summary, read back exactly; the series' SE (0: whole periods) and the 0.5 s peak.
  EXPECT_EQ(col(1, "member"), "g000-e00");
  EXPECT_EQ(col(1, kSpeed), "1");
  EXPECT_EQ(col(1, "image.synthetic.seed"), "1");
  EXPECT_EQ(col(1, "simulate.vessel.y_m"), "370.0");
  EXPECT_EQ(num(1, "mean_surge_ice_resistance_kN"), 300.0);
  EXPECT_EQ(num(1, "mean_speed_mps"), 0.1 + 0.2) << "round-trips exactly";
  EXPECT_EQ(col(1, "mean_speed_mps"), Json(0.1 + 0.2).dump()) << "byte for byte as summary.json writes it";
  EXPECT_NEAR(num(1, "batch_means_se_kN"), 0.0, 1e-9);
  const double theta = 2 * kPi * 0.25 * 0.05, gain = std::sin(5 * theta) / std::tan(theta / 2) / 10;
  EXPECT_NEAR(gain, 0.97399, 1e-5);  // a little below the continuous sinc, sin(pi/8) / (pi/8) = 0.9745
  EXPECT_NEAR(num(1, "peak_0.5s_resistance_kN"), 300.0 + 40.0 * gain, 1e-9);
  EXPECT_EQ(col(1, "fracture_bending"), "3");
  EXPECT_EQ(col(1, "fracture_radial"), "1");
  EXPECT_EQ(col(1, "fracture_splitting"), "2");
  EXPECT_EQ(num(1, "wall_s"), 4.0);
  EXPECT_EQ(col(1, "status"), "ok");
  EXPECT_EQ(col(1, "error"), "");
  // B: the remainder dropped at the start gives batch means of exactly +-30 kN.
  EXPECT_EQ(num(2, "mean_surge_ice_resistance_kN"), 1000.0 * kMeanB / 1000.0);
  EXPECT_NEAR(num(2, "batch_means_se_kN"), 30.0 / std::sqrt(19.0), 1e-9);
  EXPECT_NEAR(num(2, "peak_0.5s_resistance_kN"), 230.0, 1e-9);
  EXPECT_EQ(col(2, "fracture_bending"), "0") << "fracture disabled";
  EXPECT_EQ(col(2, "wall_s"), "") << "no stage recorded a time";
  // C: no fracture section; no y_m seed (an empty cell).
  EXPECT_EQ(num(3, "mean_surge_ice_resistance_kN"), 250.0);
  EXPECT_EQ(col(3, "simulate.vessel.y_m"), "");
  EXPECT_EQ(col(3, "fracture_splitting"), "0");
  // D: failed in simulate; the last three non-empty log lines; numbers empty; the time it took is kept.
  EXPECT_EQ(col(4, "status"), "failed");
  EXPECT_EQ(col(4, "error"),
            "step 100 of 2000 | floesim-simulate: error: numerical failure at step 1234 (t = 12.34 s) | "
            "Try a smaller \"time_step_s\", or more solver.iterations");
  for (const char* c : {"mean_surge_ice_resistance_kN", "batch_means_se_kN", "mean_speed_mps",
                        "peak_0.5s_resistance_kN", "fracture_bending"})
    EXPECT_EQ(col(4, c), "") << c;
  EXPECT_EQ(num(4, "wall_s"), 0.25);
  // E: never ran.
  EXPECT_EQ(col(5, "status"), "failed");
  EXPECT_EQ(col(5, "error"), "not run");
  // The error cell is quoted as CSV (commas and quotes inside).
  EXPECT_NE(read_text(dir / "out" / "sweep.csv").find(",failed,\"step 100 of 2000 | "), std::string::npos);

  // 2. The series statistics: the mean of the steady series is the summary's (here by construction) to round-off,
  // and the remainder is counted.
  ASSERT_EQ(g.members.size(), 5u);
  EXPECT_NEAR(g.members[0].series.mean_kN, 300.0, 1e-12 * 300);
  EXPECT_NEAR(g.members[1].series.mean_kN, kMeanB, 1e-12 * kMeanB);
  EXPECT_EQ(g.members[0].series.samples, 1600u);
  EXPECT_EQ(g.members[0].series.dropped_samples, 0u);
  EXPECT_EQ(g.members[1].series.samples, 1607u);
  EXPECT_EQ(g.members[1].series.batch_samples, 80u);
  EXPECT_EQ(g.members[1].series.dropped_samples, 7u);
  EXPECT_EQ(g.members[1].series.peak_window_samples, 10u);
  EXPECT_EQ(g.members[3].failed_stage, "simulate");

  // 3. sweep.json: the rows, the grid points' intervals by the hand formula, the failed list.
  const Json j = Json::parse(read_text(dir / "out" / "sweep.json"));
  ASSERT_EQ(j["members"].size(), 5u);
  EXPECT_EQ(j["members"][0][kSpeed], 1);
  EXPECT_EQ(j["members"][0]["mean_surge_ice_resistance_kN"].get<double>(), 300.0);
  EXPECT_TRUE(j["members"][3]["mean_surge_ice_resistance_kN"].is_null());
  EXPECT_TRUE(j["members"][2]["simulate.vessel.y_m"].is_null());
  const Json& g0 = j["grid_points"][0];
  EXPECT_EQ(g0["n_members"], 2);
  EXPECT_EQ(g0["n_ok"], 2);
  // Two values: mean (x1 + x2) / 2, s = |x1 - x2| / sqrt(2), half width t_{0.975,1} s / sqrt(2) = t |x1 - x2| / 2.
  const double t1 = std::tan(kPi * 0.475), d = 300.0 - kMeanB;
  EXPECT_NEAR(g0["mean_kN"].get<double>(), (300.0 + kMeanB) / 2, 1e-9);
  EXPECT_NEAR(g0["std_kN"].get<double>(), d / std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(g0["t_quantile"].get<double>(), t1, 1e-9);
  EXPECT_NEAR(g0["ci95_half_width_kN"].get<double>(), t1 * d / 2, 1e-7);
  const Json& g1 = j["grid_points"][1];
  EXPECT_EQ(g1["n_members"], 3);
  EXPECT_EQ(g1["n_ok"], 1);
  EXPECT_EQ(g1["mean_kN"].get<double>(), 250.0);
  // One ok member: the point's interval is that member's batch-means interval; C's series is constant, so its 20
  // batch means are equal and the half width exactly 0. The t quantile of an ensemble needs two members.
  EXPECT_EQ(g1["ci95_half_width_kN"].get<double>(), 0.0) << "one ok member: its own batch-means interval";
  EXPECT_EQ(g1["interval"], "batch means of its one member");
  EXPECT_EQ(g0["interval"], "Student t over the ok members");
  EXPECT_TRUE(g1["t_quantile"].is_null());
  EXPECT_EQ(g1["axes"][kSpeed], 2);
  ASSERT_EQ(j["failed"].size(), 2u);
  EXPECT_EQ(j["failed"][0]["member"], "g001-e01");
  EXPECT_EQ(j["failed"][0]["stage"], "simulate");
  EXPECT_EQ(j["failed"][1]["error"], "not run");
  EXPECT_EQ(j["provenance"]["program"], "floesim-gather");
  EXPECT_EQ(j["axes"][0]["key"], kSpeed);

  // 4. The plots, and nothing else (no working files).
  EXPECT_EQ(listing(dir / "out"),
            (std::vector<std::string>{"resistance_vs_simulate_vessel_propulsion_speed_mps.png",
                                      "resistance_vs_simulate_vessel_propulsion_speed_mps.svg", "running_mean.png",
                                      "running_mean.svg", "sweep.csv", "sweep.json"}));
  for (const auto& f : listing(dir / "out")) EXPECT_GT(fs::file_size(dir / "out" / f), 300u) << f;
  const std::string svg = read_text(dir / "out" / "running_mean.svg");
  EXPECT_NE(svg.find("g000-e00"), std::string::npos) << "titled with the first ok member";

  // 5. The table names each grid point and the failed members.
  const std::string table = gather_table(read_sweep_plan(plan), g);
  EXPECT_NE(table.find("5 members: 3 ok, 2 failed"), std::string::npos) << table;
  EXPECT_NE(table.find("1/3"), std::string::npos) << table;
  EXPECT_NE(table.find("g001-e01 (simulate): step 100"), std::string::npos) << table;
  EXPECT_NE(table.find("g001-e02: not run"), std::string::npos) << table;
  fs::remove_all(dir);
}

// Two axes, one of strings (categories), and a pure ensemble: the plots each shape calls for.
fs::path write_constant_member(const fs::path& root, const std::string& id, size_t gp, size_t e, const Json& axes,
                               double kN, Json& members) {
  members.push_back(plan_member(root, {id, gp, e, axes, Json::object()}));
  write_summary(root / "members" / id, {{"mean_surge_ice_resistance_N", 1000 * kN}, {"mean_vessel_speed_mps", 2}});
  write_member_results(root / "members" / id / "sim" / "results.h5", std::vector<double>(200, kN), 0.05, 1.0);
  return root / "members" / id;
}

TEST(Gather, LevelIceMembersGetLindqvistAndRiskaOfPhysicsWorkedExamples) {
  // Two level-ice members at 2 m/s (one axis: the sheet's thickness) whose hull.json holds the particulars of
  // PHYSICS.md §6's worked examples (L 100, B 20, T 7 m, phi = alpha = 30 deg, L_par 50, L_bow 25 m) and whose
  // summaries give §6.1's ice (sigma_b 0.5 MPa, E 2 GPa, mu 0.1): at h = 1 m Lindqvist's R_ice is 1028.7 kN and
  // Riska's R 943.6 kN (the printed worked examples); a member without level ice leaves the columns empty.
  const fs::path root = fs::temp_directory_path() / "floesim_gather_level_ice";
  fs::remove_all(root);
  const char* hkey = "simulate.level_ice.thickness_m";
  Json members = Json::array();
  for (const char* id : {"g000-e00", "g001-e00"}) {
    const bool level = std::string(id) == "g000-e00";
    Json m = plan_member(root, {id, level ? 0u : 1u, 0, {{hkey, level ? 1.0 : 2.0}}, Json::object()});
    const fs::path d = root / "members" / id;
    m["stages"].push_back({{"name", "hull"}, {"outputs", {(d / "hull" / "hull.obj").string()}}});
    touch(d / "hull" / "hull.obj");
    touch(d / "hull" / "hull.json",
          Json{{"particulars", {{"length_m", 100}, {"beam_m", 20}, {"draught_m", 7}, {"stem_angle_deg", 30},
                                {"entrance_angle_deg", 30}, {"parallel_midbody_m", 50}, {"bow_length_m", 25}}}}
              .dump());
    Json summary = {{"mean_surge_ice_resistance_N", 900000.0}, {"mean_vessel_speed_mps", 2.0}};
    if (level)
      summary["level_ice"] = {{"tiles_start", 4},
                              {"channel", {{"width_over_beam", 1.25}}},
                              {"ice", {{"thickness_m", 1.0}, {"flexural_strength_pa", 5e5}, {"youngs_modulus_pa", 2e9},
                                       {"poisson_ratio", 0.3}, {"ice_density_kg_m3", 900.0},
                                       {"water_density_kg_m3", 1025.0}, {"gravity_mps2", 9.81},
                                       {"mu_ice_structure", 0.1}}}};
    write_summary(d, summary);
    write_member_results(d / "sim" / "results.h5", std::vector<double>(400, 900.0), 0.05, 5.0);
    members.push_back(m);
  }
  const Json plan = {{"format", kSweepPlanFormat},
                     {"name", "level-ice-test"},
                     {"sweep_file", (root / "sweep.json").string()},
                     {"axes", Json::array({{{"key", hkey}, {"values", {1.0, 2.0}}}})},
                     {"ensemble", {{"size", 1}, {"vary", Json::array()}}},
                     {"grid_points", Json::array({{{"index", 0}, {"axes", {{hkey, 1.0}}}},
                                                  {{"index", 1}, {"axes", {{hkey, 2.0}}}}})},
                     {"members", members}};
  std::ofstream(root / "plan.json") << plan.dump(2);
  gather_sweep(root / "plan.json", root / "out");
  const auto rows = read_csv(root / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 3u);
  auto col = [&](size_t r, const std::string& name) {
    const size_t c = std::find(rows[0].begin(), rows[0].end(), name) - rows[0].begin();
    EXPECT_LT(c, rows[0].size()) << name;
    return c < rows[r].size() ? rows[r][c] : std::string("?");
  };
  EXPECT_NEAR(std::stod(col(1, "lindqvist_kN")), 1028.7, 0.05);
  EXPECT_NEAR(std::stod(col(1, "riska_kN")), 943.6, 0.05);
  EXPECT_NEAR(std::stod(col(1, "ratio_to_lindqvist")), 900.0 / 1028.7, 1e-4);
  EXPECT_EQ(col(1, "channel_width_over_beam"), "1.25");
  EXPECT_EQ(col(2, "lindqvist_kN"), "");
  EXPECT_EQ(col(2, "status"), "ok");
  EXPECT_TRUE(fs::exists(root / "out" / "level_ice_resistance.png"));
  fs::remove_all(root);
}

TEST(Gather, TwoAxesWithCategoriesAndAPureEnsembleArePlotted) {
  const fs::path dir = fresh_dir("gather_shapes");
  {
    Json members = Json::array(), grid = Json::array();
    size_t gp = 0;
    for (const char* law : {"rigid", "compliant"})
      for (double h : {0.5, 1.0}) {
        const Json axes = {{"simulate.contact.ice_structure", law}, {"image.synthetic.thickness_m", h}};
        grid.push_back({{"index", gp}, {"axes", axes}});
        for (size_t e = 0; e < 2; ++e)
          write_constant_member(dir, "g" + std::to_string(gp) + "-e" + std::to_string(e), gp, e, axes,
                                100 * h + (law[0] == 'r' ? 20 : 0) + e, members);
        ++gp;
      }
    const Json plan = {{"format", kSweepPlanFormat},
                       {"name", "law-thickness"},
                       {"axes", Json::array({{{"key", "simulate.contact.ice_structure"},
                                              {"values", {"rigid", "compliant"}}},
                                             {{"key", "image.synthetic.thickness_m"}, {"values", {0.5, 1.0}}}})},
                       {"grid_points", grid},
                       {"members", members}};
    std::ofstream(dir / "plan.json") << plan.dump(2);
    const GatherResult g = gather_sweep(dir / "plan.json", dir / "out2");
    // Grid point 0 (rigid, 0.5 m): members 70 and 71 kN: mean 70.5, s = sqrt(1/2), half width t s / sqrt(2) = t / 2.
    EXPECT_NEAR(g.grid_points[0].ci.mean, 70.5, 1e-12);
    EXPECT_NEAR(g.grid_points[0].ci.half_width, std::tan(kPi * 0.475) / 2, 1e-8);
    for (const char* f : {"resistance_vs_simulate_contact_ice_structure.png",
                          "resistance_vs_simulate_contact_ice_structure.svg",
                          "resistance_vs_image_synthetic_thickness_m.png",
                          "resistance_vs_image_synthetic_thickness_m.svg", "running_mean.png", "running_mean.svg"})
      EXPECT_GT(fs::file_size(dir / "out2" / f), 1000u) << f;
    // One line per value of the other axis, labelled with it; the categories as tics.
    const std::string svg = read_text(dir / "out2" / "resistance_vs_image_synthetic_thickness_m.svg");
    EXPECT_NE(svg.find("simulate.contact.ice_structure = compliant"), std::string::npos);
    const std::string cat = read_text(dir / "out2" / "resistance_vs_simulate_contact_ice_structure.svg");
    EXPECT_NE(cat.find(">rigid<"), std::string::npos);
    EXPECT_NE(cat.find("image.synthetic.thickness_m = 0.5"), std::string::npos);
  }
  {
    const fs::path e = dir / "ensemble";
    Json members = Json::array();
    for (size_t i = 0; i < 4; ++i)
      write_constant_member(e, "e" + std::to_string(i), 0, i, Json::object(), 100.0 + i, members);
    const Json plan = {{"format", kSweepPlanFormat},
                       {"name", "starts"},
                       {"axes", Json::array()},
                       {"grid_points", Json::array({{{"index", 0}, {"axes", Json::object()}}})},
                       {"members", members}};
    std::ofstream(e / "plan.json") << plan.dump(2);
    const GatherResult g = gather_sweep(e / "plan.json", e / "out");
    EXPECT_EQ(g.files, (std::vector<std::string>{"sweep.csv", "sweep.json", "ensemble.png", "ensemble.svg",
                                                 "running_mean.png", "running_mean.svg"}));
    for (const auto& f : g.files) EXPECT_GT(fs::file_size(e / "out" / f), 200u) << f;
    // {100, 101, 102, 103}: mean 101.5, s^2 = (2.25 + 0.25 + 0.25 + 2.25) / 3 = 5/3, t_{0.975,3} = 3.1824463.
    EXPECT_NEAR(g.grid_points[0].ci.half_width, 3.1824463 * std::sqrt(5.0 / 3) / 2, 1e-6);
    EXPECT_EQ(read_csv(e / "out" / "sweep.csv")[0][3], "mean_surge_ice_resistance_kN") << "no axis, no seed columns";
  }
  fs::remove_all(dir);
}

// ---- A bad plan: a clear error naming the file and the key, and nothing written ----

TEST(Gather, BadPlanNamesTheFileAndKeyAndWritesNothing) {
  const fs::path dir = fresh_dir("gather_bad");
  const fs::path good = write_sweep(dir);
  const Json plan = Json::parse(read_text(good));
  auto expect_error = [&](const Json* j, const std::vector<std::string>& needles) {
    const fs::path p = dir / "bad_plan.json";
    fs::remove(p);
    if (j) std::ofstream(p) << j->dump(2);
    try {
      gather_sweep(p, dir / "out");
      ADD_FAILURE() << "no error; expected one mentioning " << needles.front();
    } catch (const Error& e) {
      for (const auto& n : needles) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "out")) << "a bad plan left output behind";
  };
  expect_error(nullptr, {"bad_plan.json", "cannot open"});
  Json wrong = plan;
  wrong["format"] = "floesim-sweep-plan/2";
  expect_error(&wrong, {"bad_plan.json", "format", "floesim-sweep-plan/2", "floesim-sweep-plan/1"});
  Json no_summary = plan;
  no_summary["members"][1].erase("summary");
  expect_error(&no_summary, {"bad_plan.json", "members[1].summary is missing"});
  // Every problem at once.
  Json several = plan;
  several["members"][0].erase("results");
  several["members"][2]["grid_point"] = 7;
  several["members"][3]["axes"][kSpeed] = 3;
  expect_error(&several, {"3 problems", "members[0].results is missing", "members[2].grid_point is 7",
                          "members[3].axes"});
  fs::remove_all(dir);
}

// ---- The executable: exit 0 with failed members listed, non-zero on a bad plan ----

int run(const std::string& cmd, std::string& out) {
  const fs::path log = fs::temp_directory_path() / ("floesim_gather_cli_" + std::to_string(::getpid()) + ".log");
  const int status = std::system((cmd + " > '" + log.string() + "' 2>&1").c_str());
  out = read_text(log);
  fs::remove(log);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Gather, ExecutableExitsZeroWithFailedMembersAndNonZeroOnABadPlan) {
  const fs::path dir = fresh_dir("gather_cli");
  const fs::path plan = write_sweep(dir);
  const std::string exe = "'" + (fs::path(FLOESIM_BIN_DIR) / "floesim-gather").string() + "'";
  std::string out;
  EXPECT_EQ(run(exe + " --plan '" + plan.string() + "' --out '" + (dir / "run").string() + "'", out), 0) << out;
  EXPECT_NE(out.find("g001-e01 (simulate): step 100 of 2000"), std::string::npos) << out;
  EXPECT_NE(out.find("sweep.csv"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir / "run" / "sweep.json"));
  EXPECT_EQ(run(exe + " --plan '" + (dir / "nope.json").string() + "' --out '" + (dir / "x").string() + "'", out), 1);
  EXPECT_NE(out.find("nope.json"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "x"));
  EXPECT_EQ(run(exe + " --version", out), 0);
  EXPECT_NE(out.find("floesim-gather"), std::string::npos) << out;
  fs::remove_all(dir);
}

}  // namespace
