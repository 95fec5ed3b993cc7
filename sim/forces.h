// External forces, one function per force (PHYSICS.md §3-4). Each returns a wrench in the world frame about the
// body's centre of mass. The forces stage of World::step sums them per awake body.
#pragma once
#include <vector>

#include "sim/model.h"
#include "sim/state.h"

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

Wrench gravity_force(const Model& m, const Body& b);
// Submerged volume and centre of buoyancy (world) of a floe slab in closed form, when the water plane cuts only
// its side walls; false otherwise (then the mesh is clipped).
bool prism_submerged(const Body& b, const BodyKinematics& k, double& volume, Vec3& centroid);
// rho_w g V_sub at the centre of buoyancy: closed form for floe slabs cut through their sides, else from clipping
// the body's closed surface at z = 0.
Wrench buoyancy_force(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s);
// Linear heave (world z) and roll/pitch (body x, y) damping from the damping ratios.
Wrench hydrostatic_damping(const Model& m, const Body& b, const BodyKinematics& k);
// Per-face form drag and skin friction on the submerged faces of a floe slab, relative to the current (§3.2).
Wrench floe_water_drag(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s);
// Air skin drag on the part of the top face above water (wind on floes).
Wrench floe_wind_drag(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s);
// ITTC-57 open-water resistance opposite the surge velocity relative to the water.
Wrench vessel_resistance(const Model& m, const BodyKinematics& k);
// Cross-flow drag on strips along the waterline length: sway and yaw damping.
Wrench vessel_cross_flow(const Model& m, const BodyKinematics& k);
// Fossen-type wind load from the relative wind.
Wrench vessel_wind(const Model& m, const BodyKinematics& k);
// Thrust along the body x axis at the centre of mass, by propulsion mode. `integral` is the PI controller's state
// (advanced by dt here in speed mode); thrust_n returns the thrust.
Wrench vessel_propulsion(const Model& m, const BodyKinematics& k, double time_s, double dt, double& integral,
                         double& thrust_n);
// Heading hold: PD yaw moment towards heading_ref, limited.
Wrench vessel_autopilot(const Model& m, const Body& b, const BodyKinematics& k, double heading_ref);

// Heading of the body x axis in the horizontal plane (rad, CCW from +x).
double heading_of(const Mat3& R);

}  // namespace floesim::sim
