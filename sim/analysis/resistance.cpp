#include "sim/analysis/resistance.h"

#include <charconv>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/provenance.h"
#include "sim/analysis/table_text.h"

namespace fs = std::filesystem;

namespace floesim::sim {

LevelIce level_ice(const IceResistanceOptions& o, double h) {
  LevelIce i;
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

IceHull resolve_ice_hull(const IceResistanceOptions& o, const fs::path& hull_json, const std::string& config_name,
                         std::vector<std::pair<std::string, std::string>>* sources) {
  IceHull h;
  if (!hull_json.empty()) h = read_ice_hull(hull_json);
  const std::string cfg = config_name.empty() ? std::string("the config") : config_name;
  std::vector<std::string> missing;
  auto take = [&](const char* key, double given, double& value) {
    if (given > 0) value = given;
    else if (hull_json.empty()) missing.push_back(std::string("hull.") + key);
    if (sources) sources->emplace_back(key, given > 0 ? "config" : hull_json.string());
  };
  take("length_m", o.hull.length_m, h.length_m);
  take("beam_m", o.hull.beam_m, h.beam_m);
  take("draught_m", o.hull.draught_m, h.draught_m);
  take("stem_angle_deg", o.hull.stem_angle_deg, h.stem_angle_deg);
  take("entrance_angle_deg", o.hull.entrance_angle_deg, h.entrance_angle_deg);
  take("parallel_midbody_m", o.hull.parallel_midbody_m, h.parallel_midbody_m);
  take("bow_length_m", o.hull.bow_length_m, h.bow_length_m);
  if (!missing.empty()) {
    std::string m = cfg + ": without --hull (a hull.json written by floesim-hull) every hull particular must be given "
                          "(> 0) in the config; missing:";
    for (const std::string& k : missing) m += " " + k;
    throw Error(m);
  }
  return h;
}

std::string run_resistance(const IceResistanceOptions& o, const fs::path& hull_json, const fs::path& config_file,
                           const fs::path& out) {
  const std::string cfg = config_file.empty() ? std::string("the resistance options") : config_file.string();
  // The options' own checks, also when the struct was filled in code rather than read from JSON.
  check_options(o, cfg);
  const std::string ext = out.extension().string();
  FLOESIM_REQUIRE(ext == ".json" || ext == ".csv", out.string(), ": --out must end in .json or .csv");

  // 1. The hull and the table. An input the formulas refuse is named with where it came from.
  std::vector<std::pair<std::string, std::string>> sources;
  const IceHull hull = resolve_ice_hull(o, hull_json, cfg, &sources);
  std::vector<IceResistanceRow> rows;
  try {
    rows = ice_resistance_table(hull, level_ice(o, 1.0), o.thicknesses_m, o.speeds_mps);
  } catch (const Error& e) {
    std::string from;
    for (const auto& [k, s] : sources) from += "\n  hull." + k + " from " + s;
    throw Error(std::string(e.what()) + "\n(the hull's particulars came from:" + from +
                "\nany of them can be replaced in the config's \"hull\" section, e.g. {\"hull\": {\"stem_angle_deg\": 60}})");
  }

  // 2. The record: hull (with where each value came from), ice, rows in kN, provenance.
  nlohmann::json hj = {{"length_m", hull.length_m},
                       {"beam_m", hull.beam_m},
                       {"draught_m", hull.draught_m},
                       {"stem_angle_deg", hull.stem_angle_deg},
                       {"entrance_angle_deg", hull.entrance_angle_deg},
                       {"parallel_midbody_m", hull.parallel_midbody_m},
                       {"bow_length_m", hull.bow_length_m}};
  for (const auto& [k, s] : sources) hj["source"][k] = s;
  nlohmann::json table = nlohmann::json::array();
  for (const IceResistanceRow& r : rows)
    table.push_back({{"thickness_m", r.thickness_m},
                     {"speed_mps", r.speed_mps},
                     {"lindqvist",
                      {{"normal_flare_deg", r.lindqvist.normal_flare_deg},
                       {"crushing_kN", kn(r.lindqvist.crushing_n)},
                       {"bending_kN", kn(r.lindqvist.bending_n)},
                       {"submersion_kN", kn(r.lindqvist.submersion_n)},
                       {"breaking_at_speed_kN", kn(r.lindqvist.breaking_n)},
                       {"submersion_at_speed_kN", kn(r.lindqvist.submersion_at_speed_n)},
                       {"total_kN", kn(r.lindqvist.total_n)}}},
                     {"riska",
                      {{"c1_kN", kn(r.riska.c1_n)},
                       {"c2_kN_per_mps", kn(r.riska.c2_n_per_mps)},
                       {"total_kN", kn(r.riska.total_n)}}}});
  std::vector<NamedInput> inputs;
  if (!hull_json.empty()) inputs.push_back({"hull", hull_json});
  if (!config_file.empty()) inputs.push_back({"config", config_file});
  nlohmann::json doc;
  doc["provenance"] = make_provenance("floesim-resistance", inputs, options_to_json(o));
  doc["formulas"] = "Lindqvist (1989): R_c, R_b, R_s at rest, R_ice = (R_c + R_b)(1 + 1.4 v/sqrt(g h)) + "
                    "R_s (1 + 9.4 v/sqrt(g L)); Riska et al. (1997): R = C_1 + C_2 v (PHYSICS.md 6.1-6.2)";
  doc["hull"] = hj;
  doc["ice"] = options_to_json(o.ice);
  doc["water"] = options_to_json(o.water);
  doc["rows"] = table;

  // 3. The artefacts, each complete or not at all.
  if (!out.parent_path().empty()) ensure_directory(out.parent_path());
  fs::path json_file = out;
  json_file.replace_extension(".json");
  if (ext == ".csv") {
    std::ostringstream csv;
    csv << "thickness_m,speed_mps,lindqvist_crushing_kN,lindqvist_bending_kN,lindqvist_submersion_kN,"
           "lindqvist_breaking_at_speed_kN,lindqvist_submersion_at_speed_kN,lindqvist_total_kN,riska_c1_kN,"
           "riska_c2_kN_per_mps,riska_total_kN\n";
    for (const IceResistanceRow& r : rows)
      csv << shortest(r.thickness_m) << "," << shortest(r.speed_mps) << "," << shortest(kn(r.lindqvist.crushing_n))
          << "," << shortest(kn(r.lindqvist.bending_n)) << "," << shortest(kn(r.lindqvist.submersion_n)) << ","
          << shortest(kn(r.lindqvist.breaking_n)) << "," << shortest(kn(r.lindqvist.submersion_at_speed_n)) << ","
          << shortest(kn(r.lindqvist.total_n)) << "," << shortest(kn(r.riska.c1_n)) << ","
          << shortest(kn(r.riska.c2_n_per_mps)) << "," << shortest(kn(r.riska.total_n)) << "\n";
    write_text_atomic(out, csv.str());
  }
  write_text_atomic(json_file, doc.dump(2) + "\n");

  // 4. The table as printed.
  std::ostringstream s;
  s << "hull: L " << fixed(hull.length_m, 3) << " m, B " << fixed(hull.beam_m, 3) << " m, T "
    << fixed(hull.draught_m, 3) << " m, phi " << fixed(hull.stem_angle_deg, 2) << " deg, alpha "
    << fixed(hull.entrance_angle_deg, 2) << " deg, L_par " << fixed(hull.parallel_midbody_m, 2) << " m, L_bow "
    << fixed(hull.bow_length_m, 2) << " m"
    << (hull_json.empty() ? std::string(" (from the config)") : " (from " + hull_json.string() + ")") << "\n"
    << "ice: sigma_f " << shortest(o.fracture.flexural_strength_pa / 1e6) << " MPa, E "
    << shortest(o.fracture.youngs_modulus_pa / 1e9) << " GPa, nu " << shortest(o.fracture.poisson_ratio) << ", rho_i "
    << shortest(o.ice.density_kg_m3) << ", rho_w " << shortest(o.water.density_kg_m3) << " kg/m^3, mu "
    << shortest(o.ice.mu_ice_structure) << "; psi " << fixed(rows.front().lindqvist.normal_flare_deg, 2) << " deg\n"
    << "| h (m) | v (m/s) | Lindqvist R_c | R_b | R_s | R_ice (kN) | Riska C_1 | C_2 (kN/(m/s)) | R_ice (kN) |\n"
    << "|---|---|---|---|---|---|---|---|---|\n";
  for (const IceResistanceRow& r : rows)
    s << "| " << shortest(r.thickness_m) << " | " << shortest(r.speed_mps) << " | "
      << fixed(kn(r.lindqvist.crushing_n), 1) << " | " << fixed(kn(r.lindqvist.bending_n), 1) << " | "
      << fixed(kn(r.lindqvist.submersion_n), 1) << " | " << fixed(kn(r.lindqvist.total_n), 1) << " | "
      << fixed(kn(r.riska.c1_n), 1) << " | " << fixed(kn(r.riska.c2_n_per_mps), 1) << " | "
      << fixed(kn(r.riska.total_n), 1) << " |\n";
  s << "-> " << (ext == ".csv" ? out.string() + " (+ " + json_file.filename().string() + ")" : out.string()) << "\n";
  return s.str();
}

}  // namespace floesim::sim
