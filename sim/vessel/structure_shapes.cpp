// A structure's hull from parameters (generate_structure, write_generated_structure): cylinder, caisson, cone.
#include <cmath>
#include <sstream>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/geometry2d.h"
#include "pipeline/provenance.h"
#include "sim/vessel/hull.h"
#include "sim/vessel/hull_internal.h"

namespace floesim::sim {

namespace fs = std::filesystem;
using namespace detail;

namespace {

// A frustum between two horizontal regular polygons circumscribing circles of radius r0 at z0 and r1 at z1 (z0 < z1):
// each side face is tangent to the round frustum at its middle, so its slope is the round one's exactly and the
// width across flats is the diameter. Convex for any radii. The first face faces +x (the ice's side).
TriMesh frustum(double r0, double z0, double r1, double z1, int sides) {
  const double to_corner = 1 / std::cos(kPi / sides);
  std::vector<Vec3> pts;
  for (int k = 0; k < sides; ++k) {
    const double t = 2 * kPi * (k + 0.5) / sides;
    pts.emplace_back(r0 * to_corner * std::cos(t), r0 * to_corner * std::sin(t), z0);
    pts.emplace_back(r1 * to_corner * std::cos(t), r1 * to_corner * std::sin(t), z1);
  }
  return convex_hull(pts);
}

TriMesh box(double lx, double ly, double z0, double z1) {
  std::vector<Vec3> pts;
  for (double x : {-lx / 2, lx / 2})
    for (double y : {-ly / 2, ly / 2})
      for (double z : {z0, z1}) pts.emplace_back(x, y, z);
  return convex_hull(pts);
}

// The height of a cone's neck above (upward) or below (downward) the waterline: (w - w_T) / 2 x tan alpha.
double neck_offset_m(const StructureShapeOptions& o) {
  return 0.5 * (o.waterline_width_m - o.neck_width_m) * std::tan(o.slope_deg * kPi / 180);
}

}  // namespace

std::vector<TriMesh> generate_structure(const StructureShapeOptions& o) {
  check_options(o, "structure shape options");
  const double w = o.waterline_width_m, zb = -o.depth_m, zt = o.height_m;
  if (o.shape == "cylinder") return {frustum(w / 2, zb, w / 2, zt, o.sides)};
  if (o.shape == "caisson") return {box(o.length_m > 0 ? o.length_m : w, w, zb, zt)};
  // The cone: the radius changes by dz / tan(alpha) per metre of height, the waterline radius w / 2.
  const double cot = 1 / std::tan(o.slope_deg * kPi / 180), neck = neck_offset_m(o), rn = o.neck_width_m / 2;
  if (o.breaking == "upward") {
    FLOESIM_REQUIRE(neck < zt, "structure: the cone reaches its neck ", neck,
                    " m above the waterline, beyond its top at height_m = ", zt,
                    " m: raise height_m or widen neck_width_m");
    std::vector<TriMesh> parts = {frustum(w / 2 + o.depth_m * cot, zb, rn, neck, o.sides)};
    parts.push_back(frustum(rn, neck, rn, zt, o.sides));
    return parts;
  }
  FLOESIM_REQUIRE(neck < o.depth_m, "structure: the cone reaches its neck ", neck, " m below the waterline, beyond its "
                  "bottom at depth_m = ", o.depth_m, " m: raise depth_m or widen neck_width_m");
  std::vector<TriMesh> parts = {frustum(rn, zb, rn, -neck, o.sides)};
  parts.push_back(frustum(rn, -neck, w / 2 + o.height_m * cot, zt, o.sides));
  return parts;
}

std::string write_generated_structure(const StructureShapeOptions& o, const fs::path& out_obj,
                                      const fs::path& config_file) {
  const std::vector<TriMesh> parts = generate_structure(o);
  constexpr double rho_w = 1025.0;
  const Hydrostatics h = hydrostatics(parts, rho_w, 0.0);
  std::ostringstream shape;
  shape << o.shape;
  if (o.shape == "cone")
    shape << " (" << o.breaking << "-breaking), waterline diameter " << o.waterline_width_m << " m, neck "
          << o.neck_width_m << " m " << fmt_num(neck_offset_m(o)) << " m "
          << (o.breaking == "upward" ? "above" : "below") << " the waterline, slope " << o.slope_deg << " deg";
  else if (o.shape == "cylinder")
    shape << ", diameter " << o.waterline_width_m << " m";
  else
    shape << ", " << (o.length_m > 0 ? o.length_m : o.waterline_width_m) << " m x " << o.waterline_width_m << " m";
  shape << ", from " << -o.depth_m << " m to " << o.height_m << " m";

  std::ostringstream head;
  head << "floesim structure: " << shape.str() << "; " << parts.size() << " convex parts\n"
       << "written by floesim-hull " << version() << "; frame: x the way the ice comes from, y to port, z up, "
       << "metres; calm waterline z = 0; origin on the axis at the waterline\n";
  nlohmann::json side;
  const std::vector<NamedInput> inputs =
      config_file.empty() ? std::vector<NamedInput>{} : std::vector<NamedInput>{{"config", config_file}};
  side["provenance"] = make_provenance("floesim-hull", inputs, options_to_json(o));
  side["hull_file"] = out_obj.filename().string();
  side["frame"] = "z up; calm waterline z = 0; origin on the structure's axis at the waterline; metres";
  side.update(generated_mesh_json(parts, h, rho_w));
  side["structure"] = {{"shape", o.shape}, {"description", shape.str()}};
  if (o.shape == "cone") side["structure"]["neck_offset_m"] = neck_offset_m(o);
  // The ship's particulars (stem, entrance angle, ...) do not apply: floesim-resistance says so if given this file.
  side["particulars"] = nullptr;
  side["particulars_error"] = "a structure (" + o.shape + "), not a ship: its ice loads are floesim-ice-actions'";

  const fs::path sidecar = write_generated_files(parts, out_obj, head.str(), side);

  std::ostringstream sum;
  sum << "structure: " << shape.str() << "\n  " << parts.size() << " convex parts, " << side["vertices"].get<size_t>()
      << " vertices, " << side["triangles"].get<size_t>()
      << " triangles -> " << out_obj.string() << " (+ " << sidecar.filename().string() << ")\n"
      << "  volume below z = 0   " << fmt_num(h.volume_m3) << " m^3\n"
      << "  waterplane area      " << fmt_num(h.waterplane_area_m2) << " m^2\n";
  return sum.str();
}

}  // namespace floesim::sim
