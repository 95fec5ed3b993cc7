// Internal to sim/vessel, not part of the library's interface: the helpers that more than one of the hull's files
// uses. generate.cpp (the parametric icebreaker), import.cpp (loading and placing a CAD mesh) and hull.cpp
// (hydrostatics and the sidecar helpers both writers use, defined there) include it; a helper that one file alone
// uses stays in that file's anonymous namespace.
#pragma once
#include <cstdio>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/geometry/mesh.h"
#include "sim/vessel/hull.h"

namespace floesim::sim::detail {

inline std::string fmt_num(double v, int prec = 6) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", prec, v);
  return buf;
}

// The parts as one mesh (indices offset), in order.
TriMesh merge(const std::vector<TriMesh>& parts);

struct Bounds {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  explicit Bounds(const std::vector<Vec3>& v) {
    for (const Vec3& p : v) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  double diagonal() const { return (hi - lo).norm(); }
  bool contains(const Vec3& p, double pad) const {
    return (p.array() >= lo.array() - pad).all() && (p.array() <= hi.array() + pad).all();
  }
};

// The hydrostatics block of a hull sidecar (generated and imported hulls alike).
nlohmann::json hydrostatics_json(const Hydrostatics& h, double rho_w);

// The mesh's part of a generated hull's sidecar: parts, vertices, triangles, extent_m and the hydrostatics.
nlohmann::json generated_mesh_json(const std::vector<TriMesh>& parts, const Hydrostatics& h, double rho_w);

// Writes a generated hull: out_obj (parts, with `header` as comments) and its sidecar (out_obj with extension
// .json), each atomically; returns the sidecar's path. Error if out_obj itself ends in .json.
std::filesystem::path write_generated_files(const std::vector<TriMesh>& parts, const std::filesystem::path& out_obj,
                                            const std::string& header, const nlohmann::json& side);

// The particulars the ice-resistance formulas take, measured from `surface`, into the sidecar and the summary. A hull
// whose bow cannot be measured (a catamaran has no stem on its centreline) is still written: the sidecar then holds
// "particulars": null and the reason, which floesim-resistance reports.
void add_particulars(const TriMesh& surface, const std::string& where, nlohmann::json& side, std::ostream& sum);

}  // namespace floesim::sim::detail
