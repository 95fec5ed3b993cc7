// External forces, one function per force (PHYSICS.md §3-4). Each returns a wrench in the world frame about the
// body's centre of mass. The forces stage of World::step sums them per awake body.
#pragma once
#include <vector>

#include "sim/engine/model.h"
#include "sim/engine/state.h"

namespace floesim::sim {

struct Wrench {
  Vec3 force = Vec3::Zero();   // N, world
  Vec3 torque = Vec3::Zero();  // N m, world, about the centre of mass
  Wrench& operator+=(const Wrench& o) {
    force += o.force;
    torque += o.torque;
    return *this;
  }
  void add_at(const Vec3& f, const Vec3& lever) {
    force += f;
    torque += lever.cross(f);
  }
};

// Pose and velocity of one body, as the force functions see it.
struct BodyKinematics {
  Vec3 x, v, w;   // centre of mass, velocity, angular velocity (world)
  Quat q;
  Mat3 R;         // q as a matrix
};

// Reusable buffers of one worker (no allocation in the hot loop once warmed up).
struct ForceScratch {
  std::vector<Vec3> vertices;    // transformed vertices of the body
  std::vector<Vec3> waterline;    // per vertical edge of a floe: where it crosses the water plane
  std::vector<uint8_t> crosses;   // per vertical edge: 1 if it crosses the water plane
  std::vector<Vec3> big, big_cut; // a large face and its clipped part
};

// The jet of one propeller in one step (PHYSICS.md §3.5), world frame; made by propeller_jets from the vessel's pose
// and thrust. Axisymmetric about the line origin + x dir (x > 0 behind the propeller), Gaussian across it:
//   near field (zone of flow establishment) 0 < x < 6.2 D_0:  u_c = dV,              sigma = 0.62 D_0
//   far field x >= 6.2 D_0 (a turbulent round jet):            u_c = dV 6.2 D_0 / x,  sigma = 0.1 x
//   u(x, r) = u_c exp(-r^2 / (2 sigma^2)) along dir, for r < 4 sigma (beyond: 0, a cut of 3e-4 u_c); none at x <= 0.
// Both u_c and sigma are continuous at x = 6.2 D_0 (where the far-field formula reaches dV), and so is the jet's
// momentum flux rho pi u_c^2 sigma^2. dV = V_0 - V_A is what the jet adds to the water around it (V_0 at bollard
// pull): V_0 is the slipstream's speed relative to the propeller, which meets the water at V_A.
struct PropellerJet {
  Vec3 origin = Vec3::Zero();  // centre of the propeller disc, world
  Vec3 dir = Vec3::UnitX();    // unit: the direction the jet flows
  double efflux_mps = 0;       // V_0 = sqrt(V_A^2 + 8 |T| / (pi rho_w D_p^2)) (momentum theory)
  double excess_mps = 0;       // dV = V_0 - V_A
  double d0_m = 0;             // D_0 = 0.71 D_p, the contracted slipstream
};
// Centreline speed u_c(x) and Gaussian width sigma(x) of a jet at x metres behind its propeller (see PropellerJet).
double jet_centreline_speed(const PropellerJet& j, double x);
double jet_width(const PropellerJet& j, double x);
// Sum of the jets' velocities at the world point p.
Vec3 jet_velocity(const std::vector<PropellerJet>& jets, const Vec3& p);
// False when no jet reaches the ball (centre, radius): the floe's drag then uses the uniform current alone.
bool jets_reach(const std::vector<PropellerJet>& jets, const Vec3& centre, double radius);
// Whether a jet reaches the floe b with its centre of mass at x (its bounding ball).
bool floe_in_jets(const Body& b, const Vec3& x, const std::vector<PropellerJet>& jets);
// The jets of the vessel's propellers (options.vessel.propellers) for its pose and the propulsion thrust T (each
// propeller makes thrust_share x T along its axis; T < 0 reverses the jet). V_A: the vessel's velocity through the
// water at the propeller along the thrust axis (no wake fraction), at least 0.
void propeller_jets(const Model& m, const BodyKinematics& k, double thrust_n, std::vector<PropellerJet>& out);

Wrench gravity_force(const Model& m, const Body& b);
// Submerged volume and centre of buoyancy (world) of a floe slab in closed form, when the water plane cuts only
// its side walls or when it is wholly under water; false otherwise (then the mesh is clipped).
bool prism_submerged(const Body& b, const BodyKinematics& k, double& volume, Vec3& centroid);
// rho_w g V_sub at the centre of buoyancy: closed form for floe slabs cut through their sides, else from clipping
// the body's closed surface at z = 0.
Wrench buoyancy_force(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s);
// Linear heave (world z) and roll/pitch (body x, y) damping from the damping ratios.
Wrench hydrostatic_damping(const Model& m, const Body& b, const BodyKinematics& k);

// Wave radiation damping in heave of a floating truncated vertical cylinder (radius a, draft T) in deep water at
// frequency omega, N s/m: Haskind's relation for an axisymmetric body, B33 = k |X3|^2 / (4 rho g c_g), with the
// Froude-Krylov heave exciting force X3 = rho g pi a^2 e^(-kT) 2 J1(ka)/(ka) (the incident wave's pressure under
// the bottom; diffraction left out), k = omega^2/g and c_g = g/(2 omega). That is
//   B33 = rho omega^3 (pi a^2)^2 e^(-2kT) (2 J1(ka)/(ka))^2 / (2 g),
// the long-wave limit rho omega^3 A^2/(2g) as ka, kT -> 0; at the natural frequency, B33 / (2 (C33/omega)) =
// pi J1(ka)^2 e^(-2kT) of critical.
double disc_heave_radiation_damping(double rho_w, double g, double radius_m, double draft_m, double omega_radps);

// The radiation force on the heave velocity, a state-space stand-in for Cummins' retardation integral: the heave
// velocity v through a first-order high-pass filter, F = -G (v - u), u the low-passed velocity (State's
// heave_lowpass_mps) with du/dt = w_c (v - u), stepped by backward Euler (stable at any dt). Its damping at
// frequency w is G w^2 / (w^2 + w_c^2): G and w_c (Body::heave_radiation_gain, heave_radiation_corner_radps) make
// it B33 at the natural frequency, and zero for steady motion, as radiation is (no waves at zero frequency).
// Updates `lowpass` to the end of the step; returns the force along world z, N.
double heave_radiation_force(const Body& b, double heave_velocity_mps, double& lowpass_mps, double dt);
// Form drag and skin friction on the submerged faces of a floe slab, relative to the water (§3.2): face by face, the
// form drag sums to the lumped ½ rho_w C_d A_proj |u| u of a convex floe for in-plane flow u (A_proj: the submerged
// area projected across the flow) and to ½ rho_w C_d A |w| w on the bottom for heave. In closed form (body frame)
// while the water plane cuts only the side walls, else by clipping each face (floe_water_drag_clipped).
// The water's velocity is the current plus the propeller jets: per side wall at its wet centroid, on the bottom per
// triangle of a fan from the centroid (a jet is narrower than a big floe); the jets are looked up only for a floe
// they reach.
Wrench floe_water_drag(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s,
                       const std::vector<PropellerJet>& jets = {});
// The same by clipping every face at the water plane, in any pose (the general path; tests compare the two); the
// jets are taken at each wet face's centroid.
Wrench floe_water_drag_clipped(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s,
                               const std::vector<PropellerJet>& jets = {});
// Air skin drag on the part of the top face above water (wind on floes).
Wrench floe_wind_drag(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s);
// What the forces on a hull body need beside its body: its particulars, options and station (the vessel's, or
// structure k's).
struct HullRef {
  const VesselParticulars& info;
  const VesselOptions& options;
  const Station& station;
};
HullRef vessel_ref(const Model& m);
HullRef structure_ref(const Model& m, int k);
// ITTC-57 open-water resistance opposite the surge velocity relative to the water.
Wrench vessel_resistance(const Model& m, const HullRef& h, const BodyKinematics& k);
// Cross-flow drag on strips along the waterline length: sway and yaw damping.
Wrench vessel_cross_flow(const Model& m, const HullRef& h, const BodyKinematics& k);
// Fossen-type wind load from the relative wind.
Wrench vessel_wind(const Model& m, const BodyKinematics& k);
// Thrust along the body x axis at the centre of mass, by propulsion mode (bollard_pull: thrust_n is made, but the
// line to the bollard holds it, so the wrench is zero). `integral` is the PI controller's state
// (advanced by dt here in speed mode); thrust_n returns the thrust.
Wrench vessel_propulsion(const Model& m, const BodyKinematics& k, double time_s, double dt, double& integral,
                         double& thrust_n);
// Heading hold: PD yaw moment towards heading_ref, limited.
Wrench vessel_autopilot(const Model& m, const Body& b, const BodyKinematics& k, double heading_ref);

// A moored, DP or compliant hull body's station keeping (its station_keeping options, issue #34), from its pose at
// time t (the run's frame; the earth frame's pose is x + frame_velocity t): the mooring legs' pull (spread_at_pose,
// quasi-static catenaries, at the reference point's earth-frame offset from the station and the heading's change),
// the DP controller's delivered force (its observer and integral carry over in `dp_memory`, State::dp_memory) or a
// compliant body's spring and damper on its offset and velocity over the earth, plus the steady applied pull.
// World frame, about the centre of mass. `delivered` gets the generalised force in the station's axes (mooring,
// compliant) or body axes (dp): x, y, yaw moment; `demanded` the DP controller's before its limits (the delivered
// otherwise).
struct StationKeeping {
  double demanded[3] = {0, 0, 0};
  double delivered[3] = {0, 0, 0};
  Vec2 offset = Vec2::Zero();  // the reference point's earth-frame offset from the station
  double heading_change_rad = 0;
  std::vector<double> line_tension_n;  // moored: each line's fairlead tension, N (in the order of the lines)
};
Wrench station_keeping_force(const Model& m, const HullRef& h, const BodyKinematics& k, double time_s, double dt,
                             std::vector<double>* dp_memory, StationKeeping* out);

// Heading of the body x axis in the horizontal plane (rad, CCW from +x).
double heading_of(const Mat3& R);

}  // namespace floesim::sim
