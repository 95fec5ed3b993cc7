#include "pipeline/results_io.h"

#include <hdf5.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"

namespace floesim {

const std::vector<FieldSpec>& series_fields() {
  static const std::vector<FieldSpec> k = {
      {"time_s", 1, "time_s", "s", "simulation time at the end of the step"},
      {"vessel_position_m", 3, "x y z", "m", "vessel centre of mass, world frame"},
      {"vessel_quaternion_wxyz", 4, "w x y z", "-", "vessel attitude, body to world"},
      {"vessel_velocity_mps", 3, "surge sway heave", "m/s", "vessel velocity, body axes (surge, sway, heave)"},
      {"vessel_angular_velocity_radps", 3, "roll_rate pitch_rate yaw_rate", "rad/s", "vessel angular velocity, body axes (roll, pitch, yaw rate)"},
      {"ice_load", 6, "Fx Fy Fz Mx My Mz", "N, N m", "total ice contact load on the vessel, body axes (Fx Fy Fz Mx My Mz)"},
      {"ice_load_rigid", 6, "Fx Fy Fz Mx My Mz", "N, N m", "part of ice_load from rigid contacts"},
      {"ice_load_compliant", 6, "Fx Fy Fz Mx My Mz", "N, N m", "part of ice_load from compliant (crushing) contacts"},
      {"hydro_load", 6, "Fx Fy Fz Mx My Mz", "N, N m", "hydrostatic + hydrodynamic load on the vessel (buoyancy, drag, resistance), body axes"},
      {"wind_load", 6, "Fx Fy Fz Mx My Mz", "N, N m", "wind load on the vessel, body axes"},
      {"propulsion_load", 6, "Fx Fy Fz Mx My Mz", "N, N m", "propulsion load on the vessel, body axes"},
      {"contact_count", 1, "contact_count", "-", "contacts in the step (all bodies)"},
      {"vessel_contact_count", 1, "vessel_contact_count", "-", "contacts on the vessel"},
      {"solver_iterations", 1, "solver_iterations", "-", "contact solver sweeps in the step"},
      {"solver_residual", 1, "solver_residual", "m/s", "largest velocity change of the last sweep"},
      {"awake_floes", 1, "awake_floes", "-", "floes integrated this step (others sleep)"},
      {"fracture_events", 1, "fracture_events", "-", "fracture events in the step (floes broken, /fracture holds each event)", 2},
      {"floe_bodies", 1, "floe_bodies", "-", "floe bodies in the world at the end of the step (pieces included)", 2},
      {"solver_subspace_solves", 1, "solver_subspace_solves", "-", "subspace minimisations (exact sparse solves of the settled rows) in the solve",
       3},
      {"solver_capped", 1, "solver_capped", "-", "1 if the solve stopped at the sweep cap with the tolerance unmet, else 0", 3},
      {"solver_complementarity", 1, "solver_complementarity", "m/s",
       "largest contact-law violation left by the solve (how far one more exact row update would move a velocity)", 3},
      {"relax_iterations", 1, "relax_iterations", "-", "sweeps of the relax pass (no push-out bias), whose impulses are the recorded loads",
       3},
      {"relax_residual", 1, "relax_residual", "m/s", "largest velocity change of the relax pass's last sweep", 3},
      {"relax_capped", 1, "relax_capped", "-", "1 if the relax pass stopped at its sweep cap with the tolerance unmet, else 0", 3},
      {"relax_complementarity", 1, "relax_complementarity", "m/s", "largest contact-law violation left by the relax pass", 3},
      {"solver_surge_load_error", 1, "solver_surge_load_error", "N",
       "surge ice load minus the same from a second solve of the step (simulate.solver.reference; NaN if off)", 3},
      {"ice_load_level_ice", 6, "Fx Fy Fz Mx My Mz", "N, N m",
       "part of ice_load from contacts with level ice tiles (breaking the sheet's edge; the rest is the floes and "
       "broken pieces being cleared, turned and submerged), body axes",
       6},
      {"ice_kinetic_energy", 1, "ice_kinetic_energy", "J",
       "kinetic energy of the floes and pieces (translation and rotation) at the end of the step: a long run's ice "
       "must not gain energy",
       7},
      {"ice_load_ridge_rubble", 6, "Fx Fy Fz Mx My Mz", "N, N m",
       "part of ice_load from the rubble of ridges' keels and sails (simulate.ridges), body axes", 10},
      {"ice_load_ridge_layer", 6, "Fx Fy Fz Mx My Mz", "N, N m",
       "part of ice_load from ridges' consolidated layers and the pieces broken from them, body axes", 10},
      {"ice_load_ridge_keel", 6, "Fx Fy Fz Mx My Mz", "N, N m",
       "part of ice_load_ridge_rubble from keel blocks touching below their consolidated layer's underside (the keel "
       "action of Dolgopolov's F_K), body axes",
       12},
      {"station_offset", 3, "x y heading", "m, m, rad",
       "a moored or DP structure (simulate.vessel.station_keeping): its reference point's offset from its station, "
       "earth frame (x, y), and its heading's change; 0 for a ship or a fixed structure",
       8},
      {"station_keeping_demanded", 3, "Fx Fy Mz", "N, N, N m",
       "a moored or DP structure's station-keeping force (x, y, yaw moment) as asked: the DP controller's command "
       "before the thrust limits (body axes), or the mooring lines' pull (the station's axes); 0 otherwise",
       8},
      {"station_keeping_delivered", 3, "Fx Fy Mz", "N, N, N m",
       "the same as given: the DP thrusters' after their limits, or the mooring lines' pull",
       8},
  };
  return k;
}

const FieldSpec& series_field(const std::string& name) {
  for (const auto& f : series_fields())
    if (name == f.name) return f;
  throw Error("unknown results series '" + name + "'");
}

const char* fracture_mode_name(int32_t mode) {
  switch (mode) {
    case kFractureNone: return "input";
    case kFractureBending: return "bending";
    case kFractureRadial: return "radial";
    case kFractureSplitting: return "splitting";
    case kFractureCrushing: return "crushing";
  }
  throw Error("unknown fracture mode " + std::to_string(mode) +
              " (expected 0 input, 1 bending, 2 radial, 3 splitting, 4 crushing)");
}

const std::vector<StructureField>& structure_fields() {
  static const std::vector<StructureField> fields = {
      {"position_m", "x y z", "m", "[3] its centre of mass, earth frame"},
      {"quaternion_wxyz", "w x y z", "-", "[4] body-to-earth rotation"},
      {"velocity_mps", "x y z", "m/s", "[3] its centre of mass's velocity over the earth"},
      {"ice_force_n", "x y z", "N", "[3] the ice's force on it (every contact)"},
      {"ice_moment_nm", "x y z", "N m", "[3] the ice's moment about its reference point (its axis at the water line)"},
      {"level_ice_force_n", "x y z", "N", "[3] the part of ice_force_n from level ice tiles (breaking the sheet's edge)"},
      {"ridge_rubble_force_n", "x y z", "N", "[3] the part of ice_force_n from ridges' rubble (keels and sails; layout /10)"},
      {"ridge_layer_force_n", "x y z", "N",
       "[3] the part of ice_force_n from ridges' consolidated layers and their pieces (layout /10)"},
      {"ridge_keel_force_n", "x y z", "N",
       "[3] the part of ridge_rubble_force_n from keel blocks touching below their layer's underside (layout /12)"},
      {"water_force_n", "x y z", "N", "[3] buoyancy, damping and the water's resistance (0 for a fixed structure)"},
      {"station_keeping_force_n", "x y z", "N", "[3] its mooring lines' or thrusters' force (0 for a fixed structure)"},
      {"offset", "x y heading", "m, m, rad", "[3] its reference point's offset x, y from the station, its heading's change"},
      {"station_keeping_demanded", "Fx Fy Mz", "N, N, N m",
       "[3] dp: the controller's demand (surge, sway, yaw; body axes) before its limits; moored: as delivered"},
      {"station_keeping_delivered", "Fx Fy Mz", "N, N, N m",
       "[3] dp: the thrusters' force within their limits; moored: the spread's pull in the station's axes"},
      {"line_tension_n", "line#", "N", "[lines] moored: each line's fairlead tension, in the order of its lines"},
      {"part_force_n", "part#.x part#.y part#.z", "N", "[3 x parts] the ice's force on each of its convex parts (part k: columns 3k..3k+2)"}};
  return fields;
}

namespace {

// "N, N m" over 6 columns is 3 + 3; "m, m, rad" one each; one unit for all.
std::vector<std::string> split(const std::string& text, const std::string& sep) {
  std::vector<std::string> out;
  size_t at = 0;
  for (size_t k; (k = text.find(sep, at)) != std::string::npos; at = k + sep.size()) out.push_back(text.substr(at, k - at));
  out.push_back(text.substr(at));
  return out;
}

std::vector<DatasetSpec> make_results_datasets() {
  std::vector<DatasetSpec> d;
  auto add = [&](std::string path, std::string type, std::string shape, std::string columns, std::string unit,
                 std::string doc) { d.push_back({path, type, shape, columns, unit, doc}); };
  for (const FieldSpec& f : series_fields())
    add(std::string("/series/") + f.name, "float64", f.cols == 1 ? "steps" : "steps x " + std::to_string(f.cols),
        f.columns, f.unit, f.doc);
  add("/frames/time_s", "float64", "F", "time_s", "s", "times of the stored body states (the output interval)");
  add("/frames/offset", "int64", "F+1", "row", "-", "rows of frame k are offset[k] .. offset[k+1]-1 of /states/*");
  add("/states/body_id", "int32", "R", "body_id", "-",
      "0 = vessel, k >= 1 = floe id k; frame k stores the vessel and every body that is new or whose pose or "
      "in_contact changed since its last stored row (a body absent from a frame is unchanged, not gone)");
  add("/states/position_m", "float64", "R x 3", "x y z", "m", "centre of mass, world frame (z up from the water)");
  add("/states/quaternion_wxyz", "float64", "R x 4", "w x y z", "-", "body-to-world rotation");
  add("/states/in_contact", "int8", "R", "in_contact", "-",
      "1: a floe pressed against the vessel in the step that ends at this frame (a normal impulse), else 0");
  add("/geometry/floe_id", "int32", "n", "floe_id", "-", "every floe that ever existed, pieces included");
  add("/geometry/floe_thickness_m", "float64", "n", "thickness", "m", "its thickness");
  add("/geometry/floe_level_ice", "int8", "n", "level_ice", "-",
      "1: a tile of a level ice sheet (held by the sheet until it breaks), 0: a floe or a piece");
  add("/geometry/floe_vertex_offset", "int64", "n+1", "row", "-",
      "outline of floe k: rows offset[k] .. offset[k+1]-1 of floe_vertices_m");
  add("/geometry/floe_vertices_m", "float64", "V x 2", "x y", "m",
      "CCW outline in the floe's body frame (origin = centre of mass; the slab spans z = -h/2 .. h/2)");
  add("/geometry/floe_parent_id", "int32", "n", "parent_id", "-", "-1 for a floe of the input field, else the id it broke from");
  add("/geometry/floe_generation", "int32", "n", "generation", "-", "0 for input floes, the parent's + 1 for a piece");
  add("/geometry/floe_origin_mode", "int32", "n", "origin_mode", "-",
      "how it was made: 0 input, else the fracture mode of its event");
  add("/geometry/floe_created_s", "float64", "n", "created", "s", "time it appeared (0 for input floes)");
  add("/geometry/floe_ended_s", "float64", "n", "ended", "s", "time it broke up (replaced by its pieces); +inf if it lasted");
  add("/geometry/hull_vertices_m", "float64", "Vh x 3", "x y z", "m", "hull mesh, vessel body frame (origin = centre of mass)");
  add("/geometry/hull_triangles", "int32", "T x 3", "a b c", "-", "the mesh's triangles (rows of hull_vertices_m)");
  add("/fracture/time_s", "float64", "E", "time_s", "s", "one row per fracture event (PHYSICS.md §2), in time order");
  add("/fracture/parent_id", "int32", "E", "parent_id", "-", "the floe that broke (it ends at this time)");
  add("/fracture/mode", "int32", "E", "mode", "-",
      "1 bending, 2 radial, 3 splitting, 4 crushing (a fixed structure's crushed ice cleared from a level-ice tile)");
  add("/fracture/at_structure", "int32", "E", "at_structure", "-", "1: at a contact with the vessel, 0: floe-floe");
  add("/fracture/force_n", "float64", "E x 3", "x y z", "N", "contact force on the floe at failure, world frame");
  add("/fracture/threshold_n", "float64", "E", "threshold", "N",
      "the failure load it reached (vertical for bending/radial, horizontal for splitting)");
  add("/fracture/point_m", "float64", "E x 3", "x y z", "m", "contact point, world frame");
  add("/fracture/width_m", "float64", "E", "width", "m", "contact width used (never below the thickness)");
  add("/fracture/theta_rad", "float64", "E", "theta", "rad", "wedge angle (bending/radial), 0 for splitting");
  add("/fracture/brash_mass_kg", "float64", "E", "brash_mass", "kg",
      "mass of pieces below the minimum size, removed; for a crushing event the crushed ice cleared");
  add("/fracture/child_offset", "int64", "E+1", "row", "-", "pieces of event k: child_id[offset[k] .. offset[k+1]-1]");
  add("/fracture/child_id", "int32", "C", "floe_id", "-", "floe ids of the pieces that became bodies");
  for (const StructureField& f : structure_fields()) {
    const std::string doc = f.doc;  // "[3] ..." gives the shape
    const size_t close = doc.find("] ");
    add(std::string("/structures/NAME/") + f.name, "float64", "steps x " + doc.substr(1, close - 1), f.columns,
        f.unit, doc.substr(close + 2) + " (earth axes)");
  }
  add("/structures/NAME/hull_vertices_m", "float64", "V x 3", "x y z", "m", "its mesh, body frame (origin = centre of mass)");
  add("/structures/NAME/hull_triangles", "int32", "T x 3", "a b c", "-", "the mesh's triangles");
  return d;
}

}  // namespace

const std::vector<DatasetSpec>& results_datasets() {
  static const std::vector<DatasetSpec> d = make_results_datasets();
  return d;
}

const DatasetSpec& results_dataset(const std::string& path) {
  std::string key = path;
  if (key.rfind("/structures/", 0) == 0) {  // /structures/<name>/FIELD
    const size_t field = key.rfind('/');
    key = "/structures/NAME" + key.substr(field);
  }
  for (const DatasetSpec& d : results_datasets())
    if (d.path == key) return d;
  throw Error("internal: the results layout has no dataset " + path);
}

std::vector<std::string> column_names(const DatasetSpec& d, size_t cols) {
  const std::vector<std::string> names = split(d.columns, " ");
  if (d.columns.find('#') == std::string::npos) {
    FLOESIM_REQUIRE(names.size() == cols, "internal: ", d.path, " has ", names.size(), " column names for ", cols,
                    " columns");
    return names;
  }
  FLOESIM_REQUIRE(cols % names.size() == 0, "internal: ", d.path, ": ", cols, " columns are not groups of ",
                  names.size());
  std::vector<std::string> out;
  for (size_t g = 1; g <= cols / names.size(); ++g)
    for (const std::string& n : names) out.push_back(n.substr(0, n.find('#')) + std::to_string(g) + n.substr(n.find('#') + 1));
  return out;
}

std::vector<std::string> column_units(const DatasetSpec& d, size_t cols) {
  const std::vector<std::string> units = split(d.unit, ", ");
  if (units.size() == 1) return std::vector<std::string>(cols, units[0]);
  if (units.size() == cols) return units;
  FLOESIM_REQUIRE(units.size() == 2 && cols % 2 == 0, "internal: ", d.path, ": units '", d.unit, "' for ", cols,
                  " columns");
  std::vector<std::string> out(cols / 2, units[0]);
  out.resize(cols, units[1]);
  return out;
}

std::string results_layout_markdown() {
  std::string md =
      "# The results file, `results.h5`\n\n"
      "Generated from the field table of `pipeline/results_io.cpp` (`results_layout_markdown`; the test\n"
      "`ResultsLayout.TheGuideIsTheCodesTable` says when this file is stale and how to rewrite it). Every dataset\n"
      "carries the attributes `unit`, `columns` and `column_units` (one string per column) and `doc`. Shapes: `steps`\n"
      "rows of the series, `F` frames, `R` stored states, `n` floes, `V` outline vertices, `E` fracture events,\n"
      "`C` pieces. The root attribute `floesim` is JSON text: the layout, time step, duration, output interval, the\n"
      "structures with their columns, and the provenance.\n\n"
      "| dataset | type | shape | columns | unit | what |\n|---|---|---|---|---|---|\n";
  for (const DatasetSpec& d : results_datasets()) {
    std::string cols = d.columns;
    for (char& c : cols)
      if (c == ' ') c = ',';
    std::string doc = d.doc;
    for (size_t k; (k = doc.find('|')) != std::string::npos;) doc.replace(k, 1, "/");
    md += "| `" + d.path + "` | " + d.type + " | " + d.shape + " | " + cols + " | " + d.unit + " | " + doc + " |\n";
  }
  return md;
}

size_t Results::steps() const {
  auto it = series.find("time_s");
  return it == series.end() ? 0 : it->second.size();
}

void Results::push(const std::string& name, std::initializer_list<double> row) {
  const FieldSpec& f = series_field(name);
  FLOESIM_REQUIRE(static_cast<int>(row.size()) == f.cols, "series ", name, " takes ", f.cols, " values, got ",
                  row.size());
  auto& v = series[name];
  v.insert(v.end(), row.begin(), row.end());
}

ResultsSeries::ResultsSeries(const Results& r) : r_(r) {
  FLOESIM_REQUIRE(r.series_first_step == 0, "internal: these results hold the series from step ",
                  r.series_first_step, " on; read them through the SeriesSource that holds the earlier steps");
}

const std::vector<double>& Results::get(const std::string& name) const {
  auto it = series.find(name);
  if (it == series.end()) throw Error("results have no series '" + name + "'");
  return it->second;
}

namespace {

// RAII for HDF5 ids.
struct H5Id {
  hid_t id = -1;
  herr_t (*close)(hid_t) = nullptr;
  H5Id(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  ~H5Id() {
    if (id >= 0 && close) close(id);
  }
  H5Id(const H5Id&) = delete;
  operator hid_t() const { return id; }
};

template <class T>
hid_t h5type();
template <>
hid_t h5type<double>() { return H5T_NATIVE_DOUBLE; }
template <>
hid_t h5type<int8_t>() { return H5T_NATIVE_INT8; }
template <>
hid_t h5type<int32_t>() { return H5T_NATIVE_INT32; }
template <>
hid_t h5type<int64_t>() { return H5T_NATIVE_INT64; }

// Why HDF5 could not write: the system's reason (its file driver leaves errno set), with the fix.
std::string h5_write_reason() {
  return errno != 0 ? write_failure_reason(errno) : std::string("the disk is full, or the folder is not writable?");
}

// A string attribute: one fixed-length string, or an array of them (null-padded to the longest), which h5py reads
// as bytes. Fixed length keeps the file's bytes the same from run to run.
void write_string_attribute(hid_t obj, const char* key, const std::vector<std::string>& values, bool scalar,
                            const std::string& file, const std::string& name) {
  size_t longest = 1;
  for (const std::string& v : values) longest = std::max(longest, v.size());
  std::string packed(longest * values.size(), '\0');
  for (size_t k = 0; k < values.size(); ++k) std::copy(values[k].begin(), values[k].end(), packed.begin() + k * longest);
  H5Id st(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(st, longest);
  H5Tset_strpad(st, H5T_STR_NULLPAD);
  const hsize_t n = values.size();
  H5Id sp(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose);
  H5Id at(H5Acreate2(obj, key, st, sp, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  FLOESIM_REQUIRE(at.id >= 0 && H5Awrite(at, st, packed.data()) >= 0, file, ": cannot write the attribute ", key,
                  " of ", name, ": ", h5_write_reason());
}

// A dataset's unit, column names, column units and meaning, from the layout's table (results_datasets).
void annotate(hid_t ds, const std::string& name, size_t cols, const std::string& file) {
  const DatasetSpec& d = results_dataset(name);
  write_string_attribute(ds, "unit", {d.unit}, true, file, name);
  write_string_attribute(ds, "columns", column_names(d, cols), false, file, name);
  write_string_attribute(ds, "column_units", column_units(d, cols), false, file, name);
  write_string_attribute(ds, "doc", {d.doc}, true, file, name);
}

template <class T>
void write_ds(hid_t loc, const std::string& name, const std::vector<T>& data, size_t cols, const std::string& file) {
  FLOESIM_REQUIRE(cols > 0 && data.size() % cols == 0, file, ": internal: dataset ", name, " has ", data.size(),
                  " values, not a multiple of ", cols);
  hsize_t dims[2] = {data.size() / cols, cols};
  H5Id space(H5Screate_simple(cols == 1 ? 1 : 2, dims, nullptr), H5Sclose);
  H5Id plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_obj_track_times(plist, false);  // no timestamps: identical runs give identical bytes
  // Chunked + shuffle + light deflate for the large arrays: states dominate the file and compress well.
  if (data.size() > 65536) {
    hsize_t chunk[2] = {std::min<hsize_t>(dims[0], std::max<hsize_t>(1, 65536 / cols)), cols};
    H5Pset_chunk(plist, cols == 1 ? 1 : 2, chunk);
    H5Pset_shuffle(plist);
    H5Pset_deflate(plist, 1);
  }
  H5Id ds(H5Dcreate2(loc, name.c_str(), h5type<T>(), space, H5P_DEFAULT, plist, H5P_DEFAULT), H5Dclose);
  FLOESIM_REQUIRE(ds.id >= 0, file, ": cannot create dataset ", name, ": ", h5_write_reason());
  annotate(ds, name, cols, file);
  if (!data.empty())
    FLOESIM_REQUIRE(H5Dwrite(ds, h5type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) >= 0, file,
                    ": cannot write dataset ", name, ": ", h5_write_reason());
}

// The most rows of `row_bytes` a file can hold: deflate compresses at most 1032:1, plus room for HDF5's fill
// values in a small dataset.
hsize_t max_rows(const std::string& file, size_t row_bytes) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  return static_cast<hsize_t>((1032.0 * (ec ? 0 : static_cast<double>(size)) + (1 << 20)) / row_bytes);
}

template <class T>
std::vector<T> read_ds(hid_t file_id, const std::string& name, size_t cols, const std::string& file) {
  FLOESIM_REQUIRE(H5Lexists(file_id, name.c_str(), H5P_DEFAULT) > 0, file, ": dataset ", name,
                  " is missing (not a floesim results file, or written by another version?)");
  H5Id ds(H5Dopen2(file_id, name.c_str(), H5P_DEFAULT), H5Dclose);
  FLOESIM_REQUIRE(ds.id >= 0, file, ": cannot open dataset ", name);
  H5Id space(H5Dget_space(ds), H5Sclose);
  // The rank is checked before the dimensions are read into dims[2] (a rank-3 dataset overran it), and the row
  // count against the file's size before anything is allocated (a damaged header may claim 2^62 rows: the product
  // with the columns wrapped around, and H5Dread wrote past the buffer).
  const int rank = H5Sget_simple_extent_ndims(space);
  FLOESIM_REQUIRE(rank == 1 || rank == 2, file, ": dataset ", name, " has rank ", rank, ", expected 1 or 2 (damaged file?)");
  hsize_t dims[2] = {0, 1};
  FLOESIM_REQUIRE(H5Sget_simple_extent_dims(space, dims, nullptr) == rank, file, ": cannot read the shape of dataset ",
                  name);
  const size_t got_cols = rank == 2 ? dims[1] : 1;
  FLOESIM_REQUIRE(got_cols == cols, file, ": dataset ", name, " has ", got_cols, " columns, expected ", cols);
  FLOESIM_REQUIRE(dims[0] <= max_rows(file, cols * sizeof(T)), file, ": dataset ", name, " claims ", dims[0],
                  " rows, more than a file of this size can hold (damaged file?)");
  std::vector<T> v(dims[0] * got_cols);
  if (!v.empty())
    FLOESIM_REQUIRE(H5Dread(ds, h5type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0, file,
                    ": cannot read dataset ", name, " (truncated file?)");
  return v;
}

// The layout this version writes (floesim-results/N); it still reads every earlier one so that old artefacts still
// plot and render: /1 had no fracture (no /fracture, no lineage), /2 no solver series beyond sweeps and residual,
// /3 no /states/in_contact, /4 no /geometry/floe_level_ice, /5 no ice_load_level_ice series, /6 every alive body
// in every frame (which FrameReplay reads like the changed bodies of /7) and no ice_kinetic_energy series.
constexpr int kLayoutVersion = 12;
constexpr const char* kLayoutPrefix = "floesim-results/";
std::string layout_name(int version) { return kLayoutPrefix + std::to_string(version); }

// What reading a file of an earlier layout puts in a series that layout did not have: nothing broke before
// fracture existed (no events, every floe of the geometry a body throughout); solver figures were not recorded.
std::vector<double> missing_series(const FieldSpec& f, size_t steps, size_t floes) {
  const std::string name = f.name;
  if (name == "fracture_events") return std::vector<double>(steps, 0.0);
  if (name == "floe_bodies") return std::vector<double>(steps, static_cast<double>(floes));
  return std::vector<double>(steps * f.cols, std::numeric_limits<double>::quiet_NaN());
}

// How many rows a dataset of layout /2 holds.
enum class Rows { per_floe, per_event, events_plus_one, any };

// The lineage and fracture-event datasets of layout /2, one list for the writer, the reader and the length checks:
// f(name, the Results member, columns, rows). R is Results or const Results.
template <class R, class F>
void for_each_fracture_dataset(R& r, F&& f) {
  f("/geometry/floe_parent_id", r.floe_parent_id, 1, Rows::per_floe);
  f("/geometry/floe_generation", r.floe_generation, 1, Rows::per_floe);
  f("/geometry/floe_origin_mode", r.floe_origin_mode, 1, Rows::per_floe);
  f("/geometry/floe_created_s", r.floe_created_s, 1, Rows::per_floe);
  f("/geometry/floe_ended_s", r.floe_ended_s, 1, Rows::per_floe);
  f("/fracture/time_s", r.fracture_time_s, 1, Rows::per_event);
  f("/fracture/parent_id", r.fracture_parent_id, 1, Rows::per_event);
  f("/fracture/mode", r.fracture_mode, 1, Rows::per_event);
  f("/fracture/at_structure", r.fracture_at_structure, 1, Rows::per_event);
  f("/fracture/force_n", r.fracture_force_n, 3, Rows::per_event);
  f("/fracture/threshold_n", r.fracture_threshold_n, 1, Rows::per_event);
  f("/fracture/point_m", r.fracture_point_m, 3, Rows::per_event);
  f("/fracture/width_m", r.fracture_width_m, 1, Rows::per_event);
  f("/fracture/theta_rad", r.fracture_theta_rad, 1, Rows::per_event);
  f("/fracture/brash_mass_kg", r.fracture_brash_mass_kg, 1, Rows::per_event);
  f("/fracture/child_offset", r.fracture_child_offset, 1, Rows::events_plus_one);
  f("/fracture/child_id", r.fracture_child_id, 1, Rows::any);
}

}  // namespace

std::string fracture_problem(const Results& r) {
  std::string e;  // the first length problem
  const size_t n = r.floe_id.size();
  auto rows = [&](const char* name, size_t size, size_t cols, size_t expected, const char* what) {
    if (!e.empty() || size == expected * cols) return;
    e = std::string(name) + " has " + std::to_string(size) + (cols == 1 ? " rows" : " values") + ", expected " +
        std::to_string(expected) + (cols == 1 ? "" : " x " + std::to_string(cols)) + " (" + what + ")";
  };
  const size_t E = r.fracture_time_s.size();
  for_each_fracture_dataset(r, [&](const char* name, const auto& v, size_t cols, Rows per) {
    if (per == Rows::per_floe) rows(name, v.size(), cols, n, "one per /geometry/floe_id");
    if (per == Rows::per_event) rows(name, v.size(), cols, E, "one per event of /fracture/time_s");
    if (per == Rows::events_plus_one) rows(name, v.size(), cols, E + 1, "events + 1");
  });
  if (!e.empty()) return e;

  // Offsets into child_id: 0, non-decreasing, ending at its size.
  const auto& off = r.fracture_child_offset;
  if (off.front() != 0) return "/fracture/child_offset starts at " + std::to_string(off.front()) + ", expected 0";
  for (size_t k = 0; k < E; ++k)
    if (off[k + 1] < off[k])
      return "/fracture/child_offset decreases at event " + std::to_string(k) + " (" + std::to_string(off[k]) +
             " -> " + std::to_string(off[k + 1]) + ")";
  if (static_cast<uint64_t>(off.back()) != r.fracture_child_id.size())
    return "/fracture/child_offset ends at " + std::to_string(off.back()) + ", but /fracture/child_id has " +
           std::to_string(r.fracture_child_id.size()) + " rows";

  // Events: modes, flags, time order.
  for (size_t k = 0; k < E; ++k) {
    const std::string at = " at event " + std::to_string(k);
    if (r.fracture_mode[k] < kFractureBending || r.fracture_mode[k] > kFractureCrushing)
      return "/fracture/mode is " + std::to_string(r.fracture_mode[k]) + at +
             "; expected 1 (bending), 2 (radial), 3 (splitting) or 4 (crushing)";
    if (r.fracture_at_structure[k] != 0 && r.fracture_at_structure[k] != 1)
      return "/fracture/at_structure is " + std::to_string(r.fracture_at_structure[k]) + at + "; expected 0 or 1";
    if (!std::isfinite(r.fracture_time_s[k])) return "/fracture/time_s is not finite" + at;
    if (k > 0 && r.fracture_time_s[k] < r.fracture_time_s[k - 1])
      return "/fracture/time_s decreases" + at + " (events must be in time order)";
  }

  // Every floe an event or a lineage names has geometry: pieces are recorded like input floes.
  std::vector<int32_t> ids(r.floe_id);
  std::sort(ids.begin(), ids.end());
  auto known = [&](int32_t id) { return std::binary_search(ids.begin(), ids.end(), id); };
  for (size_t k = 0; k < E; ++k)
    if (!known(r.fracture_parent_id[k]))
      return "/fracture/parent_id " + std::to_string(r.fracture_parent_id[k]) + " at event " + std::to_string(k) +
             " is not in /geometry/floe_id";
  for (size_t c = 0; c < r.fracture_child_id.size(); ++c)
    if (!known(r.fracture_child_id[c]))
      return "/fracture/child_id " + std::to_string(r.fracture_child_id[c]) + " (row " + std::to_string(c) +
             ") is not in /geometry/floe_id";

  // Lineage: an input floe has parent -1, mode 0 and generation 0; a piece names a known parent and its mode.
  for (size_t g = 0; g < n; ++g) {
    const std::string floe = " for floe " + std::to_string(r.floe_id[g]);
    const int32_t parent = r.floe_parent_id[g], mode = r.floe_origin_mode[g];
    if (mode < kFractureNone || mode > kFractureCrushing)
      return "/geometry/floe_origin_mode is " + std::to_string(mode) + floe + "; expected 0..4";
    if ((parent == -1) != (mode == kFractureNone))
      return "/geometry/floe_parent_id is " + std::to_string(parent) + floe + " but /geometry/floe_origin_mode is " +
             std::to_string(mode) + " (-1 goes with 0: a floe of the input field)";
    if (parent != -1 && !known(parent))
      return "/geometry/floe_parent_id " + std::to_string(parent) + floe + " is not in /geometry/floe_id";
    if (r.floe_generation[g] < 0 || (parent == -1) != (r.floe_generation[g] == 0))
      return "/geometry/floe_generation is " + std::to_string(r.floe_generation[g]) + floe +
             "; expected 0 for an input floe, >= 1 for a piece";
    if (!std::isfinite(r.floe_created_s[g])) return "/geometry/floe_created_s is not finite" + floe;
    if (!(r.floe_ended_s[g] >= r.floe_created_s[g]))
      return "/geometry/floe_ended_s is " + std::to_string(r.floe_ended_s[g]) + floe + ", before it was created (" +
             std::to_string(r.floe_created_s[g]) + " s; +inf if it lasted)";
  }
  return "";
}

namespace {

}  // namespace

void write_results(const std::filesystem::path& path, const Results& r) {
  const std::string file = path.string();
  for (const auto& f : series_fields())  // before ResultsSeries::get would call a missing one an unknown series
    FLOESIM_REQUIRE(r.series.count(f.name), file, ": internal: series ", f.name, " was not recorded");
  write_results(path, r, ResultsSeries(r));
}

void write_results(const std::filesystem::path& path, const Results& r, const SeriesSource& series) {
  const std::string file = path.string();
  const size_t n = series.steps();
  FLOESIM_REQUIRE(r.frame_offset.size() == r.frame_time_s.size() + 1, file, ": internal: frame offsets");
  FLOESIM_REQUIRE(r.floe_level_ice.empty() || r.floe_level_ice.size() == r.floe_id.size(), file,
                  ": internal: floe_level_ice has ", r.floe_level_ice.size(), " rows for ", r.floe_id.size(), " floes");
  FLOESIM_REQUIRE(r.state_position_m.size() == 3 * r.state_body_id.size() &&
                      r.state_quaternion.size() == 4 * r.state_body_id.size() &&
                      r.state_in_contact.size() == r.state_body_id.size(),
                  file, ": internal: state arrays disagree");
  FLOESIM_REQUIRE(r.floe_vertex_offset.size() == r.floe_id.size() + 1, file, ": internal: floe vertex offsets");
  const std::string fracture = fracture_problem(r);
  FLOESIM_REQUIRE(fracture.empty(), file, ": internal: ", fracture);

  AtomicFile out(path);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by us, with context
  errno = 0;
  {
    // H5F_LIBVER_LATEST would embed nothing time-dependent either, but the default keeps files readable by
    // older tools; object modification times are off so that identical runs give identical bytes.
    H5Id fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
    H5Pset_obj_track_times(fcpl, false);
    H5Id fid(H5Fcreate(out.tmp().c_str(), H5F_ACC_TRUNC, fcpl, H5P_DEFAULT), H5Fclose);
    FLOESIM_REQUIRE(fid.id >= 0, file, ": cannot create: ", h5_write_reason());
    H5Id gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
    H5Pset_obj_track_times(gcpl, false);
    for (const char* g : {"/series", "/frames", "/states", "/geometry", "/fracture", "/structures"}) {
      H5Id gid(H5Gcreate2(fid, g, H5P_DEFAULT, gcpl, H5P_DEFAULT), H5Gclose);
    }
    for (const nlohmann::json& st : r.attributes.value("structures", nlohmann::json::array())) {
      const std::string name = st.at("name").get<std::string>(), g = "/structures/" + name;
      H5Id gid(H5Gcreate2(fid, g.c_str(), H5P_DEFAULT, gcpl, H5P_DEFAULT), H5Gclose);
      FLOESIM_REQUIRE(gid.id >= 0, file, ": cannot create ", g, ": ", h5_write_reason());
      for (const auto& [field, cols] : st.at("columns").items()) {
        const auto it = r.structure_series.find(name + "/" + field);
        FLOESIM_REQUIRE(it != r.structure_series.end() && it->second.size() == n * cols.get<size_t>(), file,
                        ": internal: structure series ", name, "/", field, " was not recorded for every step");
        write_ds(fid, g + "/" + field, it->second, cols.get<size_t>(), file);
      }
      write_ds(fid, g + "/hull_vertices_m", r.structure_hull_vertices_m.at(name), 3, file);
      write_ds(fid, g + "/hull_triangles", r.structure_hull_triangles.at(name), 3, file);
    }
    for (const auto& f : series_fields()) {  // one series in memory at a time (see SeriesSource)
      const std::vector<double> values = series.get(f.name);
      FLOESIM_REQUIRE(values.size() == n * f.cols, file, ": internal: series ", f.name, " has ", values.size(),
                      " values, expected ", n, " x ", f.cols);
      write_ds(fid, std::string("/series/") + f.name, values, f.cols, file);
    }
    write_ds(fid, "/frames/time_s", r.frame_time_s, 1, file);
    write_ds(fid, "/frames/offset", r.frame_offset, 1, file);
    write_ds(fid, "/states/body_id", r.state_body_id, 1, file);
    write_ds(fid, "/states/position_m", r.state_position_m, 3, file);
    write_ds(fid, "/states/quaternion_wxyz", r.state_quaternion, 4, file);
    write_ds(fid, "/states/in_contact", r.state_in_contact, 1, file);
    write_ds(fid, "/geometry/floe_id", r.floe_id, 1, file);
    write_ds(fid, "/geometry/floe_thickness_m", r.floe_thickness_m, 1, file);
    write_ds(fid, "/geometry/floe_level_ice",
             r.floe_level_ice.empty() ? std::vector<int8_t>(r.floe_id.size(), 0) : r.floe_level_ice, 1, file);
    write_ds(fid, "/geometry/floe_vertex_offset", r.floe_vertex_offset, 1, file);
    write_ds(fid, "/geometry/floe_vertices_m", r.floe_vertices_m, 2, file);
    write_ds(fid, "/geometry/hull_vertices_m", r.hull_vertices_m, 3, file);
    write_ds(fid, "/geometry/hull_triangles", r.hull_triangles, 3, file);
    for_each_fracture_dataset(r, [&](const char* name, const auto& v, size_t cols, Rows) {
      write_ds(fid, name, v, cols, file);
    });

    nlohmann::json attrs = r.attributes;
    attrs["layout"] = layout_name(kLayoutVersion);
    const std::string text = attrs.dump();
    H5Id st(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(st, text.size() + 1);
    H5Id sp(H5Screate(H5S_SCALAR), H5Sclose);
    H5Id at(H5Acreate2(fid, "floesim", st, sp, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    FLOESIM_REQUIRE(H5Awrite(at, st, text.c_str()) >= 0, file, ": cannot write the attributes: ", h5_write_reason());
    FLOESIM_REQUIRE(H5Fflush(fid, H5F_SCOPE_GLOBAL) >= 0, file, ": writing failed: ", h5_write_reason());
  }
  out.commit();
}

Results read_results(const std::filesystem::path& path, bool with_states, const std::set<std::string>& only_series) {
  const std::string file = path.string();
  FLOESIM_REQUIRE(std::filesystem::exists(path), file, ": no such results file (run floesim-simulate first)");
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  FLOESIM_REQUIRE(H5Fis_hdf5(file.c_str()) > 0, file, ": not an HDF5 file (or truncated)");
  H5Id fid(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  FLOESIM_REQUIRE(fid.id >= 0, file, ": cannot open");
  Results r;
  {
    FLOESIM_REQUIRE(H5Aexists(fid, "floesim") > 0, file, ": no 'floesim' attribute: not a floesim results file");
    H5Id at(H5Aopen(fid, "floesim", H5P_DEFAULT), H5Aclose);
    H5Id st(H5Aget_type(at), H5Tclose);
    H5Id as(H5Aget_space(at), H5Sclose);
    // One fixed-length string (an array of them would be read past the buffer), of a size the file can hold.
    const size_t text_size = H5Tget_size(st);
    FLOESIM_REQUIRE(at.id >= 0 && H5Tget_class(st) == H5T_STRING && H5Tis_variable_str(st) == 0 &&
                        H5Sget_simple_extent_npoints(as) == 1 && text_size > 0 &&
                        text_size <= std::filesystem::file_size(path),
                    file, ": the 'floesim' attribute is not one JSON string: not a floesim results file");
    std::string text(text_size, '\0');
    H5Id mt(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mt, text.size());
    FLOESIM_REQUIRE(H5Aread(at, mt, text.data()) >= 0, file, ": cannot read the attributes");
    text.resize(std::strlen(text.c_str()));
    r.attributes = nlohmann::json::parse(text, nullptr, false);
    FLOESIM_REQUIRE(!r.attributes.is_discarded() && r.attributes.is_object(), file,
                    ": the 'floesim' attribute is not a JSON object");
  }
  const auto layout_it = r.attributes.find("layout");
  const std::string layout =
      layout_it != r.attributes.end() && layout_it->is_string() ? layout_it->get<std::string>() : "?";
  int version = 0;
  for (int v = 1; v <= kLayoutVersion; ++v)
    if (layout == layout_name(v)) version = v;
  FLOESIM_REQUIRE(version > 0, file, ": layout ", layout, " is not supported by this version (it reads ",
                  layout_name(1), " to ", layout_name(kLayoutVersion), "; a newer floesim wrote it?)");
  const bool before_fracture = version < 2;
  // time_s always: it defines the steps.
  auto wanted = [&](const FieldSpec& f) {
    return only_series.empty() || only_series.count(f.name) || std::string(f.name) == "time_s";
  };
  for (const auto& f : series_fields())
    if (f.since <= version && wanted(f))
      r.series[f.name] = read_ds<double>(fid, std::string("/series/") + f.name, f.cols, file);
  const size_t n = r.steps();
  for (const auto& f : series_fields())
    if (r.series.count(f.name))
      FLOESIM_REQUIRE(r.series[f.name].size() == n * f.cols, file, ": series ", f.name, " has the wrong length");
  r.frame_time_s = read_ds<double>(fid, "/frames/time_s", 1, file);
  r.frame_offset = read_ds<int64_t>(fid, "/frames/offset", 1, file);
  FLOESIM_REQUIRE(r.frame_offset.size() == r.frame_time_s.size() + 1, file, ": /frames/offset has the wrong length");
  if (with_states) {
    r.state_body_id = read_ds<int32_t>(fid, "/states/body_id", 1, file);
    r.state_position_m = read_ds<double>(fid, "/states/position_m", 3, file);
    r.state_quaternion = read_ds<double>(fid, "/states/quaternion_wxyz", 4, file);
    // Contact with the vessel was not recorded before layout /4: no floe is shown in contact.
    r.state_in_contact = version >= 4 ? read_ds<int8_t>(fid, "/states/in_contact", 1, file)
                                      : std::vector<int8_t>(r.state_body_id.size(), 0);
    FLOESIM_REQUIRE(r.state_position_m.size() == 3 * r.state_body_id.size() &&
                        r.state_quaternion.size() == 4 * r.state_body_id.size() &&
                        r.state_in_contact.size() == r.state_body_id.size(),
                    file, ": /states arrays have different lengths");
  }
  // Offsets index the arrays after them: 0, non-decreasing, ending at their length (the render walks them).
  auto check_offsets = [&](const std::vector<int64_t>& off, size_t rows, const char* name, const char* of) {
    FLOESIM_REQUIRE(!off.empty() && off.front() == 0, file, ": ", name, " does not start at 0");
    for (size_t k = 1; k < off.size(); ++k)
      FLOESIM_REQUIRE(off[k] >= off[k - 1], file, ": ", name, " decreases at row ", k);
    FLOESIM_REQUIRE(static_cast<uint64_t>(off.back()) == rows, file, ": ", name, " ends at ", off.back(), ", but ", of,
                    " has ", rows, " rows");
  };
  if (with_states) check_offsets(r.frame_offset, r.state_body_id.size(), "/frames/offset", "/states/body_id");
  r.floe_id = read_ds<int32_t>(fid, "/geometry/floe_id", 1, file);
  r.floe_thickness_m = read_ds<double>(fid, "/geometry/floe_thickness_m", 1, file);
  r.floe_vertex_offset = read_ds<int64_t>(fid, "/geometry/floe_vertex_offset", 1, file);
  r.floe_vertices_m = read_ds<double>(fid, "/geometry/floe_vertices_m", 2, file);
  r.hull_vertices_m = read_ds<double>(fid, "/geometry/hull_vertices_m", 3, file);
  r.hull_triangles = read_ds<int32_t>(fid, "/geometry/hull_triangles", 3, file);
  FLOESIM_REQUIRE(r.floe_vertex_offset.size() == r.floe_id.size() + 1, file, ": floe vertex offsets disagree");
  FLOESIM_REQUIRE(r.floe_thickness_m.size() == r.floe_id.size(), file,
                  ": /geometry/floe_thickness_m and /geometry/floe_id have different lengths");
  // Level ice came with layout /5: an earlier file has none.
  r.floe_level_ice = version >= 5 ? read_ds<int8_t>(fid, "/geometry/floe_level_ice", 1, file)
                                  : std::vector<int8_t>(r.floe_id.size(), 0);
  FLOESIM_REQUIRE(r.floe_level_ice.size() == r.floe_id.size(), file,
                  ": /geometry/floe_level_ice and /geometry/floe_id have different lengths");
  check_offsets(r.floe_vertex_offset, r.floe_vertices_m.size() / 2, "/geometry/floe_vertex_offset",
                "/geometry/floe_vertices_m");
  const int64_t hull_vertices = static_cast<int64_t>(r.hull_vertices_m.size() / 3);
  for (int32_t t : r.hull_triangles)
    FLOESIM_REQUIRE(t >= 0 && t < hull_vertices, file, ": /geometry/hull_triangles names vertex ", t, ", but there are ",
                    hull_vertices);

  const size_t floes = r.floe_id.size();
  if (before_fracture) {
    // Nothing broke before fracture existed: every floe is an input floe that lasted, and every floe of the
    // geometry was a body for the whole run.
    r.floe_parent_id.assign(floes, -1);
    r.floe_generation.assign(floes, 0);
    r.floe_origin_mode.assign(floes, kFractureNone);
    r.floe_created_s.assign(floes, 0.0);
    r.floe_ended_s.assign(floes, std::numeric_limits<double>::infinity());
  }
  for (const auto& f : series_fields())
    if (f.since > version && wanted(f)) r.series[f.name] = missing_series(f, n, floes);
  if (before_fracture) return r;
  for_each_fracture_dataset(r, [&](const char* name, auto& v, size_t cols, Rows) {
    v = read_ds<typename std::decay_t<decltype(v)>::value_type>(fid, name, cols, file);
  });
  const std::string fracture = fracture_problem(r);
  FLOESIM_REQUIRE(fracture.empty(), file, ": ", fracture, " (a damaged file, or not written by floesim-simulate?)");
  // The structures beside the vessel (layout /9).
  if (version >= 9 && r.attributes.contains("structures")) {
    const nlohmann::json& list = r.attributes["structures"];
    FLOESIM_REQUIRE(list.is_array(), file, ": the attribute's \"structures\" is not a list");
    for (const nlohmann::json& st : list) {
      FLOESIM_REQUIRE(st.is_object() && st.contains("name") && st["name"].is_string() && st.contains("columns") &&
                          st["columns"].is_object(),
                      file, ": a structure of the attribute's \"structures\" has no name or columns");
      const std::string name = st["name"].get<std::string>(), g = "/structures/" + name;
      for (const auto& [field, cols] : st["columns"].items()) {
        FLOESIM_REQUIRE(cols.is_number_unsigned() && cols.get<size_t>() > 0, file, ": ", g, "/", field,
                        ": bad column count");
        std::vector<double> v = read_ds<double>(fid, g + "/" + field, cols.get<size_t>(), file);
        FLOESIM_REQUIRE(r.series_first_step != 0 || v.size() == n * cols.get<size_t>(), file, ": ", g, "/", field,
                        " has ", v.size() / cols.get<size_t>(), " rows, the series ", n);
        r.structure_series[name + "/" + field] = std::move(v);
      }
      r.structure_hull_vertices_m[name] = read_ds<double>(fid, g + "/hull_vertices_m", 3, file);
      r.structure_hull_triangles[name] = read_ds<int32_t>(fid, g + "/hull_triangles", 3, file);
      const int64_t nv = static_cast<int64_t>(r.structure_hull_vertices_m[name].size() / 3);
      for (int32_t t : r.structure_hull_triangles[name])
        FLOESIM_REQUIRE(t >= 0 && t < nv, file, ": ", g, "/hull_triangles names vertex ", t, ", but there are ", nv);
    }
  }
  return r;
}

FrameReplay::FrameReplay(const Results& r, const std::string& source) : r_(r) {
  slot_of_.push_back({0, 0});
  ended_s_.push_back(std::numeric_limits<double>::infinity());
  for (size_t g = 0; g < r.floe_id.size(); ++g) {
    slot_of_.push_back({r.floe_id[g], static_cast<int32_t>(g + 1)});
    ended_s_.push_back(g < r.floe_ended_s.size() ? r.floe_ended_s[g] : std::numeric_limits<double>::infinity());
  }
  std::sort(slot_of_.begin(), slot_of_.end());
  for (size_t i = 1; i < slot_of_.size(); ++i)
    FLOESIM_REQUIRE(slot_of_[i].first != slot_of_[i - 1].first, source, ": body id ", slot_of_[i].first,
                    slot_of_[i].first == 0 ? " (the vessel's)" : "", " appears twice in /geometry/floe_id");
  FLOESIM_REQUIRE(r.frame_offset.size() == r.frames() + 1 && r.frame_offset.front() == 0 &&
                      static_cast<size_t>(r.frame_offset.back()) == r.state_body_id.size(),
                  source, ": /frames/offset does not match /states");
  // Offsets all checked first: a later one that decreases would let an earlier frame's rows run past /states.
  for (size_t k = 0; k < r.frames(); ++k)
    FLOESIM_REQUIRE(r.frame_offset[k] <= r.frame_offset[k + 1], source, ": /frames/offset decreases at frame ", k);
  for (size_t k = 0; k < r.frames(); ++k) {
    bool vessel = false;
    for (int64_t row = r.frame_offset[k]; row < r.frame_offset[k + 1]; ++row) {
      const int32_t id = r.state_body_id[static_cast<size_t>(row)];
      vessel = vessel || id == 0;
      const auto it = std::lower_bound(slot_of_.begin(), slot_of_.end(), std::make_pair(id, INT32_MIN));
      FLOESIM_REQUIRE(it != slot_of_.end() && it->first == id, source, ": frame ", k, " has a state for body ", id,
                      ", which has no floe geometry in /geometry/floe_id");
    }
    FLOESIM_REQUIRE(vessel, source, ": frame ", k, " (t = ", r.frame_time_s[k], " s) has no vessel state (body_id 0)");
  }
  slot_row_.assign(slot_of_.size(), -1);
}

void FrameReplay::seek(size_t frame) {
  FLOESIM_REQUIRE(frame < r_.frames(), "internal: frame ", frame, " of ", r_.frames());
  if (static_cast<long>(frame) < frame_) {
    std::fill(slot_row_.begin(), slot_row_.end(), -1);
    frame_ = -1;
  }
  for (size_t k = static_cast<size_t>(frame_ + 1); k <= frame; ++k)
    for (int64_t row = r_.frame_offset[k]; row < r_.frame_offset[k + 1]; ++row) {
      const int32_t id = r_.state_body_id[static_cast<size_t>(row)];
      const auto it = std::lower_bound(slot_of_.begin(), slot_of_.end(), std::make_pair(id, INT32_MIN));
      slot_row_[static_cast<size_t>(it->second)] = row;
    }
  frame_ = static_cast<long>(frame);
  // A floe that broke up is replaced by its pieces from the step it broke in (ended_s is that step's end).
  const double t = r_.frame_time_s[frame];
  rows_.clear();
  floes_.clear();
  for (size_t s = 0; s < slot_row_.size(); ++s) {
    if (slot_row_[s] < 0) continue;
    if (ended_s_[s] <= t) {
      slot_row_[s] = -1;
      continue;
    }
    rows_.push_back(slot_row_[s]);
    floes_.push_back(static_cast<int32_t>(s) - 1);
  }
}

}  // namespace floesim
