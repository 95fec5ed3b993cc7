// The real benchmark hulls in ../shared/data/hulls (KCS and DTMB 5415, model scale, bow towards -x in the files,
// calm waterline at z = 0), placed with "bow_direction": "-x" (issue #13), load into convex parts and, given the mass
// they displace up to z = 0, float with their design waterline at z = 0: released off equilibrium (heave, heel and trim), free of propulsion and ice, they
// settle back with mean sinkage, trim and heel ~ 0.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sim/engine/world.h"
#include "sim/simulate/options.h"
#include "tests/sim/obj_faces.h"
#include "pipeline/geometry2d.h"

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;

using testing::hull_file;

// The raw mesh (all faces of the OBJ, no welding or slicing): its volume below z = 0 is what the ship displaces.
double raw_displaced_volume(const fs::path& f) {
  const TriMesh raw = testing::read_obj_faces(f);
  return submerged_part(raw.vertices, raw.triangles, 0.0).volume;
}

struct Attitude {
  double sinkage_m, trim_deg, heel_deg;  // sinkage: height of the hull frame's z = 0 above the water (+ = risen)
};

Attitude attitude(const World& w, const Vec3& com_hull) {
  const Mat3 R = w.state().orientation[0].toRotationMatrix();
  const Vec3 origin = w.state().position[0] - R * com_hull;  // the hull frame's origin in the world
  return {origin.z(), std::asin(-R(2, 0)) * 180 / kPi, std::atan2(R(2, 1), R(2, 2)) * 180 / kPi};
}

void settles_at_waterline(const std::string& name, double draught_m) {
  const fs::path f = hull_file(name);
  ASSERT_TRUE(fs::exists(f));
  HullPlacement bow_ahead;
  bow_ahead.bow_direction = "-x";  // as the files lie; the simulator's bow is +x
  const HullModel hull = load_hull(f, HullLoadOptions{}, bow_ahead);
  const double v_raw = raw_displaced_volume(f);
  SimulateOptions o;
  o.vessel.mass_kg = o.water.density_kg_m3 * v_raw;  // the mass the real hull displaces up to z = 0
  o.vessel.vcg_m = -0.3 * draught_m;                   // a plausible KG (~0.7 T)
  o.vessel.initial_speed_mps = 0;
  o.vessel.propulsion.mode = "constant_thrust";
  o.vessel.propulsion.thrust_n = 0;
  o.vessel.autopilot.enabled = false;
  const Model m = build_model(FloeField{}, &hull, o);
  const VesselParticulars& vp = m.vessel_info;
  // The convex parts hold a little more volume than the raw mesh (hulls of slices; +0.6 % for these hulls), so the
  // vessel must rise by about dV / A_wp: that is the only error of "waterline at z = 0" the decomposition allows.
  const double v_parts = submerged_part(hull.surface.vertices, hull.surface.triangles, 0.0).volume;
  const double expected_rise = (v_parts - v_raw) / vp.waterplane_area_m2;

  // Released 5 % of the draught low, heeled 2 degrees and trimmed 0.5 degrees.
  World w(m);
  Quat& q = w.mutable_state().orientation[0];
  q = Quat(Eigen::AngleAxisd(0.5 * kPi / 180, Vec3::UnitY())) * Quat(Eigen::AngleAxisd(2 * kPi / 180, Vec3::UnitX())) * q;
  w.mutable_state().position[0].z() -= 0.05 * draught_m;
  w.sync();
  const Attitude a0 = attitude(w, vp.centre_of_mass_hull);
  // Model-scale periods are ~1 s (heave, pitch) to ~2.5 s (roll at 8 % damping): 30 s, mean over the last 5 s.
  const int steps = 3000, tail = 500;
  Attitude mean{0, 0, 0};
  for (int i = 0; i < steps; ++i) {
    w.step();
    if (i >= steps - tail) {
      const Attitude a = attitude(w, vp.centre_of_mass_hull);
      mean.sinkage_m += a.sinkage_m / tail;
      mean.trim_deg += a.trim_deg / tail;
      mean.heel_deg += a.heel_deg / tail;
    }
  }
  std::printf("[measured] %s: L_wl %.3f m, T %.4f m, GM_T %.4f m; displaced volume raw %.5f m^3, parts %.5f m^3\n"
              "  released at sinkage %+.4f m, trim %+.3f deg, heel %+.3f deg\n"
              "  settled: sinkage %+.6f m (expected rise %+.6f m from the parts' extra volume), trim %+.5f deg, heel "
              "%+.6f deg\n",
              name.c_str(), vp.length_wl_m, draught_m, vp.gm_transverse_m, v_raw, v_parts, a0.sinkage_m, a0.trim_deg,
              a0.heel_deg, mean.sinkage_m, expected_rise, mean.trim_deg, mean.heel_deg);
  // Waterline at z = 0: sinkage within 1 % of the draught, and equal to the decomposition's rise within 0.1 mm
  // (the bisection of the initial position and the decay of the released motion are far finer).
  EXPECT_LT(std::abs(mean.sinkage_m), 0.01 * draught_m);
  EXPECT_NEAR(mean.sinkage_m, expected_rise, 1e-4);
  // Trim and heel: the centre of mass is placed above the floating hull's centre of buoyancy, so the equilibrium is
  // level; what remains is the released motion: 2 deg of heel at 8 % damping over >= 12 roll periods decays to
  // 2 deg x exp(-2 pi 0.08 x 12) ~ 0.004 deg in amplitude, and its mean over the last 5 s is smaller still.
  EXPECT_LT(std::abs(mean.trim_deg), 0.005);
  EXPECT_LT(std::abs(mean.heel_deg), 0.005);
}

// KCS model: Lpp 7.2786 m, design draught 0.3418 m.
TEST(SimRealHull, KcsSettlesAtItsWaterline) { settles_at_waterline("KCS_model_scale_L7.2786m.obj", 0.3418); }

// DTMB 5415 model: Lpp 5.72 m, design draught 0.248 m.
TEST(SimRealHull, Dtmb5415SettlesAtItsWaterline) { settles_at_waterline("DTMB5415_model_scale_L5.72m.obj", 0.248); }

}  // namespace
}  // namespace floesim::sim
