// The ice-resistance reference tool (floesim-resistance): Lindqvist's and Riska's level-ice resistance
// (PHYSICS.md §6.1-6.2; formulas in pipeline/ice_resistance.h) for a hull and an ice sheet, over thicknesses and
// speeds. The hull's particulars come from the hull.json that floesim-hull writes (measured from the mesh), each
// overridable in the config; the ice takes the simulation's own keys and defaults (SAMS Table 1), from the engine's
// settings structs, so that the reference and a simulated run cannot drift apart.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/ice_resistance.h"
#include "pipeline/options.h"
#include "sim/engine/settings.h"

namespace floesim::sim {

// The ice sheet, in the sections and spellings of the simulate stage (sim/engine/settings.h), with its defaults
// (SAMS Table 1): `ice` for the ice's density and friction, `fracture` for its strength and elasticity. Lindqvist
// calls the flexural strength sigma_b.
struct IceResistanceIceOptions {
  double density_kg_m3 = IceOptions{}.density_kg_m3;        // rho_i
  double mu_ice_structure = IceOptions{}.mu_ice_structure;  // mu
  template <class V>
  void visit(V& v) {
    v.field("density_kg_m3", density_kg_m3, "kg/m^3", "ice density rho_i", positive());
    v.field("mu_ice_structure", mu_ice_structure, "-", "ice-hull friction coefficient mu", in_range(0, 2));
  }
};

struct IceResistanceFractureOptions {
  double flexural_strength_pa = FractureOptions{}.flexural_strength_pa;  // sigma_f (sigma_b)
  double youngs_modulus_pa = FractureOptions{}.youngs_modulus_pa;        // E
  double poisson_ratio = FractureOptions{}.poisson_ratio;                // nu
  template <class V>
  void visit(V& v) {
    v.field("flexural_strength_pa", flexural_strength_pa, "Pa", "flexural strength sigma_f (Lindqvist's sigma_b)",
            positive());
    v.field("youngs_modulus_pa", youngs_modulus_pa, "Pa", "effective Young's modulus E of the ice plate", positive());
    v.field("poisson_ratio", poisson_ratio, "-", "Poisson ratio nu of ice", in_range(0, 0.49));
  }
};

struct IceResistanceWaterOptions {
  double density_kg_m3 = WaterOptions{}.density_kg_m3;  // rho_w
  double gravity_mps2 = WaterOptions{}.gravity_mps2;    // g
  template <class V>
  void visit(V& v) {
    v.field("density_kg_m3", density_kg_m3, "kg/m^3", "sea water density rho_w", positive());
    v.field("gravity_mps2", gravity_mps2, "m/s^2", "gravitational acceleration g", positive());
  }
};

// The hull's particulars: 0 = the value measured by floesim-hull (--hull FILE's "particulars"); a value > 0
// replaces it. Without --hull every one must be given.
struct IceResistanceHullOptions {
  double length_m = 0;            // L
  double beam_m = 0;              // B
  double draught_m = 0;           // T
  double stem_angle_deg = 0;      // phi
  double entrance_angle_deg = 0;  // alpha
  double parallel_midbody_m = 0;  // L_par
  double bow_length_m = 0;        // L_bow
  template <class V>
  void visit(V& v) {
    v.field("length_m", length_m, "m", "L, waterline length; 0 = from --hull", non_negative());
    v.field("beam_m", beam_m, "m", "B, waterline beam; 0 = from --hull", non_negative());
    v.field("draught_m", draught_m, "m", "T, draught; 0 = from --hull", non_negative());
    v.field("stem_angle_deg", stem_angle_deg, "deg", "phi, stem angle to the waterline; 0 = from --hull",
            in_range(0, 90));
    v.field("entrance_angle_deg", entrance_angle_deg, "deg",
            "alpha, waterline entrance angle (at B/4); 0 = from --hull", in_range(0, 90));
    v.field("parallel_midbody_m", parallel_midbody_m, "m", "L_par (Riska); 0 = from --hull", non_negative());
    v.field("bow_length_m", bow_length_m, "m", "L_bow (Riska); 0 = from --hull", non_negative());
  }
};

struct IceResistanceOptions {
  std::vector<double> thicknesses_m = {1.0};       // h: SAMS Table 1's 1 m (simulate reads h from the floes file)
  std::vector<double> speeds_mps = {1.0, 2.0, 3.0};  // v
  IceResistanceIceOptions ice;
  IceResistanceFractureOptions fracture;
  IceResistanceWaterOptions water;
  IceResistanceHullOptions hull;
  template <class V>
  void visit(V& v) {
    // A list of finite numbers, each > 0 (or >= 0 when zero_ok).
    auto list = [](bool zero_ok) {
      return Check<std::vector<double>>([=](const std::vector<double>& a) -> std::string {
        if (a.empty()) return "must list at least one value";
        for (double x : a)
          if (!std::isfinite(x) || x < 0 || (x == 0 && !zero_ok))
            return zero_ok ? "must be numbers >= 0" : "must be numbers > 0";
        return "";
      });
    };
    v.field("thicknesses_m", thicknesses_m, "m", "ice thicknesses h (a list)", list(false));
    v.field("speeds_mps", speeds_mps, "m/s", "ship speeds v (a list)", list(true));
    v.section("ice", ice, "the ice's density and friction (simulate's keys and defaults, SAMS Table 1)");
    v.section("fracture", fracture, "the ice's strength and elasticity (simulate's keys and defaults, SAMS Table 1)");
    v.section("water", water, "the water (defaults: simulate's)");
    v.section("hull", hull, "the hull's particulars, each replacing the one measured in --hull's hull.json");
  }
};

// The ice the formulas take, at thickness h.
LevelIce level_ice(const IceResistanceOptions& o, double thickness_m);

// The hull the formulas take: hull_json's particulars (if the path is not empty) with the config's non-zero values
// in their place. Errors name the file or the key and say how to fix it. `sources` (optional) gets, per field, where
// its value came from (hull_json's path or "config").
IceHull resolve_ice_hull(const IceResistanceOptions& o, const std::filesystem::path& hull_json,
                         const std::string& config_name, std::vector<std::pair<std::string, std::string>>* sources);

// The floesim-resistance stage: both formulas over o.thicknesses_m x o.speeds_mps, written to `out` (FILE.json: the
// table with the hull, ice and provenance; FILE.csv: the table as CSV, and FILE.json beside it), atomically. Returns
// the table as text (printed on stdout). config_file (may be empty) is recorded and names keys in errors.
std::string run_resistance(const IceResistanceOptions& o, const std::filesystem::path& hull_json,
                           const std::filesystem::path& config_file, const std::filesystem::path& out);

}  // namespace floesim::sim
