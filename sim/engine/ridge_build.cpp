#include "sim/engine/ridge_build.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <map>
#include <memory>

#include "pipeline/error.h"
#include "sim/engine/world.h"

namespace floesim::sim {

namespace {

constexpr double kPackCheckS = 1.0;  // how often packing measures each ridge's porosity

// Whether world point p lies in block b at pose (x, q): inside its slab and its (convex) outline.
bool block_holds(const Body& b, const Vec3& x, const Mat3& R, const Vec3& p) {
  const Vec3 l = R.transpose() * (p - x);
  if (std::abs(l.z()) > 0.5 * b.thickness_m) return false;
  const Polygon& o = b.outline;
  for (size_t i = 0; i < o.size(); ++i) {
    const Vec2 e = o[(i + 1) % o.size()] - o[i], d = Vec2(l.x(), l.y()) - o[i];
    if (e.x() * d.y() - e.y() * d.x() < 0) return false;
  }
  return true;
}

}  // namespace

RidgeBuilt measure_ridge(const Model& m, const State& st, int ridge, double voxel) {
  FLOESIM_REQUIRE(ridge >= 0 && ridge < static_cast<int>(m.settings.ridges.size()), "measure_ridge: no ridge ", ridge);
  FLOESIM_REQUIRE(voxel > 0, "measure_ridge: the voxel edge must be > 0, got ", voxel);
  const RidgeOptions& r = m.settings.ridges[ridge];
  const Vec2 a(r.line[0].x_m, r.line[0].y_m), b(r.line[1].x_m, r.line[1].y_m);
  const double length = (b - a).norm();
  const Vec2 t = (b - a) / length, n(-t.y(), t.x());
  RidgeBuilt out;
  // 1. The ridge's bodies: the ice under and over the waterline, the layer's level, the blocks' extremes.
  struct Block {
    int body;
    Vec3 x;
    Mat3 R;
    double s_lo, s_hi, t_lo, t_hi, z_lo, z_hi;
    bool keel;
  };
  std::vector<Block> blocks;
  double layer_area = 0, layer_bottom = 0, layer_top = 0;
  std::vector<Vec3> world;
  for (size_t k = 0; k < m.bodies.size(); ++k) {
    const Body& body = m.bodies[k];
    if (!st.alive[k] || body.ridge != ridge) continue;
    const Vec3& x = st.position[k];
    const Mat3 R = st.orientation[k].toRotationMatrix();
    world.clear();
    for (const Vec3& v : body.buoyancy_mesh.vertices) world.push_back(x + R * v);
    const double volume = body.section_area * body.thickness_m;
    const double below = std::min(volume, submerged_part(world, body.buoyancy_mesh.triangles, 0.0).volume);
    out.ice_below_m3 += below;
    out.ice_above_m3 += volume - below;
    if (body.ridge_part == RidgePart::layer) {
      layer_area += body.section_area;
      layer_bottom += body.section_area * (x.z() - 0.5 * body.thickness_m);
      layer_top += body.section_area * (x.z() + 0.5 * body.thickness_m);
      continue;
    }
    ++out.blocks;
    out.max_block_speed_mps = std::max(out.max_block_speed_mps, st.velocity[k].norm());
    Block bl{static_cast<int>(k), x, R, 1e300, -1e300, 1e300, -1e300, 1e300, -1e300,
             body.ridge_part == RidgePart::keel};
    for (const Vec3& p : world) {
      const Vec2 d = p.head<2>() - a;
      bl.s_lo = std::min(bl.s_lo, d.dot(n)), bl.s_hi = std::max(bl.s_hi, d.dot(n));
      bl.t_lo = std::min(bl.t_lo, d.dot(t)), bl.t_hi = std::max(bl.t_hi, d.dot(t));
      bl.z_lo = std::min(bl.z_lo, p.z()), bl.z_hi = std::max(bl.z_hi, p.z());
    }
    if (bl.keel) out.keel_depth_m = std::max(out.keel_depth_m, -bl.z_lo);
    else out.sail_height_m = std::max(out.sail_height_m, bl.z_hi);
    const double tc = (x.head<2>() - a).dot(t);
    if (tc >= 0 && tc <= length) blocks.push_back(bl);
  }
  FLOESIM_REQUIRE(layer_area > 0, "measure_ridge: ridge ", ridge, " has no consolidated layer left");
  out.layer_bottom_z = layer_bottom / layer_area;
  out.layer_top_z = layer_top / layer_area;
  if (blocks.empty()) return out;
  // 2. Voxel columns over the blocks' extent across the line, the segment along it; each column's candidates from
  // buckets of the blocks' plan extents.
  double s_lo = 1e300, s_hi = -1e300, z_lo = out.layer_bottom_z, z_hi = out.layer_top_z;
  for (const Block& bl : blocks)
    s_lo = std::min(s_lo, bl.s_lo), s_hi = std::max(s_hi, bl.s_hi), z_lo = std::min(z_lo, bl.z_lo),
    z_hi = std::max(z_hi, bl.z_hi);
  s_lo = voxel * std::floor(s_lo / voxel), s_hi = voxel * std::ceil(s_hi / voxel);
  const int ns = static_cast<int>(std::lround((s_hi - s_lo) / voxel));
  const int nt = std::max(1, static_cast<int>(std::ceil(length / voxel)));
  const double dt = length / nt;
  // Keel levels down from the highest keel block's top (blocks spread under thinner ice beside the layer rest
  // higher than its bottom); sail levels up from the layer's top.
  double keel_top = -1e300;
  for (const Block& bl : blocks)
    if (bl.keel) keel_top = std::max(keel_top, bl.z_hi);
  const int nk = keel_top > z_lo ? static_cast<int>(std::ceil((keel_top - z_lo) / voxel)) : 0;
  const int nu = static_cast<int>(std::ceil((z_hi - out.layer_top_z) / voxel));     // sail levels, up
  const double bucket = 2.0;
  const int bs = static_cast<int>(std::ceil((s_hi - s_lo) / bucket)) + 1, bt = static_cast<int>(length / bucket) + 1;
  std::vector<std::vector<int>> buckets(static_cast<size_t>(bs) * bt);
  for (size_t i = 0; i < blocks.size(); ++i) {
    const Block& bl = blocks[i];
    const int s0 = std::max(0, static_cast<int>((bl.s_lo - s_lo) / bucket));
    const int s1 = std::min(bs - 1, static_cast<int>((bl.s_hi - s_lo) / bucket));
    const int t0 = std::max(0, static_cast<int>(std::floor(bl.t_lo / bucket)));
    const int t1 = std::min(bt - 1, static_cast<int>(std::floor(bl.t_hi / bucket)));
    for (int q = t0; q <= t1; ++q)
      for (int p = s0; p <= s1; ++p) buckets[static_cast<size_t>(q) * bs + p].push_back(static_cast<int>(i));
  }
  out.profile_s_m.resize(ns);
  out.keel_bottom_z.assign(ns, 0.0);
  out.sail_top_z.assign(ns, 0.0);
  long envelope = 0, solid = 0;
  std::vector<double> middle(ns, 0.0);  // the keel's bottom over the middle half of the line
  std::vector<int> middle_n(ns, 0);
  for (int is = 0; is < ns; ++is) {
    const double s = s_lo + (is + 0.5) * voxel;
    out.profile_s_m[is] = s;
    for (int it = 0; it < nt; ++it) {
      const double u = (it + 0.5) * dt;
      const std::vector<int>& cand =
          buckets[static_cast<size_t>(std::min(bt - 1, static_cast<int>(u / bucket))) * bs +
                  std::min(bs - 1, static_cast<int>((s - s_lo) / bucket))];
      const Vec2 p = a + u * t + s * n;
      auto solid_at = [&](double z, bool keel) {
        for (int i : cand) {
          const Block& bl = blocks[i];
          if (bl.keel == keel && z >= bl.z_lo && z <= bl.z_hi &&
              block_holds(m.bodies[bl.body], bl.x, bl.R, Vec3(p.x(), p.y(), z)))
            return true;
        }
        return false;
      };
      // The keel: from the ice's underside (the layer's bottom within its width; beside it, where rubble spread
      // under thinner ice, the highest keel block) down to the deepest keel block, and the solid levels between.
      const bool under_layer = std::abs(s) <= 0.5 * r.keel_width_m;
      const int layer_level = std::max(0, static_cast<int>(std::floor((keel_top - out.layer_bottom_z) / voxel)));
      int top = under_layer ? layer_level : -1, deepest = -1, count = 0;
      for (int k = 0; k < nk; ++k)
        if (solid_at(keel_top - (k + 0.5) * voxel, true)) {
          if (top < 0) top = k;
          deepest = k;
          count += k >= top;
        }
      envelope += deepest >= top ? deepest - top + 1 : 0;
      solid += count;
      const double bottom = deepest >= 0 ? keel_top - (deepest + 1) * voxel : out.layer_bottom_z;
      out.keel_bottom_z[is] += bottom;
      if (4 * it >= nt && 4 * it < 3 * nt) middle[is] += bottom, ++middle_n[is];
      int highest = -1;
      for (int k = nu - 1; k >= 0 && highest < 0; --k)
        if (solid_at(out.layer_top_z + (k + 0.5) * voxel, false)) highest = k;
      out.sail_top_z[is] += out.layer_top_z + (highest + 1) * voxel;
      out.sail_area_m2 += (highest + 1) * voxel * voxel / nt;
    }
    out.keel_bottom_z[is] /= nt;
    out.sail_top_z[is] /= nt;
    if (middle_n[is] > 0) out.keel_depth_middle_m = std::max(out.keel_depth_middle_m, -middle[is] / middle_n[is]);
  }
  const double envelope_m3 = envelope * voxel * voxel * dt;
  out.keel_area_m2 = envelope_m3 / length;
  double keel_m3 = 0;
  for (const Block& bl : blocks)
    if (bl.keel) keel_m3 += m.bodies[bl.body].section_area * m.bodies[bl.body].thickness_m;
  out.porosity_by_volume = envelope > 0 ? 1 - keel_m3 / envelope_m3 : 1.0;
  out.porosity_by_voxels = envelope > 0 ? 1 - static_cast<double>(solid) / static_cast<double>(envelope) : 1.0;
  return out;
}

std::vector<FreezeBond> freeze_touching(const Model& model, const State& state, const std::vector<Contact>& contacts,
                                        const std::vector<uint8_t>& freezes, const FreezeBondOptions& o) {
  std::vector<FreezeBond> bonds;
  for (size_t i = 0; i < contacts.size();) {
    // The contact points of one body pair (contacts come sorted by pair).
    size_t e = i;
    while (e < contacts.size() && contacts[e].body_a == contacts[i].body_a && contacts[e].body_b == contacts[i].body_b)
      ++e;
    const Contact& c0 = contacts[i];
    const int a = c0.body_a, b = c0.body_b;
    if (!freezes[a] || !freezes[b] || c0.type != ContactType::rigid) {
      i = e;
      continue;
    }
    // Their polygon's area in the plane of the mean normal.
    Vec3 n = Vec3::Zero();
    for (size_t k = i; k < e; ++k) n += contacts[k].normal;
    n.normalize();
    const Vec3 u = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized(), v = n.cross(u);
    Polygon pts;
    for (size_t k = i; k < e; ++k) pts.push_back(Vec2(contacts[k].point.dot(u), contacts[k].point.dot(v)));
    const Polygon hull = pts.size() >= 3 ? convex_hull_2d(pts) : Polygon();
    const double area = std::max(hull.size() >= 3 ? std::abs(signed_area(hull)) : 0.0, o.min_area_m2);
    Vec3 point = Vec3::Zero();
    for (size_t k = i; k < e; ++k) point += contacts[k].point;
    point /= static_cast<double>(e - i);
    const Quat qa_inv = state.orientation[a].conjugate(), qb_inv = state.orientation[b].conjugate();
    FreezeBond fb;
    fb.body_a = a;
    fb.body_b = b;
    fb.anchor_a = qa_inv * (point - state.position[a]);
    fb.anchor_b = qb_inv * (point - state.position[b]);
    fb.normal_a = (qa_inv * n).normalized();
    fb.area_m2 = area;
    bonds.push_back(fb);
    i = e;
  }
  return bonds;
}

RidgeSettling settle_ridges(const FloeField& field, Model& model, std::ostream* progress) {
  RidgeSettling out;
  if (model.settings.ridges.empty()) return out;
  const RidgeSettlingOptions& rs = model.settings.ridge_settling;
  // 1. The settling world: the floes and ridges without hulls, fracture off, the water at rest in the ice's frame.
  EngineSettings o = model.settings;
  o.fracture.enabled = false;
  o.structures.clear();
  o.water.current_speed_mps = o.drift.speed_mps;
  o.water.current_direction_deg = o.drift.direction_deg;
  o.wind.speed_mps = 0;
  // 2. Packing: each ridge's blocks frictionless among themselves until its keel is as porous as designed (its
  // porosity, measured every kPackCheckS) or for pack_max_s, so that it packs as a keel packs by creep and by waves,
  // not jammed loose where its blocks first met (the shear box's sample packs so too, sim/engine/ridge_shear_box.cpp);
  // against the layer and the sheet they keep their friction, which holds the pile from flowing out under the ice.
  // The world is rebuilt whenever a ridge has packed (the bodies' friction is the model's), its bodies where they
  // are, moving as they move.
  const auto t0 = std::chrono::steady_clock::now();
  const double dt = o.time_step_s;
  const long report_every = std::max(1L, std::lround(10.0 / dt));
  const long check_every = std::max(1L, std::lround(kPackCheckS / dt));
  std::vector<uint8_t> packing(o.ridges.size(), rs.pack_max_s > 0);
  std::vector<double> packed_s(o.ridges.size(), 0.0);
  auto make_world = [&](const State* from) {
    Model next = build_model(field, nullptr, o);
    for (size_t b = 0; b < next.bodies.size(); ++b) {
      Body& body = next.bodies[b];
      body.frictionless = body.ridge >= 0 && body.ridge_part != RidgePart::layer && packing[body.ridge];
      if (from) body.initial_position = from->position[b], body.initial_orientation = from->orientation[b];
    }
    auto world = std::make_unique<World>(std::move(next));
    if (from) {
      State& st = world->mutable_state();
      st.velocity = from->velocity;
      st.angular_velocity = from->angular_velocity;
      world->sync();
    }
    return world;
  };
  std::unique_ptr<World> w = make_world(nullptr);
  while (std::find(packing.begin(), packing.end(), 1) != packing.end()) {
    w->step();
    ++out.steps;
    if (out.steps % check_every != 0) continue;
    const double t = out.steps * dt;
    bool packed = false;
    for (size_t r = 0; r < packing.size(); ++r) {
      if (!packing[r]) continue;
      const double e = measure_ridge(w->model(), w->state(), static_cast<int>(r), rs.voxel_m).porosity_by_volume;
      if (progress && out.steps % report_every == 0)
        *progress << "  packing the ridges' rubble (frictionless): t = " << std::fixed << std::setprecision(1) << t
                  << " s, ridge " << r << " porosity " << std::setprecision(3) << e << std::defaultfloat << std::endl;
      if (e <= o.ridges[r].porosity || t >= rs.pack_max_s) packing[r] = 0, packed_s[r] = t, packed = true;
    }
    if (packed) w = make_world(&w->state());
  }
  const Model& m = w->model();
  std::vector<int> rubble;
  for (size_t b = 0; b < m.bodies.size(); ++b)
    if (m.bodies[b].ridge_part == RidgePart::keel || m.bodies[b].ridge_part == RidgePart::sail)
      rubble.push_back(static_cast<int>(b));
  out.blocks = static_cast<int>(rubble.size());
  // 3. Then with friction until every block has been at rest for rest_time_s.
  const long max_steps = std::lround(rs.max_s / dt), rest_steps = std::lround(rs.rest_time_s / dt);
  long at_rest = 0;
  double fastest = 0;
  std::vector<uint8_t> touching;
  while (at_rest < rest_steps) {
    FLOESIM_REQUIRE(out.steps < max_steps, "ridge_settling.max_s: the ridges' rubble is not at rest after ",
                    rs.max_s, " s of settling (the fastest block moves at ", fastest,
                    " m/s): raise ridge_settling.max_s or ridge_settling.rest_speed_mps");
    w->step();
    ++out.steps;
    // A block touching nothing that neither heaves nor turns floats at its equilibrium: out of the ridge (it came
    // out from under the ice), a floe that quadratic drag stops only slowly. Its drift is not the ridge settling.
    touching.assign(m.bodies.size(), 0);
    for (const Contact& c : w->contacts()) touching[c.body_a] = touching[c.body_b] = 1;
    fastest = 0;
    for (int b : rubble) {
      if (!w->state().alive[b]) continue;
      const Vec3& v = w->state().velocity[b];
      fastest = std::max({fastest, touching[b] ? v.norm() : std::abs(v.z()), w->state().angular_velocity[b].norm()});
    }
    at_rest = fastest < rs.rest_speed_mps ? at_rest + 1 : 0;
    if (progress && out.steps % report_every == 0)
      *progress << "  settling the ridges: t = " << std::fixed << std::setprecision(1)
                << out.steps * dt << " s, fastest block " << std::setprecision(3) << fastest
                << " m/s, awake floes " << w->report().awake_floes << std::defaultfloat << std::endl;
  }
  // 4. Freeze bonds: the blocks woken for one more step, so that every pair that touches is found (a pair of
  // sleepers is not looked at), and frozen at the poses that step found them in, to each other and to the layer.
  std::vector<FreezeBond> bonds;
  if (o.freeze_bonds.enabled()) {
    for (int b : rubble) w->wake(b);
    const State before = w->state();
    w->step();
    ++out.steps;
    std::vector<uint8_t> freezes(m.bodies.size(), 0);
    for (size_t b = 0; b < m.bodies.size(); ++b) freezes[b] = m.bodies[b].ridge_part != RidgePart::none;
    bonds = freeze_touching(m, before, w->contacts(), freezes, o.freeze_bonds);
  }
  out.time_s = out.steps * dt;
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // 5. The settled poses and the bonds into the run's model, by id; they start asleep where floes may.
  std::map<int, int> index_of;
  for (size_t b = 0; b < model.bodies.size(); ++b)
    if (model.bodies[b].ridge_part == RidgePart::keel || model.bodies[b].ridge_part == RidgePart::sail)
      index_of[model.bodies[b].id] = static_cast<int>(b);
  FLOESIM_REQUIRE(index_of.size() == rubble.size(), "internal: the settling world has ", rubble.size(),
                  " blocks, the run's model ", index_of.size());
  for (int b : rubble) {
    const auto it = index_of.find(m.bodies[b].id);
    FLOESIM_REQUIRE(it != index_of.end(), "internal: block ", m.bodies[b].id, " is not in the run's model");
    Body& target = model.bodies[it->second];
    target.initial_position = w->state().position[b];
    target.initial_orientation = w->state().orientation[b];
    target.start_awake = false;
  }
  model.initial_bonds.clear();
  std::map<int, int> ridge_index_of;  // the layers' bodies too
  for (size_t b = 0; b < model.bodies.size(); ++b)
    if (model.bodies[b].ridge_part != RidgePart::none) ridge_index_of[model.bodies[b].id] = static_cast<int>(b);
  for (FreezeBond fb : bonds) {
    fb.body_a = ridge_index_of.at(m.bodies[fb.body_a].id);
    fb.body_b = ridge_index_of.at(m.bodies[fb.body_b].id);
    if (fb.body_a > fb.body_b) {
      std::swap(fb.body_a, fb.body_b);
      std::swap(fb.anchor_a, fb.anchor_b);
      fb.normal_a = -(model.bodies[fb.body_a].initial_orientation.conjugate() *
                      (model.bodies[fb.body_b].initial_orientation * fb.normal_a));
    }
    model.initial_bonds.push_back(fb);
  }
  out.bonds = static_cast<int>(bonds.size());
  for (size_t r = 0; r < o.ridges.size(); ++r) {
    out.ridges.push_back(measure_ridge(m, w->state(), static_cast<int>(r), rs.voxel_m));
    out.ridges.back().packed_s = packed_s[r];
  }
  return out;
}

}  // namespace floesim::sim
