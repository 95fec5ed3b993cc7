// floesim-identify (PHYSICS.md §4.4): synthetic series with a known ice load recovered to round-off, the mass
// matrix, wind and ITTC-57 against hand-worked numbers, bad input naming line and column with nothing written, and
// the executable end to end.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/error.h"
#include "sim/analysis/identify.h"
#include "pipeline/geometry2d.h"
#include "sim_fixtures.h"

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;
using testing::temp_dir;

const fs::path kBin = FLOESIM_BIN_DIR;

using testing::expect_error;

// The test's own Fossen wind load (written out here, not the code under test): q = 1/2 rho V^2.
Load3 hand_wind(double V, double gamma_deg, double rho, double af, double al, double loa, double cx, double cy,
                double cn) {
  const double g = gamma_deg * kPi / 180, q = 0.5 * rho * V * V;
  return {-q * cx * std::cos(g) * af, -q * cy * std::sin(g) * al, -q * cn * std::sin(2 * g) * al * loa};
}

struct Row {
  double t, u, v, r, thrust, ws, wa, du, dv, dr;
};

void write_csv(const fs::path& f, const std::vector<Row>& rows, bool with_acc) {
  std::ofstream o(f);
  o.precision(17);
  o << "time_s,u_mps,v_mps,r_radps,thrust_n,wind_speed_mps,wind_angle_deg,heading_deg" << (with_acc ? ",du_mps2,dv_mps2,dr_radps2" : "")
    << "\n";
  for (const Row& x : rows) {
    o << x.t << ',' << x.u << ',' << x.v << ',' << x.r << ',' << x.thrust << ',' << x.ws << ',' << x.wa << ",123";
    if (with_acc) o << ',' << x.du << ',' << x.dv << ',' << x.dr;
    o << '\n';
  }
}

// (2) The default mass matrix is the seed's Oden value, surge/sway/yaw, and its yaw radius of gyration is the
// 26.7 m ~ 0.25 L that PHYSICS.md §4.4 works out.
TEST(SimIdentify, DefaultMassMatrixIsOdens) {
  const IdentifyOptions o;
  EXPECT_EQ(o.mass.surge_kg, 13e6);
  EXPECT_EQ(o.mass.sway_kg, 13e6);
  EXPECT_EQ(o.mass.yaw_kg_m2, 9286.4e6);
  EXPECT_NEAR(std::sqrt(o.mass.yaw_kg_m2 / o.mass.sway_kg), 26.727, 1e-3);
}

// (2) Wind at 10 m/s from 30 deg off the port bow, rho_a 1.3, A_F 400, A_L 900, L_oa 107.75 (the defaults):
// q = 65 Pa; X = -65 * 0.7 * 400 * cos 30 = -15761.66 N; Y = -65 * 0.8 * 900 * sin 30 = -23400 N;
// N = -65 * 0.1 * 900 * 107.75 * sin 60 = -545888.3 N m. Head wind: X = -65 * 0.7 * 400 = -18200 N, no Y or N.
TEST(SimIdentify, WindLoadHandWorked) {
  const IdentifyWindOptions w;
  const Load3 a = wind_load(10, 30, w);
  EXPECT_NEAR(a.surge, -15761.66, 0.01);
  EXPECT_NEAR(a.sway, -23400.0, 1e-9);
  EXPECT_NEAR(a.yaw, -545888.29, 0.01);
  const Load3 h = wind_load(10, 0, w);
  EXPECT_NEAR(h.surge, -18200.0, 1e-9);
  EXPECT_NEAR(h.sway, 0.0, 1e-9);
  EXPECT_NEAR(h.yaw, 0.0, 1e-9);
  const Load3 s = wind_load(10, -90, w);  // from starboard: pushes to port (+y), no surge
  EXPECT_NEAR(s.surge, 0.0, 1e-9);
  EXPECT_NEAR(s.sway, 65 * 0.8 * 900, 1e-9);
}

// (2) ITTC-57 through the simulator's curve: PHYSICS.md §4.2 worked numbers, L = 100 m: C_F = 0.00206 at 2 m/s
// and 0.00177 at 6 m/s; R / (1/2 rho S u^2) = (1 + k) C_F + C_A. The quadratic fit is a u + b u|u|.
TEST(SimIdentify, OpenWaterResistance) {
  ResistanceOptions r;  // ittc57, L_wl 100 m, S 2950 m^2, k 0.3, C_A 0.0004
  for (auto [u, cf] : {std::pair{2.0, 0.00206}, std::pair{6.0, 0.00177}}) {
    const double ct = open_water_resistance(u, r) / (0.5 * 1025 * 2950 * u * u);
    EXPECT_NEAR((ct - 0.0004) / 1.3, cf, 5e-6) << "u = " << u;
  }
  EXPECT_NEAR(open_water_resistance(-2, r), -open_water_resistance(2, r), 1e-9);
  r.model = "quadratic";
  r.a_n_per_mps = 2e4;
  r.b_n_per_mps2 = 5e4;
  EXPECT_NEAR(open_water_resistance(2, r), 2e4 * 2 + 5e4 * 4, 1e-9);
  EXPECT_NEAR(open_water_resistance(-2, r), -(2e4 * 2 + 5e4 * 4), 1e-9);
}

// (1) A known constant ice load, accelerations differentiated. Closed-form trajectory: constant accelerations
// (u, v, r linear in time), so central differences and the moving average are exact. No sway/yaw damping, so the
// sway and yaw balances M a = tau_wind + tau_ice hold at constant accelerations; the surge thrust is what the
// closed form needs: T(t) = M du + R(u(t)) - X_wind - X_ice.
TEST(SimIdentify, RecoversConstantIceLoadFromVelocities) {
  const fs::path d = temp_dir("identify_velocities");
  const double M1 = 13e6, M2 = 13e6, M3 = 9.2864e9, a = 2e5, b = 5e4;
  const Load3 ice{-4e5, 3e4, -2e6};
  const double V = 12, gam = 40;
  const Load3 w = hand_wind(V, gam, 1.3, 400, 900, 107.75, 0.7, 0.8, 0.1);
  const double du = 0.01, dv = (ice.sway + w.sway) / M2, dr = (ice.yaw + w.yaw) / M3;
  std::vector<Row> rows;
  for (int i = 0; i <= 6000; ++i) {  // 60 s at 100 Hz
    const double t = 100 + i * 0.01;
    const double u = 1.0 + du * (t - 100), v = 0.05 + dv * (t - 100), r = 0.002 + dr * (t - 100);
    const double R = a * u + b * u * u;
    rows.push_back({t, u, v, r, M1 * du + R - w.surge - ice.surge, V, gam, 0, 0, 0});
  }
  write_csv(d / "measured.csv", rows, false);
  IdentifyOptions o;
  o.resistance.model = "quadratic";
  o.resistance.a_n_per_mps = a;
  o.resistance.b_n_per_mps2 = b;
  const Identification id = identify(read_measured_csv(d / "measured.csv"), o);
  EXPECT_TRUE(id.differentiated);
  EXPECT_EQ(id.acceleration_window_samples, 10u);  // 0.1 s at 0.01 s
  ASSERT_EQ(id.output.time_s.size(), 120u);        // 60 s in whole 0.5 s intervals
  EXPECT_NEAR(id.output.time_s.front(), 100.25, 1e-9);
  EXPECT_NEAR(id.output.time_s.back(), 159.75, 1e-9);
  for (size_t k = 0; k < id.output.time_s.size(); ++k) {
    EXPECT_NEAR(id.output.ice[k].surge, ice.surge, 1e-6) << k;
    EXPECT_NEAR(id.output.ice[k].sway, ice.sway, 1e-6) << k;
    EXPECT_NEAR(id.output.ice[k].yaw, ice.yaw, 1e-3) << k;
    EXPECT_NEAR(id.output.inertia[k].surge, M1 * du, 1e-6) << k;  // M nu_dot: 1.3e5 N
  }
  EXPECT_NEAR(id.mean_ice.surge, ice.surge, 1e-6);
  EXPECT_NEAR(id.mean_ice.sway, ice.sway, 1e-6);
  EXPECT_NEAR(id.mean_ice.yaw, ice.yaw, 1e-3);
  EXPECT_EQ(id.mean_samples, 6001u);
}

// (1) Measured accelerations, ITTC-57 resistance and linear sway/yaw damping: surge accelerates at a constant rate,
// sway and yaw drift steadily where damping balances wind and ice, v0 = (Y_wind + Y_ice) / Y_v.
TEST(SimIdentify, RecoversConstantIceLoadFromMeasuredAccelerations) {
  const fs::path d = temp_dir("identify_accelerations");
  const double M1 = 13e6, Yv = 1e6, Nr = 1e9;
  const Load3 ice{-3e5, -5e4, 1e6};
  const double V = 8, gam = -120;
  const Load3 w = hand_wind(V, gam, 1.3, 400, 900, 107.75, 0.7, 0.8, 0.1);
  const double v0 = (w.sway + ice.sway) / Yv, r0 = (w.yaw + ice.yaw) / Nr, du = 0.02;
  // The test's own ITTC-57 (PHYSICS.md §4.2): L 100 m, S 2950 m^2, k 0.3, C_A 0.0004, nu 1.83e-6, rho 1025.
  auto ittc = [](double u) {
    const double lg = std::log10(u * 100 / 1.83e-6) - 2;
    return 0.5 * 1025 * 2950 * u * u * (1.3 * 0.075 / (lg * lg) + 0.0004);
  };
  std::vector<Row> rows;
  for (int i = 0; i <= 400; ++i) {  // 20 s at 20 Hz
    const double t = i * 0.05, u = 2 + du * t;
    rows.push_back({t, u, v0, r0, M1 * du + ittc(u) - w.surge - ice.surge, V, gam, du, 0, 0});
  }
  write_csv(d / "measured.csv", rows, true);
  IdentifyOptions o;
  o.damping.sway_n_per_mps = Yv;
  o.damping.yaw_nm_per_radps = Nr;
  o.mean_window_s = {5, 15};
  const Identification id = identify(read_measured_csv(d / "measured.csv"), o);
  EXPECT_FALSE(id.differentiated);
  EXPECT_EQ(id.acceleration_window_samples, 2u);  // round(0.1 / 0.05)
  ASSERT_EQ(id.output.time_s.size(), 40u);
  for (size_t k = 0; k < id.output.time_s.size(); ++k) {
    EXPECT_NEAR(id.output.ice[k].surge, ice.surge, 1e-6) << k;
    EXPECT_NEAR(id.output.ice[k].sway, ice.sway, 1e-6) << k;
    EXPECT_NEAR(id.output.ice[k].yaw, ice.yaw, 1e-4) << k;
  }
  EXPECT_NEAR(id.mean_ice.surge, ice.surge, 1e-6);
  EXPECT_EQ(id.mean_samples, 201u);  // t = 5.00 .. 15.00 at 0.05 s
}

// The output rule: the mean of the samples in each whole interval [t0 + kT, t0 + (k+1)T), at the interval's centre.
// A surge ice load that steps from 0 to -1e5 N at t = 1.0 s (thrust steps down, the ship at constant speed).
TEST(SimIdentify, OutputIsTheMeanOverEachInterval) {
  const fs::path d = temp_dir("identify_rule");
  std::vector<Row> rows;
  for (int i = 0; i <= 25; ++i) {  // 2.5 s at 10 Hz: 5 whole intervals
    const double t = i * 0.1;
    rows.push_back({t, 0, 0, 0, t < 0.95 ? 1e5 : 0.0, 0, 0, 0, 0, 0});
  }
  write_csv(d / "m.csv", rows, true);
  IdentifyOptions o;
  o.filters.acceleration_window_s = 0;
  const Identification id = identify(read_measured_csv(d / "m.csv"), o);
  ASSERT_EQ(id.output.time_s.size(), 5u);
  // Samples 0.0..0.4 -> thrust 1e5, ice -1e5; 0.5..0.9 the same; 1.0.. thrust 0, ice 0.
  EXPECT_NEAR(id.output.ice[0].surge, -1e5, 1e-9);
  EXPECT_NEAR(id.output.ice[1].surge, -1e5, 1e-9);
  EXPECT_NEAR(id.output.ice[2].surge, 0, 1e-9);
  EXPECT_NEAR(id.output.time_s[1], 0.75, 1e-12);
  // The mean over all 26 samples: 10 of -1e5.
  EXPECT_NEAR(id.mean_ice.surge, -1e5 * 10 / 26, 1e-6);
}

// Coriolis-centripetal terms of a diagonal M (Fossen), hand-worked at a steady u = 2, v = 0.1, r = 0.01 with
// M11 = 1.3e7, M22 = 1.5e7 and no acceleration: C(nu) nu = [-M22 v r, M11 u r, (M22 - M11) u v]
// = [-15 000 N, 260 000 N, 400 000 N m]. Thrust 500 kN against R = 1e5 u^2 = 400 kN: surge ice -115 000 N.
TEST(SimIdentify, CoriolisTermsHandWorked) {
  const fs::path d = temp_dir("identify_coriolis");
  std::vector<Row> rows;
  for (int i = 0; i <= 20; ++i) rows.push_back({i * 0.1, 2, 0.1, 0.01, 5e5, 0, 0, 0, 0, 0});
  write_csv(d / "m.csv", rows, true);
  IdentifyOptions o;
  o.mass.sway_kg = 1.5e7;
  o.resistance.model = "quadratic";
  o.resistance.b_n_per_mps2 = 1e5;
  o.coriolis = true;
  const Identification id = identify(read_measured_csv(d / "m.csv"), o);
  EXPECT_NEAR(id.mean_ice.surge, -115000, 1e-6);
  EXPECT_NEAR(id.mean_ice.sway, 260000, 1e-6);
  EXPECT_NEAR(id.mean_ice.yaw, 400000, 1e-6);
  o.coriolis = false;  // the seed's M nu_dot alone: only the thrust deficit
  const Identification plain = identify(read_measured_csv(d / "m.csv"), o);
  EXPECT_NEAR(plain.mean_ice.surge, -100000, 1e-6);
  EXPECT_NEAR(plain.mean_ice.sway, 0, 1e-6);
}

// Two IMUs 100 m apart on the centre line, r = 0.02 rad/s, r_dot = 0.001 rad/s^2, a_G = (0.1, 0.05) m/s^2:
// a_k = a_G + r_dot (-p_y, p_x) - r^2 p: IMU at (50, 0) reads (0.1 - 0.0004 * 50, 0.05 + 0.001 * 50) = (0.08, 0.10);
// at (-50, 0) reads (0.12, 0.00). Combined back: (0.1, 0.05) and r_dot 0.001 (not the 0.5 passed for one point).
TEST(SimIdentify, CombineImusHandWorked) {
  const Load3 a = combine_imus({{50, 0, 0.08, 0.10}, {-50, 0, 0.12, 0.0}}, 0.02, 0.5);
  EXPECT_NEAR(a.surge, 0.1, 1e-12);
  EXPECT_NEAR(a.sway, 0.05, 1e-12);
  EXPECT_NEAR(a.yaw, 0.001, 1e-12);
  // One IMU: r_dot is the one given; a_G = a + r^2 p + r_dot (p_y, -p_x) = (0.08 + 0.02, 0.10 - 0.05).
  const Load3 b = combine_imus({{50, 0, 0.08, 0.10}}, 0.02, 0.001);
  EXPECT_NEAR(b.surge, 0.1, 1e-12);
  EXPECT_NEAR(b.sway, 0.05, 1e-12);
  EXPECT_NEAR(b.yaw, 0.001, 1e-12);
}

// (1) with IMUs: the trajectory of RecoversConstantIceLoadFromVelocities (constant nu_dot), measured by IMUs that
// read the rigid-body acceleration at their positions, a_k = nu_dot + [-r v, r u] + r_dot (-p_y, p_x) - r^2 p_k.
TEST(SimIdentify, RecoversConstantIceLoadFromImus) {
  const double M1 = 13e6, M2 = 13e6, M3 = 9.2864e9;
  const Load3 ice{-2.5e5, -4e4, 3e6};
  const Load3 w = hand_wind(15, 150, 1.3, 400, 900, 107.75, 0.7, 0.8, 0.1);
  const double du = -0.005, dv = (ice.sway + w.sway) / M2, dr = (ice.yaw + w.yaw) / M3;
  const std::vector<std::vector<double>> layouts[] = {{{40, 5}, {-30, -8}, {0, 10}}, {{12, -3}}};
  for (const auto& pos : layouts) {
    SCOPED_TRACE(pos.size());
    const fs::path d = temp_dir("identify_imus" + std::to_string(pos.size()));
    std::ofstream f(d / "m.csv");
    f.precision(17);
    f << "time_s,u_mps,v_mps,r_radps,thrust_n,wind_speed_mps,wind_angle_deg";
    for (size_t k = 1; k <= pos.size(); ++k) f << ",imu" << k << "_ax_mps2,imu" << k << "_ay_mps2";
    f << "\n";
    for (int i = 0; i <= 600; ++i) {  // 30 s at 20 Hz
      const double t = i * 0.05, u = 3 + du * t, v = -0.1 + dv * t, r = 0.01 + dr * t;
      f << t << ',' << u << ',' << v << ',' << r << ',' << M1 * du + 1e5 * u * u - w.surge - ice.surge << ",15,150";
      for (const auto& p : pos)
        f << ',' << du - r * v - dr * p[1] - r * r * p[0] << ',' << dv + r * u + dr * p[0] - r * r * p[1];
      f << "\n";
    }
    f.close();
    IdentifyOptions o;
    o.resistance.model = "quadratic";
    o.resistance.b_n_per_mps2 = 1e5;
    for (const auto& p : pos) o.imus.push_back({p});
    const Identification id = identify(read_measured_csv(d / "m.csv"), o);
    EXPECT_TRUE(id.from_imus);
    for (size_t k = 0; k < id.output.time_s.size(); ++k) {
      EXPECT_NEAR(id.output.ice[k].surge, ice.surge, 1e-5) << k;
      EXPECT_NEAR(id.output.ice[k].sway, ice.sway, 1e-5) << k;
      EXPECT_NEAR(id.output.ice[k].yaw, ice.yaw, 1e-2) << k;
    }
    // The config must give one position per IMU.
    o.imus.push_back({{0, 0}});
    expect_error([&] { identify(read_measured_csv(d / "m.csv"), o); }, {"IMU", "one position per IMU"});
  }
}

// (3) Bad input: clear errors naming the file, the line and the column; nothing written.
TEST(SimIdentify, BadInputNamesLineAndColumnAndWritesNothing) {
  const fs::path d = temp_dir("identify_bad");
  const std::string head = "time_s,u_mps,v_mps,r_radps,thrust_n,wind_speed_mps,wind_angle_deg\n";
  auto good_rows = [](int n, double step = 0.1) {
    std::ostringstream s;
    for (int i = 0; i < n; ++i) s << i * step << ",2,0,0,5e5,5,10\n";
    return s.str();
  };
  auto check = [&](const std::string& name, const std::string& text, std::initializer_list<const char*> pieces) {
    const fs::path f = d / (name + ".csv");
    std::ofstream(f) << text;
    const fs::path out = d / ("out_" + name);
    SCOPED_TRACE(name);
    expect_error([&] { run_identify(f, "", out); }, pieces);
    EXPECT_FALSE(fs::exists(out)) << "something was written for " << name;
  };
  check("missing", "time_s,u_mps,v_mps,r_radps,thrust_n,wind_speed_mps\n0,2,0,0,5e5,5\n",
        {"missing.csv", "missing required column", "wind_angle_deg"});
  check("monotonic", head + "0,2,0,0,5e5,5,10\n0.1,2,0,0,5e5,5,10\n0.2,2,0,0,5e5,5,10\n0.15,2,0,0,5e5,5,10\n",
        {"monotonic.csv", "line 5", "data row 4", "time_s", "not after"});
  check("gap", head + good_rows(10) + "1.5,2,0,0,5e5,5,10\n1.6,2,0,0,5e5,5,10\n",
        {"gap.csv", "line 12", "data row 11", "time_s", "gap"});
  check("nan", head + "0,2,0,0,5e5,5,10\n0.1,2,nan,0,5e5,5,10\n0.2,2,0,0,5e5,5,10\n",
        {"nan.csv", "line 3", "data row 2", "v_mps", "not a finite number"});
  check("inf", head + "0,2,0,0,5e5,5,10\n0.1,2,0,0,inf,5,10\n0.2,2,0,0,5e5,5,10\n",
        {"inf.csv", "line 3", "thrust_n", "not a finite number"});
  check("empty_cell", head + "0,2,0,0,5e5,5,10\n0.1,,0,0,5e5,5,10\n0.2,2,0,0,5e5,5,10\n",
        {"line 3", "u_mps", "not a finite number"});
  check("speed", head + "0,2,0,0,5e5,5,10\n0.1,100,0,0,5e5,5,10\n0.2,2,0,0,5e5,5,10\n",
        {"speed.csv", "line 3", "u_mps", "wrong units?"});
  check("sway", head + "0,2,0,0,5e5,5,10\n0.1,2,-20,0,5e5,5,10\n", {"line 3", "v_mps", "wrong units?"});
  check("yaw", head + "0,2,0,5,5e5,5,10\n", {"line 2", "r_radps", "wrong units?"});
  check("thrust_neg", head + "0,2,0,0,-5e5,5,10\n", {"line 2", "thrust_n", "wrong units?"});
  check("thrust_big", head + "0,2,0,0,5e11,5,10\n", {"line 2", "thrust_n", "wrong units?"});
  check("gravity", "time_s,u_mps,v_mps,r_radps,thrust_n,wind_speed_mps,wind_angle_deg,du_mps2,dv_mps2,dr_radps2\n"
                   "0,2,0,0,5e5,5,10,0,0,0\n0.1,2,0,0,5e5,5,10,0,0,0\n0.2,2,0,0,5e5,5,10,0,-9.81,0\n",
        {"line 4", "dv_mps2", "gravity"});
  check("imu_half", head.substr(0, head.size() - 1) + ",imu1_ax_mps2\n0,2,0,0,5e5,5,10,0\n",
        {"line 1", "imu1_ay_mps2"});
  check("imu_and_acc", head.substr(0, head.size() - 1) + ",du_mps2,dv_mps2,dr_radps2,imu1_ax_mps2,imu1_ay_mps2\n",
        {"line 1", "either"});
  check("imu_gravity", head.substr(0, head.size() - 1) + ",imu1_ax_mps2,imu1_ay_mps2\n0,2,0,0,5e5,5,10,9.81,0\n",
        {"line 2", "imu1_ax_mps2", "gravity"});
  check("cells", head + "0,2,0,0,5e5,5\n", {"line 2", "6 cells"});
  check("short", head + "0,2,0,0,5e5,5,10\n", {"short.csv", "at least 3"});
  check("empty", "", {"empty.csv", "empty file"});

  // The config: strict keys, named with the file.
  const fs::path good = d / "good.csv";
  std::ofstream(good) << head << good_rows(20);
  std::ofstream(d / "typo.json") << R"({"resistance": {"model": "quadratic", "a_n_per_mp": 1}})";
  expect_error([&] { run_identify(good, d / "typo.json", d / "out_typo"); }, {"typo.json", "resistance.a_n_per_mp"});
  EXPECT_FALSE(fs::exists(d / "out_typo"));
  std::ofstream(d / "window.json") << R"({"mean_window_s": [50, 60]})";
  expect_error([&] { run_identify(good, d / "window.json", d / "out_window"); }, {"mean_window_s", "no sample"});
  EXPECT_FALSE(fs::exists(d / "out_window"));
  std::ofstream(d / "window2.json") << R"({"mean_window_s": [5]})";
  expect_error([&] { run_identify(good, d / "window2.json", d / "out_window2"); }, {"window2.json", "mean_window_s"});
}

int run(const std::string& args) { return std::system((kBin / "floesim-identify").string().append(" " + args).c_str()); }

// (4) The executable end to end: 2 s at 10 Hz at a constant 2 m/s (no acceleration), 500 kN of thrust against a
// quadratic resistance of 1e5 u^2 = 400 kN and no wind: the ice takes the other 100 kN, a surge load of -1e5 N.
TEST(SimIdentify, ExecutableEndToEnd) {
  const fs::path d = temp_dir("identify_e2e");
  {
    std::ofstream f(d / "measured.csv");
    f << "time_s,u_mps,v_mps,r_radps,thrust_n,wind_speed_mps,wind_angle_deg\n";
    for (int i = 0; i <= 20; ++i) f << i * 0.1 << ",2,0,0,500000,0,0\n";
  }
  std::ofstream(d / "config.json") << R"({"resistance": {"model": "quadratic", "a_n_per_mps": 0, "b_n_per_mps2": 1e5}})";
  ASSERT_EQ(run("--measured " + (d / "measured.csv").string() + " --config " + (d / "config.json").string() +
                " --out " + (d / "out").string() + " > " + (d / "log.txt").string()),
            0);
  std::ifstream csv(d / "out" / "identified.csv");
  std::string header, row;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("time_s,ice_surge_n,ice_sway_n,ice_yaw_nm,", 0), 0u) << header;
  int rows = 0;
  while (std::getline(csv, row)) {
    ++rows;
    std::istringstream is(row);
    double t, x;
    char c;
    is >> t >> c >> x;
    EXPECT_NEAR(x, -1e5, 1e-6) << row;
  }
  EXPECT_EQ(rows, 4);
  const auto j = nlohmann::json::parse(std::ifstream(d / "out" / "identified.json"));
  EXPECT_NEAR(j.at("mean_surge_ice_load_n").get<double>(), -1e5, 1e-6);
  EXPECT_EQ(j.at("provenance").at("program"), "floesim-identify");
  EXPECT_EQ(j.at("settings").at("resistance").at("model"), "quadratic");
  // Bad input: non-zero exit, nothing written.
  {
    std::ofstream f(d / "bad.csv");
    f << "time_s,u_mps,v_mps,r_radps,thrust_n,wind_speed_mps,wind_angle_deg\n0,100,0,0,5e5,0,0\n";
  }
  EXPECT_NE(run("--measured " + (d / "bad.csv").string() + " --out " + (d / "out_bad").string() + " 2> " +
                (d / "err.txt").string()),
            0);
  EXPECT_FALSE(fs::exists(d / "out_bad"));
  EXPECT_EQ(run("--help-config > " + (d / "help.md").string()), 0);
  std::stringstream help;
  help << std::ifstream(d / "help.md").rdbuf();
  EXPECT_NE(help.str().find("mass.yaw_kg_m2"), std::string::npos);
}

}  // namespace
}  // namespace floesim::sim
