// Bad input gives a clear error naming the key, item or line, and the stage writes nothing.
#include <gtest/gtest.h>

#include <fstream>

#include "pipeline/error.h"
#include "sim/simulate.h"
#include "sim_fixtures.h"

namespace floesim::sim {
namespace {

using testing::rect_floe;
using testing::temp_dir;

// Runs f, expects floesim::Error whose message contains every piece.
template <class F>
void expect_error(F f, std::initializer_list<const char*> pieces) {
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const char* p : pieces) EXPECT_NE(msg.find(p), std::string::npos) << "missing '" << p << "' in: " << msg;
  }
}

SimulateOptions options_from(const nlohmann::json& j) { return read_options<SimulateOptions>(j, "sim.json"); }

TEST(SimInput, OptionErrorsNameTheKey) {
  expect_error([] { options_from({{"duration_s", 10}, {"tme_step_s", 0.01}}); }, {"sim.json", "tme_step_s"});
  expect_error([] { options_from({{"ice", {{"density_kg_m3", -900}}}}); }, {"ice.density_kg_m3", "> 0"});
  expect_error([] { options_from({{"water", {{"density_kg_m3", -1}}}}); }, {"water.density_kg_m3"});
  expect_error([] { options_from({{"duration_s", 10.005}, {"time_step_s", 0.01}}); },
               {"duration_s", "whole number of time steps"});
  expect_error([] { options_from({{"duration_s", 30}, {"output_interval_s", 0.005}}); },
               {"output_interval_s", ">= time_step_s"});
  expect_error([] { options_from({{"vessel", {{"propulsion", {{"mode", "oars"}}}}}}); },
               {"vessel.propulsion.mode", "speed"});
  expect_error([] { options_from({{"vessel", {{"propulsion", {{"mode", "thrust_series"}}}}}}); },
               {"vessel.propulsion.thrust_file"});
  const SimulateOptions ok = options_from({{"duration_s", 30}});
  EXPECT_EQ(ok.steps(), 3000);
  EXPECT_EQ(ok.output_every(), 20);
}

TEST(SimInput, FloeErrorsNameTheFloes) {
  SimulateOptions o;
  FloeField thin;
  thin.floes = {rect_floe(7, 0, 0, 5, 5, -1.0)};
  expect_error([&] { build_model(thin, nullptr, o); }, {"floe 7", "thickness_m"});
  FloeField overlap;
  overlap.floes = {rect_floe(3, 0, 0, 10, 10, 1.0), rect_floe(5, 20, 0, 5, 5, 1.0), rect_floe(4, 8, 8, 5, 5, 1.0)};
  expect_error([&] { build_model(overlap, nullptr, o); }, {"floes 3 and 4 overlap", "4 m^2"});
  // Touching floes are fine.
  FloeField touching;
  touching.floes = {rect_floe(1, 0, 0, 10, 10, 1.0), rect_floe(2, 10, 0, 5, 5, 1.0)};
  EXPECT_EQ(build_model(touching, nullptr, o).floe_count(), 2);
}

TEST(SimInput, ThrustSeriesErrorsNameTheLine) {
  const auto dir = temp_dir("thrust");
  std::vector<double> t, f;
  auto write = [&](const std::string& text) {
    std::ofstream(dir / "thrust.csv") << text;
    return (dir / "thrust.csv").string();
  };
  read_thrust_series(write("time_s,thrust_N\n0,1e5\n10,2e5\n"), t, f);
  EXPECT_EQ(t.size(), 2u);
  expect_error([&] { read_thrust_series(write("time_s,thrust_N\n0,1e5\n10,2e5\n5,3e5\n"), t, f); },
               {"thrust.csv:4", "increase strictly"});
  expect_error([&] { read_thrust_series(write("time_s,thrust_N\n0,1e5\n1,nan\n"), t, f); },
               {"thrust.csv:3", "thrust_N"});
  expect_error([&] { read_thrust_series(write("time_s,thrust_N\n0,1e5\n\n2,1e5\n"), t, f); },
               {"thrust.csv:3", "empty line"});
  expect_error([&] { read_thrust_series(write("t,F\n0,1\n"), t, f); }, {"thrust.csv:1", "header"});
}

TEST(SimInput, StageWritesNothingOnError) {
  const auto dir = temp_dir("nothing_written");
  FloeField field;
  field.floes = {rect_floe(1, 100, 0, 10, 10, 1.0), rect_floe(2, 105, 5, 10, 10, 1.0)};  // overlapping
  write_floes(dir / "floes.geojson", field);
  HullGeneratorOptions g;
  g.sections = 6;
  write_obj(dir / "hull.obj", generate_hull(g), "test hull");
  std::ofstream(dir / "sim.json") << R"({"duration_s": 1.0, "steady_start_s": 0.5})";
  expect_error([&] { run_simulate(dir / "floes.geojson", dir / "hull.obj", dir / "sim.json", dir / "out"); },
               {"floes 1 and 2 overlap"});
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "results.h5"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "summary.json"));
  std::ofstream(dir / "sim.json") << R"({"duration_s": 1.0, "steady_start_s": 0.5, "solver": {"iteratons": 5}})";
  expect_error([&] { run_simulate(dir / "floes.geojson", dir / "hull.obj", dir / "sim.json", dir / "out"); },
               {"solver.iteratons"});
}

}  // namespace
}  // namespace floesim::sim
