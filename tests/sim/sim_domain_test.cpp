// Drift in a uniform current and the domain walls that let floes pack (the seed's Fig. 9 case): a floe started with
// the current keeps its velocity exactly; floes driven against walls stop there and pack into the downstream
// corner, the wall carrying the drag; walls never appear in the results; walls overlapping a floe or the vessel
// are errors naming them.
#include <gtest/gtest.h>

#include <cmath>

#include "pipeline/error.h"
#include "sim/simulate/simulate.h"
#include "sim/engine/world.h"
#include "sim_fixtures.h"
#include "tests/test_util.h"

namespace floesim::sim {
namespace {

using testing::coarse_hull;
using testing::floe_options;
using testing::rect_floe;

using floesim::tests::error_of;

// Started with the current (an established drift), a free floe has no relative velocity, hence no drag: it keeps
// the current's velocity to rounding, and stays level at its draught.
TEST(SimDomain, FloeStartedWithTheCurrentKeepsDrifting) {
  SimulateOptions o = floe_options();
  o.water.current_speed_mps = 0.5;
  o.water.current_direction_deg = 45;
  o.water.floes_start_with_current = true;
  FloeField field;
  field.floes = {rect_floe(1, 0, 0, 12, 7, 1.0)};
  const Model m = build_model(field, nullptr, o);
  World w(m);
  const Vec3 x0 = w.state().position[0];
  for (int i = 0; i < 1000; ++i) w.step();
  const Vec3 v = w.state().velocity[0];
  std::printf("[measured] after 10 s: v = (%.9f, %.9f, %.2e) m/s, current (%.9f, %.9f)\n", v.x(), v.y(), v.z(),
              m.current.x(), m.current.y());
  EXPECT_NEAR((v - m.current).norm(), 0.0, 1e-9);
  EXPECT_NEAR((w.state().position[0] - x0 - 10.0 * m.current).norm(), 0.0, 1e-6);
}

// A floe carried north by a 0.5 m/s current against a north wall: it stops at the wall (no tunnelling, overlap
// below a few cm) and the wall holds it against the form drag of the current on its upstream side,
// F = 1/2 rho_w C_d (L d) u^2 plus the skin friction on the bottom and the parallel sides: the contact impulse per
// step over dt equals that drag within 2 %.
TEST(SimDomain, WallStopsADriftingFloeAndCarriesTheDrag) {
  SimulateOptions o = floe_options();
  o.water.current_speed_mps = 0.5;
  o.water.current_direction_deg = 90;
  o.water.floes_start_with_current = true;
  o.domain.walls = {"north"};
  o.domain.extent_m = {-50, -50, 50, 20};
  const double L = 10, W = 6, h = 1;
  FloeField field;
  field.floes = {rect_floe(1, -5, 10, L, W, h)};  // 4 m below the wall: reaches it after 8 s
  const Model m = build_model(field, nullptr, o);
  ASSERT_EQ(m.floe_count(), 1);
  ASSERT_EQ(m.wall_count, 1);
  World w(m);
  for (int i = 0; i < 6000; ++i) w.step();
  const double top = w.state().position[0].y() + W / 2;
  double force = 0;
  for (const Contact& c : w.contacts()) force += c.pn / o.time_step_s;
  const double d = o.ice.density_kg_m3 / o.water.density_kg_m3 * h, u = 0.5, rho = o.water.density_kg_m3;
  const double drag = 0.5 * rho * (o.water.form_drag_cd * L * d + o.water.skin_friction_cf * (L * W + 2 * W * d)) * u * u;
  std::printf("[measured] floe top at y = %.4f m (wall at 20 m), speed %.2e m/s, wall force %.1f N, drag %.1f N\n",
              top, w.state().velocity[0].norm(), force, drag);
  EXPECT_LT(top, 20.03);
  EXPECT_GT(top, 19.9);
  EXPECT_LT(w.state().velocity[0].norm(), 1e-3);
  EXPECT_NEAR(force / drag, 1.0, 0.02);
}

// Nine floes in a current towards the north-east, walls on the north and east sides: they pack into the corner
// (each ends within a few metres of its packed place: their spread shrinks, the nearest to the corner touch both
// walls) and the results list floes and vessel only.
TEST(SimDomain, FloesPackIntoTheDownstreamCornerAndWallsAreNotInTheResults) {
  SimulateOptions o;
  o.water.current_speed_mps = 0.5;
  o.water.current_direction_deg = 45;
  o.water.floes_start_with_current = true;
  o.domain.walls = {"east", "north"};
  o.domain.extent_m = {-100, -60, 60, 60};
  o.duration_s = 90;
  o.steady_start_s = 10;
  o.output_interval_s = 1;
  o.vessel.x_m = -80;  // the vessel idles in the south-west corner
  o.vessel.y_m = -40;
  o.vessel.initial_speed_mps = 0;
  o.vessel.propulsion.speed_mps = 0;
  FloeField field;
  int id = 1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) field.floes.push_back(rect_floe(id++, 20 + 12 * i, 20 + 12 * j, 8, 8, 1.0));
  const HullModel hull = coarse_hull(6);
  const Model m = build_model(field, &hull, o);
  ASSERT_EQ(m.floe_count(), 9);
  RunStats stats;
  const Results r = simulate(o, m, stats);
  // Last frame: every floe is inside the domain corner region, stopped; the spread of the field shrank.
  FrameReplay replay(r, "results");
  replay.seek(r.frames() - 1);
  double xmax = -1e9, ymax = -1e9, xmin = 1e9, ymin = 1e9;
  int rows = 0;
  for (const int64_t row : replay.rows()) {
    ++rows;
    const int32_t bid = r.state_body_id[row];
    EXPECT_GE(bid, 0) << "a wall in the results";
    if (bid == 0) continue;
    const double x = r.state_position_m[3 * row], y = r.state_position_m[3 * row + 1];
    xmax = std::max(xmax, x), ymax = std::max(ymax, y), xmin = std::min(xmin, x), ymin = std::min(ymin, y);
  }
  EXPECT_EQ(rows, 10);  // the vessel and nine floes
  std::printf("[measured] after 90 s floe centres span x %.2f..%.2f, y %.2f..%.2f m (walls at x = 60, y = 60); "
              "mean contacts %.1f\n",
              xmin, xmax, ymin, ymax, stats.mean_contacts);
  // Packed: the corner floe touches both walls (centre 4 m from each) and the nine 8 m floes fill a block of
  // 24 m x 24 m, centres 16 m apart at most (they started 24 m apart), to the rigid contacts' slop (5 mm) per joint.
  EXPECT_NEAR(xmax, 56.0, 0.05);
  EXPECT_NEAR(ymax, 56.0, 0.05);
  EXPECT_NEAR(xmax - xmin, 16.0, 0.05);
  EXPECT_NEAR(ymax - ymin, 16.0, 0.05);
}

TEST(SimDomain, WallErrorsNameTheFloeAndTheSide) {
  SimulateOptions o = floe_options();
  o.domain.walls = {"east"};
  o.domain.extent_m = {0, 0, 50, 50};
  FloeField field;
  field.floes = {rect_floe(4, 10, 10, 5, 5, 1.0), rect_floe(9, 47, 10, 5, 5, 1.0)};
  std::string e = error_of([&] { build_model(field, nullptr, o); });
  EXPECT_NE(e.find("domain wall \"east\""), std::string::npos) << e;
  EXPECT_NE(e.find("ids 9"), std::string::npos) << e;
  // No extent in the options and none in the floes file.
  o.domain.extent_m.clear();
  e = error_of([&] { build_model(field, nullptr, o); });
  EXPECT_NE(e.find("domain.extent_m"), std::string::npos) << e;
  // The vessel starting in a wall.
  const HullModel hull = coarse_hull(6);
  SimulateOptions ov;
  ov.domain.walls = {"west"};
  ov.domain.extent_m = {0, -100, 500, 100};
  e = error_of([&] { build_model(FloeField{}, &hull, ov); });  // vessel at x = 0: its stern is in the wall
  EXPECT_NE(e.find("vessel"), std::string::npos) << e;
  // Bad option values name the key.
  e = error_of([] { read_options<SimulateOptions>({{"domain", {{"walls", {"north", "up"}}}}}, "sim.json"); });
  EXPECT_NE(e.find("domain.walls"), std::string::npos) << e;
  EXPECT_NE(e.find("\"up\""), std::string::npos) << e;
  e = error_of([] { read_options<SimulateOptions>({{"domain", {{"extent_m", {0, 0, -1, 5}}}}}, "sim.json"); });
  EXPECT_NE(e.find("domain.extent_m"), std::string::npos) << e;
}

}  // namespace
}  // namespace floesim::sim
