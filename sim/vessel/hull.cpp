// Hydrostatics of a hull made of convex parts, and the helpers both hull writers (generate.cpp, import.cpp) share:
// merging parts into one mesh, the sidecar's hydrostatics block and its particulars.
#include "sim/vessel/hull.h"

#include <limits>
#include <ostream>

#include <Eigen/Geometry>

#include "pipeline/error.h"
#include "sim/vessel/hull_internal.h"
#include "sim/vessel/particulars.h"

namespace floesim::sim {

using namespace detail;

namespace {

// True if p is inside the convex mesh by more than `margin` (all its triangle planes at least `margin` above p).
bool strictly_inside_convex(const TriMesh& m, const Vec3& p, double margin) {
  for (const auto& t : m.triangles) {
    const Vec3& a = m.vertices[t[0]];
    const Vec3 n = (m.vertices[t[1]] - a).cross(m.vertices[t[2]] - a);
    const double len = n.norm();
    if (len == 0) continue;
    if (n.dot(p - a) / len > -margin) return false;
  }
  return true;
}

}  // namespace

// ---- hydrostatics ------------------------------------------------------------------------------------------------

Hydrostatics hydrostatics(const std::vector<TriMesh>& parts, double rho_w, double z0) {
  Hydrostatics h;
  const TriMesh surface = merge(parts);
  FLOESIM_REQUIRE(!surface.triangles.empty(), "hydrostatics: the hull has no triangles");
  // Faces shared by two parts cancel in the signed sums (opposite orientations), so clipping the merged surface
  // gives the union's displaced volume and waterplane as long as the parts do not overlap.
  const Submerged s = submerged_part(surface.vertices, surface.triangles, z0);
  const Bounds all(surface.vertices);
  h.volume_m3 = s.volume;
  h.displacement_t = rho_w * s.volume / 1000.0;
  h.waterplane_area_m2 = s.waterplane_area;
  h.centre_of_buoyancy = s.centroid;
  h.lcb_m = s.centroid.x();
  h.kb_m = s.centroid.z() - all.lo.z();
  h.draught_m = z0 - all.lo.z();

  // Waterplane extents from the points where edges cross z0.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k) {
      const Vec3 &a = surface.vertices[t[k]], &b = surface.vertices[t[(k + 1) % 3]];
      if ((a.z() - z0) * (b.z() - z0) > 0 || a.z() == b.z()) continue;
      const Vec3 p = a + (b - a) * ((z0 - a.z()) / (b.z() - a.z()));
      lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    }
  if (lo.x() <= hi.x()) {
    h.length_wl_m = hi.x() - lo.x();
    h.beam_wl_m = hi.y() - lo.y();
  }
  if (h.length_wl_m > 0 && h.beam_wl_m > 0 && h.draught_m > 0)
    h.block_coefficient = h.volume_m3 / (h.length_wl_m * h.beam_wl_m * h.draught_m);

  // Wetted surface: area of each part's triangles below z0, except where material lies on both sides (a face
  // shared with a neighbouring part): tested by nudging the clipped piece's centroid outwards and asking whether
  // it is inside another part.
  const double nudge = 1e-6 * all.diagonal();
  std::vector<Bounds> boxes;
  for (const TriMesh& p : parts) boxes.emplace_back(p.vertices);
  for (size_t a = 0; a < parts.size(); ++a) {
    const TriMesh& pa = parts[a];
    for (const auto& t : pa.triangles) {
      const Vec3* v[3] = {&pa.vertices[t[0]], &pa.vertices[t[1]], &pa.vertices[t[2]]};
      std::vector<Vec3> poly;  // the triangle clipped to z < z0
      for (int k = 0; k < 3; ++k) {
        const Vec3 &p = *v[k], &q = *v[(k + 1) % 3];
        const bool in_p = p.z() < z0, in_q = q.z() < z0;
        if (in_p) poly.push_back(p);
        if (in_p != in_q) poly.push_back(p + (q - p) * ((z0 - p.z()) / (q.z() - p.z())));
      }
      if (poly.size() < 3) continue;
      Vec3 area_vec = Vec3::Zero(), c = Vec3::Zero();
      double area = 0;
      for (size_t k = 1; k + 1 < poly.size(); ++k) {
        const Vec3 cr = (poly[k] - poly[0]).cross(poly[k + 1] - poly[0]);
        area_vec += cr;
        area += 0.5 * cr.norm();
        c += 0.5 * cr.norm() * (poly[0] + poly[k] + poly[k + 1]) / 3.0;
      }
      if (area <= 0) continue;
      const Vec3 probe = c / area + nudge * area_vec.normalized();
      bool shared = false;
      for (size_t b = 0; b < parts.size() && !shared; ++b)
        shared = b != a && boxes[b].contains(probe, nudge) && strictly_inside_convex(parts[b], probe, 0.25 * nudge);
      if (!shared) h.wetted_surface_m2 += area;
    }
  }
  return h;
}

namespace detail {

TriMesh merge(const std::vector<TriMesh>& parts) {
  TriMesh m;
  for (const TriMesh& p : parts) {
    const int off = static_cast<int>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), p.vertices.begin(), p.vertices.end());
    for (const auto& t : p.triangles) m.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
  }
  return m;
}

// The hydrostatics block of a hull sidecar (generated and imported hulls alike).
nlohmann::json hydrostatics_json(const Hydrostatics& h, double rho_w) {
  return {{"rho_w_kg_m3", rho_w},
          {"volume_m3", h.volume_m3},
          {"displacement_t", h.displacement_t},
          {"waterplane_area_m2", h.waterplane_area_m2},
          {"lcb_m", h.lcb_m},
          {"kb_m", h.kb_m},
          {"wetted_surface_m2", h.wetted_surface_m2},
          {"length_wl_m", h.length_wl_m},
          {"beam_wl_m", h.beam_wl_m},
          {"draught_m", h.draught_m},
          {"block_coefficient", h.block_coefficient},
          {"centre_of_buoyancy_m", {h.centre_of_buoyancy.x(), h.centre_of_buoyancy.y(), h.centre_of_buoyancy.z()}}};
}

// The particulars the ice-resistance formulas take, measured from `surface`, into the sidecar and the summary. A hull
// whose bow cannot be measured (a catamaran has no stem on its centreline) is still written: the sidecar then holds
// "particulars": null and the reason, which floesim-resistance reports.
void add_particulars(const TriMesh& surface, const std::string& where, nlohmann::json& side, std::ostream& sum) {
  try {
    const HullParticulars p = measure_particulars(surface, where);
    side["particulars"] = particulars_json(p);
    sum << "  ice particulars      L " << fmt_num(p.length_m) << " m, B " << fmt_num(p.beam_m) << " m, T "
        << fmt_num(p.draught_m) << " m; stem angle phi " << fmt_num(p.stem_angle_deg, 4) << " deg, entrance angle alpha "
        << fmt_num(p.entrance_angle_deg, 4) << " deg (at B/4), normal flare psi " << fmt_num(p.normal_flare_deg, 4)
        << " deg; phi at B/4 " << fmt_num(p.bow_angle_b4_deg, 4) << " deg; parallel midbody "
        << fmt_num(p.parallel_midbody_m, 4) << " m, bow length " << fmt_num(p.bow_length_m, 4) << " m\n";
  } catch (const Error& e) {
    side["particulars"] = nullptr;
    side["particulars_error"] = e.what();
    sum << "  ice particulars      not measured: " << e.what() << "\n";
  }
}

}  // namespace detail

}  // namespace floesim::sim
