#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "pipeline/error.h"
#include "pipeline/results_io.h"
#include "render/plot.h"
#include "synthetic_results.h"
#include "tests/test_util.h"

using namespace floesim;
using namespace floesim::render;
using namespace floesim::render::testing;
namespace fs = std::filesystem;
using floesim::tests::read_text;

namespace {
fs::path write_config(const fs::path& dir, const std::string& text) {
  const fs::path p = dir / "plot.config.json";
  std::ofstream(p) << text;
  return p;
}
}  // namespace

TEST(Plot, WritesPngSvgCsvAndTheSteadyMean) {
  const fs::path dir = fresh_dir("plot_ok");
  Results r = make_results(default_synthetic());
  r.attributes["contact_model"] = "compliant";
  r.attributes["steady_start_s"] = 5.025;
  write_results(dir / "results.h5", r);
  const fs::path cfg = write_config(dir, "{}");

  const SurgeLoadSummary s = plot_surge_load(dir / "results.h5", cfg, dir / "plots");
  // Resistance is -Fx in kN; the alternation cancels over the 300 steady steps.
  EXPECT_NEAR(s.mean_kN, 1000.0, 1e-9);
  EXPECT_EQ(s.steady_samples, 300u);
  EXPECT_DOUBLE_EQ(s.steady_start_s, 5.025);
  EXPECT_EQ(s.contact_model, "compliant");
  EXPECT_DOUBLE_EQ(s.window_s, 0.5);  // "auto" for compliant contacts
  EXPECT_EQ(s.window_samples, 10u);
  EXPECT_NEAR(s.time_step_s, 0.05, 1e-12);
  // The even window cancels the +-300 kN alternation: over full windows the steady moving average is flat at
  // 1000 kN once the 200 -> 1000 kN step has passed through the window.
  EXPECT_TRUE(s.moving_average_complete);
  EXPECT_NEAR(s.moving_average_max_kN, 1000.0, 1e-6);
  EXPECT_LT(s.moving_average_std_kN, 60.0);  // the 200 -> 1000 kN step smears into the first samples
  EXPECT_NEAR(s.raw_max_kN, 1300.0, 1e-9);

  const cv::Mat png = cv::imread((dir / "plots" / "surge_ice_load.png").string());
  ASSERT_FALSE(png.empty());
  EXPECT_EQ(png.cols, 1400);
  EXPECT_EQ(png.rows, 650);
  cv::Scalar mean, sd;
  cv::meanStdDev(png, mean, sd);
  EXPECT_GT(sd[0], 10.0) << "the PNG is blank";
  const std::string svg = read_text(dir / "plots" / "surge_ice_load.svg");
  EXPECT_GT(svg.size(), 5000u);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("1000 kN"), std::string::npos) << "the legend states the mean";

  const std::string csv = read_text(dir / "plots" / "surge_ice_load.csv");
  EXPECT_EQ(csv.rfind("time_s,ice_resistance_kN,moving_average_kN\n", 0), 0u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 401);
  // The average is left empty where its window is cut (5 samples at each end for N = 10).
  std::istringstream rows(csv);
  std::string row;
  std::getline(rows, row);
  size_t empty = 0, filled = 0;
  while (std::getline(rows, row)) (row.back() == ',' ? empty : filled)++;
  EXPECT_EQ(empty, 10u);
  EXPECT_EQ(filled, 390u);

  const auto j = nlohmann::json::parse(read_text(dir / "plots" / "plot.json"));
  EXPECT_NEAR(j["mean_kN"].get<double>(), 1000.0, 1e-9);
  EXPECT_EQ(j["moving_average"]["window_samples"], 10);
  EXPECT_EQ(j["provenance"]["program"], "floesim-plot");
  // Only the artefacts are left: no working files.
  EXPECT_EQ(listing(dir / "plots"), (std::vector<std::string>{"fracture_events.csv", "plot.json",
                                                               "surge_ice_load.csv", "surge_ice_load.png",
                                                               "surge_ice_load.svg"}));
  // No fracture: no markers, and a header-only event table.
  EXPECT_EQ(svg.find("at the vessel"), std::string::npos);
  EXPECT_EQ(read_text(dir / "plots" / "fracture_events.csv"),
            "time_s,mode,parent_id,at_structure,force_x_n,force_y_n,force_z_n,threshold_n,children\n");
  fs::remove_all(dir);
}

TEST(Plot, AutoFiltersTheRigidPartOverTwentySecondsAndTheCompliantPartOverHalfASecond) {
  // PHYSICS.md §5 for a run of both laws: each part filtered over its own window, then summed. A 60 s run (1200
  // steps of 0.05 s): the compliant part a constant 300 kN, the rigid part one spike of 2000 kN every 100th step
  // (impulses of brash). A 20 s window holds exactly 4 spikes wherever it lies, so the filtered load is
  // 300 + 4 x 2000 / 400 = 320 kN at every sample of a whole window; a 0.5 s window of the whole load would show
  // the spikes as 300 + 2000 / 10 = 500 kN.
  Synthetic syn = default_synthetic();
  syn.steps = 1200;
  Results r = make_results(syn);
  r.attributes["contact_model"] = "mixed";
  std::vector<double>& load = r.series["ice_load"];
  std::vector<double>& rigid = r.series["ice_load_rigid"];
  std::vector<double>& compliant = r.series["ice_load_compliant"];
  for (size_t k = 0; k < load.size() / 6; ++k) {
    rigid[6 * k] = k % 100 == 50 ? -2000e3 : 0.0;
    compliant[6 * k] = -300e3;
    load[6 * k] = rigid[6 * k] + compliant[6 * k];
  }
  const fs::path dir = fresh_dir("plot_mixed");
  write_results(dir / "results.h5", r);
  const SurgeLoadSummary s = plot_surge_load(dir / "results.h5", write_config(dir, "{}"), dir / "a");
  EXPECT_DOUBLE_EQ(s.window_s, 20.0);
  EXPECT_TRUE(s.moving_average_complete);
  EXPECT_NEAR(s.moving_average_max_kN, 320.0, 1e-6);
  EXPECT_NEAR(s.moving_average_std_kN, 0.0, 1e-6);
  EXPECT_NE(s.filter.find("rigid part over 20 s + compliant part over 0.5 s"), std::string::npos) << s.filter;
  fs::remove_all(dir);
}

TEST(Plot, AutoWindowIsTwentySecondsForRigidOrUnknownContactsAndOptionsOverride) {
  const fs::path dir = fresh_dir("plot_auto");
  write_results(dir / "results.h5", make_results(default_synthetic()));  // no contact_model, no steady_start_s
  const SurgeLoadSummary s = plot_surge_load(dir / "results.h5", write_config(dir, "{}"), dir / "a");
  EXPECT_DOUBLE_EQ(s.window_s, 20.0);
  EXPECT_EQ(s.window_samples, 400u);
  EXPECT_FALSE(s.moving_average_complete) << "a 20 s window does not fit in a 20 s run";
  EXPECT_DOUBLE_EQ(s.steady_start_s, 0.0);
  EXPECT_EQ(s.steady_samples, 400u);
  EXPECT_NEAR(s.mean_kN, (100 * 200.0 + 300 * 1000.0) / 400.0, 1e-9);

  const SurgeLoadSummary o = plot_surge_load(
      dir / "results.h5", write_config(dir, R"({"moving_average_window_s": 1.0, "steady_start_s": 5.025})"),
      dir / "b");
  EXPECT_EQ(o.window_samples, 20u);
  EXPECT_NEAR(o.mean_kN, 1000.0, 1e-9);
  fs::remove_all(dir);
}

TEST(Plot, BadInputNamesTheProblemAndLeavesNothing) {
  const fs::path dir = fresh_dir("plot_bad");
  write_results(dir / "results.h5", make_results(default_synthetic()));
  auto expect_error = [&](const fs::path& results, const fs::path& cfg, const std::string& needle) {
    try {
      plot_surge_load(results, cfg, dir / "out");
      ADD_FAILURE() << "no error; expected one mentioning " << needle;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "out")) << "a failed run left output behind";
  };
  expect_error(dir / "missing.h5", write_config(dir, "{}"), "missing.h5");
  expect_error(dir / "results.h5", write_config(dir, R"({"window_s": 2})"), "window_s");
  expect_error(dir / "results.h5", write_config(dir, R"({"moving_average_window_s": "long"})"),
               "moving_average_window_s");
  expect_error(dir / "results.h5", write_config(dir, R"({"steady_start_s": 1e6})"), "steady");
  fs::remove_all(dir);
}

TEST(Plot, FractureEventsAtTheVesselAreMarkedAndAllEventsListed) {
  const fs::path dir = fresh_dir("plot_fracture");
  // Splitting at the vessel at 2 s, bending at the vessel at 6 s, radial at a floe-floe contact at 9 s.
  const Synthetic syn = fractured_synthetic();
  write_results(dir / "results.h5", make_results(syn));
  const SurgeLoadSummary s = plot_surge_load(dir / "results.h5", write_config(dir, "{}"), dir / "plots");
  EXPECT_EQ(s.fracture_events, 3u);
  EXPECT_EQ(s.vessel_splitting_events, 1u);
  EXPECT_EQ(s.vessel_bending_radial_events, 1u) << "the radial event between floes is not at the vessel";

  // The legend counts what is marked: one of each style (the floe-floe event is not marked).
  const std::string svg = read_text(dir / "plots" / "surge_ice_load.svg");
  EXPECT_NE(svg.find("fracture by splitting at the vessel: 1 event"), std::string::npos);
  EXPECT_NE(svg.find("fracture by bending or radial cracking at the vessel: 1 event"), std::string::npos);

  // One CSV row per event, equal to the events.
  std::istringstream rows(read_text(dir / "plots" / "fracture_events.csv"));
  std::string row;
  std::getline(rows, row);
  EXPECT_EQ(row, "time_s,mode,parent_id,at_structure,force_x_n,force_y_n,force_z_n,threshold_n,children");
  std::vector<std::string> got;
  while (std::getline(rows, row)) got.push_back(row);
  EXPECT_EQ(got, (std::vector<std::string>{"2,splitting,1,1,-1800000,200000,-10000,1700000,2 3",
                                           "6,bending,3,1,-300000,10000,-450000,420000,4",
                                           "9,radial,5,0,20000,-10000,-250000,240000,6"}));
  ASSERT_EQ(got.size(), syn.events.size());

  const auto j = nlohmann::json::parse(read_text(dir / "plots" / "plot.json"));
  EXPECT_EQ(j["fracture"]["events"], 3);
  EXPECT_EQ(j["fracture"]["at_vessel"]["splitting"], 1);
  EXPECT_EQ(j["fracture"]["at_vessel"]["bending_or_radial"], 1);
  EXPECT_NE(std::find(j["files"].begin(), j["files"].end(), "fracture_events.csv"), j["files"].end());
  fs::remove_all(dir);
}
