#include "sim/engine/fracture.h"

#include <algorithm>
#include <cmath>

#include "pipeline/error.h"
#include "pipeline/results_io.h"
#include "sim/engine/fracture_laws.h"

namespace floesim::sim {

namespace {

constexpr double kDegToRad = kPi / 180.0;
// A structure's face pushes the ice up, and bends it up, when its normal on the ice rises more than this (the sine
// of 10 degrees): an upward-breaking cone's slope; a vertical face (its friction lifting the ice a little) does not.
constexpr double kUpwardFaceSine = 0.17;
// Draws of a failure's cut (wedge angle, split line) tried in one step before the floe is left whole (see cut()).
constexpr int kCutAttempts = 8;

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

// A level-ice tile loaded from below (a piece held under the sheet, §10.2): where the load meets the sheet's free
// edge. The free edge nearest the load point in the tile's frame (a side of its outline with open water beyond it,
// not another tile) if it lies within half a characteristic length, its point and inward normal; else false (an
// interior load: the sheet is several times stronger there, §2.1, and no wedge test applies).
bool nearest_free_edge(const Model& model, const State& state, const std::vector<int>& tiles, int tile,
                       const Vec2& p, double max_distance, Vec2* edge_point, Vec2* inward) {
  const Body& body = model.bodies[tile];
  const Polygon& o = body.outline;
  const Mat3 R = state.orientation[tile].toRotationMatrix();
  const Vec3 x = state.position[tile];
  double best = max_distance;
  bool found = false;
  for (size_t i = 0; i < o.size(); ++i) {
    const Vec2 a = o[i], b = o[(i + 1) % o.size()];
    const Vec2 ab = b - a;
    const double len2 = ab.squaredNorm();
    if (!(len2 > 0)) continue;
    const double t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
    const Vec2 q = a + t * ab;
    const double d = (p - q).norm();
    if (d >= best) continue;
    const Vec2 out = Vec2(ab.y(), -ab.x()).normalized();  // outward for a CCW ring
    // Open water beyond the side: the point 5 cm outside lies in no other tile.
    const Vec2 beyond = q + 0.05 * out;
    const Vec3 w = x + R * Vec3(beyond.x(), beyond.y(), 0);
    bool covered = false;
    for (int k : tiles) {
      if (k == tile) continue;
      const Mat3 Rk = state.orientation[k].toRotationMatrix();
      const Vec3 l = Rk.transpose() * (w - state.position[k]);
      if (chord_length(model.bodies[k].outline, Vec2(l.x(), l.y()), Vec2::UnitX()) > 0) {
        covered = true;
        break;
      }
    }
    if (covered) continue;
    best = d;
    *edge_point = q;
    *inward = -out;
    found = true;
  }
  return found;
}

// Out-of-plane and in-plane failure of one floe under one pair load (PHYSICS.md §2.1-2.4, §10). `others` is the
// (filtered) contact force of every other body on the floe, world: the reaction a splitting load is pressed
// against (§2.2). `tiles` are the level-ice tiles alive (for a tile's free edges).
Candidate evaluate(const Model& model, const State& state, const PairLoad& pl, const Vec3& others,
                   const std::vector<int>& tiles, long step, int attempt) {
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
  bool edge = inward.norm() > 0.1 * n3.norm() && n3.norm() > 0;  // not a floe under a flat bottom
  if (edge) inward.normalize();
  const double rho_w_g = model.settings.water.density_kg_m3 * model.settings.water.gravity_mps2;
  const double lc = rho_w_g > 0 ? characteristic_length_m(fo.youngs_modulus_pa, fo.poisson_ratio, h, rho_w_g) : 0.0;
  // A piece held under (or lying on) a level ice sheet presses on its flat face: the sheet bends at its free edge
  // when that is near (§10.2), the load taken at the edge.
  if (!edge && body.fixed && lc > 0) {
    Vec2 at, in;
    if (nearest_free_edge(model, state, tiles, pl.floe, c.point, 0.5 * lc, &at, &in)) {
      edge = true;
      inward = in;
      c.point = at;
    }
  }
  // The hull bends the ice (§2.4: F_V on a sloped face, the force as solved). Between floes either one may
  // ride over the other, and the vertical force is §10.2's for a contact face inclined at beta to the horizontal
  // with the friction mu_ii at its limit against the slide: F_V = F_n (cos beta - mu_ii sin beta), F_n the normal
  // force, beta from the contact normal in the plate's frame. A face steeper than atan(1 / mu_ii) (81.5 deg) does
  // not bend the plate: two floes crushing edge to edge load each other in-plane only.
  // At a structure the plate bends the way the structure's face pushes it: down under a ship's bow or a downward-
  // breaking cone (and by default, a face whose normal is nearly horizontal), up on an upward-breaking cone, whose
  // face pushes the ice up the slope (the elastic plate on its foundation fails the same either way, §8.2.2).
  const bool pushed_up = n3.z() > kUpwardFaceSine * n3.norm();
  double f_v = pushed_up ? f_local.z() : -f_local.z();
  if (!pl.at_structure) {
    const double nn = n3.norm();
    const double fn = nn > 0 ? std::max(0.0, f_local.dot(n3) / nn) : 0.0;
    const double cos_b = nn > 0 ? std::abs(n3.z()) / nn : 1.0, sin_b = std::sqrt(std::max(0.0, 1 - cos_b * cos_b));
    f_v = std::max(0.0, fn * (cos_b - model.settings.ice.mu_ice_ice * sin_b));
  }

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
  double theta = 0, alpha = 0;
  WedgeFailure wf;
  if (rho_w_g > 0) {
    theta = wedge_angle_rad(fo, body.id, step, attempt);
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

  // 2. In-plane splitting along the force line, through the contact point (§2.2), when the force pushes in. The push
  // F is reacted in two ways, and the crack's stress intensity is the sum of what each gives (LEFM superposes): the
  // floe's other contacts pressing back along the line, F_c (diametral, as a Brazilian disc: C_s), and the rest,
  // F - F_c, what accelerates the floe and what the water's drag takes, spread over its area (lower tension: the
  // free floe's C_s,free). It splits when F_c / (C_s K h sqrt(L)) + (F - F_c) / (C_s,free K h sqrt(L)) >= 1; its
  // threshold is the push at which that happens for this share. A floe pushed through open water splits only at
  // C_s,free K h sqrt(L).
  double r_split = 0;
  Candidate split = c;
  const Vec3 o_local = R.transpose() * others;
  const double f_push = f_h.norm();
  const double f_contact =
      f_push > 0 ? std::clamp(-Vec2(o_local.x(), o_local.y()).dot(f_h / f_push), 0.0, f_push) : 0.0;
  const double fh = f_push;
  // Level ice does not split: the in-plane load of a hull is carried by the semi-infinite sheet around the tile
  // (its chord L is not the tile's), and a sheet fails in bending at the hull (PHYSICS.md §2.4).
  if (!body.fixed && fh > 0 && (!edge || f_h.dot(inward) > 0)) {
    const Vec2 d = f_h / f_push;
    // A later attempt moves the line across by multiples of h/2, alternately to either side (a crack through the
    // contact patch, not through its centroid).
    const Vec2 start = c.point + ((attempt + 1) / 2) * (attempt % 2 ? 0.5 : -0.5) * h * perp(d);
    // The contact point lies in the overlap, at the edge: if rounding puts it just outside the outline, the chord
    // is taken from a point nudged into the floe along the force.
    double length = chord_length(body.outline, start, d);
    Vec2 at = start;
    for (int k = 1; k <= 4 && length <= 0; ++k) {
      at = start + (0.25 * k * width) * d;
      length = chord_length(body.outline, at, d);
    }
    // Metrikin's rule (PHYSICS.md §2.2, [READ]): a floe splits only if its chord is at least the bending radius
    // R_b; a smaller piece is a block that moves, tilts or crushes (without it, the broken ice under the bow would
    // split again and again into ever smaller pieces within a few steps).
    const double min_chord = rho_w_g > 0 ? wf.rb_over_lc * lc : 0.0;
    if (length > 0 && length >= min_chord) {
      const double reacted = splitting_load_n(fo.splitting_coefficient, fo.fracture_toughness_pa_sqrtm, h, length);
      const double free = splitting_load_n(fo.splitting_coefficient_free, fo.fracture_toughness_pa_sqrtm, h, length);
      r_split = f_contact / reacted + (f_push - f_contact) / free;
      split.threshold = f_push / r_split;
      split.mode = kFractureSplitting;
      split.point = at;
      split.direction = d;
      split.ratio = r_split;
    }
  }
  // §2.4: the mode of the lower threshold for this force's direction is the one with the larger load ratio.
  if (r_bend >= r_split) return bend;
  return split;
}

// A chip: a piece smaller than (h/2)^2 in plan or narrower than h/4. A crack that runs close to an earlier one (or
// past a corner of a jagged edge) cuts one, a tall column of ice that the cut's geometry makes rather than the ice:
// the closed-form laws do not resolve cracks that close, and any rigid impulse would throw its tiny mass about.

// The pieces of `parts` that are chips, moved out: returns the rest.
std::vector<Polygon> without_chips(const std::vector<Polygon>& parts, double h, bool* had_chips) {
  std::vector<Polygon> kept;
  for (const Polygon& p : parts) {
    if (is_chip(p, h)) *had_chips = true;
    else kept.push_back(p);
  }
  return kept;
}

// `outline` less `cutters`, one cut after another (the pieces of each cut kept apart).
std::vector<Polygon> outline_without(const Polygon& outline, const std::vector<Polygon>& cutters) {
  std::vector<Polygon> rest = {outline};
  for (const Polygon& k : cutters) {
    std::vector<Polygon> next;
    for (const Polygon& r : rest) {
      const PolygonCut c = cut_polygon(r, k);
      next.insert(next.end(), c.outside.begin(), c.outside.end());
    }
    rest = std::move(next);
  }
  return rest;
}

// A wedge's cut of a jagged outline may leave chips (is_chip): a tooth of the edge cut off inside the wedge, a sliver
// between a radial crack and an earlier one outside it. They stay with the ice they touch instead: chips of the wedge
// go to what the floe keeps (the floe less the wedge's other pieces), chips of the rest go to the wedge (the floe
// less the rest's other pieces). The areas still tile the floe; if chips are left, or nothing is left on a side, the
// cut's caller finds them and makes no cut.
void merge_chips(const Polygon& outline, double h, PolygonCut& wedge) {
  bool chips = false;
  const std::vector<Polygon> inside = without_chips(wedge.inside, h, &chips);
  if (chips && !inside.empty()) {
    wedge.inside = inside;
    wedge.outside = outline_without(outline, inside);
  }
  chips = false;
  const std::vector<Polygon> outside = without_chips(wedge.outside, h, &chips);
  if (chips && !outside.empty()) {
    wedge.outside = outside;
    wedge.inside = outline_without(outline, outside);
  } else if (chips) {
    // All that the floe would keep is chips: the wedge takes the whole floe (a small island of a level ice tile
    // breaks free whole; a free floe is then left as it is).
    wedge.inside = {outline};
    wedge.outside.clear();
  }
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
      // A wedge that is all chips (the load on a tooth of a jagged edge) grows as a small wedge does with
      // "enlarge", to the smallest that is no chip: the tooth breaks off with the ice behind it.
      const double h = body.thickness_m;
      bool all_chips = !wedge.inside.empty();
      for (const Polygon& p : wedge.inside) all_chips = all_chips && is_chip(p, h);
      if (all_chips) wedge = smallest_kept_wedge(wedge_of, c.rb, 0.25 * h, 0.25 * h * h, wedge, *rb_cut);
      if (wedge.inside.empty() || wedge.outside.empty()) return {};
      merge_chips(body.outline, h, wedge);
      // A held tile may break free whole (merge_chips); a free floe needs something left to break from.
      if (wedge.inside.empty() || (wedge.outside.empty() && !body.fixed)) return {};
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
  // No chips left (merge_chips): a split that would leave one is not made; the next attempt moves its line.
  for (const Polygon& p : pieces)
    if (is_chip(p, body.thickness_m)) return {};
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

double static_piece_rb_m(const FractureOptions& o, double rb_nevel_over_lc, double lc_m) {
  return (o.piece_size == "empirical" ? o.piece_c_l : rb_nevel_over_lc) * lc_m;
}

double wedge_angle_rad(const FractureOptions& o, int floe_id, long step, int attempt) {
  uint64_t key = splitmix64(static_cast<uint64_t>(o.seed) ^ splitmix64(static_cast<uint64_t>(floe_id) ^
                                                                        splitmix64(static_cast<uint64_t>(step))));
  if (attempt > 0) key = splitmix64(key ^ static_cast<uint64_t>(attempt));
  const double u = static_cast<double>(key >> 11) * 0x1.0p-53;  // uniform in [0, 1)
  const double lo = o.wedge_angle_deg[0] * kDegToRad, hi = o.wedge_angle_deg[1] * kDegToRad;
  return lo + u * (hi - lo);
}

bool is_chip(const Polygon& piece, double thickness_m) {
  return is_brash(piece, 0.25 * thickness_m, 0.25 * thickness_m * thickness_m);
}

std::vector<FractureCut> find_fractures(const Model& model, const State& state, const std::vector<Contact>& contacts,
                                        double dt, std::vector<PairLoadHistory>* history) {
  const FractureOptions& fo = model.settings.fracture;
  std::vector<FractureCut> cuts;
  if (!fo.enabled) {
    history->clear();
    return cuts;
  }
  // 1. Each contact's force on each floe it touches, keyed by (floe, other body). Every contact counts towards
  // the floe's load balance (splitting, §2.2); the pairs that can break it are `tested`.
  struct Share {
    int floe, other, contact;
    bool on_b, tested;
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
      const Body& fb = model.bodies[f];
      if (fb.kind != BodyKind::floe || fb.brash || !state.alive[f]) continue;
      const Body& ob = model.bodies[other];
      // A domain wall is a boundary of the model, not ice or a structure: it never breaks a floe, only presses back
      // on it. Brash breaks a plate as any piece does (a block jammed between the hull and the sheet passes the hull's
      // push on; its rigid impulses are smoothed by the load window).
      const bool tested = ob.kind == BodyKind::vessel || (ob.kind == BodyKind::floe && fo.ice_ice);
      shares.push_back({f, other, static_cast<int>(i), side == 1, tested});
    }
  }
  std::sort(shares.begin(), shares.end());
  std::vector<int> tiles;  // the level-ice tiles alive (a tile's free edges)
  for (size_t b = 0; b < model.bodies.size(); ++b)
    if (model.bodies[b].fixed && model.bodies[b].kind == BodyKind::floe && state.alive[b])
      tiles.push_back(static_cast<int>(b));

  // 2. The pair loads of this step: one per body pair, or per patch of contact on a level ice tile.
  struct Load {
    PairLoad pl;
    bool tested = false;
    Vec3 filtered = Vec3::Zero();
  };
  std::vector<Load> loads;
  for (size_t i = 0; i < shares.size();) {
    const int floe = shares[i].floe, other = shares[i].other;
    std::vector<size_t> pair;  // indices into shares
    for (; i < shares.size() && shares[i].floe == floe && shares[i].other == other; ++i) pair.push_back(i);
    // A floe's contacts with one body load it as one (the floe answers as a whole). A level ice tile is part of a
    // sheet: the hull's two sides, or its stem and a shoulder, bend it at separate places, so each patch of
    // touching contacts is a load of its own (summed, the two sides' horizontal forces would cancel and the width
    // would span the hull).
    const Body& fb = model.bodies[floe];
    const std::vector<std::vector<size_t>> groups =
        fb.fixed ? contact_patches(contacts, shares, pair, load_join_distance_m(fb.thickness_m))
                 : std::vector<std::vector<size_t>>{pair};
    for (const std::vector<size_t>& group : groups) {
      Load l;
      PairLoad& pl = l.pl;
      pl.floe = floe;
      pl.other = other;
      pl.at_structure = model.bodies[other].kind == BodyKind::vessel;
      l.tested = shares[group.front()].tested;
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
      loads.push_back(std::move(l));
    }
  }

  // 3. The settled load (fracture.load_window_s, §2.5): each load's force averaged over the window's last steps,
  // a step without contact counting as zero. A load continues the history of the same body pair whose last point
  // is nearest, within the distance at which two loads are one (a tile's patches move with the hull). The force a
  // test reads then does not hang on where one step's relax pass stopped.
  const size_t window = std::max<size_t>(1, static_cast<size_t>(std::lround(fo.load_window_s / dt)));
  const size_t slot = static_cast<size_t>(state.step + 1) % window;
  std::vector<PairLoadHistory> next;
  std::vector<uint8_t> used(history->size(), 0);
  for (Load& l : loads) {
    const double join = load_join_distance_m(model.bodies[l.pl.floe].thickness_m);
    auto key = [](int f, int o) { return std::make_pair(f, o); };
    auto it = std::lower_bound(history->begin(), history->end(), key(l.pl.floe, l.pl.other),
                               [&](const PairLoadHistory& h, const std::pair<int, int>& k) {
                                 return key(h.floe, h.other) < k;
                               });
    size_t best = history->size();
    double best_d = join;
    for (; it != history->end() && it->floe == l.pl.floe && it->other == l.pl.other; ++it) {
      const size_t k = static_cast<size_t>(it - history->begin());
      const double d = (it->point - l.pl.point).norm();
      if (!used[k] && d <= best_d) {
        best_d = d;
        best = k;
      }
    }
    PairLoadHistory h;
    h.floe = l.pl.floe;
    h.other = l.pl.other;
    h.point = l.pl.point;
    if (best < history->size()) {
      used[best] = 1;
      h.force = std::move((*history)[best].force);
    }
    h.force.resize(window, Vec3::Zero());
    h.force[slot] = l.pl.force;
    for (const Vec3& f : h.force) l.filtered += f;
    l.filtered /= static_cast<double>(window);
    next.push_back(std::move(h));
  }
  // Pairs not in contact this step carry a zero until their window has none of their force left.
  for (size_t k = 0; k < history->size(); ++k) {
    if (used[k]) continue;
    PairLoadHistory h = std::move((*history)[k]);
    if (!state.alive[h.floe] || !state.alive[h.other]) continue;
    h.force.resize(window, Vec3::Zero());
    h.force[slot] = Vec3::Zero();
    bool any = false;
    for (const Vec3& f : h.force) any = any || f != Vec3::Zero();
    if (any) next.push_back(std::move(h));
  }
  std::stable_sort(next.begin(), next.end(), [](const PairLoadHistory& a, const PairLoadHistory& b) {
    return std::make_pair(a.floe, a.other) < std::make_pair(b.floe, b.other);
  });
  *history = std::move(next);

  // 4. Per floe, the tested load closest to (or furthest past) failure.
  const long step = state.step + 1;
  for (size_t i = 0; i < loads.size();) {
    const int floe = loads[i].pl.floe;
    size_t end = i;
    Vec3 total = Vec3::Zero();
    for (; end < loads.size() && loads[end].pl.floe == floe; ++end) total += loads[end].filtered;
    Candidate best;
    const PairLoad* best_load = nullptr;
    PairLoad best_pl;
    for (size_t k = i; k < end; ++k) {
      if (!loads[k].tested) continue;
      PairLoad pl = loads[k].pl;
      pl.force = loads[k].filtered;
      const Candidate cand = evaluate(model, state, pl, total - pl.force, tiles, step, 0);
      if (cand.ratio > best.ratio) {
        best = cand;
        best_load = &loads[k].pl;
        best_pl = std::move(pl);
      }
    }
    i = end;
    if (best.ratio < 1 || !best_load) continue;
    const Vec3 best_force = best_pl.force;
    FractureCut fc;
    fc.body = floe;
    double rb_cut = best.rb;
    fc.pieces = cut(model.bodies[floe], best, fo, &fc.wedge_pieces, &rb_cut);
    // A cut that would leave a chip is drawn again (another wedge angle, or the split line moved across by h/2),
    // up to kCutAttempts times in all, among the draws that still fail under this load.
    for (int attempt = 1; attempt < kCutAttempts && fc.pieces.empty(); ++attempt) {
      const Candidate again = evaluate(model, state, best_pl, total - best_force, tiles, step, attempt);
      if (again.ratio < 1 || again.mode != best.mode) continue;
      best = again;
      rb_cut = best.rb;
      fc.pieces = cut(model.bodies[floe], best, fo, &fc.wedge_pieces, &rb_cut);
    }
    if (fc.pieces.empty()) continue;
    FractureEvent& e = fc.event;
    e.time_s = step * dt;
    e.parent_id = model.bodies[floe].id;
    e.mode = best.mode;
    e.at_structure = best_load->at_structure;
    e.force_n = best_force;
    e.threshold_n = best.threshold;
    e.point_m = best_load->point;
    e.width_m = best.width;
    e.theta_rad = best.mode == kFractureSplitting ? 0.0 : best.theta;
    e.lc_m = best.lc;
    e.rb_m = best.mode == kFractureSplitting ? 0.0 : rb_cut;
    cuts.push_back(std::move(fc));
  }
  return cuts;
}

}  // namespace floesim::sim
