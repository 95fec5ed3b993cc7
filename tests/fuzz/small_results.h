// A small valid results file's content for the results harnesses: two steps, one frame of two bodies (one in
// contact), a floe and the piece it broke into by one fracture event, one hull triangle.
#pragma once
#include <cmath>

#include "pipeline/results_io.h"

namespace floesim::fuzz {

inline floesim::Results small_results() {
  floesim::Results r;
  for (const auto& f : floesim::series_fields()) r.series[f.name].assign(2 * f.cols, 0.0);
  r.series["time_s"] = {0.0, 0.01};
  r.frame_time_s = {0.0};
  r.frame_offset = {0, 2};
  r.state_body_id = {0, 1};
  r.state_position_m = {0, 0, 0, 10, 0, 0};
  r.state_quaternion = {1, 0, 0, 0, 1, 0, 0, 0};
  r.state_in_contact = {0, 1};
  r.floe_id = {1, 2};
  r.floe_thickness_m = {1.0, 1.0};
  r.floe_vertex_offset = {0, 3, 6};
  r.floe_vertices_m = {-1, -1, 2, -1, -1, 2, -1, -1, 2, -1, -1, 2};
  r.floe_parent_id = {-1, 1};
  r.floe_generation = {0, 1};
  r.floe_origin_mode = {0, 1};
  r.floe_created_s = {0.0, 0.005};
  r.floe_ended_s = {0.005, INFINITY};
  r.hull_vertices_m = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  r.hull_triangles = {0, 1, 2};
  r.fracture_time_s = {0.005};
  r.fracture_parent_id = {1};
  r.fracture_mode = {1};
  r.fracture_at_structure = {1};
  r.fracture_force_n = {1, 0, 0};
  r.fracture_threshold_n = {1};
  r.fracture_point_m = {0, 0, 0};
  r.fracture_width_m = {1};
  r.fracture_theta_rad = {1};
  r.fracture_brash_mass_kg = {0};
  r.fracture_child_offset = {0, 1};
  r.fracture_child_id = {2};
  r.attributes = {{"time_step_s", 0.01}, {"duration_s", 0.02}, {"output_interval_s", 0.01}};
  return r;
}

}  // namespace floesim::fuzz
