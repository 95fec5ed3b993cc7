#include "sim/engine/ridge_punch.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <iomanip>
#include <vector>

#include "pipeline/error.h"
#include "pipeline/floes_io.h"
#include "sim/engine/model.h"
#include "sim/engine/ridge_build.h"
#include "sim/engine/world.h"
#include "sim/geometry/mesh.h"
#include "sim/vessel/hull.h"

namespace floesim::sim {

namespace {

constexpr double kHalf = 6.0;   // the box: 12 m x 12 m
constexpr double kPunch = 4.0;  // the punch: the sheet's middle tile
constexpr double kLayer = 0.5;  // h_c

// The box's settings: level ice with walls round it, the ridge across it, the punch as a fixed vessel beyond the east
// wall (moved into the sheet once the rubble has settled: a vessel over rubble at the start is refused).
EngineSettings punch_settings(const PunchSpec& p) {
  EngineSettings o;
  o.threads = p.threads;
  o.sleep.enabled = false;
  o.fracture.enabled = false;  // the sheet is the rig's frame
  o.level_ice.extent_m = {-kHalf, -kHalf, kHalf, kHalf};
  o.level_ice.thickness_m = kLayer;
  o.level_ice.tile_m = kPunch;  // the grid is centred on the sheet: its middle tile is the punch's place
  o.domain.extent_m = o.level_ice.extent_m;
  o.domain.walls = {"west", "east", "south", "north"};
  RidgeOptions r;
  r.line = {{0, -kHalf}, {0, kHalf}};
  r.sail_height_m = 0;
  r.keel_depth_m = p.keel_depth_m;
  r.keel_width_m = 2 * kHalf;
  r.keel_angle_deg = 85;
  r.consolidated_thickness_m = kLayer;
  r.porosity = 0.3;
  r.block_thickness_m = 0.4;
  r.block_size_m = {0.8, 1.6};
  r.seed = p.seed;
  o.ridges = {r};
  o.freeze_bonds.tensile_strength_pa = p.tensile_pa;
  o.freeze_bonds.shear_strength_pa = p.shear_pa;
  o.vessel.station_keeping.mode = "fixed";
  o.vessel.x_m = 50;
  o.vessel.y_m = 0;
  return o;
}

// The punch: a box kPunch x kPunch, h_c thick, floating as the sheet does (draft h_c rho_i / rho_w).
HullModel punch_hull(const EngineSettings& o) {
  const double a = kPunch / 2, draft = kLayer * o.ice.density_kg_m3 / o.water.density_kg_m3;
  const std::vector<Vec2> rect = {Vec2(-a, -a), Vec2(a, -a), Vec2(a, a), Vec2(-a, a)};
  HullModel h;
  h.parts = {extrude_polygon(rect, -draft, kLayer)};
  h.surface = h.parts[0];
  return h;
}

}  // namespace

PunchResult punch_test(const PunchSpec& p, std::ostream* progress) {
  FLOESIM_REQUIRE(p.speed_mps > 0 && p.travel_m > 0 && p.rest_s > 0 && p.window_s > 0,
                  "punch_test: speed, travel, rest and window must be > 0");
  const EngineSettings o = punch_settings(p);
  const HullModel hull = punch_hull(o);
  Model m = build_model(FloeField{}, &hull, o);
  const RidgeSettling settled = settle_ridges(FloeField{}, m, nullptr);
  const RidgeBuilt& built = settled.ridges.at(0);
  // The sheet's middle tile leaves the rig (moved far off: a fixed body, it never comes back), and the rubble's bonds
  // to it with it (the punch is not frozen to the plug: it pushes).
  std::vector<int> taken;
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    Body& body = m.bodies[b];
    if (body.ridge_part == RidgePart::layer && std::abs(body.initial_position.x()) < kPunch / 2 &&
        std::abs(body.initial_position.y()) < kPunch / 2) {
      body.initial_position.x() += 1000;
      taken.push_back(static_cast<int>(b));
    }
  }
  FLOESIM_REQUIRE(taken.size() == 1, "punch_test: expected the sheet's middle tile under the punch, found ",
                  taken.size());
  std::vector<FreezeBond> kept;
  for (const FreezeBond& fb : m.initial_bonds)
    if (fb.body_a != taken[0] && fb.body_b != taken[0]) kept.push_back(fb);
  m.initial_bonds = std::move(kept);
  World w(m);
  const int v = m.vessel;
  State& s0 = w.mutable_state();
  s0.position[v].x() = 0;
  s0.position[v].y() = 0;
  s0.velocity[v].setZero();
  w.sync();
  const double dt = o.time_step_s, rho_i = o.ice.density_kg_m3, rho_w = o.water.density_kg_m3;
  PunchResult r;
  r.blocks = settled.blocks;
  r.bonds = settled.bonds;
  r.settle_s = settled.time_s;
  r.keel_depth_middle_m = built.keel_depth_middle_m;
  r.plug_height_m = built.keel_depth_middle_m - kLayer * rho_i / rho_w;
  r.porosity = built.porosity_by_volume;
  r.gamma_e = (1 - r.porosity) * (rho_w - rho_i) * o.water.gravity_mps2;
  for (const Body& b : m.bodies)
    if (b.ridge_part == RidgePart::keel)
      r.rubble_buoyancy_n += (rho_w - rho_i) * o.water.gravity_mps2 * b.section_area * b.thickness_m;
  r.punch_m = kPunch;
  // The rest, then the push; the vertical load on the punch (the ice's on it: up is +z) over a moving window.
  const long rest_steps = std::lround(p.rest_s / dt), push_steps = std::lround(p.travel_m / p.speed_mps / dt);
  const long window = std::max(1L, std::lround(p.window_s / dt)), second = std::max(1L, std::lround(1.0 / dt));
  std::deque<double> recent;
  double sum = 0, residual_sum = 0;
  long residual_steps = 0;
  r.fpeak_n = -1e300;
  for (long k = 0; k < rest_steps + push_steps; ++k) {
    const bool pushing = k >= rest_steps;
    w.mutable_state().velocity[v] = pushing ? Vec3(0, 0, -p.speed_mps) : Vec3::Zero();
    w.step();
    const double fz = w.report().ice_load.force.z();
    recent.push_back(fz);
    sum += fz;
    if (static_cast<long>(recent.size()) > window) sum -= recent.front(), recent.pop_front();
    const double mean = sum / static_cast<double>(recent.size());
    if (k == rest_steps - 1) {  // the last window of the rest, and the rubble's balance
      r.f0_n = mean;
      for (const Contact& c : w.contacts()) {
        const Vec3 p = (c.pn * c.normal + c.pt1 * c.t1 + c.pt2 * c.t2) / dt;  // on b, from a
        const bool holds_a = c.body_a == v || is_fixed_body(m.bodies[c.body_a]);
        const bool holds_b = c.body_b == v || is_fixed_body(m.bodies[c.body_b]);
        if (holds_a && !holds_b) r.held_down_n -= p.z();
        if (holds_b && !holds_a) r.held_down_n += p.z();
      }
    }
    if (pushing && 3 * (k - rest_steps) >= 2 * push_steps) residual_sum += fz, ++residual_steps;
    if (pushing && k - rest_steps + 1 >= window && mean > r.fpeak_n) {  // windows of the push alone
      r.fpeak_n = mean;
      r.peak_at_m = (k + 1 - rest_steps) * dt * p.speed_mps;
    }
    if (progress && (k + 1) % second == 0)
      *progress << "  t " << std::fixed << std::setprecision(1) << (k + 1) * dt << " s: punch "
                << (pushing ? "moving" : "at rest") << ", load " << mean / 1e3 << " kN (window mean), "
                << w.state().bonds.size() << " bonds left" << std::defaultfloat << std::endl;
  }
  r.bonds_broken = w.state().bonds_broken;
  r.f0_by_hand_n = r.gamma_e * kPunch * kPunch * r.plug_height_m;
  r.tau_pa = (r.fpeak_n - r.f0_n) / (4 * kPunch * r.plug_height_m);
  r.fresidual_n = residual_steps > 0 ? residual_sum / static_cast<double>(residual_steps) : r.f0_n;
  r.tau_residual_pa = (r.fresidual_n - r.f0_n) / (4 * kPunch * r.plug_height_m);
  return r;
}

}  // namespace floesim::sim
