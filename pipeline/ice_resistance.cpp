#include "pipeline/ice_resistance.h"

#include <cmath>
#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"

namespace floesim {

namespace {

std::string num(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

double rad(double deg) { return deg * kPi / 180.0; }

// Appends "<name> must be <what>, got <v>" unless ok (NaN and infinities are never ok).
void need(std::vector<std::string>& out, bool ok, double v, const char* name, const char* what) {
  if (!(ok && std::isfinite(v))) out.push_back(std::string(name) + " must be " + what + ", got " + num(v));
}

void hull_dimension_problems(std::vector<std::string>& p, const IceHull& hull) {
  need(p, hull.length_m > 0, hull.length_m, "hull.length_m", "> 0");
  need(p, hull.beam_m > 0, hull.beam_m, "hull.beam_m", "> 0");
  need(p, hull.draught_m > 0, hull.draught_m, "hull.draught_m", "> 0");
}

std::string joined(const std::string& head, const std::vector<std::string>& problems) {
  std::string s = head;
  for (const std::string& m : problems) s += "\n  " + m;
  return s;
}

}  // namespace

std::vector<std::string> lindqvist_problems(const IceHull& hull, const LevelIce& ice, double v) {
  std::vector<std::string> p;
  hull_dimension_problems(p, hull);
  // tan(phi) and 1/tan(phi) both enter: a vertical stem (or a bulb ahead of it) is outside the formula.
  need(p, hull.stem_angle_deg > 0 && hull.stem_angle_deg < 90, hull.stem_angle_deg, "hull.stem_angle_deg",
       "in (0, 90) deg (Lindqvist's stem angle: a vertical stem or a bulb is outside the formula)");
  need(p, hull.entrance_angle_deg > 0 && hull.entrance_angle_deg <= 90, hull.entrance_angle_deg,
       "hull.entrance_angle_deg", "in (0, 90] deg");
  need(p, ice.thickness_m > 0, ice.thickness_m, "ice.thickness_m", "> 0");
  need(p, ice.flexural_strength_pa > 0, ice.flexural_strength_pa, "fracture.flexural_strength_pa", "> 0");
  need(p, ice.youngs_modulus_pa > 0, ice.youngs_modulus_pa, "fracture.youngs_modulus_pa", "> 0");
  need(p, ice.poisson_ratio >= 0 && ice.poisson_ratio < 0.5, ice.poisson_ratio, "fracture.poisson_ratio", "in [0, 0.5)");
  need(p, ice.ice_density_kg_m3 > 0, ice.ice_density_kg_m3, "ice.density_kg_m3", "> 0");
  need(p, ice.water_density_kg_m3 > ice.ice_density_kg_m3, ice.water_density_kg_m3, "water.density_kg_m3",
       ("> the ice density " + num(ice.ice_density_kg_m3) + " kg/m^3 (ice floats)").c_str());
  need(p, ice.gravity_mps2 > 0, ice.gravity_mps2, "water.gravity_mps2", "> 0");
  need(p, ice.friction >= 0, ice.friction, "ice.mu_ice_structure", ">= 0");
  need(p, v >= 0, v, "speed_mps", ">= 0");
  if (p.empty()) {
    // The crushing term divides by 1 - mu sin(phi)/cos(psi): friction that large makes the wedge self-locking and
    // the formula meaningless (negative or infinite).
    const double phi = rad(hull.stem_angle_deg), alpha = rad(hull.entrance_angle_deg);
    const double psi = std::atan2(std::tan(phi), std::sin(alpha));
    const double d = 1.0 - ice.friction * std::sin(phi) / std::cos(psi);
    if (!(d > 0))
      p.push_back("ice.mu_ice_structure = " + num(ice.friction) + " with hull.stem_angle_deg = " +
                  num(hull.stem_angle_deg) + " makes 1 - mu sin(phi)/cos(psi) = " + num(d) +
                  " <= 0 (Lindqvist's crushing term is undefined): lower the friction");
  }
  return p;
}

std::vector<std::string> riska_problems(const IceHull& hull, double h, double v) {
  std::vector<std::string> p;
  hull_dimension_problems(p, hull);
  // Riska takes phi in degrees as a linear factor; 90 deg is the FSICR convention for a bulbous bow.
  need(p, hull.stem_angle_deg > 0 && hull.stem_angle_deg <= 90, hull.stem_angle_deg, "hull.stem_angle_deg",
       "in (0, 90] deg");
  need(p, hull.parallel_midbody_m >= 0, hull.parallel_midbody_m, "hull.parallel_midbody_m", ">= 0");
  need(p, hull.bow_length_m >= 0, hull.bow_length_m, "hull.bow_length_m", ">= 0");
  need(p, h > 0, h, "ice.thickness_m", "> 0");
  need(p, v >= 0, v, "speed_mps", ">= 0");
  return p;
}

LindqvistResistance lindqvist(const IceHull& hull, const LevelIce& ice, double v) {
  const std::vector<std::string> problems = lindqvist_problems(hull, ice, v);
  if (!problems.empty()) throw Error(joined("Lindqvist resistance: bad input:", problems));
  const double L = hull.length_m, B = hull.beam_m, T = hull.draught_m;
  const double h = ice.thickness_m, sb = ice.flexural_strength_pa, mu = ice.friction, g = ice.gravity_mps2;
  const double rw = ice.water_density_kg_m3, ri = ice.ice_density_kg_m3;
  const double phi = rad(hull.stem_angle_deg), alpha = rad(hull.entrance_angle_deg);
  // psi = arctan(tan phi / sin alpha), the normal flare: the slope of the bow surface across the waterline.
  const double psi = std::atan2(std::tan(phi), std::sin(alpha));
  const double sp = std::sin(phi), cp = std::cos(phi), tp = std::tan(phi);
  const double sa = std::sin(alpha), cpsi = std::cos(psi);
  // 1/tan(alpha) as cos/sin, so that a blunt waterline (alpha = 90 deg) gives exactly 0 rather than 1/tan(pi/2).
  const double cot_a = std::cos(alpha) / sa;

  LindqvistResistance r;
  r.normal_flare_deg = psi * 180.0 / kPi;
  r.crushing_n = 0.5 * sb * h * h * (tp + mu * cp / cpsi) / (1.0 - mu * sp / cpsi);
  // 27/64 / sqrt(E / (12 (1 - nu^2) g rho_w)): 0.00313 m^-1/2 for E = 2 GPa, the "0.003" of some codes.
  const double k = 27.0 / 64.0 / std::sqrt(ice.youngs_modulus_pa / (12.0 * (1.0 - ice.poisson_ratio * ice.poisson_ratio) * g * rw));
  r.bending_n = k * sb * B * std::pow(h, 1.5) * (std::tan(psi) + mu * cp / (sa * cpsi)) * (1.0 + 1.0 / cpsi);
  // The friction length: 0.7 L, less the stem's and the entrance's share, B / (4 tan alpha) (not B/4 * tan alpha),
  // plus the submerged stem face.
  const double friction_length =
      0.7 * L - T / tp - B * cot_a / 4.0 + T * cp * cpsi * std::sqrt(1.0 / (sp * sp) + cot_a * cot_a);
  r.submersion_n = (rw - ri) * g * h * B * (T * (B + T) / (B + 2.0 * T) + mu * friction_length);
  r.breaking_n = (r.crushing_n + r.bending_n) * (1.0 + 1.4 * v / std::sqrt(g * h));
  r.submersion_at_speed_n = r.submersion_n * (1.0 + 9.4 * v / std::sqrt(g * L));
  r.total_n = r.breaking_n + r.submersion_at_speed_n;
  return r;
}

RiskaResistance riska(const IceHull& hull, double h, double v) {
  const std::vector<std::string> problems = riska_problems(hull, h, v);
  if (!problems.empty()) throw Error(joined("Riska resistance: bad input:", problems));
  constexpr double f1 = 0.23, f2 = 4.58, f3 = 1.47, f4 = 0.29;  // kN with lengths in m (Riska et al. 1997)
  constexpr double g1 = 18.9, g2 = 0.67, g3 = 1.55;
  const double L = hull.length_m, B = hull.beam_m, T = hull.draught_m, phi = hull.stem_angle_deg;
  const double Lpar = hull.parallel_midbody_m, Lbow = hull.bow_length_m;
  const double c1_kn = f1 * B * Lpar * h / (2.0 * T / B + 1.0) +
                       (1.0 + 0.021 * phi) * (f2 * B * h * h + f3 * Lbow * h * h + f4 * B * Lbow * h);
  const double c2_kn = (1.0 + 0.063 * phi) * (g1 * std::pow(h, 1.5) + g2 * B * h) +
                       g3 * h * (1.0 + 1.2 * T / B) * B * B / std::sqrt(L);
  RiskaResistance r;
  r.c1_n = 1e3 * c1_kn;
  r.c2_n_per_mps = 1e3 * c2_kn;
  r.total_n = r.c1_n + r.c2_n_per_mps * v;
  return r;
}

IceHull read_ice_hull(const std::filesystem::path& file) {
  const std::string where = file.string();
  std::ifstream in(file);
  FLOESIM_REQUIRE(in, where, ": cannot read the hull sidecar (write it with floesim-hull)");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw Error(where + ": not valid JSON: " + e.what());
  }
  if (j.is_object() && j.contains("particulars") && j["particulars"].is_null() && j.contains("particulars_error"))
    throw Error(where + ": floesim-hull could not measure this hull's particulars (" +
                (j["particulars_error"].is_string() ? j["particulars_error"].get<std::string>()
                                                    : j["particulars_error"].dump()) +
                "); give them in the config's \"hull\" section instead");
  FLOESIM_REQUIRE(j.is_object() && j.contains("particulars") && j["particulars"].is_object(), where,
                  ": has no \"particulars\" object (the hull angles and lengths the ice-resistance formulas take); "
                  "rerun floesim-hull (a sidecar from before it measured them, or not a hull.json)");
  const nlohmann::json& p = j["particulars"];
  auto get = [&](const char* key) {
    FLOESIM_REQUIRE(p.contains(key) && p[key].is_number(), where, ": particulars.", key,
                    p.contains(key) ? " must be a number, got " + p[key].dump() : std::string(" is missing"),
                    "; rerun floesim-hull");
    return p[key].get<double>();
  };
  IceHull h;
  h.length_m = get("length_m");
  h.beam_m = get("beam_m");
  h.draught_m = get("draught_m");
  h.stem_angle_deg = get("stem_angle_deg");
  h.entrance_angle_deg = get("entrance_angle_deg");
  h.parallel_midbody_m = get("parallel_midbody_m");
  h.bow_length_m = get("bow_length_m");
  return h;
}

namespace {
// The summary's keys, one list for the writer and the reader.
template <class L, class F>
void for_each_level_ice_field(L& ice, F&& f) {
  f("thickness_m", ice.thickness_m);
  f("flexural_strength_pa", ice.flexural_strength_pa);
  f("youngs_modulus_pa", ice.youngs_modulus_pa);
  f("poisson_ratio", ice.poisson_ratio);
  f("ice_density_kg_m3", ice.ice_density_kg_m3);
  f("water_density_kg_m3", ice.water_density_kg_m3);
  f("gravity_mps2", ice.gravity_mps2);
  f("mu_ice_structure", ice.friction);
}
}  // namespace

nlohmann::json level_ice_json(const LevelIce& ice) {
  nlohmann::json j = nlohmann::json::object();
  for_each_level_ice_field(ice, [&](const char* key, double v) { j[key] = v; });
  return j;
}

LevelIce level_ice_from_json(const nlohmann::json& j, const std::string& where) {
  FLOESIM_REQUIRE(j.is_object(), where, " must be an object");
  LevelIce ice;
  for_each_level_ice_field(ice, [&](const char* key, double& v) {
    FLOESIM_REQUIRE(j.contains(key) && j[key].is_number(), where, ".", key, " is missing or not a number");
    v = j[key].get<double>();
  });
  return ice;
}

std::vector<IceResistanceRow> ice_resistance_table(const IceHull& hull, const LevelIce& ice,
                                                   const std::vector<double>& thicknesses_m,
                                                   const std::vector<double>& speeds_mps) {
  std::vector<IceResistanceRow> rows;
  for (double h : thicknesses_m) {
    LevelIce at = ice;
    at.thickness_m = h;
    for (double v : speeds_mps) {
      IceResistanceRow r;
      r.thickness_m = h;
      r.speed_mps = v;
      r.lindqvist = lindqvist(hull, at, v);
      r.riska = riska(hull, h, v);
      rows.push_back(r);
    }
  }
  return rows;
}

std::vector<IceResistanceRow> ice_resistance_table(const std::filesystem::path& hull_json, const LevelIce& ice,
                                                   const std::vector<double>& thicknesses_m,
                                                   const std::vector<double>& speeds_mps) {
  const IceHull hull = read_ice_hull(hull_json);
  try {
    return ice_resistance_table(hull, ice, thicknesses_m, speeds_mps);
  } catch (const Error& e) {
    throw Error(hull_json.string() + ": " + e.what());
  }
}

}  // namespace floesim
