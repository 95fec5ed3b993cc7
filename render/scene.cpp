#include "render/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"
#include "pipeline/units.h"
#include "render/gl_context.h"
#include "render/strip_chart.h"

namespace floesim::render {

namespace {

using Mat4 = Eigen::Matrix4d;  // column-major, like GL
using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;


// Sun from the south-west, ~50 degrees up (unit vector towards the sun, world frame). With the ambient term below,
// ambient + diffuse * sun_z = 1: faces looking straight up (floe tops, the deck) show exactly their configured
// colour, and sides get relief from the sun direction.
constexpr float kSun[3] = {-0.4191f, -0.4989f, 0.7585f};
constexpr float kAmbient = 0.5f;
// Hull faces meeting at less than this angle share their corner normals (smooth shading); sharper edges stay sharp.
constexpr double kCreaseDeg = 35;
// Opacity of the water the side view lays over everything below the surface.
constexpr float kSideWaterAlpha = 0.45f;

// ---- small camera maths (no GLU: it would link libGL) ----

Mat4 look_at(const Vec3& eye, const Vec3& target, const Vec3& up) {
  const Vec3 f = (target - eye).normalized();
  const Vec3 s = f.cross(up).normalized();
  const Vec3 u = s.cross(f);
  Mat4 m = Mat4::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Mat4 perspective(double fovy_rad, double aspect, double near_m, double far_m) {
  const double t = 1.0 / std::tan(fovy_rad / 2);
  Mat4 m = Mat4::Zero();
  m(0, 0) = t / aspect;
  m(1, 1) = t;
  m(2, 2) = (far_m + near_m) / (near_m - far_m);
  m(2, 3) = 2 * far_m * near_m / (near_m - far_m);
  m(3, 2) = -1;
  return m;
}

Mat4 ortho(double half_w, double half_h, double near_m, double far_m) {
  Mat4 m = Mat4::Identity();
  m(0, 0) = 1 / half_w;
  m(1, 1) = 1 / half_h;
  m(2, 2) = -2 / (far_m - near_m);
  m(2, 3) = -(far_m + near_m) / (far_m - near_m);
  return m;
}

// The six planes of a view volume (Gribb & Hartmann), normalised so that plane . (x, 1) is a distance in metres.
struct Frustum {
  std::array<Eigen::Vector4d, 6> planes;
  explicit Frustum(const Mat4& pv) {
    for (int i = 0; i < 3; ++i) {
      planes[2 * i] = pv.row(3).transpose() + pv.row(i).transpose();
      planes[2 * i + 1] = pv.row(3).transpose() - pv.row(i).transpose();
    }
    for (auto& p : planes) p /= p.head<3>().norm();
  }
  bool outside(const Vec3& c, double radius) const {
    for (const auto& p : planes)
      if (p.head<3>().dot(c) + p[3] < -radius) return true;
    return false;
  }
};

Mat4 pose_matrix(const double* q_wxyz, const Vec3& p) {
  Mat4 m = Mat4::Identity();
  m.block<3, 3>(0, 0) = Eigen::Quaterniond(q_wxyz[0], q_wxyz[1], q_wxyz[2], q_wxyz[3]).normalized().toRotationMatrix();
  m.block<3, 1>(0, 3) = p;
  return m;
}

// Ear clipping of a simple CCW polygon; O(n^3) worst case is nothing for 10-60 vertices, and it runs once per
// floe. Outlines from segmentation are often non-convex, so a fan would draw wrong triangles.
std::vector<std::array<int, 3>> triangulate(const std::vector<Vec2>& p) {
  std::vector<std::array<int, 3>> tris;
  std::vector<int> idx(p.size());
  for (size_t i = 0; i < p.size(); ++i) idx[i] = static_cast<int>(i);
  auto cross = [&](int a, int b, int c) {
    return (p[b] - p[a]).x() * (p[c] - p[a]).y() - (p[b] - p[a]).y() * (p[c] - p[a]).x();
  };
  while (idx.size() > 3) {
    const size_t n = idx.size();
    bool clipped = false;
    for (size_t i = 0; i < n && !clipped; ++i) {
      const int a = idx[(i + n - 1) % n], b = idx[i], c = idx[(i + 1) % n];
      if (cross(a, b, c) <= 0) continue;  // reflex or degenerate corner: not an ear
      bool empty = true;
      for (int k : idx) {
        if (k == a || k == b || k == c) continue;
        if (cross(a, b, k) >= 0 && cross(b, c, k) >= 0 && cross(c, a, k) >= 0) {
          empty = false;
          break;
        }
      }
      if (!empty) continue;
      tris.push_back({a, b, c});
      idx.erase(idx.begin() + static_cast<long>(i));
      clipped = true;
    }
    if (!clipped) {
      // Self-touching or collinear leftovers: close the rest as a fan rather than dropping area.
      for (size_t i = 1; i + 1 < idx.size(); ++i) tris.push_back({idx[0], idx[i], idx[i + 1]});
      return tris;
    }
  }
  if (idx.size() == 3) tris.push_back({idx[0], idx[1], idx[2]});
  return tris;
}

struct FloeDraw {
  GLint first = 0, count = 0;            // triangles in the vertex arrays: the top face, then 6 per side quad
  GLint top_count = 0;                   // vertices of the top face
  GLint ring_first = 0, ring_count = 0;  // outline of the top face (line loop)
  double radius = 0;                     // bounding sphere about the centre of mass
  float shade = 1;                       // the per-floe shade of its top colour (also applied to contact_colour)
  bool sheet = false;                    // a tile of level ice: never lit as "in contact" (a whole tile would be)
};

// One camera's rectangle in the output frame (pixels, top-left origin): the whole frame, or a half of a split one.
struct SubView {
  std::string view;  // chase, top or side
  cv::Rect rect;
};

std::vector<SubView> sub_views(const RenderOptions& o) {
  const int w = o.width_px, h = o.height_px;
  if (o.view != "split") return {{o.view, {0, 0, w, h}}};
  if (o.split_layout == "stacked")
    return {{o.split_views[0], {0, 0, w, h / 2}}, {o.split_views[1], {0, h / 2, w, h - h / 2}}};
  return {{o.split_views[0], {0, 0, w / 2, h}}, {o.split_views[1], {w / 2, 0, w - w / 2, h}}};
}

}  // namespace

struct SceneRenderer::Impl {
  const Results& r;
  RenderOptions o;
  std::string source;
  OffscreenContext ctx;
  const GlApi& gl;

  // Interleaving is not needed: separate arrays keep the building code plain.
  std::vector<float> pos, nrm;
  std::vector<uint8_t> col;
  std::vector<FloeDraw> floes;          // per geometry index
  std::unique_ptr<FrameReplay> replay;  // every body's state at the frame drawn (a frame stores what changed)
  std::vector<int64_t> vessel_row;      // per frame
  GLint hull_first = 0, hull_count = 0;
  double hull_radius = 0;
  // The structures beside the vessel (results /structures): their meshes and pose series (earth frame, per step).
  struct StructureMesh {
    std::string name;
    GLint first = 0, count = 0;
    const std::vector<double>* position = nullptr;
    const std::vector<double>* quaternion = nullptr;
    Vec3 frame_velocity = Vec3::Zero();  // the run's frame over the earth: the frames' positions are in it
  };
  std::vector<StructureMesh> structures;
  double steps_per_frame = 0;
  std::string playback_label;  // ", plays 5x real time" (empty if the frame interval is unknown)
  float sky[3], water[3], edge[3], contact[3];
  std::vector<SubView> views;
  std::unique_ptr<LoadStripChart> strip;  // null without strip_chart
  FrameStats stats;
  // Per-frame batches of the visible floes in camera-relative world coordinates (reused between frames).
  std::vector<float> batch_pos, edge_pos;
  std::vector<uint8_t> batch_col;
  cv::Mat big, small;  // the GL frame (aliases the context's buffer) and its downsampled copy
  std::vector<float> water_grid;                  // unit square [-1, 1]^2 at z = 0 as triangles

  Impl(const Results& res, const RenderOptions& opt, const std::string& src)
      : r(res), o(opt), source(src), ctx(opt.width_px * opt.supersample, opt.height_px * opt.supersample),
        gl(ctx.gl()) {
    parse_hex_colour(o.sky_colour, sky);
    parse_hex_colour(o.water_colour, water);
    parse_hex_colour(o.edge_colour, edge);
    parse_hex_colour(o.contact_colour, contact);
    views = sub_views(o);
    check_states();
    if (o.strip_chart) strip = std::make_unique<LoadStripChart>(r, o, source);
    build_floes();
    build_hull();
    build_water_grid();
    setup_gl();
  }

  void vertex(const Vec3& p, const Vec3& n, const float c[3]) {
    pos.insert(pos.end(), {float(p.x()), float(p.y()), float(p.z())});
    nrm.insert(nrm.end(), {float(n.x()), float(n.y()), float(n.z())});
    col.insert(col.end(), {uint8_t(std::lround(255 * std::clamp(c[0], 0.f, 1.f))),
                           uint8_t(std::lround(255 * std::clamp(c[1], 0.f, 1.f))),
                           uint8_t(std::lround(255 * std::clamp(c[2], 0.f, 1.f))), 255});
  }
  GLint vertex_count() const { return static_cast<GLint>(pos.size() / 3); }

  // Every state row must name the vessel or a floe with geometry, with a finite pose; every frame needs the vessel
  // (FrameReplay checks the names and the vessel).
  void check_states() {
    const size_t frames = r.frames();
    FLOESIM_REQUIRE(frames > 0, source, ": the results hold no frames (/frames/time_s is empty): nothing to render");
    FLOESIM_REQUIRE(r.state_in_contact.size() == r.state_body_id.size(), source, ": /states/in_contact has ",
                    r.state_in_contact.size(), " rows, /states/body_id ", r.state_body_id.size());
    replay = std::make_unique<FrameReplay>(r, source);
    vessel_row.assign(frames, -1);
    for (size_t k = 0; k < frames; ++k) {
      for (int64_t row = r.frame_offset[k]; row < r.frame_offset[k + 1]; ++row) {
        const int32_t id = r.state_body_id[row];
        const double* q = &r.state_quaternion[4 * row];
        const double* p = &r.state_position_m[3 * row];
        const double qn = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        FLOESIM_REQUIRE(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && std::isfinite(qn) &&
                            qn > 0.5 && qn < 2.0,
                        source, ": body ", id, " in frame ", k, " (t = ", r.frame_time_s[k],
                        " s) has a non-finite position or an invalid quaternion (did the simulation blow up?)");
        if (id == 0) vessel_row[k] = row;
      }
    }
    // Lineage (the piece colours) and events in time order (the overlay counts them by bisection).
    const std::string problem = fracture_problem(r);
    FLOESIM_REQUIRE(problem.empty(), source, ": ", problem);
  }

  // Slabs in the body frame: top face at z = +h/2 (triangulated outline), sides as flat-shaded quads; no bottom
  // (it is under water, never seen). The top colour varies a little per floe so that touching floes stay apart.
  void build_floes() {
    const size_t n = r.floe_id.size();
    FLOESIM_REQUIRE(r.floe_vertex_offset.size() == n + 1 && r.floe_thickness_m.size() == n, source,
                    ": /geometry floe arrays disagree in length");
    float side[3];
    parse_hex_colour(o.floe_side_colour, side);
    floes.resize(n);
    std::vector<Vec2> ring;
    for (size_t g = 0; g < n; ++g) {
      const int64_t a = r.floe_vertex_offset[g], b = r.floe_vertex_offset[g + 1];
      FLOESIM_REQUIRE(a >= 0 && b >= a + 3 && static_cast<size_t>(2 * b) <= r.floe_vertices_m.size(), source,
                      ": floe ", r.floe_id[g], " has an invalid outline (", b - a,
                      " vertices; at least 3 are needed)");
      const double h = r.floe_thickness_m[g];
      FLOESIM_REQUIRE(std::isfinite(h) && h > 0, source, ": floe ", r.floe_id[g], " has thickness ", h,
                      " m; it must be > 0");
      ring.clear();
      for (int64_t v = a; v < b; ++v) ring.emplace_back(r.floe_vertices_m[2 * v], r.floe_vertices_m[2 * v + 1]);
      double area2 = 0;
      for (size_t i = 0; i < ring.size(); ++i) {
        const Vec2& p = ring[i];
        const Vec2& q = ring[(i + 1) % ring.size()];
        area2 += p.x() * q.y() - q.x() * p.y();
      }
      if (area2 < 0) std::reverse(ring.begin(), ring.end());  // the layout says CCW; be lenient, not wrong
      // A deterministic shade per floe id (Knuth's multiplicative hash), 0.92 .. 1.0 of the top colour.
      // Level ice is one sheet: its tiles (and what wedges leave of them) share one shade and the input colour.
      const bool sheet = r.floe_level_ice.size() == n && r.floe_level_ice[g];
      const float shade =
          sheet ? 1.0f : 0.92f + 0.08f * float((uint32_t(r.floe_id[g]) * 2654435761u >> 16) & 255u) / 255.f;
      float top[3];
      floe_top_colour(o, sheet ? kFractureNone : r.floe_origin_mode[g], r.floe_generation[g], top);
      const float t[3] = {top[0] * shade, top[1] * shade, top[2] * shade};
      FloeDraw& f = floes[g];
      f.shade = shade;
      f.sheet = sheet;
      f.first = vertex_count();
      const double zt = h / 2, zb = -h / 2;
      const Vec3 up(0, 0, 1);
      for (const auto& tri : triangulate(ring))
        for (int i : tri) vertex(Vec3(ring[i].x(), ring[i].y(), zt), up, t);
      f.top_count = vertex_count() - f.first;
      for (size_t i = 0; i < ring.size(); ++i) {
        const Vec2& p = ring[i];
        const Vec2& q = ring[(i + 1) % ring.size()];
        const Vec2 e = q - p;
        if (e.norm() <= 0) continue;
        const Vec3 out(e.y() / e.norm(), -e.x() / e.norm(), 0);  // outward for a CCW ring
        const Vec3 p0(p.x(), p.y(), zb), p1(q.x(), q.y(), zb), p2(q.x(), q.y(), zt), p3(p.x(), p.y(), zt);
        for (const Vec3* v : {&p0, &p1, &p2, &p0, &p2, &p3}) vertex(*v, out, side);
        f.radius = std::max(f.radius, std::hypot(p.norm(), h / 2));
      }
      f.count = vertex_count() - f.first;
      f.ring_first = vertex_count();
      // Lifted a little above the top face, so that the outline wins the depth test without a polygon offset
      // (an offset, large at grazing angles, would push distant floes behind one another).
      for (const Vec2& p : ring) vertex(Vec3(p.x(), p.y(), zt + 0.03), up, t);
      f.ring_count = vertex_count() - f.ring_first;
    }
  }

  // The hull, lit by the sun (the fixed-function light) with smooth shading: a corner's normal is the area-weighted
  // mean of the normals of the faces meeting there that turn from its own face by less than kCreaseDeg, so the
  // rounded bow and bilge shade smoothly while the knuckles, the deck edge and the deckhouse stay sharp. Upward
  // faces in the upper half are the deck. Winding is not trusted (meshes come from any tool): a neighbour wound the
  // other way points away and is left out, and two-sided lighting turns every normal towards the viewer.
  void build_hull() {
    build_mesh(r.hull_vertices_m, r.hull_triangles, hull_first, hull_count, &hull_radius);
    // The structures beside the vessel: each mesh and where its pose is in the results.
    const nlohmann::json list = r.attributes.value("structures", nlohmann::json::array());
    for (const nlohmann::json& st : list) {
      if (st.value("body", std::string()) == "vessel") continue;  // the case's hull body: drawn as the hull
      StructureMesh m;
      m.name = st.at("name").get<std::string>();
      const std::vector<double> fv = st.value("run_frame_velocity_mps", std::vector<double>{0, 0, 0});
      m.frame_velocity = Vec3(fv.at(0), fv.at(1), fv.at(2));
      const auto pos = r.structure_series.find(m.name + "/position_m");
      const auto quat = r.structure_series.find(m.name + "/quaternion_wxyz");
      FLOESIM_REQUIRE(pos != r.structure_series.end() && quat != r.structure_series.end(), source, ": structure ",
                      m.name, " has no pose series");
      m.position = &pos->second;
      m.quaternion = &quat->second;
      build_mesh(r.structure_hull_vertices_m.at(m.name), r.structure_hull_triangles.at(m.name), m.first, m.count,
                 nullptr);
      structures.push_back(m);
    }
    const double dt = r.attributes.value("time_step_s", 0.0), every = r.attributes.value("output_interval_s", 0.0);
    steps_per_frame = dt > 0 ? every / dt : 0;
    const double speed = playback_speed(r, o.fps);
    if (std::isfinite(speed)) playback_label = ", plays " + fmt("%.3g", speed) + "x real time";
  }

  // A mesh's triangles into the vertex buffer: [first, first + count).
  void build_mesh(const std::vector<double>& v, const std::vector<int32_t>& t, GLint& first, GLint& count,
                  double* radius) {
    FLOESIM_REQUIRE(v.size() % 3 == 0 && t.size() % 3 == 0, source, ": /geometry hull arrays have bad shapes");
    const size_t nv = v.size() / 3;
    float hull[3], deck[3];
    parse_hex_colour(o.hull_colour, hull);
    parse_hex_colour(o.deck_colour, deck);
    double zmin = 1e300, zmax = -1e300;
    for (size_t i = 0; i < nv; ++i) {
      zmin = std::min(zmin, v[3 * i + 2]);
      zmax = std::max(zmax, v[3 * i + 2]);
      if (radius) *radius = std::max(*radius, Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]).norm());
    }
    const size_t nt = t.size() / 3;
    for (size_t k = 0; k < nt; ++k)
      for (int j = 0; j < 3; ++j)
        FLOESIM_REQUIRE(t[3 * k + j] >= 0 && static_cast<size_t>(t[3 * k + j]) < nv, source, ": hull triangle ", k,
                        " uses vertex ", t[3 * k + j], " of ", nv);
    const std::vector<bool> internal = hull_internal_faces(v, t);
    // 1. Face normals (area-weighted: the unnormalised cross product) of the faces drawn.
    std::vector<Vec3> face(nt, Vec3::Zero());
    for (size_t k = 0; k < nt; ++k) {
      if (internal[k]) continue;
      const Vec3 p0(&v[3 * size_t(t[3 * k])]), p1(&v[3 * size_t(t[3 * k + 1])]), p2(&v[3 * size_t(t[3 * k + 2])]);
      face[k] = (p1 - p0).cross(p2 - p0);
    }
    // 2. Faces around each position (convex parts repeat vertices: corners are matched by position, to 1 mm).
    std::vector<std::pair<std::array<int64_t, 3>, size_t>> corner;  // (position key, face)
    const auto key = [&](int32_t i) {
      return std::array<int64_t, 3>{std::llround(1000 * v[3 * size_t(i)]), std::llround(1000 * v[3 * size_t(i) + 1]),
                                    std::llround(1000 * v[3 * size_t(i) + 2])};
    };
    for (size_t k = 0; k < nt; ++k)
      if (face[k].norm() > 0)
        for (int j = 0; j < 3; ++j) corner.push_back({key(t[3 * k + j]), k});
    std::sort(corner.begin(), corner.end());
    // 3. Corners: smoothed normals within the crease angle.
    const double cos_crease = std::cos(kCreaseDeg * kPi / 180);
    first = vertex_count();
    for (size_t k = 0; k < nt; ++k) {
      if (face[k].norm() <= 0) continue;  // internal, or a degenerate sliver: nothing to draw
      const Vec3 n = face[k].normalized();
      Vec3 p[3], c[3];
      for (int j = 0; j < 3; ++j) {
        const int32_t i = t[3 * k + j];
        p[j] = Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
        const auto kj = key(i);
        auto it = std::lower_bound(corner.begin(), corner.end(), std::make_pair(kj, size_t(0)));
        c[j] = Vec3::Zero();
        for (; it != corner.end() && it->first == kj; ++it)
          if (face[it->second].normalized().dot(n) > cos_crease) c[j] += face[it->second];
        c[j] = c[j].norm() > 0 ? Vec3(c[j].normalized()) : n;
      }
      const bool is_deck = std::abs(n.z()) > 0.8 && (p[0].z() + p[1].z() + p[2].z()) / 3 > (zmin + zmax) / 2;
      for (int j = 0; j < 3; ++j) vertex(p[j], c[j], is_deck ? deck : hull);
    }
    count = vertex_count() - first;
  }

  void build_water_grid() {
    const int n = 48;  // cells per side; fog is affine in position, so this only bounds its clamping error
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const float x0 = -1 + 2.f * i / n, x1 = -1 + 2.f * (i + 1) / n, y0 = -1 + 2.f * j / n,
                    y1 = -1 + 2.f * (j + 1) / n;
        water_grid.insert(water_grid.end(), {x0, y0, 0, x1, y0, 0, x1, y1, 0, x0, y0, 0, x1, y1, 0, x0, y1, 0});
      }
  }

  void setup_gl() {
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LEQUAL);
    gl.Enable(GL_LIGHTING);
    gl.Enable(GL_LIGHT0);
    gl.LightModeli(GL_LIGHT_MODEL_TWO_SIDE, 1);
    // Overcast arctic light: a strong ambient term keeps shaded floe sides readable, the sun gives them relief.
    const float d = (1 - kAmbient) / kSun[2];
    const float ambient[4] = {kAmbient, kAmbient, kAmbient, 1}, diffuse[4] = {d, d, d, 1}, zero[4] = {0, 0, 0, 1};
    gl.LightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);
    gl.Lightfv(GL_LIGHT0, GL_AMBIENT, zero);
    gl.Lightfv(GL_LIGHT0, GL_DIFFUSE, diffuse);
    gl.Lightfv(GL_LIGHT0, GL_SPECULAR, zero);
    gl.Enable(GL_COLOR_MATERIAL);
    gl.ColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
    gl.ShadeModel(GL_SMOOTH);  // the hull's corner normals; the floes and the water have one colour per face
    gl.BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);  // the side view's translucent water
    gl.Fogi(GL_FOG_MODE, GL_LINEAR);
    const float fogc[4] = {sky[0], sky[1], sky[2], 1};
    gl.Fogfv(GL_FOG_COLOR, fogc);
    gl.Fogf(GL_FOG_START, static_cast<float>(0.3 * o.view_distance_m));
    gl.Fogf(GL_FOG_END, static_cast<float>(o.view_distance_m));
    gl.Hint(GL_FOG_HINT, GL_NICEST);
    gl.LineWidth(static_cast<float>(std::max(1.0, 0.75 * o.supersample)));
    gl.Viewport(0, 0, ctx.width(), ctx.height());
  }

  Vec3 vessel_position(size_t k) const { return Vec3(&r.state_position_m[3 * vessel_row[k]]); }
  const double* vessel_quaternion(size_t k) const { return &r.state_quaternion[4 * vessel_row[k]]; }

  // The vessel's heading: its body x axis in the world, horizontal part (east if it points straight up or down).
  Vec3 heading(size_t k) const {
    const Mat4 m = pose_matrix(vessel_quaternion(k), Vec3::Zero());
    Vec2 fwd(m(0, 0), m(1, 0));
    fwd = fwd.norm() > 1e-6 ? fwd.normalized() : Vec2(1, 0);
    return Vec3(fwd.x(), fwd.y(), 0);
  }

  // Camera matrices of `view` for a viewport of the given aspect, in camera-relative world coordinates (origin =
  // vessel's horizontal position), so that floats in GL keep millimetres even kilometres from the world origin.
  void camera(size_t k, const std::string& name, double aspect, Mat4& proj, Mat4& view, Vec3& eye) const {
    if (name == "top") {
      const double altitude = 1000;
      eye = Vec3(0, 0, altitude);
      view = look_at(eye, Vec3(0, 0, 0), Vec3(0, 1, 0));
      proj = ortho(o.top_width_m / 2, o.top_width_m / 2 / aspect, 1, altitude + 500);
      return;
    }
    const Vec3 f = heading(k);
    if (name == "side") {
      // From the starboard beam looking to port, level: the bow to the right, the waterline at side_waterline of
      // the height from the top, the same metres per pixel across and up.
      const Vec3 across(-f.y(), f.x(), 0);  // to port
      const double half_w = o.side_width_m / 2, half_h = half_w / aspect, d = o.side_depth_m + 1000;
      eye = -d * across + Vec3(0, 0, half_h * (2 * o.side_waterline - 1));
      view = look_at(eye, eye + across, Vec3(0, 0, 1));
      proj = ortho(half_w, half_h, d - o.side_depth_m - 500, d + o.side_depth_m + 500);
      return;
    }
    const double pitch = o.chase_pitch_deg * kPi / 180;
    eye = -o.chase_distance_m * f + Vec3(0, 0, o.chase_height_m);
    const Vec3 dir = std::cos(pitch) * f - std::sin(pitch) * Vec3::UnitZ();
    const Vec3 up = o.chase_pitch_deg > 89.9 ? f : Vec3(0, 0, 1);
    view = look_at(eye, eye + dir, up);
    proj = perspective(o.fov_deg * kPi / 180, aspect, 0.5, o.view_distance_m);
  }

  // All views of results frame k into the GL buffer: cleared once, then each view in its viewport.
  void draw(size_t k) {
    gl.ClearColor(sky[0], sky[1], sky[2], 1);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    stats = FrameStats{};
    const int ss = o.supersample;
    for (const SubView& v : views) {
      // GL's viewport counts rows from the bottom.
      gl.Viewport(v.rect.x * ss, (o.height_px - v.rect.y - v.rect.height) * ss, v.rect.width * ss,
                  v.rect.height * ss);
      draw_view(k, v.view, double(v.rect.width) / v.rect.height);
    }
    const GLenum err = gl.GetError();
    FLOESIM_REQUIRE(err == GL_NO_ERROR, "OpenGL error 0x", std::hex, err, " while drawing frame ", std::dec, k);
  }

  // A vertical quad in the plane through the vessel across the view (camera-relative coordinates) from z = z0 to
  // z1, `half` metres either side along the heading, `ahead` metres towards the far side of the view.
  void draw_beam_quad(const Vec3& f, const Vec3& across, double half, double ahead, double z0, double z1) {
    const Vec3 c = ahead * across;
    const Vec3 q[4] = {c - half * f + Vec3(0, 0, z0), c + half * f + Vec3(0, 0, z0), c + half * f + Vec3(0, 0, z1),
                       c - half * f + Vec3(0, 0, z1)};
    float quad[18];
    int i = 0;
    for (int j : {0, 1, 2, 0, 2, 3})
      for (int d = 0; d < 3; ++d) quad[i++] = float(q[j][d]);
    gl.VertexPointer(3, GL_FLOAT, 0, quad);
    gl.DrawArrays(GL_TRIANGLES, 0, 6);
  }

  void draw_view(size_t k, const std::string& name, double aspect) {
    Mat4 proj, view;
    Vec3 eye;
    camera(k, name, aspect, proj, view, eye);
    const Vec3 vp = vessel_position(k);
    const Vec3 origin(vp.x(), vp.y(), 0);
    const bool chase = name == "chase", side = name == "side";
    const Vec3 f = heading(k), across(-f.y(), f.x(), 0);

    gl.MatrixMode(GL_PROJECTION);
    gl.LoadMatrixd(proj.data());
    gl.MatrixMode(GL_MODELVIEW);
    gl.LoadMatrixd(view.data());
    // A world direction: set while the modelview is the view matrix.
    const float sun[4] = {kSun[0], kSun[1], kSun[2], 0};
    gl.Lightfv(GL_LIGHT0, GL_POSITION, sun);
    if (chase && o.fog) gl.Enable(GL_FOG);
    else gl.Disable(GL_FOG);

    // The water surface hides everything below z = 0. Floes float only centimetres above it, closer than the
    // depth buffer resolves at a few hundred metres, so the water is not depth-tested against them: it is painted
    // first without writing depth, and every body is clipped at z = 0 by a user clip plane instead (exact).
    // The side view looks along the surface instead: it shows what is under water (floes pushed under the hull)
    // through a translucent layer drawn last, over a backdrop of water behind the scene.
    const GLdouble water_plane[4] = {0, 0, 1, 0};  // keeps z >= 0 (given while the modelview is the view matrix)
    gl.ClipPlane(GL_CLIP_PLANE0, water_plane);

    // Water: an unlit grid under the camera. A grid, not one big quad: fixed-function fog is computed per vertex,
    // and a quad whose corners all lie beyond the fog end would be fogged away entirely.
    gl.Disable(GL_LIGHTING);
    gl.EnableClientState(GL_VERTEX_ARRAY);
    gl.DepthMask(GL_FALSE);
    gl.Color4f(water[0], water[1], water[2], 1);
    if (side) {
      draw_beam_quad(f, across, o.side_width_m, o.side_depth_m + 400, -1e4, 0);
    } else {
      const double s = chase ? 1.5 * o.view_distance_m : o.top_width_m;
      Mat4 t = Mat4::Identity();
      t(0, 0) = t(1, 1) = s;
      t(0, 3) = eye.x();
      t(1, 3) = eye.y();
      const Mat4 mv = view * t;
      gl.LoadMatrixd(mv.data());
      gl.VertexPointer(3, GL_FLOAT, 0, water_grid.data());
      gl.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(water_grid.size() / 3));
    }
    gl.DepthMask(GL_TRUE);
    if (!side) gl.Enable(GL_CLIP_PLANE0);

    // Floes: the visible ones are posed on the CPU into one batch and drawn with a single call. llvmpipe costs
    // ~20-40 us per draw call, so one call per floe (glMultMatrix of its pose) spent most of a 1000-floe frame in
    // call overhead; rotating ~100k vertices here costs about a millisecond.
    const Frustum frustum(proj * view);
    batch_pos.clear();
    const Eigen::Vector3f sun_dir(kSun[0], kSun[1], kSun[2]);
    const float diffuse = (1 - kAmbient) / kSun[2];
    batch_col.clear();
    edge_pos.clear();
    const bool ortho_view = !chase;
    // Towards the viewer: the eye for the perspective view, the view's back direction for the orthographic ones.
    const Eigen::Vector3f eye_f = eye.cast<float>(), to_viewer = view.block<1, 3>(2, 0).transpose().cast<float>();
    gl.LoadMatrixd(view.data());
    replay->seek(k);
    for (size_t i = 0; i < replay->rows().size(); ++i) {
      const int64_t row = replay->rows()[i];
      const int32_t g = replay->floes()[i];
      if (g < 0) continue;
      const Vec3 c = Vec3(&r.state_position_m[3 * row]) - origin;
      // The side view shows a slab of the field about the vessel's centre plane (a floe is in it or not, whole).
      if (frustum.outside(c, floes[g].radius) || (side && std::abs(c.dot(across)) > o.side_depth_m)) {
        ++stats.floes_culled;
        continue;
      }
      ++stats.floes_drawn;
      const double* q = &r.state_quaternion[4 * row];
      const Eigen::Matrix3f rot =
          Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix().cast<float>();
      const Eigen::Vector3f t = c.cast<float>();
      const FloeDraw& f = floes[g];
      // The same directional light as the fixed-function hull, evaluated here per face: unlit vertices are
      // cheaper for llvmpipe, and the batch needs no normals. `top` replaces the prebuilt colour (contact).
      auto emit = [&](GLint v0, GLint n, const Eigen::Vector3f& normal, const float* top) {
        const float light = std::min(1.0f, kAmbient + diffuse * std::max(0.0f, normal.dot(sun_dir)));
        const uint8_t* c0 = &col[4 * v0];
        uint8_t rgba[4] = {uint8_t(c0[0] * light + 0.5f), uint8_t(c0[1] * light + 0.5f),
                           uint8_t(c0[2] * light + 0.5f), 255};
        if (top)
          for (int i = 0; i < 3; ++i)
            rgba[i] = uint8_t(std::lround(255 * std::clamp(top[i] * f.shade * light, 0.f, 1.f)));
        for (GLint v = v0; v < v0 + n; ++v) {
          const Eigen::Vector3f p = rot * Eigen::Map<const Eigen::Vector3f>(&pos[3 * v]) + t;
          batch_pos.insert(batch_pos.end(), {p.x(), p.y(), p.z()});
          batch_col.insert(batch_col.end(), rgba, rgba + 4);
        }
      };
      const bool touching = o.show_contact && !f.sheet && r.state_in_contact[row] != 0;
      emit(f.first, f.top_count, rot.col(2), touching ? contact : nullptr);
      // Sides facing away from the camera are hidden by the slab itself: dropping them here halves the side
      // triangles (and in the top view, looking straight down, all of them).
      for (GLint v0 = f.first + f.top_count; v0 < f.first + f.count; v0 += 6) {
        const Eigen::Vector3f n = rot * Eigen::Map<const Eigen::Vector3f>(&nrm[3 * v0]);
        const Eigen::Vector3f p = rot * Eigen::Map<const Eigen::Vector3f>(&pos[3 * v0]) + t;
        const float facing = ortho_view ? n.dot(to_viewer) : n.dot(eye_f - p);
        if (facing > 1e-4f) emit(v0, 6, n, nullptr);
      }
      if (o.floe_edges) {
        // The outline as GL_LINES pairs, so that all floes go in one call too.
        const size_t e0 = edge_pos.size();
        for (GLint v = f.ring_first; v < f.ring_first + f.ring_count; ++v) {
          const Eigen::Vector3f p = rot * Eigen::Map<const Eigen::Vector3f>(&pos[3 * v]) + t;
          if (v > f.ring_first) edge_pos.insert(edge_pos.end(), {p.x(), p.y(), p.z()});
          edge_pos.insert(edge_pos.end(), {p.x(), p.y(), p.z()});
        }
        edge_pos.insert(edge_pos.end(), edge_pos.begin() + static_cast<long>(e0),
                        edge_pos.begin() + static_cast<long>(e0) + 3);  // close the ring
      }
    }
    // Still unlit (as the water): the batch carries lit colours.
    if (!batch_pos.empty()) {
      gl.EnableClientState(GL_COLOR_ARRAY);
      gl.VertexPointer(3, GL_FLOAT, 0, batch_pos.data());
      gl.ColorPointer(4, GL_UNSIGNED_BYTE, 0, batch_col.data());
      gl.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(batch_pos.size() / 3));
      gl.DisableClientState(GL_COLOR_ARRAY);
    }

    // Outlines over the top faces.
    if (!edge_pos.empty()) {
      gl.Color4f(edge[0], edge[1], edge[2], 1);
      gl.VertexPointer(3, GL_FLOAT, 0, edge_pos.data());
      gl.DrawArrays(GL_LINES, 0, static_cast<GLsizei>(edge_pos.size() / 3));
    }
    gl.Enable(GL_LIGHTING);

    // Hull.
    if (hull_count > 0) {
      gl.EnableClientState(GL_NORMAL_ARRAY);
      gl.EnableClientState(GL_COLOR_ARRAY);
      gl.VertexPointer(3, GL_FLOAT, 0, pos.data());
      gl.NormalPointer(GL_FLOAT, 0, nrm.data());
      gl.ColorPointer(4, GL_UNSIGNED_BYTE, 0, col.data());
      const Mat4 mv = view * pose_matrix(vessel_quaternion(k), vp - origin);
      gl.LoadMatrixd(mv.data());
      gl.DrawArrays(GL_TRIANGLES, hull_first, hull_count);
      // The structures at frame k's step (k + 1 output intervals), moved into the run's frame.
      const size_t row = static_cast<size_t>(std::llround((static_cast<double>(k) + 1) * steps_per_frame)) - 1;
      const double t = r.frame_time_s[k];
      for (const StructureMesh& m : structures) {
        if (m.count == 0 || 4 * row + 3 >= m.quaternion->size()) continue;
        const Vec3 x = Vec3(&(*m.position)[3 * row]) - t * m.frame_velocity;
        const Mat4 ms = view * pose_matrix(&(*m.quaternion)[4 * row], x - origin);
        gl.LoadMatrixd(ms.data());
        gl.DrawArrays(GL_TRIANGLES, m.first, m.count);
      }
    }
    gl.DisableClientState(GL_COLOR_ARRAY);
    gl.DisableClientState(GL_NORMAL_ARRAY);
    gl.Disable(GL_CLIP_PLANE0);

    // Side view: the water in front of everything under the surface, translucent (what is under it shows, tinted).
    if (side) {
      gl.Disable(GL_LIGHTING);
      gl.Disable(GL_DEPTH_TEST);
      gl.Enable(GL_BLEND);
      gl.LoadMatrixd(view.data());
      gl.Color4f(water[0], water[1], water[2], kSideWaterAlpha);
      draw_beam_quad(f, across, o.side_width_m, 0, -1e4, 0);
      gl.Disable(GL_BLEND);
      gl.Enable(GL_DEPTH_TEST);
      gl.Enable(GL_LIGHTING);
    }
    gl.DisableClientState(GL_VERTEX_ARRAY);
  }

  // Vessel speed over ground from the stored frames (centred difference where possible).
  double speed(size_t k) const {
    if (r.frames() < 2) return std::nan("");
    const size_t a = k == 0 ? 0 : k - 1, b = std::min(k + 1, r.frames() - 1);
    const double dt = r.frame_time_s[b] - r.frame_time_s[a];
    if (!(dt > 0)) return std::nan("");
    const Vec3 d = vessel_position(b) - vessel_position(a);
    return std::hypot(d.x(), d.y()) / dt;
  }

  void overlay(size_t k, cv::Mat& img) const {
    const double s = img.rows / 720.0;  // text scales with the frame
    const int font = cv::FONT_HERSHEY_SIMPLEX;
    const int thick = std::max(1, int(std::lround(1.6 * s)));
    std::vector<std::string> lines = {"t = " + fmt("%.2f s", r.frame_time_s[k]),
                                      "frame " + std::to_string(k + 1) + " / " + std::to_string(r.frames()) +
                                          playback_label};
    const double v = speed(k);
    if (std::isfinite(v)) lines.push_back("speed " + fmt("%.2f m/s", v) + " (" + fmt("%.1f kn", v * 3600 / 1852) + ")");
    // Only for runs in which ice broke: without fracture a constant 0 says nothing.
    if (!r.fracture_time_s.empty()) {
      const auto so_far = std::upper_bound(r.fracture_time_s.begin(), r.fracture_time_s.end(), r.frame_time_s[k]);
      lines.push_back("fracture events " + std::to_string(so_far - r.fracture_time_s.begin()));
    }
    const double scales[4] = {0.9 * s, 0.6 * s, 0.6 * s, 0.6 * s};
    int w = 0, h = int(12 * s);
    std::vector<int> heights;
    for (size_t i = 0; i < lines.size(); ++i) {
      int base = 0;
      const cv::Size sz = cv::getTextSize(lines[i], font, scales[i], thick, &base);
      w = std::max(w, sz.width);
      heights.push_back(sz.height);
      h += sz.height + int(12 * s);
    }
    const cv::Rect box(int(16 * s), int(16 * s), w + int(28 * s), h);
    cv::Mat roi = img(box & cv::Rect(0, 0, img.cols, img.rows));
    roi *= 0.45;  // darken: translucent panel, readable on ice and on water
    int y = box.y + int(12 * s);
    for (size_t i = 0; i < lines.size(); ++i) {
      y += heights[i];
      cv::putText(img, lines[i], {box.x + int(14 * s), y}, font, scales[i], cv::Scalar(255, 255, 255), thick,
                  cv::LINE_AA);
      y += int(12 * s);
    }
    // A scale bar and a north arrow in each top view (above the strip chart, which covers the frame's bottom).
    const int bottom = o.strip_chart ? strip_chart_top(o, img.rows) : img.rows;
    for (const SubView& v : views)
      if (v.view == "top") top_view_marks(img, v.rect, std::min(bottom, v.rect.y + v.rect.height), s, thick);
  }

  // Scale bar of a round length near 15 % of the view's width at its bottom-left, a north arrow at its top-right.
  void top_view_marks(cv::Mat& img, const cv::Rect& view, int bottom, double s, int thick) const {
    const int font = cv::FONT_HERSHEY_SIMPLEX;
    const double px_per_m = view.width / o.top_width_m;
    const double target = 0.15 * view.width / px_per_m;
    double len = std::pow(10.0, std::floor(std::log10(target)));
    for (double m : {5.0, 2.0})
      if (len * m <= target) {
        len *= m;
        break;
      }
    const int x0 = view.x + int(24 * s), y0 = bottom - int(28 * s), x1 = x0 + int(std::lround(len * px_per_m));
    cv::rectangle(img, {x0 - int(8 * s), y0 - int(34 * s)}, {x1 + int(8 * s), y0 + int(12 * s)},
                  cv::Scalar(20, 20, 20), cv::FILLED);
    cv::rectangle(img, {x0, y0 - int(4 * s)}, {x1, y0 + int(4 * s)}, cv::Scalar(255, 255, 255), cv::FILLED);
    cv::putText(img, fmt("%g m", len), {x0, y0 - int(12 * s)}, font, 0.6 * s, cv::Scalar(255, 255, 255), thick,
                cv::LINE_AA);
    const int xr = view.x + view.width - int(40 * s);
    const cv::Point n0(xr, view.y + int(80 * s)), n1(xr, view.y + int(30 * s));
    cv::arrowedLine(img, n0, n1, cv::Scalar(255, 255, 255), std::max(2, thick), cv::LINE_AA, 0, 0.35);
    cv::putText(img, "N", {n0.x - int(9 * s), n0.y + int(24 * s)}, font, 0.6 * s, cv::Scalar(255, 255, 255), thick,
                cv::LINE_AA);
  }

  // A split frame: a dark line between its halves.
  void separate_halves(cv::Mat& img) const {
    if (views.size() < 2) return;
    const cv::Rect& b = views[1].rect;
    const int w = std::max(2, int(std::lround(3 * img.rows / 720.0)));
    if (b.x > 0) cv::line(img, {b.x, 0}, {b.x, img.rows}, cv::Scalar(30, 30, 30), w);
    else cv::line(img, {0, b.y}, {img.cols, b.y}, cv::Scalar(30, 30, 30), w);
  }
};

std::vector<bool> hull_internal_faces(const std::vector<double>& v, const std::vector<int32_t>& t) {
  const size_t nt = t.size() / 3;
  auto corner = [&](size_t k, int j) { return Eigen::Vector3d(&v[3 * static_cast<size_t>(t[3 * k + j])]); };
  // Planes keyed by a sign-canonical unit normal (to 1e-3) and offset (to 1 mm).
  std::vector<std::pair<std::array<int64_t, 4>, size_t>> plane(nt);
  std::vector<Eigen::Vector3d> normal(nt);
  for (size_t k = 0; k < nt; ++k) {
    Eigen::Vector3d n = (corner(k, 1) - corner(k, 0)).cross(corner(k, 2) - corner(k, 0));
    n = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
    const int lead = std::abs(n.x()) > 0.5 ? 0 : (std::abs(n.y()) > 0.5 ? 1 : 2);
    if (n[lead] < 0) n = -n;
    normal[k] = n;
    plane[k] = {{std::llround(1000 * n.x()), std::llround(1000 * n.y()), std::llround(1000 * n.z()),
                 std::llround(1000 * n.dot(corner(k, 0)))},
                k};
  }
  std::sort(plane.begin(), plane.end());
  std::vector<bool> internal(nt, false);
  for (size_t a = 0; a < nt;) {
    size_t b = a;
    while (b < nt && plane[b].first == plane[a].first) ++b;
    for (size_t i = a; i < b; ++i) {
      const size_t f = plane[i].second;
      if (normal[f].isZero()) continue;
      const Eigen::Vector3d c = (corner(f, 0) + corner(f, 1) + corner(f, 2)) / 3;
      for (size_t j = a; j < b && !internal[f]; ++j) {
        const size_t g = plane[j].second;
        if (g == f) continue;
        // Inside g or on its boundary (the centroid of one part's triangle may lie on the other part's diagonal);
        // never true for a neighbour that only shares an edge, since a centroid is strictly inside its triangle.
        const Eigen::Vector3d p0 = corner(g, 0), p1 = corner(g, 1), p2 = corner(g, 2);
        const Eigen::Vector3d ng = (p1 - p0).cross(p2 - p0);
        if (ng.norm() <= 0) continue;
        const Eigen::Vector3d u = ng.normalized();
        const double e0 = (p1 - p0).cross(c - p0).dot(u) / (p1 - p0).norm();
        const double e1 = (p2 - p1).cross(c - p1).dot(u) / (p2 - p1).norm();
        const double e2 = (p0 - p2).cross(c - p2).dot(u) / (p0 - p2).norm();
        internal[f] = e0 > -1e-6 && e1 > -1e-6 && e2 > -1e-6;
      }
    }
    a = b;
  }
  return internal;
}


SceneRenderer::SceneRenderer(const Results& r, const RenderOptions& o, const std::string& source)
    : impl_(std::make_unique<Impl>(r, o, source)) {}

SceneRenderer::~SceneRenderer() = default;

void SceneRenderer::render(size_t frame, cv::Mat& out) {
  FLOESIM_REQUIRE(frame < impl_->r.frames(), "internal: frame ", frame, " of ", impl_->r.frames());
  impl_->draw(frame);
  Impl& m = *impl_;
  m.ctx.frame_rgba_top_down(m.big);
  // Downsample first (box filter over the supersamples), then convert the small image only.
  const cv::Mat* small = &m.big;
  if (m.o.supersample > 1) {
    cv::resize(m.big, m.small, cv::Size(m.o.width_px, m.o.height_px), 0, 0, cv::INTER_AREA);
    small = &m.small;
  }
  cv::cvtColor(*small, out, cv::COLOR_RGBA2BGR);
  m.separate_halves(out);
  if (m.strip) m.strip->draw(out, m.r.frame_time_s[frame]);
  if (m.o.overlay) m.overlay(frame, out);
}

const FrameStats& SceneRenderer::last_stats() const { return impl_->stats; }

std::string SceneRenderer::gl_renderer() const { return impl_->ctx.renderer(); }

void floe_top_colour(const RenderOptions& o, int32_t origin_mode, int32_t generation, float rgb[3]) {
  switch (origin_mode) {
    case kFractureNone: parse_hex_colour(o.floe_top_colour, rgb); return;
    case kFractureBending:
    case kFractureRadial: parse_hex_colour(o.bending_piece_colour, rgb); break;
    case kFractureSplitting: parse_hex_colour(o.splitting_piece_colour, rgb); break;
    case kFractureCrushing: parse_hex_colour(o.floe_top_colour, rgb); return;  // the sheet, its crushed ice cleared
    default: throw Error("floe origin mode " + std::to_string(origin_mode) + " is not 0..4 (see FractureMode)");
  }
  const float dim = 1.0f - 0.15f * float(std::clamp(generation, 1, 4) - 1);
  for (int i = 0; i < 3; ++i) rgb[i] *= dim;
}

double playback_speed(const Results& r, double fps) {
  double every = r.attributes.value("output_interval_s", 0.0);
  if (!(every > 0) && r.frames() >= 2) every = r.frame_time_s[1] - r.frame_time_s[0];
  return every > 0 && fps > 0 ? every * fps : std::nan("");
}

cv::Point2d top_view_pixel(const Results& r, const RenderOptions& o, size_t frame, double x_m, double y_m) {
  FLOESIM_REQUIRE(frame < r.frames(), "internal: frame ", frame, " of ", r.frames());
  double vx = 0, vy = 0;
  for (int64_t row = r.frame_offset[frame]; row < r.frame_offset[frame + 1]; ++row)
    if (r.state_body_id[row] == 0) vx = r.state_position_m[3 * row], vy = r.state_position_m[3 * row + 1];
  const double px_per_m = o.width_px / o.top_width_m;
  return {o.width_px / 2.0 + (x_m - vx) * px_per_m, o.height_px / 2.0 - (y_m - vy) * px_per_m};
}

}  // namespace floesim::render
