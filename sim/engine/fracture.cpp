#include "sim/engine/fracture.h"

#include <algorithm>
#include <cmath>

#include "pipeline/error.h"
#include "pipeline/results_io.h"
#include "sim/engine/fracture_laws.h"

namespace floesim::sim {

namespace {

constexpr double kDegToRad = kPi / 180.0;

// SplitMix64 (Steele, Lea & Flood 2014): a counter-based generator, so a draw depends only on its key (no shared
// generator state, hence independent of the order in which floes are visited).
uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

Vec2 perp(const Vec2& v) { return Vec2(-v.y(), v.x()); }

// The contacts of one floe with one other body (the vessel or another floe), summed.
struct PairLoad {
  int floe = -1, other = -1;
  bool at_structure = false;
  Vec3 force = Vec3::Zero();       // on the floe, world
  Vec3 normal = Vec3::Zero();      // into the floe, weighted by the normal impulses
  Vec3 point = Vec3::Zero();       // normal-impulse-weighted mean contact point
  double weight = 0;               // sum of the normal impulses
  std::vector<Vec3> span;          // extreme points of the contact surfaces
};

// One floe's candidate failure at one pair, with what the cut needs.
struct Candidate {
  double ratio = 0;                // load / threshold of the governing mode (>= 1 fails)
  int32_t mode = kFractureNone;
  double threshold = 0, theta = 0, width = 0, lc = 0, rb = 0, apex_distance = 0;
  Vec2 point = Vec2::Zero();       // body frame
  Vec2 direction = Vec2::Zero();   // wedge axis (into the floe) or split line, body frame, unit
};

// Out-of-plane and in-plane failure of one floe under one pair load (PHYSICS.md §2.1-2.4).
Candidate evaluate(const Model& model, const State& state, const PairLoad& pl, long step) {
  const FractureOptions& fo = model.settings.fracture;
  const Body& body = model.bodies[pl.floe];
  const double h = body.thickness_m;
  const Mat3 R = state.orientation[pl.floe].toRotationMatrix();
  const Vec3 x = state.position[pl.floe];
  // The plate's own frame: out-of-plane is the body z axis (a tilted floe bends about its own plane).
  const Vec3 f_local = R.transpose() * pl.force;
  const Vec3 p3 = R.transpose() * (pl.point - x);
  const Vec3 n3 = R.transpose() * pl.normal;
  Candidate c;
  c.point = Vec2(p3.x(), p3.y());
  const Vec2 f_h(f_local.x(), f_local.y());
  Vec2 inward(n3.x(), n3.y());
  const bool edge = inward.norm() > 0.1 * n3.norm() && n3.norm() > 0;  // not a floe under a flat bottom
  if (edge) inward.normalize();
  // The hull bends the ice down (§2.4: F_V on a sloped face); between floes either one may ride over the other.
  const double f_v = pl.at_structure ? -f_local.z() : std::abs(f_local.z());

  // Contact width across the inward normal, from the contact surfaces, never below h (§2.1: thin-plate theory
  // does not resolve narrower loads).
  double width = h;
  if (edge) {
    const Vec2 t = perp(inward);
    double lo = 1e300, hi = -1e300;
    for (const Vec3& s : pl.span) {
      const Vec3 sl = R.transpose() * (s - x);
      const double u = t.dot(Vec2(sl.x(), sl.y()));
      lo = std::min(lo, u);
      hi = std::max(hi, u);
    }
    if (hi > lo) width = std::max(width, hi - lo);
  }
  c.width = width;

  // The plate's wedge under this load (§2.1): it sets the bending threshold and the piece, and its R_b is the
  // smallest floe that still splits (below).
  const double rho_w_g = model.settings.water.density_kg_m3 * model.settings.water.gravity_mps2;
  double lc = 0, theta = 0, alpha = 0;
  WedgeFailure wf;
  if (rho_w_g > 0) {
    lc = characteristic_length_m(fo.youngs_modulus_pa, fo.poisson_ratio, h, rho_w_g);
    theta = wedge_angle_rad(fo, body.id, step);
    alpha = width / (theta * lc);  // a = w / theta: the load spread over the wedge's arc
    wf = wedge_failure(theta, fo.flexural_strength_pa, h, alpha);
  }

  // 1. Out-of-plane: radial cracks at P_r, the wedge's circumferential crack at P_f; the larger governs (§2.3).
  double r_bend = 0;
  Candidate bend = c;
  if (edge && f_v > 0 && rho_w_g > 0) {
    const double pr = radial_crack_load_n(fo.flexural_strength_pa, h, width / lc);
    double rb = static_piece_rb_m(fo, wf.rb_over_lc, lc);
    if (fo.speed_correction) {
      // Approach speed of the other body into the floe at the contact point.
      const Vec3 r_f = pl.point - x, r_o = pl.point - state.position[pl.other];
      const Vec3 v_rel = state.velocity[pl.other] + state.angular_velocity[pl.other].cross(r_o) -
                         state.velocity[pl.floe] - state.angular_velocity[pl.floe].cross(r_f);
      const double vn = std::max(0.0, v_rel.dot(pl.normal.normalized()));
      rb *= std::max(0.1, 1 + fo.speed_coefficient_spm * vn);  // never below a tenth of the static piece
    }
    // The check below stays Nevel's xi* even for the empirical piece: whether the floe bends as a wedge (and
    // at what load) is the plate's mechanics; only where the circumferential crack runs is replaced.
    // A floe shorter than the wedge (apex -> crack) along the load does not bend as a wedge (§2.1, finite floes):
    // it tilts, submerges or splits instead. Level ice cannot tilt away: a cusp left between two earlier cracks
    // is held by the sheet and breaks off whole (the wedge's cut takes what of it lies inside).
    const double extent = chord_length(body.outline, c.point, inward);
    if (body.fixed || extent >= wf.xi_star * lc) {
      bend.threshold = std::max(pr, wf.load_n);
      bend.mode = pr >= wf.load_n ? kFractureRadial : kFractureBending;
      bend.theta = theta;
      bend.lc = lc;
      bend.rb = rb;
      bend.apex_distance = alpha * lc;
      bend.direction = inward;
      r_bend = f_v / bend.threshold;
      bend.ratio = r_bend;
    }
  }

  // 2. In-plane splitting along the force line, through the contact point (§2.2), when the force pushes in.
  double r_split = 0;
  Candidate split = c;
  const double fh = f_h.norm();
  // Level ice does not split: the in-plane load of a hull is carried by the semi-infinite sheet around the tile
  // (its chord L is not the tile's), and a sheet fails in bending at the hull (PHYSICS.md §2.4).
  if (!body.fixed && fh > 0 && (!edge || f_h.dot(inward) > 0)) {
    const Vec2 d = f_h / fh;
    // The contact point lies in the overlap, at the edge: if rounding puts it just outside the outline, the chord
    // is taken from a point nudged into the floe along the force.
    double length = chord_length(body.outline, c.point, d);
    Vec2 at = c.point;
    for (int k = 1; k <= 4 && length <= 0; ++k) {
      at = c.point + (0.25 * k * width) * d;
      length = chord_length(body.outline, at, d);
    }
    // Metrikin's rule (PHYSICS.md §2.2, [READ]): a floe splits only if its chord is at least the bending radius
    // R_b; a smaller piece is a block that moves, tilts or crushes (without it, the broken ice under the bow would
    // split again and again into ever smaller pieces within a few steps).
    const double min_chord = rho_w_g > 0 ? wf.rb_over_lc * lc : 0.0;
    if (length > 0 && length >= min_chord) {
      split.threshold = splitting_load_n(fo.splitting_coefficient, fo.fracture_toughness_pa_sqrtm, h, length);
      split.mode = kFractureSplitting;
      split.point = at;
      split.direction = d;
      r_split = fh / split.threshold;
      split.ratio = r_split;
    }
  }
  // §2.4: the mode of the lower threshold for this force's direction is the one with the larger load ratio.
  if (r_bend >= r_split) return bend;
  return split;
}

bool any_brash(const std::vector<Polygon>& pieces, double thickness_m, double min_area_m2) {
  for (const Polygon& p : pieces)
    if (is_brash(p, thickness_m, min_area_m2)) return true;
  return false;
}

// fracture.small_wedge "enlarge": the wedge of the smallest R_b >= rb whose pieces are none of them brash (to 1e-6
// of R_b), by doubling and then bisection (the wedge only grows with R_b), its R_b in `rb_out`; `wedge` (at rb) if
// even a wedge reaching across the whole floe is brash. wedge_of(R_b) cuts the floe.
template <class WedgeOf>
PolygonCut smallest_kept_wedge(WedgeOf wedge_of, double rb, double thickness_m, double min_area_m2,
                               const PolygonCut& wedge, double& rb_out) {
  rb_out = rb;
  auto kept = [&](const PolygonCut& w) {
    return !w.inside.empty() && !w.outside.empty() && !any_brash(w.inside, thickness_m, min_area_m2);
  };
  double lo = rb, hi = rb;
  PolygonCut best;
  for (int k = 0; k < 20; ++k) {  // up to 2^20 R_b: beyond any floe the contact can break
    hi *= 2;
    best = wedge_of(hi);
    if (kept(best)) break;
    if (best.outside.empty()) return wedge;  // the wedge took the whole floe and is still brash
    lo = hi;
  }
  if (!kept(best)) return wedge;
  rb_out = hi;
  while (hi - lo > 1e-6 * rb) {
    const double mid = 0.5 * (lo + hi);
    PolygonCut w = wedge_of(mid);
    if (kept(w)) {
      hi = rb_out = mid;
      best = std::move(w);
    } else {
      lo = mid;
    }
  }
  return best;
}

// The pieces of a decided failure, in the floe's body frame, and the R_b of a wedge as cut (`rb_cut`: c.rb, or
// larger with fracture.small_wedge "enlarge"); empty when the cut leaves the floe whole or cannot be
// made (a piece below the minimum size of a split, a degenerate boolean result).
std::vector<Polygon> cut(const Body& body, const Candidate& c, const FractureOptions& fo, int* wedge_pieces,
                         double* rb_cut) {
  std::vector<Polygon> pieces;
  *wedge_pieces = 0;
  *rb_cut = c.rb;
  try {
    if (c.mode == kFractureSplitting) {
      const LineSplit s = split_by_line(body.outline, c.point, c.direction);
      if (s.left.empty() || s.right.empty()) return {};
      pieces = s.left;
      pieces.insert(pieces.end(), s.right.begin(), s.right.end());
      // A split that leaves a sliver is no split (Metrikin's rule, PHYSICS.md §2.2): the floe crushes instead.
      if (any_brash(pieces, body.thickness_m, fo.min_piece_area_m2)) return {};
    } else {
      // The wedge: apex a = alpha l_c behind the contact point (outside the ice), radial cracks at +-theta/2 about
      // the inward normal, the circumferential crack R_b beyond the load point, so its radius about the apex is
      // a + R_b (Nevel's xi* l_c; with the empirical piece C_l l_c (1 + C_v v_n) + a: the apex stays Nevel's,
      // set by the contact width, and the piece's reach from the load point is the empirical R_b). The crack is cut as two straight
      // cracks meeting on the axis at R_b, the radial cracks as long as makes the piece's area the sector's
      // (equal_area_wedge): the piece reaches as far and weighs as much as Nevel's sector. The arc itself (16
      // chords) notched the floe left behind at 17 reflex corners, so it became a body of ~10 convex parts (68
      // after repeated bites), and the bow's rubble of such bodies had 4x the contacts of the field without
      // fracture (floesim-bench: fracture_speed_ratio 0.26, with the kite 0.45). The crack's shape is not
      // resolved finer than that by the closed-form laws anyway.
      const Vec2 apex = c.point - c.apex_distance * c.direction;
      auto wedge_of = [&](double rb) {
        return cut_polygon(body.outline, equal_area_wedge(apex, c.direction, 0.5 * c.theta, c.apex_distance + rb));
      };
      PolygonCut wedge = wedge_of(c.rb);
      if (fo.small_wedge == "enlarge" && any_brash(wedge.inside, body.thickness_m, fo.min_piece_area_m2))
        wedge = smallest_kept_wedge(wedge_of, c.rb, body.thickness_m, fo.min_piece_area_m2, wedge, *rb_cut);
      if (wedge.inside.empty() || wedge.outside.empty()) return {};
      pieces = wedge.inside;
      *wedge_pieces = static_cast<int>(wedge.inside.size());
      pieces.insert(pieces.end(), wedge.outside.begin(), wedge.outside.end());
    }
  } catch (const Error&) {
    return {};  // a cut the boolean operations cannot represent (a hole): the floe stays whole this step
  }
  // The pieces must tile the floe: guard against a boolean result that lost or made area.
  double sum = 0;
  for (const Polygon& p : pieces) sum += signed_area(p);
  const double area = signed_area(body.outline);
  if (!(std::abs(sum - area) <= 1e-9 * area)) return {};
  return pieces;
}

// The contacts of one pair (indices into shares, each naming a contact) in patches: two contacts share a patch when
// their horizontal extents (span_lo - span_hi) come within join_m of each other (union-find; patches in the order
// of their first contact, contacts in their order: deterministic).
template <class Share>
std::vector<std::vector<size_t>> contact_patches(const std::vector<Contact>& contacts, const std::vector<Share>& shares,
                                                 const std::vector<size_t>& pair, double join_m) {
  const size_t n = pair.size();
  std::vector<size_t> root(n);
  for (size_t k = 0; k < n; ++k) root[k] = k;
  auto find = [&](size_t k) {
    while (root[k] != k) k = root[k] = root[root[k]];
    return k;
  };
  auto flat = [](const Vec3& v) { return Vec2(v.x(), v.y()); };
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n; ++b) {
      const Contact& ca = contacts[shares[pair[a]].contact];
      const Contact& cb = contacts[shares[pair[b]].contact];
      const Vec2 a0 = flat(ca.span_lo), a1 = flat(ca.span_hi), b0 = flat(cb.span_lo), b1 = flat(cb.span_hi);
      const double d = std::min({point_segment_distance(a0, b0, b1), point_segment_distance(a1, b0, b1),
                                 point_segment_distance(b0, a0, a1), point_segment_distance(b1, a0, a1)});
      if (d <= join_m) {
        const size_t ra = find(a), rb = find(b);
        if (ra != rb) root[std::max(ra, rb)] = std::min(ra, rb);
      }
    }
  std::vector<std::vector<size_t>> groups;
  std::vector<int> group_of(n, -1);
  for (size_t k = 0; k < n; ++k) {
    const size_t r = find(k);
    if (group_of[r] < 0) {
      group_of[r] = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    groups[group_of[r]].push_back(pair[k]);
  }
  return groups;
}

}  // namespace

bool is_brash(const Polygon& piece, double thickness_m, double min_area_m2) {
  const double area = signed_area(piece);
  if (area < min_area_m2) return true;
  double perimeter = 0;
  for (size_t i = 0; i < piece.size(); ++i) perimeter += (piece[(i + 1) % piece.size()] - piece[i]).norm();
  return 4 * area / perimeter < thickness_m;
}

double static_piece_rb_m(const FractureOptions& o, double rb_nevel_over_lc, double lc_m) {
  return (o.piece_size == "empirical" ? o.piece_c_l : rb_nevel_over_lc) * lc_m;
}

double wedge_angle_rad(const FractureOptions& o, int floe_id, long step) {
  const uint64_t key = splitmix64(static_cast<uint64_t>(o.seed) ^ splitmix64(static_cast<uint64_t>(floe_id) ^
                                                                              splitmix64(static_cast<uint64_t>(step))));
  const double u = static_cast<double>(key >> 11) * 0x1.0p-53;  // uniform in [0, 1)
  const double lo = o.wedge_angle_deg[0] * kDegToRad, hi = o.wedge_angle_deg[1] * kDegToRad;
  return lo + u * (hi - lo);
}

std::vector<FractureCut> find_fractures(const Model& model, const State& state, const std::vector<Contact>& contacts,
                                        double dt) {
  const FractureOptions& fo = model.settings.fracture;
  std::vector<FractureCut> cuts;
  if (!fo.enabled) return cuts;
  // 1. Each contact's force on each floe it touches, keyed by (floe, other body).
  struct Share {
    int floe, other, contact;
    bool on_b;
    bool operator<(const Share& o) const {
      if (floe != o.floe) return floe < o.floe;
      if (other != o.other) return other < o.other;
      return contact < o.contact;
    }
  };
  std::vector<Share> shares;
  for (size_t i = 0; i < contacts.size(); ++i) {
    const Contact& c = contacts[i];
    if (!(c.pn > 0)) continue;
    for (int side = 0; side < 2; ++side) {
      const int f = side ? c.body_b : c.body_a, other = side ? c.body_a : c.body_b;
      if (model.bodies[f].kind != BodyKind::floe || !state.alive[f]) continue;
      const BodyKind ok = model.bodies[other].kind;
      if (ok == BodyKind::wall) continue;  // a domain wall is a boundary of the model, not ice or a structure
      if (ok == BodyKind::floe && !fo.ice_ice) continue;
      shares.push_back({f, other, static_cast<int>(i), side == 1});
    }
  }
  std::sort(shares.begin(), shares.end());
  // 2. Pair loads, and per floe the pair whose load is closest to (or furthest past) failure.
  const long step = state.step + 1;
  size_t i = 0;
  while (i < shares.size()) {
    const int floe = shares[i].floe;
    Candidate best;
    PairLoad best_load;
    while (i < shares.size() && shares[i].floe == floe) {
      const int other = shares[i].other;
      std::vector<size_t> pair;  // indices into shares
      for (; i < shares.size() && shares[i].floe == floe && shares[i].other == other; ++i) pair.push_back(i);
      // A floe's contacts with one body load it as one (the floe answers as a whole). A level ice tile is part of
      // a sheet: the hull's two sides, or its stem and a shoulder, bend it at separate places, so each patch of
      // touching contacts is a load of its own (summed, the two sides' horizontal forces would cancel and the
      // width would span the hull).
      const Body& fb = model.bodies[floe];
      const std::vector<std::vector<size_t>> groups =
          fb.fixed ? contact_patches(contacts, shares, pair, load_join_distance_m(fb.thickness_m))
                   : std::vector<std::vector<size_t>>{pair};
      for (const std::vector<size_t>& group : groups) {
        PairLoad pl;
        pl.floe = floe;
        pl.other = other;
        pl.at_structure = model.bodies[other].kind == BodyKind::vessel;
        for (size_t k : group) {
          const Contact& c = contacts[shares[k].contact];
          const double sign = shares[k].on_b ? 1.0 : -1.0;  // the impulse acts on b, its opposite on a
          pl.force += sign * (c.pn * c.normal + c.pt1 * c.t1 + c.pt2 * c.t2) / dt;
          pl.normal += sign * c.pn * c.normal;
          pl.point += c.pn * c.point;
          pl.weight += c.pn;
          pl.span.push_back(c.span_lo);
          pl.span.push_back(c.span_hi);
        }
        pl.point /= pl.weight;
        const Candidate cand = evaluate(model, state, pl, step);
        if (cand.ratio > best.ratio) {
          best = cand;
          best_load = std::move(pl);
        }
      }
    }
    if (best.ratio < 1) continue;
    FractureCut fc;
    fc.body = floe;
    double rb_cut = best.rb;
    fc.pieces = cut(model.bodies[floe], best, fo, &fc.wedge_pieces, &rb_cut);
    if (fc.pieces.empty()) continue;
    FractureEvent& e = fc.event;
    e.time_s = step * dt;
    e.parent_id = model.bodies[floe].id;
    e.mode = best.mode;
    e.at_structure = best_load.at_structure;
    e.force_n = best_load.force;
    e.threshold_n = best.threshold;
    e.point_m = best_load.point;
    e.width_m = best.width;
    e.theta_rad = best.mode == kFractureSplitting ? 0.0 : best.theta;
    e.lc_m = best.lc;
    e.rb_m = best.mode == kFractureSplitting ? 0.0 : rb_cut;
    cuts.push_back(std::move(fc));
  }
  return cuts;
}

}  // namespace floesim::sim
