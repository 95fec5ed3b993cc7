#include "sim/engine/model.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <sstream>
#include <Eigen/Eigenvalues>

#include "pipeline/error.h"
#include "sim/engine/forces.h"
#include "sim/geometry/polygon3d.h"
#include "pipeline/geometry2d.h"

namespace floesim::sim {

namespace {


// Buoyancy of a body-frame mesh placed at (position, orientation): submerged volume and centre of buoyancy.
Submerged submerged_at(const TriMesh& mesh, const Vec3& position, const Quat& orientation) {
  std::vector<Vec3> w(mesh.vertices.size());
  const Mat3 R = orientation.toRotationMatrix();
  for (size_t i = 0; i < w.size(); ++i) w[i] = position + R * mesh.vertices[i];
  return submerged_part(w, mesh.triangles, 0.0);
}

// Hydrostatic restoring stiffness about the body axis `axis` (body frame) at the given pose, by central
// differences of the buoyancy moment about the centre of mass (gravity acts at the centre of mass: no moment).
double rotational_stiffness(const TriMesh& mesh, const Vec3& position, const Quat& orientation, const Vec3& axis,
                            double rho_g) {
  const double eps = 1e-3;
  const Vec3 world_axis = orientation * axis;
  double m[2];
  for (int s = 0; s < 2; ++s) {
    const double a = s == 0 ? eps : -eps;
    const Quat q = (orientation * Quat(Eigen::AngleAxisd(a, axis))).normalized();
    const Submerged sub = submerged_at(mesh, position, q);
    const Vec3 f(0, 0, rho_g * sub.volume);
    m[s] = sub.volume > 0 ? (sub.centroid - position).cross(f).dot(world_axis) : 0.0;
  }
  return -(m[0] - m[1]) / (2 * eps);
}

// Fills the linear damping coefficients of a body floating at its initial pose.
void set_damping(Body& b, const EngineSettings& o, double zeta_heave, double zeta_roll, double zeta_pitch) {
  const double rho_g = o.water.density_kg_m3 * o.water.gravity_mps2;
  const Submerged sub = submerged_at(b.buoyancy_mesh, b.initial_position, b.initial_orientation);
  const double c33 = rho_g * sub.waterplane_area;
  const double c44 = std::max(0.0, rotational_stiffness(b.buoyancy_mesh, b.initial_position, b.initial_orientation,
                                                        Vec3::UnitX(), rho_g));
  const double c55 = std::max(0.0, rotational_stiffness(b.buoyancy_mesh, b.initial_position, b.initial_orientation,
                                                        Vec3::UnitY(), rho_g));
  // Critical damping of the mass-spring system that moves: the heave added mass is part of its mass.
  b.heave_damping = 2 * zeta_heave * std::sqrt(c33 * (b.mass_kg + b.added_mass.z()));
  b.roll_damping = 2 * zeta_roll * std::sqrt(c44 * (b.inertia(0, 0) + b.added_inertia.x()));
  b.pitch_damping = 2 * zeta_pitch * std::sqrt(c55 * (b.inertia(1, 1) + b.added_inertia.y()));
}

// The radiation filter's corner frequency as a fraction of the heave natural frequency. The real retardation kernel
// of a floating disc lasts about one natural period; w_c = w_n/2 forgets a steady push in 1/w_c = T_n/pi (0.7-2.1 s
// for 1-40 m floes 1 m thick), while the filter's reactive part, an extra mass G w_c/(w_n^2 + w_c^2) =
// 2 zeta r (m + A33) at w_n (r = w_c/w_n, zeta the radiation damping ratio), stays at zeta (m + A33). A lower corner
// would keep that mass smaller but damp a steady push for longer.
constexpr double kRadiationCornerRatio = 0.5;

// Floe heave radiation damping (water.floe_heave_damping "radiation"): the floating disc of the floe's area (a =
// sqrt(A/pi)) at its floating draft T = m/(rho_w A), its B33 at the heave natural frequency w_n = sqrt(C33/(m +
// A33)) (disc_heave_radiation_damping), and the filter gain G = B33 (1 + r^2) that gives B33 there through the
// high-pass G w^2/(w^2 + w_c^2).
void set_heave_radiation(Body& b, const EngineSettings& o) {
  const double rho = o.water.density_kg_m3, g = o.water.gravity_mps2, area = b.section_area;
  if (!(g > 0) || !(area > 0)) return;
  const double omega_n = std::sqrt(rho * g * area / (b.mass_kg + b.added_mass.z()));
  const double b33 = disc_heave_radiation_damping(rho, g, std::sqrt(area / kPi), b.mass_kg / (rho * area), omega_n);
  b.heave_radiation_corner_radps = kRadiationCornerRatio * omega_n;
  b.heave_radiation_gain = b33 * (1 + kRadiationCornerRatio * kRadiationCornerRatio);
}

struct Aabb2 {
  Vec2 lo, hi;
  bool overlaps(const Aabb2& o) const {
    return lo.x() <= o.hi.x() && o.lo.x() <= hi.x() && lo.y() <= o.hi.y() && o.lo.y() <= hi.y();
  }
};
Aabb2 bounds(const Polygon& p) {
  Aabb2 b{p[0], p[0]};
  for (const Vec2& v : p) {
    b.lo = b.lo.cwiseMin(v);
    b.hi = b.hi.cwiseMax(v);
  }
  return b;
}

// A floe during building: world outline, convex pieces (world) and their boxes.
struct FloeGeometry {
  const Floe* floe = nullptr;
  Polygon outline;              // cleaned, CCW, world
  std::vector<Polygon> pieces;  // convex, world
  std::vector<Aabb2> piece_box;
  Aabb2 box;
  double area = 0;
};

// The level ice of a model as fixed floes (issue #10): each sheet (the options' rectangle, the floes file's features
// of kind "level_ice") cut into tiles by a grid centred on the sheet (level_ice.tile_m) whose lines also run
// along every opening's sides, so that each grid cell lies wholly inside or outside an opening (a cell is dropped
// when its centre is in one; a boolean difference would leave holes). Ids follow the floes file's largest id.
// Deterministic: sheets in order, cells row by row, the pieces of a cell as polygon_intersection orders them.
std::vector<Floe> level_ice_tiles(const FloeField& field, const LevelIceOptions& li) {
  struct Sheet {
    Polygon outline;
    double thickness_m;  // <= 0: from the options' profile at each tile's centre
    std::string name;
  };
  std::vector<Sheet> sheets;
  int next_id = 1;
  for (const Floe& f : field.floes) {
    next_id = std::max(next_id, f.id + 1);
    if (f.level_ice) sheets.push_back({f.outline, f.thickness_m, "level ice sheet, floe id " + std::to_string(f.id)});
  }
  if (!li.extent_m.empty()) {
    const std::vector<double>& e = li.extent_m;
    sheets.push_back({{Vec2(e[0], e[1]), Vec2(e[2], e[1]), Vec2(e[2], e[3]), Vec2(e[0], e[3])}, 0.0,
                      "level_ice.extent_m"});
  }
  std::vector<Floe> tiles;
  const double t = li.tile_m;
  for (const Sheet& sh : sheets) {
    const Aabb2 box = bounds(sh.outline);
    // Each tile is a body: a sheet of more tiles than a large field has floes is a mistake of units or of tile_m
    // (and a grid of billions of lines would never finish).
    constexpr double kMaxTiles = 1e6;
    const double nx = std::ceil((box.hi.x() - box.lo.x()) / t) + 1, ny = std::ceil((box.hi.y() - box.lo.y()) / t) + 1;
    FLOESIM_REQUIRE(nx * ny <= kMaxTiles, sh.name, ": a sheet of ", box.hi.x() - box.lo.x(), " m x ",
                    box.hi.y() - box.lo.y(), " m makes ", nx * ny, " tiles of level_ice.tile_m = ", t,
                    " m, more than ", kMaxTiles, "; enlarge level_ice.tile_m or give a smaller sheet");
    // Grid lines: tile_m apart, centred on the sheet's box (a vessel on the sheet's centre line meets the middle of
    // a tile, not a crack-stopping side), plus the openings' sides inside it.
    auto lines = [&](double lo, double hi, int axis) {
      std::vector<double> v;
      const double mid = 0.5 * (lo + hi) - 0.5 * t;
      for (double k = std::floor((lo - mid) / t); mid + k * t < hi; k += 1) v.push_back(std::max(lo, mid + k * t));
      v.push_back(hi);
      for (const LevelIceOpening& op : li.openings)
        for (double c : {op.rect_m[axis], op.rect_m[axis + 2]})
          if (c > lo && c < hi) v.push_back(c);
      std::sort(v.begin(), v.end());
      v.erase(std::unique(v.begin(), v.end()), v.end());
      return v;
    };
    const std::vector<double> xs = lines(box.lo.x(), box.hi.x(), 0), ys = lines(box.lo.y(), box.hi.y(), 1);
    for (size_t j = 0; j + 1 < ys.size(); ++j)
      for (size_t i = 0; i + 1 < xs.size(); ++i) {
        const Vec2 lo(xs[i], ys[j]), hi(xs[i + 1], ys[j + 1]), mid = 0.5 * (lo + hi);
        bool open = false;
        for (const LevelIceOpening& op : li.openings)
          open = open || (mid.x() > op.rect_m[0] && mid.x() < op.rect_m[2] && mid.y() > op.rect_m[1] &&
                          mid.y() < op.rect_m[3]);
        if (open) continue;
        const Polygon cell = {lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())};
        std::vector<Polygon> pieces;
        try {
          pieces = polygon_intersection(sh.outline, cell);
        } catch (const Error& e) {
          throw Error(sh.name + ": cannot cut the sheet into tiles at [" + std::to_string(lo.x()) + ", " +
                      std::to_string(lo.y()) + "] (" + e.what() + "); change level_ice.tile_m");
        }
        for (Polygon& p : pieces) {
          Floe f;
          f.id = next_id++;
          f.outline = std::move(p);
          f.area_m2 = signed_area(f.outline);
          f.thickness_m = sh.thickness_m > 0 ? sh.thickness_m : li.thickness_at(centroid(f.outline).x());
          f.level_ice = true;
          tiles.push_back(std::move(f));
        }
      }
  }
  return tiles;
}

double overlap_area(const FloeGeometry& a, const FloeGeometry& b) {
  double area = 0;
  for (size_t i = 0; i < a.pieces.size(); ++i)
    for (size_t j = 0; j < b.pieces.size(); ++j)
      if (a.piece_box[i].overlaps(b.piece_box[j])) area += convex_intersection_area(a.pieces[i], b.pieces[j]);
  return area;
}

// Section of a convex mesh between two horizontal planes, projected on the xy plane (convex).
Polygon band_footprint(const std::vector<Vec3>& v, const std::vector<std::array<int, 3>>& tris, double zlo,
                       double zhi) {
  std::vector<Vec2> pts;
  for (const Vec3& p : v)
    if (p.z() >= zlo && p.z() <= zhi) pts.emplace_back(p.x(), p.y());
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e) {
      const Vec3& a = v[t[e]];
      const Vec3& b = v[t[(e + 1) % 3]];
      for (double z : {zlo, zhi})
        if ((a.z() - z) * (b.z() - z) < 0) {
          const Vec3 p = a + (z - a.z()) / (b.z() - a.z()) * (b - a);
          pts.emplace_back(p.x(), p.y());
        }
    }
  return pts.size() >= 3 ? convex_hull_2d(pts) : Polygon{};
}

// Length, beam, draught and strip stations at the waterline z = 0 of a mesh already placed in its floating position (hull frame + sinkage).
void waterline_particulars(const TriMesh& m, VesselParticulars& p) {
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300, zmin = 1e300;
  double lx0 = 1e300, lx1 = -1e300;
  for (const Vec3& v : m.vertices) {
    xmin = std::min(xmin, v.x());
    xmax = std::max(xmax, v.x());
    zmin = std::min(zmin, v.z());
  }
  for (const auto& t : m.triangles) {
    const Vec3 tri[3] = {m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]};
    for (int e = 0; e < 3; ++e) {
      const Vec3& a = tri[e];
      const Vec3& b = tri[(e + 1) % 3];
      if ((a.z() <= 0) != (b.z() <= 0)) {
        const Vec3 q = a + (0 - a.z()) / (b.z() - a.z()) * (b - a);
        lx0 = std::min(lx0, q.x());
        lx1 = std::max(lx1, q.x());
        ymin = std::min(ymin, q.y());
        ymax = std::max(ymax, q.y());
      }
    }
  }
  FLOESIM_REQUIRE(lx1 > lx0 && ymax > ymin, "hull: the mesh does not cross the waterline z = 0 (is the hull frame's "
                  "waterline at z = 0, z up?)");
  p.length_oa_m = xmax - xmin;
  p.length_wl_m = lx1 - lx0;
  p.beam_wl_m = ymax - ymin;
  p.draught_m = -zmin;
  p.strip_x_m.clear();
  p.strip_beam_m.clear();
  const int strips = 20;
  p.strip_length_m = p.length_wl_m / strips;
  for (int i = 0; i < strips; ++i) p.strip_x_m.push_back(lx0 + (i + 0.5) * p.strip_length_m);
  // Waterline beam at each station: the y extent of the waterline segments (where the triangles cross z = 0) that
  // span the station's x.
  std::vector<double> ylo(strips, 1e300), yhi(strips, -1e300);
  for (const auto& t : m.triangles) {
    Vec3 q[2];
    int nq = 0;
    for (int e = 0; e < 3 && nq < 2; ++e) {
      const Vec3& a = m.vertices[t[e]];
      const Vec3& b = m.vertices[t[(e + 1) % 3]];
      if ((a.z() <= 0) != (b.z() <= 0)) q[nq++] = a + (0 - a.z()) / (b.z() - a.z()) * (b - a);
    }
    if (nq < 2) continue;
    for (int i = 0; i < strips; ++i) {
      const double x = p.strip_x_m[i];
      if ((q[0].x() - x) * (q[1].x() - x) > 0 || q[0].x() == q[1].x()) continue;
      const double y = q[0].y() + (x - q[0].x()) / (q[1].x() - q[0].x()) * (q[1].y() - q[0].y());
      ylo[i] = std::min(ylo[i], y);
      yhi[i] = std::max(yhi[i], y);
    }
  }
  for (int i = 0; i < strips; ++i) p.strip_beam_m.push_back(yhi[i] > ylo[i] ? yhi[i] - ylo[i] : 0.0);
}

TriMesh shifted(const TriMesh& m, const Vec3& d) {
  TriMesh r = m;
  for (Vec3& v : r.vertices) v += d;
  return r;
}

// The inverses of the mass matrix with the added mass (translational per body axis, rotational as a tensor).
void set_added_mass(Body& b, const Vec3& added_mass, const Vec3& added_inertia) {
  b.added_mass = added_mass;
  b.added_inertia = added_inertia;
  for (int i = 0; i < 3; ++i) b.inv_mass_added[i] = 1 / (b.mass_kg + added_mass[i]);
  Mat3 I = b.inertia;
  I.diagonal() += added_inertia;
  b.inv_inertia_added = I.inverse();
}

}  // namespace

double perimeter_m(const Polygon& outline) {
  double perimeter = 0;
  for (size_t i = 0; i < outline.size(); ++i) perimeter += (outline[(i + 1) % outline.size()] - outline[i]).norm();
  return perimeter;
}

bool is_brash(const Polygon& outline, double thickness_m, double min_area_m2) {
  const double area = signed_area(outline);
  return area < min_area_m2 || 4 * area / perimeter_m(outline) < thickness_m;  // plan width 4 A / perimeter
}

void hold_fixed(Body& b) {
  b.fixed = true;
  b.brash = false;
  b.inv_mass = 0;
  b.inv_inertia = Mat3::Zero();
  b.inv_mass_added = Vec3::Zero();
  b.inv_inertia_added = Mat3::Zero();
}

Body make_floe_body(const Polygon& outline, double h, int id, int body_index, const Vec2& centre,
                    const EngineSettings& o, std::vector<ConvexPart>& parts) {
  FLOESIM_REQUIRE(outline.size() >= 3 && signed_area(outline) > 0, "floe ", id,
                  ": internal: a floe body needs a CCW outline of positive area");
  const double rho_i = o.ice.density_kg_m3, draught_ratio = rho_i / o.water.density_kg_m3;
  Body b;
  b.kind = BodyKind::floe;
  b.id = id;
  b.thickness_m = h;
  b.brash = o.fracture.brash == "rigid" && is_brash(outline, h, o.fracture.min_piece_area_m2);
  if (b.brash)  // p_c h x the plan width 4 A / perimeter
    b.brash_crush_force_n = o.ice.crushing_strength_pa * h * 4 * signed_area(outline) / perimeter_m(outline);
  b.outline = outline;
  b.buoyancy_mesh = extrude_polygon(b.outline, -h / 2, h);
  // Second moments of the section (Green's theorem over the CCW outline, which is centred on its centroid).
  for (size_t i = 0; i < b.outline.size(); ++i) {
    const Vec2& p = b.outline[i];
    const Vec2& q = b.outline[(i + 1) % b.outline.size()];
    const double cr = p.x() * q.y() - q.x() * p.y();
    b.section_area += cr / 2;
    b.section_sxx += cr * (p.x() * p.x() + p.x() * q.x() + q.x() * q.x()) / 12;
    b.section_syy += cr * (p.y() * p.y() + p.y() * q.y() + q.y() * q.y()) / 12;
    b.section_sxy += cr * (p.x() * q.y() + 2 * p.x() * p.y() + 2 * q.x() * q.y() + q.x() * p.y()) / 24;
    b.section_radius = std::max(b.section_radius, p.norm());
  }
  const MassProperties mp = mass_properties(b.buoyancy_mesh);
  FLOESIM_REQUIRE(mp.volume > 0, "floe ", id, ": internal: non-positive slab volume");
  b.mass_kg = rho_i * mp.volume;
  b.inv_mass = 1 / b.mass_kg;
  b.inertia = rho_i * mp.inertia;
  if (b.brash) {
    // A block is at least as hard to turn as a cube of side h (m h^2 / 6 about any axis): a needle cut beside an
    // earlier crack would otherwise spin up on the smallest impulse (its inertia about z goes as its width^2).
    Eigen::SelfAdjointEigenSolver<Mat3> eig(b.inertia);
    const Vec3 l = eig.eigenvalues().cwiseMax(b.mass_kg * h * h / 6);
    b.inertia = eig.eigenvectors() * l.asDiagonal() * eig.eigenvectors().transpose();
  }
  b.inv_inertia = b.inertia.inverse();
  // Added mass of the floating thin plate (PHYSICS.md §3.3), only with water: heave along the floe's normal (body z),
  // roll and pitch about the body x and y axes; surge, sway and yaw none (a thin plate moving in its own plane).
  // High-frequency limit (phi = 0 on the free surface): half of the plate's added mass in unbounded fluid, where a
  // disc of radius a has (8/3) rho a^3 broadside and (16/45) rho a^5 about a diameter (Lamb 1932, Hydrodynamics
  // §108; Newman 1977, Marine Hydrodynamics, §4.13). A floe is the disc of its area A (a = sqrt(A/pi)): heave
  // (4/3) rho_w a^3 = (4/(3 pi)) rho_w a A, which grows with D/h against the floe's mass (2.4 x for D = 10 m,
  // h = 1 m); roll and pitch (8/45) rho_w a^5 scaled by the floe's second moment of area about the axis over the
  // disc's pi a^4 / 4, i.e. (32/(45 pi)) rho_w a S_yy (roll) and S_xx (pitch): exact for a disc, longer floes get
  // more about their short axis. The product moment S_xy is left out (diagonal added inertia in body axes).
  if (o.water.enabled) {
    const double rho_w = o.water.density_kg_m3, s = o.water.floe_added_mass_scale;
    const double a = std::sqrt(b.section_area / kPi);
    const double c_rot = s * 32 / (45 * kPi) * rho_w * a;
    set_added_mass(b, Vec3(0, 0, s * 4 / (3 * kPi) * rho_w * a * b.section_area),
                   Vec3(c_rot * b.section_syy, c_rot * b.section_sxx, 0));
  } else {
    set_added_mass(b, Vec3::Zero(), Vec3::Zero());
  }
  b.initial_position = Vec3(centre.x(), centre.y(), h / 2 - draught_ratio * h);
  b.initial_orientation = Quat::Identity();
  const std::vector<Polygon> pieces = convex_decompose(b.outline);
  b.first_part = static_cast<int>(parts.size());
  for (const Polygon& piece : pieces) parts.push_back(make_convex_part(extrude_polygon(piece, -h / 2, h), body_index));
  b.part_count = static_cast<int>(pieces.size());
  mark_shared_faces(parts, b.first_part, b.part_count);
  // Drag faces: vertices 0..n-1 the bottom ring, n..2n-1 the top ring.
  const int n = static_cast<int>(b.outline.size());
  for (int i = 0; i < n; ++i) b.drag_vertices.emplace_back(b.outline[i].x(), b.outline[i].y(), -h / 2);
  for (int i = 0; i < n; ++i) b.drag_vertices.emplace_back(b.outline[i].x(), b.outline[i].y(), h / 2);
  auto add_face = [&](std::vector<int> idx, const Vec3& nrm) {
    DragFace df;
    df.first = static_cast<int>(b.drag_face_index.size());
    df.count = static_cast<int>(idx.size());
    df.normal = nrm;
    std::vector<Vec3> pts;
    for (int i : idx) pts.push_back(b.drag_vertices[i]);
    const AreaCentroid ac = polygon_area_centroid(pts.data(), static_cast<int>(pts.size()));
    df.area = ac.area;
    df.centroid = ac.centroid;
    b.drag_face_index.insert(b.drag_face_index.end(), idx.begin(), idx.end());
    b.drag_faces.push_back(df);
  };
  std::vector<int> bottom, top;
  for (int i = n - 1; i >= 0; --i) bottom.push_back(i);  // clockwise seen from above = CCW from below
  for (int i = 0; i < n; ++i) top.push_back(n + i);
  add_face(bottom, -Vec3::UnitZ());
  b.top_face = static_cast<int>(b.drag_faces.size());
  add_face(top, Vec3::UnitZ());
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const Vec2 e = b.outline[j] - b.outline[i];
    const Vec3 nrm = Vec3(e.y(), -e.x(), 0).normalized();  // outward for a CCW ring
    add_face({i, j, n + j, n + i}, nrm);
    b.drag_faces.back().side = i;
  }
  if (o.water.enabled) {
    const bool radiation = o.water.floe_heave_damping == "radiation";
    set_damping(b, o, radiation ? 0.0 : o.water.floe_heave_damping_ratio, o.water.floe_roll_pitch_damping_ratio,
                o.water.floe_roll_pitch_damping_ratio);
    if (radiation) set_heave_radiation(b, o);
  }
  return b;
}

ConvexPart make_convex_part(const TriMesh& mesh, int body) {
  ConvexPart part;
  part.body = body;
  part.vertices = mesh.vertices;
  double scale = 0;
  for (const Vec3& v : mesh.vertices) scale = std::max(scale, v.norm());
  part.bounding_radius = scale;
  // Group triangles by plane (a convex mesh has one face per outward normal).
  std::vector<Vec3> normals;
  std::vector<double> offsets;
  std::vector<std::vector<int>> groups;
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3 n = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
    const double len = n.norm();
    if (len <= 1e-12 * std::max(1.0, scale * scale)) continue;  // degenerate sliver
    const Vec3 u = n / len;
    const double d = u.dot(a);
    size_t g = 0;
    for (; g < normals.size(); ++g)
      if (normals[g].dot(u) > 1 - 1e-7 && std::abs(offsets[g] - d) < 1e-6 * std::max(1.0, scale)) break;
    if (g == normals.size()) {
      normals.push_back(u);
      offsets.push_back(d);
      groups.emplace_back();
    }
    for (int k = 0; k < 3; ++k) groups[g].push_back(t[k]);
  }
  for (size_t g = 0; g < groups.size(); ++g) {
    std::vector<int> idx = groups[g];
    std::sort(idx.begin(), idx.end());
    idx.erase(std::unique(idx.begin(), idx.end()), idx.end());
    // Remove vertices at the same place (meshes with split vertices).
    std::vector<int> uniq;
    for (int i : idx) {
      bool dup = false;
      for (int j : uniq) dup = dup || (mesh.vertices[i] - mesh.vertices[j]).norm() < 1e-9 * std::max(1.0, scale);
      if (!dup) uniq.push_back(i);
    }
    if (uniq.size() < 3) continue;
    const Vec3 n = normals[g];
    Vec3 c = Vec3::Zero();
    for (int i : uniq) c += mesh.vertices[i];
    c /= static_cast<double>(uniq.size());
    const Vec3 u = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
    const Vec3 w = n.cross(u);
    std::vector<std::pair<double, int>> ang;
    for (int i : uniq) {
      const Vec3 d = mesh.vertices[i] - c;
      ang.emplace_back(std::atan2(d.dot(w), d.dot(u)), i);
    }
    std::sort(ang.begin(), ang.end());  // counter-clockwise about n (u x w = n)
    std::vector<int> face;
    for (auto& a : ang) face.push_back(a.second);
    part.faces.push_back(face);
    part.face_normal.push_back(n);
    part.face_internal.push_back(0);
  }
  FLOESIM_REQUIRE(part.faces.size() >= 4, "internal: convex part with fewer than 4 faces");
  return part;
}

void mark_shared_faces(std::vector<ConvexPart>& parts, int first, int count) {
  // Centroid of a face and whether a point of its plane lies inside it (convex, CCW about the normal).
  auto centre = [](const ConvexPart& p, int f) {
    Vec3 c = Vec3::Zero();
    for (int i : p.faces[f]) c += p.vertices[i];
    return Vec3(c / static_cast<double>(p.faces[f].size()));
  };
  auto inside = [](const ConvexPart& p, int f, const Vec3& x) {
    const auto& face = p.faces[f];
    const Vec3& n = p.face_normal[f];
    for (size_t i = 0; i < face.size(); ++i) {
      const Vec3& a = p.vertices[face[i]];
      const Vec3& b = p.vertices[face[(i + 1) % face.size()]];
      if ((b - a).cross(x - a).dot(n) < -1e-9) return false;
    }
    return true;
  };
  for (int i = first; i < first + count; ++i)
    for (int j = i + 1; j < first + count; ++j) {
      ConvexPart& P = parts[i];
      ConvexPart& Q = parts[j];
      const double tol = 1e-6 * std::max({1.0, P.bounding_radius, Q.bounding_radius});
      for (size_t f = 0; f < P.faces.size(); ++f)
        for (size_t g = 0; g < Q.faces.size(); ++g) {
          const Vec3& nf = P.face_normal[f];
          const Vec3& ng = Q.face_normal[g];
          if (nf.dot(ng) > -1 + 1e-7) continue;
          const double df = nf.dot(P.vertices[P.faces[f][0]]), dg = ng.dot(Q.vertices[Q.faces[g][0]]);
          if (std::abs(df + dg) > tol) continue;
          if (inside(Q, g, centre(P, f)) || inside(P, f, centre(Q, g))) P.face_internal[f] = Q.face_internal[g] = 1;
        }
    }
}

void read_thrust_series(const std::string& file, std::vector<double>& time_s, std::vector<double>& thrust_n) {
  std::ifstream in(file);
  FLOESIM_REQUIRE(in, file, ": cannot open the thrust series (vessel.propulsion.thrust_file)");
  time_s.clear();
  thrust_n.clear();
  std::string line;
  int lineno = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!header) {
      std::string h = line;
      h.erase(std::remove_if(h.begin(), h.end(), [](char c) { return c == ' ' || c == '\t'; }), h.end());
      FLOESIM_REQUIRE(h == "time_s,thrust_N", file, ":", lineno, ": expected the header 'time_s,thrust_N', got '",
                      line, "'");
      header = true;
      continue;
    }
    FLOESIM_REQUIRE(!line.empty(), file, ":", lineno, ": empty line (gaps are not allowed)");
    const size_t comma = line.find(',');
    FLOESIM_REQUIRE(comma != std::string::npos && line.find(',', comma + 1) == std::string::npos, file, ":", lineno,
                    ": expected two comma-separated numbers 'time_s,thrust_N', got '", line, "'");
    double v[2];
    const std::string cell[2] = {line.substr(0, comma), line.substr(comma + 1)};
    for (int k = 0; k < 2; ++k) {
      size_t used = 0;
      bool ok = true;
      try {
        v[k] = std::stod(cell[k], &used);
      } catch (const std::exception&) {
        ok = false;
      }
      if (ok)
        for (size_t i = used; i < cell[k].size(); ++i) ok = ok && (cell[k][i] == ' ' || cell[k][i] == '\t');
      FLOESIM_REQUIRE(ok && std::isfinite(v[k]), file, ":", lineno, ": column ", k == 0 ? "time_s" : "thrust_N",
                      " is not a finite number: '", cell[k], "'");
    }
    FLOESIM_REQUIRE(time_s.empty() || v[0] > time_s.back(), file, ":", lineno, ": time ", v[0],
                    " s is not after the previous time ", time_s.empty() ? 0.0 : time_s.back(),
                    " s (times must increase strictly)");
    time_s.push_back(v[0]);
    thrust_n.push_back(v[1]);
  }
  FLOESIM_REQUIRE(header, file, ": empty file (expected the header 'time_s,thrust_N' and rows)");
  FLOESIM_REQUIRE(!time_s.empty(), file, ": no data rows after the header");
}

Ittc57 ittc57_of(const VesselParticulars& v, const EngineSettings& o) { return ittc57_of(v, o.vessel, o); }

Ittc57 ittc57_of(const VesselParticulars& v, const VesselOptions& vo, const EngineSettings& o) {
  Ittc57 c;
  c.length_wl_m = v.length_wl_m;
  c.wetted_surface_m2 = v.wetted_surface_m2;
  c.form_factor_k = vo.form_factor_k;
  c.roughness_ca = vo.roughness_ca;
  c.water_density_kg_m3 = o.water.density_kg_m3;
  c.kinematic_viscosity_m2ps = o.water.kinematic_viscosity_m2ps;
  return c;
}

namespace {

// 1. A ridge's strips: each segment of its line swept keel_width_m across (the width of its consolidated layer).
std::vector<Polygon> ridge_strips(const RidgeOptions& r) {
  std::vector<Polygon> strips;
  for (size_t k = 1; k < r.line.size(); ++k) {
    const Vec2 a(r.line[k - 1].x_m, r.line[k - 1].y_m), b(r.line[k].x_m, r.line[k].y_m);
    const Vec2 t = (b - a).normalized(), n = 0.5 * r.keel_width_m * Vec2(-t.y(), t.x());
    strips.push_back({a - n, b - n, b + n, a + n});
  }
  return strips;
}

// 1. The ridges' consolidated layers (settings.ridges, issue #36) cut out of the level ice tiles: each tile is cut
// by every ridge's strips in order (ridge by ridge, segment by segment), what lies inside a strip a tile of that
// ridge's layer, consolidated_thickness_m thick, what is left cut by the next strip. The tiles are numbered again in
// that order from the first tile's id; `ridge_of` gets each tile's ridge (-1: the sheet). A ridge that no sheet
// reaches floats freely: its layer is a free floe per segment (the strip less the earlier strips), appended to
// `free_layers` (ids after the tiles') with its ridge in `free_ridge`. A strip the tiles cover only in part (beside
// the sheet's edge, over an opening) is an error naming the ridge and the segment. At a bend of a line the strips
// of its two segments overlap on the inside (the first takes the overlap) and leave a wedge uncut on the outside.
void cut_ridge_layers(const std::vector<RidgeOptions>& ridges, int next_id, std::vector<Floe>& tiles,
                      std::vector<int>& ridge_of, std::vector<Floe>& free_layers, std::vector<int>& free_ridge) {
  ridge_of.assign(tiles.size(), -1);
  if (ridges.empty()) return;
  struct Strip {
    Polygon outline;
    int ridge = 0, segment = 0;
    double expected_m2 = 0, cut_m2 = 0;  // its area less the earlier strips' overlap; what the tiles gave it
  };
  std::vector<Strip> strips;
  for (size_t i = 0; i < ridges.size(); ++i) {
    const std::vector<Polygon> own = ridge_strips(ridges[i]);
    for (size_t k = 0; k < own.size(); ++k) {
      Strip s{own[k], static_cast<int>(i), static_cast<int>(k)};
      s.expected_m2 = signed_area(s.outline);
      for (const Strip& e : strips) s.expected_m2 -= convex_intersection_area(s.outline, e.outline);
      strips.push_back(std::move(s));
    }
  }
  const int first_id = tiles.empty() ? 0 : tiles.front().id;
  std::vector<Floe> out;
  std::vector<int> out_ridge;
  for (const Floe& tile : tiles) {
    std::vector<Polygon> rest = {tile.outline};
    const Aabb2 box = bounds(tile.outline);
    for (Strip& s : strips) {
      if (!box.overlaps(bounds(s.outline))) continue;
      std::vector<Polygon> left;
      for (const Polygon& p : rest) {
        PolygonCut cut;
        try {
          cut = cut_polygon(p, s.outline);
        } catch (const Error& e) {
          throw Error("ridges[" + std::to_string(s.ridge) + "]: cannot cut segment " + std::to_string(s.segment) +
                      "'s consolidated layer out of the level ice tile at [" + std::to_string(box.lo.x()) + ", " +
                      std::to_string(box.lo.y()) + "] (" + e.what() +
                      "); a layer lying inside one tile would leave a hole: run the line across the sheet's tiles "
                      "or change level_ice.tile_m");
        }
        for (Polygon& q : cut.inside) {
          Floe f = tile;
          f.outline = std::move(q);
          f.area_m2 = signed_area(f.outline);
          f.thickness_m = ridges[s.ridge].consolidated_thickness_m;
          s.cut_m2 += f.area_m2;
          out.push_back(std::move(f));
          out_ridge.push_back(s.ridge);
        }
        for (Polygon& q : cut.outside) left.push_back(std::move(q));
      }
      rest = std::move(left);
    }
    for (Polygon& q : rest) {
      Floe f = tile;
      f.outline = std::move(q);
      f.area_m2 = signed_area(f.outline);
      out.push_back(std::move(f));
      out_ridge.push_back(-1);
    }
  }
  for (const Strip& s : strips)
    FLOESIM_REQUIRE(s.cut_m2 == 0 || s.cut_m2 >= s.expected_m2 * (1 - 1e-6), "ridges[", s.ridge,
                    "]: the consolidated layer along segment ", s.segment, " of its line (", s.expected_m2,
                    " m^2) lies on the level ice sheet over only ", s.cut_m2, " m^2: a ridge lies wholly in a sheet "
                    "(level_ice.extent_m or floes of kind \"level_ice\"), clear of its openings, or wholly off it; "
                    "move the line or enlarge the sheet");
  for (size_t k = 0; k < out.size(); ++k) out[k].id = first_id + static_cast<int>(k);
  if (!out.empty()) next_id = std::max(next_id, out.back().id + 1);
  for (size_t k = 0; k < strips.size(); ++k) {
    if (strips[k].cut_m2 > 0) continue;
    std::vector<Polygon> pieces = {strips[k].outline};
    for (size_t j = 0; j < k; ++j) {
      std::vector<Polygon> left;
      for (const Polygon& p : pieces)
        for (Polygon& q : polygon_difference(p, strips[j].outline)) left.push_back(std::move(q));
      pieces = std::move(left);
    }
    for (Polygon& q : pieces) {
      Floe f;
      f.id = next_id++;
      f.outline = std::move(q);
      f.area_m2 = signed_area(f.outline);
      f.thickness_m = ridges[strips[k].ridge].consolidated_thickness_m;
      free_layers.push_back(std::move(f));
      free_ridge.push_back(strips[k].ridge);
    }
  }
  tiles = std::move(out);
  ridge_of = std::move(out_ridge);
}

// 1. The floes of the model: the free floes of the field, the layers of the ridges no sheet reaches, then the level
// ice sheets as tiles (fixed floes), the ridges' consolidated layers cut out of them; `ridge_of` the ridge of each
// (-1: none).
std::vector<Floe> model_floes(const FloeField& field, const EngineSettings& o, std::vector<int>& ridge_of) {
  std::vector<Floe> floes;
  for (const Floe& f : field.floes)
    if (!f.level_ice) floes.push_back(f);
  std::vector<Floe> tiles = level_ice_tiles(field, o.level_ice), free_layers;
  std::vector<int> tile_ridge, free_ridge;
  int next_id = 1;
  for (const Floe& f : field.floes) next_id = std::max(next_id, f.id + 1);
  cut_ridge_layers(o.ridges, next_id, tiles, tile_ridge, free_layers, free_ridge);
  ridge_of.assign(floes.size(), -1);
  for (Floe& f : free_layers) floes.push_back(std::move(f));
  ridge_of.insert(ridge_of.end(), free_ridge.begin(), free_ridge.end());
  for (Floe& f : tiles) floes.push_back(std::move(f));
  ridge_of.insert(ridge_of.end(), tile_ridge.begin(), tile_ridge.end());
  return floes;
}

// 1. Floe geometry in the world: cleaned CCW outline, convex pieces and boxes; a floe without thickness, without
// area or whose outline intersects itself is an error. The results point into `floes`.
std::vector<FloeGeometry> floe_geometry(const std::vector<Floe>& floes) {
  std::vector<FloeGeometry> geo(floes.size());
  for (size_t k = 0; k < floes.size(); ++k) {
    const Floe& f = floes[k];
    FLOESIM_REQUIRE(std::isfinite(f.thickness_m) && f.thickness_m > 0, "floe ", f.id, ": thickness_m must be > 0, got ",
                    f.thickness_m);
    FloeGeometry& fg = geo[k];
    fg.floe = &f;
    fg.outline = clean_polygon(f.outline, 1e-9);
    make_ccw(fg.outline);
    FLOESIM_REQUIRE(fg.outline.size() >= 3 && signed_area(fg.outline) > 0, "floe ", f.id,
                    ": degenerate outline (zero area)");
    const auto si = find_self_intersection(fg.outline);
    FLOESIM_REQUIRE(si.first < 0, "floe ", f.id, ": the outline intersects itself (edges ", si.first, " and ",
                    si.second, ")");
    fg.area = signed_area(fg.outline);
    fg.pieces = convex_decompose(fg.outline);
    for (const Polygon& p : fg.pieces) fg.piece_box.push_back(bounds(p));
    fg.box = bounds(fg.outline);
  }
  return geo;
}

// 2. Floes must not overlap each other (sweep over x-sorted boxes; pairs reported by id): overlaps above
// ice.max_overlap_fraction of the smaller floe are an error; returns the number of smaller ones (digitisation noise).
int count_small_overlaps(const std::vector<FloeGeometry>& geo, const EngineSettings& o) {
  std::vector<size_t> order(geo.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return geo[a].box.lo.x() < geo[b].box.lo.x() || (geo[a].box.lo.x() == geo[b].box.lo.x() && a < b);
  });
  std::ostringstream bad;
  int nbad = 0, small = 0;
  for (size_t i = 0; i < order.size(); ++i) {
    const FloeGeometry& a = geo[order[i]];
    for (size_t j = i + 1; j < order.size(); ++j) {
      const FloeGeometry& b = geo[order[j]];
      if (b.box.lo.x() > a.box.hi.x()) break;
      if (!a.box.overlaps(b.box)) continue;
      const double area = overlap_area(a, b);
      if (area <= 1e-9) continue;
      const double smaller = std::min(a.area, b.area);
      if (area > o.ice.max_overlap_fraction * smaller) {
        if (nbad < 10)
          bad << "\n  - floes " << std::min(a.floe->id, b.floe->id) << " and " << std::max(a.floe->id, b.floe->id)
              << " overlap by " << area << " m^2 (" << 100 * area / smaller << " % of the smaller)";
        ++nbad;
      } else {
        ++small;
      }
    }
  }
  FLOESIM_REQUIRE(nbad == 0, "the floes file has ", nbad, " pair(s) of overlapping floes (above ",
                  100 * o.ice.max_overlap_fraction, " % of the smaller floe, ice.max_overlap_fraction):", bad.str(),
                  nbad > 10 ? "\n  - ..." : "", "\n  fix the digitisation, or raise ice.max_overlap_fraction");
  return small;
}

// How a hull body floats: its mass and the sinkage that carries it.
struct Flotation {
  double mass = 0;  // kg
  double dz = 0;    // the hull frame raised by dz, so that rho_w V_sub = mass (0 when the mass comes from the hull)
};

// 3. A hull body's mass (KEY.mass_kg, else the hull's displacement at z = 0) and the sinkage that floats it
// (bisection); a hull without volume below z = 0, or one that cannot carry the mass, is an error.
Flotation flotation(const TriMesh& surf, const VesselOptions& vo, const std::string& key, const EngineSettings& o) {
  const double rho_w = o.water.density_kg_m3;
  const double m0 = rho_w * submerged_part(surf.vertices, surf.triangles, 0.0).volume;
  FLOESIM_REQUIRE(m0 > 0, key, ": the hull has no volume below the waterline z = 0 (is z up and the waterline at "
                  "z = 0?)");
  const double mass = vo.mass_kg > 0 ? vo.mass_kg : m0;
  // Sinkage dz (hull frame raised by dz) so that rho_w V_sub = mass; 0 when the mass comes from the hull.
  double dz = 0;
  if (vo.mass_kg > 0) {
    double zmin = 1e300, zmax = -1e300;
    for (const Vec3& v : surf.vertices) {
      zmin = std::min(zmin, v.z());
      zmax = std::max(zmax, v.z());
    }
    double lo = -zmax, hi = -zmin;  // raised by -zmax: fully submerged; by -zmin: out of the water
    const double full = rho_w * mass_properties(surf).volume;
    FLOESIM_REQUIRE(mass < full, key, ".mass_kg = ", mass, " is more than the hull can carry (", full,
                    " kg fully submerged)");
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      const double mm = rho_w * submerged_part(shifted(surf, Vec3(0, 0, mid)).vertices, surf.triangles, 0).volume;
      (mm > mass ? lo : hi) = mid;
    }
    dz = 0.5 * (lo + hi);
  }
  return {mass, dz};
}

// 3. The particulars of the floating hull into vp: waterline, wetted surface, displacement, mass, centre of mass
// (hull frame), radii of gyration, strips about the centre of mass. Returns the submerged part.
Submerged floating_particulars(const HullModel& hull, const Flotation& fl, const VesselOptions& vo,
                               const EngineSettings& o, VesselParticulars& vp) {
  const TriMesh floating = shifted(hull.surface, Vec3(0, 0, fl.dz));
  const Submerged sub = submerged_part(floating.vertices, floating.triangles, 0.0);
  waterline_particulars(floating, vp);
  // The merged surface holds the faces shared by adjacent parts: the hull module's hydrostatics excludes them
  // from the wetted surface (they cancel in volumes, so clipping the merged surface is right for buoyancy).
  vp.wetted_surface_m2 = hydrostatics(hull.parts, o.water.density_kg_m3, -fl.dz).wetted_surface_m2;
  vp.displacement_m3 = sub.volume;
  vp.waterplane_area_m2 = sub.waterplane_area;
  vp.mass_kg = fl.mass;
  vp.centre_of_mass_hull = Vec3(sub.centroid.x(), sub.centroid.y(), vo.vcg_m);
  const Vec3 com = vp.centre_of_mass_hull;  // hull frame
  vp.radii_of_gyration_m = Vec3(vo.kxx_m > 0 ? vo.kxx_m : 0.38 * vp.beam_wl_m,
                                vo.kyy_m > 0 ? vo.kyy_m : 0.25 * vp.length_oa_m,
                                vo.kzz_m > 0 ? vo.kzz_m : 0.25 * vp.length_oa_m);
  for (double& x : vp.strip_x_m) x -= com.x();
  return sub;
}

// 3. The vessel's added mass (PHYSICS.md §3.3), only with water: surge, sway and yaw as fractions of the mass and
// I_zz; heave and pitch by strip theory, each waterline strip a semicircular section of beam B(x) with the
// high-frequency 2-D heave added mass (pi/8) rho_w B^2 per metre (half the circle's rho pi (B/2)^2, also the flat
// plate's; Lewis 1929 forms of a full section of B/T ~ 3 carry a coefficient C of about 1-1.2 on it: the scale
// option), so A33 = (pi/8) rho_w sum B^2 dx and A55 = (pi/8) rho_w sum B^2 x^2 dx about the centre of mass. Roll
// keeps none (the roll period is not what the ice loads depend on).
void set_vessel_added_mass(Body& b, const VesselParticulars& vp, const VesselOptions& vo, const EngineSettings& o) {
  if (o.water.enabled) {
    const double rho_w = o.water.density_kg_m3, mass = b.mass_kg;
    double a33 = 0, a55 = 0;
    for (size_t i = 0; i < vp.strip_x_m.size(); ++i) {
      const double x = vp.strip_x_m[i], beam = vp.strip_beam_m[i];
      const double strip = kPi / 8 * rho_w * beam * beam * vp.strip_length_m;
      a33 += strip;
      a55 += strip * x * x;
    }
    const double s = vo.heave_pitch_added_mass_scale;
    set_added_mass(b, Vec3(vo.surge_added_mass_ratio * mass, vo.sway_added_mass_ratio * mass, s * a33),
                   Vec3(0, s * a55, vo.yaw_added_inertia_ratio * b.inertia(2, 2)));
  } else {
    set_added_mass(b, Vec3::Zero(), Vec3::Zero());
  }
}

// 3. A hull body's rigid body (the vessel's id is 0, structure k's -1 - k): mass, inertia from the radii of gyration
// or given outright (inertia_kg_m2, body axes about the centre of mass; the radii reported are then those of its
// diagonal), added mass.
Body vessel_body(double mass, VesselParticulars& vp, const VesselOptions& vo, int id, const EngineSettings& o) {
  Body b;
  b.kind = BodyKind::vessel;
  b.id = id;
  b.mass_kg = mass;
  b.inv_mass = 1 / mass;
  const std::vector<double>& Ig = vo.inertia_kg_m2;
  if (Ig.empty()) {
    b.inertia = mass * vp.radii_of_gyration_m.cwiseProduct(vp.radii_of_gyration_m).asDiagonal();
  } else {
    // Given outright (body axes about the centre of mass); the radii reported are those of its diagonal.
    const double xy = Ig.size() == 6 ? Ig[3] : 0, xz = Ig.size() == 6 ? Ig[4] : 0, yz = Ig.size() == 6 ? Ig[5] : 0;
    b.inertia << Ig[0], xy, xz, xy, Ig[1], yz, xz, yz, Ig[2];
    vp.radii_of_gyration_m = (b.inertia.diagonal() / mass).cwiseSqrt();
  }
  b.inv_inertia = b.inertia.inverse();
  set_vessel_added_mass(b, vp, vo, o);
  return b;
}

// 3. The propellers, moved from the hull frame to the body frame (about the centre of mass com).
void add_propellers(const EngineSettings& o, const Vec3& com, Model& model) {
  for (const PropellerOptions& po : o.vessel.propellers) {
    Propeller p;
    p.position = Vec3(po.position_m[0], po.position_m[1], po.position_m[2]) - com;  // hull frame to body frame
    p.axis = Vec3(po.axis[0], po.axis[1], po.axis[2]).normalized();
    p.diameter_m = po.diameter_m;
    p.thrust_share = po.thrust_share;
    model.propellers.push_back(p);
  }
}

// 3. Places hull body `index`: buoyancy mesh and convex parts about the centre of mass, afloat at the sinkage dz,
// turned to heading_deg, at (x_m, y_m); its parts follow the model's parts so far.
void place_hull(Body& b, int index, const HullModel& hull, const Vec3& com, double dz, const VesselOptions& vo,
                Model& model) {
  b.buoyancy_mesh = shifted(hull.surface, -com);
  const double heading = vo.heading_deg * kPi / 180;
  b.initial_orientation = Quat(Eigen::AngleAxisd(heading, Vec3::UnitZ()));
  b.initial_position = Vec3(vo.x_m, vo.y_m, com.z() + dz);
  b.first_part = static_cast<int>(model.parts.size());
  b.part_count = static_cast<int>(hull.parts.size());
  for (const TriMesh& p : hull.parts) model.parts.push_back(make_convex_part(shifted(p, -com), index));
  mark_shared_faces(model.parts, b.first_part, b.part_count);
}

// 3. Metacentric heights from the clipped hull (the same buoyancy the simulation applies) into vp; a vessel unstable
// in roll is an error.
void metacentric_heights(const Body& b, double displacement_m3, const VesselOptions& vo, const std::string& key,
                         const EngineSettings& o, VesselParticulars& vp) {
  const double rho_w = o.water.density_kg_m3, g = o.water.gravity_mps2;
  const double rho_g = rho_w * g > 0 ? rho_w * g : rho_w * 9.81;
  const double k44 =
      rotational_stiffness(b.buoyancy_mesh, b.initial_position, b.initial_orientation, Vec3::UnitX(), rho_g);
  const double k55 =
      rotational_stiffness(b.buoyancy_mesh, b.initial_position, b.initial_orientation, Vec3::UnitY(), rho_g);
  vp.gm_transverse_m = k44 / (rho_g * displacement_m3);
  vp.gm_longitudinal_m = k55 / (rho_g * displacement_m3);
  FLOESIM_REQUIRE(vp.gm_transverse_m > 0, key, ".vcg_m = ", vo.vcg_m,
                  " m makes the body unstable in roll (GM_T = ", vp.gm_transverse_m,
                  " m): lower the centre of mass");
}

// 3. Footprint of the hull parts in the band of z the floes occupy, at the vessel's initial pose: what a floe must
// not overlap at the start.
std::vector<Polygon> vessel_footprint(const HullModel& hull, const Body& vb, const Vec3& com,
                                      const std::vector<Floe>& floes, const EngineSettings& o) {
  // Floes float at hydrostatic equilibrium; without water they are placed with their base at z = -draught anyway.
  const double draught_ratio = o.ice.density_kg_m3 / o.water.density_kg_m3;
  double zlo = 0, zhi = 0;
  for (const Floe& f : floes) {
    zlo = std::min(zlo, -draught_ratio * f.thickness_m);
    zhi = std::max(zhi, (1 - draught_ratio) * f.thickness_m);
  }
  const Mat3 R = vb.initial_orientation.toRotationMatrix();
  std::vector<Polygon> footprint;
  for (int p = 0; p < vb.part_count; ++p) {
    const TriMesh& tm = hull.parts[p];
    std::vector<Vec3> w(tm.vertices.size());
    for (size_t i = 0; i < w.size(); ++i) w[i] = vb.initial_position + R * (tm.vertices[i] - com);
    Polygon fp = band_footprint(w, tm.triangles, zlo, zhi);
    if (fp.size() >= 3) footprint.push_back(std::move(fp));
  }
  return footprint;
}

// 3. Hull body `index` (the vessel's, options `vo` under `key`, or a structure's): floating position, mass, inertia,
// particulars into vp, convex parts, damping and its station into st. Returns its footprint among the floes.
std::vector<Polygon> add_hull(const HullModel& hull, const VesselOptions& vo, const std::string& key, int index,
                              int id, const std::vector<Floe>& floes, const EngineSettings& o, Model& model,
                              VesselParticulars& vp, Station& st) {
  FLOESIM_REQUIRE(!hull.parts.empty(), key, ": the hull has no convex parts");
  FLOESIM_REQUIRE(index == static_cast<int>(model.bodies.size()), "internal: hull bodies come first");
  const Flotation fl = flotation(hull.surface, vo, key, o);
  const Submerged sub = floating_particulars(hull, fl, vo, o, vp);
  const Vec3 com = vp.centre_of_mass_hull;  // hull frame
  Body b = vessel_body(fl.mass, vp, vo, id, o);
  // A fixed or compliant structure stands where the hull frame puts it (its waterline at z = 0, not floated to its
  // weight).
  const bool founded = vo.station_keeping.fixed() || vo.station_keeping.compliant_held();
  place_hull(b, index, hull, com, founded ? 0.0 : fl.dz, vo, model);
  b.clears_ice = founded;
  // A structure's station: its reference point (the hull frame's origin) and heading at the start.
  st.reference_point_body = -com;
  st.position = b.initial_position + b.initial_orientation * st.reference_point_body;
  st.heading_rad = vo.heading_deg * kPi / 180;
  if (vo.station_keeping.fixed()) {
    // A fixed structure: nothing moves it (its floating figures are reported, its stability does not matter).
    b.kinematic = true;
    b.inv_mass = 0;
    b.inv_inertia.setZero();
    b.inv_mass_added.setZero();
    b.inv_inertia_added.setZero();
    model.bodies.push_back(std::move(b));
    return vessel_footprint(hull, model.bodies[index], com, floes, o);
  }
  if (vo.station_keeping.compliant_held()) {
    // Its first mode: the modal mass on a horizontal spring and damper; it neither heaves nor turns, and the water's
    // buoyancy and drag on it are in what holds it (its foundation), not modelled apart.
    const CompliantOptions& c = vo.station_keeping.compliant;
    const double m = c.modal_mass_kg, wn = 2 * kPi * c.natural_frequency_hz;
    b.mass_kg = m;
    b.inv_mass = 1 / m;
    b.added_mass.setZero();
    b.added_inertia.setZero();
    b.inv_mass_added = Vec3(1 / m, 1 / m, 0);
    b.inv_inertia.setZero();
    b.inv_inertia_added.setZero();
    st.spring_npm = m * wn * wn;
    st.damper_nspm = 2 * c.damping_ratio * m * wn;
    model.bodies.push_back(std::move(b));
    return vessel_footprint(hull, model.bodies[index], com, floes, o);
  }
  metacentric_heights(b, sub.volume, vo, key, o, vp);
  for (size_t i = 0; i < vo.station_keeping.lines.size(); ++i) {
    try {
      st.mooring.push_back(mooring_leg(vo.station_keeping.lines[i]));
    } catch (const Error& e) {
      throw Error(key + ".station_keeping.lines[" + std::to_string(i) + "]: " + e.what());
    }
  }
  if (vo.station_keeping.dp_held()) {  // gains per degree of freedom from its mass with the added mass
    const DpOptions& d = vo.station_keeping.dp;
    st.dp.surge = dp_gains(b.mass_kg + b.added_mass.x(), d.natural_period_s, d.damping_ratio);
    st.dp.sway = dp_gains(b.mass_kg + b.added_mass.y(), d.natural_period_s, d.damping_ratio);
    st.dp.yaw = dp_gains(b.inertia(2, 2) + b.added_inertia.z(), d.yaw_natural_period_s, d.damping_ratio);
    st.dp.max_force_x_n = d.max_force_x_n;
    st.dp.max_force_y_n = d.max_force_y_n;
    st.dp.max_moment_z_nm = d.max_moment_z_nm;
    st.dp.observer_time_constant_s = d.observer_time_constant_s;
  }
  if (o.water.enabled)
    set_damping(b, o, o.water.vessel_heave_damping_ratio, o.water.vessel_roll_damping_ratio,
                o.water.vessel_pitch_damping_ratio);
  model.bodies.push_back(std::move(b));
  return vessel_footprint(hull, model.bodies[index], com, floes, o);
}

// 3. The hull bodies, the model's first: the vessel (body 0, with its propellers) and the structures beside it.
// Returns their footprints among the floes.
std::vector<Polygon> add_hulls(const HullModel& hull, const std::vector<HullModel>& structures,
                               const std::vector<Floe>& floes, const EngineSettings& o, Model& model) {
  FLOESIM_REQUIRE(structures.size() == o.structures.size(), "internal: ", structures.size(),
                  " structure meshes for ", o.structures.size(), " structures");
  std::vector<Polygon> footprint = add_hull(hull, o.vessel, "vessel", 0, 0, floes, o, model, model.vessel_info,
                                            model.station);
  model.vessel = 0;
  add_propellers(o, model.vessel_info.centre_of_mass_hull, model);
  for (size_t k = 0; k < structures.size(); ++k) {
    StructureBody sb;
    sb.body = static_cast<int>(model.bodies.size());
    const std::string key = "structures[" + std::to_string(k) + "] (" + o.structures[k].name + ")";
    for (Polygon& p : add_hull(structures[k], o.structures[k].body, key, sb.body, -1 - static_cast<int>(k), floes, o,
                               model, sb.info, sb.station))
      footprint.push_back(std::move(p));
    sb.part_count = model.bodies[sb.body].part_count;
    model.structures.push_back(std::move(sb));
  }
  return footprint;
}

// 4. Whether a floe overlaps the vessel's footprint (boxes first, then the convex pieces).
bool overlaps_footprint(const FloeGeometry& fg, const std::vector<Polygon>& footprint,
                        const std::vector<Aabb2>& fp_box) {
  bool hit = false;
  for (size_t i = 0; i < footprint.size() && !hit; ++i) {
    if (!fp_box[i].overlaps(fg.box)) continue;
    for (size_t j = 0; j < fg.pieces.size() && !hit; ++j)
      hit = fp_box[i].overlaps(fg.piece_box[j]) && convex_intersection_area(footprint[i], fg.pieces[j]) > 1e-9;
  }
  return hit;
}

// 4. Floe bodies: slab of the floe's thickness, body frame at the centre of mass, at hydrostatic equilibrium; level
// ice tiles held fixed. The vessel starts in open water or in broken ice: a floe in its way is removed, level ice
// is an error.
void add_floe_bodies(const std::vector<FloeGeometry>& geo, const std::vector<int>& ridge_of,
                     const std::vector<Polygon>& footprint, const EngineSettings& o, Model& model) {
  std::vector<Aabb2> fp_box;
  for (const Polygon& p : footprint) fp_box.push_back(bounds(p));
  for (size_t k = 0; k < geo.size(); ++k) {
    const FloeGeometry& fg = geo[k];
    const Floe& f = *fg.floe;
    const bool hit = overlaps_footprint(fg, footprint, fp_box);
    // The vessel starts in open water or in broken ice: a floe in its way is removed, level ice is an error.
    FLOESIM_REQUIRE(!(hit && f.level_ice), "the level ice sheet (tile id ", f.id, " at ", fg.box.lo.x(), ", ",
                    fg.box.lo.y(), " m) overlaps the vessel's start: move vessel.x_m / vessel.y_m into open water, or "
                    "cut an opening (level_ice.openings) where the vessel starts");
    if (hit) {
      model.removed_floe_ids.push_back(f.id);
      continue;
    }
    const Vec2 c = centroid(fg.outline);
    Polygon local;
    for (const Vec2& v : fg.outline) local.push_back(v - c);
    model.bodies.push_back(make_floe_body(local, f.thickness_m, f.id, static_cast<int>(model.bodies.size()), c, o,
                                          model.parts));
    if (f.level_ice) hold_fixed(model.bodies.back());
    if (ridge_of[k] >= 0) {
      model.bodies.back().ridge = ridge_of[k];
      model.bodies.back().ridge_part = RidgePart::layer;
    }
  }
}

// 4. The ridges' rubble (settings.ridges): the blocks release_blocks gives each ridge, as floes where they were
// released (under the layer, to float up; over it, to fall), after the other floes, ids from next_id (after every
// floe's, those removed from the vessel's start included: the same with or without a hull). A block is
// brash (rigid contacts, its crushing force as their ceiling, never broken), so a keel costs contact points rather
// than crushing rows; it starts awake (World). A block over the vessel's start is an error.
void add_ridge_blocks(int next_id, const std::vector<Polygon>& footprint, const EngineSettings& o, Model& model) {
  for (size_t i = 0; i < o.ridges.size(); ++i) {
    const RidgeOptions& r = o.ridges[i];
    const std::string where = "ridges[" + std::to_string(i) + "]";
    const RidgeSection section = ridge_section(r, o.ice.density_kg_m3, o.water.density_kg_m3, where);
    for (const RidgeBlock& k : release_blocks(r, section)) {
      Polygon world;
      for (const Vec2& v : rubble_block_outline(k)) world.push_back(v + k.centre);
      for (const Polygon& fp : footprint)
        FLOESIM_REQUIRE(convex_intersection_area(fp, world) <= 1e-9, where, ": a block of its rubble at (",
                        k.centre.x(), ", ", k.centre.y(), ") m lies under the vessel's start (vessel.x_m, "
                        "vessel.y_m): start the vessel clear of the ridge");
      Body b = make_rubble_block(k, next_id++, static_cast<int>(model.bodies.size()), o, model.parts);
      b.ridge = static_cast<int>(i);
      b.ridge_part = k.keel ? RidgePart::keel : RidgePart::sail;
      model.bodies.push_back(std::move(b));
    }
  }
}

// The domain rectangle the walls stand outside of, and the walls' band of z.
struct WallFrame {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // domain corners (m)
  double t = 0;                           // wall thickness (m)
  double zlo = -10, zhi = 10;
};

// 5. The walls' frame: domain.extent_m, else the floes file's field extent (an error if it has none); tall enough
// for the vessel's keel and any floe: from 2 m below the deepest hull point to 10 m above water.
WallFrame wall_frame(const FloeField& field, bool has_vessel, const EngineSettings& o, const Model& model) {
  const std::vector<double>& e = o.domain.extent_m;
  FLOESIM_REQUIRE(!e.empty() || (field.width_m > 0 && field.height_m > 0),
                  "domain.walls: the floes file gives no field extent (width_m, height_m): set domain.extent_m");
  WallFrame w;
  w.x0 = e.empty() ? 0.0 : e[0], w.y0 = e.empty() ? 0.0 : e[1];
  w.x1 = e.empty() ? field.width_m : e[2], w.y1 = e.empty() ? field.height_m : e[3];
  w.t = o.domain.wall_thickness_m;
  // Tall enough for the vessel's keel and any floe: from 2 m below the deepest hull point to 10 m above water.
  if (has_vessel)
    for (const Vec3& v : model.bodies[0].buoyancy_mesh.vertices)
      w.zlo = std::min(w.zlo, model.bodies[0].initial_position.z() + v.z() - 2);
  return w;
}

// 5. A wall overlapping a floe (up to 10 ids named) or the vessel's start is an error.
void require_wall_clear(const std::string& side, const Polygon& rect, const Aabb2& rbox, const WallFrame& w,
                        bool has_vessel, const std::vector<Polygon>& footprint, const Model& model) {
  std::ostringstream bad;
  int nbad = 0;
  for (size_t k = (has_vessel ? 1 : 0); k < model.bodies.size(); ++k) {
    const Body& fb = model.bodies[k];
    if (fb.kind != BodyKind::floe) continue;
    Polygon world;
    for (const Vec2& v : fb.outline) world.push_back(v + fb.initial_position.head<2>());
    if (!rbox.overlaps(bounds(world))) continue;
    bool hit = false;
    for (const Polygon& piece : convex_decompose(world)) hit = hit || convex_intersection_area(piece, rect) > 1e-9;
    if (hit && nbad++ < 10) bad << " " << fb.id;
  }
  FLOESIM_REQUIRE(nbad == 0, "domain wall \"", side, "\" (outside the domain [", w.x0, ", ", w.y0, "] - [", w.x1,
                  ", ", w.y1, "] m) overlaps ", nbad, " floe(s), ids", bad.str(), nbad > 10 ? " ..." : "",
                  ": enlarge domain.extent_m or drop the wall");
  for (const Polygon& fp : footprint)
    FLOESIM_REQUIRE(convex_intersection_area(fp, rect) <= 1e-9, "domain wall \"", side,
                    "\" overlaps the vessel's start (vessel.x_m, vessel.y_m): move the vessel into the domain");
}

// 5. Domain walls: static boxes outside the sides of the domain rectangle, overlapping at the corners (two walls
// never collide with each other: both sleep). A floe or the vessel's start overlapping a wall is an error.
void add_walls(const FloeField& field, bool has_vessel, const std::vector<Polygon>& footprint,
               const EngineSettings& o, Model& model) {
  const WallFrame w = wall_frame(field, has_vessel, o, model);
  const double x0 = w.x0, y0 = w.y0, x1 = w.x1, y1 = w.y1, t = w.t, zlo = w.zlo, zhi = w.zhi;
  for (const std::string& side : o.domain.walls) {
    Vec2 lo, hi;
    if (side == "west") lo = {x0 - t, y0 - t}, hi = {x0, y1 + t};
    else if (side == "east") lo = {x1, y0 - t}, hi = {x1 + t, y1 + t};
    else if (side == "south") lo = {x0 - t, y0 - t}, hi = {x1 + t, y0};
    else lo = {x0 - t, y1}, hi = {x1 + t, y1 + t};
    const Polygon rect = {lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())};
    require_wall_clear(side, rect, Aabb2{lo, hi}, w, has_vessel, footprint, model);
    Body b;
    b.kind = BodyKind::wall;
    b.id = -1 - model.wall_count;
    const Vec2 c = 0.5 * (lo + hi);
    b.initial_position = Vec3(c.x(), c.y(), 0.5 * (zlo + zhi));
    Polygon local;
    for (const Vec2& v : rect) local.push_back(v - c);
    b.first_part = static_cast<int>(model.parts.size());
    b.part_count = 1;
    model.parts.push_back(make_convex_part(extrude_polygon(local, -0.5 * (zhi - zlo), zhi - zlo),
                                           static_cast<int>(model.bodies.size())));
    model.bodies.push_back(std::move(b));  // mass 0: inv_mass and inverse inertia stay 0 (immovable)
    ++model.wall_count;
  }
}

}  // namespace

Polygon rubble_block_outline(const RidgeBlock& k) {
  const double c = std::cos(k.yaw_rad), s = std::sin(k.yaw_rad), hx = 0.5 * k.size_x, hy = 0.5 * k.size_y;
  Polygon local;
  for (const Vec2& corner : {Vec2(-hx, -hy), Vec2(hx, -hy), Vec2(hx, hy), Vec2(-hx, hy)})
    local.emplace_back(c * corner.x() - s * corner.y(), s * corner.x() + c * corner.y());
  return local;
}

Body make_rubble_block(const RidgeBlock& k, int id, int body_index, const EngineSettings& o,
                       std::vector<ConvexPart>& parts) {
  const Polygon local = rubble_block_outline(k);
  Body b = make_floe_body(local, k.thickness, id, body_index, k.centre, o, parts);
  b.initial_position.z() = k.z;
  b.brash = true;  // p_c h x the plan width 4 A / perimeter, as make_floe_body's brash
  b.brash_crush_force_n = o.ice.crushing_strength_pa * k.thickness * 4 * signed_area(local) / perimeter_m(local);
  b.start_awake = true;
  return b;
}

Model build_model(const FloeField& field, const HullModel* hull, const EngineSettings& o,
                  const std::vector<HullModel>& structures) {
  Model model;
  model.settings = o;
  // The ridges of the ridge field join the listed ones: from here on the model's settings list them all.
  for (RidgeOptions& r : ridge_field_ridges(o.ridge_field)) model.settings.ridges.push_back(std::move(r));
  model.settings.ridge_field = RidgeFieldOptions();
  const double g = o.water.gravity_mps2;
  model.gravity = Vec3(0, 0, -g);
  const double cdir = o.water.current_direction_deg * kPi / 180, wdir = o.wind.direction_deg * kPi / 180;
  // With a drift, the run is in the ice's frame: the water and the air move relative to it.
  const Vec2 drift = o.drift.velocity();
  model.frame_velocity = Vec3(drift.x(), drift.y(), 0);
  model.current = o.water.current_speed_mps * Vec3(std::cos(cdir), std::sin(cdir), 0) - model.frame_velocity;
  model.wind = o.wind.speed_mps * Vec3(std::cos(wdir), std::sin(wdir), 0) - model.frame_velocity;

  // 1. Floe geometry in the world: cleaned outline and convex pieces. The level ice sheets come as tiles (fixed
  // floes) after the free floes.
  std::vector<int> ridge_of;
  const std::vector<Floe> floes = model_floes(field, model.settings, ridge_of);
  const std::vector<FloeGeometry> geo = floe_geometry(floes);
  FLOESIM_REQUIRE(o.drift.speed_mps == 0 || !floes.empty(), "drift.speed_mps is ", o.drift.speed_mps,
                  " m/s but there is no ice to drift (no floes, no level_ice.extent_m): give the ice, or set "
                  "drift.speed_mps to 0");

  // 2. Floes must not overlap each other.
  model.small_overlaps += count_small_overlaps(geo, o);

  // 3. The hull bodies (the vessel, the structures): floating position, mass, inertia, particulars, convex parts;
  // their footprint among the floes.
  std::vector<Polygon> footprint;
  FLOESIM_REQUIRE(hull || o.structures.empty(), "structures need the vessel's hull beside them");
  if (hull) footprint = add_hulls(*hull, structures, floes, o, model);

  // 4. Floe bodies: slab of the floe's thickness, body frame at the centre of mass, at hydrostatic equilibrium.
  add_floe_bodies(geo, ridge_of, footprint, o, model);
  int next_id = 1;
  for (const Floe& f : floes) next_id = std::max(next_id, f.id + 1);
  add_ridge_blocks(next_id, footprint, model.settings, model);

  // 5. Domain walls outside the sides of the domain rectangle.
  if (!o.domain.walls.empty()) add_walls(field, hull != nullptr, footprint, o, model);

  // 6. Thrust series (the caller resolved the path relative to the config file).
  if (hull && o.vessel.propulsion.mode == "thrust_series")
    read_thrust_series(o.vessel.propulsion.thrust_file, model.thrust_time_s, model.thrust_n);
  model.built_bodies = model.bodies.size();
  return model;
}

}  // namespace floesim::sim
