#include "sim/engine/forces.h"

#include <algorithm>
#include <cmath>

#include "sim/geometry/polygon3d.h"
#include "pipeline/geometry2d.h"

namespace floesim::sim {

double heading_of(const Mat3& R) { return std::atan2(R(1, 0), R(0, 0)); }

namespace {
constexpr double kJetCore = 6.2;       // far-field constant of u_c = 6.2 V_0 D_0 / x; also the near field's length
constexpr double kJetSpread = 0.1;     // sigma = 0.1 x in the far field
constexpr double kJetCutSigmas = 4.0;  // the Gaussian is cut at 4 sigma (exp(-8) = 3e-4 of u_c)
}  // namespace

double jet_centreline_speed(const PropellerJet& j, double x) {
  if (x <= 0) return 0.0;
  const double xe = kJetCore * j.d0_m;
  return x < xe ? j.excess_mps : j.excess_mps * xe / x;
}

double jet_width(const PropellerJet& j, double x) { return kJetSpread * std::max(x, kJetCore * j.d0_m); }

Vec3 jet_velocity(const std::vector<PropellerJet>& jets, const Vec3& p) {
  Vec3 u = Vec3::Zero();
  for (const PropellerJet& j : jets) {
    const Vec3 d = p - j.origin;
    const double x = d.dot(j.dir);
    if (x <= 0) continue;
    const double r2 = (d - x * j.dir).squaredNorm(), sigma = jet_width(j, x);
    if (r2 >= kJetCutSigmas * kJetCutSigmas * sigma * sigma) continue;
    u += jet_centreline_speed(j, x) * std::exp(-r2 / (2 * sigma * sigma)) * j.dir;
  }
  return u;
}

bool jets_reach(const std::vector<PropellerJet>& jets, const Vec3& c, double radius) {
  for (const PropellerJet& j : jets) {
    const Vec3 d = c - j.origin;
    const double x = d.dot(j.dir);
    if (x + radius <= 0) continue;  // wholly ahead of the propeller
    // The jet's reach grows with x: at most kJetCutSigmas sigma(x + radius) from the axis anywhere in the ball.
    const double reach = kJetCutSigmas * jet_width(j, x + radius) + radius;
    if ((d - x * j.dir).squaredNorm() < reach * reach) return true;
  }
  return false;
}

void propeller_jets(const Model& m, const BodyKinematics& k, double thrust_n, std::vector<PropellerJet>& out) {
  out.clear();
  const double rho = m.settings.water.density_kg_m3;
  for (const Propeller& p : m.propellers) {
    const double t = p.thrust_share * thrust_n;
    if (t == 0) continue;
    PropellerJet j;
    j.origin = k.x + k.R * p.position;
    const Vec3 thrust_dir = k.R * p.axis;
    j.dir = t > 0 ? Vec3(-thrust_dir) : thrust_dir;  // the jet flows against the thrust it makes
    const Vec3 vp = k.v + k.w.cross(j.origin - k.x) - m.current;  // the propeller through the water
    const double va = std::max(0.0, -vp.dot(j.dir));                // inflow speed along the jet's axis
    j.efflux_mps = std::sqrt(va * va + 8 * std::abs(t) / (kPi * rho * p.diameter_m * p.diameter_m));
    j.excess_mps = j.efflux_mps - va;
    j.d0_m = 0.71 * p.diameter_m;
    out.push_back(j);
  }
}

Wrench gravity_force(const Model& m, const Body& b) {
  Wrench w;
  w.force = b.mass_kg * m.gravity;
  return w;
}

bool prism_submerged(const Body& b, const BodyKinematics& k, double& volume, Vec3& centroid) {
  // A floe is a prism along its body z (section A about its centroid, height h). With the water plane written in
  // the body frame as m.p = c (m = R^T z, c = -x_z), a column at (x, y) is under water over the length
  // l(x, y) = l0 - a x - b y from the bottom (a = m_x/m_z, b = m_y/m_z). While the plane cuts only the side walls
  // (0 <= l <= h everywhere), volume and centre of buoyancy follow from the section's area and second moments.
  if (b.kind != BodyKind::floe || b.section_area <= 0) return false;
  if (k.x.z() + std::hypot(b.section_radius, 0.5 * b.thickness_m) <= 0) {
    // Wholly under water at any tilt (a keel's block): the whole prism, centred on its origin.
    volume = b.section_area * b.thickness_m;
    centroid = k.x;
    return true;
  }
  const Vec3 mv = k.R.row(2).transpose();
  if (mv.z() < 0.5) return false;  // tilted beyond 60 degrees: clip the mesh
  const double h = b.thickness_m, A = b.section_area;
  const double a = mv.x() / mv.z(), bb = mv.y() / mv.z();
  const double l0 = -k.x.z() / mv.z() + h / 2;
  const double spread = b.section_radius * std::sqrt(a * a + bb * bb);
  if (l0 - spread < 0 || l0 + spread > h) return false;
  volume = A * l0;
  const double mx = -a * b.section_sxx - bb * b.section_sxy;
  const double my = -a * b.section_sxy - bb * b.section_syy;
  const double l2 = A * l0 * l0 + a * a * b.section_sxx + 2 * a * bb * b.section_sxy + bb * bb * b.section_syy;
  const double ms = 0.5 * (l2 - h * volume);
  centroid = k.x + k.R * Vec3(mx / volume, my / volume, ms / volume);
  return true;
}

Wrench buoyancy_force(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s) {
  Wrench w;
  const double g = -m.gravity.z();
  double volume;
  Vec3 centre;
  if (prism_submerged(b, k, volume, centre)) {
    w.add_at(Vec3(0, 0, m.settings.water.density_kg_m3 * g * volume), centre - k.x);
    return w;
  }
  const auto& mv = b.buoyancy_mesh.vertices;
  s.vertices.resize(mv.size());
  bool any_below = false;
  for (size_t i = 0; i < mv.size(); ++i) {
    s.vertices[i] = k.x + k.R * mv[i];
    any_below = any_below || s.vertices[i].z() < 0;
  }
  if (!any_below) return w;
  const Submerged sub = submerged_part(s.vertices, b.buoyancy_mesh.triangles, 0.0);
  if (sub.volume <= 0) return w;
  w.add_at(Vec3(0, 0, m.settings.water.density_kg_m3 * g * sub.volume), sub.centroid - k.x);
  return w;
}

Wrench hydrostatic_damping(const Model& m, const Body& b, const BodyKinematics& k) {
  Wrench w;
  w.force.z() = -b.heave_damping * k.v.z();
  const Vec3 wb = k.R.transpose() * k.w;  // body axes
  const Vec3 tb(-b.roll_damping * wb.x(), -b.pitch_damping * wb.y(), 0);
  w.torque = k.R * tb;
  return w;
}

double disc_heave_radiation_damping(double rho_w, double g, double radius_m, double draft_m, double omega_radps) {
  const double k = omega_radps * omega_radps / g;
  const double ka = k * radius_m;
  // 2 J1(x)/x -> 1 as x -> 0 (the long-wave limit: the whole waterplane sees the same pressure).
  const double shape = ka > 1e-8 ? 2 * std::cyl_bessel_j(1.0, ka) / ka : 1.0;
  const double area = kPi * radius_m * radius_m;
  const double x3 = rho_w * g * area * std::exp(-k * draft_m) * shape;  // |X3| per unit wave amplitude, N/m
  const double cg = g / (2 * omega_radps);
  return k * x3 * x3 / (4 * rho_w * g * cg);
}

double heave_radiation_force(const Body& b, double heave_velocity_mps, double& lowpass_mps, double dt) {
  if (b.heave_radiation_gain <= 0) return 0.0;
  const double wc_dt = b.heave_radiation_corner_radps * dt;
  lowpass_mps = (lowpass_mps + wc_dt * heave_velocity_mps) / (1 + wc_dt);
  return -b.heave_radiation_gain * (heave_velocity_mps - lowpass_mps);
}

namespace {
// Form drag and skin friction on one submerged face of a floe slab (outward normal n, area, relative velocity vrel
// of the face through the water), PHYSICS.md §3.2. Form drag is the lumped ½ rho_w C_d A_proj |v| v of the seed
// (SAMS Table 1) face by face: a face advancing into the flow u contributes its projected area A (u.n) / |u|, and
// the force is along -u, so the faces of a convex floe sum to ½ rho_w C_d A_proj |u| u, A_proj the floe's area
// projected across the flow, at any heading. (Forcing each face along its own normal with (u.n)^2 gave 0.5-1.0 of
// that: 2/3 for a disc, 1/2 for a square at 45 degrees.) The flow that matters is the one the face sees edge on:
// for the side walls the relative velocity in the floe's plane (`plane_normal`: the floe's z axis; a heave velocity
// does not make an edge advance), for the top and bottom faces the velocity along their normal (the lumped form for
// flow normal to the plate: heave, roll and pitch). Skin friction takes the tangential relative velocity.
inline Vec3 face_force(const Vec3& vrel, const Vec3& n, double area, bool side_wall, const Vec3& plane_normal,
                       double cd, double cf, double half_rho) {
  const double vn = vrel.dot(n);
  Vec3 f = Vec3::Zero();
  if (side_wall) {
    const Vec3 u = vrel - vrel.dot(plane_normal) * plane_normal;
    const double un = u.dot(n);
    if (un > 0) f -= half_rho * cd * area * un * u;
  } else if (vn > 0) {
    f -= half_rho * cd * area * vn * vn * n;
  }
  const Vec3 vt = vrel - vn * n;
  f -= half_rho * cf * area * vt.norm() * vt;
  return f;
}

// face_force on a face given in the world (normal n, area, centroid c), with the moment about the centre of mass;
// the water moves with the current and, if given, the jets at c.
inline Wrench face_drag(const Model& m, const BodyKinematics& k, const Vec3& n, double area, const Vec3& c,
                        bool side_wall, double cd, double cf, double half_rho, const std::vector<PropellerJet>* jets) {
  Wrench w;
  const Vec3 r = c - k.x;
  Vec3 vrel = k.v + k.w.cross(r) - m.current;
  if (jets) vrel -= jet_velocity(*jets, c);
  w.add_at(face_force(vrel, n, area, side_wall, k.R.col(2), cd, cf, half_rho), r);
  return w;
}
}  // namespace

namespace {
// The usual case of a floe afloat and nearly level: the water plane cuts only its side walls, so the bottom is wet,
// the top dry and each side wall wet over a trapezoid between the bottom and the waterline, whose heights l_i, l_j
// at the wall's ends follow from the plane in the body frame (l = l0 - a x - b y from the bottom, as in
// prism_submerged). Everything is done in the body frame with the relative velocity turned once: ~60 flops per
// wall instead of transforming and clipping the slab's vertices. Returns false when the plane may cut the top or
// bottom face (then the general path clips).
bool floe_drag_afloat(const Model& m, const Body& b, const BodyKinematics& k, double cd, double cf, double half_rho,
                      const std::vector<PropellerJet>* jets, Wrench& out) {
  if (b.section_area <= 0 || b.top_face < 0) return false;
  const Vec3 mv = k.R.row(2).transpose();  // world z in the body frame
  if (mv.z() < 0.5) return false;
  const double h = b.thickness_m;
  const double a = mv.x() / mv.z(), bb = mv.y() / mv.z();
  const double l0 = -k.x.z() / mv.z() + h / 2;
  const double spread = b.section_radius * std::sqrt(a * a + bb * bb);
  if (l0 - spread < 0 || l0 + spread > h) return false;
  const Vec3 vb = k.R.transpose() * (k.v - m.current), wb = k.R.transpose() * k.w;
  Vec3 F = Vec3::Zero(), T = Vec3::Zero();
  auto face = [&](const Vec3& n, double area, const Vec3& c, bool side_wall) {
    Vec3 vrel = vb + wb.cross(c);
    if (jets) vrel -= k.R.transpose() * jet_velocity(*jets, k.x + k.R * c);  // the jets where the face is
    const Vec3 f = face_force(vrel, n, area, side_wall, Vec3::UnitZ(), cd, cf, half_rho);
    F += f;
    T += c.cross(f);
  };
  // Bottom: whole and wet (faces 0 = bottom, top_face = top, then the side walls). In a jet, per triangle of the fan
  // from the centroid (the body origin), with signed areas so that a non-convex outline still sums to the face.
  const DragFace& bottom = b.drag_faces[0];
  const int n = static_cast<int>(b.outline.size());
  if (!jets) {
    face(bottom.normal, bottom.area, bottom.centroid, false);
  } else {
    for (int i = 0; i < n; ++i) {
      const Vec2& p = b.outline[i];
      const Vec2& q = b.outline[i + 1 == n ? 0 : i + 1];
      const double area = 0.5 * (p.x() * q.y() - p.y() * q.x());
      const Vec2 c = (p + q) / 3;
      face(bottom.normal, area, Vec3(c.x(), c.y(), bottom.centroid.z()), false);
    }
  }
  for (const DragFace& f : b.drag_faces) {
    if (f.side < 0) continue;
    const int i = f.side, j = i + 1 == n ? 0 : i + 1;
    const Vec2& pi = b.outline[i];
    const Vec2& pj = b.outline[j];
    const double li = l0 - a * pi.x() - bb * pi.y(), lj = l0 - a * pj.x() - bb * pj.y();
    const double sum = li + lj;
    if (sum <= 0) continue;
    const double len = f.area / h;  // the wall is len x h
    // Trapezoid with parallel vertical sides li (at vertex i) and lj: area, centroid along the edge and height.
    const double area = 0.5 * len * sum;
    const double t = (li + 2 * lj) / (3 * sum);
    const double zc = -h / 2 + (li * li + li * lj + lj * lj) / (3 * sum);
    const Vec2 cxy = pi + t * (pj - pi);
    face(f.normal, area, Vec3(cxy.x(), cxy.y(), zc), true);
  }
  out.force = k.R * F;
  out.torque = k.R * T;
  return true;
}
}  // namespace

bool floe_in_jets(const Body& b, const Vec3& x, const std::vector<PropellerJet>& jets) {
  return !jets.empty() && jets_reach(jets, x, std::hypot(b.section_radius, 0.5 * b.thickness_m));
}

namespace {
// The jets if any reaches the floe, else null (the drag then uses the uniform current alone).
const std::vector<PropellerJet>* jets_on(const Body& b, const BodyKinematics& k, const std::vector<PropellerJet>& jets) {
  return floe_in_jets(b, k.x, jets) ? &jets : nullptr;
}

// floe_water_drag_clipped with the jets that reach the floe already looked up (null: none).
Wrench drag_clipped(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s,
                    const std::vector<PropellerJet>* jets) {
  Wrench w;
  const double cd = m.settings.water.form_drag_cd, cf = m.settings.water.skin_friction_cf;
  const double half_rho = 0.5 * m.settings.water.density_kg_m3;
  s.vertices.resize(b.drag_vertices.size());
  for (size_t i = 0; i < b.drag_vertices.size(); ++i) s.vertices[i] = k.x + k.R * b.drag_vertices[i];
  // Waterline points of the vertical edges (bottom ring vertex i, top ring vertex n + i) that cross the water
  // plane: shared by the two side walls of each edge.
  const int n = static_cast<int>(b.drag_vertices.size() / 2);
  s.waterline.resize(n);
  s.crosses.resize(n);
  for (int i = 0; i < n; ++i) {
    const Vec3& lo = s.vertices[i];
    const Vec3& hi = s.vertices[n + i];
    const bool cross = lo.z() < 0 && hi.z() > 0;
    s.crosses[i] = cross;
    if (cross) s.waterline[i] = lo + (-lo.z() / (hi.z() - lo.z())) * (hi - lo);
  }
  for (const DragFace& f : b.drag_faces) {
    if (f.side >= 0) {
      const int i = f.side, j = i + 1 == n ? 0 : i + 1;
      if (s.crosses[i] && s.crosses[j]) {
        // The usual case: both vertical edges cross the waterline; the submerged part is the quad
        // (b_i, b_j, w_j, w_i), two triangles with signed areas along the face normal.
        const Vec3 nw = k.R * f.normal;
        const Vec3 &bi = s.vertices[i], &bj = s.vertices[j], &wi = s.waterline[i], &wj = s.waterline[j];
        const double a1 = 0.5 * (bj - bi).cross(wj - bi).dot(nw), a2 = 0.5 * (wj - bi).cross(wi - bi).dot(nw);
        const double area = a1 + a2;
        if (area <= 0) continue;
        const Vec3 c = (a1 * (bi + bj + wj) + a2 * (bi + wj + wi)) / (3 * area);
        w += face_drag(m, k, nw, area, c, true, cd, cf, half_rho, jets);
        continue;
      }
    }
    // Otherwise the general case below.

    // Submerged part of the face (full, none, or clipped at the water plane).
    bool all_below = true, any_below = false;
    for (int i = 0; i < f.count; ++i) {
      const double z = s.vertices[b.drag_face_index[f.first + i]].z();
      all_below = all_below && z <= 0;
      any_below = any_below || z < 0;
    }
    if (!any_below) continue;
    AreaCentroid ac;
    if (all_below) {
      ac.area = f.area;
      ac.centroid = k.x + k.R * f.centroid;
    } else if (f.count <= 8) {
      // Side walls (quads) and small top or bottom faces cut by the waterline: clipped on the stack. A face of a
      // non-convex outline (a top or bottom of up to 8 vertices, tilted through the water plane) can cross it at
      // every edge, so the cut has up to 2 x 8 vertices (a tilted small brash piece found the 9 of a convex one).
      Vec3 in[8], out[16];
      for (int i = 0; i < f.count; ++i) in[i] = s.vertices[b.drag_face_index[f.first + i]];
      ac = polygon_area_centroid(out, clip_polygon_z(in, f.count, 0.0, true, out));
    } else {
      // Gather the face's vertices, then clip (the top/bottom faces of large floes can have many vertices).
      s.big.clear();
      for (int i = 0; i < f.count; ++i) s.big.push_back(s.vertices[b.drag_face_index[f.first + i]]);
      clip_polygon_z(s.big.data(), f.count, 0.0, true, s.big_cut);
      ac = polygon_area_centroid(s.big_cut.data(), static_cast<int>(s.big_cut.size()));
    }
    if (ac.area <= 0) continue;
    w += face_drag(m, k, k.R * f.normal, ac.area, ac.centroid, f.side >= 0, cd, cf, half_rho, jets);
  }
  return w;
}
}  // namespace

Wrench floe_water_drag(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s,
                       const std::vector<PropellerJet>& all_jets) {
  Wrench w;
  const double cd = m.settings.water.form_drag_cd, cf = m.settings.water.skin_friction_cf;
  const double half_rho = 0.5 * m.settings.water.density_kg_m3;
  const std::vector<PropellerJet>* jets = jets_on(b, k, all_jets);
  if (floe_drag_afloat(m, b, k, cd, cf, half_rho, jets, w)) return w;
  return drag_clipped(m, b, k, s, jets);
}

Wrench floe_water_drag_clipped(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s,
                               const std::vector<PropellerJet>& all_jets) {
  return drag_clipped(m, b, k, s, jets_on(b, k, all_jets));
}


Wrench floe_wind_drag(const Model& m, const Body& b, const BodyKinematics& k, ForceScratch& s) {
  Wrench w;
  if (m.wind.squaredNorm() == 0 || b.top_face < 0) return w;
  const DragFace& f = b.drag_faces[b.top_face];
  s.big.clear();
  for (int i = 0; i < f.count; ++i) s.big.push_back(k.x + k.R * b.drag_vertices[b.drag_face_index[f.first + i]]);
  clip_polygon_z(s.big.data(), f.count, 0.0, false, s.big_cut);
  const AreaCentroid ac = polygon_area_centroid(s.big_cut.data(), static_cast<int>(s.big_cut.size()));
  if (ac.area <= 0) return w;
  const Vec3 n = k.R * f.normal;
  const Vec3 r = ac.centroid - k.x;
  const Vec3 arel = m.wind - (k.v + k.w.cross(r));
  const Vec3 at = arel - arel.dot(n) * n;
  w.add_at(0.5 * m.settings.wind.air_density_kg_m3 * m.settings.ice.air_drag_ca * ac.area * at.norm() * at, r);
  return w;
}

HullRef vessel_ref(const Model& m) { return {m.vessel_info, m.settings.vessel, m.station}; }

HullRef structure_ref(const Model& m, int k) {
  return {m.structures[k].info, m.settings.structures[k].body, m.structures[k].station};
}

Wrench vessel_resistance(const Model& m, const HullRef& h, const BodyKinematics& k) {
  Wrench w;
  const Vec3 ex = k.R.col(0);
  const double u = (k.v - m.current).dot(ex);
  w.force = -ittc57_resistance(u, ittc57_of(h.info, h.options, m.settings)) * ex;
  return w;
}

Wrench vessel_cross_flow(const Model& m, const HullRef& h, const BodyKinematics& k) {
  Wrench w;
  const VesselParticulars& vp = h.info;
  const Vec3 ey = k.R.col(1), ez = k.R.col(2);
  const double v = (k.v - m.current).dot(ey);  // sway velocity relative to the water
  const double r = k.w.dot(ez);               // yaw rate
  const double c = 0.5 * m.settings.water.density_kg_m3 * h.options.sway_drag_cd * vp.draught_m *
                   vp.strip_length_m;
  double fy = 0, mz = 0;
  for (double x : vp.strip_x_m) {
    const double vl = v + r * x;  // local sway velocity of the strip
    const double f = -c * vl * std::abs(vl);
    fy += f;
    mz += x * f;
  }
  w.force = fy * ey;
  w.torque = mz * ez;
  return w;
}

Wrench vessel_wind(const Model& m, const BodyKinematics& k) {
  Wrench w;
  const WindOptions& o = m.settings.wind;
  if (m.wind.squaredNorm() == 0) return w;
  const Vec3 a = k.R.transpose() * (m.wind - k.v);  // air velocity relative to the vessel, body axes
  const double ah2 = a.x() * a.x() + a.y() * a.y();
  if (ah2 == 0) return w;
  // gamma: angle the relative wind comes from, 0 = head wind, positive from port (y to port, z up).
  const double gamma = std::atan2(-a.y(), -a.x());
  const double q = 0.5 * o.air_density_kg_m3 * ah2;
  const Vec3 xyn = fossen_wind_xyn(q, gamma, o.frontal_area_m2, o.lateral_area_m2, m.vessel_info.length_oa_m, o.cx,
                                   o.cy, o.cn);
  w.force = k.R * Vec3(xyn.x(), xyn.y(), 0);
  w.torque = k.R * Vec3(0, 0, xyn.z());
  return w;
}

Wrench vessel_propulsion(const Model& m, const BodyKinematics& k, double time_s, double dt, double& integral,
                         double& thrust_n) {
  const PropulsionOptions& p = m.settings.vessel.propulsion;
  const Vec3 ex = k.R.col(0);
  double thrust = 0;
  if (p.mode == "constant_thrust" || p.mode == "bollard_pull") {
    thrust = p.thrust_n;
  } else if (p.mode == "thrust_series") {
    const auto& t = m.thrust_time_s;
    const auto& f = m.thrust_n;
    if (time_s <= t.front()) {
      thrust = f.front();
    } else if (time_s >= t.back()) {
      thrust = f.back();
    } else {
      const size_t i = std::upper_bound(t.begin(), t.end(), time_s) - t.begin();
      const double s = (time_s - t[i - 1]) / (t[i] - t[i - 1]);
      thrust = f[i - 1] + s * (f[i] - f[i - 1]);
    }
  } else {
    // PI on the speed through the water, with the open-water resistance at the target speed as feed-forward;
    // the integral is frozen while the thrust saturates (anti-windup).
    const double u = (k.v - m.current).dot(ex);
    const double e = p.speed_mps - u;
    const double ff = ittc57_resistance(p.speed_mps, ittc57_of(m.vessel_info, m.settings));
    const double trial = ff + p.kp_n_per_mps * e + p.ki_n_per_m * (integral + e * dt);
    if (trial > p.min_thrust_n && trial < p.max_thrust_n) integral += e * dt;
    thrust = std::clamp(ff + p.kp_n_per_mps * e + p.ki_n_per_m * integral, p.min_thrust_n, p.max_thrust_n);
  }
  thrust_n = thrust;
  Wrench w;
  if (p.mode != "bollard_pull") w.force = thrust * ex;
  return w;
}

Wrench vessel_autopilot(const Model& m, const Body& b, const BodyKinematics& k, double heading_ref) {
  Wrench w;
  const AutopilotOptions& a = m.settings.vessel.autopilot;
  if (!a.enabled) return w;
  double e = heading_of(k.R) - heading_ref;
  e = std::remainder(e, 2 * kPi);
  const double wn = 2 * kPi / a.natural_period_s;
  const Vec3 ez = k.R.col(2);
  const double r = k.w.dot(ez);
  const double izz = b.inertia(2, 2) + b.added_inertia.z();  // the yaw inertia the moment acts against
  const double mz = std::clamp(-izz * (wn * wn * e + 2 * a.damping_ratio * wn * r), -a.max_moment_nm, a.max_moment_nm);
  w.torque = mz * ez;
  return w;
}

Wrench station_keeping_force(const Model& m, const HullRef& h, const BodyKinematics& k, double time_s, double dt,
                             std::vector<double>* dp_memory, StationKeeping* out) {
  const StationKeepingOptions& sk = h.options.station_keeping;
  const Station& st = h.station;
  const Vec3 ref = k.x + k.R * st.reference_point_body;  // the reference point, run frame
  const Vec3 earth = ref + time_s * m.frame_velocity;
  const Vec2 offset = (earth - st.position).head<2>();
  const double psi = heading_of(k.R);
  const double dpsi = std::remainder(psi - st.heading_rad, 2 * kPi);
  out->offset = offset;
  out->heading_change_rad = dpsi;
  const double ramp = sk.applied_force_ramp_s > 0 ? std::min(1.0, time_s / sk.applied_force_ramp_s) : 1.0;
  Vec3 force = ramp * Vec3(sk.applied_force_n[0], sk.applied_force_n[1], 0);
  double moment_z = 0;
  if (sk.moored()) {
    // The legs are laid out in the station's axes: the offset turned into them, the pull turned back.
    const double c0 = std::cos(st.heading_rad), s0 = std::sin(st.heading_rad);
    const double dx = c0 * offset.x() + s0 * offset.y(), dy = -s0 * offset.x() + c0 * offset.y();
    const SpreadState sp = spread_at_pose(st.mooring, dx, dy, dpsi);
    out->line_tension_n.clear();
    for (const CatenaryState& l : sp.lines) out->line_tension_n.push_back(l.fairlead_tension_n);
    out->delivered[0] = out->demanded[0] = sp.force_x_n;
    out->delivered[1] = out->demanded[1] = sp.force_y_n;
    out->delivered[2] = out->demanded[2] = sp.moment_z_nm;
    force += Vec3(c0 * sp.force_x_n - s0 * sp.force_y_n, s0 * sp.force_x_n + c0 * sp.force_y_n, 0);
    moment_z = sp.moment_z_nm;
  } else if (sk.compliant_held()) {
    // The first mode's spring and damper on the horizontal offset and velocity over the earth; in the station's
    // axes as the mooring's pull.
    const Vec3 v_earth = k.v + m.frame_velocity;
    const Vec2 f = -st.spring_npm * offset - st.damper_nspm * v_earth.head<2>();
    const double c0 = std::cos(st.heading_rad), s0 = std::sin(st.heading_rad);
    out->delivered[0] = out->demanded[0] = c0 * f.x() + s0 * f.y();
    out->delivered[1] = out->demanded[1] = -s0 * f.x() + c0 * f.y();
    force += Vec3(f.x(), f.y(), 0);
  } else if (sk.dp_held()) {
    DpController dp(st.dp, st.position.x(), st.position.y(), st.heading_rad, st.position.x(), st.position.y(),
                    st.heading_rad);
    if (!dp_memory->empty()) dp.set_memory(*dp_memory);
    const DpCommand c = dp.step(dt, earth.x(), earth.y(), psi);
    *dp_memory = dp.memory();
    for (int i = 0; i < 3; ++i) out->demanded[i] = c.demanded[i], out->delivered[i] = c.delivered[i];
    const double cp = std::cos(psi), sp = std::sin(psi);
    force += Vec3(cp * c.delivered[0] - sp * c.delivered[1], sp * c.delivered[0] + cp * c.delivered[1], 0);
    moment_z = c.delivered[2];
  }
  Wrench w;
  w.force = force;
  w.torque = (ref - k.x).cross(force) + Vec3(0, 0, moment_z);
  return w;
}

}  // namespace floesim::sim
