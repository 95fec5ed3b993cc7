// Floe hydrostatics and hydrodynamics against closed forms: floating draught, heave period, current drift,
// wind drift balance.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sim/geometry.h"
#include "sim/world.h"
#include "sim_fixtures.h"
#include "pipeline/geometry2d.h"

namespace floesim::sim {
namespace {

using testing::floe_options;
using testing::rect_floe;

// A floe released 5 cm above equilibrium settles at draught rho_i/rho_w h (bottom at -draught).
TEST(SimHydro, FloeFloatsAtDraught) {
  FloeField field;
  field.floes = {rect_floe(1, 0, 0, 8, 6, 1.0)};
  SimulateOptions o = floe_options();
  const Model m = build_model(field, nullptr, o);
  World w(m);
  w.mutable_state().position[0].z() += 0.05;
  w.sync();
  for (int i = 0; i < 2000; ++i) w.step();  // 20 s, ~10 periods at 20 % damping
  const double h = 1.0, draught = o.ice.density_kg_m3 / o.water.density_kg_m3 * h;
  const double bottom = w.state().position[0].z() - h / 2;
  std::printf("[measured] floe bottom %.6f m, expected %.6f m\n", bottom, -draught);
  EXPECT_NEAR(bottom, -draught, 1e-3);
  EXPECT_LT(w.state().velocity[0].norm(), 1e-3);
}

// Undamped, drag-free heave: period 2 pi sqrt((m + a33) / (rho_w g A)). Without added mass (a33 = 0) that is
// 2 pi sqrt(rho_i h / (rho_w g)); with the default C_a33 = 1 it is sqrt(2) longer, which shows that the added mass
// acts through the mass matrix and not on the weight (the draught is unchanged). Within 1 %: semi-implicit Euler
// shifts the period of an oscillator by O((omega dt)^2 / 24) ~ 5e-5 here, and the zero crossings are interpolated
// linearly between steps (error ~ 1e-4 of the period over 5-8 periods).
TEST(SimHydro, HeavePeriod) {
  for (double ca33 : {0.0, 1.0, 2.0}) {
    FloeField field;
    field.floes = {rect_floe(1, 0, 0, 6, 6, 1.0)};
    SimulateOptions o = floe_options();
    o.water.floe_heave_damping_ratio = 0;
    o.water.floe_roll_pitch_damping_ratio = 0;
    o.water.form_drag_cd = 0;
    o.water.skin_friction_cf = 0;
    o.water.floe_heave_added_mass_ratio = ca33;
    const Model m = build_model(field, nullptr, o);
    World w(m);
    const double z0 = w.state().position[0].z();
    w.mutable_state().position[0].z() += 0.02;
    w.sync();
    // Upward zero crossings of z - z0 (linear interpolation between steps).
    std::vector<double> up;
    double prev = w.state().position[0].z() - z0, tprev = 0;
    for (int i = 0; i < 1600; ++i) {
      w.step();
      const double cur = w.state().position[0].z() - z0, t = w.state().time_s;
      if (prev < 0 && cur >= 0) up.push_back(tprev + (t - tprev) * (-prev) / (cur - prev));
      prev = cur;
      tprev = t;
    }
    ASSERT_GE(up.size(), 4u);
    const double period = (up.back() - up.front()) / (up.size() - 1);
    const double mass = o.ice.density_kg_m3 * 36 * 1.0;
    const double expected =
        2 * kPi * std::sqrt((1 + ca33) * mass / (o.water.density_kg_m3 * 9.81 * 36));
    if (ca33 == 0)  // the closed form without added mass
      EXPECT_NEAR(expected, 2 * kPi * std::sqrt(o.ice.density_kg_m3 * 1.0 / (o.water.density_kg_m3 * 9.81)), 1e-12);
    std::printf("[measured] C_a33 = %.1f: heave period %.4f s, theory %.4f s (%+.2f %%)\n", ca33, period, expected,
                100 * (period / expected - 1));
    EXPECT_NEAR(period / expected, 1.0, 0.01);
  }
}

// A floe at rest in a uniform current: the relative speed decays by quadratic drag,
// v_rel(t) = v0 / (1 + k v0 t), k = rho_w/2 (C_d L d + C_f (L^2 + 2 L d)) / m for a square floe moving along x
// (form drag on the advancing face, skin friction on the bottom and the two faces parallel to the flow).
TEST(SimHydro, DriftTowardsCurrent) {
  const double L = 4, h = 0.5;
  FloeField field;
  field.floes = {rect_floe(1, 0, 0, L, L, h)};
  SimulateOptions o = floe_options();
  o.water.current_speed_mps = 0.5;
  o.water.current_direction_deg = 0;
  const Model m = build_model(field, nullptr, o);
  World w(m);
  const double d = o.ice.density_kg_m3 / o.water.density_kg_m3 * h;
  const double mass = o.ice.density_kg_m3 * L * L * h;
  const double k = 0.5 * o.water.density_kg_m3 *
                   (o.water.form_drag_cd * L * d + o.water.skin_friction_cf * (L * L + 2 * L * d)) / mass;
  const double v0 = 0.5;
  double last_rel = v0;
  for (int s = 1; s <= 6; ++s) {
    for (int i = 0; i < 1000; ++i) w.step();
    const double t = w.state().time_s;
    const double rel = o.water.current_speed_mps - w.state().velocity[0].x();
    const double theory = v0 / (1 + k * v0 * t);
    std::printf("[measured] t = %.0f s: relative speed %.5f m/s, theory %.5f m/s (%+.2f %%)\n", t, rel, theory,
                100 * (rel / theory - 1));
    EXPECT_NEAR(rel / theory, 1.0, 0.03);
    EXPECT_LT(rel, last_rel);  // decays monotonically towards 0: the floe approaches the current
    last_rel = rel;
    EXPECT_NEAR(w.state().velocity[0].y(), 0.0, 1e-6);
  }
}

// Wind-driven free drift: with skin drag only, rho_a C_a A_top (U - v)^2 = rho_w C_f A_wet v^2 (A_wet = bottom +
// the two submerged faces parallel to the motion). A floe started at that speed keeps it; one started slower
// accelerates towards it.
TEST(SimHydro, WindDriftBalance) {
  const double L = 20, h = 1.0;
  SimulateOptions o = floe_options();
  o.water.form_drag_cd = 0;
  o.wind.speed_mps = 15;
  const double d = o.ice.density_kg_m3 / o.water.density_kg_m3 * h;
  const double s = std::sqrt(o.wind.air_density_kg_m3 * o.ice.air_drag_ca * L * L /
                             (o.water.density_kg_m3 * o.water.skin_friction_cf * (L * L + 2 * L * d)));
  const double v_drift = o.wind.speed_mps * s / (1 + s);
  std::printf("[theory] wind drift %.4f m/s = %.2f %% of the wind speed\n", v_drift, 100 * v_drift / 15);
  for (double start : {1.0, 0.8}) {
    FloeField field;
    field.floes = {rect_floe(1, 0, 0, L, L, h)};
    const Model m = build_model(field, nullptr, o);
    World w(m);
    w.mutable_state().velocity[0] = Vec3(start * v_drift, 0, 0);
    for (int i = 0; i < 1000; ++i) w.step();
    const double v = w.state().velocity[0].x();
    std::printf("[measured] started at %.0f %%: after 10 s %.5f m/s (drift %.5f)\n", 100 * start, v, v_drift);
    if (start == 1.0) EXPECT_NEAR(v / v_drift, 1.0, 0.005);
    else EXPECT_GT(v, start * v_drift * 1.001);
  }
}

}  // namespace
}  // namespace floesim::sim

namespace floesim::sim {
namespace {

// The closed-form prism buoyancy agrees with clipping the slab mesh, for an irregular (non-convex) floe at random
// heave, roll, pitch and yaw.
TEST(SimHydro, PrismBuoyancyMatchesClipping) {
  FloeField field;
  Floe f;
  f.id = 1;
  f.thickness_m = 1.2;
  f.outline = {Vec2(0, 0), Vec2(12, 1), Vec2(14, 7), Vec2(8, 5), Vec2(6, 11), Vec2(-1, 8)};
  field.floes = {f};
  const Model m = build_model(field, nullptr, testing::floe_options());
  const Body& b = m.bodies[0];
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int closed_form = 0;
  for (int i = 0; i < 200; ++i) {
    BodyKinematics k;
    k.x = Vec3(3 * u(rng), 2 * u(rng), 0.3 * u(rng));
    k.q = Quat(Eigen::AngleAxisd(3 * u(rng), Vec3::UnitZ()) * Eigen::AngleAxisd(0.05 * u(rng), Vec3::UnitX()) *
               Eigen::AngleAxisd(0.05 * u(rng), Vec3::UnitY()));
    k.R = k.q.toRotationMatrix();
    double v;
    Vec3 c;
    if (!prism_submerged(b, k, v, c)) continue;
    ++closed_form;
    std::vector<Vec3> w;
    for (const Vec3& p : b.buoyancy_mesh.vertices) w.push_back(k.x + k.R * p);
    const Submerged s = submerged_part(w, b.buoyancy_mesh.triangles, 0.0);
    EXPECT_NEAR(v, s.volume, 1e-9 * s.volume);
    EXPECT_LT((c - s.centroid).norm(), 1e-9);
  }
  std::printf("[measured] %d of 200 random poses in closed form, all equal to clipping\n", closed_form);
  EXPECT_GT(closed_form, 50);
}

}  // namespace
}  // namespace floesim::sim

namespace floesim::sim {
namespace {

// The per-face drag (with its shortcut for side walls cut by the waterline) equals a plain evaluation that clips
// every face of the slab, at random poses and velocities.
TEST(SimHydro, FaceDragMatchesGenericClipping) {
  FloeField field;
  Floe f;
  f.id = 1;
  f.thickness_m = 1.0;
  f.outline = {Vec2(0, 0), Vec2(12, 1), Vec2(14, 7), Vec2(8, 5), Vec2(6, 11), Vec2(-1, 8)};
  field.floes = {f};
  SimulateOptions o = testing::floe_options();
  o.water.current_speed_mps = 0.4;
  o.water.current_direction_deg = 20;
  const Model m = build_model(field, nullptr, o);
  const Body& b = m.bodies[0];
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  ForceScratch scratch;
  int afloat = 0;
  for (int it = 0; it < 100; ++it) {
    BodyKinematics k;
    // Odd poses strongly tilted or far from the draught (clipped), even ones nearly level (mostly closed form).
    const double tilt = it % 2 ? 0.2 : 0.01, heave = it % 2 ? 0.3 : 0.2;
    k.x = Vec3(u(rng), u(rng), -0.38 + heave * u(rng));
    k.q = Quat(Eigen::AngleAxisd(3 * u(rng), Vec3::UnitZ()) * Eigen::AngleAxisd(tilt * u(rng), Vec3::UnitX()) *
               Eigen::AngleAxisd(tilt * u(rng), Vec3::UnitY()));
    k.R = k.q.toRotationMatrix();
    k.v = Vec3(u(rng), u(rng), 0.2 * u(rng));
    k.w = Vec3(0.1 * u(rng), 0.1 * u(rng), 0.2 * u(rng));
    const Wrench got = floe_water_drag(m, b, k, scratch);
    double vol;
    Vec3 cb;
    afloat += prism_submerged(b, k, vol, cb);  // the condition of floe_water_drag's closed-form (body-frame) path
    Wrench ref;
    for (const DragFace& df : b.drag_faces) {
      std::vector<Vec3> poly, cut;
      for (int i = 0; i < df.count; ++i) poly.push_back(k.x + k.R * b.drag_vertices[b.drag_face_index[df.first + i]]);
      clip_polygon_z(poly.data(), df.count, 0.0, true, cut);
      const AreaCentroid ac = polygon_area_centroid(cut.data(), static_cast<int>(cut.size()));
      if (ac.area <= 0) continue;
      const Vec3 n = k.R * df.normal, r = ac.centroid - k.x;
      const Vec3 vrel = k.v + k.w.cross(r) - m.current;
      const double vn = vrel.dot(n);
      Vec3 force = -0.5 * 1025 * 0.005 * ac.area * (vrel - vn * n).norm() * (vrel - vn * n);
      if (vn > 0) force -= 0.5 * 1025 * 0.5 * ac.area * vn * vn * n;
      ref.add_at(force, r);
    }
    EXPECT_LT((got.force - ref.force).norm(), 1e-9 * (1 + ref.force.norm()));
    EXPECT_LT((got.torque - ref.torque).norm(), 1e-9 * (1 + ref.torque.norm()));
  }
  // Both paths are exercised: the body-frame trapezoids (afloat, cut through the side walls only) and clipping.
  std::printf("[measured] %d of 100 random poses on the closed-form path, all equal to clipping\n", afloat);
  EXPECT_GT(afloat, 10);
  EXPECT_LT(afloat, 90);
}

}  // namespace
}  // namespace floesim::sim
