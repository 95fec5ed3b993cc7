// The structure formula tool (floesim-ice-actions): the closed-form ice actions on a fixed structure (PHYSICS.md §8.1
// ISO 19906 crushing on a vertical face; §8.2 Croasdale's and Ralston's methods on a cone or sloping face; formulas
// in pipeline/ice_actions.h) over ice thicknesses, and the station keeping of a floating one (§8.4: its mooring lines'
// catenaries, the spread's stiffness and its offsets under steady loads, or the DP gains; pipeline/station_keeping.h),
// and a ridge's load (§9.3: the keel by Dolgopolov with its surcharge bound, the consolidated layer as level ice).
// The ice takes the simulation's keys and defaults (SAMS Table 1), as floesim-resistance's does.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/ice_actions.h"
#include "pipeline/options.h"
#include "pipeline/station_keeping.h"
#include "sim/analysis/resistance.h"

namespace floesim::sim {

struct IceActionsStructureOptions {
  std::string kind = "cone";     // "cone" (Croasdale, Ralston) or "vertical" (ISO 19906 crushing)
  double waterline_width_m = 10;  // w
  double neck_width_m = 0;        // w_T (cone)
  double slope_deg = 45;          // alpha (cone)
  template <class V>
  void visit(V& v) {
    v.field("kind", kind, "-", "cone (sloping: Croasdale and Ralston) or vertical (ISO 19906 global crushing)",
            one_of({"cone", "vertical"}));
    v.field("waterline_width_m", waterline_width_m, "m", "width w at the waterline (a cone's waterline diameter)",
            positive());
    v.field("neck_width_m", neck_width_m, "m", "cone: top (neck) diameter w_T, for Ralston's ride-up weight",
            non_negative());
    v.field("slope_deg", slope_deg, "deg", "cone: slope angle alpha from the horizontal (20-70)", in_range(20, 70));
    if (neck_width_m >= waterline_width_m) v.problem("neck_width_m", "must be smaller than waterline_width_m");
  }
};

struct IceActionsCrushingOptions {
  double strength_coefficient_pa = 2.8e6;  // C_R
  std::string form = "2019";
  template <class V>
  void visit(V& v) {
    v.field("strength_coefficient_pa", strength_coefficient_pa, "Pa",
            "ISO 19906 ice strength coefficient C_R (2.8 MPa Arctic)", positive());
    v.field("form", form, "-", "2019 (with the aspect-ratio term f_AR) or 2010 (without, as IceFloe)",
            one_of({"2019", "2010"}));
  }
};

struct IceActionsRubbleOptions {
  Rubble r;
  template <class V>
  void visit(V& v) {
    v.field("height_m", r.height_m, "m", "Croasdale: ride-up rubble height h_r (0 = clear ice)", non_negative());
    v.field("ride_up_thickness_m", r.ride_up_thickness_m, "m",
            "Ralston: thickness h_R of the ice ridden up the slope (0 = none)", non_negative());
    v.field("porosity", r.porosity, "-", "rubble porosity e", in_range(0, 0.95));
    v.field("cohesion_pa", r.cohesion_pa, "Pa", "rubble apparent cohesion c", non_negative());
    v.field("pile_slope_deg", r.pile_slope_deg, "deg", "rubble pile slope theta (below the structure's)",
            in_range(1, 89));
    v.field("friction_angle_deg", r.friction_angle_deg, "deg", "rubble internal friction angle phi", in_range(1, 89));
    v.field("mu_ice_ice", r.ice_ice_friction, "-", "ice-ice friction mu_i in the rubble", in_range(0, 2));
  }
};

struct IceActionsMooringOptions {
  std::vector<MooringLineOptions> lines;
  std::vector<double> loads_n = {1e6, 2e6};
  double load_direction_deg = 0;
  template <class V>
  void visit(V& v) {
    v.list("lines", lines, "the mooring lines (none: no mooring figures), each from the body's reference point");
    v.field("loads_n", loads_n, "N", "steady loads on the body, for the offsets they cause (a list)",
            Check<std::vector<double>>([](const std::vector<double>& a) -> std::string {
              for (double x : a)
                if (!std::isfinite(x) || x < 0) return "must be numbers >= 0";
              return "";
            }));
    v.field("load_direction_deg", load_direction_deg, "deg", "direction of the steady loads, from +x towards +y");
  }
};

struct IceActionsDpOptions {
  double mass_kg = 0;  // 0: no DP figures
  double natural_period_s = 100;
  double damping_ratio = 0.7;
  template <class V>
  void visit(V& v) {
    v.field("mass_kg", mass_kg, "kg", "rigid-body plus added mass of the degree of freedom (0 = no DP gains)",
            non_negative());
    v.field("natural_period_s", natural_period_s, "s", "closed-loop natural period T_n (60-150 s typical)",
            positive());
    v.field("damping_ratio", damping_ratio, "-", "closed-loop damping ratio zeta", positive());
  }
};

struct IceActionsRidgeOptions {
  std::vector<double> keel_depths_m;  // none: no ridge figures
  RidgeKeel keel;
  double consolidated_thickness_m = 0;
  double ship_beam_m = 0, ship_draught_m = 0;  // 0: no ship figures
  template <class V>
  void visit(V& v) {
    v.field("keel_depths_m", keel_depths_m, "m",
            "depths h_k of unconsolidated keel rubble the structure meets (a list; none: no ridge figures)",
            Check<std::vector<double>>([](const std::vector<double>& a) -> std::string {
              for (double x : a)
                if (!std::isfinite(x) || x <= 0) return "must be numbers > 0";
              return "";
            }));
    v.field("porosity", keel.porosity, "-", "keel macro-porosity e (0.25-0.35 measured)", in_range(0.01, 0.95));
    v.field("cohesion_pa", keel.cohesion_pa, "Pa", "keel rubble apparent cohesion c (2-10 kPa)", non_negative());
    v.field("friction_angle_deg", keel.friction_angle_deg, "deg", "keel rubble internal friction angle phi",
            in_range(1, 89));
    v.field("consolidated_thickness_m", consolidated_thickness_m, "m",
            "consolidated layer thickness h_c, loading the structure as level ice of that thickness (0: none)",
            non_negative());
    v.field("ship_beam_m", ship_beam_m, "m",
            "a ship's waterline beam B: each keel's bound on the ship (PHYSICS.md 9.4, Rankine's passive force over "
            "the bow's vertical projection, the keel's draft h_k + h_c; 0: none)",
            non_negative());
    v.field("ship_draught_m", ship_draught_m, "m", "the ship's draught T (with ship_beam_m)", non_negative());
    if ((ship_beam_m > 0) != (ship_draught_m > 0))
      v.problem("ship_draught_m", "give both ship_beam_m and it, or neither");
  }
};

struct IceActionsOptions {
  std::vector<double> thicknesses_m = {0.5, 1.0, 1.5};
  IceActionsStructureOptions structure;
  IceResistanceIceOptions ice;
  IceResistanceFractureOptions fracture;
  IceResistanceWaterOptions water;
  IceActionsCrushingOptions crushing;
  IceActionsRubbleOptions rubble;
  IceActionsMooringOptions mooring;
  IceActionsDpOptions dp;
  IceActionsRidgeOptions ridge;
  template <class V>
  void visit(V& v) {
    v.field("thicknesses_m", thicknesses_m, "m", "ice thicknesses h (a list)",
            Check<std::vector<double>>([](const std::vector<double>& a) -> std::string {
              if (a.empty()) return "must list at least one value";
              for (double x : a)
                if (!std::isfinite(x) || x <= 0) return "must be numbers > 0";
              return "";
            }));
    v.section("structure", structure, "the structure at the waterline");
    v.section("ice", ice, "the ice's density and friction with the structure (simulate's keys and defaults)");
    v.section("fracture", fracture, "the ice's strength and elasticity (simulate's keys and defaults)");
    v.section("water", water, "the water (defaults: simulate's)");
    v.section("crushing", crushing, "ISO 19906 global crushing (vertical structures)");
    v.section("rubble", rubble, "the rubble on a cone (Croasdale) and the ice ridden up it (Ralston)");
    v.section("mooring", mooring, "a spread mooring holding a floating structure");
    v.section("dp", dp, "dynamic positioning gains of one degree of freedom");
    v.section("ridge", ridge, "a ridge: its keel by Dolgopolov (ISO 19906) and its consolidated layer as level ice");
  }
};

// The ice the formulas take at thickness h, from the options.
StructureIce structure_ice(const IceActionsOptions& o, double thickness_m);

// The floesim-ice-actions stage: the formulas for the structure over o.thicknesses_m, the mooring and the DP gains,
// written to `out` (FILE.json: everything with the provenance; FILE.csv: the per-thickness table, and FILE.json
// beside it), atomically. Returns the tables as text (printed on stdout). config_file (may be empty) is recorded.
std::string run_ice_actions(const IceActionsOptions& o, const std::filesystem::path& config_file,
                            const std::filesystem::path& out);

}  // namespace floesim::sim
