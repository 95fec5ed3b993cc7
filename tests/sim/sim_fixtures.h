// Synthetic inputs with known answers for the simulation tests: rectangular floes, a coarse generated hull,
// options with the pieces of physics a test needs switched on.
#pragma once
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <string>

#include <gtest/gtest.h>

#include "pipeline/error.h"
#include "pipeline/floes_io.h"
#include "sim/vessel/hull.h"
#include "sim/engine/model.h"
#include "sim/simulate/options.h"
#include "sim/engine/world.h"

namespace floesim::sim::testing {

inline Floe rect_floe(int id, double x0, double y0, double w, double l, double h) {
  Floe f;
  f.id = id;
  f.outline = {Vec2(x0, y0), Vec2(x0 + w, y0), Vec2(x0 + w, y0 + l), Vec2(x0, y0 + l)};
  f.area_m2 = w * l;
  f.thickness_m = h;
  return f;
}

// Options for floe-only tests: no sleeping (we watch the motion), everything else default.
inline SimulateOptions floe_options() {
  SimulateOptions o;
  o.sleep.enabled = false;
  o.duration_s = 10;
  o.steady_start_s = 0;
  return o;
}

// A coarse parametric icebreaker (fast to collide), as a HullModel (parts + merged surface).
inline HullModel coarse_hull(int sections = 8) {
  HullGeneratorOptions g;
  g.sections = sections;
  return hull_model_from_parts(generate_hull(g));
}

// A vertical wall (box lx x ly x hz, centred on the origin in x and y, z from z0) as a single-part hull.
inline HullModel box_hull(double lx, double ly, double z0, double hz) {
  const std::vector<Vec2> rect = {Vec2(-lx / 2, -ly / 2), Vec2(lx / 2, -ly / 2), Vec2(lx / 2, ly / 2),
                                  Vec2(-lx / 2, ly / 2)};
  HullModel h;
  h.parts = {extrude_polygon(rect, z0, hz)};
  h.surface = h.parts[0];
  return h;
}

// A rectangular ramp as the vessel: the bow face of slope beta (from the horizontal) and width `width`, its stem
// through (0, 0, 0) rising forward, 40 m long, from z = -5 to 3 m.
inline HullModel ramp_hull(double beta_deg, double width) {
  const double t = std::tan(beta_deg * kPi / 180);
  // Profile in (x, z), CCW seen from +y... extruded along y; the stem passes through (0, 0) rising forward.
  const std::vector<Vec2> profile = {{-40, -5}, {-5 / t, -5}, {3 / t, 3}, {-40, 3}};
  TriMesh m;
  for (double y : {-width / 2, width / 2})
    for (const Vec2& q : profile) m.vertices.emplace_back(q.x(), y, q.y());
  // Faces: sides y = -w/2 (0..3) and y = +w/2 (4..7), and the four quads between them.
  auto quad = [&](int a, int b, int c, int d) {
    m.triangles.push_back({a, b, c});
    m.triangles.push_back({a, c, d});
  };
  quad(0, 1, 2, 3);
  quad(4, 7, 6, 5);
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) % 4;
    quad(i, i + 4, j + 4, j);
  }
  HullModel h;
  h.parts = {m};
  h.surface = m;
  return h;
}

// l_c for the defaults (E = 5 GPa, nu = 0.3, h = 1 m, rho_w g = 1025 x 9.81): (D / rho_w g)^(1/4) by hand.
inline double lc_by_hand(double h) {
  const double D = 5e9 * h * h * h / (12 * (1 - 0.3 * 0.3));
  return std::pow(D / (1025 * 9.81), 0.25);
}

// PHYSICS.md §2.1 wedge table, P_f / (theta sigma_f h^2) and R_b / l_c, read linearly between alpha = 0.1, 0.2 and
// 0.3 (the fracture and level-ice tests' expected loads, never the module's own table).
inline double table_pf(double alpha) {
  const double a[] = {0.1, 0.2, 0.3}, p[] = {0.223, 0.265, 0.305};
  const int k = alpha < 0.2 ? 0 : 1;
  return p[k] + (alpha - a[k]) / (a[k + 1] - a[k]) * (p[k + 1] - p[k]);
}
inline double table_rb(double alpha) {
  const double a[] = {0.1, 0.2, 0.3}, r[] = {0.50, 0.61, 0.67};
  const int k = alpha < 0.2 ? 0 : 1;
  return r[k] + (alpha - a[k]) / (a[k + 1] - a[k]) * (r[k + 1] - r[k]);
}

// The ramp driven into ice: theta fixed at 60 deg, held at 0.1 m/s (the crushing force grows by ~6 kN per step once
// the face bites, sigma_c w 1 mm: 4 % of the load), 30 s. The ramp's centre of mass is 22.1 m behind its stem
// (waterline); the stem starts 0.9 m behind x = 0, so ice whose edge is at x = -0.4 meets the face within a few
// seconds.
// The coarse hull at 2 m/s (held) from x = -60 m into a 120 m x 120 m level ice sheet of 40 m tiles, 10 s: wedges
// break off within seconds (a short transit with fracture of a sheet).
inline SimulateOptions level_ice_transit_options() {
  SimulateOptions o = floe_options();
  o.vessel.propulsion.mode = "speed";
  o.vessel.propulsion.speed_mps = 2;
  o.vessel.initial_speed_mps = 2;
  o.vessel.x_m = -60;
  o.duration_s = 10;
  o.level_ice.extent_m = {0, -60, 120, 60};
  o.level_ice.tile_m = 40;
  return o;
}

inline SimulateOptions ramp_options() {
  SimulateOptions o = floe_options();
  o.fracture.wedge_angle_deg = {60, 60};
  o.vessel.vcg_m = -4;
  o.vessel.propulsion.mode = "speed";
  o.vessel.propulsion.speed_mps = 0.1;
  o.vessel.initial_speed_mps = 0.1;
  o.duration_s = 30;
  o.vessel.x_m = -23;
  return o;
}

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

// A fresh temporary directory for one test.
inline std::filesystem::path temp_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("floesim_sim_test_" + name);
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// Net contact force on body b this step (impulse / dt), world frame.
inline Vec3 contact_force_on(const World& w, int b) {
  Vec3 f = Vec3::Zero();
  const double dt = w.model().settings.time_step_s;
  for (const Contact& c : w.contacts()) {
    const Vec3 p = c.pn * c.normal + c.pt1 * c.t1 + c.pt2 * c.t2;
    if (c.body_b == b) f += p / dt;
    if (c.body_a == b) f -= p / dt;
  }
  return f;
}

}  // namespace floesim::sim::testing
