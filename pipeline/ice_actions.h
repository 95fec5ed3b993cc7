// Ice actions on fixed structures by the closed forms designers check against (PHYSICS.md §8.1-8.2): ISO 19906's
// global crushing pressure on a vertical structure, and the two level-ice methods for sloping structures and cones,
// Croasdale's (all five terms, as ISO 19906 and OpenFAST's IceFloe state it) and Ralston's plastic limit analysis
// (IEC 61400-3's closed form). In the core, beside the level-ice resistance formulas, so that a structure's summary
// and a sweep's gather hold simulated loads against the very same numbers.
//
// Units are SI throughout (N, m, Pa; angles in degrees at the interface, from the horizontal). Every function
// throws an Error listing what is wrong with its inputs, each problem naming the field by the key a case gives it
// (the simulation's: ice.mu_ice_structure, fracture.flexural_strength_pa, ...) and its valid range.
#pragma once
#include <string>
#include <vector>

namespace floesim {

// The ice sheet that meets the structure.
struct StructureIce {
  double thickness_m = 1.0;               // h
  double flexural_strength_pa = 0.5e6;    // sigma_f
  double youngs_modulus_pa = 5e9;         // E
  double poisson_ratio = 0.3;             // nu
  double ice_density_kg_m3 = 900;         // rho_i
  double water_density_kg_m3 = 1025;      // rho_w
  double gravity_mps2 = 9.81;             // g
  double friction = 0.15;                 // mu: ice-structure friction
};

// Characteristic length L_c = (E h^3 / (12 rho_w g (1 - nu^2)))^(1/4), the l_c of the fracture module (§0.2).
double characteristic_length_m(const StructureIce& ice);

// ---- §8.1: ISO 19906 global crushing on a vertical structure of width w.
enum class IsoCrushingForm {
  iso2019,  // p_G = C_R [(h/h_1)^n (w/h)^m + f_AR], f_AR = e^(-w/3h) sqrt(1 + 5h/w)
  iso2010,  // without f_AR (as OpenFAST's IceFloe implements it)
};
struct IsoCrushing {
  double pressure_pa = 0;  // p_G
  double force_n = 0;      // F_G = p_G w h
};
// C_R is the ice strength coefficient (2.8 MPa for Arctic ice); h_1 = 1 m, m = -0.16, n = -0.5 + h/5 below 1 m and
// -0.3 from 1 m on.
IsoCrushing iso_global_crushing(double thickness_m, double width_m, double strength_coefficient_pa = 2.8e6,
                                IsoCrushingForm form = IsoCrushingForm::iso2019);

// ---- §8.2: a sloping structure (a cone, or a sloping face of width w) and the rubble ridden up on it.
struct SlopingStructure {
  double waterline_width_m = 10;  // w (a cone's waterline diameter)
  double neck_width_m = 0;        // w_T: a cone's top (neck) diameter (Ralston's ride-up weight)
  double slope_deg = 45;          // alpha, from the horizontal
};
struct Rubble {
  double height_m = 0;             // h_r: height of the ride-up pile (Croasdale); 0 = clear ice
  double ride_up_thickness_m = 0;  // h_R: thickness of the ice ridden up the slope (Ralston's weight W)
  double porosity = 0.3;           // e
  double cohesion_pa = 0;          // c
  double pile_slope_deg = 35;      // theta: slope of the rubble pile
  double friction_angle_deg = 45;  // phi: internal friction angle of the rubble
  double ice_ice_friction = 0.1;   // mu_i
};

// Croasdale's method (ISO 19906, 3-D form with the circumferential-crack width L_eff = w + pi^2 L_c / 4).
struct CroasdaleLoad {
  double characteristic_length_m = 0;  // L_c
  double effective_width_m = 0;        // L_eff
  double xi = 0;                       // (sin a + mu cos a) / (cos a - mu sin a)
  double breaking_n = 0;               // H_B
  double push_through_n = 0;           // H_P: pushing the sheet through the rubble
  double ride_up_n = 0;                // H_R: pushing blocks up the slope through the rubble
  double lift_n = 0;                   // H_L: lifting the rubble
  double turning_n = 0;                // H_T: turning the blocks at the top
  double horizontal_n = 0;             // F_H = (H_B + H_P + H_R + H_L + H_T) / (1 - H_B / (sigma_f h L_eff))
  double vertical_breaking_n = 0;      // V_B = H_B / xi
};
// Valid for slopes of 20-70 deg (IceFloe's range) with mu < min(tan a, cot a); with rubble, theta < alpha.
std::vector<std::string> croasdale_problems(const SlopingStructure& s, const StructureIce& ice, const Rubble& r);
CroasdaleLoad croasdale(const SlopingStructure& s, const StructureIce& ice, const Rubble& r);

// Ralston's method (plastic limit analysis, Tresca Y = 2.711), IceFloe's reading: rho_i in G and in W. The complete
// elliptic integrals K(k), E(k) at k = sin a are exact (IceFloe's polynomials agree within 2e-5).
struct RalstonLoad {
  double g_ratio = 0;       // G = rho_i g w^2 / (4 sigma_f h)
  double x = 0;             // 1 + (3G + Y/2)^(-1/2)
  double g_r = 0;           // (sin a + a / cos a) / (2 mu a cos a + (pi/2) sin^2 a)
  double breaking_n = 0;    // H_B
  double ride_up_weight_n = 0;  // W = rho_i g h_R (w^2 - w_T^2) / (4 cos a)
  double ride_up_n = 0;     // H_R
  double horizontal_n = 0;  // F = H_B + H_R
};
std::vector<std::string> ralston_problems(const SlopingStructure& s, const StructureIce& ice, const Rubble& r);
RalstonLoad ralston(const SlopingStructure& s, const StructureIce& ice, const Rubble& r);

// ---- §9: ice ridges. A keel of buoyant rubble under a consolidated layer (the layer itself loads a structure as
// level ice of its thickness h_c: iso_global_crushing, croasdale, ralston; a ship as Lindqvist's level ice).
struct RidgeKeel {
  double depth_m = 8;              // h_k: the depth of unconsolidated rubble the structure or bow meets
  double porosity = 0.3;           // e: macro-porosity of the rubble
  double cohesion_pa = 5e3;        // c: apparent cohesion of the rubble (freeze bonds)
  double friction_angle_deg = 30;  // phi: its internal friction angle
};
std::vector<std::string> keel_problems(const RidgeKeel& k, const StructureIce& ice);

// The keel's effective unit weight gamma_e = (1 - e)(rho_w - rho_i) g: the net buoyancy of the rubble, with which the
// vertical effective stress grows upward from the keel's bottom (N/m^3).
double keel_unit_weight_npm3(const RidgeKeel& k, const StructureIce& ice);

// The keel load on a vertical structure of width w by Dolgopolov et al. (1975), as ISO 19906 adopts it: Rankine's
// passive pressure on the keel's depth with the 3-D factor,
//   F_K = mu_phi h_k w (h_k mu_phi gamma_e / 2 + 2 c) (1 + h_k / (6 w)),   mu_phi = tan(45 deg + phi / 2).
// With the surcharge of the rubble piled in front of the structure, Dolgopolov bounded the design keel depth by
// h_k + w / 2: surcharge_bound_n is F_K there (PHYSICS.md §9.3, §9.5 check 3).
struct KeelLoad {
  double unit_weight_npm3 = 0;  // gamma_e
  double mu_phi = 0;            // tan(45 deg + phi / 2) = sqrt(K_p)
  double friction_n = 0;        // the gamma_e (friction) part of F_K
  double cohesion_n = 0;        // the cohesion part of F_K
  double force_n = 0;           // F_K(h_k)
  double surcharge_bound_n = 0;  // F_K(h_k + w / 2)
};
KeelLoad dolgopolov_keel_load(const RidgeKeel& k, double width_m, const StructureIce& ice);

// The keel's load on a ship's bow, bounded by Rankine's passive force on the bow's vertical projection (PHYSICS.md
// §9.4): the rubble between the consolidated layer's bottom (h_c below the waterline) and the shallower of the
// draught T and the keel's draft H_k, with the effective stress counted from the keel's bottom,
//   R_keel <= B int_{zeta_a}^{zeta_b} (K_p gamma_e zeta + 2 c sqrt(K_p)) d zeta,
//   zeta_a = H_k - min(T, H_k), zeta_b = H_k - h_c.
// An upper bound: a sloping bow pushes the rubble down and aside at less. Here k.depth_m is the keel's draft H_k
// (from the waterline); 0 when the keel does not reach below the layer within the draught.
double keel_ship_bound_n(const RidgeKeel& k, double beam_m, double draught_m, double consolidated_m,
                         const StructureIce& ice);

// The keel-to-sail cross-section ratio of a ridge in hydrostatic balance, the consolidated layer floating freely and
// keel and sail of one porosity: A_k / A_s = rho_i / (rho_w - rho_i) (7.20 for rho_i = 900, 8.49 for 917).
double keel_sail_area_ratio(const StructureIce& ice);

}  // namespace floesim
