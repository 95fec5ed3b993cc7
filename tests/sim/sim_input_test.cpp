// Bad input gives a clear error naming the key, item or line, and the stage writes nothing.
#include <gtest/gtest.h>

#include <fstream>

#include "pipeline/error.h"
#include "sim/simulate/simulate.h"
#include "sim/engine/world.h"
#include "sim_fixtures.h"

namespace floesim::sim {
namespace {

using testing::rect_floe;
using testing::temp_dir;

using testing::expect_error;

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
  expect_error([] { options_from({{"solver", {{"method", "jacobi"}}}}); }, {"solver.method", "pgs_subspace"});
  expect_error([] { options_from({{"solver", {{"subspace_every", 0}}}}); }, {"solver.subspace_every"});
  expect_error([] { options_from({{"solver", {{"subspace_above_mps", -1}}}}); }, {"solver.subspace_above_mps"});
  expect_error([] { options_from({{"solver", {{"subspace_max_rows", 0}}}}); }, {"solver.subspace_max_rows"});
  expect_error([] { options_from({{"solver", {{"reference_sweeps", 0}}}}); }, {"solver.reference_sweeps"});
  expect_error([] { options_from({{"solver", {{"skip_settled", 1.5}}}}); }, {"solver.skip_settled"});
  expect_error([] { options_from({{"solver", {{"reference", "converged"}}}}); },
               {"solver.reference", "converged_relax", "double_cap", "reverse_order", "every_contact"});
  expect_error([] { options_from({{"solver", {{"reference_horizon_s", 5}}}}); },
               {"solver.reference_horizon_s", "double_cap", "\"off\""});
  expect_error([] { options_from({{"solver", {{"reference", "converged_relax"}, {"reference_horizon_s", 5}}}}); },
               {"solver.reference_horizon_s", "converged_relax"});
  expect_error([] { options_from({{"solver", {{"reference", "double_cap"}, {"reference_horizon_s", 0.015}}}}); },
               {"solver.reference_horizon_s", "whole number of time steps"});
  expect_error([] { options_from({{"solver", {{"reference", "double_cap"}, {"reference_horizon_s", -1}}}}); },
               {"solver.reference_horizon_s"});
  // The added-mass factors and the propellers (a list: errors name the item).
  expect_error([] { options_from({{"water", {{"floe_added_mass_scale", -1}}}}); }, {"water.floe_added_mass_scale"});
  expect_error([] { options_from({{"water", {{"floe_heave_added_mass_ratio", 1}}}}); },
               {"water.floe_heave_added_mass_ratio"});  // the old key is unknown now
  // The floe heave damping model: a choice of two, its ratio (linear) in range.
  expect_error([] { options_from({{"water", {{"floe_heave_damping", "quadratic"}}}}); },
               {"water.floe_heave_damping", "radiation", "linear"});
  expect_error([] { options_from({{"water", {{"floe_heave_damping", 0.2}}}}); }, {"water.floe_heave_damping"});
  expect_error([] { options_from({{"water", {{"floe_heave_damping", "linear"}, {"floe_heave_damping_ratio", 3}}}}); },
               {"water.floe_heave_damping_ratio"});
  expect_error([] { options_from({{"water", {{"floe_heave_radiation", "on"}}}}); }, {"water.floe_heave_radiation"});
  EXPECT_EQ(options_from({{"duration_s", 30}}).water.floe_heave_damping, "radiation");
  expect_error([] { options_from({{"vessel", {{"heave_pitch_added_mass_scale", 9}}}}); },
               {"vessel.heave_pitch_added_mass_scale"});
  expect_error([] { options_from({{"vessel", {{"propellers", {{{"position_m", {1, 2}}}}}}}}); },
               {"vessel.propellers[0].position_m", "[x, y, z]"});
  expect_error([] { options_from({{"vessel", {{"propellers", {{{"position_m", {-40, 0, 2}}}}}}}}); },
               {"vessel.propellers[0].position_m", "below the waterline"});
  expect_error(
      [] {
        options_from({{"vessel",
                       {{"propellers", {{{"position_m", {-40, 5, -5}}, {"diameter_m", 4}},
                                        {{"position_m", {-40, -5, -5}}, {"diametr_m", 4}}}}}}});
      },
      {"vessel.propellers[1].diametr_m"});
  expect_error(
      [] {
        options_from({{"vessel",
                       {{"propellers", {{{"position_m", {-40, 5, -5}}, {"thrust_share", 0.7}},
                                        {{"position_m", {-40, -5, -5}}, {"thrust_share", 0.7}}}}}}});
      },
      {"vessel.propellers", "adds up to 1.4"});
  expect_error([] { options_from({{"vessel", {{"propellers", {{{"position_m", {-40, 0, -5}}, {"axis", {0, 0, 0}}}}}}}}); },
               {"vessel.propellers[0].axis", "non-zero"});
  expect_error([] { options_from({{"vessel", {{"propellers", 3}}}}); }, {"vessel.propellers", "array of objects"});
  const SimulateOptions two = options_from(
      {{"vessel", {{"propellers", {{{"position_m", {-47, 6, -5.5}}}, {{"position_m", {-47, -6, -5.5}}}}}}}});
  ASSERT_EQ(two.vessel.propellers.size(), 2u);
  EXPECT_EQ(two.vessel.propellers[1].position_m[1], -6.0);
  EXPECT_EQ(two.vessel.propellers[1].diameter_m, 4.0);  // the item's default
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


// Each bad input of issue #4 through the stage itself: a clear error naming the file and the item, and no
// results.h5 or summary.json written.
TEST(SimInput, BadInputsNameFileAndItemAndWriteNothing) {
  const auto dir = temp_dir("bad_inputs");
  HullGeneratorOptions g;
  g.sections = 6;
  write_obj(dir / "hull.obj", generate_hull(g), "test hull");
  FloeField good;
  good.floes = {rect_floe(1, 100, 0, 10, 10, 1.0)};
  write_floes(dir / "floes.geojson", good);
  std::ofstream(dir / "sim.json") << R"({"duration_s": 1.0, "steady_start_s": 0.5})";
  auto run = [&](const std::string& floes, const std::string& hull, const std::string& cfg,
                 std::initializer_list<const char*> pieces) {
    std::filesystem::remove_all(dir / "out");
    expect_error([&] { run_simulate(dir / floes, dir / hull, dir / cfg, dir / "out"); }, pieces);
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "results.h5"));
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "summary.json"));
  };
  // A hull that is not closed (a box missing its lid).
  std::ofstream(dir / "open.obj") << "o box\nv 0 0 -1\nv 1 0 -1\nv 1 1 -1\nv 0 1 -1\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                     "f 1 3 2\nf 1 4 3\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\n"
                                     "f 4 1 5\nf 4 5 8\n";
  run("floes.geojson", "open.obj", "sim.json", {"open.obj", "not closed"});
  // A closed hull lying entirely above the water (keel at z = 0, as some CAD exports): refused, naming the fix.
  std::ofstream(dir / "dry.obj") << "o box\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                                    "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\n"
                                    "f 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n";
  run("floes.geojson", "dry.obj", "sim.json", {"dry.obj", "above the water", "waterline_z_m"});
  // A floe polygon that intersects itself (a bow tie), in the file: named by file and feature.
  std::ofstream(dir / "bowtie.geojson")
      << R"({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"id": 3, "thickness_m": 1},
           "geometry": {"type": "Polygon", "coordinates": [[[100, 0], [110, 10], [110, 0], [100, 10], [100, 0]]]}}]})";
  run("bowtie.geojson", "hull.obj", "sim.json", {"bowtie.geojson", "intersects itself"});
  // Two floes overlapping each other.
  FloeField overlap;
  overlap.floes = {rect_floe(1, 100, 0, 10, 10, 1.0), rect_floe(2, 105, 5, 10, 10, 1.0)};
  write_floes(dir / "overlap.geojson", overlap);
  run("overlap.geojson", "hull.obj", "sim.json", {"floes 1 and 2 overlap"});
  // A negative thickness in the file.
  std::ofstream(dir / "thin.geojson")
      << R"({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"id": 5, "thickness_m": -1},
           "geometry": {"type": "Polygon", "coordinates": [[[100, 0], [110, 0], [110, 10], [100, 10], [100, 0]]]}}]})";
  run("thin.geojson", "hull.obj", "sim.json", {"thin.geojson", "thickness_m"});
  // A negative strength, an unknown key (with the file name).
  std::ofstream(dir / "strength.json") << R"({"duration_s": 1.0, "steady_start_s": 0.5,
                                              "ice": {"crushing_strength_pa": -2e6}})";
  run("floes.geojson", "hull.obj", "strength.json", {"strength.json", "ice.crushing_strength_pa", "> 0"});
  std::ofstream(dir / "unknown.json") << R"({"duration_s": 1.0, "steady_start_s": 0.5, "water": {"curent_speed_mps": 1}})";
  run("floes.geojson", "hull.obj", "unknown.json", {"unknown.json", "water.curent_speed_mps"});
  // Fracture options (issue #7): a wedge angle range outside (0, 180) deg, a zero toughness, a negative piece size.
  std::ofstream(dir / "theta.json") << R"({"duration_s": 1.0, "steady_start_s": 0.5,
                                           "fracture": {"wedge_angle_deg": [30, 200]}})";
  run("floes.geojson", "hull.obj", "theta.json", {"theta.json", "fracture.wedge_angle_deg", "(0, 180)"});
  std::ofstream(dir / "kic.json") << R"({"duration_s": 1.0, "steady_start_s": 0.5,
                                         "fracture": {"fracture_toughness_pa_sqrtm": 0}})";
  run("floes.geojson", "hull.obj", "kic.json", {"kic.json", "fracture.fracture_toughness_pa_sqrtm", "> 0"});
  std::ofstream(dir / "piece.json") << R"({"duration_s": 1.0, "steady_start_s": 0.5,
                                           "fracture": {"min_piece_area_m2": -1}})";
  run("floes.geojson", "hull.obj", "piece.json", {"piece.json", "fracture.min_piece_area_m2"});
  // Ridges (issue #36): a keel shallower than its consolidated layer, a porosity outside (0, 1), blocks larger than
  // the keel, an unknown key, a ridge off its sheet's edge: each named by file and ridge.
  auto ridge_case = [&](const std::string& ridge, std::initializer_list<const char*> pieces) {
    std::ofstream(dir / "ridge.json")
        << R"({"duration_s": 1.0, "steady_start_s": 0.5, "level_ice": {"extent_m": [200, -40, 280, 40],
              "tile_m": 40}, "ridges": [{"line": [{"x_m": 240, "y_m": -30}, {"x_m": 240, "y_m": 30}], )"
        << ridge << "}]}";
    run("floes.geojson", "hull.obj", "ridge.json", pieces);
  };
  ridge_case(R"("keel_depth_m": 0.5, "consolidated_thickness_m": 1.0)", {"ridges[0]", "keel_depth_m", "layer"});
  ridge_case(R"("porosity": 1.2)", {"ridge.json", "ridges[0].porosity", "(0, 1)"});
  ridge_case(R"("block_size_m": [1, 30])", {"ridges[0]", "block_size_m", "smaller"});
  ridge_case(R"("keel_draught_m": 6)", {"ridge.json", "ridges[0].keel_draught_m"});
  std::ofstream(dir / "ridge.json")
      << R"({"duration_s": 1.0, "steady_start_s": 0.5, "level_ice": {"extent_m": [200, -40, 280, 40], "tile_m": 40},
            "ridges": [{"line": [{"x_m": 240, "y_m": -30}, {"x_m": 240, "y_m": 60}]}]})";
  run("floes.geojson", "hull.obj", "ridge.json", {"ridges[0]", "segment 0", "sheet"});
  std::ofstream(dir / "ridge.json") << R"({"duration_s": 1.0, "steady_start_s": 0.5,
                                           "ridge_field": {"density_per_km": 5, "keel_depth_mean_m": 2}})";
  run("floes.geojson", "hull.obj", "ridge.json", {"ridge.json", "ridge_field.keel_depth_mean_m", "keel_depth_min_m"});
  // A thrust series with a gap (an empty line, a missing value) or with time going back.
  auto thrust_case = [&](const std::string& csv, std::initializer_list<const char*> pieces) {
    std::ofstream(dir / "thrust.csv") << csv;
    std::ofstream(dir / "thrust.json")
        << R"({"duration_s": 1.0, "steady_start_s": 0.5, "vessel": {"propulsion": {"mode": "thrust_series",
              "thrust_file": "thrust.csv"}}})";
    run("floes.geojson", "hull.obj", "thrust.json", pieces);
  };
  thrust_case("time_s,thrust_N\n0,1e5\n\n2,1e5\n", {"thrust.csv:3", "empty line"});
  thrust_case("time_s,thrust_N\n0,1e5\n1,\n2,1e5\n", {"thrust.csv:3", "thrust_N"});
  thrust_case("time_s,thrust_N\n0,1e5\n2,1e5\n1,1e5\n", {"thrust.csv:4", "increase strictly"});
  std::filesystem::remove_all(dir);
}

// A simulation that goes unstable stops with a diagnosis naming the step and the body: a non-finite state (NaN) of
// a free body, or of a body in contact (which the contact solver spreads to its partner), stops the step that
// produced it. (Blow-ups that stay finite are stopped by the health limits: SimVessel.HealthStopWritesNothing.)
TEST(SimInput, NumericalFailureIsDiagnosed) {
  SimulateOptions o = testing::floe_options();
  FloeField field;
  field.floes = {rect_floe(1, 0, 0, 10, 10, 1.0), rect_floe(2, 30, 0, 5, 5, 1.0)};
  const Model m = build_model(field, nullptr, o);
  {
    World w(m);
    w.mutable_state().velocity[1] = Vec3(std::nan(""), 0, 0);
    expect_error([&] { w.step(); }, {"numerical failure at step 1", "floe id 2", "not finite"});
  }
  {
    // Two floes pressed together, one with a NaN velocity: the contact solver's residual is NaN.
    FloeField touching;
    touching.floes = {rect_floe(1, 0, 0, 10, 10, 1.0), rect_floe(2, 10, 0, 5, 5, 1.0)};
    const Model mt = build_model(touching, nullptr, o);
    World w(mt);
    w.mutable_state().velocity[0] = Vec3(0.1, 0, 0);
    w.step();
    ASSERT_GT(w.contacts().size(), 0u);
    w.mutable_state().velocity[1] = Vec3(std::nan(""), 0, 0);
    expect_error([&] { w.step(); }, {"numerical failure at step 2", "floe id", "not finite"});
  }
}

}  // namespace
}  // namespace floesim::sim
