// The vessel's loads in open water, as closed forms of its particulars: ITTC-57 resistance and Fossen's wind load.
// The simulator's forces stage (sim/engine/forces.cpp) and floesim-identify (sim/analysis/identify.cpp) share them,
// so that a simulated ship and the ship identified from its data meet the same water and wind.
#pragma once
#include <Eigen/Core>

namespace floesim::sim {

// What the ITTC-57 line needs: R(u) = 1/2 rho S u|u| ((1 + k) C_F(Re) + C_A), C_F = 0.075 / (log10 Re - 2)^2,
// Re = |u| L_wl / nu (held at 1e5 below it).
struct Ittc57 {
  double length_wl_m = 0;              // L_wl, for the Reynolds number
  double wetted_surface_m2 = 0;        // S
  double form_factor_k = 0;            // k
  double roughness_ca = 0;             // C_A
  double water_density_kg_m3 = 1025;   // rho_w
  double kinematic_viscosity_m2ps = 1.83e-6;  // nu
};

// The force opposing a surge speed u through the water (N; sign of u).
double ittc57_resistance(double u_mps, const Ittc57& c);

// Fossen-type wind load in body axes for dynamic pressure q = ½ rho_a V² of the relative wind coming from gamma
// (0 = head wind, positive from port; y to port, z up): X = -q cx cos(gamma) A_F, Y = -q cy sin(gamma) A_L,
// N = -q cn sin(2 gamma) A_L L_oa. Returns (X, Y, N).
Eigen::Vector3d fossen_wind_xyn(double q, double gamma_rad, double frontal_area_m2, double lateral_area_m2,
                                double length_oa_m, double cx, double cy, double cn);

}  // namespace floesim::sim
