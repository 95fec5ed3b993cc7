// The simulation results artefact (HDF5), one documented layout. The table of per-step series below drives the
// writer, the reader and the README's table; add a field here and it flows everywhere.
//
//   /series/<name>         [steps x cols] float64   one row per time step (see series_fields())
//   /frames/time_s         [F]            float64   times of the stored body states (output interval)
//   /frames/offset         [F+1]          int64     rows of frame k are offset[k] .. offset[k+1]-1 of /states/*
//   /states/body_id        [R]            int32     0 = vessel, k >= 1 = floe id k (bodies may appear later)
//   /states/position_m     [R x 3]        float64   centre of mass, world frame (x right, y up, z up from water)
//   /states/quaternion_wxyz[R x 4]        float64   body-to-world rotation
//   /geometry/floe_id            [n]      int32
//   /geometry/floe_thickness_m   [n]      float64
//   /geometry/floe_vertex_offset [n+1]    int64     outline of floe k: rows offset[k] .. offset[k+1]-1
//   /geometry/floe_vertices_m    [V x 2]  float64   CCW outline in the floe's body frame (origin = centre of mass;
//                                                   the slab spans z = -h/2 .. h/2 in that frame)
//   /geometry/hull_vertices_m    [Vh x 3] float64   hull mesh in the vessel body frame (origin = centre of mass)
//   /geometry/hull_triangles     [T x 3]  int32
//   attribute "floesim" on the root: JSON text with layout version, time_step_s, duration_s,
//   output_interval_s and the provenance.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace floesim {

struct FieldSpec {
  const char* name;
  int cols;
  const char* unit;
  const char* doc;
};

// Per-step series written by simulate. Loads on the vessel are in body axes (x forward = surge, y = sway to port,
// z = heave up; moments roll, pitch, yaw about the centre of mass); ice resistance is a negative surge force.
const std::vector<FieldSpec>& series_fields();
const FieldSpec& series_field(const std::string& name);  // Error if unknown

struct Results {
  std::map<std::string, std::vector<double>> series;  // name -> row-major [steps x cols]

  std::vector<double> frame_time_s;
  std::vector<int64_t> frame_offset;  // size frames+1
  std::vector<int32_t> state_body_id;
  std::vector<double> state_position_m;     // [R x 3]
  std::vector<double> state_quaternion;     // [R x 4] w x y z

  std::vector<int32_t> floe_id;
  std::vector<double> floe_thickness_m;
  std::vector<int64_t> floe_vertex_offset;  // size n+1
  std::vector<double> floe_vertices_m;      // [V x 2]
  std::vector<double> hull_vertices_m;      // [Vh x 3]
  std::vector<int32_t> hull_triangles;      // [T x 3]

  nlohmann::json attributes = nlohmann::json::object();

  size_t steps() const;   // rows of /series/time_s
  size_t frames() const { return frame_time_s.size(); }
  // Appends a row to a series (checks the column count against the table).
  void push(const std::string& name, std::initializer_list<double> row);
  const std::vector<double>& get(const std::string& name) const;  // Error if absent
};

// Checks consistency (every series has steps x cols values, offsets monotone, ...) and writes atomically.
void write_results(const std::filesystem::path& file, const Results& r);
// Reads and validates; errors name the file and the dataset.
Results read_results(const std::filesystem::path& file, bool with_states = true);

}  // namespace floesim
