#include <gtest/gtest.h>

#include <filesystem>
#include <algorithm>
#include <fstream>

#include "pipeline/error.h"
#include "pipeline/runner/plan.h"
#include "pipeline/runner/sweep.h"
#include "pipeline/sweep/sweep_plan.h"

using namespace floesim;
namespace fs = std::filesystem;

namespace {
std::string plan_error(const nlohmann::json& c, const fs::path& dir) {
  runner::StageLayout layout;
  layout.dir = [](const std::string& s, const std::string&) { return fs::path("/run") / s; };
  layout.config = [](const std::string& s, const std::string&) { return fs::path("/run/config") / (s + ".json"); };
  try {
    runner::plan_case(c, "case.json", dir, "/bin", layout);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

// A case's own file must be a file: a folder was hashed as if it were empty and a device (/dev/zero) read forever
// (tests/fuzz/fuzz_case).
TEST(Plan, CaseFilesMustBeRegularFiles) {
  const fs::path dir = fs::temp_directory_path() / "floesim_plan_test";
  fs::create_directories(dir);
  for (const char* name : {".", "", "/dev/zero"}) {
    const std::string e = plan_error({{"floes", {{"file", name}}}}, dir);
    EXPECT_NE(e.find("floes.file names"), std::string::npos) << name << ": " << e;
    EXPECT_NE(e.find("which is not a file"), std::string::npos) << name << ": " << e;
  }
  std::ofstream(dir / "floes.geojson") << "{}";
  std::ofstream(dir / "hull.obj") << "";
  EXPECT_EQ(plan_error({{"floes", {{"file", "floes.geojson"}}}, {"hull", {{"file", "hull.obj"}}}}, dir), "");
  fs::remove_all(dir);
}

// A case's structures: each gets a hull stage of its own and its options, with that stage's mesh, in the simulate
// stage's structures; a structure without a name or hull, or with a hull_file of its own, is named.
TEST(Plan, EachStructureGetsItsHullStageAndItsSimulateEntry) {
  const fs::path dir = fs::temp_directory_path() / "floesim_plan_structures";
  fs::create_directories(dir);
  std::ofstream(dir / "floes.geojson") << "{}";
  const nlohmann::json cone = {{"structure", {{"shape", "cone"}}}};
  nlohmann::json c = {{"floes", {{"file", "floes.geojson"}}},
                      {"hull", {{"generate", nlohmann::json::object()}}},
                      {"structures", {{{"name", "pier"}, {"hull", cone}, {"x_m", 50.0},
                                       {"station_keeping", {{"mode", "fixed"}}}}}}};
  runner::StageLayout layout;
  layout.dir = [](const std::string& s, const std::string&) { return fs::path("/run") / s; };
  layout.config = [](const std::string& s, const std::string&) { return fs::path("/run/config") / (s + ".json"); };
  const runner::CasePlan p = runner::plan_case(c, "case.json", dir, "/bin", layout);
  const runner::PlannedStage* hull = nullptr;
  const runner::PlannedStage* sim = nullptr;
  for (const runner::PlannedStage& s : p.stages) {
    if (s.name == "structure-pier") hull = &s;
    if (s.name == "simulate") sim = &s;
  }
  ASSERT_TRUE(hull && sim);
  EXPECT_EQ(hull->outputs.at(0), fs::path("/run/structure-pier/hull.obj"));
  const nlohmann::json settings = nlohmann::json::parse(sim->config_text);
  EXPECT_EQ(settings["structures"][0]["hull_file"], "/run/structure-pier/hull.obj");
  EXPECT_EQ(settings["structures"][0]["x_m"], 50.0);
  EXPECT_FALSE(settings["structures"][0].contains("hull"));
  EXPECT_NE(std::find(sim->inputs.begin(), sim->inputs.end(), hull->outputs[0]), sim->inputs.end());

  c["structures"][0].erase("hull");
  EXPECT_NE(plan_error(c, dir).find("structures[0] needs \"name\" (a string) and \"hull\""), std::string::npos);
  c["structures"][0]["hull"] = cone;
  c["structures"][0]["hull_file"] = "x.obj";
  EXPECT_NE(plan_error(c, dir).find("structures[0].hull_file is set by the runner"), std::string::npos);
  c["structures"][0].erase("hull_file");
  c["structures"][0]["name"] = "a/b";
  EXPECT_NE(plan_error(c, dir).find("structures[0].name \"a/b\" may hold only"), std::string::npos);
  fs::remove_all(dir);
}

// A sweep's key path reaches into a list the case has by an element's index (simulate.ridges.0.keel_depth_m); an
// index the list does not have is named with the list's length.
TEST(Plan, SweepKeyPathsReachListElementsByIndex) {
  nlohmann::json c = {{"simulate", {{"ridges", {{{"keel_depth_m", 5.0}}, {{"keel_depth_m", 6.0}}}}}}};
  runner::set_key_path(c, "simulate.ridges.1.keel_depth_m", 7.0, "sweep.json");
  EXPECT_EQ(c["simulate"]["ridges"][1]["keel_depth_m"], 7.0);
  EXPECT_EQ(c["simulate"]["ridges"][0]["keel_depth_m"], 5.0);
  std::string error;
  try {
    runner::set_key_path(c, "simulate.ridges.2.keel_depth_m", 7.0, "sweep.json");
  } catch (const Error& e) {
    error = e.what();
  }
  EXPECT_NE(error.find("simulate.ridges is a list of 2"), std::string::npos) << error;
  EXPECT_NE(error.find("sweep.json"), std::string::npos) << error;
}

// A sweep axis is named for a reader from its option's unit and meaning (the stage's --describe-config), after the
// sections it is in; a list index is the item's number from 1.
TEST(SweepAxis, ALabelIsTheOptionsMeaningWithItsSectionsAndUnit) {
  EXPECT_EQ(sweep::axis_label("level_ice.thickness_m", "m", "thickness of the sheet (when thickness_profile is empty)"),
            "level ice: thickness of the sheet (m)");
  EXPECT_EQ(sweep::axis_label("ridges.0.keel_depth_m", "m", "keel draft: its deepest point below the waterline"),
            "ridge 1: keel draft (m)");
  EXPECT_EQ(sweep::axis_label("vessel.propulsion.speed_mps", "m/s", "speed: prescribed forward speed through the water"),
            "vessel propulsion: prescribed forward speed through the water (m/s)");
  EXPECT_EQ(sweep::axis_label("concentration", "-", "target floe area / image area"), "target floe area / image area");
  // Without a description (a key of the case itself): the key's words.
  EXPECT_EQ(sweep::axis_label("image.metres_per_pixel", "", ""), "image: metres per pixel");
  EXPECT_EQ(sweep::axis_label("duration_s", "s", ""), "duration (s)");
  EXPECT_EQ(sweep::list_item_path("ridges.0.keel_depth_m"), "ridges[].keel_depth_m");
  EXPECT_EQ(sweep::list_item_path("vessel.propellers.12.diameter_m"), "vessel.propellers[].diameter_m");
  EXPECT_EQ(sweep::list_item_path("level_ice.thickness_m"), "level_ice.thickness_m");
}
