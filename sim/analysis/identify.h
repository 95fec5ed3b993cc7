// The identify stage: measured ship data -> ice load time series, by the Fossen-type horizontal-plane model of
// Kjerstad et al. (2018) (PHYSICS.md §4.4):
//
//   M nu_dot = tau_thr + tau_hyd(nu) + tau_wind + tau_ice     =>     tau_ice = M nu_dot - tau_thr - tau_hyd - tau_wind
//
// in surge, sway and yaw (nu = [u v r], body frame). Axes and signs are those of floesim-simulate: x forward,
// y to port, z up, r > 0 turning the bow to port; every tau is a force (moment) ON the ship, so ice that resists the
// ship's advance gives a negative surge ice load (the resistance is its negative), as mean_surge_ice_load_N of
// simulate's summary.json.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/options.h"

namespace floesim::sim {

// The rigid-body mass matrix, diagonal, surge/sway/yaw. Default: the seed's Oden value 1e6 diag[13 kg, 13 kg,
// 9286.4 kg m^2] (added mass neglected or lumped, PHYSICS.md §4.4).
struct IdentifyMassOptions {
  double surge_kg = 13e6;        // M_11
  double sway_kg = 13e6;         // M_22
  double yaw_kg_m2 = 9.2864e9;   // M_33 = I_z (yaw radius of gyration 26.7 m ~ 0.25 L)
  template <class V>
  void visit(V& v) {
    v.field("surge_kg", surge_kg, "kg", "surge mass M_11 (default Oden, seed paper)", positive());
    v.field("sway_kg", sway_kg, "kg", "sway mass M_22 (default Oden, seed paper)", positive());
    v.field("yaw_kg_m2", yaw_kg_m2, "kg m^2", "yaw moment of inertia M_33 (default Oden, seed paper)", positive());
  }
};

// Open-water surge resistance R(u) >= 0 for u > 0; X_hyd = -R(u). Either a fit of trials, or ITTC-57 of the hull.
struct ResistanceOptions {
  std::string model = "ittc57";            // quadratic | ittc57
  double a_n_per_mps = 0.0;                // quadratic: R = a u + b u|u|
  double b_n_per_mps2 = 0.0;
  double length_wl_m = 100.0;              // ittc57: waterline length (Oden ~100 m)
  double wetted_surface_m2 = 2950.0;       // ittc57: S (Oden by Mumford, 1.7 L T + displaced volume / T)
  double form_factor_k = 0.3;              // ittc57: (1 + k) C_F
  double roughness_ca = 0.0004;            // ittc57: C_A
  double water_density_kg_m3 = 1025.0;
  double kinematic_viscosity_m2ps = 1.83e-6;  // sea water at 0 degC
  template <class V>
  void visit(V& v) {
    v.field("model", model, "-",
            "quadratic (R = a u + b u abs(u), a fit of trials) or ittc57 (R = 1/2 rho S u abs(u) ((1 + k) C_F(Re) + "
            "C_A), the simulator's curve)",
            one_of({"quadratic", "ittc57"}));
    v.field("a_n_per_mps", a_n_per_mps, "N/(m/s)", "quadratic: linear coefficient a");
    v.field("b_n_per_mps2", b_n_per_mps2, "N/(m/s)^2", "quadratic: quadratic coefficient b");
    v.field("length_wl_m", length_wl_m, "m", "ittc57: waterline length (Reynolds number)", positive());
    v.field("wetted_surface_m2", wetted_surface_m2, "m^2", "ittc57: wetted surface S", positive());
    v.field("form_factor_k", form_factor_k, "-", "ittc57: form factor k", in_range(0, 2));
    v.field("roughness_ca", roughness_ca, "-", "ittc57: roughness allowance C_A", in_range(0, 0.01));
    v.field("water_density_kg_m3", water_density_kg_m3, "kg/m^3", "ittc57: sea water density", positive());
    v.field("kinematic_viscosity_m2ps", kinematic_viscosity_m2ps, "m^2/s", "ittc57: water kinematic viscosity",
            positive());
  }
};

// Linear sway and yaw damping: Y_hyd = -Y_v v, N_hyd = -N_r r (PHYSICS.md §4.4; the coupling terms are left out).
struct DampingOptions {
  double sway_n_per_mps = 0.0;       // Y_v; 0 = sway damping not modelled (it then shows in the sway "ice" load)
  double yaw_nm_per_radps = 0.0;     // N_r
  template <class V>
  void visit(V& v) {
    v.field("sway_n_per_mps", sway_n_per_mps, "N/(m/s)", "linear sway damping Y_v (Y_hyd = -Y_v v); 0 = none",
            non_negative());
    v.field("yaw_nm_per_radps", yaw_nm_per_radps, "N m/(rad/s)", "linear yaw damping N_r (N_hyd = -N_r r); 0 = none",
            non_negative());
  }
};

// Wind on the ship above water (Fossen 2011, the same coefficients and signs as floesim-simulate's vessel wind).
struct IdentifyWindOptions {
  double air_density_kg_m3 = 1.3;
  double frontal_area_m2 = 400.0;
  double lateral_area_m2 = 900.0;
  double length_oa_m = 107.75;       // L_oa, the lever of the yaw moment
  double cx = 0.7;                   // C_X = -cx cos(gamma)
  double cy = 0.8;                   // C_Y = -cy sin(gamma)  (y to port: wind from port pushes to starboard)
  double cn = 0.1;                   // C_N = -cn sin(2 gamma)
  template <class V>
  void visit(V& v) {
    v.field("air_density_kg_m3", air_density_kg_m3, "kg/m^3", "air density", positive());
    v.field("frontal_area_m2", frontal_area_m2, "m^2", "frontal wind area A_F", non_negative());
    v.field("lateral_area_m2", lateral_area_m2, "m^2", "lateral wind area A_L", non_negative());
    v.field("length_oa_m", length_oa_m, "m", "length over all (yaw moment lever)", positive());
    v.field("cx", cx, "-", "surge coefficient amplitude: X = -cx cos(gamma) q A_F", non_negative());
    v.field("cy", cy, "-", "sway coefficient amplitude: Y = -cy sin(gamma) q A_L", non_negative());
    v.field("cn", cn, "-", "yaw coefficient amplitude: N = -cn sin(2 gamma) q A_L L_oa", non_negative());
  }
};

struct IdentifyFilterOptions {
  double acceleration_window_s = 0.1;  // centred moving average on the accelerations (the seed's)
  double output_interval_s = 0.5;      // loads averaged over consecutive intervals of this length (2 Hz)
  template <class V>
  void visit(V& v) {
    v.field("acceleration_window_s", acceleration_window_s, "s",
            "centred moving average on the accelerations (measured or differentiated); N = round(T_w / median "
            "step) samples, 1 = none",
            non_negative());
    v.field("output_interval_s", output_interval_s, "s",
            "the loads are averaged over consecutive intervals of this length from the first sample (2 Hz)",
            positive());
  }
};

// An IMU of the ship: its position relative to the centre of gravity; its accelerations are the CSV columns
// imu<k>_ax_mps2, imu<k>_ay_mps2 (k = 1.. in list order).
struct ImuOptions {
  std::vector<double> position_m;  // [x, y] from the centre of gravity, body axes (x forward, y to port)
  template <class V>
  void visit(V& v) {
    v.field("position_m", position_m, "m",
            "[x, y] of the IMU from the centre of gravity, body axes (x forward, y to port)",
            plane_point());
  }
};

struct IdentifyOptions {
  IdentifyMassOptions mass;
  ResistanceOptions resistance;
  DampingOptions damping;
  IdentifyWindOptions wind;
  IdentifyFilterOptions filters;
  std::vector<double> mean_window_s;  // [t0, t1] of the mean; empty = the whole series
  bool coriolis = false;              // add Fossen's C(nu) nu of the diagonal M to M nu_dot
  std::vector<ImuOptions> imus;       // IMUs whose accelerations the CSV gives (imu<k>_ax_mps2, imu<k>_ay_mps2)
  template <class V>
  void visit(V& v) {
    v.section("mass", mass, "diagonal mass matrix, surge/sway/yaw");
    v.section("resistance", resistance, "open-water surge resistance");
    v.section("damping", damping, "linear sway and yaw damping");
    v.section("wind", wind, "wind load on the ship (Fossen)");
    v.section("filters", filters, "acceleration filter and output rate");
    v.field("mean_window_s", mean_window_s, "s",
            "[t0, t1]: the mean ice loads over t0 <= t <= t1 (measured times); [] = the whole series",
            Check<std::vector<double>>([](const std::vector<double>& w) -> std::string {
              if (w.empty()) return "";
              if (w.size() != 2) return "must be [] or [t0, t1]";
              if (!std::isfinite(w[0]) || !std::isfinite(w[1]) || !(w[0] < w[1])) return "must have t0 < t1";
              return "";
            }));
    v.field("coriolis", coriolis, "-",
            "add the Coriolis-centripetal terms of the diagonal M (Fossen): C(nu) nu = [-M22 v r, M11 u r, "
            "(M22 - M11) u v]; false = M nu_dot alone, as in the seed's model (matters in turns: M22 r u)");
    v.list("imus", imus,
           "up to 4 IMUs (positions); the CSV then gives imu<k>_ax_mps2, imu<k>_ay_mps2 (k = 1..), the horizontal "
           "accelerations each measures (gravity removed), combined to the centre of gravity; [] = none");
    if (imus.size() > 4) v.problem("imus", "has " + std::to_string(imus.size()) + " IMUs, at most 4");
  }
};

// A surge/sway/yaw triple (N, N, N m), body axes.
struct Load3 {
  double surge = 0, sway = 0, yaw = 0;
};

// The measured series (one entry per CSV row), checked. Accelerations are empty when the file has none.
// du/dv/dr are the time derivatives of u, v, r (nu_dot); an IMU at the centre of gravity measures u_dot - r v and
// v_dot + r u instead (give the IMU columns, which are converted, or correct the columns first).
struct MeasuredSeries {
  std::vector<double> time_s, u_mps, v_mps, r_radps, thrust_n, wind_speed_mps, wind_angle_deg;
  std::vector<double> du_mps2, dv_mps2, dr_radps2;
  std::vector<std::vector<double>> imu_ax_mps2, imu_ay_mps2;  // per IMU (k = 1.. in order), per sample
  // A known ice load (columns sim_ice_surge_n, sim_ice_sway_n, sim_ice_yaw_nm, which floesim-shipdata writes for a
  // simulated ship): not used by the identification, only compared with its result. Empty when absent.
  std::vector<double> known_ice_surge_n, known_ice_sway_n, known_ice_yaw_nm;
  bool has_accelerations() const { return !du_mps2.empty(); }
  bool has_known_ice() const { return !known_ice_surge_n.empty(); }
};

// Reads and checks the measured CSV: header with the required columns (any order, extra ones ignored; all three
// acceleration columns or none), finite numbers, strictly increasing time without gaps (no step > 1.5 x the median
// step), plausible values. Errors name the file, the line and the column, and the fix.
// IMU columns imu<k>_ax_mps2, imu<k>_ay_mps2 are read for k = 1.. while present (both of each, at most 4); they
// exclude du/dv/dr.
MeasuredSeries read_measured_csv(const std::filesystem::path& file);

// The acceleration at the centre of gravity from IMUs at positions p_k (rigid body in the plane):
// a_k = a_G + r_dot z x p_k - r^2 p_k. With two or more IMUs at distinct positions (a_Gx, a_Gy, r_dot) by least
// squares; with one (or all at one point) r_dot is given (differentiated yaw rate) and a_G = mean(a_k - r_dot z x
// p_k + r^2 p_k). Returns {a_Gx, a_Gy, r_dot}: the inertial acceleration in body axes, nu_dot + [-r v, r u].
struct ImuSample {
  double x_m, y_m, ax_mps2, ay_mps2;
};
Load3 combine_imus(const std::vector<ImuSample>& imus, double r_radps, double r_dot_radps2);

// Open-water resistance R(u) (N, positive opposing u > 0, odd in u).
double open_water_resistance(double u_mps, const ResistanceOptions& o);

// Wind load on the ship from the relative wind speed and the angle it comes from (0 = head wind, > 0 from port):
// q = 1/2 rho_a V^2; X = -cx cos(g) q A_F, Y = -cy sin(g) q A_L, N = -cn sin(2g) q A_L L_oa.
Load3 wind_load(double speed_mps, double angle_deg, const IdentifyWindOptions& o);

// The identified series: per input sample (full rate) and averaged per output interval.
struct IdentifiedSeries {
  std::vector<double> time_s;
  std::vector<Load3> inertia, thrust, hydro, wind, ice;  // inertia = M nu_dot (+ C(nu) nu)
  std::vector<Load3> known;   // the known ice load of the input, when it has one (else empty)
  std::vector<double> u_mps;  // averaged velocity (output series only)
};

// The identified ice load against a known one (a simulated ship's), over the mean window: the means of the
// full-rate series, and the output-rate (filtered) series over the intervals whose centre lies in the window.
struct KnownLoadComparison {
  Load3 mean_known;               // arithmetic mean of the known full-rate load over the mean window
  double surge_error_n = 0;       // identified mean surge load - known mean surge load
  double surge_error_relative = 0;  // ... / |known mean surge load|
  double surge_rms_n = 0;         // RMS of identified - known, output rate, surge
  double surge_sd_n = 0;          // standard deviation of the known output-rate surge load (the scale of the RMS)
  size_t intervals = 0;           // output intervals compared
};
struct Identification {
  IdentifiedSeries samples;  // at the input rate
  IdentifiedSeries output;   // at the output rate: time_s = centre of each interval
  size_t acceleration_window_samples = 1;
  double median_step_s = 0;
  bool differentiated = false;  // accelerations from central differences of the velocities
  bool from_imus = false;       // accelerations from the IMU columns, combined to the centre of gravity
  double mean_t0_s = 0, mean_t1_s = 0;
  size_t mean_samples = 0;
  Load3 mean_ice;  // arithmetic mean of the full-rate ice load over [mean_t0_s, mean_t1_s]
  bool has_known = false;          // the input had a known ice load
  KnownLoadComparison known;       // ... and how the identified one compares with it
};

// Solves the model for the ice load. Errors if the series is shorter than one output interval or its step is
// longer than the output interval.
Identification identify(const MeasuredSeries& m, const IdentifyOptions& o);

// The stage: reads the CSV and the config (empty path = defaults), identifies, writes out_dir/identified.csv and
// out_dir/identified.json atomically (nothing on error), and returns the report printed on stdout.
std::string run_identify(const std::filesystem::path& measured_file, const std::filesystem::path& config_file,
                         const std::filesystem::path& out_dir);

}  // namespace floesim::sim
