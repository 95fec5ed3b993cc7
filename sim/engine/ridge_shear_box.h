// A direct shear box on a keel's rubble (issue #36, PHYSICS.md §9.2 and §9.5 check 2): its cohesion c and friction
// angle phi from the peak shear stress at several normal stresses, as a laboratory or in-situ shear box measures them.
// A punch test on a keel reads its rubble at the keel's own normal stress, 1-2 kPa of buoyancy, where a cohesion of a
// few kPa dominates the shear stress and the friction part is smaller than the test's scatter; the box sets the
// normal stress, so the friction part can be made as large as the cohesion and the Mohr-Coulomb line is fitted over
// a range of it.
//
// The rubble is the keel's: blocks of the ridge's sizes released in its lattice (release_blocks) and settled by
// buoyancy, frozen by the same freeze bonds. Buoyant rubble rises, so the box stands upside down to a soil box: its
// base is on top. In a square box of side a, under water:
// - the top frame (held fixed): a plate on top and walls down to the shear plane;
// - the bottom frame: walls from just under the shear plane down past the released blocks; it moves along +x to
//   shear the sample;
// - the loading plate: under the rubble inside the bottom frame, moving with it along x and servo-controlled in z so
//   that the normal stress on the shear plane is the one asked for.
// The blocks rise against the top plate and come to rest; the loading plate comes up under them and holds the normal
// stress (a servo on the stress measured), first for 30 s without friction between the blocks and on the frames (a
// sample that came to rest with friction where the blocks first met stays at a porosity near 0.6; without friction
// they pack as a keel's do by long creep, to about 0.45 in this box), then with friction until the rubble rests (at
// most 60 s). The sample at rest is then sheared once for each bond strength asked, each time from where it rested:
// the freeze bonds form between the blocks that touch then (none for a strength of 0), and the bottom frame and the
// loading plate move along x at a steady speed, the servo following the sample's dilation. Over the shear plane's area
// A(d) = a (a - d) at a travel d:
// - the normal stress sigma = (N + B_l - F_w) / A: the loading plate's push N, the net buoyancy B_l of the blocks
//   whose centre is under the plane, less the vertical load F_w the rubble hangs on the bottom frame's walls;
// - the shear stress tau = F_x / A: the horizontal force on the bottom frame and the loading plate together.
// tau's peak (over a window, within the first peak_within_m of travel) against sigma then, over tests at several
// normal stresses, gives c and phi.
#pragma once
#include <ostream>
#include <vector>

namespace floesim::sim {

struct ShearBoxSpec {
  double normal_stress_pa = 5000;          // sigma asked for on the shear plane
  // The freeze bonds the sample is sheared with, sigma_t = tau_b (0: none): the one consolidated sample is sheared
  // once for each, from where it came to rest, so that tests of several bond strengths differ only in their bonds.
  std::vector<double> bonds_pa = {0};
  double box_m = 8.0;                      // a, the box's inner side
  double sample_height_m = 3.2;            // the rubble released: (1 - porosity) a^2 of it in blocks
  double porosity = 0.35;                  // of the sample as it is expected to consolidate (sets the blocks)
  double block_thickness_m = 0.4;          // the rubble of the punch rig (sim/engine/ridge_punch.h)
  double block_min_m = 0.8, block_max_m = 1.6;
  double speed_mps = 0.02, travel_m = 0.4;  // the shear (slow enough for the plate to follow the sample's dilation)
  // The peak is read within this travel (3.75 % of the default box): further on, blocks wedge between the frames at
  // the box's two ends and the shear stress jumps by half or doubles (from 0.35-0.7 m on in the series looked at), a
  // jam of the box, not the rubble's strength.
  double peak_within_m = 0.3;
  double window_s = 0.5;                   // the shear stress's averaging window (its peak)
  double max_settle_s = 150;               // the blocks' rise may take this long
  int threads = 2, seed = 1;
};

// One shear of the consolidated sample, with one bond strength.
struct ShearTest {
  double bonds_pa = 0;
  int bonds = 0;
  long bonds_broken = 0;
  // At each step the travel d, the shear stress and the normal stress on the plane, and how far the loading plate
  // has moved up (dilation negative: the sample grew).
  std::vector<double> travel_m, tau_pa, sigma_pa, plate_rise_m;
  double tau_peak_pa = 0, sigma_at_peak_pa = 0, peak_at_m = 0;  // the window-mean's peak within peak_within_m
  double tau_residual_pa = 0, sigma_residual_pa = 0;            // means over the last quarter of the travel
  double sigma_mean_pa = 0;                                     // over the whole shear
};

struct ShearBoxResult {
  int blocks = 0;
  double rise_s = 0, consolidate_s = 0;  // simulated time the blocks took to rise to rest, then to consolidate
  bool consolidated_at_rest = false;     // every block still for 2 s at the end (else: the longest consolidation)
  double sample_height_m = 0;            // top plate to loading plate, consolidated
  double plane_depth_m = 0;              // the shear plane under the top plate
  double porosity = 0;                   // 1 - the blocks' volume / (a^2 x the sample's height), consolidated
  double buoyancy_n = 0;                 // the blocks' net buoyancy (rho_w - rho_i) g V
  // Consolidated, over its last second: what holds the rubble down (the vertical load on the top frame) against what
  // pushes it up (the blocks' net buoyancy and the loading plate's push, less what hangs on the bottom frame): equal
  // at rest.
  double held_down_n = 0, pushed_up_n = 0;
  double sigma_consolidated_pa = 0;      // on the shear plane at the end of the consolidation
  std::vector<ShearTest> shears;         // one per spec.bonds_pa, in its order
};

// Builds the rubble in the box and consolidates it at the normal stress; then, for each bond strength, freezes it
// and shears it. `progress` (null: none) gets a line per 5 simulated seconds. Throws floesim::Error if the spec
// cannot make a box (the error names the spec's field) or the released blocks do not come to rest within
// max_settle_s.
ShearBoxResult shear_box_test(const ShearBoxSpec& spec, std::ostream* progress);

}  // namespace floesim::sim
