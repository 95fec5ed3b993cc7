// The round trip of issue #11: a real simulated transit -> floesim-shipdata's measured data -> floesim-identify with
// the sidecar config -> the ice load, checked against the ice load the simulator recorded (an independent number:
// the contact impulses of the solver, not the balance identify solves).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/error.h"
#include "pipeline/options.h"
#include "sim/shipdata.h"
#include "sim/simulate.h"
#include "sim_fixtures.h"

namespace fs = std::filesystem;
using namespace floesim;
using namespace floesim::sim;
using floesim::sim::testing::coarse_hull;
using floesim::sim::testing::rect_floe;

namespace {

const fs::path kBin = FLOESIM_BIN_DIR;

// A field of 7 m square floes, 1 m thick, 1.5 m gaps, 12 along the track and 5 across: ice for the whole transit.
FloeField floe_field() {
  FloeField field;
  int id = 1;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 5; ++j) field.floes.push_back(rect_floe(id++, 60 + i * 8.5, -21 + j * 8.5, 7, 7, 1.0));
  return field;
}

// One 40 s transit at 2 m/s (the speed controller), shared by the tests: the model, the results, the summary (with
// the settings, as floesim-simulate writes it).
struct Transit {
  Model model;
  Results results;
  nlohmann::json summary;
};
const Transit& transit() {
  static const Transit t = [] {
    const HullModel hull = coarse_hull(8);
    SimulateOptions o;
    o.duration_s = 40;
    o.steady_start_s = 10;
    o.output_interval_s = 1;
    Transit tr{build_model(floe_field(), &hull, o), {}, {}};
    RunStats stats;
    tr.results = simulate(tr.model, stats);
    tr.summary = summarize(tr.model, tr.results);
    tr.summary["settings"] = options_to_json(tr.model.options);
    return tr;
  }();
  return t;
}

// The simulated surge ice load averaged over identify's output intervals (the same membership rule: [t0 + kT,
// t0 + (k+1)T) from the first sample), so the two filtered series compare sample by sample.
std::vector<double> interval_means(const ShipData& d, double T, size_t K) {
  const double t0 = d.measured.time_s.front();
  std::vector<double> sum(K, 0.0), cnt(K, 0.0);
  for (size_t i = 0; i < d.measured.time_s.size(); ++i) {
    const double k = std::floor((d.measured.time_s[i] - t0) / T + 1e-9);
    if (k >= 0 && k < double(K)) sum[size_t(k)] += d.sim_ice[i].surge, cnt[size_t(k)] += 1;
  }
  for (size_t k = 0; k < K; ++k) sum[k] /= cnt[k];
  return sum;
}

struct RoundTrip {
  double sim_mean = 0, id_mean = 0, rel_error = 0, rms = 0, sim_sd = 0;
};

// Identify with the sidecar; compare means over the steady part and the 0.5 s (2 Hz) series over the same part.
RoundTrip round_trip(const ShipDataOptions& so) {
  const Transit& tr = transit();
  const ShipData d = make_ship_data(tr.results, tr.summary, so);
  const Identification id = identify(d.measured, d.identify);
  RoundTrip rt;
  rt.sim_mean = tr.summary["mean_surge_ice_load_N"].get<double>();
  rt.id_mean = id.mean_ice.surge;
  rt.rel_error = (rt.id_mean - rt.sim_mean) / std::abs(rt.sim_mean);
  const std::vector<double> sim = interval_means(d, d.identify.filters.output_interval_s, id.output.time_s.size());
  double se = 0, m = 0, m2 = 0, n = 0;
  for (size_t k = 0; k < sim.size(); ++k) {
    if (id.output.time_s[k] < d.mean_t0_s) continue;  // the steady part only
    se += std::pow(id.output.ice[k].surge - sim[k], 2);
    m += sim[k], m2 += sim[k] * sim[k], n += 1;
  }
  rt.rms = std::sqrt(se / n);
  rt.sim_sd = std::sqrt(m2 / n - (m / n) * (m / n));
  std::printf("[measured] simulated mean surge ice load %.2f kN, identified %.2f kN (%+.3f %%); 0.5 s series RMS "
              "error %.2f kN (simulated 0.5 s series: sd %.1f kN, %zu intervals)\n",
              rt.sim_mean / 1e3, rt.id_mean / 1e3, 100 * rt.rel_error, rt.rms / 1e3, rt.sim_sd / 1e3, size_t(n));
  return rt;
}

}  // namespace

// The transit does meet ice, and the sidecar is the simulated ship: M with the simulator's added mass.
TEST(ShipData, SidecarIsTheSimulatedShip) {
  const Transit& tr = transit();
  ASSERT_LT(tr.summary["mean_surge_ice_load_N"].get<double>(), -20e3);  // ice resists: at least 20 kN
  const ShipData d = make_ship_data(tr.results, tr.summary, {});
  const Body& b = tr.model.bodies[tr.model.vessel];
  EXPECT_NEAR(d.identify.mass.surge_kg, b.mass_kg + b.added_mass.x(), 1e-6 * b.mass_kg);
  EXPECT_NEAR(d.identify.mass.sway_kg, b.mass_kg + b.added_mass.y(), 1e-6 * b.mass_kg);
  EXPECT_NEAR(d.identify.mass.yaw_kg_m2, b.inertia(2, 2) + b.added_inertia.z(), 1e-6 * b.inertia(2, 2));
  EXPECT_EQ(d.identify.resistance.model, "ittc57");
  // Same curve as the simulator's at 2 m/s.
  EXPECT_NEAR(open_water_resistance(2.0, d.identify.resistance),
              ittc57_resistance(2.0, tr.model.vessel_info, tr.model.options), 1e-9);
  EXPECT_EQ(d.measured.time_s.size(), tr.results.steps());
  EXPECT_FALSE(d.wind);
}

// Noise off: the identified mean surge ice load within 2 % of the simulated one, and the 0.5 s series within 5 % of
// the mean load RMS (measured: see the [measured] line).
TEST(ShipData, RoundTripWithoutNoise) {
  const RoundTrip rt = round_trip({});
  EXPECT_LT(std::abs(rt.rel_error), 0.02);
  EXPECT_LT(rt.rms, 0.05 * std::abs(rt.sim_mean));
}

// Accelerations left to identify (central differences, 0.1 s moving average): the mean is the same within 2 %
// (differences telescope), the series is smoothed a little more.
TEST(ShipData, RoundTripDifferentiated) {
  ShipDataOptions so;
  so.write_accelerations = false;
  const RoundTrip rt = round_trip(so);
  EXPECT_LT(std::abs(rt.rel_error), 0.02);
  EXPECT_LT(rt.rms, 0.10 * std::abs(rt.sim_mean));
}

// IMU noise 0.02 m/s^2 (surge, sway), 0.001 rad/s^2 (yaw), bias 2e-4 m/s^2, velocity noise 0.005 m/s: the bias
// shifts the mean by M11 b (about 3 kN), the noise averages out over 3000 samples (M11 0.02 / sqrt(3000) ~ 5 kN).
TEST(ShipData, RoundTripWithNoise) {
  ShipDataOptions so;
  so.noise.surge_sd_mps2 = 0.02;
  so.noise.sway_sd_mps2 = 0.02;
  so.noise.yaw_sd_radps2 = 0.001;
  so.noise.surge_bias_mps2 = 2e-4;
  so.noise.sway_bias_mps2 = 2e-4;
  so.noise.velocity_sd_mps = 0.005;
  so.seed = 7;
  const RoundTrip rt = round_trip(so);
  const double m11 = make_ship_data(transit().results, transit().summary, so).identify.mass.surge_kg;
  // The expected shift M11 b plus 4 standard errors of the noise's mean.
  const double tol = m11 * (2e-4 + 4 * 0.02 / std::sqrt(3000.0));
  EXPECT_LT(std::abs(rt.id_mean - rt.sim_mean), tol + 0.02 * std::abs(rt.sim_mean));
  // Deterministic: the same seed gives the same data.
  const ShipData a = make_ship_data(transit().results, transit().summary, so);
  const ShipData b = make_ship_data(transit().results, transit().summary, so);
  EXPECT_EQ(a.measured.du_mps2, b.measured.du_mps2);
  EXPECT_EQ(a.measured.u_mps, b.measured.u_mps);
}

// Every k-th step: a 0.05 s ship log still gives the mean within 2 %.
TEST(ShipData, EveryFifthStep) {
  ShipDataOptions so;
  so.every = 5;
  const RoundTrip rt = round_trip(so);
  EXPECT_LT(std::abs(rt.rel_error), 0.02);
}

// The executables: results.h5 + summary.json -> CSV + sidecar; the sidecar passes identify's --check-config and
// identify's mean equals the in-process one; a summary of another run is refused.
TEST(ShipData, Executables) {
  const fs::path dir = floesim::sim::testing::temp_dir("shipdata_exe");
  const Transit& tr = transit();
  Results r = tr.results;
  write_results(dir / "results.h5", r);
  std::ofstream(dir / "summary.json") << tr.summary.dump(2);
  auto run = [&](const std::string& args) {
    const std::string cmd = args + " > '" + (dir / "log.txt").string() + "' 2>&1";
    const int status = std::system(cmd.c_str());
    std::ifstream in(dir / "log.txt");
    std::stringstream ss;
    ss << in.rdbuf();
    return std::make_pair(WEXITSTATUS(status), ss.str());
  };
  const std::string shipdata = "'" + (kBin / "floesim-shipdata").string() + "'";
  const std::string ident = "'" + (kBin / "floesim-identify").string() + "'";
  auto [c1, out1] = run(shipdata + " --results '" + (dir / "results.h5").string() + "' --out '" +
                        (dir / "ship.csv").string() + "'");
  ASSERT_EQ(c1, 0) << out1;
  ASSERT_TRUE(fs::exists(dir / "ship.json"));
  ASSERT_TRUE(fs::exists(dir / "ship.provenance.json"));
  auto [c2, out2] = run(ident + " --check-config --config '" + (dir / "ship.json").string() + "'");
  EXPECT_EQ(c2, 0) << out2;
  auto [c3, out3] = run(ident + " --measured '" + (dir / "ship.csv").string() + "' --config '" +
                        (dir / "ship.json").string() + "' --out '" + (dir / "id").string() + "'");
  ASSERT_EQ(c3, 0) << out3;
  const nlohmann::json j = load_json_file(dir / "id" / "identified.json");
  const ShipData d = make_ship_data(tr.results, tr.summary, {});
  const Identification id = identify(d.measured, d.identify);
  // The CSV holds 15 significant digits: the same mean up to their round-off.
  EXPECT_NEAR(j["mean_surge_ice_load_n"].get<double>(), id.mean_ice.surge, 1e-6 * std::abs(id.mean_ice.surge));

  // A summary of another run: refused, nothing written.
  r.attributes["provenance"] = {{"config", {{"duration_s", 1}}}};
  write_results(dir / "other.h5", r);
  auto [c4, out4] = run(shipdata + " --results '" + (dir / "other.h5").string() + "' --summary '" +
                        (dir / "summary.json").string() + "' --out '" + (dir / "other.csv").string() + "'");
  EXPECT_NE(c4, 0);
  EXPECT_NE(out4.find("another run"), std::string::npos) << out4;
  EXPECT_FALSE(fs::exists(dir / "other.csv"));
  fs::remove_all(dir);
}
