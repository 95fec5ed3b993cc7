// Level ice (issue #10): a sheet as fixed tiles that only fracture breaks. The tiling against areas and counts
// worked out by hand, a sheet at rest costing nothing, the ramp of the fracture tests breaking a sheet at PHYSICS.md
// §2.1's table load (read by hand here, as in sim_fracture_test.cpp), ice mass conserved, byte-identical reruns,
// bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"
#include "pipeline/options.h"
#include "pipeline/results_io.h"
#include "sim/simulate/simulate.h"
#include "sim_fixtures.h"

namespace floesim::sim {
namespace {

using testing::coarse_hull;
using testing::lc_by_hand;
using testing::ramp_hull;
using testing::table_pf;

std::vector<int> tiles_of(const Model& m) {
  std::vector<int> t;
  for (size_t b = 0; b < m.bodies.size(); ++b)
    if (m.bodies[b].fixed) t.push_back(static_cast<int>(b));
  return t;
}

TEST(LevelIce, SheetIsTiledAroundItsOpeningsWithTheThicknessProfile) {
  SimulateOptions o = testing::floe_options();
  o.level_ice.extent_m = {0, -60, 200, 60};
  o.level_ice.tile_m = 50;
  o.level_ice.openings = {LevelIceOpening{{0, -10, 30, 10}}};
  o.level_ice.thickness_profile = {ThicknessPoint{0, 0.5}, ThicknessPoint{200, 1.5}};
  const Model m = build_model(FloeField{}, nullptr, o);
  const std::vector<int> tiles = tiles_of(m);
  // Grid centred on the sheet: x lines at 25, 75, 125, 175 and the opening's side at 30 (6 columns), y lines at
  // -25, 25 and the opening's sides at -10, 10 (5 rows); the opening takes the two cells in [0, 30] x [-10, 10].
  EXPECT_EQ(tiles.size(), 6u * 5u - 2u);
  EXPECT_EQ(static_cast<int>(tiles.size()), m.floe_count());
  double area = 0, mass = 0, mass_by_hand = 0;
  for (int b : tiles) {
    const Body& t = m.bodies[b];
    area += t.section_area;
    mass += t.mass_kg;
    EXPECT_EQ(t.inv_mass, 0);
    EXPECT_TRUE(t.inv_mass_added.isZero(0));
    EXPECT_TRUE(t.inv_inertia_added.isZero(0));
    // Thickness at the tile's centre, linear from 0.5 m at x = 0 to 1.5 m at x = 200.
    const double h = 0.5 + t.initial_position.x() / 200.0;
    EXPECT_NEAR(t.thickness_m, h, 1e-12);
    mass_by_hand += 900.0 * t.section_area * h;
    Vec2 lo = t.outline[0], hi = t.outline[0];
    for (const Vec2& p : t.outline) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    EXPECT_LE(hi.x() - lo.x(), 50 + 1e-9);
    EXPECT_LE(hi.y() - lo.y(), 50 + 1e-9);
  }
  EXPECT_NEAR(area, 200.0 * 120.0 - 30.0 * 20.0, 1e-6);
  EXPECT_NEAR(mass, mass_by_hand, 1e-6 * mass);
  // Ids follow the floes file's (none here): 1, 2, ...
  EXPECT_EQ(m.bodies[tiles.front()].id, 1);
}

TEST(LevelIce, SheetFromTheFloesFileIsTiledBesideItsFloes) {
  // A floes file with one floe and one level ice polygon (an L shape), both 0.8 m thick.
  FloeField f;
  f.floes.push_back(testing::rect_floe(7, -30, 0, 20, 20, 0.8));
  Floe sheet;
  sheet.id = 3;
  sheet.outline = {Vec2(0, 0), Vec2(120, 0), Vec2(120, 40), Vec2(60, 40), Vec2(60, 100), Vec2(0, 100)};
  sheet.thickness_m = 0.8;
  sheet.level_ice = true;
  f.floes.push_back(sheet);
  SimulateOptions o = testing::floe_options();
  o.level_ice.tile_m = 40;
  const Model m = build_model(f, nullptr, o);
  const std::vector<int> tiles = tiles_of(m);
  double area = 0;
  for (int b : tiles) {
    area += m.bodies[b].section_area;
    EXPECT_EQ(m.bodies[b].thickness_m, 0.8);
    EXPECT_GT(m.bodies[b].id, 7);  // after the file's largest id
  }
  EXPECT_NEAR(area, 120.0 * 40.0 + 60.0 * 60.0, 1e-6);
  EXPECT_EQ(m.floe_count(), static_cast<int>(tiles.size()) + 1);
  // The floe stays a free floe.
  EXPECT_FALSE(m.bodies[0].fixed);
  EXPECT_EQ(m.bodies[0].id, 7);
}

TEST(LevelIce, SheetAtRestCostsNothingAndNeverMoves) {
  SimulateOptions o = testing::floe_options();
  o.sleep.enabled = true;
  o.level_ice.extent_m = {0, -100, 300, 100};
  const Model m = build_model(FloeField{}, nullptr, o);
  World w(m);
  for (int k = 0; k < 200; ++k) w.step();
  EXPECT_EQ(w.report().awake_floes, 0);
  EXPECT_EQ(w.report().contacts, 0);
  for (int b : tiles_of(m)) {
    EXPECT_EQ(w.state().position[b], m.bodies[b].initial_position);  // bit for bit
    EXPECT_EQ(w.state().awake[b], 0);
  }
}

TEST(LevelIce, RampBreaksTheSheetAtTheTableLoadAndTheSheetStaysPut) {
  // The fracture tests' ramp (a 30 deg face 0.2 l_c wide) driven at 0.1 m/s into the edge of a sheet: one tile of
  // 200 m x 200 m (tile_m larger than the sheet).
  const double h = 1.0, lc = lc_by_hand(h), w = 0.2 * lc;
  SimulateOptions o = testing::ramp_options();
  o.level_ice.extent_m = {-0.4, -100, 199.6, 100};
  o.level_ice.tile_m = 250;
  o.level_ice.thickness_m = h;
  const HullModel hull = ramp_hull(30, w);
  const Model model = build_model(FloeField{}, &hull, o);
  ASSERT_EQ(tiles_of(model).size(), 1u);
  const int tile = tiles_of(model)[0];
  World world(model);
  for (int k = 0; k < 3000 && world.fracture_events().empty(); ++k) {
    world.step();
    ASSERT_EQ(world.state().position[tile], model.bodies[tile].initial_position) << "the sheet moved at step " << k;
    // Only the sheet is touched: its part of the vessel's ice load is the whole of it.
    ASSERT_EQ(world.report().ice_load_level_ice.force, world.report().ice_load.force) << "step " << k;
  }
  ASSERT_EQ(world.fracture_events().size(), 1u) << "no fracture in 30 s";
  const FractureEvent& e = world.fracture_events()[0];
  EXPECT_EQ(e.mode, kFractureBending);
  const double theta = kPi / 3, alpha = e.width_m / (theta * lc);
  const double fail = std::max(table_pf(alpha) * theta * 5e5 * h * h, 0.226 * 5e5 * h * h);
  EXPECT_NEAR(e.width_m, w, 0.02 * w);
  const double fv = -e.force_n.z();  // the sheet is level: its frame is the world's
  EXPECT_GE(fv, 0.99 * fail);
  EXPECT_LE(fv, 1.05 * fail);
  // The wedge is a free floe, what the tile keeps is still fixed sheet; no ice made or lost.
  const Model& wm = world.model();
  double children = e.brash_mass_kg;
  int free_pieces = 0, sheet_pieces = 0;
  for (int id : e.child_ids)
    for (const Body& b : wm.bodies)
      if (b.id == id) {
        children += b.mass_kg;
        (b.fixed ? sheet_pieces : free_pieces) += 1;
        if (!b.fixed) {
          EXPECT_LT(b.section_area, 0.01 * model.bodies[tile].section_area);
        }
      }
  EXPECT_EQ(free_pieces, 1);
  EXPECT_GE(sheet_pieces, 1);
  EXPECT_NEAR(children, model.bodies[tile].mass_kg, 1e-9 * model.bodies[tile].mass_kg);
  EXPECT_EQ(world.state().alive[tile], 0);
}

TEST(LevelIce, TransitIsByteIdenticalOnRerunAndAcrossThreads) {
  const auto dir = testing::temp_dir("level_ice_determinism");
  SimulateOptions o = testing::level_ice_transit_options();
  const HullModel hull = coarse_hull();
  std::vector<std::string> bytes;
  for (int threads : {1, 1, 2}) {
    o.threads = threads;
    const Model model = build_model(FloeField{}, &hull, o);
    RunStats stats;
    const Results r = simulate(o, model, stats);
    EXPECT_GT(r.fracture_time_s.size(), 0u);
    const auto file = dir / ("r" + std::to_string(bytes.size()) + ".h5");
    write_results(file, r);
    // The layout records the sheet: read back, the tiles are flagged.
    const Results back = read_results(file);
    int sheet = 0;
    for (int8_t x : back.floe_level_ice) sheet += x;
    EXPECT_GE(sheet, 9);
    std::ifstream in(file, std::ios::binary);
    bytes.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  EXPECT_EQ(bytes[0], bytes[1]);
  EXPECT_EQ(bytes[0], bytes[2]);
}

TEST(LevelIce, ChannelWidthIsTheSheetAreaLostBehindMidshipOverItsLength) {
  // A 100 m x 100 m sheet (one tile) ahead of the coarse hull (start x = -60, heading +x); at the end the vessel's
  // centre is at x = 80 and the tile left is the sheet with a channel 20 m wide cut from x = 0 to x = 90 (ahead of
  // the window's end, as the bow reaches past midship). By hand: the window runs from the sheet's edge (x = 0) to
  // x = 80, the area lost there is 80 x 20 m^2, the mean width 20 m.
  SimulateOptions o = testing::floe_options();
  o.vessel.x_m = -60;
  o.level_ice.extent_m = {0, -50, 100, 50};
  o.level_ice.tile_m = 200;
  const HullModel hull = coarse_hull();
  const Model m = build_model(FloeField{}, &hull, o);
  ASSERT_EQ(tiles_of(m).size(), 1u);
  const Polygon left = {Vec2(0, -50), Vec2(100, -50), Vec2(100, 50), Vec2(0, 50),
                        Vec2(0, 10),  Vec2(90, 10),   Vec2(90, -10), Vec2(0, -10)};
  const Vec2 c = centroid(left);
  Results r;
  r.frame_time_s = {10.0};
  r.frame_offset = {0, 2};
  r.state_body_id = {0, 99};
  r.state_position_m = {80, 0, 0, c.x(), c.y(), 0};
  r.state_quaternion = {1, 0, 0, 0, 1, 0, 0, 0};
  r.state_in_contact = {0, 0};
  r.floe_id = {1, 99};
  r.floe_level_ice = {1, 1};
  r.floe_vertex_offset = {0, 4};
  for (const Vec2& p : m.bodies[tiles_of(m)[0]].outline)
    r.floe_vertices_m.insert(r.floe_vertices_m.end(), {p.x(), p.y()});
  for (const Vec2& p : left) r.floe_vertices_m.insert(r.floe_vertices_m.end(), {p.x() - c.x(), p.y() - c.y()});
  r.floe_vertex_offset.push_back(static_cast<int64_t>(r.floe_vertices_m.size() / 2));
  const Json j = level_ice_summary(o, m, r);
  EXPECT_EQ(j["tiles_start"], 1);
  EXPECT_NEAR(j["sheet_area_start_m2"].get<double>(), 1e4, 1e-6);
  const Json& ch = j["channel"];
  EXPECT_NEAR(ch["from_m"].get<double>(), 60.0, 1e-9);  // along the track from the vessel's start
  EXPECT_NEAR(ch["to_m"].get<double>(), 140.0, 1e-9);
  EXPECT_NEAR(ch["broken_area_m2"].get<double>(), 1600.0, 1e-6);
  EXPECT_NEAR(ch["mean_width_m"].get<double>(), 20.0, 1e-9);
  EXPECT_NEAR(ch["width_over_beam"].get<double>(), 20.0 / m.vessel_info.beam_wl_m, 1e-12);
}

TEST(LevelIce, FloesFarAsternSleepAtAnySpeed) {
  // sleep.freeze_astern_m = 150: of three floes drifting at 0.5 m/s, the one 300 m astern of the vessel falls asleep
  // after one step, the ones 100 m astern and 300 m ahead keep moving.
  SimulateOptions o = testing::floe_options();
  o.sleep.enabled = true;
  o.sleep.freeze_astern_m = 150;
  o.vessel.x_m = 0;
  FloeField f;
  f.floes = {testing::rect_floe(1, -310, 40, 20, 20, 1.0), testing::rect_floe(2, -110, 40, 20, 20, 1.0),
             testing::rect_floe(3, 290, 40, 20, 20, 1.0)};
  const HullModel hull = coarse_hull();
  const Model m = build_model(f, &hull, o);
  World w(m);
  for (int b = 1; b <= 3; ++b) {
    w.wake(b);
    w.mutable_state().velocity[b] = Vec3(0, 0.5, 0);
  }
  w.step();
  EXPECT_EQ(w.state().awake[1], 0);
  EXPECT_EQ(w.state().velocity[1], Vec3::Zero());
  EXPECT_EQ(w.state().awake[2], 1);
  EXPECT_EQ(w.state().awake[3], 1);
  EXPECT_GT(w.state().velocity[2].y(), 0.4);
}

TEST(LevelIce, BadInputNamesTheKeyAndTheFix) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"({"level_ice": {"extent_m": [0, 0, 100]}})", "level_ice.extent_m"},
      {R"({"level_ice": {"extent_m": [0, 0, -100, 50]}})", "level_ice.extent_m"},
      {R"({"level_ice": {"extent_m": [0, 0, 1e12, 50]}})", "level_ice.extent_m"},
      {R"({"vessel": {"x_m": 2e7}})", "vessel.x_m"},
      {R"({"domain": {"extent_m": [-1e300, 0, 100, 50]}})", "domain.extent_m"},
      {R"({"level_ice": {"thickness_m": 0}})", "level_ice.thickness_m"},
      {R"({"level_ice": {"tile_m": 0}})", "level_ice.tile_m"},
      {R"({"level_ice": {"openings": [{"rect_m": [5, 5, 1, 1]}]}})", "level_ice.openings[0].rect_m"},
      {R"({"level_ice": {"openings": [{"rect": [0, 0, 1, 1]}]}})", "rect"},
      {R"({"level_ice": {"thickness_profile": [{"x_m": 10, "thickness_m": 1}, {"x_m": 5, "thickness_m": 1}]}})",
       "level_ice.thickness_profile"},
      {R"({"level_ice": {"thickness_profile": [{"x_m": 0, "thickness_m": -1}]}})",
       "level_ice.thickness_profile[0].thickness_m"},
      {R"({"level_ice": {"sheet": 1}})", "sheet"},
      {R"({"sleep": {"freeze_astern_m": -1}})", "sleep.freeze_astern_m"},
  };
  for (const auto& [text, key] : bad) {
    try {
      read_options<SimulateOptions>(Json::parse(text), "simulate.json");
      ADD_FAILURE() << "accepted " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
  // A floes file feature of an unknown kind.
  const Json fc = Json::parse(R"({"type": "FeatureCollection", "features": [{"type": "Feature",
      "properties": {"id": 1, "kind": "pack"},
      "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [10, 0], [10, 10], [0, 0]]]}}]})");
  testing::expect_error([&] { floes_from_geojson(fc, "floes.geojson"); },
                        {"floes.geojson", "floe id 1", "properties.kind", "level_ice"});
  // A sheet of more tiles than any field has floes (10 km x 10 km at 5 m: 4 million tiles).
  {
    SimulateOptions o;
    o.level_ice.extent_m = {0, -5000, 10000, 5000};
    o.level_ice.tile_m = 5;
    testing::expect_error([&] { build_model(FloeField{}, nullptr, o); },
                          {"level_ice.extent_m: a sheet of 10000 m x 10000 m makes", "tiles of level_ice.tile_m = 5 m",
                           "enlarge level_ice.tile_m"});
  }
  // A sheet under the vessel's start.
  SimulateOptions o = testing::floe_options();
  o.level_ice.extent_m = {-200, -50, 200, 50};
  const HullModel hull = coarse_hull();
  testing::expect_error([&] { build_model(FloeField{}, &hull, o); },
                        {"level ice", "overlaps the vessel's start", "level_ice.openings"});
}

}  // namespace
}  // namespace floesim::sim
