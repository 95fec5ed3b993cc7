// Added mass through the mass matrix (PHYSICS.md §3.3) and the vessel's mass properties: surge acceleration under
// thrust, the yaw period of the heading autopilot, collisions that conserve the momentum of mass plus added mass,
// and an inertia tensor given outright.
#include <gtest/gtest.h>

#include <cmath>

#include "pipeline/error.h"
#include "sim/engine/forces.h"
#include "sim/geometry/mesh.h"
#include "sim/engine/world.h"
#include "sim_fixtures.h"
#include "pipeline/geometry2d.h"

namespace floesim::sim {
namespace {

using testing::coarse_hull;
using testing::rect_floe;

// A vessel at rest in calm water, not steered, not driven.
SimulateOptions still_vessel() {
  SimulateOptions o;
  o.vessel.initial_speed_mps = 0;
  o.vessel.propulsion.mode = "constant_thrust";
  o.vessel.propulsion.thrust_n = 0;
  o.vessel.autopilot.enabled = false;
  return o;
}

// From rest, thrust T gives the acceleration T / (m + A11) (no resistance at u = 0): after one step the speed is
// dt T / (m + A11) to rounding, for A11 = 0 and for the default 5 %.
TEST(SimAddedMass, SurgeAccelerationUnderThrust) {
  const HullModel hull = coarse_hull(8);
  for (double a11 : {0.0, 0.05, 0.2}) {
    SimulateOptions o = still_vessel();
    o.vessel.surge_added_mass_ratio = a11;
    o.vessel.propulsion.thrust_n = 1e6;
    const Model m = build_model(FloeField{}, &hull, o);
    EXPECT_NEAR(m.bodies[0].added_mass.x(), a11 * m.vessel_info.mass_kg, 1e-9 * m.vessel_info.mass_kg);
    World w(m);
    w.step();
    const double u = w.state().velocity[0].x();
    const double theory = o.time_step_s * 1e6 / ((1 + a11) * m.vessel_info.mass_kg);
    std::printf("[measured] A11 = %.2f m: speed after one step %.6e m/s, theory %.6e m/s\n", a11, u, theory);
    EXPECT_NEAR(u / theory, 1.0, 1e-9);
  }
}

// The autopilot's PD moment is designed on I_zz + A66; the yaw motion integrates with the same inertia, so the
// closed loop oscillates with the design period T_n / sqrt(1 - zeta^2). With the inertia used inconsistently
// (A66 = 0.5 I_zz in one place only) the period would be off by sqrt(1.5) = 22 %. Cross-flow drag off (it damps
// yaw); within 1 %.
TEST(SimAddedMass, AutopilotYawPeriodWithAddedInertia) {
  const HullModel hull = coarse_hull(8);
  for (double a66 : {0.0, 0.5}) {
    SimulateOptions o = still_vessel();
    o.vessel.sway_drag_cd = 0;
    o.vessel.yaw_added_inertia_ratio = a66;
    o.vessel.autopilot.enabled = true;
    o.vessel.autopilot.natural_period_s = 20;
    o.vessel.autopilot.damping_ratio = 0.1;
    const Model m = build_model(FloeField{}, &hull, o);
    World w(m);
    // Start 2 degrees off the course the autopilot holds (heading 0).
    w.mutable_state().orientation[0] = Quat(Eigen::AngleAxisd(2 * kPi / 180, Vec3::UnitZ())) * w.state().orientation[0];
    w.sync();
    std::vector<double> down;  // downward zero crossings of the heading error
    double prev = heading_of(w.state().orientation[0].toRotationMatrix()), tprev = 0;
    for (int i = 0; i < 6000; ++i) {
      w.step();
      const double cur = heading_of(w.state().orientation[0].toRotationMatrix()), t = w.state().time_s;
      if (prev > 0 && cur <= 0) down.push_back(tprev + (t - tprev) * prev / (prev - cur));
      prev = cur;
      tprev = t;
    }
    ASSERT_GE(down.size(), 2u);
    const double period = (down.back() - down.front()) / (down.size() - 1);
    const double theory = 20 / std::sqrt(1 - 0.1 * 0.1);
    std::printf("[measured] A66 = %.1f I_zz: yaw period %.3f s, theory %.3f s (%+.2f %%)\n", a66, period, theory,
                100 * (period / theory - 1));
    EXPECT_NEAR(period / theory, 1.0, 0.01);

    // Open loop: a saturated steering moment M gives the yaw acceleration M / (I_zz + A66) (one step from rest).
    SimulateOptions os = o;
    os.vessel.autopilot.max_moment_nm = 1e6;
    const Model ms = build_model(FloeField{}, &hull, os);
    World ws(ms);
    ws.mutable_state().orientation[0] = Quat(Eigen::AngleAxisd(-2 * kPi / 180, Vec3::UnitZ()));
    ws.sync();
    ws.step();
    const double izz = ms.bodies[0].inertia(2, 2);
    EXPECT_NEAR(ws.state().angular_velocity[0].z() / (os.time_step_s * 1e6 / ((1 + a66) * izz)), 1.0, 1e-6);
  }
}

// A floe thrown sideways against the vessel's side, off the centre of mass (gravity off: no hydrostatics; no drag;
// rigid contact, so that the impact takes one step): the contact impulses are equal and opposite and each body's
// velocity changes by (M + A)^-1 times its impulse, so across the impact step the momentum of mass plus added mass,
// sum (M_i + A_i) v_i (the vessel's surge/sway added mass in its body axes, the floe's heave added mass along its
// normal), is conserved, while the plain sum of m_i v_i is not (the vessel's A22 takes its share). Within 1e-3 of
// the floe's momentum: what leaks in the step is the rotation of the added-mass axes of the tilting, turning bodies
// (the Kirchhoff/Munk terms of a body with anisotropic added mass, which the model neglects), ~1e-4 here.
TEST(SimAddedMass, CollisionConservesMomentumWithAddedMass) {
  const HullModel hull = coarse_hull(8);
  SimulateOptions o = still_vessel();
  o.water.gravity_mps2 = 0;
  o.water.form_drag_cd = 0;
  o.water.skin_friction_cf = 0;
  o.sleep.enabled = false;
  o.contact.ice_structure = "rigid";
  FloeField field;
  // Beside the parallel body's port side (half beam 12.5 m), 15 m aft of midship, 2 m clear of the hull.
  field.floes = {rect_floe(1, -20, 14.5, 10, 8, 1.0)};
  const Model m = build_model(field, &hull, o);
  ASSERT_EQ(m.floe_count(), 1);
  World w(m);
  w.mutable_state().velocity[1] = Vec3(0, -1.5, 0);
  auto momentum = [&](bool with_added) {
    Vec3 p = Vec3::Zero();
    for (size_t b = 0; b < m.bodies.size(); ++b) {
      const Body& body = m.bodies[b];
      const Mat3 R = w.state().orientation[b].toRotationMatrix();
      Vec3 mass = Vec3::Constant(body.mass_kg);
      if (with_added) mass += body.added_mass;
      p += R * mass.asDiagonal() * R.transpose() * w.state().velocity[b];
    }
    return p;
  };
  Vec3 p0, q0;
  int step = 0;
  for (; step < 500; ++step) {
    p0 = momentum(true);
    q0 = momentum(false);
    w.step();
    if (w.report().vessel_contacts > 0) break;
  }
  ASSERT_LT(step, 500) << "no impact";
  const Vec3 p1 = momentum(true), q1 = momentum(false);
  const double scale = m.bodies[1].mass_kg * 1.5;
  std::printf("[measured] impact at step %d: floe v_y -1.5 -> %.4f m/s, vessel sway %.3e m/s; |dP|/p = %.2e with "
              "added mass, %.2e without\n",
              step + 1, w.state().velocity[1].y(), w.state().velocity[0].y(), (p1 - p0).norm() / scale,
              (q1 - q0).norm() / scale);
  EXPECT_GT(w.state().velocity[1].y(), -1.2);  // the impact took a good part of the floe's momentum
  EXPECT_LT((p1 - p0).norm(), 1e-3 * scale);
  EXPECT_GT((q1 - q0).norm(), 0.05 * scale);  // the test can tell: without the added mass it is not conserved
}

// The vessel's inertia given outright (diagonal or full tensor) replaces the radii of gyration; bad tensors are
// errors naming the key.
TEST(SimAddedMass, VesselInertiaGivenOutright) {
  const HullModel hull = coarse_hull(8);
  SimulateOptions o = still_vessel();
  const Model radii = build_model(FloeField{}, &hull, o);
  const double mass = radii.vessel_info.mass_kg;
  EXPECT_NEAR(radii.bodies[0].inertia(2, 2), mass * std::pow(0.25 * radii.vessel_info.length_oa_m, 2), 1e-6 * mass);
  o.vessel.inertia_kg_m2 = {1.5e9, 9.0e9, 9.2864e9, 0, -2e8, 0};
  const Model given = build_model(FloeField{}, &hull, o);
  const Mat3& I = given.bodies[0].inertia;
  EXPECT_EQ(I(0, 0), 1.5e9);
  EXPECT_EQ(I(1, 1), 9.0e9);
  EXPECT_EQ(I(2, 2), 9.2864e9);
  EXPECT_EQ(I(0, 2), -2e8);
  EXPECT_EQ(I(2, 0), -2e8);
  EXPECT_NEAR(given.vessel_info.radii_of_gyration_m.z(), std::sqrt(9.2864e9 / mass), 1e-9);
  EXPECT_NEAR(given.bodies[0].added_inertia.z(), 0.5 * 9.2864e9, 1.0);
  auto msg = [](const nlohmann::json& j) {
    try {
      read_options<SimulateOptions>(j, "sim.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(msg({{"vessel", {{"inertia_kg_m2", {1, 2}}}}}).find("vessel.inertia_kg_m2 must have 0, 3 or 6"),
            std::string::npos);
  EXPECT_NE(msg({{"vessel", {{"inertia_kg_m2", {1, 1, 5}}}}}).find("triangle inequality"), std::string::npos);
  EXPECT_NE(msg({{"vessel", {{"inertia_kg_m2", {1, 1, 1, 2, 0, 0}}}}}).find("positive definite"), std::string::npos);
  EXPECT_NE(msg({{"vessel", {{"sway_added_mass_ratio", -0.5}}}}).find("vessel.sway_added_mass_ratio"),
            std::string::npos);
}

// A 10 m disc floe, 1 m thick (64-gon): heave added mass of the floating disc (4/3) rho_w R^3, 2.4 x the floe's mass
// (PHYSICS.md §3.3's figure), roll and pitch (8/45) rho_w R^5 (Lamb 1932 §108: (16/45) rho a^5 about a diameter in
// unbounded fluid, half of it under a free surface), none in surge, sway and yaw. A 40 x 10 m floe of the same
// thickness: heave added mass over its own mass grows with the size (the 10 m disc's 2.4 x becomes 5.5 x), and more
// pitch (about its short axis y) than roll. Within 0.5 %: the 64-gon's area is 0.16 % below pi R^2, its second
// moment 0.3 % below pi R^4 / 4.
TEST(SimAddedMass, FloeAddedMassOfFloatingDisc) {
  SimulateOptions o;
  const double rho = o.water.density_kg_m3, R = 5;
  FloeField field;
  Floe disc;
  disc.id = 1;
  disc.thickness_m = 1.0;
  for (int i = 0; i < 64; ++i)
    disc.outline.push_back(Vec2(R * std::cos(2 * kPi * i / 64), R * std::sin(2 * kPi * i / 64)));
  field.floes = {disc, rect_floe(2, 20, -5, 40, 10, 1.0)};
  const Model m = build_model(field, nullptr, o);
  const Body& b = m.bodies[0];
  EXPECT_NEAR(b.added_mass.z() / (4.0 / 3.0 * rho * R * R * R), 1.0, 5e-3);
  EXPECT_NEAR(b.added_mass.z() / b.mass_kg, 2.4, 0.05);
  EXPECT_NEAR(b.added_inertia.x() / (8.0 / 45.0 * rho * std::pow(R, 5)), 1.0, 5e-3);
  EXPECT_NEAR(b.added_inertia.y() / (8.0 / 45.0 * rho * std::pow(R, 5)), 1.0, 5e-3);
  EXPECT_EQ(b.added_mass.head<2>().norm() + b.added_inertia.z(), 0.0);
  const Body& r = m.bodies[1];
  // Equivalent disc a = sqrt(400 / pi) = 11.28 m: (4/3) rho a^3 over 900 x 400 kg.
  EXPECT_NEAR(r.added_mass.z() / r.mass_kg, 4.0 / 3.0 * rho * std::pow(400 / kPi, 1.5) / (900 * 400), 1e-9);
  EXPECT_GT(r.added_mass.z() / r.mass_kg, 5.0);
  EXPECT_GT(r.added_inertia.y(), 10 * r.added_inertia.x());  // S_xx / S_yy = (40/10)^2 = 16
  std::printf("[measured] disc D = 10 m: A33 = %.3g kg (%.2f x mass), A44 = %.3g kg m^2; 40 x 10 m: A33 %.2f x mass\n",
              b.added_mass.z(), b.added_mass.z() / b.mass_kg, b.added_inertia.x(), r.added_mass.z() / r.mass_kg);
}

// A box hull (L = 100 m, B = 20 m, draught 5 m): the strip-theory heave added mass is (pi/8) rho_w B^2 L and the pitch
// added inertia (pi/8) rho_w B^2 L^3 / 12 about midship (the box's centre of mass). Heave exact to round-off; pitch
// by the midpoint rule over 20 strips, which gives L^3/12 (1 - 1/20^2): within 0.5 %.
TEST(SimAddedMass, VesselHeavePitchByStripTheory) {
  const double L = 100, B = 20, T = 5;
  HullModel hull;
  hull.parts = {extrude_polygon({Vec2(-L / 2, -B / 2), Vec2(L / 2, -B / 2), Vec2(L / 2, B / 2), Vec2(-L / 2, B / 2)},
                                -T, 2 * T)};
  hull.surface = hull.parts[0];
  SimulateOptions o = still_vessel();
  const double rho = o.water.density_kg_m3;
  const Model m = build_model(FloeField{}, &hull, o);
  const Body& b = m.bodies[0];
  const double a33 = kPi / 8 * rho * B * B * L, a55 = kPi / 8 * rho * B * B * L * L * L / 12;
  std::printf("[measured] box hull: A33 = %.4g kg (%.3f of theory, %.2f x mass), A55 = %.4g kg m^2 (%.4f)\n",
              b.added_mass.z(), b.added_mass.z() / a33, b.added_mass.z() / b.mass_kg, b.added_inertia.y(),
              b.added_inertia.y() / a55);
  EXPECT_NEAR(b.added_mass.z() / a33, 1.0, 1e-9);
  EXPECT_NEAR(b.added_inertia.y() / a55, 1.0, 5e-3);
  // The default Oden-like hull, for the record (no closed form to compare with).
  const HullModel oden = coarse_hull(30);
  const Model mo = build_model(FloeField{}, &oden, o);
  std::printf("[measured] Oden-like hull: A33 = %.2f x mass, A55 = %.2f x I_yy\n",
              mo.bodies[0].added_mass.z() / mo.bodies[0].mass_kg, mo.bodies[0].added_inertia.y() / mo.bodies[0].inertia(1, 1));
  o.vessel.heave_pitch_added_mass_scale = 0;
  const Model none = build_model(FloeField{}, &hull, o);
  EXPECT_EQ(none.bodies[0].added_mass.z(), 0.0);
  EXPECT_EQ(none.bodies[0].added_inertia.y(), 0.0);
}

// No water, no added mass: the vacuum tests' momentum stays the plain m v.
TEST(SimAddedMass, NoneWithoutWater) {
  const HullModel hull = coarse_hull(8);
  SimulateOptions o = still_vessel();
  o.water.enabled = false;
  FloeField field;
  field.floes = {rect_floe(1, 100, 0, 5, 5, 1.0)};
  const Model m = build_model(field, &hull, o);
  for (const Body& b : m.bodies) {
    EXPECT_EQ(b.added_mass.norm(), 0.0);
    EXPECT_EQ(b.added_inertia.norm(), 0.0);
  }
}

}  // namespace
}  // namespace floesim::sim
