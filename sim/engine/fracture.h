// The fracture stage of the time step (PHYSICS.md §2.5, the seed's third module): after the relax pass has
// converged, the contact force on each floe, summed over the contacts of one body pair, is compared with the
// closed-form failure loads of sim/engine/fracture_laws.h:
//
//   bending / radial  F_V >= max(P_r(w/l_c), P_f(theta, a/l_c))    out-of-plane: a wedge of angle theta breaks
//                                                                   off (radial cracks at +-theta/2, the
//                                                                   circumferential crack R_b beyond the load:
//                                                                   Nevel's or C_l l_c, fracture.piece_size);
//                                                                   "radial" when P_r governs, "bending" when P_f does
//   splitting         F_H >= C_s K_IC h sqrt(L)                     in-plane: the floe splits along the force line
//
// with F_V, F_H the force components normal to and in the floe's plane (its body frame), w the contact width
// (from the contact surface, never below h) and L the chord of the floe along the force line. When both are
// reached, the mode with the lower threshold for this force's slope happens (§2.4): the larger of F_V / F_V,fail
// and F_H / F_split. Crushing stays the contact law (sim/engine/solver.cpp). At most one event per floe and step; the
// pieces made in a step are tested from the next step on (no cascades inside one step).
//
// This file decides (a pure function of the model, the state and the contacts); the world applies the cuts: the
// broken floe leaves, its pieces enter the body table as new floes (sim/engine/world.cpp).
#pragma once
#include <cstdint>
#include <vector>

#include "pipeline/geometry2d.h"
#include "sim/engine/model.h"
#include "sim/engine/state.h"

namespace floesim::sim {

// One fracture event as the results record it (pipeline/results_io.h, /fracture).
struct FractureEvent {
  double time_s = 0;
  int parent_id = 0;               // floe id of the broken floe
  int32_t mode = 0;                // FractureMode: 1 bending, 2 radial, 3 splitting
  bool at_structure = false;       // at a contact with the vessel (else floe-floe)
  Vec3 force_n = Vec3::Zero();     // contact force on the floe, world
  double threshold_n = 0;          // failure load reached: F_V,fail (bending, radial) or F_split
  Vec3 point_m = Vec3::Zero();     // contact point, world
  double width_m = 0;              // contact width used (>= h)
  double theta_rad = 0;            // wedge angle (0 for splitting)
  double lc_m = 0;                 // characteristic length of the floe's plate
  double rb_m = 0;                 // R_b as cut: load -> circumferential crack (wedges; 0 for splitting)
  double brash_mass_kg = 0;        // pieces below fracture.min_piece_area_m2, removed
  std::vector<int> child_ids;      // the pieces that became bodies
};

// A decided fracture: the floe (body index), its event (children and brash not yet filled) and the pieces'
// outlines in the floe's body frame (CCW; they tile the floe's outline: areas add up to round-off).
struct FractureCut {
  int body = -1;
  FractureEvent event;
  std::vector<Polygon> pieces;
  int wedge_pieces = 0;  // bending and radial: pieces[0, wedge_pieces) are the wedge, the rest what the floe keeps
};

// The fractures of this step from the contacts after the relax pass (impulses over dt are forces). Floes that
// are not alive are not tested (pieces made this step have no contacts yet). Deterministic: contacts are
// sorted, wedge angles come from a hash of (fracture.seed, floe id, step), never from a shared generator.
// `history` is the pair loads' recent forces (State::pair_loads), advanced here by this step's loads.
std::vector<FractureCut> find_fractures(const Model& model, const State& state, const std::vector<Contact>& contacts,
                                        double dt, std::vector<PairLoadHistory>* history);

// The broken wedge's static extent R_b beyond the load point (PHYSICS.md §2.1 step 3), m: Nevel's
// (xi* - alpha) l_c (rb_nevel_over_lc, from wedge_failure) with fracture.piece_size "nevel", C_l l_c with
// "empirical". The speed correction (1 + C_v v_n) multiplies it where the approach speed is known (the fracture step).
double static_piece_rb_m(const FractureOptions& o, double rb_nevel_over_lc, double lc_m);

// A chip: a piece smaller than (h/2)^2 in plan or narrower than h/4, a tall column that a cut's geometry makes rather
// than the ice (the closed-form laws do not resolve cracks that close); no cut leaves one.
bool is_chip(const Polygon& piece, double thickness_m);

// The wedge angle drawn for a floe at a step: uniform in fracture.wedge_angle_deg (radians), from a hash of the seed,
// the floe, the step and the attempt (a cut that would leave a chip is drawn again; attempt 0 is the first draw).
double wedge_angle_rad(const FractureOptions& o, int floe_id, long step, int attempt = 0);

}  // namespace floesim::sim
