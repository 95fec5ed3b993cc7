#include "sim/engine/solver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace floesim::sim {

namespace {

// Orthonormal tangents of a unit normal, a deterministic function of the normal alone.
void tangents(const Vec3& n, Vec3& t1, Vec3& t2) {
  if (std::abs(n.x()) >= 0.57735026919) t1 = Vec3(n.y(), -n.x(), 0).normalized();
  else t1 = Vec3(0, n.z(), -n.y()).normalized();
  t2 = n.cross(t1);
}

// The cache's order: by body pair, then part pair.
bool body_pair_less(const CachedContact& c, const Contact& k) {
  if (c.body_a != k.body_a) return c.body_a < k.body_a;
  return c.body_b < k.body_b;
}
bool key_less(const CachedContact& c, const Contact& k) {
  if (c.body_a != k.body_a || c.body_b != k.body_b) return body_pair_less(c, k);
  if (c.part_a != k.part_a) return c.part_a < k.part_a;
  return c.part_b < k.part_b;
}
bool same_key(const CachedContact& c, const Contact& k) {
  return c.body_a == k.body_a && c.part_a == k.part_a && c.body_b == k.body_b && c.part_b == k.part_b;
}

}  // namespace

double maattanen_strength_ratio(double closing_mps, double width_m, double thickness_m, double reference_pa) {
  // Maattanen (1998) as IceFloe codes it (PHYSICS.md 8.3): sigma_dot = v 8 sigma_ref / (pi w_d) in MPa/s, w_d =
  // min(w, 2 h), sigma(sigma_dot) a quartic in MPa on 0 .. 1.3287 MPa/s and the brittle plateau above; over its value
  // at rest, 2.00 MPa.
  const double wd = std::max(std::min(width_m, 2 * thickness_m), 1e-6);
  constexpr double kBrittle = 1.3287;
  const double rate = std::min(std::max(closing_mps, 0.0) * 8 * (reference_pa / 1e6) / (kPi * wd), kBrittle);
  const double sigma = 2.00 + rate * (7.80 + rate * (-18.57 + rate * (13.00 - 2.91 * rate)));
  return sigma / 2.00;
}

namespace {

// The pressure-area law p_c(A) = sigma_c (A / 1 m^2)^e_x (PHYSICS.md §1.8(a)); A = 0 carries no pressure.
double crushing_pressure(const EngineSettings& o, double area) {
  const double e = o.contact.pressure_area_exponent;
  if (e == 0) return o.ice.crushing_strength_pa;
  return area > 0 ? o.ice.crushing_strength_pa * std::pow(area, e) : 0.0;
}

// The crushing law of every crushing row (PHYSICS.md §1.8(a)): F = p_c(A_pair) A with A_pair the contact area of
// the row's body pair (the sum over all its rows), so that the pressure acts on the whole contact: cutting a body
// into convex parts must not change it (with e_x < 0 each part's own area would raise the pressure, up to sqrt(2)
// for a contact halved by a seam at e_x = -0.5). F_0 at the current (crushed) overlap, F_end at the overlap
// deepened by the step the collision stage measured, and the gradient K_t = dF/d(delta) as the secant between
// them (for e_x = 0 and a wedge: exactly 2 sigma_c h tan(phi)). Returns each body pair's total K_t (the sum over
// its rows), in contact order (deterministic sums).
std::map<std::pair<int, int>, double> crushing_law(const Model& model, const State& state,
                                                   std::vector<Contact>& contacts) {
  const EngineSettings& o = model.settings;
  const bool speed_law = o.contact.crushing_speed_law == "maattanen";
  const int hulls = model.hull_count();
  struct PairArea {
    double area = 0, area_end = 0;
  };
  std::map<std::pair<int, int>, PairArea> areas;
  for (const Contact& c : contacts) {
    if (c.type != ContactType::crushing) continue;
    PairArea& p = areas[{c.body_a, c.body_b}];
    p.area += c.area_m2;
    p.area_end += c.area_end_m2;
  }
  std::map<std::pair<int, int>, double> stiffness;
  for (Contact& c : contacts) {
    if (c.type != ContactType::crushing) continue;
    const PairArea& pa = areas.at({c.body_a, c.body_b});
    // Against a structure with Maattanen's law: the pressure scaled by the strength at the speed the ice closes on
    // it (the bodies' velocities as the solve starts, at the contact point), over the contact's width.
    double scale = 1;
    if (speed_law && c.body_a < hulls) {
      const Vec3 arm_a = c.point - state.position[c.body_a], arm_b = c.point - state.position[c.body_b];
      const Vec3 va = state.velocity[c.body_a] + state.angular_velocity[c.body_a].cross(arm_a);
      const Vec3 vb = state.velocity[c.body_b] + state.angular_velocity[c.body_b].cross(arm_b);
      const double closing = std::max(0.0, -(vb - va).dot(c.normal));
      const double width = (c.span_hi - c.span_lo).norm();
      scale = maattanen_strength_ratio(closing, width, model.bodies[c.body_b].thickness_m,
                                       o.contact.maattanen_reference_pa);
    }
    c.crush_force_n = scale * crushing_pressure(o, pa.area) * c.area_m2;
    c.crush_force_end_n = std::max(c.crush_force_n, scale * crushing_pressure(o, pa.area_end) * c.area_end_m2);
    c.crush_stiffness_npm = c.area_step_m > 0 ? (c.crush_force_end_n - c.crush_force_n) / c.area_step_m : 0.0;
    stiffness[{c.body_a, c.body_b}] += c.crush_stiffness_npm;
  }
  return stiffness;
}

// Applies an impulse p along the row (d, ia, ib) to the two bodies: a gets -p, b gets +p. A fixed body (a wall)
// is not written: islands solved in parallel may share it.
inline void apply(State& s, const SolverBodies& sb, const Contact& c, const Vec3& d, const Vec3& ia, const Vec3& ib,
                  double p) {
  if (!c.fixed_a) {
    s.velocity[c.body_a] -= p * (sb.inv_mass[c.body_a] * d);
    s.angular_velocity[c.body_a] -= p * ia;
  }
  if (!c.fixed_b) {
    s.velocity[c.body_b] += p * (sb.inv_mass[c.body_b] * d);
    s.angular_velocity[c.body_b] += p * ib;
  }
}

// A body the contact impulses cannot move (zero inverse mass and inertia: a domain wall).
bool is_fixed(const SolverBodies& sb, int b) { return sb.inv_mass[b].isZero(0) && sb.inv_inertia_world[b].isZero(0); }

// A body asleep (a state without awake flags, as a solver test's, has every body awake).
bool asleep(const State& s, int b) { return static_cast<size_t>(b) < s.awake.size() && !s.awake[b]; }

// Relative velocity of b with respect to a at the contact, and its component along d.
inline Vec3 rel_velocity(const State& s, const Contact& c) {
  const Vec3 va = s.velocity[c.body_a] + s.angular_velocity[c.body_a].cross(c.ra);
  const Vec3 vb = s.velocity[c.body_b] + s.angular_velocity[c.body_b].cross(c.rb);
  return vb - va;
}
inline double rel_velocity(const State& s, const Contact& c, const Vec3& d) { return d.dot(rel_velocity(s, c)); }

// The bounds of a contact's impulses: the normal impulse's floor (0; a bond's -dt sigma_t A) and the radius of the
// tangential impulse's disk (Coulomb's mu p_n; a bond's dt tau A, whatever the normal impulse).
inline double normal_floor(const Contact& c) { return c.type == ContactType::bond ? -c.tension_limit : 0.0; }
inline double shear_radius(const Contact& c, double pn) {
  return c.type == ContactType::bond ? c.shear_limit : c.mu * pn;
}

// The normal impulse of a crushing row given its current normal velocity vn (PHYSICS.md §1.8(c)), the local
// three-branch update of a Gauss-Seidel sweep (velocities counted from the bias, see below). With W = 1/m_eff and
// v0 = vn - W p the velocity without this row's impulse, the end-of-step velocity is v = v0 + W p and
//   v0 >= 0                        -> p = 0                  separating: no tension, no spring-back
//   -v0 <= W dt F_0                -> p = -v0 / W            below the crushing force: rigid (v = 0), no push-out
//   otherwise                      -> p = dt (F_0 - k v) with k = dt K_t + c_n, i.e.
//                                     p = dt (F_0 - k v0) / (1 + dt k W)   crushing, the force hardening with the
//                                     area at the end-of-step penetration delta + dt (-v) (implicit in v),
// the hardening capped at F_end (+ damping), the force of the area the collision stage measured at the end of the
// step's expected penetration: the secant K_t is exact up to there, and beyond it the area is unknown, so the force
// stays at p_c A of a penetration that is certainly reached (A grows with the penetration): never above p_c A.
// Written without dividing by W, so that two kinematic bodies (W = 0) crush at exactly F_0 + K_t dt (-v0).
// A pair that backed off from its crushed depth by g (the crushed ice is gone) approaches over g freely: velocities
// count from the bias -g/dt (v0 - bias is what crushes beyond the crushed depth in this step); without a gap the
// bias is 0.
double crushing_impulse(const Contact& c, double vn, double dt) {
  const double W = c.inv_mass_n;
  const double v0 = vn - W * c.pn - c.bias;
  if (v0 >= 0) return 0.0;
  if (-v0 <= W * dt * c.crush_force_n) return -v0 / W;
  const double k = dt * c.crush_stiffness_npm + c.crush_damping_nspm;
  const double hardening = dt * (c.crush_force_n - k * v0) / (1 + dt * k * W);
  const double capped = dt * (c.crush_force_end_n - c.crush_damping_nspm * v0) / (1 + dt * c.crush_damping_nspm * W);
  return std::min(hardening, capped);
}

// The islands of ContactIslands, from the fixed flags prepare_contacts has set.
ContactIslands contact_islands(const std::vector<Contact>& contacts, size_t bodies) {
  std::vector<int> parent(bodies);
  for (size_t b = 0; b < bodies; ++b) parent[b] = static_cast<int>(b);
  auto find = [&](int b) {
    while (parent[b] != b) b = parent[b] = parent[parent[b]];
    return b;
  };
  for (const Contact& c : contacts)
    if (!c.fixed_a && !c.fixed_b) {
      const int ra = find(c.body_a), rb = find(c.body_b);
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  // Island of each contact by first appearance (a contact between two fixed bodies is an island of its own).
  const int n = static_cast<int>(contacts.size());
  std::vector<int> island_of_root(bodies, -1), island(n);
  int count = 0;
  for (int i = 0; i < n; ++i) {
    const Contact& c = contacts[i];
    if (c.fixed_a && c.fixed_b) {
      island[i] = count++;
      continue;
    }
    int& id = island_of_root[find(c.fixed_a ? c.body_b : c.body_a)];
    if (id < 0) id = count++;
    island[i] = id;
  }
  ContactIslands is;
  is.begin.assign(count + 1, 0);
  for (int i = 0; i < n; ++i) ++is.begin[island[i] + 1];
  for (int k = 0; k < count; ++k) is.begin[k + 1] += is.begin[k];
  is.index.resize(n);
  std::vector<int> fill(is.begin.begin(), is.begin.end() - 1);
  for (int i = 0; i < n; ++i) is.index[fill[island[i]]++] = i;
  return is;
}

}  // namespace

ContactIslands prepare_contacts(const Model& model, const SolverBodies& sb, State& state,
                                std::vector<Contact>& contacts, double dt) {
  const SolverOptions& o = model.settings.solver;
  const double match_tol2 = 0.1 * 0.1;  // m^2: a cached point further than 10 cm is another point
  const std::map<std::pair<int, int>, double> pair_stiffness = crushing_law(model, state, contacts);
  for (Contact& c : contacts) {
    // 1. Auxiliary data: lever arms, tangents, I^-1 (r x d) per row and body, effective masses 1/W.
    c.ra = c.point - state.position[c.body_a];
    c.rb = c.point - state.position[c.body_b];
    // Fixed: a wall, a tile of level ice, or a body asleep in a contact with an awake one (rubble the touch left at
    // rest, World::touch_wakes): the impulses do not move them.
    c.fixed_a = is_fixed(sb, c.body_a) || asleep(state, c.body_a);
    c.fixed_b = is_fixed(sb, c.body_b) || asleep(state, c.body_b);
    tangents(c.normal, c.t1, c.t2);
    const Mat3& Ia = sb.inv_inertia_world[c.body_a];
    const Mat3& Ib = sb.inv_inertia_world[c.body_b];
    const Mat3 im = sb.inv_mass[c.body_a] + sb.inv_mass[c.body_b];  // translational part of W (added mass: a tensor)
    auto row = [&](const Vec3& d, Vec3& ia, Vec3& ib) {
      const Vec3 rad = c.ra.cross(d), rbd = c.rb.cross(d);
      ia = Ia * rad;
      ib = Ib * rbd;
      const double w = d.dot(im * d) + rad.dot(ia) + rbd.dot(ib);
      return w > 0 ? 1.0 / w : 0.0;
    };
    c.mass_n = row(c.normal, c.ia_n, c.ib_n);
    c.inv_mass_n = c.mass_n > 0 ? 1.0 / c.mass_n : 0.0;
    c.mass_t1 = row(c.t1, c.ia_t1, c.ib_t1);
    c.mass_t2 = row(c.t2, c.ia_t2, c.ib_t2);
    // Bias = smallest allowed normal velocity. Rigid: push out the overlap beyond the slop at ERP per step (capped);
    // a speculative gap allows approaching by gap/dt. Crushing rows never push out (PHYSICS.md §1.8(c)); a pair
    // backed off from its crushed depth approaches over the gap freely.
    if (c.type == ContactType::crushing) {
      c.bias = -c.crush_gap_m / dt;  // free approach back to the crushed depth; never a push-out
      // Optional damping c_n = 2 zeta sqrt(m K_t) of the body pair (m its translational reduced mass along the
      // normal, K_t the sum over its rows), shared among the rows by their K_t, so that cutting the contact into
      // rows does not change it (none between two kinematic bodies: m infinite).
      const double w_pair = c.normal.dot(im * c.normal), k_pair = pair_stiffness.at({c.body_a, c.body_b});
      c.crush_damping_nspm = w_pair > 0 && k_pair > 0 ? 2 * model.settings.contact.crushing_damping_ratio *
                                                            std::sqrt(k_pair / w_pair) * c.crush_stiffness_npm / k_pair
                                                      : 0.0;
      c.max_normal_impulse = dt * c.crush_force_n;  // the cap at the start-of-step penetration (warm start clamp)
    } else if (c.type == ContactType::bond) {
      // A bond pulls its two material points together at ERP per step, along the normal and the tangents.
      auto pull = [&](double d) { return std::clamp(-o.erp * d / dt, -o.max_push_mps, o.max_push_mps); };
      const Vec3& d = c.bond_separation;
      c.bias = pull(d.dot(c.normal));
      c.bias_t1 = pull(d.dot(c.t1));
      c.bias_t2 = pull(d.dot(c.t2));
    } else if (c.gap > 0) c.bias = -c.gap / dt;
    else c.bias = std::min(o.erp * std::max(0.0, -c.gap - o.slop_m) / dt, o.max_push_mps);
    c.local_a = state.orientation[c.body_a].conjugate() * c.ra;
    c.pn = c.pt1 = c.pt2 = 0;

    // 2. Warm start: the cached row this one continues, its impulse projected on the new rows.
    if (!o.warm_start) continue;
    const std::vector<CachedContact>& cache = state.contact_cache;
    const CachedContact* best = nullptr;
    CachedContact bonded;
    if (c.type == ContactType::bond) {
      // A bond's own impulse of the last step, turned with its body a.
      bonded.impulse = state.orientation[c.body_a] * state.bonds[c.bond].impulse_a;
      best = &bonded;
    } else if (c.type == ContactType::crushing) {
      // A crushing row carries a half of a contact of the body pair, whose part pairs may come and go and whose
      // centroid may slide: its predecessor is the cached row of the same pair and half whose crushed normal is
      // in the same direction (kSameContactCos), the nearest.
      double bd = std::numeric_limits<double>::infinity();
      for (auto it = std::lower_bound(cache.begin(), cache.end(), c, body_pair_less);
           it != cache.end() && it->body_a == c.body_a && it->body_b == c.body_b; ++it) {
        if (it->type != ContactType::crushing || it->row != c.row ||
            it->crush_normal_a.dot(c.crush_normal_a) < kSameContactCos)
          continue;
        const double d = (it->local_a - c.local_a).squaredNorm();
        if (d < bd) bd = d, best = &*it;
      }
    } else {
      // Rigid points: the nearest cached point of the same part pair within match_tol.
      double bd = match_tol2;
      for (auto it = std::lower_bound(cache.begin(), cache.end(), c, key_less); it != cache.end() && same_key(*it, c);
           ++it) {
        const double d = (it->local_a - c.local_a).squaredNorm();
        if (d < bd) bd = d, best = &*it;
      }
    }
    if (!best) continue;
    c.pn = std::clamp(best->impulse.dot(c.normal), normal_floor(c), c.max_normal_impulse);
    c.pt1 = best->impulse.dot(c.t1);
    c.pt2 = best->impulse.dot(c.t2);
    const double lim = shear_radius(c, c.pn), pt = std::sqrt(c.pt1 * c.pt1 + c.pt2 * c.pt2);
    if (pt > lim) {
      const double s = pt > 0 ? lim / pt : 0.0;
      c.pt1 *= s;
      c.pt2 *= s;
    }
    apply(state, sb, c, c.normal, c.ia_n, c.ib_n, c.pn);
    apply(state, sb, c, c.t1, c.ia_t1, c.ib_t1, c.pt1);
    apply(state, sb, c, c.t2, c.ia_t2, c.ib_t2, c.pt2);
  }
  return contact_islands(contacts, sb.inv_mass.size());
}

namespace {

// The normal velocity a rigid row aims at: the bias (push-out, speculative gap) in the solve; in the relax pass
// only non-penetration (or the speculative gap).
inline double rigid_target(const Contact& c, double dt, bool use_bias) {
  if (c.type == ContactType::bond) return use_bias ? c.bias : 0.0;
  return use_bias ? c.bias : (c.gap > 0 ? -c.gap / dt : 0.0);
}

// The new normal impulse of one contact's normal row from its current normal velocity vn: the local law.
inline double normal_update(const Contact& c, double vn, double dt, bool use_bias) {
  if (c.type == ContactType::crushing) return crushing_impulse(c, vn, dt);
  return std::clamp(c.pn + c.mass_n * (rigid_target(c, dt, use_bias) - vn), normal_floor(c), c.max_normal_impulse);
}

// The new friction impulses from the current tangential velocities, projected together onto the Coulomb disk of
// radius mu p_n (the exact cone section, no polyhedral anisotropy); a bond's aim at its tangential bias, in the disk
// of its shear strength.
inline void friction_update(const Contact& c, double v1, double v2, bool use_bias, double& p1, double& p2) {
  const double lim = shear_radius(c, c.pn);
  const bool pull = use_bias && c.type == ContactType::bond;
  p1 = c.pt1 - c.mass_t1 * (v1 - (pull ? c.bias_t1 : 0.0));
  p2 = c.pt2 - c.mass_t2 * (v2 - (pull ? c.bias_t2 : 0.0));
  const double pt = std::sqrt(p1 * p1 + p2 * p2);
  if (pt > lim) {
    const double s = pt > 0 ? lim / pt : 0.0;
    p1 *= s;
    p2 *= s;
  }
}

// The contacts of one island (joined by bodies that move), by index into the step's contact list, in its order.
struct Island {
  std::vector<Contact>* contacts;
  const int* index;
  int n;
  Contact& operator[](int i) const { return (*contacts)[index[i]]; }
};

// One Gauss-Seidel update of a contact (normal row, then the two friction rows on the new normal impulse), from
// its current relative velocity dv0. Returns the largest row velocity change it made (m/s).
double sweep_contact(State& state, const SolverBodies& sb, Contact& c, double dt, bool use_bias, const Vec3& dv0) {
  double change = 0;
  const double pn = normal_update(c, c.normal.dot(dv0), dt, use_bias);
  const double dpn = pn - c.pn;
  if (dpn != 0) {
    apply(state, sb, c, c.normal, c.ia_n, c.ib_n, dpn);
    c.pn = pn;
    change = std::abs(dpn) * c.inv_mass_n;
  }
  double p1, p2;
  const Vec3 dv = rel_velocity(state, c);  // once for both friction rows
  friction_update(c, c.t1.dot(dv), c.t2.dot(dv), use_bias, p1, p2);
  const double d1 = p1 - c.pt1, d2 = p2 - c.pt2;
  if (d1 != 0) {
    apply(state, sb, c, c.t1, c.ia_t1, c.ib_t1, d1);
    change = std::max(change, std::abs(d1) / std::max(c.mass_t1, 1e-300));
  }
  if (d2 != 0) {
    apply(state, sb, c, c.t2, c.ia_t2, c.ib_t2, d2);
    change = std::max(change, std::abs(d2) / std::max(c.mass_t2, 1e-300));
  }
  c.pt1 = p1;
  c.pt2 = p2;
  return change;
}

// How far one exact local update would move each row's velocity (m/s), nothing applied: the violation of the
// contact law (complementarity, crushing law, Coulomb disk) at the current impulses. Returns the largest over all
// rows; `sum_sq` gets the sum of squares (the merit the subspace step must lower). The sum only grows, so once it
// reaches `stop_at` the rest cannot bring it below: the measurement stops there (a failed subspace step is known
// as soon as its first rows exceed the merit before it), and `sum_sq` is then at least `stop_at`.
double law_violation(const State& state, const Island& island, double dt, bool use_bias, double* sum_sq = nullptr,
                     double stop_at = std::numeric_limits<double>::infinity()) {
  double worst = 0, sq = 0;
  for (int i = 0; i < island.n && !(sq >= stop_at); ++i) {
    const Contact& c = island[i];
    const double pn = normal_update(c, rel_velocity(state, c, c.normal), dt, use_bias);
    double p1, p2;
    friction_update(c, rel_velocity(state, c, c.t1), rel_velocity(state, c, c.t2), use_bias, p1, p2);
    const double e[3] = {std::abs(pn - c.pn) * c.inv_mass_n, std::abs(p1 - c.pt1) / std::max(c.mass_t1, 1e-300),
                         std::abs(p2 - c.pt2) / std::max(c.mass_t2, 1e-300)};
    for (double x : e) {
      worst = std::max(worst, x);
      sq += x * x;
    }
  }
  if (sum_sq) *sum_sq = sq;
  return worst;
}

// A row of the subspace: which contact and which of its rows (0 normal, 1 and 2 friction), and its equation
// v + soft p = target (soft = 0: an equality on the velocity; soft > 0: the crushing law's hardening branch,
// p = dt (F - k v) <=> v + p / (dt k) = F / k).
struct SubspaceRow {
  int contact;
  int k;
  double soft, target;
};

// One row's block on one body: the Jacobian J (linear, angular) and M^-1 J^T.
struct SubspaceEntry {
  int body, row;
  Vec3 lin, ang, mlin, mang;
};

// The subspace minimisation of PGS-SM (Silcowitz, Niebe & Erleben 2010). The rows whose state the sweeps have
// settled are solved exactly, the others held: normal rows that press (rigid rows: v_n = target; crushing rows by
// their branch: rigid v_n = 0 below dt F_0, or the hardening/capped law above it) and friction rows that stick
// (v_t = 0). Their Delassus matrix W = J M^-1 J^T (sparse: rows share a body only through that body's block) is
// factorised by a sparse LDL^T with a fill-reducing ordering; W may be singular or nearly so (four manifold points
// on one face, many crushing rows between the parts of two floes), so its diagonal is regularised (the regularised
// variant of PHYSICS.md §1.5; how much, below). The new impulses are projected on their bounds and applied; the
// next sweeps correct rows that changed state. Returns the number of rows solved (0: nothing settled, the factorisation
// failed, or the step did not lower the violation and was undone).
int subspace_step(const SolverBodies& sb, State& state, const Island& island, double dt, bool use_bias,
                  int max_rows) {
  std::vector<Contact>& contacts = *island.contacts;
  std::vector<SubspaceRow> rows;
  for (int i = 0; i < island.n; ++i) {
    const int ci = island.index[i];
    const Contact& c = contacts[ci];
    if (c.type == ContactType::bond) {
      // A bond: its normal row while above its tension floor, its tangent rows while inside its shear disk.
      if (c.mass_n <= 0) continue;
      if (c.pn > -c.tension_limit * (1 - 1e-9)) rows.push_back({ci, 0, 0.0, rigid_target(c, dt, use_bias)});
      if (std::hypot(c.pt1, c.pt2) < c.shear_limit * (1 - 1e-9)) {
        rows.push_back({ci, 1, 0.0, use_bias ? c.bias_t1 : 0.0});
        rows.push_back({ci, 2, 0.0, use_bias ? c.bias_t2 : 0.0});
      }
      continue;
    }
    if (c.mass_n <= 0 || c.pn <= 0) continue;  // between two fixed bodies, or not pressing: held (at zero)
    if (c.type == ContactType::rigid) {
      rows.push_back({ci, 0, 0.0, rigid_target(c, dt, use_bias)});
    } else if (c.pn < dt * c.crush_force_n) {
      rows.push_back({ci, 0, 0.0, c.bias});  // below the crushing force: rigid (from the bias), no push-out
    } else {
      // Crushing: the branch crushing_impulse takes at the current velocity (counted from the bias, as there).
      const double W = c.inv_mass_n;
      const double v0 = rel_velocity(state, c, c.normal) - W * c.pn - c.bias;
      const double k = dt * c.crush_stiffness_npm + c.crush_damping_nspm, cn = c.crush_damping_nspm;
      const double hardening = dt * (c.crush_force_n - k * v0) / (1 + dt * k * W);
      const double capped = dt * (c.crush_force_end_n - cn * v0) / (1 + dt * cn * W);
      if (hardening <= capped) {
        if (k > 0) rows.push_back({ci, 0, 1 / (dt * k), c.crush_force_n / k + c.bias});
      } else if (cn > 0) {
        rows.push_back({ci, 0, 1 / (dt * cn), c.crush_force_end_n / cn + c.bias});
      }
      // Otherwise the impulse is a constant of the branch (dt F_0 or dt F_end): held.
    }
    const double pt = std::sqrt(c.pt1 * c.pt1 + c.pt2 * c.pt2);
    if (c.mu > 0 && pt < c.mu * c.pn * (1 - 1e-9)) {
      rows.push_back({ci, 1, 0.0, 0.0});  // sticking
      rows.push_back({ci, 2, 0.0, 0.0});
    }
  }
  const int m = static_cast<int>(rows.size());
  if (m == 0 || m > max_rows) return 0;

  // Jacobian blocks per body (a fixed body has M^-1 = 0 and couples nothing), grouped by body.
  std::vector<SubspaceEntry> entries;
  entries.reserve(2 * rows.size());
  for (int r = 0; r < m; ++r) {
    const Contact& c = contacts[rows[r].contact];
    const int k = rows[r].k;
    const Vec3& d = k == 0 ? c.normal : k == 1 ? c.t1 : c.t2;
    const Vec3& ia = k == 0 ? c.ia_n : k == 1 ? c.ia_t1 : c.ia_t2;
    const Vec3& ib = k == 0 ? c.ib_n : k == 1 ? c.ib_t1 : c.ib_t2;
    if (!c.fixed_a)
      entries.push_back({c.body_a, r, -d, -c.ra.cross(d), -(sb.inv_mass[c.body_a] * d), -ia});
    if (!c.fixed_b)
      entries.push_back({c.body_b, r, d, c.rb.cross(d), sb.inv_mass[c.body_b] * d, ib});
  }
  std::sort(entries.begin(), entries.end(), [](const SubspaceEntry& x, const SubspaceEntry& y) {
    return x.body != y.body ? x.body < y.body : x.row < y.row;
  });
  std::vector<Eigen::Triplet<double>> triplets;
  for (size_t g = 0; g < entries.size();) {
    size_t e = g;
    while (e < entries.size() && entries[e].body == entries[g].body) ++e;
    for (size_t i = g; i < e; ++i)
      for (size_t j = g; j <= i; ++j)  // lower triangle: row i >= row j (sorted by row within the body)
        triplets.emplace_back(entries[i].row, entries[j].row,
                              entries[i].lin.dot(entries[j].mlin) + entries[i].ang.dot(entries[j].mang));
    g = e;
  }
  Eigen::SparseMatrix<double> W(m, m);
  W.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::VectorXd rhs(m), diag(m);
  for (int r = 0; r < m; ++r) {
    Contact& c = contacts[rows[r].contact];
    const int k = rows[r].k;
    const Vec3& d = k == 0 ? c.normal : k == 1 ? c.t1 : c.t2;
    const double p = k == 0 ? c.pn : k == 1 ? c.pt1 : c.pt2;
    diag[r] = W.coeff(r, r);
    W.coeffRef(r, r) = diag[r] + rows[r].soft;
    rhs[r] = rows[r].target - rel_velocity(state, c, d) - rows[r].soft * p;
  }

  // The step is kept only if it lowers the violation of the contact law (the sum of squares over all rows). Two
  // things can make it worse than the sweeps had it. The settled set was wrong (a row that must slide or
  // separate): the projection then spoils the balance (PGS-SM has no convergence guarantee of its own). Or rows are
  // nearly dependent (ten crushing rows between the parts of two floes span six relative motions): their tiny
  // eigenvalues turn a residual of 1e-5 m/s into opposite impulses of 1e4 N s that the projection cannot keep.
  // So the regularisation grows (Levenberg-Marquardt: mu = 1e-9, 1e-6, 1e-3 of each diagonal) until the step
  // helps; mu = 1e-9 leaves a mass-ratio direction (an eigenvalue ~ m_light / m_heavy ~ 1e-3 of the diagonal)
  // exact to 1e-6, mu = 1e-3 damps near-dependent directions. If none helps, the step is undone exactly and the
  // sweeps go on.
  double before = 0, after = 0;
  law_violation(state, island, dt, use_bias, &before);
  std::vector<Vec3> old(m);  // (pn, pt1, pt2) of each row's contact before the step
  for (int r = 0; r < m; ++r) {
    const Contact& c = contacts[rows[r].contact];
    old[r] = Vec3(c.pn, c.pt1, c.pt2);
  }
  auto set_impulses = [&](Contact& c, double pn, double p1, double p2) {
    apply(state, sb, c, c.normal, c.ia_n, c.ib_n, pn - c.pn);
    apply(state, sb, c, c.t1, c.ia_t1, c.ib_t1, p1 - c.pt1);
    apply(state, sb, c, c.t2, c.ia_t2, c.ib_t2, p2 - c.pt2);
    c.pn = pn;
    c.pt1 = p1;
    c.pt2 = p2;
  };
  auto undo = [&] {
    for (int r = m - 1; r >= 0; --r) {  // each contact once: the rows of a contact are adjacent
      if (r + 1 < m && rows[r + 1].contact == rows[r].contact) continue;
      const Vec3& p = old[r];
      set_impulses(contacts[rows[r].contact], p.x(), p.y(), p.z());
    }
  };
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt;
  ldlt.analyzePattern(W);
  double applied_mu = 0;
  for (double mu : {1e-9, 1e-6, 1e-3}) {
    for (int r = 0; r < m; ++r) W.coeffRef(r, r) = diag[r] * (1 + mu) + rows[r].soft;
    ldlt.factorize(W);
    if (ldlt.info() != Eigen::Success) continue;
    const Eigen::VectorXd dp = ldlt.solve(rhs);
    if (ldlt.info() != Eigen::Success || !dp.allFinite()) continue;
    // New impulses, projected (normal >= 0, friction in the disk of the new normal impulse), applied per contact.
    for (int r = 0; r < m;) {
      Contact& c = contacts[rows[r].contact];
      Vec3 p = old[r];
      for (const int ci = rows[r].contact; r < m && rows[r].contact == ci; ++r) p[rows[r].k] += dp[r];
      // Rigid rows and bonds keep their bounds; a crushing row's bound is its law, which the next sweep applies.
      const double pn = c.type != ContactType::crushing ? std::clamp(p.x(), normal_floor(c), c.max_normal_impulse)
                                                        : std::max(p.x(), 0.0);
      const double lim = shear_radius(c, pn), pt = std::hypot(p.y(), p.z());
      const double s = pt > lim ? (pt > 0 ? lim / pt : 0.0) : 1.0;
      set_impulses(c, pn, s * p.y(), s * p.z());
    }
    law_violation(state, island, dt, use_bias, &after, before);
    if (after < before) {
      applied_mu = mu;
      break;
    }
    undo();
  }
  return applied_mu > 0 ? m : 0;
}

}  // namespace

namespace {

// 3. The sweeps of one island until its largest velocity change is below the tolerance or the sweep cap.
SolverReport solve_island(const SolverOptions& o, const SolverBodies& sb, State& state, const Island& island,
                          double dt, bool use_bias, int iterations, double tolerance) {
  SolverReport rep;
  const int n = island.n;
  // Each contact's normal row, then its two friction rows on the new normal impulse; every subspace_every
  // unconverged sweeps, the subspace minimisation.
  bool try_subspace = o.method == "pgs_subspace";
  // Settled contacts are left out of a sweep. A contact's update is a function of its relative velocity (and its
  // own impulses): if its last update changed its row velocities by less than `skip` and its relative velocity has
  // moved by less than `skip` since that update began, the update it would make now is of the same small order,
  // below the tolerance that decides convergence, so it is left out (not lost: once its bodies have moved by
  // `skip`, it is updated again). In a capped solve most contacts sit still while a few light pieces creep between
  // heavy bodies; the test costs one relative velocity, about a quarter of an update. A sweep after a subspace
  // step visits every contact (the step moves impulses outside this bookkeeping).
  // (skip 0: no change is below it, so every contact is updated.)
  const double skip = o.skip_settled * tolerance;
  std::vector<Vec3> dv_seen(n);  // relative velocity when the contact's last update began
  std::vector<double> last_change(n);
  bool full = true;
  auto visit = [&](int i) {
    Contact& c = island[i];
    const Vec3 dv = rel_velocity(state, c);
    if (!full && last_change[i] < skip && (dv - dv_seen[i]).cwiseAbs().maxCoeff() < skip) return 0.0;
    dv_seen[i] = dv;
    return last_change[i] = sweep_contact(state, sb, c, dt, use_bias, dv);
  };
  for (int it = 0; it < iterations; ++it) {
    double change = 0;
    if (o.reverse_order)
      for (int i = n - 1; i >= 0; --i) change = std::max(change, visit(i));
    else
      for (int i = 0; i < n; ++i) change = std::max(change, visit(i));
    full = false;
    // 4. Residual and iteration count.
    rep.iterations = it + 1;
    rep.residual = change;
    if (!(change > tolerance)) break;  // also stops on NaN: the caller's health check reports it
    // A step that did not help (undone) will not help on the next try either (the sweeps have not changed which
    // rows are settled enough for it), so the first failure ends the attempts of this solve: in the default case
    // most attempts are undone (redundant crushing rows between the parts of two floes, branch switching of the
    // crushing law), and this keeps their cost at about one factorisation per unconverged solve.
    // subspace_above_mps (default 0) can restrict the attempts to sweeps that still change velocities a lot.
    if (try_subspace && (it + 1) % o.subspace_every == 0 && it + 1 < iterations && change > o.subspace_above_mps) {
      try_subspace = subspace_step(sb, state, island, dt, use_bias, o.subspace_max_rows) > 0;
      rep.subspace_solves += try_subspace;
      full = true;
    }
  }
  rep.capped = rep.residual > tolerance;
  rep.complementarity = law_violation(state, island, dt, use_bias);
  return rep;
}

}  // namespace

SolverReport solve_contacts(const Model& model, const SolverBodies& sb, State& state, std::vector<Contact>& contacts,
                            const ContactIslands& is, double dt, bool use_bias, int iterations, double tolerance,
                            ThreadPool* pool, const SolverOptions* options) {
  SolverReport rep;
  if (contacts.empty()) return rep;
  const SolverOptions& o = options ? *options : model.settings.solver;
  // Islands are independent problems: each sweeps until it has converged (a pair of floes touching far from the
  // bow stops after a few sweeps while the bow's rubble takes the cap), and they run on the pool's threads. An
  // island's result depends only on its own contacts, so it does not depend on the thread count or the schedule.
  const int count = is.count();
  std::vector<SolverReport> reports(count);
  auto solve = [&](int k) {
    const Island island{&contacts, is.index.data() + is.begin[k], is.begin[k + 1] - is.begin[k]};
    reports[k] = solve_island(o, sb, state, island, dt, use_bias, iterations, tolerance);
  };
  const int threads = pool ? pool->threads() : 1;
  if (threads > 1 && count > 1 && contacts.size() >= 64) {
    // Largest islands first, each to the least loaded thread (by contacts).
    std::vector<int> order(count);
    for (int k = 0; k < count; ++k) order[k] = k;
    auto size = [&](int k) { return is.begin[k + 1] - is.begin[k]; };
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return size(a) > size(b); });
    std::vector<std::vector<int>> work(threads);
    std::vector<long> load(threads, 0);
    for (int k : order) {
      const int w = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
      work[w].push_back(k);
      load[w] += size(k);
    }
    pool->parallel_for(threads, [&](int begin, int end, int) {
      for (int w = begin; w < end; ++w)
        for (int k : work[w]) solve(k);
    }, 1);
  } else {
    for (int k = 0; k < count; ++k) solve(k);
  }
  // The step's report: the worst island (sweeps, residual, violation), the subspace solves of all.
  for (const SolverReport& r : reports) {
    rep.iterations = std::max(rep.iterations, r.iterations);
    rep.subspace_solves += r.subspace_solves;
    rep.capped = rep.capped || r.capped;
    rep.residual = std::max(rep.residual, r.residual);
    rep.complementarity = std::max(rep.complementarity, r.complementarity);
  }
  return rep;
}

void store_impulses(const Model& model, State& state, const std::vector<Contact>& contacts) {
  state.contact_cache.clear();
  for (const Contact& c : contacts) {
    if (c.type == ContactType::bond) {  // kept with the bond, in a's frame
      state.bonds[c.bond].impulse_a =
          state.orientation[c.body_a].conjugate() * (c.pn * c.normal + c.pt1 * c.t1 + c.pt2 * c.t2);
      continue;
    }
    state.contact_cache.push_back(CachedContact{c.body_a, c.part_a, c.body_b, c.part_b, c.row, c.local_a,
                                                c.pn * c.normal + c.pt1 * c.t1 + c.pt2 * c.t2, c.type,
                                                c.crush_normal_a, c.crush_point_a, c.crush_point_b});
  }
}

}  // namespace floesim::sim
