// Station keeping in ice by closed forms (PHYSICS.md §8.4): the quasi-static catenary of a mooring line with a part
// grounded on a horizontal seabed (inextensible, no seabed friction, the anchor pulled horizontally), a spread of such
// lines holding a body (its restoring force at an offset, its linear stiffness, the offset under a steady load), and
// the PID gains of a dynamic-positioning controller. In the core, so that the structure formula tool, the tests and
// (issue #34's next step) the engine's moored bodies use the same lines.
//
// Units are SI (N, m; azimuths in degrees at the interface). Lines lie in the horizontal plane of the fairleads:
// x forward, y to port. Functions throw an Error listing what is wrong, each problem naming the field.
#pragma once
#include <string>
#include <vector>

#include "pipeline/options.h"

namespace floesim {

// One line: submerged weight per length w_l, fairlead height above the seabed h_d, length L.
struct CatenaryLine {
  double weight_n_per_m = 1000;  // w_l
  double fairlead_height_m = 40;  // h_d
  double length_m = 600;          // L
};

// The line at one horizontal tension H (a = H / w_l the catenary parameter).
struct CatenaryState {
  double horizontal_tension_n = 0;    // H
  double span_m = 0;                  // X: anchor to fairlead, horizontally = L - l_s + x_s
  double suspended_length_m = 0;      // l_s = sqrt(h_d^2 + 2 a h_d)
  double suspended_span_m = 0;        // x_s = a acosh(1 + h_d / a)
  double fairlead_tension_n = 0;      // T_f = H + w_l h_d
  double fairlead_vertical_n = 0;     // V_f = w_l l_s
  double stiffness_n_per_m = 0;       // k_H = dH/dX = w_l / (acosh(1 + h_d/a) - 2 / sqrt(1 + 2a/h_d))
};

// What is wrong with a line, each problem named with `where` (e.g. "mooring.lines[3]").
std::vector<std::string> catenary_problems(const CatenaryLine& line, const std::string& where);
// The line at horizontal tension H > 0; an Error if the whole line would hang (l_s >= L: it lifts its anchor).
CatenaryState catenary_at_tension(const CatenaryLine& line, double horizontal_tension_n);
// The largest horizontal tension with a grounded part (l_s = L) and the span it has then.
double catenary_liftoff_tension_n(const CatenaryLine& line);
// The line at horizontal span X, in (L - h_d, X(liftoff)): H found by bisection on X(H), which rises with H.
CatenaryState catenary_at_span(const CatenaryLine& line, double span_m);

// One mooring line as a case gives it: the catenary, its direction and pretension at the station, its fairlead.
struct MooringLineOptions {
  double weight_n_per_m = 1000;   // w_l
  double fairlead_height_m = 40;  // h_d
  double length_m = 600;          // L
  double azimuth_deg = 0;         // from +x towards +y
  double pretension_n = 300e3;    // H_0: sets the anchor's distance
  std::vector<double> fairlead_m = {0, 0};  // on the body, from its reference point (a structure's axis), body axes
  template <class V>
  void visit(V& v) {
    v.field("weight_n_per_m", weight_n_per_m, "N/m", "submerged weight per metre w_l", positive());
    v.field("fairlead_height_m", fairlead_height_m, "m",
            "fairlead height above the seabed h_d (the anchor lies on the seabed below it)", positive());
    v.field("length_m", length_m, "m", "line length L (longer than fairlead_height_m)", positive());
    v.field("azimuth_deg", azimuth_deg, "deg", "direction from the fairlead to the anchor, from +x towards +y");
    v.field("pretension_n", pretension_n, "N", "horizontal pretension H_0 at the station (places the anchor)",
            positive());
    v.field("fairlead_m", fairlead_m, "m",
            "[x, y] of the fairlead on the body, from its reference point (a structure's axis at the water line), "
            "body axes",
            plane_point());
    if (length_m <= fairlead_height_m)
      v.problem("length_m", "must exceed fairlead_height_m: a line shorter than the depth cannot reach the seabed");
  }
};

// A spread mooring: lines from fairleads on the body (relative to its reference point, body at rest heading +x) to
// anchors on the seabed.
struct MooringLeg {
  CatenaryLine line;
  double fairlead_x_m = 0, fairlead_y_m = 0;  // on the body
  double anchor_x_m = 0, anchor_y_m = 0;      // on the seabed, with the body at its station (offset 0)
};
// A leg at azimuth theta (deg, from +x towards +y) from a fairlead at the reference point, its anchor at the span
// that gives the pretension H_0.
MooringLeg leg_from_pretension(const CatenaryLine& line, double azimuth_deg, double pretension_n);
// The leg of a line as given: from its fairlead at its azimuth, the anchor at the pretension's span beyond it.
MooringLeg mooring_leg(const MooringLineOptions& o);

struct SpreadState {
  double force_x_n = 0, force_y_n = 0;   // restoring force on the body
  double moment_z_nm = 0;                // and yaw moment about its reference point
  std::vector<CatenaryState> lines;     // each leg's line
};
// The legs' pull on the body translated by (dx, dy) from its station (no rotation).
SpreadState spread_at_offset(const std::vector<MooringLeg>& legs, double dx_m, double dy_m);
// The same with the body also turned by dpsi (rad, about its reference point): the fairleads turn with it.
SpreadState spread_at_pose(const std::vector<MooringLeg>& legs, double dx_m, double dy_m, double dpsi_rad);
// Linear surge-sway stiffness at the station: K = sum k_H n n^T + (H / X)(I - n n^T), n each leg's horizontal unit
// vector (the second term the geometric stiffness of lines across the offset). Row-major [xx, xy, yx, yy].
std::vector<double> spread_linear_stiffness(const std::vector<MooringLeg>& legs);
// The offset (dx, dy) at which the legs balance a steady load (fx, fy) on the body (Newton on the restoring force,
// from the linear estimate); an Error if no offset within the legs' lift-off balances it.
struct SpreadOffset {
  double dx_m = 0, dy_m = 0;
  SpreadState state;
};
SpreadOffset spread_offset(const std::vector<MooringLeg>& legs, double load_x_n, double load_y_n);

// PID gains of one degree of freedom of dynamic positioning (§8.4.2): K_p = M w_n^2, K_d = 2 zeta M w_n,
// K_i = K_p w_n / 10, w_n = 2 pi / T_n, M the rigid-body plus added mass (or inertia) of that degree of freedom.
struct DpGains {
  double proportional = 0;  // N/m (N m/rad)
  double derivative = 0;    // N s/m
  double integral = 0;      // N/(m s)
};
DpGains dp_gains(double mass_kg, double natural_period_s, double damping_ratio);

// A dynamic-positioning controller (§8.4.2): PID on the earth-frame position (x, y) and heading psi about a set
// point, fed by a first-order low-pass observer of the measured pose (floe impacts at 0.05-0.5 Hz lie far above the
// DP bandwidth: unfiltered, the D-term would chase single floes), its command turned into body axes and clipped at
// the thrusters' limits. The integral stops growing on an axis that is saturated and would saturate further
// (conditional integration: no wind-up).
struct DpControllerSettings {
  DpGains surge, sway, yaw;          // gains per degree of freedom (yaw: N m/rad, N m s/rad, N m/(rad s))
  double max_force_x_n = 0;          // thrust limits, body axes: surge, sway force and yaw moment (> 0)
  double max_force_y_n = 0;
  double max_moment_z_nm = 0;
  double observer_time_constant_s = 10;  // the low-pass observer's time constant (0: the measured pose as it is)
};

// The demanded (before the limits) and delivered (after) generalised force, body axes: surge, sway, yaw moment.
struct DpCommand {
  double demanded[3] = {0, 0, 0};
  double delivered[3] = {0, 0, 0};
};

class DpController {
 public:
  // The set point (earth frame) and the pose at the start (the observer starts there, the integral at 0).
  DpController(const DpControllerSettings& s, double x_set_m, double y_set_m, double psi_set_rad, double x0_m,
               double y0_m, double psi0_rad);
  // One control step of dt seconds with the measured pose: the command the thrusters are to give until the next.
  DpCommand step(double dt_s, double x_m, double y_m, double psi_rad);
  // What carries over from one step to the next (the observer's pose, the integral, the last pose, whether a step
  // was made), so that a run saved and restored, or one controller per step, goes on exactly as one controller would.
  static constexpr int kMemory = 10;
  std::vector<double> memory() const;
  void set_memory(const std::vector<double>& m);  // an Error unless m has kMemory values

 private:
  DpControllerSettings s_;
  double set_[3];
  double est_[3];       // the observer's pose
  double integral_[3];  // of the error, earth frame (x, y) and heading
  bool first_ = true;
  double prev_[3];
};

}  // namespace floesim
