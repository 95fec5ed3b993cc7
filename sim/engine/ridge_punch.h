// A punch test on a built keel (issue #36, PHYSICS.md §9.2 and §9.5 check 2): how strong a keel's rubble is, as a
// full-scale punch-through test measures it. A keel is built as a case builds it (settle_ridges: blocks released
// under a consolidated layer, settled by buoyancy, frozen together by freeze bonds), here in a box: a level sheet of
// 12 m x 12 m, 0.5 m thick, in tiles of 4 m, walls on its four sides, the ridge's line across it and its keel as wide
// as the box with steep sides, so that the rubble fills the box under the sheet to about its depth. The sheet's middle
// tile (4 m x 4 m) is taken out and a rigid punch of that size and thickness put in its place (a vessel body held
// fixed: it moves only as it is told). The punch rests, carrying the net buoyancy of the rubble under it (the buoyant
// plug load F_0), then moves down at a steady speed, shearing a plug of rubble out of the keel along its four sides.
// Its vertical load, averaged over a window, peaks at F_p; the plug's sides, 4 a h_p with h_p the keel's depth under
// the sheet as built, carry F_p - F_0 as their mean shear stress tau = (F_p - F_0) / (4 a h_p).
#pragma once
#include <ostream>

namespace floesim::sim {

struct PunchSpec {
  double keel_depth_m = 3.0;                    // as given (the ridge's keel_depth_m)
  double tensile_pa = 0, shear_pa = 0;          // freeze bonds (both 0: none)
  double speed_mps = 0.05, travel_m = 1.5;      // the push
  double rest_s = 2.0, window_s = 0.5;          // the rest before it; the load's averaging window
  int threads = 2, seed = 1;
};

struct PunchResult {
  int blocks = 0, bonds = 0;
  long bonds_broken = 0;
  double settle_s = 0;             // simulated time the rubble took to settle
  double keel_depth_middle_m = 0;  // as built (measure_ridge)
  double plug_height_m = 0;        // h_p: the keel's depth under the sheet, as built
  double porosity = 0;             // as built, by volume
  double gamma_e = 0;              // (1 - e)(rho_w - rho_i) g, N/m^3
  double punch_m = 0;              // a, the punch's side
  double f0_n = 0;                 // the load at the end of the rest
  double f0_by_hand_n = 0;         // gamma_e a^2 h_p: the net buoyancy of the rubble under the punch, were it free
  // At the end of the rest: the rubble's net buoyancy (rho_w - rho_i) g V of its blocks, and what holds it down: the
  // vertical contact force on the punch, the sheet and the walls (the rubble at rest: the two are equal).
  double rubble_buoyancy_n = 0, held_down_n = 0;
  double fpeak_n = 0, peak_at_m = 0;
  double tau_pa = 0;               // (F_p - F_0) / (4 a h_p)
  // The residual: the mean load over the last third of the push, once the plug slides (its bonds broken), and the
  // same as a shear stress on the plug's sides, (F_r - F_0) / (4 a h_p).
  double fresidual_n = 0, tau_residual_pa = 0;
};

// Builds the keel and punches it; `progress` (null: none) gets a line per simulated second. Throws floesim::Error
// if the rig cannot be built (settling's errors included).
PunchResult punch_test(const PunchSpec& spec, std::ostream* progress);

}  // namespace floesim::sim
