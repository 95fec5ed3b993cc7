#include "sim/engine/clearing.h"

#include <algorithm>
#include <map>
#include <set>

#include "pipeline/error.h"
#include "pipeline/results_io.h"

namespace floesim::sim {

namespace {

// The share of level_ice.clearing_depth_m left in contact after a clearing: the crushed face stays loaded.
constexpr double kKeptShare = 0.2;
// The tile's new outline loses vertices within this of a straight line (the footprint's round sides cut many).
constexpr double kCleanTolM = 1e-3;

// What a fixed structure does to one tile this step: the sum of its crushing contacts' normal impulses (world; from
// the structure into the ice), their force and where they act.
struct TilePress {
  Vec3 impulse = Vec3::Zero();
  Vec3 point_sum = Vec3::Zero();
  double weight = 0;
};

double extent_along(const Polygon& p, const Vec2& d) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Vec2& v : p) {
    lo = std::min(lo, v.dot(d));
    hi = std::max(hi, v.dot(d));
  }
  return p.empty() ? 0.0 : hi - lo;
}

}  // namespace

Polygon part_band_footprint(const ConvexPart& part, const Vec3& position, const Quat& orientation, double zlo,
                            double zhi) {
  const Mat3 R = orientation.toRotationMatrix();
  std::vector<Vec3> w(part.vertices.size());
  for (size_t i = 0; i < w.size(); ++i) w[i] = position + R * part.vertices[i];
  std::vector<Vec2> pts;
  for (const Vec3& p : w)
    if (p.z() >= zlo && p.z() <= zhi) pts.emplace_back(p.x(), p.y());
  for (const std::vector<int>& f : part.faces)
    for (size_t e = 0; e < f.size(); ++e) {
      const Vec3& a = w[f[e]];
      const Vec3& b = w[f[(e + 1) % f.size()]];
      for (double z : {zlo, zhi})
        if ((a.z() - z) * (b.z() - z) < 0) {
          const Vec3 p = a + (z - a.z()) / (b.z() - a.z()) * (b - a);
          pts.emplace_back(p.x(), p.y());
        }
    }
  return pts.size() >= 3 ? convex_hull_2d(pts) : Polygon{};
}

namespace {

// The clearings by hull body s (a fixed or compliant structure: Body::clears_ice), into cuts (tiles in cut_tiles
// are left alone; the ones cut join them).
void clear_for(const Model& model, const State& state, const std::vector<Contact>& contacts, int s,
               std::set<int>& cut_tiles, std::vector<FractureCut>& cuts) {
  // 1. The tiles the structure crushes, and how it presses on each.
  std::map<int, TilePress> press;
  for (const Contact& c : contacts) {
    if (c.type != ContactType::crushing || c.body_a != s || c.pn <= 0 || cut_tiles.count(c.body_b)) continue;
    const Body& tile = model.bodies[c.body_b];
    if (tile.kind != BodyKind::floe || !tile.fixed || !state.alive[c.body_b]) continue;
    TilePress& p = press[c.body_b];
    p.impulse += c.pn * c.normal;
    p.point_sum += c.pn * c.point;
    p.weight += c.pn;
  }
  const Body& structure = model.bodies[s];
  const double clear = model.settings.level_ice.clearing_depth_m, kept = kKeptShare * clear;
  const double dt = model.settings.time_step_s, rho_i = model.settings.ice.density_kg_m3;
  for (const auto& [b, p] : press) {
    const Vec2 d = p.impulse.head<2>();
    if (d.norm() <= 0) continue;
    const Vec2 dir = d.normalized();
    const Body& tile = model.bodies[b];
    const double h = tile.thickness_m;
    const Vec3& xt = state.position[b];
    const Mat3 Rt = state.orientation[b].toRotationMatrix();
    // 2. The structure's section at the tile's mid-plane, in the tile's frame, and how deep it is in the tile.
    const double zc = xt.z();
    std::vector<Polygon> footprints;
    double depth = 0, width = 0;
    const Vec2 dir_local = (Rt.transpose() * Vec3(dir.x(), dir.y(), 0)).head<2>().normalized();
    try {
      for (int k = 0; k < structure.part_count; ++k) {
        const Polygon world = part_band_footprint(model.parts[structure.first_part + k], state.position[s],
                                                  state.orientation[s], zc, zc);
        if (world.size() < 3) continue;
        Polygon local;
        for (const Vec2& v : world)
          local.push_back((Rt.transpose() * Vec3(v.x() - xt.x(), v.y() - xt.y(), 0)).head<2>());
        // The mean depth of the overlap: its area over its width across the pressing direction (a crescent of
        // depth d across a round front is d deep, though its horns reach back along the sides).
        double area = 0, across = 0;
        for (const Polygon& o : polygon_intersection(tile.outline, local)) {
          area += signed_area(o);
          across = std::max(across, extent_along(o, Vec2(-dir_local.y(), dir_local.x())));
        }
        if (across > 0) depth = std::max(depth, area / across);
        width = std::max(width, across);
        footprints.push_back(std::move(local));
      }
      if (depth <= clear) continue;
      // 3. The tile less the footprints moved back by the kept depth; leftovers that are chips are crushed too.
      std::vector<Polygon> rest = {tile.outline};
      for (const Polygon& f : footprints) {
        Polygon cutter;
        for (const Vec2& v : f) cutter.push_back(v - kept * dir_local);
        std::vector<Polygon> next;
        for (const Polygon& r : rest)
          for (Polygon& q : polygon_difference(r, cutter)) next.push_back(std::move(q));
        rest = std::move(next);
      }
      double kept_area = 0;
      FractureCut cut;
      for (Polygon& q : rest) {
        q = clean_polygon(q, kCleanTolM);
        if (q.size() < 3 || is_chip(q, h)) continue;
        kept_area += signed_area(q);
        cut.pieces.push_back(std::move(q));
      }
      const double crushed = signed_area(tile.outline) - kept_area;
      if (crushed <= 0) continue;
      cut.body = b;
      cut.wedge_pieces = 0;
      FractureEvent& e = cut.event;
      e.time_s = (state.step + 1) * dt;
      e.parent_id = tile.id;
      e.mode = kFractureCrushing;
      e.at_structure = true;
      e.force_n = p.impulse / dt;
      e.point_m = p.point_sum / p.weight;
      e.width_m = std::max(width, h);
      e.brash_mass_kg = rho_i * h * crushed;
      cuts.push_back(std::move(cut));
      cut_tiles.insert(b);
    } catch (const Error&) {
      // A cut the boolean operations cannot represent (a hole, a degenerate overlay): no clearing this step.
    }
  }
}

}  // namespace

std::vector<FractureCut> find_clearings(const Model& model, const State& state, const std::vector<Contact>& contacts) {
  std::vector<FractureCut> cuts;
  std::set<int> cut_tiles;  // a tile two structures crush in one step is cleared by the first
  for (int s = 0; s < model.hull_count(); ++s)
    if (model.bodies[s].clears_ice) clear_for(model, state, contacts, s, cut_tiles, cuts);
  return cuts;
}

}  // namespace floesim::sim
