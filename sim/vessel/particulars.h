// The main particulars and bow angles the level-ice resistance formulas take (PHYSICS.md §6.1-6.2: Lindqvist,
// Riska), measured from a hull mesh in the hull frame (x forward, y to port, z up, calm waterline z = 0). floesim-hull
// writes them to hull.json ("particulars") for the generated hull and for any user's mesh; floesim-resistance and a
// sweep's gather read them back (pipeline/ice_resistance.h).
//
// Definitions (the angles follow the Finnish-Swedish ice class rules' convention, which Riska's formula comes from:
// the entrance angle at B/4, the stem angle at the centreline):
// - waterline: the section of the hull by the plane z = 0. Its main part is the longest stretch in x over which the
//   section is continuous; a rudder or skeg that pierces the water apart from the hull (open water between) is not
//   part of it.
// - L: length of the main waterline (its x extent; for a real ship this is L_wl, about 1 % more than L_pp).
// - B: its beam (y extent); the centreline is the middle of that extent, y_c.
// - T: the draught at mid L (the keel there: a sonar dome or a skeg elsewhere does not count).
// - stem angle phi: the angle between the waterline (+x) and the stem, the forward-most line of the hull's section by
//   the plane y = y_c, fitted by least squares over z in [-T/4, 0] (where the ice meets the stem, and above any
//   bulb on most ships). 90 deg is a vertical stem; above 90 the stem leans aft going up (a bulb ahead of it).
// - entrance angle alpha: the angle between the waterline and the centreline, from the least-squares slope of the
//   waterline's forward edge x(|y - y_c|) over |y - y_c| in [B/4 - B/40, B/4 + B/40], both sides averaged. 90 deg is
//   a waterline square across (a blunt bow).
// - bow angle at B/4, phi_B4: as phi, on the buttock y = y_c +- B/4 (both sides averaged).
// - normal flare psi = arctan(tan phi / sin alpha) (Lindqvist's, PHYSICS.md §6.1); psi_B4 = arctan(tan phi_B4 /
//   sin alpha): the slope, from the horizontal, of the bow surface across the waterline at B/4 measured from the
//   mesh (for a locally plane bow surface the relation is exact).
// - parallel midbody L_par: the longest stretch of the main waterline over which its half-breadth stays within 1 %
//   of B/2; bow length L_bow: from its forward end to the stem at the waterline (the main waterline's forward end).
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "sim/geometry/mesh.h"

namespace floesim::sim {

// Where the measurements are taken (the definitions above; the README quotes them).
struct ParticularsDefinition {
  static constexpr double kEntranceAtBeam = 0.25;     // alpha and phi_B4 at |y - y_c| = B/4 ...
  static constexpr double kEntranceBandBeam = 0.025;  // ... alpha fitted over B/4 +- B/40
  static constexpr double kStemDepthDraught = 0.25;   // phi, phi_B4 fitted over z in [-T/4, 0]
  static constexpr double kParallelTolerance = 0.01;  // parallel midbody: half-breadth >= (1 - 0.01) B/2
};

struct HullParticulars {
  double length_m = 0;               // L
  double beam_m = 0;                 // B
  double draught_m = 0;              // T
  double centreline_y_m = 0;         // y_c
  double x_aft_m = 0, x_stem_m = 0;  // the main waterline's ends (x_stem: the stem at the waterline)
  double stem_angle_deg = 0;         // phi
  double entrance_angle_deg = 0;     // alpha
  double bow_angle_b4_deg = 0;       // phi_B4
  double normal_flare_deg = 0;       // psi = arctan(tan phi / sin alpha)
  double normal_flare_b4_deg = 0;    // psi_B4 = arctan(tan phi_B4 / sin alpha)
  double x_parallel_aft_m = 0, x_parallel_fwd_m = 0;  // the parallel midbody's ends
  double parallel_midbody_m = 0;     // L_par
  double bow_length_m = 0;           // L_bow = x_stem - x_parallel_fwd
};

// Measures a closed hull surface (one closed mesh, or convex parts merged: faces shared between parts lie inside
// and do not disturb the outermost crossings used here). `where` names the hull in errors (a hull that does not
// reach the waterline, or whose bow has no surface at a depth the definitions need).
HullParticulars measure_particulars(const TriMesh& surface, const std::string& where);

// The "particulars" block of hull.json: the values, then "definitions" (one line each, as above).
nlohmann::json particulars_json(const HullParticulars& p);

// Lowest z of the mesh's section by the plane x = const; +inf if the plane misses the mesh.
double lowest_z_at(const TriMesh& m, double x);

}  // namespace floesim::sim
