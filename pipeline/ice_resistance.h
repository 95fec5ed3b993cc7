// Level-ice resistance of a ship by the two empirical formulas the industry checks against (PHYSICS.md §6.1-6.2):
// Lindqvist (1989), split into crushing R_c, bending R_b and submersion R_s, and Riska et al. (1997), C_1 + C_2 v.
// In the core, not in sim/, so that the gather of a sweep (render/) can put them beside simulated resistance.
//
// Units are SI throughout (N, m, Pa, rad inside; angles in degrees at the interface, as a hull.json reports them).
// Riska's formula is written in kN; riska() converts, so that both functions return newtons.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace floesim {

// The hull particulars both formulas take. floesim-hull measures them from the mesh and writes them to hull.json
// ("particulars"; definitions in sim/vessel/particulars.h and the README); read_ice_hull() reads them back.
struct IceHull {
  double length_m = 0;            // L: waterline length
  double beam_m = 0;              // B: waterline beam (over the reamers, if any)
  double draught_m = 0;           // T
  double stem_angle_deg = 0;      // phi: stem angle to the waterline, at the centreline
  double entrance_angle_deg = 0;  // alpha: waterline entrance angle (to the centreline, at B/4)
  double parallel_midbody_m = 0;  // L_par (Riska)
  double bow_length_m = 0;        // L_bow (Riska)
};

// Level ice and water: the ice sheet's thickness and material, and the ice-hull friction.
struct LevelIce {
  double thickness_m = 0;           // h
  double flexural_strength_pa = 0;  // sigma_b (sigma_f)
  double youngs_modulus_pa = 0;     // E
  double poisson_ratio = 0;         // nu
  double ice_density_kg_m3 = 0;     // rho_i
  double water_density_kg_m3 = 0;   // rho_w
  double gravity_mps2 = 0;          // g
  double friction = 0;              // mu: ice-hull friction coefficient
};

struct LindqvistResistance {
  double normal_flare_deg = 0;  // psi = arctan(tan phi / sin alpha)
  double crushing_n = 0;        // R_c (at the stem)
  double bending_n = 0;         // R_b
  double submersion_n = 0;      // R_s (buoyancy of the broken ice pushed down, and its friction)
  double breaking_n = 0;        // (R_c + R_b)(1 + 1.4 v / sqrt(g h)): the breaking part at speed v
  double submersion_at_speed_n = 0;  // R_s (1 + 9.4 v / sqrt(g L)): the submersion part at speed v
  double total_n = 0;           // R_ice = breaking_n + submersion_at_speed_n
};

struct RiskaResistance {
  double c1_n = 0;        // C_1
  double c2_n_per_mps = 0;  // C_2
  double total_n = 0;     // C_1 + C_2 v
};

// What is wrong with the inputs, one message per problem, each naming the field ("hull.stem_angle_deg must be in
// (0, 90) deg, got 95"); empty if the formula can be evaluated. lindqvist() and riska() throw an Error listing them.
std::vector<std::string> lindqvist_problems(const IceHull& hull, const LevelIce& ice, double speed_mps);
std::vector<std::string> riska_problems(const IceHull& hull, double thickness_m, double speed_mps);

// Lindqvist (1989) at speed v (m/s), PHYSICS.md §6.1. The submersion term carries mu (0.7 L - T/tan phi
// - B/(4 tan alpha) + ...): B over (4 tan alpha), the bracketing one public implementation gets wrong.
LindqvistResistance lindqvist(const IceHull& hull, const LevelIce& ice, double speed_mps);

// Riska et al. (1997) at speed v (m/s), PHYSICS.md §6.2 (its constants f_1..f_4, g_1..g_3 give kN with lengths in
// m and phi in degrees; returned here in N). It takes neither the ice's strength nor alpha: only h and geometry.
RiskaResistance riska(const IceHull& hull, double thickness_m, double speed_mps);

// The "particulars" block of a hull.json written by floesim-hull. Errors name the file and the key, and say to
// rerun floesim-hull if the block is missing (a sidecar from an older build).
IceHull read_ice_hull(const std::filesystem::path& hull_json);

// The ice as a run's summary records it (summary.json level_ice.ice: thickness_m, flexural_strength_pa,
// youngs_modulus_pa, poisson_ratio, ice_density_kg_m3, water_density_kg_m3, gravity_mps2, mu_ice_structure), written
// by simulate and read by a sweep's gather. Reading: errors name `where` and the key.
nlohmann::json level_ice_json(const LevelIce& ice);
LevelIce level_ice_from_json(const nlohmann::json& j, const std::string& where);

// One row of a resistance table: both formulas for one thickness and one speed.
struct IceResistanceRow {
  double thickness_m = 0;
  double speed_mps = 0;
  LindqvistResistance lindqvist;
  RiskaResistance riska;
};

// Both formulas over thicknesses x speeds (thickness-major), ice.thickness_m replaced by each thickness in turn:
// the call a sweep's gather makes with the case's hull.json and ice.
std::vector<IceResistanceRow> ice_resistance_table(const IceHull& hull, const LevelIce& ice,
                                                   const std::vector<double>& thicknesses_m,
                                                   const std::vector<double>& speeds_mps);
std::vector<IceResistanceRow> ice_resistance_table(const std::filesystem::path& hull_json, const LevelIce& ice,
                                                   const std::vector<double>& thicknesses_m,
                                                   const std::vector<double>& speeds_mps);

}  // namespace floesim
