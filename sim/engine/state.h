// The mutable state of a simulation (MuJoCo's mjData idea), and the contact record that the collision stage fills
// and the solver reads and updates. Comments say which stage writes each field.
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/geometry/mesh.h"

namespace floesim::sim {

using Quat = Eigen::Quaterniond;

// Rigid: non-penetration with ERP push-out. Crushing: compliant ice crushing (PHYSICS.md §1.8(c)): rigid while the
// normal force is below the crushing force p_c(A) A of the overlap, crushing (hardening with K_t) above it, never
// pushed out and never pulling. Which law a pair gets is chosen per pair of body classes (options.contact).
// Bond: a freeze bond (PHYSICS.md §9.5) holding two material points together, in tension up to tension_limit and in
// shear up to shear_limit (its strengths times its area, per step), in compression without limit.
enum class ContactType : uint8_t { rigid, crushing, bond };

// One contact point between body a and body b (a < b). Written by collide, completed and solved by solve.
struct Contact {
  int body_a = -1, body_b = -1;
  int part_a = -1, part_b = -1;
  int row = 0;                 // crushing contacts: which half of the contact surface this row carries (0, 1)
  Vec3 point = Vec3::Zero();   // world, midway between the surfaces
  Vec3 normal = Vec3::UnitZ(); // world, unit, from a to b
  double gap = 0;              // signed distance along the normal: < 0 overlap, > 0 speculative
  ContactType type = ContactType::rigid;
  double mu = 0;               // friction coefficient
  double max_normal_impulse = std::numeric_limits<double>::infinity();  // N s; dt F_0 for crushing contacts
  // Crushing contacts (collide): nominal contact area of the overlap projected on the contact plane, and the area
  // after a further penetration step along the normal (the clipped geometry re-measured): the step is what this
  // time step adds at the current approach speed (at least contact.area_gradient_step_m).
  double area_m2 = 0;
  double area_end_m2 = 0;      // A(delta + step) >= A
  double area_step_m = 0;      // the step, m
  double area_slope_m = 0;     // (area_end - area) / step, m^2/m
  // Crushed state of the part pair (collide; kept in the cache): where it crushed last, as the contact point held
  // as a material point of a and of b and the normal in a's frame, and how far b's point has moved away from a's
  // along that normal since (>= 0: backed off from the crushed depth). The crushed ice is gone: the row is measured
  // at the crushed depth and lets the pair approach freely over the gap (bias -gap/dt) before it crushes again.
  Vec3 crush_normal_a = Vec3::UnitZ();
  Vec3 crush_point_a = Vec3::Zero(), crush_point_b = Vec3::Zero();
  double crush_gap_m = 0;
  // Horizontal extent of the contact (collide): the two extreme points of the contact surface (crushing) or the
  // point itself (rigid manifold points) along the horizontal tangent z x normal. The fracture stage takes the
  // contact width of a body pair from the spread of these over the pair's contacts (PHYSICS.md §2.1: the real
  // width from the overlap).
  Vec3 span_lo = Vec3::Zero(), span_hi = Vec3::Zero();
  // Crushing law (solve): F_0 = p_c(A_pair) A, its secant gradient K_t = dF/d(delta) over the step, the cap
  // F_end = p_c(A_pair,end) A_end, damping c_n, and W = 1/m_eff of the normal row. A_pair is the contact area of
  // the whole body pair (all its rows), so the pressure does not depend on how the bodies are cut into parts.
  double crush_force_n = 0, crush_force_end_n = 0, crush_stiffness_npm = 0, crush_damping_nspm = 0, inv_mass_n = 0;
  // Solver data (solve): lever arms, tangents, effective masses, bias and the accumulated impulses.
  Vec3 ra = Vec3::Zero(), rb = Vec3::Zero();
  Vec3 t1 = Vec3::Zero(), t2 = Vec3::Zero();
  Vec3 ia_n = Vec3::Zero(), ib_n = Vec3::Zero();    // I^-1 (r x n), world
  Vec3 ia_t1 = Vec3::Zero(), ib_t1 = Vec3::Zero();
  Vec3 ia_t2 = Vec3::Zero(), ib_t2 = Vec3::Zero();
  double mass_n = 0, mass_t1 = 0, mass_t2 = 0;       // effective masses 1/W of the rows
  double bias = 0;                                    // smallest allowed normal velocity (m/s); crushing:
                                                      // -crush_gap_m / dt (free approach to the crushed depth)
  double pn = 0, pt1 = 0, pt2 = 0;                    // accumulated impulses (N s)
  Vec3 local_a = Vec3::Zero();                        // point in a's body frame (warm-start matching)
  bool fixed_a = false, fixed_b = false;              // a body the impulses cannot move (a wall)
  // Bond rows (the world adds them after collide): the bond's index in State::bonds, how far its material point on b
  // is from the one on a (world), the smallest normal impulse (-dt sigma_t A: tension), the radius of the shear
  // impulse's disk (dt tau A), and (solve) the tangential velocities that pull the two points back together (the ERP
  // bias of the tangents; the normal's is `bias`).
  int bond = -1;
  Vec3 bond_separation = Vec3::Zero();
  double tension_limit = 0, shear_limit = 0;          // N s
  double bias_t1 = 0, bias_t2 = 0;                    // m/s
};

// A freeze bond between two blocks of rubble (PHYSICS.md §9.5): where they froze together, as a material point of
// each (body frames) and the contact normal in a's frame, and the area it holds. It takes tension up to
// tensile_strength_pa x area and shear up to shear_strength_pa x area (EngineSettings::freeze_bonds); once either is
// reached it breaks, for good. Its impulse of the last step (in a's frame) warm-starts the next.
struct FreezeBond {
  int body_a = -1, body_b = -1;  // a < b
  Vec3 anchor_a = Vec3::Zero(), anchor_b = Vec3::Zero();
  Vec3 normal_a = Vec3::UnitZ();
  double area_m2 = 0;
  Vec3 impulse_a = Vec3::Zero();
};
inline bool bond_pair_less(const FreezeBond& x, const FreezeBond& y) {
  return x.body_a != y.body_a ? x.body_a < y.body_a : x.body_b < y.body_b;
}

// The part pairs of a body pair whose vector areas point within this cosine (26 deg) of each other press in one
// direction and make one crushing contact (collide); the warm start takes a crushing row's predecessor from the
// cached rows of the same body pair and half whose crushed normals are that close (solve).
constexpr double kSameContactCos = 0.9;

// The impulses of one contact kept for warm starting the next step, keyed by body/part pair and local point (rigid)
// or by body pair, row and crushed normal (crushing: the key's part pair, its first, may change as parts come and
// go), and the crushed state of a crushing contact (the same in both its rows).
struct CachedContact {
  int body_a, part_a, body_b, part_b;
  int row;
  Vec3 local_a;
  Vec3 impulse;  // world: pn n + pt1 t1 + pt2 t2
  ContactType type;
  Vec3 crush_normal_a, crush_point_a, crush_point_b;
};

// The recent contact force of one body pair on a floe, for the failure tests (fracture.load_window_s): the last
// steps' forces in a ring (zero for a step without contact), where the load acted last (world; a level-ice tile
// has one load per patch of contact, told apart by this point).
struct PairLoadHistory {
  int floe = -1, other = -1;
  Vec3 point = Vec3::Zero();
  std::vector<Vec3> force;  // ring of the window's steps, force[step % size] this step's
};

struct State {
  double time_s = 0;
  long step = 0;
  // Per body (index as in Model::bodies). Positions are centres of mass; quaternions body -> world.
  std::vector<Vec3> position;
  std::vector<Quat> orientation;
  std::vector<Vec3> velocity;           // world, m/s
  std::vector<Vec3> angular_velocity;   // world, rad/s
  std::vector<uint8_t> awake;           // 0: sleeping (not integrated, no forces)
  std::vector<uint8_t> alive;           // 0: broken up (replaced by its pieces) or removed as brash: never again
                                        // awake, in the broad phase or in the results
  std::vector<double> still_time_s;     // time spent below the sleep thresholds without contacts
  std::vector<double> heave_lowpass_mps;  // forces: heave velocity through the radiation filter's low pass
                                          // (heave_radiation_force); 0 while asleep, a piece takes its parent's
  std::vector<CachedContact> contact_cache;  // sorted by (body_a, body_b, part_a, part_b)
  std::vector<PairLoadHistory> pair_loads;   // the fracture stage's, sorted by (floe, other), then as made
  std::vector<FreezeBond> bonds;             // the freeze bonds not yet broken, sorted by (body_a, body_b)
  long bonds_broken = 0;                     // freeze bonds broken since the start
  // Vessel controllers.
  double speed_error_integral = 0;      // m, integral of the speed error (PI thrust controller)
  double heading_ref_rad = 0;           // course held by the autopilot
  std::vector<double> dp_memory;        // a DP body's controller (DpController::memory; empty before its first step)
  std::vector<std::vector<double>> structure_dp_memory;  // the same for each structure (Model::structures)
};

}  // namespace floesim::sim
