// The results HDF5 reader's own logic (pipeline/results_io.h read_results): a valid results file (HDF5 container
// written by write_results) whose datasets and attribute the fuzz input replaces, removes or reshapes through the
// HDF5 API: ranks, shapes, element types, values, offsets, lineage, the fracture table, the 'floesim' attribute
// (scalar or array, fixed or variable length, any text). libhdf5's parsing of damaged bytes is fuzz_results_raw's.
#include <fuzzer/FuzzedDataProvider.h>
#include <hdf5.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "small_results.h"
#include "pipeline/results_io.h"

namespace {

std::vector<std::string> dataset_names() {
  std::vector<std::string> n;
  for (const auto& f : floesim::series_fields()) n.push_back(std::string("/series/") + f.name);
  for (const char* s :
       {"/frames/time_s", "/frames/offset", "/states/body_id", "/states/position_m", "/states/quaternion_wxyz",
        "/geometry/floe_id", "/geometry/floe_thickness_m", "/geometry/floe_vertex_offset",
        "/geometry/floe_vertices_m", "/geometry/hull_vertices_m", "/geometry/hull_triangles",
        "/geometry/floe_parent_id", "/geometry/floe_generation", "/geometry/floe_origin_mode",
        "/geometry/floe_created_s", "/geometry/floe_ended_s", "/fracture/time_s", "/fracture/parent_id",
        "/fracture/mode", "/fracture/at_structure", "/fracture/force_n", "/fracture/threshold_n",
        "/fracture/point_m", "/fracture/width_m", "/fracture/theta_rad", "/fracture/brash_mass_kg",
        "/fracture/child_offset", "/fracture/child_id"})
    n.push_back(s);
  return n;
}

// One replaced dataset: rank 0..3, small dimensions, an element type, values from the input.
void replace_dataset(hid_t f, const std::string& name, FuzzedDataProvider& in) {
  H5Ldelete(f, name.c_str(), H5P_DEFAULT);
  if (in.ConsumeBool() && in.ConsumeBool()) return;  // removed
  const int rank = in.ConsumeIntegralInRange(0, 3);
  hsize_t dims[3] = {1, 1, 1};
  size_t count = 1;
  for (int k = 0; k < rank; ++k) count *= (dims[k] = in.ConsumeIntegralInRange<hsize_t>(0, 8));
  const hid_t types[] = {H5T_NATIVE_DOUBLE, H5T_NATIVE_INT32, H5T_NATIVE_INT64, H5T_NATIVE_FLOAT, H5T_NATIVE_UINT8};
  const int t = in.ConsumeIntegralInRange(0, 4);
  const hid_t sp = rank == 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(rank, dims, nullptr);
  const hid_t ds = H5Dcreate2(f, name.c_str(), types[t], sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (ds >= 0 && count > 0) {
    std::vector<uint8_t> bytes = in.ConsumeBytes<uint8_t>(count * H5Tget_size(types[t]));
    bytes.resize(count * H5Tget_size(types[t]));
    // Offsets and ids are more interesting when small: an int64 "pick" of a few values.
    if (t == 2 && in.ConsumeBool())
      for (size_t k = 0; k < count; ++k) {
        const int64_t v = in.ConsumeIntegralInRange<int64_t>(-2, 10);
        std::memcpy(bytes.data() + 8 * k, &v, 8);
      }
    H5Dwrite(ds, types[t], H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data());
  }
  if (ds >= 0) H5Dclose(ds);
  H5Sclose(sp);
}

void replace_attribute(hid_t f, FuzzedDataProvider& in) {
  H5Adelete(f, "floesim");
  std::string text = in.ConsumeRandomLengthString(512);
  if (in.ConsumeBool()) text = R"({"layout": "floesim-results/)" + std::to_string(in.ConsumeIntegralInRange(0, 4)) +
                               "\", " + text;
  const int kind = in.ConsumeIntegralInRange(0, 3);
  const hid_t st = H5Tcopy(H5T_C_S1);
  if (kind == 3) {
    H5Tset_size(st, H5T_VARIABLE);
    const hid_t sp = H5Screate(H5S_SCALAR);
    const hid_t at = H5Acreate2(f, "floesim", st, sp, H5P_DEFAULT, H5P_DEFAULT);
    const char* p = text.c_str();
    if (at >= 0) H5Awrite(at, st, &p), H5Aclose(at);
    H5Sclose(sp);
  } else {
    const hsize_t n = kind == 2 ? 3 : 1;
    H5Tset_size(st, text.size() + (kind == 1 ? 0 : 1));  // kind 1: no room for the terminating zero
    const hid_t sp = kind == 2 ? H5Screate_simple(1, &n, nullptr) : H5Screate(H5S_SCALAR);
    std::vector<char> buf(n * (text.size() + 1), '\0');
    for (hsize_t k = 0; k < n; ++k) std::memcpy(buf.data() + k * H5Tget_size(st), text.data(), text.size());
    const hid_t at = H5Acreate2(f, "floesim", st, sp, H5P_DEFAULT, H5P_DEFAULT);
    if (at >= 0) H5Awrite(at, st, buf.data()), H5Aclose(at);
    H5Sclose(sp);
  }
  H5Tclose(st);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const auto base = floesim::fuzz::temp_file(".base.h5");
  static const auto file = floesim::fuzz::temp_file(".h5");
  static const std::vector<std::string> names = dataset_names();
  static const bool written = (floesim::write_results(base, floesim::fuzz::small_results()), true);
  (void)written;
  std::filesystem::copy_file(base, file, std::filesystem::copy_options::overwrite_existing);
  FuzzedDataProvider in(data, size);
  {
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    if (f < 0) std::abort();
    const int edits = in.ConsumeIntegralInRange(1, 6);
    for (int e = 0; e < edits && in.remaining_bytes() > 0; ++e) {
      if (in.ConsumeIntegralInRange(0, 7) == 0)
        replace_attribute(f, in);
      else
        replace_dataset(f, names[in.ConsumeIntegralInRange<size_t>(0, names.size() - 1)], in);
    }
    H5Fclose(f);
  }
  floesim::fuzz::expect_ok_or_error([&] {
    const floesim::Results r = floesim::read_results(file);
    // What an accepted file promises its readers (render, plot, shipdata): the offsets index inside their arrays.
    const size_t R = r.state_body_id.size();
    for (size_t k = 0; k + 1 < r.frame_offset.size(); ++k)
      if (r.frame_offset[k] < 0 || r.frame_offset[k] > r.frame_offset[k + 1] || size_t(r.frame_offset[k + 1]) > R)
        std::abort();
    for (size_t k = 0; k + 1 < r.floe_vertex_offset.size(); ++k)
      if (r.floe_vertex_offset[k] < 0 || r.floe_vertex_offset[k] > r.floe_vertex_offset[k + 1] ||
          size_t(r.floe_vertex_offset[k + 1]) > r.floe_vertices_m.size() / 2)
        std::abort();
    if (r.state_quaternion.size() != 4 * R || r.state_in_contact.size() != R ||
        r.floe_thickness_m.size() != r.floe_id.size())
      std::abort();
    for (const auto& f : floesim::series_fields())
      if (r.get(f.name).size() != r.steps() * f.cols) std::abort();
    // The frames replayed (layout /7 stores the changed bodies; the render and the summaries replay them): either
    // refused with an Error or every frame's rows inside /states, the vessel first.
    floesim::FrameReplay walk(r, file);
    for (size_t k = 0; k < r.frames(); ++k) {
      walk.seek(k);
      if (walk.rows().empty() || r.state_body_id[size_t(walk.vessel_row())] != 0) std::abort();
      for (int64_t row : walk.rows())
        if (row < 0 || size_t(row) >= R) std::abort();
    }
    if (r.frames() > 1) walk.seek(0);  // backwards: replays from the start
  });
  if (H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL) != 0) {
    std::fprintf(stderr, "read_results left HDF5 ids open\n");
    std::abort();
  }
  return 0;
}
