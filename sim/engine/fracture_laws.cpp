#include "sim/engine/fracture_laws.h"

#include <array>
#include <cmath>
#include <cstddef>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"

namespace floesim::sim {
namespace {


// ---- Tables (data) ----------------------------------------------------------------------------------------------

// Radial-crack coefficient C_r(w/l_c), nu = 0.3: the largest along-edge bending tension at the free edge of a
// semi-infinite floating plate under a vertical load spread uniformly over a width w, sigma = C_r P / h^2.
// Nodes 0.02 ... 2.0 are the table of PHYSICS.md §2.1 at the digits physics-scripts/semiinf.py prints
// (coeffs(w, 0), the stress at the load's centre). Added from the same script's functions:
// - 0.005 and 0.01 (coeffs at the centre), to carry the log(l_c/w) growth of narrow contacts further;
// - 2.5 ... 20: for a wide load the tension peaks not at the centre but ~0.8 l_c inside each end of the load
//   (the centre's stress decays exponentially with w: semiinf.py gives C = 0.0031 at w = 10 l_c, which would make
//   P_r absurdly high). These nodes are the maximum along the edge of the same integrand times cos(k x)
//   (the along-edge transform evaluated off-centre; at x = 0 it is semiinf.py to all printed digits). For
//   w <= 3.5 l_c that maximum is at the centre, so the table's values and these agree where both exist.
constexpr std::array<double, 20> kRadialW{0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 2.5,
                                          3.0,   3.5,  4.0,  5.0,  6.0, 7.0, 8.0, 10.0, 15.0, 20.0};
constexpr std::array<double, 20> kRadialC{9.9680,   8.9250,   7.8820,   6.5033,   5.4606,   4.4187,   3.0474,
                                          2.0305,   1.0836,   0.813436, 0.613587, 0.462945, 0.35233,  0.236806,
                                          0.184921, 0.156258, 0.136926, 0.11003,  0.0733396, 0.0550044};

// Nevel's narrow wedge: P_f/(theta sigma_f h^2) and R_b/l_c = xi* - alpha against alpha = a/l_c. Nodes 0.01 ... 3.0
// are the table of PHYSICS.md §2.1 from physics-scripts/wedge.py's solve() (RK4, domain alpha + 18 l_c), with the
// crack position on a 1e-4 l_c grid rather than the script's ~5e-4 (which puts xi*(1) at 1.858, not 1.8574, and
// R_b(0.02) at 0.3050, on the table's rounding edge).
// Added with the same solve(): 0.0002 ... 0.005 on a 2e-5 l_c grid (the wedge's tip region needs the finer
// steps; converged to the digits given), and 4 ... 30 on 1e-4, toward the semi-infinite-beam limit.
constexpr std::array<double, 25> kWedgeAlpha{0.0002, 0.0005, 0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1,
                                             0.2,    0.3,    0.5,   0.75,  1.0,   1.5,  2.0,  3.0,  4.0,
                                             5.0,    6.0,    8.0,   10.0,  15.0,  20.0, 30.0};
constexpr std::array<double, 25> kWedgeLoad{0.16743, 0.16808, 0.16891, 0.17024, 0.17331, 0.17735, 0.18399,
                                            0.20023, 0.22336, 0.26509, 0.30459, 0.38109, 0.47478, 0.56752,
                                            0.75179, 0.93531, 1.30148, 1.66720, 2.03276, 2.39825, 3.12918,
                                            3.86011, 5.68750, 7.51500, 11.17019};
constexpr std::array<double, 25> kWedgeRb{0.0657, 0.0894, 0.1129, 0.1424, 0.1935, 0.2434, 0.3052, 0.4074, 0.5008,
                                          0.6058, 0.6705, 0.7525, 0.8153, 0.8574, 0.9117, 0.9460, 0.9876, 1.0122,
                                          1.0285, 1.0402, 1.0557, 1.0656, 1.0796, 1.0870, 1.0946};

// ---- Interpolation ------------------------------------------------------------------------------------------------

// Monotone piecewise-cubic Hermite interpolation (Fritsch & Carlson 1980; end slopes as in scipy's
// PchipInterpolator) of y(x) on strictly increasing nodes, at x0 <= xq <= x_{n-1}. Monotone data stay monotone and
// inside the range of the bracketing nodes, so a positive table never interpolates to a non-positive value.
// Linear interpolation was tried and missed the solutions by up to 1.0 % (C_r, linear in log w) and 0.9 %
// (P_f, power law between nodes); this is within 0.5 % of every script value checked (the tests list them).
template <std::size_t N>
double pchip(const std::array<double, N>& x, const std::array<double, N>& y, double xq) {
  static_assert(N >= 3);
  std::size_t i = 0;  // interval [x_i, x_{i+1}] holding xq
  while (i + 2 < N && xq > x[i + 1]) ++i;
  auto h = [&](std::size_t k) { return x[k + 1] - x[k]; };
  auto d = [&](std::size_t k) { return (y[k + 1] - y[k]) / h(k); };
  auto sign = [](double v) { return (v > 0) - (v < 0); };
  auto slope = [&](std::size_t k) {
    if (k == 0 || k == N - 1) {
      // One-sided three-point estimate, kept from overshooting.
      const bool first = k == 0;
      const std::size_t a = first ? 0 : N - 2, b = first ? 1 : N - 3;
      const double m = ((2 * h(a) + h(b)) * d(a) - h(a) * d(b)) / (h(a) + h(b));
      if (sign(m) != sign(d(a))) return 0.0;
      if (sign(d(a)) != sign(d(b)) && std::abs(m) > 3 * std::abs(d(a))) return 3 * d(a);
      return m;
    }
    const double d0 = d(k - 1), d1 = d(k);
    if (d0 * d1 <= 0) return 0.0;  // a local extremum stays one
    const double w1 = 2 * h(k) + h(k - 1), w2 = h(k) + 2 * h(k - 1);
    return (w1 + w2) / (w1 / d0 + w2 / d1);
  };
  const double t = (xq - x[i]) / h(i), hi = h(i);
  const double h00 = (1 + 2 * t) * (1 - t) * (1 - t), h10 = t * (1 - t) * (1 - t);
  const double h01 = t * t * (3 - 2 * t), h11 = t * t * (t - 1);
  return h00 * y[i] + h10 * hi * slope(i) + h01 * y[i + 1] + h11 * hi * slope(i + 1);
}

template <std::size_t N>
std::array<double, N> log_of(const std::array<double, N>& v) {
  std::array<double, N> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = std::log(v[i]);
  return out;
}

void require_positive(double v, const char* what, const char* name) {
  FLOESIM_REQUIRE(std::isfinite(v) && v > 0, what, ": ", name, " must be finite and > 0, got ", v);
}

double require_load(double load, const char* what) {
  FLOESIM_REQUIRE(std::isfinite(load) && load > 0, what, ": load overflows (", load, "); arguments out of scale");
  return load;
}

}  // namespace

double characteristic_length_m(double youngs_pa, double poisson, double thickness_m, double rho_w_g) {
  const char* what = "characteristic_length_m";
  require_positive(youngs_pa, what, "Young's modulus");
  require_positive(thickness_m, what, "thickness");
  require_positive(rho_w_g, what, "rho_w g");
  FLOESIM_REQUIRE(poisson > -1 && poisson < 0.5, what, ": Poisson ratio must be in (-1, 0.5), got ", poisson);
  const double d = youngs_pa * thickness_m * thickness_m * thickness_m / (12 * (1 - poisson * poisson));
  return std::pow(d / rho_w_g, 0.25);
}

// Interpolated in log(w/l_c), where C_r is nearly straight (plate theory: sigma ~ log(l_c/w) under a narrow load).
// Below the first node the log growth continues with the slope of the first interval (1.5047 per e-fold; the
// script gives 1.5047 between 0.02 and 0.05 too, and C_r(0.002) = 11.3468 against 11.3467 extrapolated). Beyond
// the last node the tension near each end of the load depends only on the load per width P/w, so
// C_r = C_r(20) * 20 / (w/l_c): the edge maximum gives C_r w/l_c = 1.1001, 1.1001 and 1.1000 at 20, 30 and 40.
double radial_crack_coefficient(double w_over_lc) {
  require_positive(w_over_lc, "radial_crack_coefficient", "w/l_c");
  static const std::array<double, kRadialW.size()> log_w = log_of(kRadialW);
  constexpr std::size_t n = kRadialW.size();
  if (w_over_lc < kRadialW[0]) {
    const double per_efold = (kRadialC[0] - kRadialC[1]) / (log_w[1] - log_w[0]);
    return kRadialC[0] + per_efold * (log_w[0] - std::log(w_over_lc));
  }
  if (w_over_lc > kRadialW[n - 1]) return kRadialC[n - 1] * (kRadialW[n - 1] / w_over_lc);
  return pchip(log_w, kRadialC, std::log(w_over_lc));
}

double radial_crack_load_n(double sigma_f_pa, double thickness_m, double w_over_lc) {
  const char* what = "radial_crack_load_n";
  require_positive(sigma_f_pa, what, "flexural strength");
  require_positive(thickness_m, what, "thickness");
  return require_load(sigma_f_pa * thickness_m * thickness_m / radial_crack_coefficient(w_over_lc), what);
}

// Interpolated in log(alpha) on log P_f and log R_b (both positive and increasing; power laws between nodes are
// nearly exact, the cubic takes the rest). Out of the table, the two limits of plate theory:
// - alpha -> 0 (load at the apex): near the tip the wedge is a cantilever whose moment per width is
//   P (1 - a/x) - C x^2 (the foundation's reaction), largest at x* ~ a^(1/3), with value ~ P (1 - c a^(2/3)). So
//   xi* = xi*(a0) (alpha/a0)^(1/3) and P_f/(theta sigma_f h^2) = (1/6) / (1 - c (alpha/a0)^(2/3)), c matching the
//   first node: both reach the rigid-tip limit P_f = theta sigma_f h^2 / 6, R_b = 0 at alpha = 0. (wedge.py at
//   alpha = 1e-4 on a 1e-5 grid: 0.16715 and xi* = 0.0521, against 0.16715 and 0.0523 extrapolated.)
// - alpha -> infinity: a semi-infinite beam of width theta a, whose moment peaks (pi/4) sqrt(2) l_c from the load
//   at e^(-pi/4) P l_c: so dP_f/dalpha -> e^(pi/4)/6 theta sigma_f h^2 and R_b -> (pi/4) sqrt(2) l_c = 1.11 l_c,
//   both approached as 1/alpha (the wedge widens by 1/alpha over the crack distance). Beyond the last node:
//   P_f linear with that slope, R_b = R_inf - (R_inf - R_b(30)) 30/alpha. (wedge.py at 50 and 100: 18.48085 and
//   36.75795, R_b 1.1010 and 1.1060, against 18.481 and 36.758, 1.1010 and 1.1059 extrapolated.)
WedgeFailure wedge_failure(double theta_rad, double sigma_f_pa, double thickness_m, double alpha) {
  const char* what = "wedge_failure";
  FLOESIM_REQUIRE(std::isfinite(theta_rad) && theta_rad > 0 && theta_rad <= kPi, what,
                  ": wedge angle must be in (0, pi], got ", theta_rad);
  require_positive(sigma_f_pa, what, "flexural strength");
  require_positive(thickness_m, what, "thickness");
  FLOESIM_REQUIRE(std::isfinite(alpha) && alpha >= 0, what, ": alpha = a/l_c must be finite and >= 0, got ", alpha);
  static const std::array<double, kWedgeAlpha.size()> log_alpha = log_of(kWedgeAlpha);
  static const std::array<double, kWedgeLoad.size()> log_load = log_of(kWedgeLoad);
  static const std::array<double, kWedgeRb.size()> log_rb = log_of(kWedgeRb);
  constexpr std::size_t n = kWedgeAlpha.size();

  double load, rb;  // P_f/(theta sigma_f h^2), R_b/l_c
  if (alpha < kWedgeAlpha[0]) {
    const double s = alpha / kWedgeAlpha[0];
    const double c = 1 - 1 / (6 * kWedgeLoad[0]);
    load = (1.0 / 6) / (1 - c * std::cbrt(s * s));
    const double xi = (kWedgeRb[0] + kWedgeAlpha[0]) * std::cbrt(s);
    rb = xi - alpha;
  } else if (alpha > kWedgeAlpha[n - 1]) {
    const double r_inf = kPi / 4 * std::sqrt(2.0);
    load = kWedgeLoad[n - 1] + std::exp(kPi / 4) / 6 * (alpha - kWedgeAlpha[n - 1]);
    rb = r_inf - (r_inf - kWedgeRb[n - 1]) * (kWedgeAlpha[n - 1] / alpha);
  } else {
    const double la = std::log(alpha);
    load = std::exp(pchip(log_alpha, log_load, la));
    rb = std::exp(pchip(log_alpha, log_rb, la));
  }
  WedgeFailure f;
  f.load_n = require_load(load * theta_rad * sigma_f_pa * thickness_m * thickness_m, what);
  f.rb_over_lc = rb;
  f.xi_star = alpha + rb;
  return f;
}

double splitting_load_n(double c_s, double k_ic_pa_sqrtm, double thickness_m, double length_m) {
  const char* what = "splitting_load_n";
  require_positive(c_s, what, "C_s");
  require_positive(k_ic_pa_sqrtm, what, "fracture toughness");
  require_positive(thickness_m, what, "thickness");
  require_positive(length_m, what, "floe length");
  return require_load(c_s * k_ic_pa_sqrtm * thickness_m * std::sqrt(length_m), what);
}

double vertical_to_horizontal_ratio(double beta_rad, double mu) {
  const char* what = "vertical_to_horizontal_ratio";
  FLOESIM_REQUIRE(std::isfinite(beta_rad) && beta_rad >= 0 && beta_rad <= kPi / 2, what,
                  ": face angle must be in [0, pi/2], got ", beta_rad);
  FLOESIM_REQUIRE(std::isfinite(mu) && mu >= 0, what, ": friction coefficient must be >= 0, got ", mu);
  const double s = std::sin(beta_rad), c = std::cos(beta_rad);
  // A horizontal face without friction takes no horizontal force at all: the ratio is infinite.
  FLOESIM_REQUIRE(s + mu * c > 0, what, ": a horizontal frictionless face has no horizontal force");
  return (c - mu * s) / (s + mu * c);
}

}  // namespace floesim::sim
