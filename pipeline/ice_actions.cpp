#include "pipeline/ice_actions.h"

#include <cmath>
#include <sstream>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"

namespace floesim {

namespace {

double rad(double deg) { return deg * kPi / 180.0; }

std::string range_text(const char* field, double value, const char* what) {
  std::ostringstream s;
  s << field << " " << what << ", got " << value;
  return s.str();
}

// The problems common to every formula: the ice's own numbers.
void ice_problems(const StructureIce& ice, std::vector<std::string>& out) {
  auto positive = [&](const char* field, double v) {
    if (!(std::isfinite(v) && v > 0)) out.push_back(range_text(field, v, "must be > 0"));
  };
  positive("thicknesses_m", ice.thickness_m);
  positive("fracture.flexural_strength_pa", ice.flexural_strength_pa);
  positive("fracture.youngs_modulus_pa", ice.youngs_modulus_pa);
  positive("ice.density_kg_m3", ice.ice_density_kg_m3);
  positive("water.density_kg_m3", ice.water_density_kg_m3);
  positive("water.gravity_mps2", ice.gravity_mps2);
  if (!(ice.poisson_ratio >= 0 && ice.poisson_ratio < 0.5))
    out.push_back(range_text("fracture.poisson_ratio", ice.poisson_ratio, "must be in [0, 0.5)"));
  if (!(ice.friction >= 0 && ice.friction < 2))
    out.push_back(range_text("ice.mu_ice_structure", ice.friction, "must be in [0, 2)"));
}

// A cone's slope and width, and the friction the slope can carry.
void slope_problems(const SlopingStructure& s, const StructureIce& ice, std::vector<std::string>& out) {
  if (!(std::isfinite(s.waterline_width_m) && s.waterline_width_m > 0))
    out.push_back(range_text("structure.waterline_width_m", s.waterline_width_m, "must be > 0"));
  if (!(s.slope_deg >= 20 && s.slope_deg <= 70)) {
    out.push_back(range_text("structure.slope_deg", s.slope_deg,
                             "must be in [20, 70] deg (the range of the sloping-structure methods)"));
    return;
  }
  const double a = rad(s.slope_deg);
  const double limit = std::min(std::tan(a), 1.0 / std::tan(a));
  if (ice.friction >= limit)
    out.push_back(range_text("ice.mu_ice_structure", ice.friction,
                             ("must be below min(tan a, cot a) = " + std::to_string(limit) +
                              " for this slope (the ice would not slide up it)")
                                 .c_str()));
}

void throw_if(const std::vector<std::string>& problems, const char* what) {
  if (problems.empty()) return;
  std::string m = std::string(what) + ": ";
  for (size_t i = 0; i < problems.size(); ++i) m += (i ? "; " : "") + problems[i];
  throw Error(m);
}

}  // namespace

double characteristic_length_m(const StructureIce& ice) {
  const double nu = ice.poisson_ratio;
  const double d = ice.youngs_modulus_pa * std::pow(ice.thickness_m, 3) / (12 * (1 - nu * nu));
  return std::pow(d / (ice.water_density_kg_m3 * ice.gravity_mps2), 0.25);
}

IsoCrushing iso_global_crushing(double h, double w, double c_r, IsoCrushingForm form) {
  std::vector<std::string> p;
  if (!(std::isfinite(h) && h > 0)) p.push_back(range_text("thicknesses_m", h, "must be > 0"));
  if (!(std::isfinite(w) && w > 0)) p.push_back(range_text("structure.waterline_width_m", w, "must be > 0"));
  if (!(std::isfinite(c_r) && c_r > 0)) p.push_back(range_text("strength_coefficient_pa", c_r, "must be > 0"));
  throw_if(p, "ISO 19906 global crushing");
  const double n = h < 1.0 ? -0.5 + h / 5.0 : -0.3, m = -0.16;
  double shape = std::pow(h / 1.0, n) * std::pow(w / h, m);
  if (form == IsoCrushingForm::iso2019) shape += std::exp(-w / (3 * h)) * std::sqrt(1 + 5 * h / w);
  IsoCrushing r;
  r.pressure_pa = c_r * shape;
  r.force_n = r.pressure_pa * w * h;
  return r;
}

std::vector<std::string> croasdale_problems(const SlopingStructure& s, const StructureIce& ice, const Rubble& r) {
  std::vector<std::string> p;
  ice_problems(ice, p);
  slope_problems(s, ice, p);
  if (!(r.height_m >= 0)) p.push_back(range_text("rubble.height_m", r.height_m, "must be >= 0"));
  if (!(r.porosity >= 0 && r.porosity < 1)) p.push_back(range_text("rubble.porosity", r.porosity, "must be in [0, 1)"));
  if (!(r.cohesion_pa >= 0)) p.push_back(range_text("rubble.cohesion_pa", r.cohesion_pa, "must be >= 0"));
  if (!(r.friction_angle_deg > 0 && r.friction_angle_deg < 90))
    p.push_back(range_text("rubble.friction_angle_deg", r.friction_angle_deg, "must be in (0, 90) deg"));
  if (!(r.ice_ice_friction >= 0)) p.push_back(range_text("rubble.mu_ice_ice", r.ice_ice_friction, "must be >= 0"));
  if (!(r.pile_slope_deg > 0 && r.pile_slope_deg < s.slope_deg))
    p.push_back(range_text("rubble.pile_slope_deg", r.pile_slope_deg,
                           "must be in (0, structure.slope_deg): the pile is flatter than the structure"));
  return p;
}

CroasdaleLoad croasdale(const SlopingStructure& s, const StructureIce& ice, const Rubble& r) {
  throw_if(croasdale_problems(s, ice, r), "Croasdale's sloping-structure load");
  const double a = rad(s.slope_deg), th = rad(r.pile_slope_deg), ph = rad(r.friction_angle_deg);
  const double w = s.waterline_width_m, h = ice.thickness_m, mu = ice.friction, mui = r.ice_ice_friction;
  const double rho_i = ice.ice_density_kg_m3, g = ice.gravity_mps2, e = r.porosity, hr = r.height_m;
  const double sa = std::sin(a), ca = std::cos(a), cot_a = ca / sa, cot_th = 1 / std::tan(th);
  CroasdaleLoad o;
  o.characteristic_length_m = characteristic_length_m(ice);
  o.effective_width_m = w + kPi * kPi * o.characteristic_length_m / 4;
  o.xi = (sa + mu * ca) / (ca - mu * sa);
  const double ar = 1 - std::tan(th) / std::tan(a);  // (1 - tan theta / tan alpha)
  const double unit = rho_i * g * (1 - e);            // the rubble's unit weight
  o.breaking_n = 0.68 * o.xi * ice.flexural_strength_pa *
                 std::pow(ice.water_density_kg_m3 * g * std::pow(h, 5) / ice.youngs_modulus_pa, 0.25) *
                 o.effective_width_m;
  o.push_through_n = w * hr * hr * mui * unit * ar * ar / (2 * std::tan(th));
  const double pr = 0.5 * mui * (mui + mu) * unit * hr * hr * sa * (cot_th - cot_a) * ar +
                    0.5 * (mui + mu) * unit * hr * hr * ca * cot_a * ar + hr * h * rho_i * g * (sa + mu * ca) / sa;
  o.ride_up_n = w * pr / (ca - mu * sa);
  o.lift_n = o.xi * w * hr * ar * (0.5 * hr * unit * (cot_th - cot_a + std::tan(ph) * ar) + r.cohesion_pa);
  o.turning_n = 1.5 * w * h * h * rho_i * g * ca / (sa - mu * ca);
  const double sum = o.breaking_n + o.push_through_n + o.ride_up_n + o.lift_n + o.turning_n;
  const double denominator = 1 - o.breaking_n / (ice.flexural_strength_pa * o.effective_width_m * h);
  if (!(denominator > 0))
    throw Error("Croasdale's sloping-structure load: H_B reaches sigma_f h L_eff (the breaking term alone would fail "
                "the sheet in compression): the method does not apply to this slope and ice");
  o.horizontal_n = sum / denominator;
  o.vertical_breaking_n = o.breaking_n / o.xi;
  return o;
}

std::vector<std::string> ralston_problems(const SlopingStructure& s, const StructureIce& ice, const Rubble& r) {
  std::vector<std::string> p;
  ice_problems(ice, p);
  slope_problems(s, ice, p);
  if (!(s.neck_width_m >= 0 && s.neck_width_m < s.waterline_width_m))
    p.push_back(range_text("structure.neck_width_m", s.neck_width_m, "must be in [0, structure.waterline_width_m)"));
  if (!(r.ride_up_thickness_m >= 0))
    p.push_back(range_text("rubble.ride_up_thickness_m", r.ride_up_thickness_m, "must be >= 0"));
  return p;
}

RalstonLoad ralston(const SlopingStructure& s, const StructureIce& ice, const Rubble& r) {
  throw_if(ralston_problems(s, ice, r), "Ralston's cone load");
  constexpr double kY = 2.711;  // Tresca
  const double a = rad(s.slope_deg), sa = std::sin(a), ca = std::cos(a);
  const double w = s.waterline_width_m, h = ice.thickness_m, mu = ice.friction, sf = ice.flexural_strength_pa;
  const double rho_g = ice.ice_density_kg_m3 * ice.gravity_mps2;
  RalstonLoad o;
  o.g_ratio = rho_g * w * w / (4 * sf * h);
  o.x = 1 + 1 / std::sqrt(3 * o.g_ratio + 0.5 * kY);
  o.g_r = (sa + a / ca) / (2 * mu * a * ca + 0.5 * kPi * sa * sa);
  if (!(1 - o.g_r * mu > 0))
    throw Error("Ralston's cone load: 1 - g_r mu <= 0 (ice.friction too high for this slope): the method does not "
                "apply");
  const double x = o.x;
  o.breaking_n = sf * h * h / 3 * std::tan(a) / (1 - o.g_r * mu) *
                 (o.g_ratio * (x - 1) * (x + 2) + (1 + kY * x * std::log(x)) / (x - 1));
  const double k = sa, big_k = std::comp_ellint_1(k), big_e = std::comp_ellint_2(k);
  o.ride_up_weight_n = rho_g * r.ride_up_thickness_m * (w * w - s.neck_width_m * s.neck_width_m) / (4 * ca);
  const double f = mu * big_k * ca + sa;
  o.ride_up_n = o.ride_up_weight_n * (std::tan(a) + mu * (big_e - f * o.g_r * ca)) / (1 - o.g_r * mu);
  o.horizontal_n = o.breaking_n + o.ride_up_n;
  return o;
}

std::vector<std::string> keel_problems(const RidgeKeel& k, const StructureIce& ice) {
  std::vector<std::string> p;
  if (!(std::isfinite(k.depth_m) && k.depth_m > 0))
    p.push_back(range_text("ridge.keel_depth_m", k.depth_m, "must be > 0"));
  if (!(k.porosity > 0 && k.porosity < 1)) p.push_back(range_text("ridge.porosity", k.porosity, "must be in (0, 1)"));
  if (!(std::isfinite(k.cohesion_pa) && k.cohesion_pa >= 0))
    p.push_back(range_text("ridge.cohesion_pa", k.cohesion_pa, "must be >= 0"));
  if (!(k.friction_angle_deg > 0 && k.friction_angle_deg < 90))
    p.push_back(range_text("ridge.friction_angle_deg", k.friction_angle_deg, "must be in (0, 90) deg"));
  if (!(ice.ice_density_kg_m3 > 0 && ice.water_density_kg_m3 > ice.ice_density_kg_m3))
    p.push_back(range_text("ice.density_kg_m3", ice.ice_density_kg_m3,
                           "must be > 0 and below water.density_kg_m3 (a keel floats)"));
  if (!(std::isfinite(ice.gravity_mps2) && ice.gravity_mps2 > 0))
    p.push_back(range_text("water.gravity_mps2", ice.gravity_mps2, "must be > 0"));
  return p;
}

double keel_unit_weight_npm3(const RidgeKeel& k, const StructureIce& ice) {
  return (1 - k.porosity) * (ice.water_density_kg_m3 - ice.ice_density_kg_m3) * ice.gravity_mps2;
}

namespace {
// F_K's two parts at keel depth h on width w.
void dolgopolov_parts(double h, double w, double mu, double gamma, double c, double& friction, double& cohesion) {
  const double three_d = 1 + h / (6 * w);
  friction = mu * h * w * (h * mu * gamma / 2) * three_d;
  cohesion = mu * h * w * (2 * c) * three_d;
}
}  // namespace

KeelLoad dolgopolov_keel_load(const RidgeKeel& k, double w, const StructureIce& ice) {
  std::vector<std::string> p = keel_problems(k, ice);
  if (!(std::isfinite(w) && w > 0)) p.push_back(range_text("structure.waterline_width_m", w, "must be > 0"));
  throw_if(p, "Dolgopolov's keel load");
  KeelLoad r;
  r.unit_weight_npm3 = keel_unit_weight_npm3(k, ice);
  r.mu_phi = std::tan(rad(45 + k.friction_angle_deg / 2));
  dolgopolov_parts(k.depth_m, w, r.mu_phi, r.unit_weight_npm3, k.cohesion_pa, r.friction_n, r.cohesion_n);
  r.force_n = r.friction_n + r.cohesion_n;
  double f, c;
  dolgopolov_parts(k.depth_m + w / 2, w, r.mu_phi, r.unit_weight_npm3, k.cohesion_pa, f, c);
  r.surcharge_bound_n = f + c;
  return r;
}

double keel_ship_bound_n(const RidgeKeel& k, double beam, double draught, double consolidated,
                         const StructureIce& ice) {
  std::vector<std::string> p = keel_problems(k, ice);
  if (!(std::isfinite(beam) && beam > 0)) p.push_back(range_text("beam_m", beam, "must be > 0"));
  if (!(std::isfinite(draught) && draught > 0)) p.push_back(range_text("draught_m", draught, "must be > 0"));
  if (!(std::isfinite(consolidated) && consolidated >= 0))
    p.push_back(range_text("ridge.consolidated_thickness_m", consolidated, "must be >= 0"));
  throw_if(p, "the keel's bound on a ship");
  const double gamma = keel_unit_weight_npm3(k, ice);
  const double kp = std::pow(std::tan(rad(45 + k.friction_angle_deg / 2)), 2);
  const double bottom = std::min(draught, k.depth_m);
  if (bottom <= consolidated) return 0.0;
  const double za = k.depth_m - bottom, zb = k.depth_m - consolidated;
  return beam * (kp * gamma * (zb * zb - za * za) / 2 + 2 * k.cohesion_pa * std::sqrt(kp) * (zb - za));
}

double keel_sail_area_ratio(const StructureIce& ice) {
  std::vector<std::string> p;
  if (!(ice.ice_density_kg_m3 > 0 && ice.water_density_kg_m3 > ice.ice_density_kg_m3))
    p.push_back(range_text("ice.density_kg_m3", ice.ice_density_kg_m3,
                           "must be > 0 and below water.density_kg_m3 (a ridge floats)"));
  throw_if(p, "the keel-to-sail area ratio");
  return ice.ice_density_kg_m3 / (ice.water_density_kg_m3 - ice.ice_density_kg_m3);
}

}  // namespace floesim
