#include "pipeline/vtk_series.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"

namespace floesim {

namespace fs = std::filesystem;

namespace {

// The appended block of a VTK XML file: each array a UInt64 byte count and its bytes; `offset` where it starts.
struct Appended {
  std::string bytes;
  template <class T>
  size_t add(const std::vector<T>& v) {
    const size_t offset = bytes.size();
    const uint64_t n = v.size() * sizeof(T);
    bytes.append(reinterpret_cast<const char*>(&n), sizeof n);
    if (n) bytes.append(reinterpret_cast<const char*>(v.data()), n);
    return offset;
  }
};

// `tuples` > 0: a field-data array, which must say how many tuples it holds.
std::string array(const char* type, const char* name, int components, size_t offset, size_t tuples = 0) {
  return std::string("<DataArray type=\"") + type + "\" Name=\"" + name + "\" NumberOfComponents=\"" +
         std::to_string(components) + "\"" + (tuples ? " NumberOfTuples=\"" + std::to_string(tuples) + "\"" : "") +
         " format=\"appended\" offset=\"" + std::to_string(offset) + "\"/>\n";
}

// The value of a series at the step that ends at time t (the frame's), or NaN.
double at_time(const Results& r, const std::vector<double>& series, int cols, int col, double t) {
  const std::vector<double>& time = r.get("time_s");
  const auto it = std::lower_bound(time.begin(), time.end(), t - 1e-9);
  if (it == time.end() || std::abs(*it - t) > 1e-9) return std::nan("");
  return series[static_cast<size_t>(it - time.begin()) * cols + col];
}

// One frame's PolyData file.
std::string frame_file(const Results& r, const FrameReplay& replay, size_t k) {
  std::vector<float> points;
  std::vector<int32_t> connectivity, offsets, body_id, kind;
  std::vector<int8_t> in_contact;
  std::vector<double> centre;
  auto pose = [&](int64_t row) {
    const double* q = &r.state_quaternion[4 * static_cast<size_t>(row)];
    const double* p = &r.state_position_m[3 * static_cast<size_t>(row)];
    return std::make_pair(Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized(), Eigen::Vector3d(p[0], p[1], p[2]));
  };
  // A cell's data; its points follow, then end_cell() (VTK's offsets are each cell's end in the connectivity).
  auto cell = [&](int64_t row, int32_t k_kind) {
    body_id.push_back(r.state_body_id[static_cast<size_t>(row)]);
    kind.push_back(k_kind);
    in_contact.push_back(r.state_in_contact[static_cast<size_t>(row)]);
    for (int c = 0; c < 3; ++c) centre.push_back(r.state_position_m[3 * static_cast<size_t>(row) + c]);
  };
  auto end_cell = [&] { offsets.push_back(static_cast<int32_t>(connectivity.size())); };
  auto add_point = [&](const Eigen::Vector3d& x) {
    for (int c = 0; c < 3; ++c) points.push_back(static_cast<float>(x[c]));
  };
  auto point = [&](const Eigen::Vector3d& x) {  // a point of the cell being written, its own
    connectivity.push_back(static_cast<int32_t>(points.size() / 3));
    add_point(x);
  };
  for (size_t i = 0; i < replay.rows().size(); ++i) {
    const int64_t row = replay.rows()[i];
    const int32_t g = replay.floes()[i];
    const auto [q, p] = pose(row);
    if (g < 0) {  // the hull: its triangles
      for (size_t t = 0; t + 2 < r.hull_triangles.size(); t += 3) {
        cell(row, 3);
        for (int c = 0; c < 3; ++c) {
          const double* v = &r.hull_vertices_m[3 * static_cast<size_t>(r.hull_triangles[t + c])];
          point(q * Eigen::Vector3d(v[0], v[1], v[2]) + p);
        }
        end_cell();
      }
      continue;
    }
    const size_t gi = static_cast<size_t>(g);
    const int32_t floe_kind = r.floe_level_ice[gi] ? 1 : (r.floe_parent_id[gi] >= 0 ? 2 : 0);
    // A prism of the floe's thickness on 2 n shared points (top ring, then bottom ring): its top face, its bottom
    // face (turned to face down), a quad per side of its outline.
    const double half = r.floe_thickness_m[gi] / 2;
    const int64_t v0 = r.floe_vertex_offset[gi], n = r.floe_vertex_offset[gi + 1] - v0;
    const auto first = static_cast<int32_t>(points.size() / 3);
    for (double z : {half, -half})
      for (int64_t v = v0; v < v0 + n; ++v)
        add_point(q * Eigen::Vector3d(r.floe_vertices_m[2 * v], r.floe_vertices_m[2 * v + 1], z) + p);
    const auto top = [&](int64_t i) { return first + static_cast<int32_t>(i % n); };
    const auto bottom = [&](int64_t i) { return first + static_cast<int32_t>(n + i % n); };
    cell(row, floe_kind);
    for (int64_t i = 0; i < n; ++i) connectivity.push_back(top(i));
    end_cell();
    cell(row, floe_kind);
    for (int64_t i = n - 1; i >= 0; --i) connectivity.push_back(bottom(i));
    end_cell();
    for (int64_t i = 0; i < n; ++i) {
      cell(row, floe_kind);
      for (int32_t c : {bottom(i), bottom(i + 1), top(i + 1), top(i)}) connectivity.push_back(c);
      end_cell();
    }
  }
  const double t = r.frame_time_s[k];
  const std::vector<double> time_value{t};
  const std::vector<double> load{at_time(r, r.get("ice_load"), 6, 0, t)};
  Appended a;
  const size_t o_time = a.add(time_value), o_load = a.add(load), o_points = a.add(points),
               o_conn = a.add(connectivity), o_off = a.add(offsets), o_id = a.add(body_id), o_kind = a.add(kind),
               o_contact = a.add(in_contact), o_centre = a.add(centre);
  std::string x =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n<PolyData>\n<FieldData>\n" +
      array("Float64", "TimeValue", 1, o_time, 1) + array("Float64", "surge_ice_load_n", 1, o_load, 1) +
      "</FieldData>\n<Piece NumberOfPoints=\"" + std::to_string(points.size() / 3) +
      "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" +
      std::to_string(offsets.size()) + "\">\n<Points>\n" + array("Float32", "Points", 3, o_points) +
      "</Points>\n<Polys>\n" + array("Int32", "connectivity", 1, o_conn) + array("Int32", "offsets", 1, o_off) +
      "</Polys>\n<CellData Scalars=\"kind\">\n" + array("Int32", "body_id", 1, o_id) + array("Int32", "kind", 1, o_kind) +
      array("Int8", "in_contact", 1, o_contact) + array("Float64", "centre_m", 3, o_centre) +
      "</CellData>\n</Piece>\n</PolyData>\n<AppendedData encoding=\"raw\">\n_";
  x += a.bytes;
  x += "\n</AppendedData>\n</VTKFile>\n";
  return x;
}

}  // namespace

size_t write_vtk_series(const Results& r, const fs::path& dir, const std::string& source) {
  FLOESIM_REQUIRE(r.frames() > 0, source, ": no frames to write for ParaView");
  FrameReplay replay(r, source);
  fs::path tmp = dir;
  tmp += ".tmp";
  std::error_code ec;
  fs::remove_all(tmp, ec);
  ensure_directory(tmp);
  std::string pvd =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "<Collection>\n";
  size_t bytes = 0;
  for (size_t k = 0; k < r.frames(); ++k) {
    replay.seek(k);
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05zu.vtp", k);
    const std::string text = frame_file(r, replay, k);
    write_file_checked(tmp / name, text, dir / name);
    bytes += text.size();
    char t[40];
    std::snprintf(t, sizeof t, "%.17g", r.frame_time_s[k]);
    pvd += std::string("<DataSet timestep=\"") + t + "\" part=\"0\" file=\"" + name + "\"/>\n";
  }
  pvd += "</Collection>\n</VTKFile>\n";
  write_file_checked(tmp / "results.pvd", pvd, dir / "results.pvd");
  fs::remove_all(dir, ec);
  fs::rename(tmp, dir, ec);
  FLOESIM_REQUIRE(!ec, dir.string(), ": cannot move the ParaView series into place: ", ec.message());
  return bytes + pvd.size();
}

}  // namespace floesim
