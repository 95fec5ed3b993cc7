// The vessel in open water against closed forms: hydrostatic equilibrium and heave period from the clipped hull,
// the ITTC-57 friction line against PHYSICS.md §4.2's worked numbers, terminal speed under a thrust built by hand
// from them, the speed controller, numerical-health stop.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "pipeline/error.h"
#include "sim/engine/forces.h"
#include "sim/simulate/simulate.h"
#include "sim/engine/world.h"
#include "sim_fixtures.h"
#include "pipeline/geometry2d.h"

namespace floesim::sim {
namespace {

using testing::coarse_hull;

double surge_speed(const World& w) {
  const int v = w.model().vessel;
  return (w.state().orientation[v].toRotationMatrix().transpose() * w.state().velocity[v]).x();
}

// Released 10 cm low, undamped, the vessel heaves with T = 2 pi sqrt((m + A33) / (rho_w g A_wp)) about its initial
// (hydrostatic) position, without heave added mass and with the strip-theory A33 (checked against the closed form
// of a box in SimAddedMass.VesselHeavePitchByStripTheory); heave-pitch coupling of the asymmetric waterplane shifts
// it a little.
TEST(SimVessel, HeavePeriodFromWaterplane) {
  const HullModel hull = coarse_hull(10);
  for (double scale : {0.0, 1.0}) {
    SimulateOptions o;
    o.vessel.heave_pitch_added_mass_scale = scale;
    o.water.vessel_heave_damping_ratio = 0;
    o.water.vessel_pitch_damping_ratio = 0;
    o.vessel.initial_speed_mps = 0;
    o.vessel.propulsion.mode = "constant_thrust";
    o.vessel.propulsion.thrust_n = 0;
    const Model m = build_model(FloeField{}, &hull, o);
    World w(m);
    const double z0 = w.state().position[0].z();
    w.mutable_state().position[0].z() -= 0.1;
    w.sync();
    std::vector<double> up;
    double prev = -0.1, tprev = 0, zsum = 0;
    int n = 0;
    for (int i = 0; i < 4000; ++i) {
      w.step();
      const double cur = w.state().position[0].z() - z0, t = w.state().time_s;
      if (prev < 0 && cur >= 0) up.push_back(tprev + (t - tprev) * (-prev) / (cur - prev));
      prev = cur;
      tprev = t;
      zsum += cur;
      ++n;
    }
    ASSERT_GE(up.size(), 3u);
    const double period = (up.back() - up.front()) / (up.size() - 1);
    const double theory = 2 * kPi * std::sqrt((m.vessel_info.mass_kg + m.bodies[0].added_mass.z()) /
                                              (o.water.density_kg_m3 * 9.81 * m.vessel_info.waterplane_area_m2));
    std::printf("[measured] vessel heave period (A33 x %.0f) %.3f s, theory %.3f s (%+.2f %%); mean heave offset "
                "%.4f m\n", scale, period, theory, 100 * (period / theory - 1), zsum / n);
    EXPECT_NEAR(period / theory, 1.0, 0.05);
    EXPECT_NEAR(zsum / n, 0.0, 0.01);  // oscillates about the hydrostatic equilibrium it was built at
  }
}

// The ITTC-57 friction line C_F = 0.075 / (log10 Re - 2)^2 against the worked numbers of PHYSICS.md §4.2:
// L = 100 m, nu = 1.83e-6 m^2/s gives C_F = 0.00206 at 2 m/s and 0.00177 at 6 m/s. C_F is read from the resistance
// with k = 0, C_A = 0 and S = 1 m^2 (R = 1/2 rho S u^2 C_F). Tolerance: half a unit of the worked numbers' last digit.
TEST(SimVessel, IttcFrictionLineMatchesWorkedNumbers) {
  VesselParticulars vp;
  vp.length_wl_m = 100;
  vp.wetted_surface_m2 = 1;
  SimulateOptions o;
  o.vessel.form_factor_k = 0;
  o.vessel.roughness_ca = 0;
  ASSERT_EQ(o.water.kinematic_viscosity_m2ps, 1.83e-6);  // the brief's value is the default
  for (const auto& [u, cf] : {std::pair{2.0, 0.00206}, std::pair{6.0, 0.00177}}) {
    const double c = 2 * ittc57_resistance(u, ittc57_of(vp, o)) / (o.water.density_kg_m3 * u * u);
    std::printf("[measured] C_F(L = 100 m, %.0f m/s) = %.6f (PHYSICS.md: %.5f)\n", u, c, cf);
    EXPECT_NEAR(c, cf, 0.5e-5);
  }
}

// Constant thrust equal to the open-water resistance at 2 m/s, built by hand from the worked C_F = 0.00206 of
// PHYSICS.md §4.2 (the viscosity scaled so that this hull's Reynolds number at 2 m/s is that of L = 100 m):
// T = 1/2 rho S u^2 ((1 + k) C_F + C_A), S the hull's wetted surface. Started at 2 m/s, the vessel stays there, level
// and on course. C_F rounded to 3 digits is within 0.25 %, so the equilibrium speed (R ~ u^2) is within 0.125 %
// of 2 m/s, and the speed, converging to it monotonically, stays within 0.0025 m/s.
TEST(SimVessel, TerminalSpeedUnderConstantThrust) {
  const HullModel hull = coarse_hull(10);
  SimulateOptions o;
  o.vessel.initial_speed_mps = 2.0;
  o.vessel.heading_deg = 30;
  o.vessel.propulsion.mode = "constant_thrust";
  Model m = build_model(FloeField{}, &hull, o);
  m.settings.water.kinematic_viscosity_m2ps = 1.83e-6 * m.vessel_info.length_wl_m / 100;
  const double u = 2.0, cf = 0.00206;
  const double thrust = 0.5 * o.water.density_kg_m3 * m.vessel_info.wetted_surface_m2 * u * u *
                        ((1 + o.vessel.form_factor_k) * cf + o.vessel.roughness_ca);
  m.settings.vessel.propulsion.thrust_n = thrust;
  World w(m);
  for (int i = 0; i < 3000; ++i) w.step();
  const double speed = surge_speed(w);
  const Mat3 R = w.state().orientation[0].toRotationMatrix();
  std::printf("[measured] thrust %.1f kN (R_ow(2 m/s) by hand); speed after 30 s %.5f m/s; heading %.4f deg\n",
              thrust / 1e3, speed, heading_of(R) * 180 / kPi);
  EXPECT_NEAR(speed, 2.0, 0.0025);
  EXPECT_NEAR(heading_of(R) * 180 / kPi, 30.0, 0.01);
  EXPECT_GT(R(2, 2), std::cos(0.2 * kPi / 180));  // no heel or trim beyond 0.2 deg

  // The same thrust as a series (interpolated between its rows) gives the same motion.
  const auto dir = testing::temp_dir("thrust_series");
  std::ofstream(dir / "thrust.csv") << "time_s,thrust_N\n0," << thrust / 2 << "\n10," << thrust << "\n100," << thrust
                                    << "\n";
  SimulateOptions os = o;
  os.vessel.propulsion.mode = "thrust_series";
  os.vessel.propulsion.thrust_file = (dir / "thrust.csv").string();
  Model ms = build_model(FloeField{}, &hull, os);
  ms.settings.water.kinematic_viscosity_m2ps = m.settings.water.kinematic_viscosity_m2ps;
  World ws(ms);
  for (int i = 0; i < 500; ++i) ws.step();
  EXPECT_NEAR(ws.report().thrust_n, 0.5 * thrust + 0.5 * thrust * (4.99 / 10), 1e-6 * thrust);  // at t = 4.99 s
  for (int i = 500; i < 3000; ++i) ws.step();
  EXPECT_NEAR(surge_speed(ws), 2.0, 0.01);
}

// Speed mode: the PI controller brings the vessel from 1 to 2 m/s and settles at the open-water thrust (the
// closed loop is overdamped with a slow pole of ~16 s for Oden's mass).
TEST(SimVessel, SpeedControllerHoldsTarget) {
  const HullModel hull = coarse_hull(10);
  SimulateOptions o;
  o.vessel.initial_speed_mps = 1.0;
  o.vessel.propulsion.speed_mps = 2.0;
  const Model m = build_model(FloeField{}, &hull, o);
  World w(m);
  for (int i = 0; i < 15000; ++i) w.step();
  const double r2 = ittc57_resistance(2.0, ittc57_of(m.vessel_info, o));
  std::printf("[measured] speed after 150 s %.5f m/s, thrust %.1f kN (R_ow(2) %.1f kN)\n", surge_speed(w),
              w.report().thrust_n / 1e3, r2 / 1e3);
  EXPECT_NEAR(surge_speed(w), 2.0, 0.002);
  EXPECT_NEAR(w.report().thrust_n / r2, 1.0, 0.05);
}

// A health limit crossed stops the stage with a diagnosis naming the body, and nothing is written.
TEST(SimVessel, HealthStopWritesNothing) {
  const auto dir = testing::temp_dir("health");
  FloeField field;
  field.floes = {testing::rect_floe(1, 300, 0, 5, 5, 1)};
  write_floes(dir / "floes.geojson", field);
  HullGeneratorOptions g;
  g.sections = 6;
  write_obj(dir / "hull.obj", generate_hull(g), "test hull");
  std::ofstream(dir / "sim.json") << R"({"duration_s": 1.0, "steady_start_s": 0.5, "health": {"max_speed_mps": 1.5}})";
  try {
    run_simulate(dir / "floes.geojson", dir / "hull.obj", dir / "sim.json", dir / "out");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    std::printf("[message] %s\n", msg.c_str());
    EXPECT_NE(msg.find("the vessel"), std::string::npos);
    EXPECT_NE(msg.find("step 1 "), std::string::npos);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "results.h5"));
}

}  // namespace
}  // namespace floesim::sim
