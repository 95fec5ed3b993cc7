#include "sim/vessel/open_water.h"

#include <algorithm>
#include <cmath>

namespace floesim::sim {

double ittc57_resistance(double u, const Ittc57& c) {
  const double au = std::abs(u);
  if (au == 0 || c.wetted_surface_m2 <= 0) return 0.0;
  // The ITTC line is undefined as Re -> 0; below Re = 1e5 the friction coefficient is held (tiny forces anyway).
  const double re = std::max(1e5, au * c.length_wl_m / c.kinematic_viscosity_m2ps);
  const double lg = std::log10(re) - 2.0;
  const double cf = 0.075 / (lg * lg);
  const double ct = (1 + c.form_factor_k) * cf + c.roughness_ca;
  return 0.5 * c.water_density_kg_m3 * c.wetted_surface_m2 * ct * u * au;
}

Eigen::Vector3d fossen_wind_xyn(double q, double gamma_rad, double frontal_area_m2, double lateral_area_m2,
                                double length_oa_m, double cx, double cy, double cn) {
  return Eigen::Vector3d(-q * cx * std::cos(gamma_rad) * frontal_area_m2,  // head wind pushes astern
                         -q * cy * std::sin(gamma_rad) * lateral_area_m2,  // wind from port pushes to starboard
                         // Wind on the bow quarter turns the bow away from the wind (Fossen's C_N ~ sin 2 gamma).
                         -q * cn * std::sin(2 * gamma_rad) * lateral_area_m2 * length_oa_m);
}

}  // namespace floesim::sim
