// floesim-resistance (issue #10 item 3): the stage over the core's formulas. Its defaults are the simulation's ice
// (SAMS Table 1); PHYSICS.md §6.1-6.2's worked examples through the stage and its artefacts; the Oden-like hull's
// table against the closed form its blunt waterline (alpha = 90 deg) reduces Lindqvist to; strict options and
// clear errors; the executable end to end.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/csv.h"
#include "pipeline/error.h"
#include "pipeline/geometry2d.h"
#include "sim/vessel/hull.h"
#include "sim/analysis/resistance.h"
#include "tests/sim/sim_fixtures.h"
#include "tests/test_util.h"

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;
using floesim::tests::read_text;
using testing::expect_error;
using testing::temp_dir;

const fs::path kBin = FLOESIM_BIN_DIR;

// PHYSICS.md §6.1-6.2's example hull and ice, as a config.
IceResistanceOptions example_options() {
  IceResistanceOptions o;
  o.thicknesses_m = {1.0};
  o.speeds_mps = {0.0, 1.0, 2.0};
  o.fracture.flexural_strength_pa = 0.5e6;
  o.fracture.youngs_modulus_pa = 2e9;
  o.fracture.poisson_ratio = 0.3;
  o.ice.density_kg_m3 = 900;
  o.ice.mu_ice_structure = 0.1;
  o.water.density_kg_m3 = 1025;
  o.water.gravity_mps2 = 9.81;
  o.hull = {100, 20, 7, 30, 30, 50, 25};
  return o;
}

TEST(Resistance, DefaultIceIsTheSimulationsSamsTable1) {
  // SAMS Table 1 (PHYSICS.md, top): h = 1 m, sigma_f = 500 kPa, E = 5 GPa, nu = 0.3, rho_i = 900, rho_w = 1025,
  // mu_is = 0.15; and the values simulate itself runs with.
  const IceResistanceOptions o;
  EXPECT_EQ(o.thicknesses_m, std::vector<double>{1.0});
  EXPECT_EQ(o.fracture.flexural_strength_pa, 500e3);
  EXPECT_EQ(o.fracture.youngs_modulus_pa, 5e9);
  EXPECT_EQ(o.fracture.poisson_ratio, 0.3);
  EXPECT_EQ(o.ice.density_kg_m3, 900.0);
  EXPECT_EQ(o.water.density_kg_m3, 1025.0);
  EXPECT_EQ(o.ice.mu_ice_structure, 0.15);
  const SimulateOptions s;
  EXPECT_EQ(o.fracture.flexural_strength_pa, s.fracture.flexural_strength_pa);
  EXPECT_EQ(o.fracture.youngs_modulus_pa, s.fracture.youngs_modulus_pa);
  EXPECT_EQ(o.fracture.poisson_ratio, s.fracture.poisson_ratio);
  EXPECT_EQ(o.ice.density_kg_m3, s.ice.density_kg_m3);
  EXPECT_EQ(o.ice.mu_ice_structure, s.ice.mu_ice_structure);
  EXPECT_EQ(o.water.density_kg_m3, s.water.density_kg_m3);
  EXPECT_EQ(o.water.gravity_mps2, s.water.gravity_mps2);
}

TEST(Resistance, WorkedExamplesThroughTheStageAndItsArtefacts) {
  const fs::path dir = temp_dir("resistance_examples");
  const std::string printed = run_resistance(example_options(), "", "", dir / "ref.csv");
  std::cout << printed;
  // The CSV: one row per (h, v); PHYSICS.md §6.1's totals and §6.2's R at 2 m/s, in kN.
  const NumericCsv csv = read_numeric_csv(dir / "ref.csv", {"speed_mps", "lindqvist_total_kN", "riska_total_kN"});
  ASSERT_EQ(csv.column("speed_mps").size(), 3u);
  EXPECT_NEAR(csv.column("lindqvist_total_kN")[0], 587.0, 0.05);
  EXPECT_NEAR(csv.column("lindqvist_total_kN")[1], 807.8, 0.05);
  EXPECT_NEAR(csv.column("lindqvist_total_kN")[2], 1028.7, 0.05);
  EXPECT_NEAR(csv.column("lindqvist_crushing_kN")[0], 192.1, 0.05);
  EXPECT_NEAR(csv.column("lindqvist_bending_kN")[0], 112.1, 0.05);
  EXPECT_NEAR(csv.column("lindqvist_submersion_kN")[0], 282.8, 0.05);
  EXPECT_NEAR(csv.column("riska_c1_kN")[2], 580.9, 0.05);
  EXPECT_NEAR(csv.column("riska_c2_kN_per_mps")[2], 181.4, 0.05);
  EXPECT_NEAR(csv.column("riska_total_kN")[2], 943.6, 0.05);
  // The breaking and submersion parts at speed add up to the total.
  for (size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(csv.column("lindqvist_breaking_at_speed_kN")[i] + csv.column("lindqvist_submersion_at_speed_kN")[i],
                csv.column("lindqvist_total_kN")[i], 1e-9);
  // The JSON beside it: the same table, the hull with where each value came from, the provenance.
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "ref.json"));
  EXPECT_NEAR(j["rows"][2]["lindqvist"]["total_kN"].get<double>(), 1028.7, 0.05);
  EXPECT_NEAR(j["rows"][0]["lindqvist"]["normal_flare_deg"].get<double>(), 49.11, 0.005);
  EXPECT_EQ(j["hull"]["source"]["stem_angle_deg"], "config");
  EXPECT_EQ(j["provenance"]["program"], "floesim-resistance");
  // Deterministic: a second run writes the same bytes.
  const std::string first = read_text(dir / "ref.csv") + read_text(dir / "ref.json");
  run_resistance(example_options(), "", "", dir / "ref.csv");
  EXPECT_EQ(read_text(dir / "ref.csv") + read_text(dir / "ref.json"), first);
  fs::remove_all(dir);
}

TEST(Resistance, OdenLikeHullMatchesTheBluntWaterlineClosedForm) {
  // The Oden-like hull's waterline is square across at B/4 (alpha = 90 deg; tests/sim/hull_particulars_test.cpp):
  // then psi = phi and Lindqvist reduces to
  //   R_c = 1/2 sigma h^2 (tan phi + mu) / (1 - mu tan phi)
  //   R_b = 27/64 sigma B h^1.5 / sqrt(E / (12 (1 - nu^2) g rho_w)) (tan phi + mu) (1 + 1/cos phi)
  //   R_s = (rho_w - rho_i) g h B [T (B + T)/(B + 2T) + mu (0.7 L - T/tan phi + T cos^2 phi / sin phi)]
  // written out here from PHYSICS.md §6.1, with the hull's measured L, B, T, phi, and the default (Table 1) ice.
  const fs::path dir = temp_dir("resistance_oden");
  write_generated_hull(HullGeneratorOptions{}, dir / "hull.obj", "");
  IceResistanceOptions o;
  o.thicknesses_m = {0.5, 1.0, 1.5};
  o.speeds_mps = {1.0, 2.0, 3.0};
  std::cout << run_resistance(o, dir / "hull.json", "", dir / "ref.json");
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "ref.json"));
  const nlohmann::json& hull = j["hull"];
  const double L = hull["length_m"], B = hull["beam_m"], T = hull["draught_m"];
  const double phi = hull["stem_angle_deg"].get<double>() * kPi / 180.0;
  ASSERT_NEAR(hull["entrance_angle_deg"].get<double>(), 90.0, 0.05);
  const double sigma = 0.5e6, E = 5e9, nu = 0.3, g = 9.81, rw = 1025, ri = 900, mu = 0.15;
  ASSERT_EQ(j["rows"].size(), 9u);
  for (const nlohmann::json& row : j["rows"]) {
    const double h = row["thickness_m"], v = row["speed_mps"];
    const double tp = std::tan(phi);
    const double rc = 0.5 * sigma * h * h * (tp + mu) / (1 - mu * tp);
    const double rb = 27.0 / 64.0 * sigma * B * std::pow(h, 1.5) / std::sqrt(E / (12 * (1 - nu * nu) * g * rw)) *
                      (tp + mu) * (1 + 1 / std::cos(phi));
    const double rs = (rw - ri) * g * h * B *
                      (T * (B + T) / (B + 2 * T) +
                       mu * (0.7 * L - T / tp + T * std::cos(phi) * std::cos(phi) / std::sin(phi)));
    const double total = (rc + rb) * (1 + 1.4 * v / std::sqrt(g * h)) + rs * (1 + 9.4 * v / std::sqrt(g * L));
    // 0.05 deg of alpha about 90 deg moves these by far less than 1e-6 (sin, cos are flat there).
    EXPECT_NEAR(row["lindqvist"]["crushing_kN"].get<double>(), rc / 1e3, 1e-6 * rc);
    EXPECT_NEAR(row["lindqvist"]["bending_kN"].get<double>(), rb / 1e3, 1e-6 * rb);
    EXPECT_NEAR(row["lindqvist"]["submersion_kN"].get<double>(), rs / 1e3, 1e-6 * rs);
    EXPECT_NEAR(row["lindqvist"]["total_kN"].get<double>(), total / 1e3, 1e-6 * total);
  }
  // Monotone in thickness and speed, both formulas.
  for (size_t k = 0; k + 1 < 9; ++k) {
    const nlohmann::json &a = j["rows"][k], &b = j["rows"][k + 1];
    if (a["thickness_m"] == b["thickness_m"]) {
      EXPECT_LT(a["lindqvist"]["total_kN"].get<double>(), b["lindqvist"]["total_kN"].get<double>());
      EXPECT_LT(a["riska"]["total_kN"].get<double>(), b["riska"]["total_kN"].get<double>());
    }
    if (k + 3 < 9) {
      EXPECT_LT(a["lindqvist"]["total_kN"].get<double>(), j["rows"][k + 3]["lindqvist"]["total_kN"].get<double>());
      EXPECT_LT(a["riska"]["total_kN"].get<double>(), j["rows"][k + 3]["riska"]["total_kN"].get<double>());
    }
  }
  // The same table from the library call a sweep's gather makes: hull.json + the ice.
  const auto rows = ice_resistance_table(dir / "hull.json", level_ice(o, 1.0), o.thicknesses_m, o.speeds_mps);
  ASSERT_EQ(rows.size(), 9u);
  EXPECT_DOUBLE_EQ(rows[4].lindqvist.total_n / 1e3, j["rows"][4]["lindqvist"]["total_kN"].get<double>());
  EXPECT_DOUBLE_EQ(rows[4].riska.total_n / 1e3, j["rows"][4]["riska"]["total_kN"].get<double>());
  fs::remove_all(dir);
}

TEST(Resistance, BadOptionsAndInputsAreErrorsNamingTheKey) {
  const fs::path dir = temp_dir("resistance_bad");
  auto problem = [&](const char* text) {
    try {
      read_options<IceResistanceOptions>(Json::parse(text), "res.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(problem(R"({"thickness_m": [1]})").find("thickness_m"), std::string::npos);  // unknown (a typo)
  EXPECT_NE(problem(R"({"thicknesses_m": []})").find("thicknesses_m"), std::string::npos);
  EXPECT_NE(problem(R"({"thicknesses_m": [1, -0.5]})").find("thicknesses_m"), std::string::npos);
  EXPECT_NE(problem(R"({"speeds_mps": [-1]})").find("speeds_mps"), std::string::npos);
  EXPECT_NE(problem(R"({"fracture": {"poisson_ratio": 0.7}})").find("fracture.poisson_ratio"), std::string::npos);
  EXPECT_NE(problem(R"({"hull": {"stem_angle_deg": 120}})").find("hull.stem_angle_deg"), std::string::npos);
  EXPECT_NE(problem(R"({"ice": {"flexural_strength": 5e5}})").find("ice.flexural_strength"), std::string::npos);
  // No hull.json and not all particulars: every missing key named.
  IceResistanceOptions o;
  o.hull.length_m = 100;
  expect_error([&] { run_resistance(o, "", "res.json", dir / "r.json"); },
               {"res.json", "hull.beam_m", "hull.bow_length_m", "--hull"});
  // A hull.json from before the particulars were measured.
  std::ofstream(dir / "old.json") << R"({"hydrostatics": {"volume_m3": 1}})";
  expect_error([&] { run_resistance(IceResistanceOptions{}, dir / "old.json", "", dir / "r.json"); },
               {"old.json", "particulars", "floesim-hull"});
  // A measured particular the formula cannot take (a bulb's stem angle): the key, its value and its source.
  std::ofstream(dir / "bulb.json") << R"({"particulars": {"length_m": 7.36, "beam_m": 1.02, "draught_m": 0.34,
      "stem_angle_deg": 155.9, "entrance_angle_deg": 18.3, "parallel_midbody_m": 3.96, "bow_length_m": 2.33}})";
  expect_error([&] { run_resistance(IceResistanceOptions{}, dir / "bulb.json", "", dir / "r.json"); },
               {"hull.stem_angle_deg", "155.9", "bulb.json"});
  o = example_options();
  expect_error([&] { run_resistance(o, "", "", dir / "r.txt"); }, {".json or .csv"});
  EXPECT_FALSE(fs::exists(dir / "r.json"));
  fs::remove_all(dir);
}

TEST(Resistance, ExecutableEndToEnd) {
  const fs::path dir = temp_dir("resistance_exe");
  const std::string hull = (kBin / "floesim-hull").string(), res = (kBin / "floesim-resistance").string();
  ASSERT_EQ(std::system((hull + " --out " + (dir / "hull.obj").string() + " > /dev/null").c_str()), 0);
  const std::string base = res + " --hull " + (dir / "hull.json").string();
  ASSERT_EQ(std::system((base + " --speeds 1,2,3 --thicknesses 0.5,1,1.5 --out " + (dir / "ref.csv").string() +
                         " > " + (dir / "out.txt").string())
                            .c_str()),
            0);
  const NumericCsv csv = read_numeric_csv(dir / "ref.csv", {"thickness_m", "speed_mps", "lindqvist_total_kN"});
  EXPECT_EQ(csv.column("thickness_m").size(), 9u);
  EXPECT_NE(read_text(dir / "out.txt").find("| 1.5 | 3 |"), std::string::npos) << read_text(dir / "out.txt");
  // --help-config lists the keys; --check-config refuses a typo, naming it, and writes nothing.
  ASSERT_EQ(std::system((res + " --help-config > " + (dir / "help.txt").string()).c_str()), 0);
  EXPECT_NE(read_text(dir / "help.txt").find("ice.mu_ice_structure"), std::string::npos);
  std::ofstream(dir / "bad.json") << R"({"ice": {"mu": 0.1}})";
  const int rc = std::system((base + " --config " + (dir / "bad.json").string() + " --check-config 2> " +
                              (dir / "err.txt").string())
                                 .c_str());
  EXPECT_NE(rc, 0);
  EXPECT_NE(read_text(dir / "err.txt").find("ice.mu"), std::string::npos) << read_text(dir / "err.txt");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace floesim::sim
