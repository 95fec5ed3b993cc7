// Propeller wash (PHYSICS.md §3.5): the jets of the vessel's propellers against the formulas of §3.5 evaluated by
// hand, a floe carried by a jet against an independent integration of its drag balance, and the bollard-pull case's
// lane cleared astern (deterministic over thread counts).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "pipeline/geometry2d.h"
#include "pipeline/options.h"
#include "sim/engine/forces.h"
#include "sim/engine/world.h"
#include "sim_fixtures.h"

namespace floesim::sim {
namespace {

using testing::coarse_hull;
using testing::rect_floe;

const std::filesystem::path fs_source() { return FLOESIM_SOURCE_DIR; }

constexpr double kThrust = 1e6, kDiameter = 4.0;

// The coarse hull at the origin, heading 0, held at a bollard with thrust kThrust from one propeller on the
// centreline under the run (hull frame x = -45 m, z = -5 m), or moving ahead at `speed` under the same thrust.
SimulateOptions wash_options(double speed = 0) {
  SimulateOptions o;
  o.sleep.enabled = false;
  o.vessel.initial_speed_mps = speed;
  o.vessel.propulsion.mode = speed > 0 ? "constant_thrust" : "bollard_pull";
  o.vessel.propulsion.thrust_n = kThrust;
  PropellerOptions p;
  p.position_m = {-45, 0, -5};
  p.diameter_m = kDiameter;
  p.thrust_share = 1.0;
  o.vessel.propellers = {p};
  return o;
}

// The jet against §3.5 by hand: V_0 = sqrt(V_A^2 + 8 T / (pi rho D^2)) (at bollard pull the actuator disc's
// T = rho (pi D^2/4) (V_0/2) V_0), flowing astern from the propeller; centreline speed 6.2 V_0 D_0 / x with
// D_0 = 0.71 D at x = 5-80 D (all beyond 6.2 D_0 = 4.4 D), V_0 in the near field (2 D and 4 D), nothing ahead of the
// propeller; the Gaussian profile of width 0.1 x: u_c / 2 at r = 0.1 x sqrt(2 ln 2), exp(-2) u_c at r = 0.2 x, in
// any direction across the axis. Ahead at 2 m/s, V_A = 2 m/s and the jet adds V_0 - V_A to the water. All to
// round-off (1e-9 relative): the same closed forms evaluated twice.
TEST(SimWash, JetFollowsMomentumTheoryAndRoundJet) {
  const HullModel hull = coarse_hull(8);
  for (double speed : {0.0, 2.0}) {
    const SimulateOptions o = wash_options(speed);
    const Model m = build_model(FloeField{}, &hull, o);
    World w(m);
    const Vec3 x0 = w.state().position[0];
    w.step();
    ASSERT_EQ(w.jets().size(), 1u);
    const PropellerJet& j = w.jets()[0];
    const double rho = o.water.density_kg_m3, D0 = 0.71 * kDiameter;
    const double v0 = std::sqrt(speed * speed + 8 * kThrust / (kPi * rho * kDiameter * kDiameter));
    if (speed == 0) {
      EXPECT_NEAR(rho * kPi * kDiameter * kDiameter / 4 * (v0 / 2) * v0 / kThrust, 1.0, 1e-12);
    }
    EXPECT_NEAR(j.efflux_mps / v0, 1.0, 1e-9);
    EXPECT_NEAR(j.excess_mps, v0 - speed, 1e-9);
    EXPECT_LT((j.dir - Vec3(-1, 0, 0)).norm(), 1e-9);  // astern
    // The propeller's world position: the hull-frame point, moved with the body (x and y unchanged at heading 0).
    EXPECT_NEAR(j.origin.x() - x0.x(), -45 - m.vessel_info.centre_of_mass_hull.x(), 1e-6);
    EXPECT_NEAR(j.origin.y(), 0.0, 1e-6);
    const double dv = v0 - speed;
    const Vec3 across = Vec3(0, 1, 1).normalized();
    for (double xd : {2.0, 4.0, 5.0, 10.0, 20.0, 40.0, 80.0}) {
      const double x = xd * kDiameter;
      const Vec3 p = j.origin + x * j.dir;
      const double uc = x < 6.2 * D0 ? dv : 6.2 * dv * D0 / x;
      const Vec3 u = jet_velocity(w.jets(), p);
      EXPECT_NEAR(u.x() / -uc, 1.0, 1e-9) << "x = " << xd << " D";
      EXPECT_NEAR(u.tail<2>().norm(), 0.0, 1e-12);
      if (x >= 6.2 * D0) {
        const double half = 0.1 * x * std::sqrt(2 * std::log(2.0));
        EXPECT_NEAR(jet_velocity(w.jets(), p + half * across).x() / (-uc / 2), 1.0, 1e-9);
        EXPECT_NEAR(jet_velocity(w.jets(), p + 0.2 * x * Vec3::UnitY()).x() / (-uc * std::exp(-2.0)), 1.0, 1e-9);
        if (speed == 0 && (xd == 10 || xd == 40))
          std::printf("[measured] x = %2.0f D: u_c %.3f m/s (6.2 V_0 D_0/x = %.3f), half width %.2f m\n", xd, -u.x(),
                      uc, half);
      }
    }
    EXPECT_EQ(jet_velocity(w.jets(), j.origin - 5.0 * j.dir).norm(), 0.0);  // ahead of the propeller
  }
}

// jets_reach is the fast test that lets floes far from every jet skip it: where it says no, the jet is zero
// everywhere in the ball (random balls around a jet, 1000 points each).
TEST(SimWash, ReachTestIsConservative) {
  std::vector<PropellerJet> jets(1);
  jets[0].origin = Vec3(0, 0, -5);
  jets[0].dir = Vec3(-1, 0, 0);
  jets[0].efflux_mps = jets[0].excess_mps = 8;
  jets[0].d0_m = 0.71 * kDiameter;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  int skipped = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec3 c(-150 + 160 * u(rng), 100 * u(rng), -0.4);
    const double radius = 1 + 20 * (u(rng) + 1);
    if (jets_reach(jets, c, radius)) continue;
    ++skipped;
    for (int k = 0; k < 1000; ++k) {
      Vec3 d(u(rng), u(rng), u(rng));
      if (d.norm() > 1) continue;
      EXPECT_EQ(jet_velocity(jets, c + radius * d).norm(), 0.0);
    }
  }
  EXPECT_GT(skipped, 50);
}

// A 2 m x 2 m x 0.5 m floe released at rest 100 m astern of the propeller, on the jet's vertical plane: it is carried
// astern by the drag of the jet. Its speed follows m dv/dt = ½ rho_w (C_d L d + C_f (L^2 + 2 L d)) (u - v)|u - v|
// (the lumped form drag on the face across the flow and skin friction on the bottom and the two faces along it) with
// u the §3.5 jet speed at its centre, u = 6.2 V_0 D_0 / s exp(-r^2 / (2 (0.1 s)^2)), s its distance behind the
// propeller and r its depth below the axis, integrated here by RK4 (a second algorithm). In a jet alone the drag
// balance (u - v)^2 = 0 is v = u: the floe drifts at the local jet speed, lagging it by what the jet's decay along
// its path asks. Within 3 % of u: the simulation takes the jet face by face (across the 2 m floe u varies by 2 %,
// and the bottom is 0.2 m nearer the axis: 1 % more u on the skin friction).
TEST(SimWash, FloeDriftsAtTheJetsDragBalance) {
  const HullModel hull = coarse_hull(8);
  const SimulateOptions o = wash_options();
  const double L = 2, h = 0.5, x_f = -47 - 100;
  FloeField field;
  field.floes = {rect_floe(1, x_f - L / 2, -L / 2, L, L, h)};
  const Model m = build_model(field, &hull, o);
  ASSERT_EQ(m.floe_count(), 1);
  World w(m);
  w.step();
  const PropellerJet j = w.jets()[0];
  const double rho = o.water.density_kg_m3, d = o.ice.density_kg_m3 / rho * h, mass = o.ice.density_kg_m3 * L * L * h;
  const double k = 0.5 * rho * (o.water.form_drag_cd * L * d + o.water.skin_friction_cf * (L * L + 2 * L * d)) / mass;
  const double v0 = std::sqrt(8 * kThrust / (kPi * rho * kDiameter * kDiameter)), D0 = 0.71 * kDiameter;
  const double r = j.origin.z() - w.state().position[1].z();
  auto jet_u = [&](double s) { return 6.2 * v0 * D0 / s * std::exp(-r * r / (2 * 0.01 * s * s)); };
  // RK4 on (s, v), s the distance astern of the propeller, v the speed astern.
  double s = j.origin.x() - w.state().position[1].x(), v = -w.state().velocity[1].x();
  auto acc = [&](double s, double v) { return k * (jet_u(s) - v) * std::abs(jet_u(s) - v); };
  const double dt = o.time_step_s;
  for (int step = 1; step < 3000; ++step) {
    const double s1 = v, v1 = acc(s, v);
    const double s2 = v + dt / 2 * v1, v2 = acc(s + dt / 2 * s1, v + dt / 2 * v1);
    const double s3 = v + dt / 2 * v2, v3 = acc(s + dt / 2 * s2, v + dt / 2 * v2);
    const double s4 = v + dt * v3, v4 = acc(s + dt * s3, v + dt * v3);
    s += dt / 6 * (s1 + 2 * s2 + 2 * s3 + s4);
    v += dt / 6 * (v1 + 2 * v2 + 2 * v3 + v4);
    w.step();
    if ((step + 1) % 500 == 0) {
      const double sim_v = -w.state().velocity[1].x(), sim_s = j.origin.x() - w.state().position[1].x();
      std::printf("[measured] t = %4.1f s: floe %.2f m astern at %.4f m/s; by hand %.2f m at %.4f m/s; local jet "
                  "%.4f m/s\n", w.state().time_s, sim_s, sim_v, s, v, jet_u(s));
      EXPECT_NEAR(sim_v, v, 0.03 * jet_u(s));
      EXPECT_NEAR(w.state().velocity[1].y(), 0.0, 1e-6);  // on the jet's plane of symmetry
    }
  }
  EXPECT_GT(-w.state().velocity[1].x() / jet_u(s), 0.9);  // drifting at (nearly) the local jet speed
}

}  // namespace
}  // namespace floesim::sim

namespace floesim::sim {
namespace {

// The bollard-pull-wash case's vessel and propellers (its simulate slice) over a regular field of 8 m floes on a 12 m
// grid astern (44 % ice), 60 s: the jets clear a lane astern (the ice in a 24 m wide box on the jets' axis falls below
// half of what it was, and the floes there move away from the vessel) while a box beside the jets keeps its ice; at
// 1 and 2 threads the final states are bit-identical (the jets are made once per step on the main thread and
// each floe's drag reads them only).
TEST(SimWash, BollardPullClearsALaneDeterministically) {
  const Json c = load_json_file(fs_source() / "cases" / "bollard-pull-wash" / "case.json");
  SimulateOptions o = read_options<SimulateOptions>(c["simulate"], "case.json", "simulate");
  o.duration_s = 60;
  FloeField field;
  int id = 1;
  for (int i = 0; i < 10; ++i)
    for (int k = 0; k < 10; ++k) field.floes.push_back(rect_floe(id++, 2 + 12 * i, 92 + 12 * k, 8, 8, 1.0));
  const HullModel hull = coarse_hull(30);
  std::vector<Vec3> final_positions[2];
  for (int threads : {1, 2}) {
    o.threads = threads;
    const Model m = build_model(field, &hull, o);
    ASSERT_EQ(m.floe_count(), 100);
    World w(m);
    // Ice area (floes whose centre is inside) over the box area: on the jets' axis and beside them.
    auto ice = [&](double y0, double y1) {
      double a = 0;
      for (int b = 1; b < static_cast<int>(m.bodies.size()); ++b) {
        const Vec3& x = w.state().position[b];
        if (x.x() >= 0 && x.x() <= 122 && x.y() >= y0 && x.y() <= y1) a += m.bodies[b].section_area;
      }
      return a / (122 * (y1 - y0));
    };
    const double lane0 = ice(138, 162), side0 = ice(90, 126);
    for (long s = 0; s < o.steps(); ++s) w.step();
    const double lane1 = ice(138, 162), side1 = ice(90, 126);
    if (threads == 1)
      std::printf("[measured] ice in the lane astern %.3f -> %.3f after 60 s, beside the jets %.3f -> %.3f\n", lane0,
                  lane1, side0, side1);
    EXPECT_LT(lane1, 0.5 * lane0);
    EXPECT_NEAR(side1, side0, 0.02);
    EXPECT_NEAR(w.state().velocity[0].norm(), 0.0, 1e-3);  // held at the bollard
    final_positions[threads - 1] = w.state().position;
  }
  for (size_t b = 0; b < final_positions[0].size(); ++b)
    EXPECT_EQ((final_positions[0][b] - final_positions[1][b]).norm(), 0.0) << "body " << b;
}

}  // namespace
}  // namespace floesim::sim
