// Small geometric kernels of the simulation core: planar polygons in 3D (area, clipping at a plane)
// and convex polygons in 2D (hull, intersection). Header-only, allocation-free when given scratch buffers.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "pipeline/geometry2d.h"

namespace floesim::sim {

using Vec3 = Eigen::Vector3d;

// Area and centroid of a planar polygon in 3D (any orientation).
struct AreaCentroid {
  double area = 0;
  Vec3 centroid = Vec3::Zero();
};

inline AreaCentroid polygon_area_centroid(const Vec3* p, int n) {
  AreaCentroid r;
  if (n < 3) return r;
  // Fan from p[0]: the vector area of each triangle, projected on the total normal, gives signed weights that
  // handle any (planar, simple) polygon.
  Vec3 total = Vec3::Zero();
  for (int i = 1; i + 1 < n; ++i) total += (p[i] - p[0]).cross(p[i + 1] - p[0]);
  const double twice = total.norm();
  if (twice <= 0) return r;
  const Vec3 nrm = total / twice;
  Vec3 c = Vec3::Zero();
  for (int i = 1; i + 1 < n; ++i) {
    const double w = (p[i] - p[0]).cross(p[i + 1] - p[0]).dot(nrm);
    c += w * (p[0] + p[i] + p[i + 1]) / 3.0;
  }
  r.area = 0.5 * twice;
  r.centroid = c / twice;
  return r;
}

// Part of the polygon p[0..n) with z <= z0 (below = true) or z >= z0 (below = false), written to out.
inline void clip_polygon_z(const Vec3* p, int n, double z0, bool below, std::vector<Vec3>& out) {
  out.clear();
  auto inside = [&](const Vec3& v) { return below ? v.z() <= z0 : v.z() >= z0; };
  for (int i = 0; i < n; ++i) {
    const Vec3& a = p[i];
    const Vec3& b = p[(i + 1) % n];
    const bool ia = inside(a), ib = inside(b);
    if (ia) out.push_back(a);
    if (ia != ib) {
      const double t = (z0 - a.z()) / (b.z() - a.z());
      out.push_back(a + t * (b - a));
    }
  }
}

// The same into a caller's array of at least n + 1 points for a convex polygon (it gains at most one vertex), 2 n
// for any other (each edge gives at most two points); returns the count.
inline int clip_polygon_z(const Vec3* p, int n, double z0, bool below, Vec3* out) {
  int k = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3& a = p[i];
    const Vec3& b = p[i + 1 == n ? 0 : i + 1];
    const bool ia = below ? a.z() <= z0 : a.z() >= z0;
    const bool ib = below ? b.z() <= z0 : b.z() >= z0;
    if (ia) out[k++] = a;
    if (ia != ib) out[k++] = a + ((z0 - a.z()) / (b.z() - a.z())) * (b - a);
  }
  return k;
}

// The parts of the polygon p[0..n) in the half-spaces u.x <= d (below) and u.x >= d (above), in one pass: each
// vertex's signed distance is computed once (any plane; clip_polygon_z is z alone). A point on the plane is in
// both. `above` is bit for bit what clipping by the flipped plane (-u, -d) gives: that plane's distances are the
// exact negations of these, and an edge's crossing point a + (s_a / (s_a - s_b)) (b - a) is the same with both
// distances negated. Each edge gives at most two points, so the outputs are sized once and written by index (no
// push_back in the loop: this runs for every face of every crushing contact, twice per step).
inline void split_polygon_plane(const Vec3* p, int n, const Vec3& u, double d, std::vector<Vec3>& below,
                                std::vector<Vec3>& above) {
  below.resize(2 * static_cast<size_t>(n));
  above.resize(2 * static_cast<size_t>(n));
  int kb = 0, ka = 0;
  double sb = n > 0 ? u.dot(p[0]) - d : 0;  // the distance of the edge's end, carried to the next edge's start
  for (int i = 0; i < n; ++i) {
    const Vec3& a = p[i];
    const Vec3& b = p[i + 1 == n ? 0 : i + 1];
    const double sa = sb;
    sb = u.dot(b) - d;
    if (sa <= 0) below[kb++] = a;
    if (sa >= 0) above[ka++] = a;
    const bool cross_below = (sa <= 0) != (sb <= 0), cross_above = (sa >= 0) != (sb >= 0);
    if (cross_below || cross_above) {
      const Vec3 x = a + (sa / (sa - sb)) * (b - a);
      if (cross_below) below[kb++] = x;
      if (cross_above) above[ka++] = x;
    }
  }
  below.resize(kb);
  above.resize(ka);
}

// 2D cross product of (b - a) and (c - a).
inline double cross2(const Vec2& a, const Vec2& b, const Vec2& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// Intersection of two convex CCW polygons (Sutherland-Hodgman: clip a by each edge of b).
inline Polygon clip_convex_2d(const Polygon& a, const Polygon& b) {
  Polygon out = a, in;
  const size_t m = b.size();
  for (size_t j = 0; j < m && !out.empty(); ++j) {
    const Vec2& e0 = b[j];
    const Vec2& e1 = b[(j + 1) % m];
    in.swap(out);
    out.clear();
    for (size_t i = 0; i < in.size(); ++i) {
      const Vec2& p = in[i];
      const Vec2& q = in[(i + 1) % in.size()];
      const double sp = cross2(e0, e1, p), sq = cross2(e0, e1, q);
      if (sp >= 0) out.push_back(p);
      if ((sp >= 0) != (sq >= 0)) out.push_back(p + (sp / (sp - sq)) * (q - p));
    }
  }
  return out;
}

inline double convex_intersection_area(const Polygon& a, const Polygon& b) {
  const Polygon c = clip_convex_2d(a, b);
  return c.size() >= 3 ? std::max(0.0, signed_area(c)) : 0.0;
}

}  // namespace floesim::sim
