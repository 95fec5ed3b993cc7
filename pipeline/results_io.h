// The simulation results artefact (HDF5), one documented layout. Its datasets, with shape, type, columns, units and
// meaning, are the table results_datasets() below (pipeline/results-layout.md is generated from it, and every
// dataset carries those as attributes); the per-step series come from series_fields(). In short:
//
//   /series/<name>      one row per time step (series_fields())
//   /frames, /states    body states at the output interval. Frame k stores the vessel and every body that is new or
//                       whose pose or in_contact changed since its last stored row: a body absent from a frame is
//                       unchanged, not gone. A body is gone from the frames at and after its /geometry/floe_ended_s.
//                       FrameReplay below gives the state of every body at a frame (a sleeping field costs nothing
//                       per frame, so a long transit's file grows with the ice that moves, not with the field).
//   /geometry           every floe that ever existed (outline in its body frame, thickness, level ice, lineage),
//                       and the hull mesh in the vessel's body frame
//   /fracture           one row per fracture event (PHYSICS.md §2), in time order, with its pieces
//   /structures/NAME    the structures: the vessel's hull body when it is one (NAME "vessel") and those beside it
//                       (simulate.structures), one group each, one row per step, earth axes, and each one's mesh;
//                       the root attribute's "structures" lists them: name, kind, reference point and each field's
//                       columns (structure_fields below).
//   attribute "floesim" on the root: JSON text with layout version, time_step_s, duration_s,
//   output_interval_s and the provenance.
//
//   Layout "floesim-results/12" (this one) added the series ice_load_ridge_keel (NaN when reading an earlier file) and
//   the structures' field ridge_keel_force_n. "/11" added the dataset attributes unit, columns, column_units and doc
//   (the data are those of /10). "/10" added the series ice_load_ridge_rubble and ice_load_ridge_layer (NaN when reading an
//   earlier file) and the structures' fields ridge_rubble_force_n and ridge_layer_force_n. "/9" added
//   /structures (none when reading an earlier file). "/8" added the
//   fracture mode 4, crushing, and the series station_offset, station_keeping_demanded and
//   station_keeping_delivered (NaN when reading an earlier file). "/7" stores only the
//   changed bodies in a frame and added the series ice_kinetic_energy (NaN when reading an earlier file); earlier
//   layouts stored every alive body in every frame, which FrameReplay reads the same way. "/6" added the series
//   ice_load_level_ice (NaN when reading an earlier file); "/5" added /geometry/floe_level_ice (all 0 when reading an
//   earlier file); "/4" added /states/in_contact; "/3" added the solver series (relax sweeps and residual, subspace
//   solves, capped steps, contact-law violations); "/2" added /fracture and the lineage datasets. "/1" to "/11" files
//   are still read: a series a file lacks is filled as FieldSpec::since says (input floes only, no events; solver
//   figures NaN: not recorded), /states/in_contact as all 0 (not recorded: no floe is shown in contact) and
//   /geometry/floe_level_ice as all 0.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace floesim {

// How a fracture event broke a floe (PHYSICS.md §2.1-2.4): a wedge cut out when the circumferential (Nevel) load
// P_f governs (bending) or when the radial-crack initiation load P_r governs (radial), or a split along the force
// line (splitting). 0 marks a floe of the input field in /geometry/floe_origin_mode.
// A crushing event (4, layout /8) is not a crack: a fixed structure's crushed ice cleared from a level-ice tile
// (level_ice.clearing_depth_m), the tile's rest its pieces, the crushed mass in /fracture/brash_mass_kg.
enum FractureMode : int32_t {
  kFractureNone = 0,
  kFractureBending = 1,
  kFractureRadial = 2,
  kFractureSplitting = 3,
  kFractureCrushing = 4
};
const char* fracture_mode_name(int32_t mode);  // "input", "bending", "radial", "splitting"

struct FieldSpec {
  const char* name;
  int cols;
  const char* columns;  // the column names, space-separated (one per column)
  const char* unit;
  const char* doc;
  int since = 1;  // the layout version (floesim-results/N) that added it
};

// Per-step series written by simulate. Loads on the vessel are in body axes (x forward = surge, y = sway to port,
// z = heave up; moments roll, pitch, yaw about the centre of mass); ice resistance is a negative surge force.
const std::vector<FieldSpec>& series_fields();
const FieldSpec& series_field(const std::string& name);  // Error if unknown

struct Results {
  std::map<std::string, std::vector<double>> series;  // name -> row-major [steps x cols]
  // The step of series' first rows: 0, unless a long run left the earlier rows on disk (see SeriesSource).
  size_t series_first_step = 0;

  std::vector<double> frame_time_s;
  std::vector<int64_t> frame_offset;  // size frames+1
  std::vector<int32_t> state_body_id;
  std::vector<double> state_position_m;     // [R x 3]
  std::vector<double> state_quaternion;     // [R x 4] w x y z
  std::vector<int8_t> state_in_contact;     // [R] 1: pressed against the vessel in the frame's step (layout /4)

  std::vector<int32_t> floe_id;
  std::vector<double> floe_thickness_m;
  std::vector<int8_t> floe_level_ice;       // [n] 1: a level ice tile (layout /5); empty when writing: all 0
  std::vector<int64_t> floe_vertex_offset;  // size n+1
  std::vector<double> floe_vertices_m;      // [V x 2]
  // Lineage of every floe that ever existed (same order as floe_id).
  std::vector<int32_t> floe_parent_id;
  std::vector<int32_t> floe_generation;
  std::vector<int32_t> floe_origin_mode;
  std::vector<double> floe_created_s;
  std::vector<double> floe_ended_s;
  std::vector<double> hull_vertices_m;      // [Vh x 3]
  std::vector<int32_t> hull_triangles;      // [T x 3]

  // Fracture events (see the layout above).
  std::vector<double> fracture_time_s;
  std::vector<int32_t> fracture_parent_id;
  std::vector<int32_t> fracture_mode;
  std::vector<int32_t> fracture_at_structure;
  std::vector<double> fracture_force_n;      // [E x 3]
  std::vector<double> fracture_threshold_n;
  std::vector<double> fracture_point_m;      // [E x 3]
  std::vector<double> fracture_width_m;
  std::vector<double> fracture_theta_rad;
  std::vector<double> fracture_brash_mass_kg;
  std::vector<int64_t> fracture_child_offset = {0};  // size E+1
  std::vector<int32_t> fracture_child_id;

  // The structures beside the vessel (layout /9): "NAME/FIELD" -> row-major [steps x cols], cols from
  // attributes["structures"]; and each one's mesh.
  std::map<std::string, std::vector<double>> structure_series;
  std::map<std::string, std::vector<double>> structure_hull_vertices_m;  // NAME -> [V x 3]
  std::map<std::string, std::vector<int32_t>> structure_hull_triangles;  // NAME -> [T x 3]

  nlohmann::json attributes = nlohmann::json::object();

  size_t steps() const;   // rows of /series/time_s
  size_t frames() const { return frame_time_s.size(); }
  // Appends a row to a series (checks the column count against the table).
  void push(const std::string& name, std::initializer_list<double> row);
  const std::vector<double>& get(const std::string& name) const;  // Error if absent
};

// The per-step fields of a structure beside the vessel (/structures/NAME/FIELD): name, columns (0: as many as it
// has lines or parts, see the doc), unit, doc. All earth axes; moments about its reference point.
struct StructureField {
  const char* name;
  const char* columns;  // space-separated; "#" is the 1-based line or part of a repeated group
  const char* unit;
  const char* doc;
};
const std::vector<StructureField>& structure_fields();

// Every dataset of the layout, in the order of the file: the one table from which the writer takes each dataset's
// attributes (unit, columns, column_units, doc; layout /11) and pipeline/results-layout.md is generated
// (results_layout_markdown; a test keeps the file current). The series come from series_fields(), a structure's
// fields from structure_fields() (path /structures/NAME/FIELD).
struct DatasetSpec {
  std::string path;     // e.g. "/series/ice_load", "/structures/NAME/ice_force_n"
  std::string type;     // "float64", "int64", "int32", "int8"
  std::string shape;    // e.g. "steps x 6", "R", "V x 2"
  std::string columns;  // space-separated column names; "#" in a name is the 1-based index of a repeated group
  std::string unit;     // "-" for a count, a flag or an index; per column as "N, N m" (3 + 3) or "m, m, rad"
  std::string doc;
};
const std::vector<DatasetSpec>& results_datasets();
// The spec of a dataset by its path (a structure's by /structures/<any name>/FIELD); Error if the layout has none.
const DatasetSpec& results_dataset(const std::string& path);
// A dataset's column names and each column's unit, for `cols` columns (a repeated group, as a mooring's lines or
// a structure's parts, expanded to fill them). Error if they cannot fill `cols`.
std::vector<std::string> column_names(const DatasetSpec& d, size_t cols);
std::vector<std::string> column_units(const DatasetSpec& d, size_t cols);
// The table as Markdown: pipeline/results-layout.md.
std::string results_layout_markdown();

// The lineage and the fracture events checked for consistency (lengths, offsets, modes, time order, ids known to
// /geometry), as write_results and read_results do; for code that builds Results in memory. Returns the first
// problem found, naming the dataset, or "" if there is none.
std::string fracture_problem(const Results& r);

// The state of every body at one frame, from the frames up to it (see the layout above: a body keeps its last
// stored row until it ends). Reads every layout: the earlier ones store every alive body in every frame, which
// replays to the same thing. Frames are visited forwards in O(rows stored since the last one + bodies); seeking
// backwards replays from the first frame.
class FrameReplay {
 public:
  // Error if a state row names a body that is neither the vessel (0) nor in /geometry/floe_id, or a frame lacks the
  // vessel. `source` names the file in messages.
  FrameReplay(const Results& r, const std::string& source);
  void seek(size_t frame);
  size_t frame() const { return static_cast<size_t>(frame_); }
  // The /states rows that hold each body's state at the current frame: the vessel's first, then the floes in
  // /geometry/floe_id order (the order in which they were made).
  const std::vector<int64_t>& rows() const { return rows_; }
  // The /geometry index of each row's floe (-1 for the vessel), in the order of rows().
  const std::vector<int32_t>& floes() const { return floes_; }
  int64_t vessel_row() const { return rows_.empty() ? -1 : rows_.front(); }

 private:
  const Results& r_;
  std::vector<std::pair<int32_t, int32_t>> slot_of_;  // body id -> slot (0 vessel, 1 + geometry index), sorted
  std::vector<int64_t> slot_row_;                     // slot -> latest /states row, -1 if none yet or gone
  std::vector<double> ended_s_;                       // slot -> time it ended (+inf: lasted)
  long frame_ = -1;
  std::vector<int64_t> rows_;
  std::vector<int32_t> floes_;
};

// The per-step series of a run, one at a time. A long simulation keeps only the rows since its last checkpoint in
// Results::series and leaves the earlier ones on disk in the checkpoint's chunks (sim/simulate/checkpoint.h): all the series
// together are 81 values, 0.65 kB, per step (233 MB per simulated hour at 0.01 s), one of them at most 6 values.
// The results writer and the summary read them through this, one series at a time, so that a run's memory does not
// hold them all.
class SeriesSource {
 public:
  virtual ~SeriesSource() = default;
  virtual size_t steps() const = 0;
  // The whole series, row-major [steps x cols]; Error if the layout has no such series.
  virtual std::vector<double> get(const std::string& name) const = 0;
};

// The series as Results::series holds them (all rows in memory).
class ResultsSeries final : public SeriesSource {
 public:
  explicit ResultsSeries(const Results& r);  // Error if r.series do not start at step 0
  size_t steps() const override { return r_.steps(); }
  std::vector<double> get(const std::string& name) const override { return r_.get(name); }

 private:
  const Results& r_;
};

// Checks consistency (every series has steps x cols values, offsets monotone, ...) and writes atomically. The
// series come from `series` (one at a time), or from r.series.
void write_results(const std::filesystem::path& file, const Results& r, const SeriesSource& series);
void write_results(const std::filesystem::path& file, const Results& r);
// Reads and validates; errors name the file and the dataset. `only_series` (non-empty) reads just those series
// (and time_s): a reader that needs one series of a long run need not hold them all (81 values, 0.65 kB, per step).
Results read_results(const std::filesystem::path& file, bool with_states = true,
                     const std::set<std::string>& only_series = {});

}  // namespace floesim
