// A small synthetic results set with known geometry and motion, for the render and plot tests.
#pragma once
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <unistd.h>

#include "pipeline/results_io.h"

namespace floesim::render::testing {

struct SyntheticFloe {
  int32_t id;
  std::vector<double> outline;  // x0 y0 x1 y1 ... CCW, body frame
  double thickness_m;
  double x, y;                  // fixed world position of the centre of mass
  // Lineage (an input floe by default): a floe has a state in the frames at t with created_s <= t < ended_s.
  int32_t parent_id = -1;
  int32_t generation = 0;
  int32_t origin_mode = kFractureNone;
  double created_s = 0;
  double ended_s = std::numeric_limits<double>::infinity();
  double z = std::nan("");  // centre of mass height; NaN: 0.1 x thickness (floating)
  std::vector<int> contact_frames = {};  // frames in which it is pressed against the vessel (/states/in_contact)
};

struct SyntheticEvent {
  double time_s;
  int32_t parent_id;
  int32_t mode;
  int32_t at_structure;
  double force_n[3];
  double threshold_n;
  std::vector<int32_t> children;
};

inline std::vector<double> square(double half) { return {-half, -half, half, -half, half, half, -half, half}; }
inline std::vector<double> rectangle(double half_x, double half_y) {
  return {-half_x, -half_y, half_x, -half_y, half_x, half_y, -half_x, half_y};
}

// A U-shaped (non-convex) outline: 30 x 30 m with a 10 m wide notch open to +y, centred on the origin.
inline std::vector<double> u_shape() {
  std::vector<double> v = {0, 0, 30, 0, 30, 30, 20, 30, 20, 10, 10, 10, 10, 30, 0, 30};
  for (double& c : v) c -= 15;
  return v;
}

struct Synthetic {
  std::vector<SyntheticFloe> floes;
  std::vector<SyntheticEvent> events;  // in time order; their floes must be in `floes` with matching lineage
  double vessel_speed_mps = 2.0;  // along +x (east), heading east
  double time_step_s = 0.05;
  int steps = 400;                // 20 s
  int frames = 12;                // one per second
  double frame_interval_s = 1.0;
};

inline Synthetic default_synthetic() {
  Synthetic s;
  s.floes = {{1, square(10), 1.0, 60, 0},
             {2, square(8), 0.8, 60, 40},
             {3, square(10), 1.2, -40, -50},
             {4, u_shape(), 1.0, 100, -45},
             {5, square(12), 1.5, 150, 10}};
  return s;
}

// Vessel: a 50 x 12 x 8 m box hull centred on its centre of mass at z = 0, moving east at constant speed.
// Surge ice load Fx = -200 kN for steps 0..99 (t <= 5.0 s) and -1000 kN from step 100 (t = 5.05 s) on, plus a
// +-300 kN alternation that cancels over every pair of steps: the mean over t >= 5.025 s (300 steps) is exactly
// 1000 kN of resistance.
// Ice that breaks (the same vessel, load and frames as default_synthetic):
//   t = 2 s (frame 2): floe 1 (20 x 20 m at 60, 0) splits at the vessel into pieces 2 (south) and 3 (north), 20 x
//                      10 m each, which have drifted 3 m apart from the crack: water at (60, 0) from frame 2 on;
//   t = 6 s (frame 6): piece 3 loses a bending wedge at the vessel; its piece 4 (8 x 8 m at 60, 8) remains;
//   t = 9 s (frame 9): floe 5 (16 x 16 m at -40, -50) cracks radially at a floe-floe contact into piece 6.
inline Synthetic fractured_synthetic() {
  Synthetic s;
  const double inf = std::numeric_limits<double>::infinity();
  s.floes = {{1, square(10), 1.0, 60, 0, -1, 0, kFractureNone, 0, 2.0},
             {2, rectangle(10, 5), 1.0, 60, -8, 1, 1, kFractureSplitting, 2.0, inf},
             {3, rectangle(10, 5), 1.0, 60, 8, 1, 1, kFractureSplitting, 2.0, 6.0},
             {4, square(4), 1.0, 60, 8, 3, 2, kFractureBending, 6.0, inf},
             {5, square(8), 1.2, -40, -50, -1, 0, kFractureNone, 0, 9.0},
             {6, square(5), 1.2, -40, -50, 5, 1, kFractureRadial, 9.0, inf}};
  s.events = {{2.0, 1, kFractureSplitting, 1, {-1.8e6, 2.0e5, -1.0e4}, 1.7e6, {2, 3}},
              {6.0, 3, kFractureBending, 1, {-3.0e5, 1.0e4, -4.5e5}, 4.2e5, {4}},
              {9.0, 5, kFractureRadial, 0, {2.0e4, -1.0e4, -2.5e5}, 2.4e5, {6}}};
  return s;
}

inline Results make_results(const Synthetic& s) {
  Results r;
  for (int k = 0; k < s.steps; ++k) {
    const double t = (k + 1) * s.time_step_s;
    for (const auto& f : series_fields()) {
      std::vector<double> row(f.cols, 0.0);
      const std::string name = f.name;
      if (name == "time_s") row[0] = t;
      if (name == "vessel_position_m") row[0] = s.vessel_speed_mps * t;
      if (name == "vessel_quaternion_wxyz") row[0] = 1;
      if (name == "vessel_velocity_mps") row[0] = s.vessel_speed_mps;
      if (name == "ice_load") row[0] = (k >= 100 ? -1.0e6 : -2.0e5) + (k % 2 == 0 ? 3e5 : -3e5);
      // Events in this step, (t - dt, t], and the floes alive at its end (1e-9 s absorbs round-off in t).
      if (name == "fracture_events")
        for (const auto& e : s.events) row[0] += e.time_s > t - s.time_step_s + 1e-9 && e.time_s <= t + 1e-9;
      if (name == "floe_bodies")
        for (const auto& fl : s.floes) row[0] += fl.created_s <= t + 1e-9 && t + 1e-9 < fl.ended_s;
      auto& v = r.series[f.name];
      v.insert(v.end(), row.begin(), row.end());
    }
  }
  r.frame_offset = {0};
  for (int k = 0; k < s.frames; ++k) {
    const double t = k * s.frame_interval_s;
    r.frame_time_s.push_back(t);
    r.state_body_id.push_back(0);
    r.state_position_m.insert(r.state_position_m.end(), {s.vessel_speed_mps * t, 0.0, 0.0});
    r.state_quaternion.insert(r.state_quaternion.end(), {1, 0, 0, 0});
    r.state_in_contact.push_back(0);
    for (const auto& f : s.floes) {
      if (!(f.created_s <= t && t < f.ended_s)) continue;  // not yet made, or broken
      r.state_body_id.push_back(f.id);
      r.state_position_m.insert(r.state_position_m.end(),
                                {f.x, f.y, std::isnan(f.z) ? 0.1 * f.thickness_m : f.z});
      r.state_quaternion.insert(r.state_quaternion.end(), {1, 0, 0, 0});
      r.state_in_contact.push_back(
          std::find(f.contact_frames.begin(), f.contact_frames.end(), k) != f.contact_frames.end() ? 1 : 0);
    }
    r.frame_offset.push_back(static_cast<int64_t>(r.state_body_id.size()));
  }
  r.floe_vertex_offset = {0};
  for (const auto& f : s.floes) {
    r.floe_id.push_back(f.id);
    r.floe_thickness_m.push_back(f.thickness_m);
    r.floe_vertices_m.insert(r.floe_vertices_m.end(), f.outline.begin(), f.outline.end());
    r.floe_vertex_offset.push_back(static_cast<int64_t>(r.floe_vertices_m.size() / 2));
    r.floe_parent_id.push_back(f.parent_id);
    r.floe_generation.push_back(f.generation);
    r.floe_origin_mode.push_back(f.origin_mode);
    r.floe_created_s.push_back(f.created_s);
    r.floe_ended_s.push_back(f.ended_s);
  }
  for (const auto& e : s.events) {
    r.fracture_time_s.push_back(e.time_s);
    r.fracture_parent_id.push_back(e.parent_id);
    r.fracture_mode.push_back(e.mode);
    r.fracture_at_structure.push_back(e.at_structure);
    r.fracture_force_n.insert(r.fracture_force_n.end(), e.force_n, e.force_n + 3);
    r.fracture_threshold_n.push_back(e.threshold_n);
    r.fracture_point_m.insert(r.fracture_point_m.end(), {0.0, 0.0, 0.0});
    r.fracture_width_m.push_back(1.0);
    r.fracture_theta_rad.push_back(e.mode == kFractureSplitting ? 0.0 : 1.0);
    r.fracture_brash_mass_kg.push_back(0.0);
    r.fracture_child_id.insert(r.fracture_child_id.end(), e.children.begin(), e.children.end());
    r.fracture_child_offset.push_back(static_cast<int64_t>(r.fracture_child_id.size()));
  }
  // Box hull, 8 corners, 12 triangles (outward winding).
  const double L = 25, B = 6, H = 4;
  r.hull_vertices_m = {-L, -B, -H, L, -B, -H, L, B, -H, -L, B, -H, -L, -B, H, L, -B, H, L, B, H, -L, B, H};
  r.hull_triangles = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                      1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
  r.attributes = {{"time_step_s", s.time_step_s}, {"output_interval_s", s.frame_interval_s},
                  {"duration_s", s.steps * s.time_step_s}};
  return r;
}

// A fresh, empty directory per test.
inline std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() /
                 ("floesim_render_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// Names of the files in a directory (sorted), to check that failures leave nothing behind.
inline std::vector<std::string> listing(const std::filesystem::path& d) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(d)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace floesim::render::testing
