#include "sim/analysis/ice_actions.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/geometry2d.h"
#include "pipeline/provenance.h"
#include "sim/analysis/table_text.h"

namespace fs = std::filesystem;

namespace floesim::sim {

namespace {

// One thickness's loads on the structure.
struct ThicknessRow {
  double thickness_m = 0;
  IsoCrushing crushing;     // vertical
  CroasdaleLoad croasdale;  // cone
  RalstonLoad ralston;      // cone
};

SlopingStructure sloping(const IceActionsOptions& o) {
  SlopingStructure s;
  s.waterline_width_m = o.structure.waterline_width_m;
  s.neck_width_m = o.structure.neck_width_m;
  s.slope_deg = o.structure.slope_deg;
  return s;
}

nlohmann::json row_json(const IceActionsOptions& o, const ThicknessRow& r) {
  nlohmann::json j = {{"thickness_m", r.thickness_m}};
  if (o.structure.kind == "vertical") {
    j["iso19906"] = {{"pressure_MPa", r.crushing.pressure_pa / 1e6}, {"force_kN", kn(r.crushing.force_n)}};
    return j;
  }
  const CroasdaleLoad& c = r.croasdale;
  j["croasdale"] = {{"characteristic_length_m", c.characteristic_length_m},
                    {"effective_width_m", c.effective_width_m},
                    {"xi", c.xi},
                    {"breaking_kN", kn(c.breaking_n)},
                    {"push_through_kN", kn(c.push_through_n)},
                    {"ride_up_kN", kn(c.ride_up_n)},
                    {"lift_kN", kn(c.lift_n)},
                    {"turning_kN", kn(c.turning_n)},
                    {"horizontal_kN", kn(c.horizontal_n)},
                    {"vertical_breaking_kN", kn(c.vertical_breaking_n)}};
  const RalstonLoad& a = r.ralston;
  j["ralston"] = {{"G", a.g_ratio},
                  {"x", a.x},
                  {"g_r", a.g_r},
                  {"breaking_kN", kn(a.breaking_n)},
                  {"ride_up_weight_kN", kn(a.ride_up_weight_n)},
                  {"ride_up_kN", kn(a.ride_up_n)},
                  {"horizontal_kN", kn(a.horizontal_n)}};
  return j;
}

}  // namespace

StructureIce structure_ice(const IceActionsOptions& o, double h) {
  StructureIce i;
  i.thickness_m = h;
  i.flexural_strength_pa = o.fracture.flexural_strength_pa;
  i.youngs_modulus_pa = o.fracture.youngs_modulus_pa;
  i.poisson_ratio = o.fracture.poisson_ratio;
  i.ice_density_kg_m3 = o.ice.density_kg_m3;
  i.water_density_kg_m3 = o.water.density_kg_m3;
  i.gravity_mps2 = o.water.gravity_mps2;
  i.friction = o.ice.mu_ice_structure;
  return i;
}

std::string run_ice_actions(const IceActionsOptions& o, const fs::path& config_file, const fs::path& out) {
  const std::string cfg = config_file.empty() ? std::string("the ice-action options") : config_file.string();
  check_options(o, cfg);
  const std::string ext = out.extension().string();
  FLOESIM_REQUIRE(ext == ".json" || ext == ".csv", out.string(), ": --out must end in .json or .csv");

  // 1. The structure's loads per thickness; an input a formula refuses is named with the config it came from.
  const bool vertical = o.structure.kind == "vertical";
  std::vector<ThicknessRow> rows;
  try {
    for (double h : o.thicknesses_m) {
      ThicknessRow r;
      r.thickness_m = h;
      if (vertical) {
        r.crushing = iso_global_crushing(h, o.structure.waterline_width_m, o.crushing.strength_coefficient_pa,
                                         o.crushing.form == "2010" ? IsoCrushingForm::iso2010
                                                                   : IsoCrushingForm::iso2019);
      } else {
        r.croasdale = croasdale(sloping(o), structure_ice(o, h), o.rubble.r);
        r.ralston = ralston(sloping(o), structure_ice(o, h), o.rubble.r);
      }
      rows.push_back(r);
    }
  } catch (const Error& e) {
    throw Error(cfg + ": " + e.what());
  }

  // 2. A ridge: the keel per depth (Dolgopolov, and with the surcharge bound h_k + w/2), the consolidated layer as
  // level ice of thickness h_c by the structure's own method, and their sum F_R = F_C + F_K.
  nlohmann::json ridge;
  std::ostringstream ridge_text;
  if (!o.ridge.keel_depths_m.empty()) {
    const double w = o.structure.waterline_width_m, hc = o.ridge.consolidated_thickness_m;
    double layer_n = 0;
    try {
      if (hc > 0)
        layer_n = vertical ? iso_global_crushing(hc, w, o.crushing.strength_coefficient_pa,
                                                 o.crushing.form == "2010" ? IsoCrushingForm::iso2010
                                                                           : IsoCrushingForm::iso2019)
                                 .force_n
                           : croasdale(sloping(o), structure_ice(o, hc), o.rubble.r).horizontal_n;
      nlohmann::json keels = nlohmann::json::array();
      ridge_text << "ridge: keel e " << shortest(o.ridge.keel.porosity) << ", c "
                 << shortest(o.ridge.keel.cohesion_pa / 1e3) << " kPa, phi "
                 << shortest(o.ridge.keel.friction_angle_deg)
                 << " deg; consolidated layer h_c " << shortest(hc) << " m: F_C " << fixed(kn(layer_n), 1)
                 << " kN (" << (vertical ? "ISO 19906" : "Croasdale") << ")\n"
                 << "| h_k (m) | F_K (kN) | friction part | cohesion part | F_K(h_k + w/2) | F_C + F_K (kN) |\n"
                 << "|---|---|---|---|---|---|\n";
      KeelLoad any;  // its unit weight and mu_phi are every depth's
      for (double hk : o.ridge.keel_depths_m) {
        RidgeKeel k = o.ridge.keel;
        k.depth_m = hk;
        const KeelLoad r = dolgopolov_keel_load(k, w, structure_ice(o, hc > 0 ? hc : 1.0));
        any = r;
        keels.push_back({{"keel_depth_m", hk},
                         {"force_kN", kn(r.force_n)},
                         {"friction_kN", kn(r.friction_n)},
                         {"cohesion_kN", kn(r.cohesion_n)},
                         {"surcharge_bound_kN", kn(r.surcharge_bound_n)},
                         {"ridge_total_kN", kn(layer_n + r.force_n)}});
        if (o.ridge.ship_beam_m > 0) {
          RidgeKeel draft = o.ridge.keel;
          draft.depth_m = hk + hc;  // the keel's draft from the waterline
          keels.back()["ship_keel_bound_kN"] = kn(keel_ship_bound_n(draft, o.ridge.ship_beam_m, o.ridge.ship_draught_m,
                                                                    hc, structure_ice(o, hc > 0 ? hc : 1.0)));
        }
        ridge_text << "| " << shortest(hk) << " | " << fixed(kn(r.force_n), 1) << " | " << fixed(kn(r.friction_n), 1)
                   << " | " << fixed(kn(r.cohesion_n), 1) << " | " << fixed(kn(r.surcharge_bound_n), 1) << " | "
                   << fixed(kn(layer_n + r.force_n), 1) << " |\n";
      }
      ridge = {{"keel_unit_weight_N_per_m3", any.unit_weight_npm3},
               {"mu_phi", any.mu_phi},
               {"keel_sail_area_ratio", keel_sail_area_ratio(structure_ice(o, 1.0))},
               {"consolidated_thickness_m", hc},
               {"consolidated_layer_kN", kn(layer_n)},
               {"keels", keels}};
    } catch (const Error& e) {
      throw Error(cfg + ": " + e.what());
    }
  }

  // 3. The mooring: each line at its pretension, the spread's stiffness, the offsets under the loads.
  nlohmann::json mooring;
  std::ostringstream mooring_text;
  if (!o.mooring.lines.empty()) {
    std::vector<MooringLeg> legs;
    nlohmann::json lines = nlohmann::json::array();
    for (size_t i = 0; i < o.mooring.lines.size(); ++i) {
      const MooringLineOptions& l = o.mooring.lines[i];
      const CatenaryLine line{l.weight_n_per_m, l.fairlead_height_m, l.length_m};
      CatenaryState s;
      try {
        s = catenary_at_tension(line, l.pretension_n);
      } catch (const Error& e) {
        throw Error(cfg + ": mooring.lines[" + std::to_string(i) + "]: " + e.what());
      }
      legs.push_back(mooring_leg(l));
      lines.push_back({{"span_m", s.span_m},
                       {"suspended_length_m", s.suspended_length_m},
                       {"suspended_span_m", s.suspended_span_m},
                       {"fairlead_tension_kN", kn(s.fairlead_tension_n)},
                       {"fairlead_vertical_kN", kn(s.fairlead_vertical_n)},
                       {"stiffness_kN_per_m", kn(s.stiffness_n_per_m)},
                       {"liftoff_tension_kN", kn(catenary_liftoff_tension_n(line))}});
    }
    const std::vector<double> k = spread_linear_stiffness(legs);
    mooring["lines"] = lines;
    mooring["linear_stiffness_kN_per_m"] = {{"xx", kn(k[0])}, {"xy", kn(k[1])}, {"yy", kn(k[3])}};
    mooring_text << "mooring: " << legs.size() << " lines; linear stiffness K_xx " << fixed(kn(k[0]), 1)
                 << " kN/m, K_yy " << fixed(kn(k[3]), 1) << " kN/m, K_xy " << fixed(kn(k[1]), 1) << " kN/m\n"
                 << "| load (kN) | offset (m) | linear offset (m) | largest H (kN) | largest T_f (kN) | "
                    "smallest H (kN) |\n|---|---|---|---|---|---|\n";
    nlohmann::json offsets = nlohmann::json::array();
    const double t = o.mooring.load_direction_deg * kPi / 180, cx = std::cos(t), cy = std::sin(t);
    for (double load : o.mooring.loads_n) {
      SpreadOffset so;
      try {
        so = spread_offset(legs, load * cx, load * cy);
      } catch (const Error& e) {
        throw Error(cfg + ": mooring.loads_n " + shortest(load) + " N: " + e.what());
      }
      double h_max = 0, h_min = 1e300, t_max = 0;
      for (const CatenaryState& s : so.state.lines) {
        h_max = std::max(h_max, s.horizontal_tension_n);
        h_min = std::min(h_min, s.horizontal_tension_n);
        t_max = std::max(t_max, s.fairlead_tension_n);
      }
      const double det = k[0] * k[3] - k[1] * k[2];
      const double lx = (k[3] * load * cx - k[1] * load * cy) / det, ly = (k[0] * load * cy - k[2] * load * cx) / det;
      const double offset = std::hypot(so.dx_m, so.dy_m), linear = std::hypot(lx, ly);
      offsets.push_back({{"load_kN", kn(load)},
                         {"offset_x_m", so.dx_m},
                         {"offset_y_m", so.dy_m},
                         {"offset_m", offset},
                         {"linear_offset_m", linear},
                         {"largest_horizontal_tension_kN", kn(h_max)},
                         {"largest_fairlead_tension_kN", kn(t_max)},
                         {"smallest_horizontal_tension_kN", kn(h_min)}});
      mooring_text << "| " << fixed(kn(load), 0) << " | " << fixed(offset, 2) << " | " << fixed(linear, 2) << " | "
                   << fixed(kn(h_max), 0) << " | " << fixed(kn(t_max), 0) << " | " << fixed(kn(h_min), 0) << " |\n";
    }
    mooring["load_direction_deg"] = o.mooring.load_direction_deg;
    mooring["offsets"] = offsets;
  }

  // 4. DP gains.
  nlohmann::json dp;
  std::ostringstream dp_text;
  if (o.dp.mass_kg > 0) {
    const DpGains g = dp_gains(o.dp.mass_kg, o.dp.natural_period_s, o.dp.damping_ratio);
    dp = {{"proportional_kN_per_m", kn(g.proportional)},
          {"derivative_kN_s_per_m", kn(g.derivative)},
          {"integral_kN_per_m_s", kn(g.integral)}};
    dp_text << "DP gains (M " << shortest(o.dp.mass_kg) << " kg, T_n " << shortest(o.dp.natural_period_s)
            << " s, zeta " << shortest(o.dp.damping_ratio) << "): K_p " << fixed(kn(g.proportional), 1)
            << " kN/m, K_d " << fixed(kn(g.derivative), 0) << " kN s/m, K_i " << fixed(kn(g.integral), 3)
            << " kN/(m s)\n";
  }

  // 5. The record.
  nlohmann::json table = nlohmann::json::array();
  for (const ThicknessRow& r : rows) table.push_back(row_json(o, r));
  std::vector<NamedInput> inputs;
  if (!config_file.empty()) inputs.push_back({"config", config_file});
  nlohmann::json doc;
  doc["provenance"] = make_provenance("floesim-ice-actions", inputs, options_to_json(o));
  doc["formulas"] = vertical ? "ISO 19906 global crushing p_G = C_R [(h/h1)^n (w/h)^m + f_AR] (2019; 2010 without "
                               "f_AR), F_G = p_G w h (PHYSICS.md 8.1)"
                             : "Croasdale (ISO 19906, 3-D: H_B, H_P, H_R, H_L, H_T; L_eff = w + pi^2 L_c / 4) and "
                               "Ralston (IEC 61400-3 closed form) for a cone (PHYSICS.md 8.2)";
  doc["structure"] = options_to_json(o.structure);
  doc["rows"] = table;
  if (!ridge.is_null()) doc["ridge"] = ridge;
  if (!mooring.is_null()) doc["mooring"] = mooring;
  if (!dp.is_null()) doc["dp"] = dp;
  if (!out.parent_path().empty()) ensure_directory(out.parent_path());
  fs::path json_file = out;
  json_file.replace_extension(".json");
  if (ext == ".csv") {
    std::ostringstream csv;
    if (vertical) {
      csv << "thickness_m,iso19906_pressure_MPa,iso19906_force_kN\n";
      for (const ThicknessRow& r : rows)
        csv << shortest(r.thickness_m) << "," << shortest(r.crushing.pressure_pa / 1e6) << ","
            << shortest(kn(r.crushing.force_n)) << "\n";
    } else {
      csv << "thickness_m,croasdale_breaking_kN,croasdale_push_through_kN,croasdale_ride_up_kN,croasdale_lift_kN,"
             "croasdale_turning_kN,croasdale_horizontal_kN,croasdale_vertical_breaking_kN,ralston_breaking_kN,"
             "ralston_ride_up_kN,ralston_horizontal_kN\n";
      for (const ThicknessRow& r : rows) {
        const CroasdaleLoad& c = r.croasdale;
        csv << shortest(r.thickness_m) << "," << shortest(kn(c.breaking_n)) << "," << shortest(kn(c.push_through_n))
            << "," << shortest(kn(c.ride_up_n)) << "," << shortest(kn(c.lift_n)) << "," << shortest(kn(c.turning_n))
            << "," << shortest(kn(c.horizontal_n)) << "," << shortest(kn(c.vertical_breaking_n)) << ","
            << shortest(kn(r.ralston.breaking_n)) << "," << shortest(kn(r.ralston.ride_up_n)) << ","
            << shortest(kn(r.ralston.horizontal_n)) << "\n";
      }
    }
    write_text_atomic(out, csv.str());
  }
  write_text_atomic(json_file, doc.dump(2) + "\n");

  // 6. The tables as printed.
  std::ostringstream s;
  s << "structure: " << o.structure.kind << ", waterline width " << shortest(o.structure.waterline_width_m) << " m";
  if (!vertical)
    s << ", neck " << shortest(o.structure.neck_width_m) << " m, slope " << shortest(o.structure.slope_deg) << " deg";
  s << "\nice: sigma_f " << shortest(o.fracture.flexural_strength_pa / 1e6) << " MPa, E "
    << shortest(o.fracture.youngs_modulus_pa / 1e9) << " GPa, nu " << shortest(o.fracture.poisson_ratio)
    << ", rho_i " << shortest(o.ice.density_kg_m3) << ", rho_w " << shortest(o.water.density_kg_m3)
    << " kg/m^3, mu " << shortest(o.ice.mu_ice_structure) << "\n";
  if (vertical) {
    s << "| h (m) | p_G (MPa) | F_G (kN) |\n|---|---|---|\n";
    for (const ThicknessRow& r : rows)
      s << "| " << shortest(r.thickness_m) << " | " << fixed(r.crushing.pressure_pa / 1e6, 3) << " | "
        << fixed(kn(r.crushing.force_n), 1) << " |\n";
  } else {
    s << "rubble: h_r " << shortest(o.rubble.r.height_m) << " m, h_R " << shortest(o.rubble.r.ride_up_thickness_m)
      << " m\n| h (m) | Croasdale H_B | H_P | H_R | H_L | H_T | F_H | V_B (kN) | Ralston H_B | H_R | F (kN) |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const ThicknessRow& r : rows) {
      const CroasdaleLoad& c = r.croasdale;
      s << "| " << shortest(r.thickness_m) << " | " << fixed(kn(c.breaking_n), 1) << " | "
        << fixed(kn(c.push_through_n), 1) << " | " << fixed(kn(c.ride_up_n), 1) << " | " << fixed(kn(c.lift_n), 1)
        << " | " << fixed(kn(c.turning_n), 1) << " | " << fixed(kn(c.horizontal_n), 1) << " | "
        << fixed(kn(c.vertical_breaking_n), 1) << " | " << fixed(kn(r.ralston.breaking_n), 1) << " | "
        << fixed(kn(r.ralston.ride_up_n), 1) << " | " << fixed(kn(r.ralston.horizontal_n), 1) << " |\n";
    }
  }
  s << ridge_text.str() << mooring_text.str() << dp_text.str();
  s << "-> " << (ext == ".csv" ? out.string() + " (+ " + json_file.filename().string() + ")" : out.string()) << "\n";
  return s.str();
}

}  // namespace floesim::sim
