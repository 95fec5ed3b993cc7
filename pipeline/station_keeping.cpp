#include "pipeline/station_keeping.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <sstream>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"

namespace floesim {

namespace {

template <class T>
std::string text(const T& v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void throw_if(const std::vector<std::string>& problems, const std::string& what) {
  if (problems.empty()) return;
  std::string m = what + ": ";
  for (size_t i = 0; i < problems.size(); ++i) m += (i ? "; " : "") + problems[i];
  throw Error(m);
}

}  // namespace

std::vector<std::string> catenary_problems(const CatenaryLine& l, const std::string& where) {
  std::vector<std::string> p;
  if (!(std::isfinite(l.weight_n_per_m) && l.weight_n_per_m > 0))
    p.push_back(where + ".weight_n_per_m must be > 0 (the submerged weight per metre), got " + text(l.weight_n_per_m));
  if (!(std::isfinite(l.fairlead_height_m) && l.fairlead_height_m > 0))
    p.push_back(where + ".fairlead_height_m must be > 0: the anchor lies on the seabed below the fairlead, got " +
                text(l.fairlead_height_m));
  if (!(std::isfinite(l.length_m) && l.length_m > l.fairlead_height_m))
    p.push_back(where + ".length_m must exceed the fairlead's height above the seabed (" + text(l.fairlead_height_m) +
                " m): a shorter line cannot reach the seabed, got " + text(l.length_m));
  return p;
}

double catenary_liftoff_tension_n(const CatenaryLine& l) {
  throw_if(catenary_problems(l, "line"), "mooring line");
  // l_s^2 = h_d^2 + 2 a h_d = L^2.
  return l.weight_n_per_m * (l.length_m * l.length_m - l.fairlead_height_m * l.fairlead_height_m) /
         (2 * l.fairlead_height_m);
}

CatenaryState catenary_at_tension(const CatenaryLine& l, double h) {
  throw_if(catenary_problems(l, "line"), "mooring line");
  if (!(std::isfinite(h) && h > 0)) throw Error("mooring line: horizontal tension must be > 0, got " + text(h));
  const double hd = l.fairlead_height_m, a = h / l.weight_n_per_m;
  CatenaryState s;
  s.horizontal_tension_n = h;
  s.suspended_length_m = std::sqrt(hd * hd + 2 * a * hd);
  if (s.suspended_length_m >= l.length_m)
    throw Error("mooring line: at a horizontal tension of " + text(h) + " N the whole line hangs (" +
                text(s.suspended_length_m) + " m suspended of " + text(l.length_m) +
                " m): it would lift its anchor (a longer line, or less tension)");
  s.suspended_span_m = a * std::acosh(1 + hd / a);
  s.span_m = l.length_m - s.suspended_length_m + s.suspended_span_m;
  s.fairlead_tension_n = h + l.weight_n_per_m * hd;
  s.fairlead_vertical_n = l.weight_n_per_m * s.suspended_length_m;
  s.stiffness_n_per_m = l.weight_n_per_m / (std::acosh(1 + hd / a) - 2 / std::sqrt(1 + 2 * a / hd));
  return s;
}

CatenaryState catenary_at_span(const CatenaryLine& l, double x) {
  const double h_max = catenary_liftoff_tension_n(l);
  const double x_min = l.length_m - l.fairlead_height_m;
  // X(H) rises from L - h_d (H -> 0, the line hangs straight down) to the lift-off span.
  const double hd = l.fairlead_height_m, a_max = h_max / l.weight_n_per_m;
  const double x_max = a_max * std::acosh(1 + hd / a_max);  // l_s = L: X = x_s
  if (!(x > x_min && x < x_max))
    throw Error("mooring line: a horizontal span of " + text(x) + " m is outside what the line can span with a part "
                "on the seabed (" + text(x_min) + " m slack to " + text(x_max) + " m at lift-off): move the anchor "
                "or change the line's length");
  // Bisection on log H between a tension far below any load and lift-off: X is monotone, 200 halvings reach the
  // last bit whatever the bracket.
  double lo = h_max * 1e-12, hi = h_max * (1 - 1e-12);
  for (int i = 0; i < 200 && hi > lo * (1 + 1e-15); ++i) {
    const double mid = std::sqrt(lo * hi);
    if (catenary_at_tension(l, mid).span_m < x) lo = mid;
    else hi = mid;
  }
  return catenary_at_tension(l, std::sqrt(lo * hi));
}

MooringLeg leg_from_pretension(const CatenaryLine& line, double azimuth_deg, double pretension_n) {
  const CatenaryState s = catenary_at_tension(line, pretension_n);
  const double t = azimuth_deg * kPi / 180;
  MooringLeg g;
  g.line = line;
  g.anchor_x_m = s.span_m * std::cos(t);
  g.anchor_y_m = s.span_m * std::sin(t);
  return g;
}

MooringLeg mooring_leg(const MooringLineOptions& o) {
  MooringLeg g = leg_from_pretension(CatenaryLine{o.weight_n_per_m, o.fairlead_height_m, o.length_m}, o.azimuth_deg,
                                     o.pretension_n);
  g.fairlead_x_m = o.fairlead_m[0];
  g.fairlead_y_m = o.fairlead_m[1];
  g.anchor_x_m += o.fairlead_m[0];
  g.anchor_y_m += o.fairlead_m[1];
  return g;
}

SpreadState spread_at_offset(const std::vector<MooringLeg>& legs, double dx, double dy) {
  return spread_at_pose(legs, dx, dy, 0.0);
}

SpreadState spread_at_pose(const std::vector<MooringLeg>& legs, double dx, double dy, double dpsi) {
  SpreadState r;
  const double c = std::cos(dpsi), sn = std::sin(dpsi);
  for (size_t i = 0; i < legs.size(); ++i) {
    const MooringLeg& g = legs[i];
    // The fairlead turned with the body about its reference point, then moved with it.
    const double fx = c * g.fairlead_x_m - sn * g.fairlead_y_m, fy = sn * g.fairlead_x_m + c * g.fairlead_y_m;
    const double vx = g.anchor_x_m - (fx + dx), vy = g.anchor_y_m - (fy + dy);
    const double x = std::hypot(vx, vy);
    CatenaryState s;
    try {
      s = catenary_at_span(g.line, x);
    } catch (const Error& e) {
      throw Error("mooring leg " + std::to_string(i) + " at the offset (" + text(dx) + ", " + text(dy) + ") m: " +
                  e.what());
    }
    const double px = s.horizontal_tension_n * vx / x, py = s.horizontal_tension_n * vy / x;
    r.force_x_n += px;
    r.force_y_n += py;
    r.moment_z_nm += fx * py - fy * px;  // the lever from the reference point to the turned fairlead
    r.lines.push_back(s);
  }
  return r;
}

std::vector<double> spread_linear_stiffness(const std::vector<MooringLeg>& legs) {
  std::vector<double> k(4, 0.0);
  for (const MooringLeg& g : legs) {
    const double vx = g.anchor_x_m - g.fairlead_x_m, vy = g.anchor_y_m - g.fairlead_y_m, x = std::hypot(vx, vy);
    const CatenaryState s = catenary_at_span(g.line, x);
    const double nx = vx / x, ny = vy / x, geometric = s.horizontal_tension_n / x;
    k[0] += s.stiffness_n_per_m * nx * nx + geometric * (1 - nx * nx);
    k[1] += (s.stiffness_n_per_m - geometric) * nx * ny;
    k[3] += s.stiffness_n_per_m * ny * ny + geometric * (1 - ny * ny);
  }
  k[2] = k[1];
  return k;
}

SpreadOffset spread_offset(const std::vector<MooringLeg>& legs, double fx, double fy) {
  if (legs.empty()) throw Error("mooring: no legs to hold the load");
  // Newton on R(d) = restoring(d) - restoring(0) + load = 0 (the pretensions' resultant, zero for a balanced spread,
  // is part of the station), with a central-difference Jacobian, from the linear estimate.
  const SpreadState rest = spread_at_offset(legs, 0, 0);
  const std::vector<double> k = spread_linear_stiffness(legs);
  const double det = k[0] * k[3] - k[1] * k[2];
  if (!(det > 0)) throw Error("mooring: the legs give no stiffness in some direction: no offset balances a load");
  double dx = (k[3] * fx - k[1] * fy) / det, dy = (k[0] * fy - k[2] * fx) / det;
  auto residual = [&](double x, double y, double& rx, double& ry) {
    const SpreadState s = spread_at_offset(legs, x, y);
    rx = s.force_x_n - rest.force_x_n + fx;
    ry = s.force_y_n - rest.force_y_n + fy;
  };
  const double scale = std::max(1.0, std::hypot(fx, fy));
  for (int it = 0; it < 100; ++it) {
    double rx, ry;
    residual(dx, dy, rx, ry);
    if (std::hypot(rx, ry) < 1e-9 * scale) break;
    const double e = 1e-4;
    double ax, ay, bx, by, cx, cy, ex, ey;
    residual(dx + e, dy, ax, ay);
    residual(dx - e, dy, bx, by);
    residual(dx, dy + e, cx, cy);
    residual(dx, dy - e, ex, ey);
    const double j00 = (ax - bx) / (2 * e), j10 = (ay - by) / (2 * e), j01 = (cx - ex) / (2 * e),
                 j11 = (cy - ey) / (2 * e);
    const double d = j00 * j11 - j01 * j10;
    if (!(std::abs(d) > 0)) throw Error("mooring: the restoring force stopped changing with the offset (lift-off?)");
    double sx = -(j11 * rx - j01 * ry) / d, sy = -(j00 * ry - j10 * rx) / d;
    // Halve the step until the residual falls (a lift-off span is an Error, so stay within the lines' reach).
    for (int h = 0; h < 30; ++h) {
      double nx, ny;
      try {
        residual(dx + sx, dy + sy, nx, ny);
        if (std::hypot(nx, ny) < std::hypot(rx, ry)) break;
      } catch (const Error&) {
      }
      sx *= 0.5, sy *= 0.5;
    }
    dx += sx, dy += sy;
    if (it == 99) throw Error("mooring: the offset under the load did not converge (the load may exceed what the legs "
                              "can hold before one lifts its anchor)");
  }
  SpreadOffset o;
  o.dx_m = dx;
  o.dy_m = dy;
  o.state = spread_at_offset(legs, dx, dy);
  return o;
}

DpGains dp_gains(double mass_kg, double natural_period_s, double damping_ratio) {
  std::vector<std::string> p;
  if (!(std::isfinite(mass_kg) && mass_kg > 0)) p.push_back("mass_kg must be > 0, got " + text(mass_kg));
  if (!(std::isfinite(natural_period_s) && natural_period_s > 0))
    p.push_back("natural_period_s must be > 0, got " + text(natural_period_s));
  if (!(std::isfinite(damping_ratio) && damping_ratio > 0))
    p.push_back("damping_ratio must be > 0, got " + text(damping_ratio));
  throw_if(p, "dynamic positioning gains");
  const double wn = 2 * kPi / natural_period_s;
  DpGains g;
  g.proportional = mass_kg * wn * wn;
  g.derivative = 2 * damping_ratio * mass_kg * wn;
  g.integral = g.proportional * wn / 10;
  return g;
}

namespace {

// The angle a - b wrapped to (-pi, pi].
double angle_difference(double a, double b) {
  double d = std::fmod(a - b, 2 * kPi);
  if (d > kPi) d -= 2 * kPi;
  if (d <= -kPi) d += 2 * kPi;
  return d;
}

}  // namespace

DpController::DpController(const DpControllerSettings& s, double xs, double ys, double psis, double x0, double y0,
                           double psi0)
    : s_(s), set_{xs, ys, psis}, est_{x0, y0, psi0}, integral_{0, 0, 0}, prev_{x0, y0, psi0} {
  std::vector<std::string> p;
  for (const auto& [g, name] : {std::pair{&s.surge, "surge"}, std::pair{&s.sway, "sway"}, std::pair{&s.yaw, "yaw"}})
    if (!(g->proportional >= 0 && g->derivative >= 0 && g->integral >= 0))
      p.push_back(std::string("dp.") + name + " gains must be >= 0 (a negative gain pushes away from the set point)");
  if (!(s.max_force_x_n > 0 && s.max_force_y_n > 0 && s.max_moment_z_nm > 0))
    p.push_back("dp thrust limits (max_force_x_n, max_force_y_n, max_moment_z_nm) must be > 0");
  if (!(s.observer_time_constant_s >= 0))
    p.push_back("dp.observer_time_constant_s must be >= 0, got " + text(s.observer_time_constant_s));
  throw_if(p, "dynamic positioning");
}

std::vector<double> DpController::memory() const {
  return {est_[0], est_[1], est_[2], integral_[0], integral_[1], integral_[2], prev_[0], prev_[1], prev_[2],
          first_ ? 1.0 : 0.0};
}

void DpController::set_memory(const std::vector<double>& m) {
  FLOESIM_REQUIRE(m.size() == static_cast<size_t>(kMemory), "dynamic positioning: a controller's memory has ",
                  kMemory, " values, not ", m.size());
  for (int k = 0; k < 3; ++k) est_[k] = m[k], integral_[k] = m[3 + k], prev_[k] = m[6 + k];
  first_ = m[9] != 0;
}

DpCommand DpController::step(double dt, double x, double y, double psi) {
  // 1. The observer: x_est += (x - x_est) dt / (T + dt) (backward Euler of the first-order low-pass).
  const double a = s_.observer_time_constant_s > 0 ? dt / (s_.observer_time_constant_s + dt) : 1.0;
  est_[0] += a * (x - est_[0]);
  est_[1] += a * (y - est_[1]);
  est_[2] += a * angle_difference(psi, est_[2]);
  // 2. Errors (earth frame) and their rates from the observed pose.
  const double e[3] = {est_[0] - set_[0], est_[1] - set_[1], angle_difference(est_[2], set_[2])};
  double rate[3] = {0, 0, 0};
  if (!first_) {
    rate[0] = (est_[0] - prev_[0]) / dt;
    rate[1] = (est_[1] - prev_[1]) / dt;
    rate[2] = angle_difference(est_[2], prev_[2]) / dt;
  }
  first_ = false;
  for (int k = 0; k < 3; ++k) prev_[k] = est_[k];
  // 3. The PID command in body axes (surge and sway gains act along the body's axes, so the earth-frame error, rate
  // and integral are turned into them first), with the integral as it stands; clipped at the limits below.
  const DpGains* g[3] = {&s_.surge, &s_.sway, &s_.yaw};
  auto body_command = [&](const double* integral, double* out) {
    const double c = std::cos(est_[2]), sn = std::sin(est_[2]);
    const double eb[3] = {c * e[0] + sn * e[1], -sn * e[0] + c * e[1], e[2]};
    const double rb[3] = {c * rate[0] + sn * rate[1], -sn * rate[0] + c * rate[1], rate[2]};
    const double ib[3] = {c * integral[0] + sn * integral[1], -sn * integral[0] + c * integral[1], integral[2]};
    for (int k = 0; k < 3; ++k)
      out[k] = -(g[k]->proportional * eb[k] + g[k]->derivative * rb[k] + g[k]->integral * ib[k]);
  };
  const double limit[3] = {s_.max_force_x_n, s_.max_force_y_n, s_.max_moment_z_nm};
  DpCommand cmd;
  body_command(integral_, cmd.demanded);
  // 4. Conditional integration: this step's error enters the integral unless some axis is saturated and the error
  // would drive it further into its limit (then the integral is held on every axis, as it is kept in earth axes).
  double trial[3] = {integral_[0] + e[0] * dt, integral_[1] + e[1] * dt, integral_[2] + e[2] * dt};
  double with[3];
  body_command(trial, with);
  bool hold = false;
  for (int k = 0; k < 3; ++k)
    if (std::abs(cmd.demanded[k]) >= limit[k] && std::abs(with[k]) > std::abs(cmd.demanded[k])) hold = true;
  if (!hold)
    for (int k = 0; k < 3; ++k) integral_[k] = trial[k];
  for (int k = 0; k < 3; ++k) cmd.delivered[k] = std::clamp(cmd.demanded[k], -limit[k], limit[k]);
  return cmd;
}

}  // namespace floesim
