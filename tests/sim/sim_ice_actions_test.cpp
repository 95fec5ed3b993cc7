// floesim-ice-actions (issue #34 item 4): the stage over the core's structure formulas (pipeline/ice_actions.h,
// pipeline/station_keeping.h, whose worked examples tests/core holds). Here: the stage's tables carry those numbers
// through its options (the brief's cone, the 12-line spread, the DP gains of PHYSICS.md §8), strict options with
// the key named and nothing written, the executable end to end; and a ridge's keel and consolidated layer (§9.3).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "pipeline/csv.h"
#include "pipeline/error.h"
#include "sim/analysis/ice_actions.h"
#include "tests/sim/sim_fixtures.h"
#include "tests/test_util.h"

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;
using floesim::tests::read_text;
using testing::expect_error;
using testing::temp_dir;

const fs::path kBin = FLOESIM_BIN_DIR;

// The 12 lines of §8.4.1 (chain 1 kN/m, 40 m to the seabed, 600 m, 300 kN pretension; at 15 + 30 i deg), a 1 and a
// 2 MN load, and the surge DP example (M = 1.3e7 kg x 1.05).
nlohmann::json floater() {
  nlohmann::json lines = nlohmann::json::array();
  for (int i = 0; i < 12; ++i) lines.push_back({{"azimuth_deg", 15 + 30 * i}});
  return {{"structure", {{"kind", "vertical"}, {"waterline_width_m", 10}}},
          {"thicknesses_m", {1.0}},
          {"mooring", {{"lines", lines}, {"loads_n", {1e6, 2e6}}}},
          {"dp", {{"mass_kg", 1.3e7 * 1.05}, {"natural_period_s", 100}, {"damping_ratio", 0.7}}}};
}

TEST(IceActions, TheStageCarriesTheBriefsNumbers) {
  const fs::path dir = temp_dir("ice_actions");
  // The brief's cone (w 10 m, 45 deg, h 1 m, the simulation's default ice): Croasdale F_H 987.6 kN clear.
  IceActionsOptions cone;
  cone.thicknesses_m = {1.0};
  run_ice_actions(cone, "", dir / "cone.json");
  const nlohmann::json c = nlohmann::json::parse(read_text(dir / "cone.json"));
  EXPECT_NEAR(c["rows"][0]["croasdale"]["horizontal_kN"].get<double>(), 987.6, 0.05);
  EXPECT_NEAR(c["rows"][0]["ralston"]["breaking_kN"].get<double>(), 1406, 0.5);
  // A vertical face with the mooring and DP of §8.4: F_G 20.59 MN; K_xx 557.3 kN/m; offsets 1.64 and 2.74 m; K_p.
  const auto o = read_options<IceActionsOptions>(floater(), "floater");
  const std::string text = run_ice_actions(o, "", dir / "floater.csv");
  const nlohmann::json f = nlohmann::json::parse(read_text(dir / "floater.json"));
  EXPECT_NEAR(f["rows"][0]["iso19906"]["force_kN"].get<double>(), 20590, 5);
  EXPECT_NEAR(f["mooring"]["linear_stiffness_kN_per_m"]["xx"].get<double>(), 557.3, 0.05);
  EXPECT_NEAR(f["mooring"]["offsets"][0]["offset_m"].get<double>(), 1.64, 0.005);
  EXPECT_NEAR(f["mooring"]["offsets"][1]["offset_m"].get<double>(), 2.74, 0.005);
  EXPECT_NEAR(f["mooring"]["lines"][0]["stiffness_kN_per_m"].get<double>(), 92.37, 0.005);
  EXPECT_NEAR(f["dp"]["proportional_kN_per_m"].get<double>(), 53.9, 0.05);
  const NumericCsv csv = read_numeric_csv(dir / "floater.csv", {"thickness_m", "iso19906_force_kN"});
  EXPECT_NEAR(csv.column("iso19906_force_kN")[0], 20590, 5);
  EXPECT_NE(text.find("| 2000 | 2.74 |"), std::string::npos) << text;
  fs::remove_all(dir);
}

// PHYSICS.md §9.3's worked ridge on a 10 m vertical structure: a consolidated layer of 1.5 m (ISO 19906: p_G 2.232
// MPa, F_C 33.47 MN) over a keel of 8 m (phi 30 deg, c 5 kPa, e 0.3: F_K 2.504 MN, 5.39 MN at h_k + w/2), F_R 35.98 MN.
TEST(IceActions, ARidgesKeelAndConsolidatedLayer) {
  const fs::path dir = temp_dir("ice_actions_ridge");
  const auto o = read_options<IceActionsOptions>(
      {{"structure", {{"kind", "vertical"}, {"waterline_width_m", 10}}},
       {"ridge", {{"keel_depths_m", {4, 8}}, {"consolidated_thickness_m", 1.5}}}},
      "ridge");
  const std::string text = run_ice_actions(o, "", dir / "ridge.json");
  const nlohmann::json r = nlohmann::json::parse(read_text(dir / "ridge.json"))["ridge"];
  EXPECT_NEAR(r["consolidated_layer_kN"].get<double>(), 33470, 5);
  EXPECT_NEAR(r["keels"][0]["force_kN"].get<double>(), 959, 0.5);
  EXPECT_NEAR(r["keels"][1]["force_kN"].get<double>(), 2504, 0.5);
  EXPECT_NEAR(r["keels"][1]["surcharge_bound_kN"].get<double>(), 5390, 5);
  EXPECT_NEAR(r["keels"][1]["ridge_total_kN"].get<double>(), 35980, 5);
  EXPECT_NEAR(r["keel_sail_area_ratio"].get<double>(), 7.20, 0.005);
  EXPECT_NE(text.find("| 8 | 2504.3 | 933.9 | 1570.4 | 5387.0 | 35978.7 |"), std::string::npos) << text;
  fs::remove_all(dir);
}

TEST(IceActions, BadInputNamesTheKeyAndWritesNothing) {
  const fs::path dir = temp_dir("ice_actions_bad");
  const std::vector<std::pair<nlohmann::json, std::string>> bad = {
      {{{"mooring", {{"lines", {{{"length_m", 30}}}}}}}, "mooring.lines[0].length_m"},  // shorter than the depth
      {{{"mooring", {{"lines", {{{"fairlead_height_m", -5}}}}}}}, "fairlead_height_m"},  // anchor above the seabed
      {{{"dp", {{"mass_kg", 1e7}, {"damping_ratio", -0.7}}}}, "dp.damping_ratio"},      // a negative gain
      {{{"structure", {{"slope_deg", 80}}}}, "structure.slope_deg"},
      {{{"structure", {{"kind", "caisson"}}}}, "structure.kind"},
      {{{"structure", {{"neck_width_m", 20}}}}, "structure.neck_width_m"},
      {{{"ice", {{"mu_ice_structure", 1.5}}}}, "ice.mu_ice_structure"},  // above cot 45 deg: refused by the formula
      {{{"mooring", {{"lines", {{{"pretension_n", 1e9}}}}}}}, "mooring.lines[0]"},  // lifts the anchor
      {{{"ridge", {{"keel_depths_m", {8}}, {"porosity", 1.5}}}}, "ridge.porosity"},
      {{{"ridge", {{"keel_depths_m", {-2}}}}}, "ridge.keel_depths_m"},
      {{{"ridge", {{"keel_depths_m", {8}}, {"sail_height_m", 2}}}}, "sail_height_m"},  // not a key of this tool
  };
  for (const auto& [j, key] : bad) {
    expect_error(
        [&] {
          const auto o = read_options<IceActionsOptions>(j, "bad.json");
          run_ice_actions(o, "", dir / "out.json");
        },
        {key.c_str()});
    EXPECT_FALSE(fs::exists(dir / "out.json")) << j.dump();
  }
  fs::remove_all(dir);
}

TEST(IceActions, ExecutableEndToEnd) {
  const fs::path dir = temp_dir("ice_actions_exe");
  const std::string tool = (kBin / "floesim-ice-actions").string();
  ASSERT_EQ(std::system((tool + " --kind cone --width 10 --slope 45 --thicknesses 0.5,1,1.5 --out " +
                         (dir / "cone.csv").string() + " > " + (dir / "out.txt").string())
                            .c_str()),
            0);
  const NumericCsv csv = read_numeric_csv(dir / "cone.csv", {"thickness_m", "croasdale_horizontal_kN"});
  ASSERT_EQ(csv.column("thickness_m").size(), 3u);
  EXPECT_NEAR(csv.column("croasdale_horizontal_kN")[1], 987.6, 0.05);
  // Croasdale's breaking term grows as h^(5/4) at a fixed L_eff; L_eff grows with L_c ~ h^(3/4), so H_B grows
  // faster than h^(5/4) here: thicker ice, a larger load, at every step.
  EXPECT_LT(csv.column("croasdale_horizontal_kN")[0], csv.column("croasdale_horizontal_kN")[1]);
  EXPECT_LT(csv.column("croasdale_horizontal_kN")[1], csv.column("croasdale_horizontal_kN")[2]);
  ASSERT_EQ(std::system((tool + " --help-config > " + (dir / "help.txt").string()).c_str()), 0);
  EXPECT_NE(read_text(dir / "help.txt").find("mooring.lines"), std::string::npos);
  std::ofstream(dir / "bad.json") << R"({"structure": {"slope": 45}})";
  const int rc = std::system((tool + " --config " + (dir / "bad.json").string() + " --out " +
                              (dir / "x.json").string() + " 2> " + (dir / "err.txt").string())
                                 .c_str());
  EXPECT_NE(rc, 0);
  EXPECT_NE(read_text(dir / "err.txt").find("structure.slope"), std::string::npos) << read_text(dir / "err.txt");
  EXPECT_FALSE(fs::exists(dir / "x.json"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace floesim::sim
