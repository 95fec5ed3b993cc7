#include "sim/geometry/mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <Eigen/Geometry>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"

namespace floesim::sim {

namespace {

// Half the bounding-box diagonal and its centre: the length scale for relative tolerances, and a reference point
// that keeps sums of products well conditioned for meshes far from the origin.
struct Box {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  void add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Vec3 centre() const { return 0.5 * (lo + hi); }
  double diagonal() const { return (hi - lo).norm(); }
};

Box box_of(const std::vector<Vec3>& v) {
  Box b;
  for (const Vec3& p : v) b.add(p);
  return b;
}

// Eberly's subexpressions for the polyhedral integrals of one coordinate over a triangle.
struct Sub {
  double f1, f2, f3, g0, g1, g2;
};
Sub subexpressions(double w0, double w1, double w2) {
  const double t0 = w0 + w1, t1 = w0 * w0, t2 = t1 + w1 * t0;
  Sub s;
  s.f1 = t0 + w2;
  s.f2 = t2 + w2 * s.f1;
  s.f3 = w0 * t1 + w1 * t2 + w2 * s.f2;
  s.g0 = s.f2 + w0 * (s.f1 + w0);
  s.g1 = s.f2 + w1 * (s.f1 + w1);
  s.g2 = s.f2 + w2 * (s.f1 + w2);
  return s;
}

}  // namespace

MassProperties mass_properties(const TriMesh& m) {
  MassProperties mp;
  if (m.vertices.empty() || m.triangles.empty()) return mp;
  // Integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz, zx over the enclosed volume (Eberly, "Polyhedral Mass
  // Properties (Revisited)", 2002, itself Mirtich's algorithm via the divergence theorem), relative to `ref`.
  const Vec3 ref = box_of(m.vertices).centre();
  double in[10] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  for (const auto& t : m.triangles) {
    const Vec3 p0 = m.vertices[t[0]] - ref, p1 = m.vertices[t[1]] - ref, p2 = m.vertices[t[2]] - ref;
    const Vec3 d = (p1 - p0).cross(p2 - p0);
    const Sub x = subexpressions(p0.x(), p1.x(), p2.x());
    const Sub y = subexpressions(p0.y(), p1.y(), p2.y());
    const Sub z = subexpressions(p0.z(), p1.z(), p2.z());
    in[0] += d.x() * x.f1;
    in[1] += d.x() * x.f2;
    in[2] += d.y() * y.f2;
    in[3] += d.z() * z.f2;
    in[4] += d.x() * x.f3;
    in[5] += d.y() * y.f3;
    in[6] += d.z() * z.f3;
    in[7] += d.x() * (p0.y() * x.g0 + p1.y() * x.g1 + p2.y() * x.g2);
    in[8] += d.y() * (p0.z() * y.g0 + p1.z() * y.g1 + p2.z() * y.g2);
    in[9] += d.z() * (p0.x() * z.g0 + p1.x() * z.g1 + p2.x() * z.g2);
  }
  const double mult[10] = {1. / 6, 1. / 24, 1. / 24, 1. / 24, 1. / 60, 1. / 60, 1. / 60, 1. / 120, 1. / 120, 1. / 120};
  for (int i = 0; i < 10; ++i) in[i] *= mult[i];
  const double V = in[0];
  mp.volume = V;
  if (V == 0) {
    mp.centroid = ref;
    return mp;
  }
  const Vec3 c(in[1] / V, in[2] / V, in[3] / V);
  mp.centroid = ref + c;
  // Second moments about the centroid (parallel-axis shift from `ref`); products of inertia enter the tensor
  // with a minus sign, so that L = I w.
  const double xx = in[4] - V * c.x() * c.x(), yy = in[5] - V * c.y() * c.y(), zz = in[6] - V * c.z() * c.z();
  const double xy = in[7] - V * c.x() * c.y(), yz = in[8] - V * c.y() * c.z(), zx = in[9] - V * c.z() * c.x();
  mp.inertia << yy + zz, -xy, -zx,  //
      -xy, zz + xx, -yz,            //
      -zx, -yz, xx + yy;
  return mp;
}

Submerged submerged_part(const std::vector<Vec3>& v, const std::vector<std::array<int, 3>>& triangles, double z0) {
  Submerged s;
  if (v.empty()) return s;
  // Reference point on the water plane: every tetrahedron (ref, cap triangle) is flat, so the cap that closes the
  // submerged volume contributes nothing and need not be built.
  Box b = box_of(v);
  const Vec3 ref(b.centre().x(), b.centre().y(), z0);
  double vol6 = 0;
  Vec3 moment = Vec3::Zero();  // sum of 6 V_tet * 4 centroid_tet (relative to ref)
  double area2 = 0;            // twice the waterplane area
  Vec3 poly[4];
  bool on_plane_after[4];  // the clipped polygon's edge k -> k+1 lies in the water plane
  for (const auto& t : triangles) {
    const Vec3* p[3] = {&v[t[0]], &v[t[1]], &v[t[2]]};
    double d[3];
    int below = 0;
    for (int k = 0; k < 3; ++k) {
      d[k] = p[k]->z() - z0;
      below += d[k] < 0;
    }
    if (below == 0) continue;
    int n = 0;
    if (below == 3) {
      for (int k = 0; k < 3; ++k) poly[n] = *p[k] - ref, on_plane_after[n++] = false;
    } else {
      // Sutherland-Hodgman against z < z0. The crossing point of an edge is always computed from its submerged
      // end, so both triangles sharing the edge get the same point and the waterline contour closes exactly.
      for (int k = 0; k < 3; ++k) {
        const int k1 = (k + 1) % 3;
        const bool in0 = d[k] < 0, in1 = d[k1] < 0;
        if (in0) poly[n] = *p[k] - ref, on_plane_after[n++] = false;
        if (in0 != in1) {
          const Vec3& a = in0 ? *p[k] : *p[k1];
          const Vec3& c = in0 ? *p[k1] : *p[k];
          const double da = in0 ? d[k] : d[k1], dc = in0 ? d[k1] : d[k];
          Vec3 x = a + (c - a) * (da / (da - dc));
          x.z() = z0;
          poly[n] = x - ref;
          on_plane_after[n++] = in0;  // leaving the water: the next polygon edge runs along the plane
        }
      }
    }
    for (int k = 1; k + 1 < n; ++k) {
      const double v6 = poly[0].dot(poly[k].cross(poly[k + 1]));
      vol6 += v6;
      moment += v6 * (poly[0] + poly[k] + poly[k + 1]);
    }
    // The cap closing the submerged solid runs each waterline segment backwards, counter-clockwise seen from
    // above (its outward normal is +z).
    for (int k = 0; k < n; ++k)
      if (on_plane_after[k]) {
        const Vec3& a = poly[k];
        const Vec3& c = poly[(k + 1) % n];
        area2 += c.x() * a.y() - a.x() * c.y();
      }
  }
  s.volume = vol6 / 6.0;
  s.waterplane_area = 0.5 * area2;
  s.centroid = vol6 != 0 ? Vec3(ref + moment / (4.0 * vol6)) : ref;
  return s;
}

// ---- convex hull: quickhull on triangles ------------------------------------------------------------------------

namespace {

struct HullFace {
  std::array<int, 3> v;   // CCW seen from outside
  std::array<int, 3> nb;  // neighbour across edge v[k] -> v[k+1]
  Vec3 n = Vec3::Zero();  // unit outward normal
  double d = 0;           // plane: n . x = d
  std::vector<int> outside;
  bool alive = true;
  int mark = -1;  // visit stamp
  bool visible = false;
};

class QuickHull {
 public:
  explicit QuickHull(const std::vector<Vec3>& pts) {
    FLOESIM_REQUIRE(pts.size() >= 4, "convex hull: needs at least 4 points, got ", pts.size());
    Box b;
    for (const Vec3& p : pts) {
      FLOESIM_REQUIRE(p.allFinite(), "convex hull: a point is not finite");
      b.add(p);
    }
    const Vec3 c = b.centre();
    for (const Vec3& p : pts) q_.push_back(p - c);  // centred: smaller numbers, smaller round-off
    origin_ = c;
    // Points closer than eps to a face's plane count as on it (dropped: they add nothing). eps is kept tiny: faces
    // built from points that are only nearly coplanar tilt by up to eps / (face size), and a far vertex then pokes
    // through the tilted plane by that angle times the hull size. Input read in single precision (assimp) is
    // noisy at ~1e-7 of its coordinates, far above eps, so such points are simply hull vertices. The floor is
    // round-off: a face of height >= eps has a normal good to ~1e-16 L / eps = 1e-6 rad.
    eps_ = 1e-10 * std::max(b.diagonal(), std::numeric_limits<double>::min());
  }

  TriMesh run() {
    initial_simplex();
    for (size_t fi = 0; fi < faces_.size(); ++fi) {
      if (!faces_[fi].alive || faces_[fi].outside.empty()) continue;
      add_point(static_cast<int>(fi));
    }
    TriMesh m;
    std::map<int, int> remap;
    for (const HullFace& f : faces_) {
      if (!f.alive) continue;
      std::array<int, 3> t;
      for (int k = 0; k < 3; ++k) {
        auto it = remap.find(f.v[k]);
        if (it == remap.end()) {
          it = remap.emplace(f.v[k], static_cast<int>(m.vertices.size())).first;
          m.vertices.push_back(q_[f.v[k]] + origin_);
        }
        t[k] = it->second;
      }
      m.triangles.push_back(t);
    }
    return m;
  }

 private:
  double dist(const HullFace& f, int p) const { return f.n.dot(q_[p]) - f.d; }

  int make_face(int a, int b, int c) {
    HullFace f;
    f.v = {a, b, c};
    f.nb = {-1, -1, -1};
    const Vec3 &A = q_[a], &B = q_[b], &C = q_[c];
    // The cross product of the two edges at the vertex opposite the longest edge is the best conditioned.
    const double lab = (B - A).squaredNorm(), lbc = (C - B).squaredNorm(), lca = (A - C).squaredNorm();
    Vec3 n;
    if (lab >= lbc && lab >= lca) n = (A - C).cross(B - C);
    else if (lbc >= lca) n = (B - A).cross(C - A);
    else n = (C - B).cross(A - B);
    const double len = n.norm();
    f.n = len > 0 ? Vec3(n / len) : Vec3::Zero();
    f.d = f.n.dot((A + B + C) / 3.0);
    faces_.push_back(std::move(f));
    return static_cast<int>(faces_.size()) - 1;
  }

  void initial_simplex() {
    const int n = static_cast<int>(q_.size());
    // The two farthest apart of the six axis-extreme points.
    std::array<int, 6> ext{};
    for (int k = 0; k < 3; ++k) {
      int lo = 0, hi = 0;
      for (int i = 1; i < n; ++i) {
        if (q_[i][k] < q_[lo][k]) lo = i;
        if (q_[i][k] > q_[hi][k]) hi = i;
      }
      ext[2 * k] = lo;
      ext[2 * k + 1] = hi;
    }
    int i0 = ext[0], i1 = ext[1];
    double best = -1;
    for (int a = 0; a < 6; ++a)
      for (int b = a + 1; b < 6; ++b) {
        const double d = (q_[ext[a]] - q_[ext[b]]).squaredNorm();
        if (d > best) best = d, i0 = ext[a], i1 = ext[b];
      }
    FLOESIM_REQUIRE(std::sqrt(best) > eps_, "convex hull: degenerate points (all coincide)");
    const Vec3 dir = (q_[i1] - q_[i0]).normalized();
    int i2 = -1;
    best = -1;
    for (int i = 0; i < n; ++i) {
      const Vec3 r = q_[i] - q_[i0];
      const double d = (r - dir * dir.dot(r)).norm();
      if (d > best) best = d, i2 = i;
    }
    FLOESIM_REQUIRE(best > eps_, "convex hull: degenerate points (all on one line)");
    const Vec3 nrm = (q_[i1] - q_[i0]).cross(q_[i2] - q_[i0]).normalized();
    int i3 = -1;
    best = -1;
    double side = 0;
    for (int i = 0; i < n; ++i) {
      const double d = nrm.dot(q_[i] - q_[i0]);
      if (std::abs(d) > best) best = std::abs(d), i3 = i, side = d;
    }
    FLOESIM_REQUIRE(best > eps_, "convex hull: degenerate points (all in one plane)");
    // Base (i0, i1, i2) must face away from i3.
    if (side > 0) std::swap(i1, i2);
    const int f0 = make_face(i0, i1, i2), f1 = make_face(i0, i3, i1), f2 = make_face(i1, i3, i2),
              f3 = make_face(i2, i3, i0);
    link({f0, f1, f2, f3});
    std::vector<int> all;
    for (int i = 0; i < n; ++i)
      if (i != i0 && i != i1 && i != i2 && i != i3) all.push_back(i);
    assign(all, {f0, f1, f2, f3});
  }

  // Neighbour links among a set of faces that together are closed.
  void link(const std::vector<int>& fs) {
    std::map<std::pair<int, int>, std::pair<int, int>> edge;
    for (int f : fs)
      for (int k = 0; k < 3; ++k) edge[{faces_[f].v[k], faces_[f].v[(k + 1) % 3]}] = {f, k};
    for (int f : fs)
      for (int k = 0; k < 3; ++k) {
        const auto it = edge.find({faces_[f].v[(k + 1) % 3], faces_[f].v[k]});
        FLOESIM_REQUIRE(it != edge.end(), "convex hull: internal error (open initial simplex)");
        faces_[f].nb[k] = it->second.first;
      }
  }

  // Each point goes to the outside set of the face it is farthest above (if above any by more than eps).
  void assign(const std::vector<int>& pts, const std::vector<int>& fs) {
    for (int p : pts) {
      int best_f = -1;
      double best_d = eps_;
      for (int f : fs) {
        const double d = dist(faces_[f], p);
        if (d > best_d) best_d = d, best_f = f;
      }
      if (best_f >= 0) faces_[best_f].outside.push_back(p);
    }
  }

  int edge_index(const HullFace& f, int from) const {
    for (int k = 0; k < 3; ++k)
      if (f.v[k] == from) return k;
    return -1;
  }

  // Horizon as a closed walk of (face, edge) pairs with the visible face on the left, in order: from the horizon
  // edge ending at vertex w, rotate around w through visible faces to the next horizon edge. This stays correct
  // when the visible region touches itself at a vertex.
  bool horizon_walk(const std::vector<int>& visible, std::vector<std::pair<int, int>>& walk) {
    walk.clear();
    int total = 0, f0 = -1, k0 = -1;
    for (int f : visible)
      for (int k = 0; k < 3; ++k)
        if (!faces_[faces_[f].nb[k]].visible) {
          ++total;
          if (f0 < 0) f0 = f, k0 = k;
        }
    if (total < 3) return false;
    int f = f0, k = k0;
    do {
      walk.emplace_back(f, k);
      if (static_cast<int>(walk.size()) > total) return false;
      const int w = faces_[f].v[(k + 1) % 3];
      int g = f, j = (k + 1) % 3;  // edge of g leaving w
      int guard = 0;
      while (faces_[faces_[g].nb[j]].visible) {
        g = faces_[g].nb[j];
        j = edge_index(faces_[g], w);
        if (j < 0 || ++guard > static_cast<int>(faces_.size())) return false;
      }
      f = g, k = j;
    } while (!(f == f0 && k == k0));
    return static_cast<int>(walk.size()) == total;
  }

  void add_point(int fi) {
    const HullFace& start = faces_[fi];
    int p = start.outside[0];
    for (int i : start.outside)
      if (dist(start, i) > dist(start, p)) p = i;

    // Visible region: faces reachable from the start face across faces that see p.
    ++stamp_;
    std::vector<int> visible{fi};
    faces_[fi].mark = stamp_;
    faces_[fi].visible = true;
    for (size_t h = 0; h < visible.size(); ++h)
      for (int g : faces_[visible[h]].nb) {
        HullFace& G = faces_[g];
        if (G.mark == stamp_) continue;
        G.mark = stamp_;
        // Visible unless p is clearly below: then every horizon edge is convex by a margin of at least eps and the
        // new face over it has a height of at least eps (no slivers with ill-defined planes).
        G.visible = dist(G, p) > -eps_;
        if (G.visible) visible.push_back(g);
      }
    std::vector<std::pair<int, int>> walk;
    if (!horizon_walk(visible, walk)) {
      // Round-off left islands of "invisible" faces inside the visible region: keep only the invisible component
      // that holds the face farthest below p, the rest becomes visible.
      fill_islands(p, visible);
      FLOESIM_REQUIRE(horizon_walk(visible, walk),
                      "convex hull: numerical failure (inconsistent visibility); the points are too degenerate");
    }

    const int m = static_cast<int>(walk.size());
    std::vector<int> created(m);
    for (int i = 0; i < m; ++i) {
      const auto [f, k] = walk[i];
      created[i] = make_face(faces_[f].v[k], faces_[f].v[(k + 1) % 3], p);
    }
    for (int i = 0; i < m; ++i) {
      const auto [f, k] = walk[i];
      HullFace& F = faces_[created[i]];
      const int other = faces_[f].nb[k];
      F.nb = {other, created[(i + 1) % m], created[(i + m - 1) % m]};
      HullFace& O = faces_[other];
      O.nb[edge_index(O, F.v[1])] = created[i];
    }
    std::vector<int> orphans;
    for (int f : visible) {
      HullFace& F = faces_[f];
      for (int i : F.outside)
        if (i != p) orphans.push_back(i);
      F.outside.clear();
      F.outside.shrink_to_fit();
      F.alive = false;
      F.visible = false;
    }
    assign(orphans, created);
  }

  void fill_islands(int p, std::vector<int>& visible) {
    int deepest = -1;
    double dmin = std::numeric_limits<double>::infinity();
    for (size_t f = 0; f < faces_.size(); ++f)
      if (faces_[f].alive && !faces_[f].visible) {
        const double d = dist(faces_[f], p);
        if (d < dmin) dmin = d, deepest = static_cast<int>(f);
      }
    FLOESIM_REQUIRE(deepest >= 0, "convex hull: numerical failure (every face sees a point)");
    ++stamp_;
    std::vector<int> keep{deepest};
    faces_[deepest].mark = stamp_;
    for (size_t h = 0; h < keep.size(); ++h)
      for (int g : faces_[keep[h]].nb)
        if (faces_[g].mark != stamp_ && !faces_[g].visible) {
          faces_[g].mark = stamp_;
          keep.push_back(g);
        }
    for (size_t f = 0; f < faces_.size(); ++f)
      if (faces_[f].alive && !faces_[f].visible && faces_[f].mark != stamp_) {
        faces_[f].visible = true;
        visible.push_back(static_cast<int>(f));
      }
  }

  std::vector<Vec3> q_;
  Vec3 origin_ = Vec3::Zero();
  double eps_ = 0;
  std::vector<HullFace> faces_;
  int stamp_ = 0;
};

}  // namespace

TriMesh convex_hull(const std::vector<Vec3>& points) { return QuickHull(points).run(); }

bool is_convex(const TriMesh& m, double tol) {
  if (m.triangles.empty()) return false;
  const double diag = box_of(m.vertices).diagonal();
  // A zero-area triangle has no plane; skip it (it cannot make a closed mesh non-convex on its own).
  const double min_cross = 1e-14 * diag * diag;
  for (const auto& t : m.triangles) {
    const Vec3& a = m.vertices[t[0]];
    const Vec3 n = (m.vertices[t[1]] - a).cross(m.vertices[t[2]] - a);
    const double len = n.norm();
    if (len <= min_cross) continue;
    const Vec3 u = n / len;
    for (const Vec3& p : m.vertices)
      if (u.dot(p - a) > tol) return false;
  }
  return true;
}

TriMesh extrude_polygon(const std::vector<Eigen::Vector2d>& ccw_polygon, double z_bottom, double h) {
  FLOESIM_REQUIRE(h > 0, "extrude_polygon: thickness must be > 0, got ", h);
  FLOESIM_REQUIRE(ccw_polygon.size() >= 3, "extrude_polygon: polygon needs at least 3 vertices");
  FLOESIM_REQUIRE(signed_area(ccw_polygon) > 0, "extrude_polygon: polygon must be counter-clockwise");
  const int n = static_cast<int>(ccw_polygon.size());
  TriMesh m;
  for (const auto& p : ccw_polygon) m.vertices.emplace_back(p.x(), p.y(), z_bottom);
  for (const auto& p : ccw_polygon) m.vertices.emplace_back(p.x(), p.y(), z_bottom + h);
  // Caps: fans over convex pieces; every polygon vertex stays a cap vertex, so the slab is closed.
  std::map<std::pair<double, double>, int> index;
  for (int i = 0; i < n; ++i) index.emplace(std::make_pair(ccw_polygon[i].x(), ccw_polygon[i].y()), i);
  for (const Polygon& piece : convex_decompose(ccw_polygon)) {
    std::vector<int> id;
    for (const Vec2& v : piece) id.push_back(index.at({v.x(), v.y()}));
    for (size_t k = 1; k + 1 < id.size(); ++k) {
      m.triangles.push_back({n + id[0], n + id[k], n + id[k + 1]});  // top, normal +z
      m.triangles.push_back({id[0], id[k + 1], id[k]});              // bottom, normal -z
    }
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.triangles.push_back({i, j, n + j});
    m.triangles.push_back({i, n + j, n + i});
  }
  return m;
}

}  // namespace floesim::sim
