#include "pipeline/results_io.h"

#include <hdf5.h>

#include <algorithm>
#include <cstring>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"

namespace floesim {

const std::vector<FieldSpec>& series_fields() {
  static const std::vector<FieldSpec> k = {
      {"time_s", 1, "s", "simulation time at the end of the step"},
      {"vessel_position_m", 3, "m", "vessel centre of mass, world frame"},
      {"vessel_quaternion_wxyz", 4, "-", "vessel attitude, body to world"},
      {"vessel_velocity_mps", 3, "m/s", "vessel velocity, body axes (surge, sway, heave)"},
      {"vessel_angular_velocity_radps", 3, "rad/s", "vessel angular velocity, body axes (roll, pitch, yaw rate)"},
      {"ice_load", 6, "N, N m", "total ice contact load on the vessel, body axes (Fx Fy Fz Mx My Mz)"},
      {"ice_load_rigid", 6, "N, N m", "part of ice_load from rigid contacts"},
      {"ice_load_compliant", 6, "N, N m", "part of ice_load from compliant (crushing) contacts"},
      {"hydro_load", 6, "N, N m", "hydrostatic + hydrodynamic load on the vessel (buoyancy, drag, resistance), body axes"},
      {"wind_load", 6, "N, N m", "wind load on the vessel, body axes"},
      {"propulsion_load", 6, "N, N m", "propulsion load on the vessel, body axes"},
      {"contact_count", 1, "-", "contacts in the step (all bodies)"},
      {"vessel_contact_count", 1, "-", "contacts on the vessel"},
      {"solver_iterations", 1, "-", "contact solver sweeps in the step"},
      {"solver_residual", 1, "m/s", "largest velocity change of the last sweep"},
      {"awake_floes", 1, "-", "floes integrated this step (others sleep)"},
  };
  return k;
}

const FieldSpec& series_field(const std::string& name) {
  for (const auto& f : series_fields())
    if (name == f.name) return f;
  throw Error("unknown results series '" + name + "'");
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
hid_t h5type<int32_t>() { return H5T_NATIVE_INT32; }
template <>
hid_t h5type<int64_t>() { return H5T_NATIVE_INT64; }

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
  FLOESIM_REQUIRE(ds.id >= 0, file, ": cannot create dataset ", name);
  if (!data.empty())
    FLOESIM_REQUIRE(H5Dwrite(ds, h5type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) >= 0, file,
                    ": cannot write dataset ", name, " (disk full?)");
}

template <class T>
std::vector<T> read_ds(hid_t file_id, const std::string& name, size_t cols, const std::string& file) {
  FLOESIM_REQUIRE(H5Lexists(file_id, name.c_str(), H5P_DEFAULT) > 0, file, ": dataset ", name,
                  " is missing (not a floesim results file, or written by another version?)");
  H5Id ds(H5Dopen2(file_id, name.c_str(), H5P_DEFAULT), H5Dclose);
  FLOESIM_REQUIRE(ds.id >= 0, file, ": cannot open dataset ", name);
  H5Id space(H5Dget_space(ds), H5Sclose);
  int rank = H5Sget_simple_extent_ndims(space);
  hsize_t dims[2] = {0, 1};
  H5Sget_simple_extent_dims(space, dims, nullptr);
  const size_t got_cols = rank == 2 ? dims[1] : 1;
  FLOESIM_REQUIRE(got_cols == cols, file, ": dataset ", name, " has ", got_cols, " columns, expected ", cols);
  std::vector<T> v(dims[0] * got_cols);
  if (!v.empty())
    FLOESIM_REQUIRE(H5Dread(ds, h5type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) >= 0, file,
                    ": cannot read dataset ", name, " (truncated file?)");
  return v;
}

}  // namespace

void write_results(const std::filesystem::path& path, const Results& r) {
  const std::string file = path.string();
  const size_t n = r.steps();
  for (const auto& f : series_fields()) {
    auto it = r.series.find(f.name);
    FLOESIM_REQUIRE(it != r.series.end(), file, ": internal: series ", f.name, " was not recorded");
    FLOESIM_REQUIRE(it->second.size() == n * f.cols, file, ": internal: series ", f.name, " has ",
                    it->second.size(), " values, expected ", n, " x ", f.cols);
  }
  FLOESIM_REQUIRE(r.frame_offset.size() == r.frame_time_s.size() + 1, file, ": internal: frame offsets");
  FLOESIM_REQUIRE(r.state_position_m.size() == 3 * r.state_body_id.size() &&
                      r.state_quaternion.size() == 4 * r.state_body_id.size(),
                  file, ": internal: state arrays disagree");
  FLOESIM_REQUIRE(r.floe_vertex_offset.size() == r.floe_id.size() + 1, file, ": internal: floe vertex offsets");

  AtomicFile out(path);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by us, with context
  {
    // H5F_LIBVER_LATEST would embed nothing time-dependent either, but the default keeps files readable by
    // older tools; object modification times are off so that identical runs give identical bytes.
    H5Id fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
    H5Pset_obj_track_times(fcpl, false);
    H5Id fid(H5Fcreate(out.tmp().c_str(), H5F_ACC_TRUNC, fcpl, H5P_DEFAULT), H5Fclose);
    FLOESIM_REQUIRE(fid.id >= 0, file, ": cannot create (is the directory writable?)");
    H5Id gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
    H5Pset_obj_track_times(gcpl, false);
    for (const char* g : {"/series", "/frames", "/states", "/geometry"}) {
      H5Id gid(H5Gcreate2(fid, g, H5P_DEFAULT, gcpl, H5P_DEFAULT), H5Gclose);
    }
    for (const auto& f : series_fields())
      write_ds(fid, std::string("/series/") + f.name, r.series.at(f.name), f.cols, file);
    write_ds(fid, "/frames/time_s", r.frame_time_s, 1, file);
    write_ds(fid, "/frames/offset", r.frame_offset, 1, file);
    write_ds(fid, "/states/body_id", r.state_body_id, 1, file);
    write_ds(fid, "/states/position_m", r.state_position_m, 3, file);
    write_ds(fid, "/states/quaternion_wxyz", r.state_quaternion, 4, file);
    write_ds(fid, "/geometry/floe_id", r.floe_id, 1, file);
    write_ds(fid, "/geometry/floe_thickness_m", r.floe_thickness_m, 1, file);
    write_ds(fid, "/geometry/floe_vertex_offset", r.floe_vertex_offset, 1, file);
    write_ds(fid, "/geometry/floe_vertices_m", r.floe_vertices_m, 2, file);
    write_ds(fid, "/geometry/hull_vertices_m", r.hull_vertices_m, 3, file);
    write_ds(fid, "/geometry/hull_triangles", r.hull_triangles, 3, file);

    nlohmann::json attrs = r.attributes;
    attrs["layout"] = "floesim-results/1";
    const std::string text = attrs.dump();
    H5Id st(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(st, text.size() + 1);
    H5Id sp(H5Screate(H5S_SCALAR), H5Sclose);
    H5Id at(H5Acreate2(fid, "floesim", st, sp, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    FLOESIM_REQUIRE(H5Awrite(at, st, text.c_str()) >= 0, file, ": cannot write the attributes");
    FLOESIM_REQUIRE(H5Fflush(fid, H5F_SCOPE_GLOBAL) >= 0, file, ": flush failed (disk full?)");
  }
  out.commit();
}

Results read_results(const std::filesystem::path& path, bool with_states) {
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
    std::string text(H5Tget_size(st), '\0');
    H5Id mt(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mt, text.size());
    FLOESIM_REQUIRE(H5Aread(at, mt, text.data()) >= 0, file, ": cannot read the attributes");
    text.resize(std::strlen(text.c_str()));
    r.attributes = nlohmann::json::parse(text, nullptr, false);
    FLOESIM_REQUIRE(!r.attributes.is_discarded(), file, ": the 'floesim' attribute is not JSON");
    FLOESIM_REQUIRE(r.attributes.value("layout", "") == "floesim-results/1", file, ": layout ",
                    r.attributes.value("layout", "?"), " is not supported by this version");
  }
  for (const auto& f : series_fields()) r.series[f.name] = read_ds<double>(fid, std::string("/series/") + f.name, f.cols, file);
  const size_t n = r.steps();
  for (const auto& f : series_fields())
    FLOESIM_REQUIRE(r.series[f.name].size() == n * f.cols, file, ": series ", f.name, " has the wrong length");
  r.frame_time_s = read_ds<double>(fid, "/frames/time_s", 1, file);
  r.frame_offset = read_ds<int64_t>(fid, "/frames/offset", 1, file);
  FLOESIM_REQUIRE(r.frame_offset.size() == r.frame_time_s.size() + 1, file, ": /frames/offset has the wrong length");
  if (with_states) {
    r.state_body_id = read_ds<int32_t>(fid, "/states/body_id", 1, file);
    r.state_position_m = read_ds<double>(fid, "/states/position_m", 3, file);
    r.state_quaternion = read_ds<double>(fid, "/states/quaternion_wxyz", 4, file);
    FLOESIM_REQUIRE(r.state_position_m.size() == 3 * r.state_body_id.size() &&
                        static_cast<size_t>(r.frame_offset.back()) == r.state_body_id.size(),
                    file, ": /states arrays disagree with /frames/offset");
  }
  r.floe_id = read_ds<int32_t>(fid, "/geometry/floe_id", 1, file);
  r.floe_thickness_m = read_ds<double>(fid, "/geometry/floe_thickness_m", 1, file);
  r.floe_vertex_offset = read_ds<int64_t>(fid, "/geometry/floe_vertex_offset", 1, file);
  r.floe_vertices_m = read_ds<double>(fid, "/geometry/floe_vertices_m", 2, file);
  r.hull_vertices_m = read_ds<double>(fid, "/geometry/hull_vertices_m", 3, file);
  r.hull_triangles = read_ds<int32_t>(fid, "/geometry/hull_triangles", 3, file);
  FLOESIM_REQUIRE(r.floe_vertex_offset.size() == r.floe_id.size() + 1, file, ": floe vertex offsets disagree");
  return r;
}

}  // namespace floesim
