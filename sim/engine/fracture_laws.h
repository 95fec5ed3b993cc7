// Closed-form ice fracture laws of PHYSICS.md §2: the characteristic length of a floating plate, radial-crack
// initiation at a loaded edge, Nevel's wedge (circumferential crack), in-plane splitting, and the vertical to
// horizontal force ratio on an inclined face. Pure functions of their arguments (SI units); the tables they
// interpolate are the plate-theory solutions of PHYSICS.md §2.1 (scripts in ../shared/docs/physics-scripts/).
#pragma once

namespace floesim::sim {

// l_c = (E h^3 / (12 (1 - nu^2) rho_w g))^(1/4), m: the length over which a floating plate bends (§0.2).
double characteristic_length_m(double youngs_pa, double poisson, double thickness_m, double rho_w_g);

// Radial-crack initiation (§2.1 step 1): a vertical edge load P spread over a contact width w puts the free edge
// in bending; the largest along-edge tension is sigma = C_r(w/l_c) P / h^2, so radial cracks start at
// P_r = sigma_f h^2 / C_r. C_r grows as log(l_c/w) for narrow contacts and falls as l_c/w for wide ones.
double radial_crack_coefficient(double w_over_lc);
double radial_crack_load_n(double sigma_f_pa, double thickness_m, double w_over_lc);

// Nevel wedge (§2.1 step 2): failure load P_f of a wedge of full angle theta loaded at alpha = a/l_c from its apex,
// the crack position xi* (apex -> crack, in l_c) and R_b/l_c = xi* - alpha (load -> crack).
struct WedgeFailure {
  double load_n = 0;      // P_f, N
  double xi_star = 0;     // apex -> circumferential crack, in l_c
  double rb_over_lc = 0;  // load -> crack (the broken piece's radial extent beyond the load), in l_c
};
WedgeFailure wedge_failure(double theta_rad, double sigma_f_pa, double thickness_m, double alpha);

// In-plane splitting (§2.2): F_split = C_s K_IC h sqrt(L), N.
double splitting_load_n(double c_s, double k_ic_pa_sqrtm, double thickness_m, double length_m);

// §2.4: F_V/F_H on a face inclined at beta to the horizontal with friction mu:
// (cos b - mu sin b) / (sin b + mu cos b). Negative when the face is too steep to bend the ice down.
double vertical_to_horizontal_ratio(double beta_rad, double mu);

}  // namespace floesim::sim
