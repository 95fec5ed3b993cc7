#include "imaging/shapes.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace floesim::imaging {

namespace {
double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

bool segments_touch(const Vec2& p1, const Vec2& p2, const Vec2& q1, const Vec2& q2) {
  const double d1 = cross(q2 - q1, p1 - q1), d2 = cross(q2 - q1, p2 - q1);
  const double d3 = cross(p2 - p1, q1 - p1), d4 = cross(p2 - p1, q2 - p1);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  return false;  // collinear or endpoint contact is caught by the point-segment distances (== 0)
}
}  // namespace

BBox bounding_box(const Polygon& p) {
  BBox b{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
         -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const Vec2& v : p) {
    b.x0 = std::min(b.x0, v.x());
    b.y0 = std::min(b.y0, v.y());
    b.x1 = std::max(b.x1, v.x());
    b.y1 = std::max(b.y1, v.y());
  }
  return b;
}

bool point_in_polygon(const Vec2& p, const Polygon& poly) {
  bool inside = false;
  const size_t n = poly.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

double segment_distance(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  if (segments_touch(a, b, c, d)) return 0.0;
  return std::min({point_segment_distance(a, c, d), point_segment_distance(b, c, d), point_segment_distance(c, a, b),
                   point_segment_distance(d, a, b)});
}

bool polygons_within(const Polygon& a, const Polygon& b, double gap) {
  // Only edges that reach the other polygon's box (grown by the gap) can be closer than the gap.
  const BBox ba = bounding_box(a), bb = bounding_box(b);
  if (!ba.overlaps(bb, gap)) return false;
  auto near_edges = [gap](const Polygon& p, const BBox& box) {
    std::vector<int> idx;
    const size_t n = p.size();
    for (size_t i = 0; i < n; ++i) {
      const Vec2& u = p[i];
      const Vec2& v = p[(i + 1) % n];
      const BBox e{std::min(u.x(), v.x()), std::min(u.y(), v.y()), std::max(u.x(), v.x()), std::max(u.y(), v.y())};
      if (e.overlaps(box, gap)) idx.push_back(static_cast<int>(i));
    }
    return idx;
  };
  const std::vector<int> ea = near_edges(a, bb), eb = near_edges(b, ba);
  const size_t na = a.size(), nb = b.size();
  for (int i : ea)
    for (int j : eb) {
      const double d = segment_distance(a[i], a[(i + 1) % na], b[j], b[(j + 1) % nb]);
      if (d < gap || d == 0.0) return true;
    }
  // No edges come close: they overlap only if one lies inside the other.
  return point_in_polygon(a[0], b) || point_in_polygon(b[0], a);
}

Polygon clip_to_rect(const Polygon& p, double x0, double y0, double x1, double y1) {
  // One pass per rectangle side; `inside` and `cut` describe the half-plane of that side.
  auto pass = [](const Polygon& in, auto inside, auto cut) {
    Polygon out;
    const size_t n = in.size();
    for (size_t i = 0; i < n; ++i) {
      const Vec2& cur = in[i];
      const Vec2& prev = in[(i + n - 1) % n];
      const bool ci = inside(cur), pi = inside(prev);
      if (ci) {
        if (!pi) out.push_back(cut(prev, cur));
        out.push_back(cur);
      } else if (pi) {
        out.push_back(cut(prev, cur));
      }
    }
    return out;
  };
  auto lerp_x = [](double x) {
    return [x](const Vec2& a, const Vec2& b) {
      const double t = (x - a.x()) / (b.x() - a.x());
      return Vec2(x, a.y() + t * (b.y() - a.y()));
    };
  };
  auto lerp_y = [](double y) {
    return [y](const Vec2& a, const Vec2& b) {
      const double t = (y - a.y()) / (b.y() - a.y());
      return Vec2(a.x() + t * (b.x() - a.x()), y);
    };
  };
  Polygon r = p;
  r = pass(
      r, [x0](const Vec2& v) { return v.x() >= x0; }, lerp_x(x0));
  if (r.size() >= 3)
    r = pass(
        r, [x1](const Vec2& v) { return v.x() <= x1; }, lerp_x(x1));
  if (r.size() >= 3)
    r = pass(
        r, [y0](const Vec2& v) { return v.y() >= y0; }, lerp_y(y0));
  if (r.size() >= 3)
    r = pass(
        r, [y1](const Vec2& v) { return v.y() <= y1; }, lerp_y(y1));
  if (r.size() < 3) return {};
  r = clean_polygon(r, 1e-9);
  if (r.size() < 3 || std::abs(signed_area(r)) <= 0) return {};
  return r;
}

}  // namespace floesim::imaging
