// The engine's physics settings: ice, water, vessel, wind, contact solver, contact laws, domain, fracture, sleep,
// health and level ice, one strict struct per section, every field with default, unit and doc. The engine reads
// these and nothing of any stage; the simulate stage's options (sim/simulate/options.h) are these settings plus the
// run's own (duration, output, checkpoints, how the hull file is loaded).
// Angles are measured counter-clockwise from the world x axis (east), in degrees; "direction" of a current or of
// the wind is the direction it flows TO (oceanographic convention for both, so that a current of direction 0 and a
// wind of direction 0 push a floe the same way).
#pragma once
#include <cctype>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "pipeline/geometry2d.h"
#include "pipeline/options.h"
#include "pipeline/station_keeping.h"
#include "sim/engine/ridge.h"

namespace floesim::sim {

struct IceOptions {
  double density_kg_m3 = 900.0;        // rho_i; the thickness comes from the floes file
  double mu_ice_ice = 0.15;            // friction coefficient between floes
  double mu_ice_structure = 0.15;      // friction coefficient between floe and hull
  double crushing_strength_pa = 2e6;   // sigma_c: crushing pressure of compliant contacts (p_0 of the p-A law)
  double air_drag_ca = 0.0012;         // air-ice skin drag coefficient on the exposed top face (wind on floes)
  double max_overlap_fraction = 0.02;  // floes overlapping more than this fraction of the smaller floe are an error
  template <class V>
  void visit(V& v) {
    v.field("density_kg_m3", density_kg_m3, "kg/m^3", "ice density", positive());
    v.field("mu_ice_ice", mu_ice_ice, "-", "ice-ice friction coefficient", in_range(0, 2));
    v.field("mu_ice_structure", mu_ice_structure, "-", "ice-hull friction coefficient", in_range(0, 2));
    v.field("crushing_strength_pa", crushing_strength_pa, "Pa",
            "ice crushing strength sigma_c: the pressure that caps the normal force of compliant contacts",
            positive());
    v.field("air_drag_ca", air_drag_ca, "-", "air-ice skin drag coefficient (wind on the floes' top faces)",
            non_negative());
    v.field("max_overlap_fraction", max_overlap_fraction, "-",
            "two input floes overlapping by more than this fraction of the smaller one's area are an error; smaller "
            "overlaps (digitisation noise) are pushed apart by the contact solver",
            in_range(0, 1));
  }
};

struct WaterOptions {
  bool enabled = true;                   // false: no buoyancy, drag, damping or resistance (gravity still acts)
  double density_kg_m3 = 1025.0;         // rho_w
  double gravity_mps2 = 9.81;            // g, downwards along -z
  double skin_friction_cf = 0.005;       // C_f on submerged floe faces (tangential drag)
  double form_drag_cd = 0.5;             // C_d on submerged floe faces advancing into the water
  double current_speed_mps = 0.0;        // uniform current speed
  double current_direction_deg = 0.0;    // direction the current flows to
  // Floe heave damping: "radiation" (wave radiation, B33 at the heave natural frequency through a high-pass filter,
  // so it vanishes for steady motion; sim/engine/forces.h) or "linear" (the old dashpot, floe_heave_damping_ratio).
  std::string floe_heave_damping = "radiation";
  double floe_heave_damping_ratio = 0.2;  // "linear" only: heave damping, fraction of critical
  double floe_roll_pitch_damping_ratio = 0.2;
  double vessel_heave_damping_ratio = 0.2;
  double vessel_roll_damping_ratio = 0.08;
  double vessel_pitch_damping_ratio = 0.2;
  double kinematic_viscosity_m2ps = 1.83e-6;  // sea water at 0 degC (ITTC-57 Reynolds number)
  double floe_added_mass_scale = 1.0;         // x the floating thin-disc heave/roll/pitch added mass (§3.3)
  bool floes_start_with_current = false;      // floes start drifting with the current (else at rest)
  template <class V>
  void visit(V& v) {
    v.field("enabled", enabled, "-", "buoyancy, drag, damping and open-water resistance on (false: vacuum)");
    v.field("density_kg_m3", density_kg_m3, "kg/m^3", "sea water density", positive());
    v.field("gravity_mps2", gravity_mps2, "m/s^2", "gravitational acceleration (0 allowed for tests)",
            non_negative());
    v.field("skin_friction_cf", skin_friction_cf, "-", "skin friction coefficient C_f on submerged floe faces",
            non_negative());
    v.field("form_drag_cd", form_drag_cd, "-", "form drag coefficient C_d on submerged floe faces", non_negative());
    v.field("current_speed_mps", current_speed_mps, "m/s", "uniform current speed", non_negative());
    v.field("current_direction_deg", current_direction_deg, "deg", "direction the current flows to (CCW from +x)",
            in_range(-360, 360));
    v.field("floe_heave_damping", floe_heave_damping, "-",
            "radiation (wave radiation damping of the floating disc of the floe's area at its heave natural "
            "frequency, Haskind relation with the Froude-Krylov force, acting on the high-passed heave velocity: "
            "zero for steady motion) | linear (a dashpot of floe_heave_damping_ratio of critical)",
            one_of({"radiation", "linear"}));
    v.field("floe_heave_damping_ratio", floe_heave_damping_ratio, "-",
            "floe heave damping, fraction of critical (floe_heave_damping linear only)", in_range(0, 2));
    v.field("floe_roll_pitch_damping_ratio", floe_roll_pitch_damping_ratio, "-",
            "floe roll and pitch damping, fraction of critical", in_range(0, 2));
    v.field("vessel_heave_damping_ratio", vessel_heave_damping_ratio, "-", "vessel heave damping, fraction of critical",
            in_range(0, 2));
    v.field("vessel_roll_damping_ratio", vessel_roll_damping_ratio, "-", "vessel roll damping, fraction of critical",
            in_range(0, 2));
    v.field("vessel_pitch_damping_ratio", vessel_pitch_damping_ratio, "-", "vessel pitch damping, fraction of critical",
            in_range(0, 2));
    v.field("kinematic_viscosity_m2ps", kinematic_viscosity_m2ps, "m^2/s", "water kinematic viscosity (ITTC-57)",
            positive());
    v.field("floe_added_mass_scale", floe_added_mass_scale, "-",
            "factor on the floes' heave added mass (4/3) rho_w a^3 and roll/pitch added inertia of the floating thin "
            "disc of the same area (a = sqrt(A/pi)), in the mass matrix (implicit); 0 = none",
            in_range(0, 10));
    v.field("floes_start_with_current", floes_start_with_current, "-",
            "floes start drifting with the current (an established drift) instead of at rest");
  }
};

// How the vessel is driven.
struct PropulsionOptions {
  std::string mode = "speed";        // constant_thrust | thrust_series | speed | bollard_pull
  double thrust_n = 0.0;             // constant_thrust: thrust along the body x axis
  std::string thrust_file;           // thrust_series: CSV "time_s,thrust_N" (relative to the config file)
  double speed_mps = 2.0;            // speed: prescribed forward speed through the water
  double kp_n_per_mps = 4e6;         // speed: proportional gain (m / kp ~ 3 s for Oden)
  double ki_n_per_m = 2e5;           // speed: integral gain (closed loop overdamped, zeta ~ 1.2 for Oden)
  double min_thrust_n = 0.0;         // speed: thrust limits (anti-windup clamps the integral)
  double max_thrust_n = 4e6;
  template <class V>
  void visit(V& v) {
    v.field("mode", mode, "-",
            "constant_thrust | thrust_series | speed (PI controller on thrust) | bollard_pull (thrust_n made by the "
            "propellers, held by a line to a fixed bollard: no net force on the vessel)",
            one_of({"constant_thrust", "thrust_series", "speed", "bollard_pull"}));
    v.field("thrust_n", thrust_n, "N", "constant_thrust and bollard_pull: thrust along the vessel's x axis");
    v.field("thrust_file", thrust_file, "-",
            "thrust_series: CSV with header time_s,thrust_N (path relative to the config file); linear "
            "interpolation, held constant outside");
    v.field("speed_mps", speed_mps, "m/s", "speed: prescribed forward speed through the water", non_negative());
    v.field("kp_n_per_mps", kp_n_per_mps, "N/(m/s)", "speed: proportional gain of the thrust controller",
            non_negative());
    v.field("ki_n_per_m", ki_n_per_m, "N/m", "speed: integral gain of the thrust controller", non_negative());
    v.field("min_thrust_n", min_thrust_n, "N", "speed: smallest thrust (negative = astern allowed)");
    v.field("max_thrust_n", max_thrust_n, "N", "speed: largest thrust", positive());
    if (min_thrust_n > max_thrust_n) v.problem("min_thrust_n", "must be <= max_thrust_n");
    if (mode == "thrust_series" && thrust_file.empty()) v.problem("thrust_file", "must be set for mode thrust_series");
  }
};

// One propeller of the vessel: its share of the propulsion thrust makes a jet (PHYSICS.md §3.5) that the floes' drag
// sees. Positions in the hull frame (x forward, y to port, z up, waterline z = 0, the hull's own origin): the hull
// file's frame after the case's hull placement (up_direction, bow_direction, waterline_z_m, origin_m,
// scale).
struct PropellerOptions {
  std::vector<double> position_m;         // [x, y, z] of the propeller disc's centre, hull frame
  std::vector<double> axis = {1, 0, 0};   // direction of the thrust it gives (body axes); the jet flows opposite
  double diameter_m = 4.0;                // D_p
  double thrust_share = 0.5;              // fraction of the propulsion thrust this propeller makes
  template <class V>
  void visit(V& v) {
    v.field("position_m", position_m, "m",
            "[x, y, z] of the propeller disc's centre in the hull frame (after the hull placement; waterline z = 0); "
            "must be under water",
            Check<std::vector<double>>([](const std::vector<double>& p) -> std::string {
              if (p.size() != 3) return "must be [x, y, z] (3 numbers)";
              for (double x : p)
                if (!std::isfinite(x)) return "must be finite numbers";
              if (!(p[2] < 0)) return "z must be below the waterline (z < 0)";
              return "";
            }));
    v.field("axis", axis, "-",
            "direction of the thrust the propeller gives, body axes ([1, 0, 0] ahead); the jet flows the other way",
            Check<std::vector<double>>([](const std::vector<double>& a) -> std::string {
              if (a.size() != 3) return "must be [x, y, z] (3 numbers)";
              const double n2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
              if (!std::isfinite(n2) || n2 < 1e-12) return "must be a non-zero vector";
              return "";
            }));
    v.field("diameter_m", diameter_m, "m", "propeller diameter D_p", positive());
    v.field("thrust_share", thrust_share, "-",
            "fraction of the propulsion thrust this propeller makes (the shares of all propellers add up to <= 1)",
            in_range(0, 1));
  }
};

// Heading hold: a PD yaw moment (rudder/azimuth thrusters lumped) that keeps the initial course.
struct AutopilotOptions {
  bool enabled = true;
  double natural_period_s = 40.0;  // closed-loop yaw natural period
  double damping_ratio = 1.0;      // closed-loop yaw damping ratio
  double max_moment_nm = 5e8;      // limit of the steering moment
  template <class V>
  void visit(V& v) {
    v.field("enabled", enabled, "-", "hold the initial heading with a PD yaw moment");
    v.field("natural_period_s", natural_period_s, "s", "closed-loop yaw natural period", positive());
    v.field("damping_ratio", damping_ratio, "-", "closed-loop yaw damping ratio", positive());
    v.field("max_moment_nm", max_moment_nm, "N m", "largest steering moment", positive());
  }
};

// Dynamic positioning (§8.4.2): a PID controller over the earth-frame position and heading about the station (the
// start), fed by a low-pass observer, its command in body axes clipped at the thrusters' limits. Gains per degree of
// freedom from the closed loop asked for: K_p = M w_n^2, K_d = 2 zeta M w_n, K_i = K_p w_n / 10, M the body's mass (or
// yaw inertia) with its added mass.
struct DpOptions {
  double natural_period_s = 100.0;         // T_n of surge and sway
  double yaw_natural_period_s = 100.0;     // T_n of yaw
  double damping_ratio = 0.7;
  double max_force_x_n = 2e6;              // thrust limits, body axes
  double max_force_y_n = 1e6;
  double max_moment_z_nm = 5e7;
  double observer_time_constant_s = 10.0;  // 0: the measured pose as it is
  template <class V>
  void visit(V& v) {
    v.field("natural_period_s", natural_period_s, "s", "closed-loop natural period of surge and sway (60-150 s)",
            positive());
    v.field("yaw_natural_period_s", yaw_natural_period_s, "s", "closed-loop natural period of yaw", positive());
    v.field("damping_ratio", damping_ratio, "-", "closed-loop damping ratio", positive());
    v.field("max_force_x_n", max_force_x_n, "N", "largest surge thrust (body x)", positive());
    v.field("max_force_y_n", max_force_y_n, "N", "largest sway thrust (body y)", positive());
    v.field("max_moment_z_nm", max_moment_z_nm, "N m", "largest yaw moment of the thrusters", positive());
    v.field("observer_time_constant_s", observer_time_constant_s, "s",
            "time constant of the low-pass observer of the measured pose (0: none; floe impacts at 0.05-0.5 Hz lie "
            "far above the DP bandwidth)",
            non_negative());
  }
};

// How the hull body is held (issue #34). A ship is driven by its propulsion; a structure is "fixed" (it does not move
// in the earth frame: in a run with drift, in the ice's frame it moves at minus the drift; kinematic, infinite
// mass), "moored" (it floats, held by a spread of catenary mooring lines, §8.4.1), "dp" (it floats, held by a
// dynamic-positioning controller, §8.4.2) or "compliant" (bottom-founded, its first mode a horizontal spring and
// damper, §8.3). The station is where the body starts.
// A compliant structure's first mode (PHYSICS.md 8.3): a rigid body of the modal mass on a horizontal spring and damper
// about its station, k = m (2 pi f_n)^2, c = 2 zeta m 2 pi f_n; it neither floats nor turns nor heaves.
struct CompliantOptions {
  double modal_mass_kg = 1e6;
  double natural_frequency_hz = 0.33;
  double damping_ratio = 0.02;
  template <class V>
  void visit(V& v) {
    v.field("modal_mass_kg", modal_mass_kg, "kg", "the first mode's modal mass", positive());
    v.field("natural_frequency_hz", natural_frequency_hz, "Hz", "the first mode's natural frequency f_n",
            in_range(0.01, 10));
    v.field("damping_ratio", damping_ratio, "-", "the first mode's damping, fraction of critical", in_range(0, 1));
  }
};

struct StationKeepingOptions {
  std::string mode = "propulsion";  // propulsion | fixed | moored | dp | compliant
  std::vector<MooringLineOptions> lines;       // moored
  DpOptions dp;
  CompliantOptions compliant;
  std::vector<double> applied_force_n = {0, 0};  // moored, dp: a steady pull, earth frame
  double applied_force_ramp_s = 0;               // the pull grows linearly over this time (0: at once)
  template <class V>
  void visit(V& v) {
    v.field("mode", mode, "-",
            "propulsion (a ship, driven by vessel.propulsion and steered by vessel.autopilot), fixed (a structure "
            "that does not move in the earth frame: a bridge pier, a lighthouse, a platform on the seabed), moored "
            "(a floating structure held by the mooring lines of station_keeping.lines) or dp (held by the "
            "dynamic-positioning controller of station_keeping.dp) or compliant (a bottom-founded structure whose "
            "first mode sways: on the horizontal spring and damper of station_keeping.compliant); for all but "
            "propulsion the vessel's propulsion, autopilot and initial speed do not apply, and the station is where "
            "the body starts",
            one_of({"propulsion", "fixed", "moored", "dp", "compliant"}));
    v.list("lines", lines,
           "moored: the mooring lines, each a catenary with a grounded part (PHYSICS.md 8.4.1) from its fairlead on "
           "the body to its anchor on the seabed, placed by its azimuth and pretension at the station");
    v.section("dp", dp, "dp: the dynamic-positioning controller");
    v.section("compliant", compliant, "compliant: the structure's first mode, a horizontal spring and damper");
    v.field("applied_force_n", applied_force_n, "N",
            "moored, dp: a steady external pull [x, y] on the body's reference point, earth frame (a tug, or a "
            "pull test of the mooring)",
            plane_point());
    v.field("applied_force_ramp_s", applied_force_ramp_s, "s",
            "the applied pull grows linearly from 0 over this time (a tug taking the strain; long against the "
            "body's natural period, the pull is quasi-static); 0 = at once",
            non_negative());
    if (mode == "moored" && lines.empty()) v.problem("lines", "a moored body needs at least one mooring line");
    if (mode != "moored" && !lines.empty())
      v.problem("lines", "mooring lines hold only a moored body (mode \"moored\"), not mode \"" + mode + "\"");
    if ((mode == "propulsion" || mode == "fixed") && (applied_force_n[0] != 0 || applied_force_n[1] != 0))
      v.problem("applied_force_n", "acts only on a moored or dp body");
  }
  bool fixed() const { return mode == "fixed"; }
  bool compliant_held() const { return mode == "compliant"; }
  bool moored() const { return mode == "moored"; }
  bool dp_held() const { return mode == "dp"; }
  bool held() const { return mode != "propulsion"; }  // a structure: fixed, moored, dp or compliant
};

struct VesselOptions {
  double x_m = 0.0;               // initial centre of mass, world x
  double y_m = 0.0;               // initial centre of mass, world y
  double heading_deg = 0.0;       // course: direction of the bow (CCW from +x)
  double initial_speed_mps = 2.0;  // initial forward speed
  double mass_kg = 0.0;           // 0: rho_w times the hull volume below z = 0
  double vcg_m = -0.5;            // z of the centre of mass in the hull frame (waterline z = 0)
  double kxx_m = 0.0;             // radii of gyration; 0: 0.38 B, 0.25 L, 0.25 L
  double kyy_m = 0.0;
  double kzz_m = 0.0;
  double form_factor_k = 0.3;     // ITTC-57 form factor
  double roughness_ca = 0.0004;   // ITTC roughness allowance C_A
  double sway_drag_cd = 0.8;      // cross-flow drag coefficient (sway and yaw damping), on L_wl x draught
  std::vector<double> inertia_kg_m2;   // given outright: [Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]
  double surge_added_mass_ratio = 0.05;  // A11 / m (PHYSICS.md §3.3: 0.05-0.1)
  double sway_added_mass_ratio = 0.5;    // A22 / m (0.5-1.0)
  double yaw_added_inertia_ratio = 0.5;  // A66 / I_zz (0.5-1.0)
  double heave_pitch_added_mass_scale = 1.0;  // x strip theory (pi/8) rho_w B(x)^2 per metre (heave and pitch)
  PropulsionOptions propulsion;
  AutopilotOptions autopilot;
  std::vector<PropellerOptions> propellers;  // none: no propeller wash on the floes
  StationKeepingOptions station_keeping;
  template <class V>
  void visit(V& v) {
    visit_body(v);
    v.field("initial_speed_mps", initial_speed_mps, "m/s", "initial forward speed", non_negative());
    v.section("propulsion", propulsion, "how the vessel is driven");
    v.section("autopilot", autopilot, "heading hold");
    v.list("propellers", propellers,
           "the vessel's propellers, whose jets (PHYSICS.md 3.5) wash the floes; [] = no propeller wash");
    v.section("station_keeping", station_keeping,
              "how the hull body is held: a ship's propulsion, or a structure fixed, moored or on DP");
    if (station_keeping.held() && !propellers.empty())
      v.problem("propellers", "a structure (station_keeping.mode " + station_keeping.mode + ", not propulsion) has no "
                "propellers whose wash is modelled: remove them");
    double shares = 0;
    for (const PropellerOptions& p : propellers) shares += p.thrust_share;
    if (shares > 1 + 1e-9)
      v.problem("propellers", "thrust_share adds up to " + Json(shares).dump() + " (must be <= 1: the shares split "
                "the propulsion thrust)");
  }
  // What any hull body has, a ship's or a structure's (simulate.structures): its placement, mass, inertia, added
  // mass and the water's resistance to it.
  template <class V>
  void visit_body(V& v) {
    v.field("x_m", x_m, "m", "initial centre of mass, world x",
            in_range(-kMaxWorldCoordinateM, kMaxWorldCoordinateM));
    v.field("y_m", y_m, "m", "initial centre of mass, world y",
            in_range(-kMaxWorldCoordinateM, kMaxWorldCoordinateM));
    v.field("heading_deg", heading_deg, "deg", "course: direction of the bow, CCW from +x", in_range(-360, 360));
    v.field("mass_kg", mass_kg, "kg", "vessel mass; 0 = rho_w x hull volume below the waterline", non_negative());
    v.field("vcg_m", vcg_m, "m", "height of the centre of mass in the hull frame (waterline at z = 0)");
    v.field("kxx_m", kxx_m, "m", "roll radius of gyration; 0 = 0.38 x waterline beam", non_negative());
    v.field("kyy_m", kyy_m, "m", "pitch radius of gyration; 0 = 0.25 x length over all", non_negative());
    v.field("kzz_m", kzz_m, "m", "yaw radius of gyration; 0 = 0.25 x length over all", non_negative());
    v.field("form_factor_k", form_factor_k, "-", "ITTC-57 form factor (1 + k) C_F", in_range(0, 2));
    v.field("roughness_ca", roughness_ca, "-", "ITTC roughness allowance C_A", in_range(0, 0.01));
    v.field("sway_drag_cd", sway_drag_cd, "-", "cross-flow drag coefficient for sway and yaw damping",
            non_negative());
    v.field("inertia_kg_m2", inertia_kg_m2, "kg m^2",
            "inertia tensor about the centre of mass, body axes, given outright: [] (from the radii of gyration), "
            "[Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] (products as tensor entries); overrides kxx_m..kzz_m",
            Check<std::vector<double>>([](const std::vector<double>& I) -> std::string {
              if (I.empty()) return "";
              if (I.size() != 3 && I.size() != 6) return "must have 0, 3 or 6 values";
              for (double x : I)
                if (!std::isfinite(x)) return "must be finite numbers";
              const double a = I[0], b = I[1], c = I[2];
              if (!(a > 0 && b > 0 && c > 0)) return "Ixx, Iyy, Izz must be > 0";
              if (a + b < c || b + c < a || a + c < b) return "violates the triangle inequality of a rigid body";
              if (I.size() == 6) {  // positive definite: leading minors
                const double xy = I[3], xz = I[4], yz = I[5];
                const double m2 = a * b - xy * xy;
                const double m3 = a * (b * c - yz * yz) - xy * (xy * c - yz * xz) + xz * (xy * yz - b * xz);
                if (!(m2 > 0 && m3 > 0)) return "is not positive definite";
              }
              return "";
            }));
    v.field("surge_added_mass_ratio", surge_added_mass_ratio, "-",
            "surge added mass A11 as a fraction of the vessel mass, in the mass matrix", in_range(0, 2));
    v.field("sway_added_mass_ratio", sway_added_mass_ratio, "-",
            "sway added mass A22 as a fraction of the vessel mass, in the mass matrix", in_range(0, 5));
    v.field("yaw_added_inertia_ratio", yaw_added_inertia_ratio, "-",
            "yaw added moment of inertia A66 as a fraction of the vessel's I_zz, in the mass matrix", in_range(0, 5));
    v.field("heave_pitch_added_mass_scale", heave_pitch_added_mass_scale, "-",
            "factor on the heave added mass A33 = (pi/8) rho_w integral B(x)^2 dx and pitch added inertia "
            "A55 = (pi/8) rho_w integral B(x)^2 x^2 dx (strip theory, semicircular sections of the waterline beam "
            "B(x)); 0 = none",
            in_range(0, 5));
  }
};

// A structure beside the case's hull body (simulate.structures, issue #34): a hull body of its own, fixed, moored or
// on DP, from a mesh already in its hull frame (bow +x, z up, waterline z = 0: floesim-hull's output). Its loads,
// pose and station keeping are recorded under its name (pipeline/results_io.h, /structures). The wind on its part
// above water is not modelled (the wind's areas are the case's hull body's).
struct StructureOptions {
  std::string name;
  std::string hull_file;  // relative to the config file
  VesselOptions body;     // its placement, mass and hydrodynamics (visit_body) and station_keeping
  template <class V>
  void visit(V& v) {
    v.field("name", name, "-",
            "the structure's name: its results group (/structures/NAME) and its part of the summary and report; "
            "letters, digits, '-' and '_'",
            Check<std::string>([](const std::string& n) -> std::string {
              if (n.empty() || n.size() > 64) return "must have 1 to 64 characters";
              if (n == "vessel") return "\"vessel\" names the vessel's own results group: choose another name";
              for (char c : n)
                if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_')
                  return "may hold only letters, digits, '-' and '_'";
              return "";
            }));
    v.field("hull_file", hull_file, "-",
            "its mesh (OBJ, or any mesh assimp reads) in its hull frame: bow +x, z up, waterline z = 0, taken as the "
            "file has it (floesim-hull's output); relative to the config file");
    body.visit_body(v);
    v.section("station_keeping", body.station_keeping, "how it is held: fixed, moored, dp or compliant");
    if (hull_file.empty()) v.problem("hull_file", "must name the structure's mesh");
    if (!body.station_keeping.held())
      v.problem("station_keeping", "a structure is fixed, moored, dp or compliant (mode \"" +
                                       body.station_keeping.mode + "\" drives a ship: that is the case's vessel)");
  }
};

// Wind on the vessel (Fossen's coefficients) and on the floes' top faces (air skin drag).
struct WindOptions {
  double speed_mps = 0.0;
  double direction_deg = 0.0;        // direction the wind blows to
  double air_density_kg_m3 = 1.3;
  double frontal_area_m2 = 400.0;    // vessel projected area above water, seen from ahead
  double lateral_area_m2 = 900.0;    // vessel projected area above water, seen from the side
  double cx = 0.7;                   // C_X = -cx cos(gamma), gamma = relative wind angle, 0 = head wind
  double cy = 0.8;                   // C_Y = cy sin(gamma)
  double cn = 0.1;                   // C_N = cn sin(2 gamma)
  template <class V>
  void visit(V& v) {
    v.field("speed_mps", speed_mps, "m/s", "wind speed (0 = no wind)", non_negative());
    v.field("direction_deg", direction_deg, "deg", "direction the wind blows to (CCW from +x)", in_range(-360, 360));
    v.field("air_density_kg_m3", air_density_kg_m3, "kg/m^3", "air density", positive());
    v.field("frontal_area_m2", frontal_area_m2, "m^2", "vessel frontal wind area", non_negative());
    v.field("lateral_area_m2", lateral_area_m2, "m^2", "vessel lateral wind area", non_negative());
    v.field("cx", cx, "-", "Fossen surge wind coefficient amplitude", non_negative());
    v.field("cy", cy, "-", "Fossen sway wind coefficient amplitude", non_negative());
    v.field("cn", cn, "-", "Fossen yaw wind coefficient amplitude", non_negative());
  }
};

struct SolverOptions {
  int iterations = 60;             // largest number of projected Gauss-Seidel sweeps per step
  int relax_iterations = 15;       // sweeps without the push-out bias after integration (Box2D v3 "relax")
  double tolerance_mps = 1e-5;     // stop when no contact velocity changed by more than this in a sweep
  double erp = 0.2;                // error reduction: fraction of the overlap (beyond slop) closed per step
  double slop_m = 0.005;           // overlap tolerated without push-out (prevents jitter)
  double max_push_mps = 0.5;       // cap of the push-out velocity of rigid contacts
  double speculative_m = 0.02;     // manifold points up to this far apart are kept (speculative contacts)
  bool warm_start = true;          // start from the previous step's impulses (matched per contact)
  // pgs_subspace: Gauss-Seidel with a subspace minimisation (an exact sparse solve of the settled rows) every
  // subspace_every sweeps while unconverged, for heavy-on-light chains; pgs: sweeps alone (for comparison).
  std::string method = "pgs_subspace";
  int subspace_every = 8;
  int subspace_max_rows = 128;     // ... and only for at most this many settled rows (see visit)
  double subspace_above_mps = 0.0;  // ... and only while a sweep still changes a velocity by more than this
  // Diagnostic (costly): a second solve of every step on copies, from the same state, and the difference in the
  // vessel's surge ice load recorded (solver_surge_load_error). "converged_relax": the relax pass continued up to
  // reference_sweeps; "double_cap": solve and relax with twice their sweep caps; "reverse_order": the rows swept
  // in the other order; "every_contact": every contact in every sweep (skip_settled 0). Paired on one trajectory,
  // it measures what the setting changes in the load without the chaos of a transit, which makes two runs differ
  // by far more (5-15 % between starts).
  std::string reference = "off";
  int reference_sweeps = 2000;     // sweeps of the "converged_relax" reference
  // 0: the reference is the step's solve again (paired on one step). > 0 (double_cap, reverse_order,
  // every_contact): the reference is a branch, a copy of the world that runs on by itself with the reference's
  // settings for this long and is then replaced by a fresh copy; each step records the difference of the two
  // worlds' loads. The paired solve sees what a setting changes in one step; the branch also sees what it carries
  // into the next steps (other velocities, positions, crushed depths), until the transit's chaos parts the two.
  double reference_horizon_s = 0;
  bool reverse_order = false;      // sweep the rows last to first (to check that results do not hang on the order)
  // A sweep leaves out a contact that has settled: its last update changed its row velocities by less than this
  // fraction of tolerance_mps, and its relative velocity has moved by less than that since (see solve_island).
  double skip_settled = 0.5;
  template <class V>
  void visit(V& v) {
    v.field("method", method, "-",
            "pgs_subspace (Gauss-Seidel + exact sparse solve of the settled rows, converges on heavy-on-light "
            "chains) or pgs (sweeps only)",
            one_of({"pgs_subspace", "pgs"}));
    v.field("subspace_every", subspace_every, "-",
            "sweeps between two subspace minimisations while the tolerance is unmet (pgs_subspace)",
            int_in_range(1, 10000));
    v.field("subspace_max_rows", subspace_max_rows, "-",
            "no subspace minimisation when more rows than this are settled: larger sets are the bow's rubble, "
            "whose steps are nearly always undone (floesim-bench with fracture, 100 s: 0 of 139 kept above 128 "
            "rows, 7 of 2,108 from 64 to 128, 6 % from 32 to 64, 30-55 % below 16) while their factorisations "
            "cost a third of a step at 300; the jam of ten floes (sim_solver_test) needs more than 64",
            int_in_range(1, 1000000));
    v.field("subspace_above_mps", subspace_above_mps, "m/s",
            "subspace minimisations only while the last sweep changed a contact velocity by more than this (the "
            "signature of a heavy-on-light chain)",
            non_negative());
    v.field("reference", reference, "-",
            "diagnostic (costly): each step is solved a second time on copies from the same state and the "
            "vessel's surge ice load minus the reference's is recorded (solver_surge_load_error): off, "
            "converged_relax (the relax pass continued to reference_sweeps), double_cap (solve and relax with "
            "twice their sweep caps), reverse_order (the rows swept in the other order) or every_contact (no "
            "settled contact left out of a sweep: skip_settled 0)",
            one_of({"off", "converged_relax", "double_cap", "reverse_order", "every_contact"}));
    v.field("reference_sweeps", reference_sweeps, "-",
            "sweeps of the converged_relax reference (tolerance 1e-3 of tolerance_mps)", int_in_range(1, 1000000));
    v.field("reference_horizon_s", reference_horizon_s, "s",
            "0: the reference is each step solved again; > 0 (double_cap, reverse_order, every_contact): a copy of "
            "the world runs on with the reference's settings for this long (a whole number of time steps), then a "
            "fresh copy is taken, and each step records the two worlds' difference (what the setting carries from "
            "step to step)",
            non_negative());
    v.field("reverse_order", reverse_order, "-", "sweep the contact rows in reverse order (an order-dependence check)");
    v.field("skip_settled", skip_settled, "-",
            "a sweep leaves out a contact whose last update and whose relative velocity since then both changed by "
            "less than this fraction of tolerance_mps (its update would change nothing that counts); 0: every "
            "contact in every sweep",
            in_range(0, 1));
    v.field("iterations", iterations, "-", "largest number of Gauss-Seidel sweeps per step", int_in_range(1, 10000));
    v.field("relax_iterations", relax_iterations, "-",
            "sweeps without push-out bias after the position update, so that push-out leaves no velocity",
            int_in_range(0, 10000));
    v.field("tolerance_mps", tolerance_mps, "m/s", "stop when a sweep changes no contact velocity by more than this",
            non_negative());
    v.field("erp", erp, "-", "error reduction parameter: fraction of the overlap closed per step", in_range(0, 1));
    v.field("slop_m", slop_m, "m", "overlap tolerated without push-out", non_negative());
    v.field("max_push_mps", max_push_mps, "m/s", "largest push-out velocity of the ERP bias", positive());
    v.field("speculative_m", speculative_m, "m",
            "manifold points separated by up to this are kept as speculative contacts", non_negative());
    v.field("warm_start", warm_start, "-", "start each step from the previous impulses");
  }
};

// Contact laws per pair of body classes (PHYSICS.md §1.7-1.8). Rigid: non-penetration with ERP push-out and a
// manifold of up to 4 points. Compliant: crushing (§1.8(c)), one contact (two rows) per body pair, direction and
// place over the overlaps' contact surfaces, normal force capped by p_c(A) A of the overlap's nominal contact area A, hardening with
// K_t = dF/d(delta) inside the implicit step, no push-out and no spring-back. Both compliant by default, as in SAMS
// (PHYSICS.md §1.7: compliant ice-structure and ice-ice contacts, "large rubble accumulation and ice-ice
// contact-induced failure"): with fracture, broken pieces are squeezed between floes, and rigid ice-ice rows there
// have no ceiling (a 15 m^2 piece jammed between two floes drove the PGS solve to 3e10 N and a blow-up on one of five
// starts of the default case); a compliant row is capped at p_c A and never pushes out.
struct ContactOptions {
  std::string ice_structure = "compliant";  // contacts between a floe and the vessel
  std::string ice_ice = "compliant";        // contacts between two floes
  double pressure_area_exponent = 0.0;      // e_x of p_c(A) = sigma_c (A / 1 m^2)^e_x; 0: constant pressure sigma_c
  double area_gradient_step_m = 0.005;      // smallest step of the secant dA/d(delta) = (A(delta + step) - A) / step
  double crushing_damping_ratio = 0.0;      // zeta of c_n = 2 zeta sqrt(m_eff K_t) added to the crushing force
  // The crushing pressure against a structure with the relative speed (PHYSICS.md 8.3): "none" (p_c(A) at any
  // speed) or "maattanen" (p_c(A) times Maattanen's strength over its value at rest, sigma(sigma_dot) / 2 MPa, with
  // sigma_dot = v_n 8 sigma_ref / (pi w_d), w_d = min(w, 2 h): up to 1.5 on the rising branch, down to 0.5 above it,
  // a negative damping between v_n = 0.104 and 0.474 m/s for w_d = 2 m and sigma_ref = 2.2 MPa).
  std::string crushing_speed_law = "none";
  double maattanen_reference_pa = 2.2e6;    // sigma_ref of the stress rate
  template <class V>
  void visit(V& v) {
    v.field("ice_structure", ice_structure, "-",
            "contact law between floes and the vessel: compliant (crushing, force <= p_c(A) x contact area) or rigid "
            "(non-penetration)",
            one_of({"compliant", "rigid"}));
    v.field("ice_ice", ice_ice, "-", "contact law between floes: rigid or compliant", one_of({"compliant", "rigid"}));
    v.field("pressure_area_exponent", pressure_area_exponent, "-",
            "pressure-area exponent e_x of the crushing pressure p_c = ice.crushing_strength_pa x (A / 1 m^2)^e_x "
            "(0: constant pressure)",
            in_range(-0.9, 0));
    v.field("area_gradient_step_m", area_gradient_step_m, "m",
            "smallest penetration step of the secant dA/d(delta) of the contact area (force-penetration gradient); "
            "the step is the penetration the approach speed adds in one time step when that is larger",
            in_range(1e-5, 0.1));
    v.field("crushing_damping_ratio", crushing_damping_ratio, "-",
            "damping c_n = 2 zeta sqrt(m_eff K_t) of crushing contacts, fraction of critical (0: pure crushing)",
            in_range(0, 2));
    v.field("crushing_speed_law", crushing_speed_law, "-",
            "the ice's crushing pressure against a structure with the speed the ice closes on it: none, or "
            "maattanen (PHYSICS.md 8.3: p_c(A) x sigma(sigma_dot) / sigma(0), the stress rate sigma_dot = v_n x 8 "
            "sigma_ref / (pi w_d), w_d = min(contact width, 2 h); a falling branch, the negative damping of "
            "frequency lock-in)",
            one_of({"none", "maattanen"}));
    v.field("maattanen_reference_pa", maattanen_reference_pa, "Pa", "sigma_ref of Maattanen's stress rate",
            positive());
  }
};

// The simulation domain: optional fixed walls along the sides of a rectangle (a coast, fast ice or a basin), so
// that floes driven by a current or wind pack against them instead of drifting away. Walls are static bodies with
// rigid contacts (ice.mu_ice_ice); they are not written to the results.
// A rectangle [x_min, y_min, x_max, y_max] in world metres, checked.
inline Check<std::vector<double>> rectangle_m(bool may_be_empty) {
  return [may_be_empty](const std::vector<double>& e) -> std::string {
    if (e.empty()) return may_be_empty ? "" : "must be [x_min, y_min, x_max, y_max]";
    if (e.size() != 4) return "must be [x_min, y_min, x_max, y_max]";
    for (double x : e)
      if (!std::isfinite(x) || std::abs(x) > kMaxWorldCoordinateM) return "must hold finite numbers within +-1e7 m";
    if (!(e[2] > e[0] && e[3] > e[1])) return "needs x_max > x_min and y_max > y_min";
    return "";
  };
}

struct DomainOptions {
  std::vector<std::string> walls;   // any of "west", "east", "south", "north"
  std::vector<double> extent_m;     // [x_min, y_min, x_max, y_max]; empty: the floes file's extent [0, 0, w, h]
  double wall_thickness_m = 20.0;
  template <class V>
  void visit(V& v) {
    v.field("walls", walls, "-",
            "fixed walls on these sides of the domain: any of \"west\", \"east\", \"south\", \"north\"",
            Check<std::vector<std::string>>([](const std::vector<std::string>& w) -> std::string {
              for (size_t i = 0; i < w.size(); ++i) {
                if (w[i] != "west" && w[i] != "east" && w[i] != "south" && w[i] != "north")
                  return "unknown side \"" + w[i] + "\" (known: west, east, south, north)";
                for (size_t j = 0; j < i; ++j)
                  if (w[j] == w[i]) return "side \"" + w[i] + "\" given twice";
              }
              return "";
            }));
    v.field("extent_m", extent_m, "m",
            "domain rectangle [x_min, y_min, x_max, y_max] whose sides carry the walls; [] = the floes file's image "
            "extent [0, 0, width_m, height_m]",
            rectangle_m(true));
    v.field("wall_thickness_m", wall_thickness_m, "m", "thickness of each wall (outside the domain)", positive());
  }
};

// Ice fracture (PHYSICS.md §2; the seed's third module): at each contact the converged force is compared with the
// closed-form failure loads; the mode of lowest threshold happens (§2.4) and the floe is replaced by its pieces.
// Material defaults are the seed's Table 1 (E = 5 GPa, nu = 0.3, K_IC = 150 kPa sqrt(m), sigma_f = 500 kPa).
struct FractureOptions {
  bool enabled = true;
  // Also at floe-floe contacts, level-ice tiles included: a piece pushed against or under the sheet's edge breaks it
  // (PHYSICS.md §10.3 a), a floe jammed between bow and ice breaks.
  bool ice_ice = true;
  double flexural_strength_pa = 5e5;         // sigma_f
  double youngs_modulus_pa = 5e9;            // E (effective, of the floating plate)
  double poisson_ratio = 0.3;                // nu
  double fracture_toughness_pa_sqrtm = 1.5e5;  // K_IC
  double splitting_coefficient = 2.0;        // C_s of F_split = C_s K_IC h sqrt(L) (§2.2: 2-3; §2.4's example: 2)
  double splitting_coefficient_free = 2.5;   // C_s of the part reacted by the floe's inertia and drag (§2.2: higher)
  std::vector<double> wedge_angle_deg = {45.0, 90.0};  // theta drawn uniformly in [min, max] per event (§2.1)
  int seed = 1;                              // of the theta draws (a hash of seed, floe id and step: reproducible)
  // The broken piece's extent R_b beyond the load point (§2.1 step 3): "nevel", the static wedge's
  // (xi* - alpha) l_c (0.3-0.8 l_c for ship contacts); or "empirical", C_l l_c (Wang 2001; Su et al. 2010), the
  // size of observed icebreaker cusps (0.1-0.3 l_c). Either way P_f and the finite-floe check stay Nevel's.
  std::string piece_size = "nevel";
  double piece_c_l = 1.0 / 6;                // C_l of the empirical R_b = C_l l_c (§2.1: ~1/6)
  bool speed_correction = false;             // R_b x (1 + C_v v_n) (§2.1, velocity effects), either piece size
  double speed_coefficient_spm = -0.1;       // C_v, s/m
  // The load a failure test reads: the pair's contact force averaged over the last load_window_s of contact (a box
  // mean of whole steps; §2.5), so that it does not depend on where the relax pass stopped. 0: this step's force.
  double load_window_s = 0.05;
  double min_piece_area_m2 = 1.0;            // smaller pieces (and slivers) are brash
  // Brash: "rigid" (kept: bodies with rigid contacts, no crushing rows and no fracture; SAMS's small fragments,
  // §1.7) or "removed" (deleted, its mass counted: the model before issue #33, kept for comparison).
  std::string brash = "rigid";
  // A bending wedge that would be brash: "brash" (cut as is: a brash piece) or "enlarge" (its R_b grown until it
  // is the smallest piece that is not brash).
  std::string small_wedge = "brash";
  template <class V>
  void visit(V& v) {
    v.field("enabled", enabled, "-", "floes break (bending, radial cracking, splitting); false: they only crush");
    v.field("ice_ice", ice_ice, "-",
            "fracture at floe-floe contacts too: floes break against floes and pieces pushed against or under a level "
            "ice sheet break its edge (false: only at the vessel)");
    v.field("flexural_strength_pa", flexural_strength_pa, "Pa", "flexural strength sigma_f (bending, radial cracks)",
            positive());
    v.field("youngs_modulus_pa", youngs_modulus_pa, "Pa", "effective Young's modulus E of the ice plate (l_c)",
            positive());
    v.field("poisson_ratio", poisson_ratio, "-", "Poisson ratio nu of ice (l_c)", in_range(0, 0.49));
    v.field("fracture_toughness_pa_sqrtm", fracture_toughness_pa_sqrtm, "Pa m^0.5",
            "apparent fracture toughness K_IC (splitting)", positive());
    v.field("splitting_coefficient", splitting_coefficient, "-",
            "C_s of the splitting load C_s K_IC h sqrt(L), L the chord along the force line, for the part of the push "
            "the floe's other contacts press back (diametral)", positive());
    v.field("splitting_coefficient_free", splitting_coefficient_free, "-",
            "C_s for the part of the push the floe's inertia and the water's drag take (a free floe: lower tension, a "
            "higher C_s; PHYSICS.md 2.2)", positive());
    v.field("wedge_angle_deg", wedge_angle_deg, "deg",
            "[min, max] of the wedge angle theta between the two radial cracks, drawn per event; inside (0, 180)",
            Check<std::vector<double>>([](const std::vector<double>& a) -> std::string {
              if (a.size() != 2) return "must be [min, max] in degrees, e.g. [45, 90]";
              if (!(a[0] > 0 && a[1] < 180)) return "both angles must lie inside (0, 180) degrees (0 < theta < pi)";
              if (!(a[0] <= a[1])) return "needs min <= max";
              return "";
            }));
    v.field("seed", seed, "-", "seed of the wedge-angle draws", int_in_range(0, 2147483647));
    v.field("piece_size", piece_size, "-",
            "the broken wedge's extent R_b beyond the load point: \"nevel\" (the static wedge's (xi* - alpha) l_c, "
            "PHYSICS.md 2.1's table) or \"empirical\" (piece_c_l x l_c, Wang 2001); the failure load is the table's",
            one_of({"nevel", "empirical"}));
    v.field("piece_c_l", piece_c_l, "-",
            "C_l of the empirical piece size R_b = C_l l_c (x (1 + C_v v_n) with speed_correction); "
            "used with piece_size \"empirical\"",
            in_range(0.01, 1.5));
    v.field("speed_correction", speed_correction, "-",
            "shrink the broken piece with the normal speed: R_b x (1 + speed_coefficient_spm x v_n), R_b from "
            "piece_size");
    v.field("speed_coefficient_spm", speed_coefficient_spm, "s/m", "C_v of the speed correction (< 0: smaller pieces)",
            in_range(-10, 0));
    v.field("load_window_s", load_window_s, "s",
            "the failure tests read the contact force of a body pair averaged over this much of its contact (whole "
            "steps; 0: the step's own force), so that fracture does not depend on where the solver stopped",
            in_range(0, 1));
    v.field("min_piece_area_m2", min_piece_area_m2, "m^2",
            "pieces smaller than this, or narrower than the ice is thick, are brash (see brash)", non_negative());
    v.field("brash", brash, "-",
            "what becomes of brash: \"rigid\" (kept as bodies with rigid contacts: no crushing rows, never broken; "
            "their load on the vessel is the rigid part) or \"removed\" (deleted, its mass counted in the summary)",
            one_of({"rigid", "removed"}));
    v.field("small_wedge", small_wedge, "-",
            "a bending wedge that would be brash (below min_piece_area_m2 or narrower than the ice is thick): "
            "\"brash\" (cut as it is: a brash piece) or \"enlarge\" (R_b grown to the smallest wedge that is not "
            "brash)",
            one_of({"brash", "enlarge"}));
  }
};

struct SleepOptions {
  bool enabled = true;
  double linear_mps = 0.02;      // a floe slower than this ...
  double angular_radps = 0.02;   // ... and turning slower than this ...
  double time_s = 1.0;           // ... without contacts for this long falls asleep (not integrated)
  double freeze_astern_m = 0;    // > 0: floes this far astern of every hull body sleep at any speed
  template <class V>
  void visit(V& v) {
    v.field("enabled", enabled, "-", "let resting floes sleep (no integration until touched)");
    v.field("linear_mps", linear_mps, "m/s", "speed below which a floe may sleep", non_negative());
    v.field("angular_radps", angular_radps, "rad/s", "angular speed below which a floe may sleep", non_negative());
    v.field("time_s", time_s, "s", "time below the thresholds, without contacts, before sleeping", non_negative());
    v.field("freeze_astern_m", freeze_astern_m, "m",
            "0: off; else a floe far astern of every hull body falls asleep at once, whatever its speed, and is "
            "held there (a moving body that touches it wakes it for that step). Far astern of a ship: behind its "
            "centre of mass along its heading and farther than this from it; of a structure in drifting ice: more "
            "than this behind it along its motion through the ice (the ice it breaks spreads beside it and still "
            "flows past it there). Broken ice far behind no longer loads the hull, and would otherwise stay awake for "
            "minutes (quadratic drag stops a piece slowly): the cost then follows the ice near the hull, not the "
            "length of ice broken. Only in still water and air (or in the drifting ice's frame), like all sleeping",
            non_negative());
  }
};

// Numerical health: the run stops with a diagnosis instead of writing nonsense.
struct HealthOptions {
  double max_speed_mps = 30.0;        // any body faster than this is a blow-up
  double max_angular_radps = 30.0;    // any body turning faster than this is a blow-up
  template <class V>
  void visit(V& v) {
    v.field("max_speed_mps", max_speed_mps, "m/s", "a body faster than this stops the run (energy blow-up)",
            positive());
    v.field("max_angular_radps", max_angular_radps, "rad/s", "a body turning faster than this stops the run",
            positive());
  }
};

// Open water cut out of a level ice sheet (a channel, or room for a pre-broken zone given as floes).
struct LevelIceOpening {
  std::vector<double> rect_m;
  template <class V>
  void visit(V& v) {
    v.field("rect_m", rect_m, "m", "the opening [x_min, y_min, x_max, y_max]", rectangle_m(false));
  }
};

// One point of a thickness that varies along x (the track): linear between points, constant beyond the ends.
struct ThicknessPoint {
  double x_m = 0;
  double thickness_m = 1.0;
  template <class V>
  void visit(V& v) {
    v.field("x_m", x_m, "m", "position along x", Check<double>([](const double& x) -> std::string {
              return std::isfinite(x) ? "" : "must be finite";
            }));
    v.field("thickness_m", thickness_m, "m", "ice thickness there", positive());
  }
};

// A level ice sheet (issue #10): a continuous sheet held by the ice around it, broken only by the fracture module.
// It is cut into tiles of tile_m x tile_m on a grid centred on the sheet; each tile is one fixed body (a floe
// of infinite mass, never awake: it costs nothing per step until the vessel or a moving floe touches it). A
// wedge broken off a tile is a floe; what is left of the tile stays fixed (sim/engine/model.h, Body::fixed). The sheet
// may also come from the floes file (features with "kind": "level_ice"), tiled the same way.
struct LevelIceOptions {
  std::vector<double> extent_m;              // [] = no sheet from these options
  double thickness_m = 1.0;
  std::vector<ThicknessPoint> thickness_profile;  // [] = uniform thickness_m
  std::vector<LevelIceOpening> openings;
  double tile_m = 50.0;
  double clearing_depth_m = 0.1;
  template <class V>
  void visit(V& v) {
    v.field("extent_m", extent_m, "m",
            "the sheet's rectangle [x_min, y_min, x_max, y_max]; [] = no sheet from these options (features of the "
            "floes file with \"kind\": \"level_ice\" are sheets too)",
            rectangle_m(true));
    v.field("thickness_m", thickness_m, "m", "thickness of the sheet (when thickness_profile is empty)", positive());
    v.list("thickness_profile", thickness_profile,
           "thickness along x: [{\"x_m\", \"thickness_m\"}, ...] in increasing x, linear between points; each tile "
           "takes the value at its centre (so tile_m sets the resolution)");
    v.list("openings", openings, "open water cut out of the sheet: [{\"rect_m\": [x_min, y_min, x_max, y_max]}]");
    v.field("tile_m", tile_m, "m",
            "side of the square tiles the sheet is cut into (fixed bodies; a crack stops at a tile's side, so keep "
            "it several times the ice's characteristic length)",
            in_range(1, 1e4));
    v.field("clearing_depth_m", clearing_depth_m, "m",
            "a structure (vessel.station_keeping.mode fixed) crushing into a tile: once its section at the tile's "
            "mid-plane overlaps the tile this deep on average (area over width), the crushed ice is cleared "
            "(extruded: cut out of the tile along the section, a fifth of this depth left in contact, its mass "
            "counted); without it a vertical structure would tunnel into the sheet",
            in_range(0.01, 10));
    for (size_t i = 1; i < thickness_profile.size(); ++i)
      if (!(thickness_profile[i].x_m > thickness_profile[i - 1].x_m))
        v.problem("thickness_profile", "needs strictly increasing x_m (point " + std::to_string(i) + ")");
  }
  // The sheet's thickness at x (thickness_m, or the profile interpolated).
  double thickness_at(double x) const {
    const auto& p = thickness_profile;
    if (p.empty()) return thickness_m;
    if (x <= p.front().x_m) return p.front().thickness_m;
    if (x >= p.back().x_m) return p.back().thickness_m;
    size_t i = 1;
    while (p[i].x_m < x) ++i;
    const double s = (x - p[i - 1].x_m) / (p[i].x_m - p[i - 1].x_m);
    return p[i - 1].thickness_m + s * (p[i].thickness_m - p[i - 1].thickness_m);
  }
};

// What the engine reads: the time step, its threads and the physics sections. Read from a case through the
// simulate stage's options (EngineSettings derives from it and keeps the keys and their order).
// The ice's drift (issue #34): ice coming to a structure. With a drift the run is computed in the ice's frame,
// which moves at the drift velocity: the level ice and the floes start at rest, the water moves at the current minus
// the drift, the air at the wind minus the drift, and a fixed structure moves at minus the drift. Loads depend on
// relative motion only, so this is exact, and ice far from the structure rests (asleep: it costs nothing) until the
// structure reaches it. Positions in the results are in the ice's frame; an earth-frame position is that plus the
// drift velocity times the time.
struct DriftOptions {
  double speed_mps = 0.0;      // 0: no drift, the earth frame
  double direction_deg = 0.0;  // the direction the ice drifts to, CCW from +x
  template <class V>
  void visit(V& v) {
    v.field("speed_mps", speed_mps, "m/s",
            "the ice's drift speed in the earth frame (0: none); the run is computed in the ice's frame (ice carried "
            "by the current: set water.current_speed_mps and current_direction_deg to the same drift)",
            in_range(0, 10));
    v.field("direction_deg", direction_deg, "deg", "the direction the ice drifts to, CCW from +x",
            in_range(-360, 360));
  }
  // The drift velocity, earth frame (horizontal).
  Vec2 velocity() const {
    const double a = direction_deg * kPi / 180;
    return speed_mps * Vec2(std::cos(a), std::sin(a));
  }
};

struct EngineSettings {
  double time_step_s = 0.01;
  int threads = 1;
  IceOptions ice;
  WaterOptions water;
  VesselOptions vessel;
  WindOptions wind;
  SolverOptions solver;
  ContactOptions contact;
  DomainOptions domain;
  FractureOptions fracture;
  SleepOptions sleep;
  HealthOptions health;
  LevelIceOptions level_ice;
  DriftOptions drift;
  std::vector<StructureOptions> structures;  // hull bodies beside the vessel's (see StructureOptions)
  std::vector<RidgeOptions> ridges;          // ridges in the level ice (sim/engine/ridge.h, issue #36)
  RidgeFieldOptions ridge_field;             // more ridges along a route at a density (after `ridges`)
  RidgeSettlingOptions ridge_settling;       // how their rubble is settled before the run
  FreezeBondOptions freeze_bonds;            // and frozen together once settled

  long reference_horizon_steps() const { return std::lround(solver.reference_horizon_s / time_step_s); }  // 0: none
};

}  // namespace floesim::sim
