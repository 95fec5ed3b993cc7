#include "pipeline/geometry2d.h"

#include <algorithm>
#include <cmath>

namespace floesim {

double signed_area(const Polygon& p) {
  double a = 0;
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2& u = p[i];
    const Vec2& v = p[(i + 1) % n];
    a += u.x() * v.y() - v.x() * u.y();
  }
  return 0.5 * a;
}

Vec2 centroid(const Polygon& p) {
  // Shifted to the first vertex to keep precision for polygons far from the origin.
  const Vec2 o = p.empty() ? Vec2::Zero() : p[0];
  double a = 0, cx = 0, cy = 0;
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2 u = p[i] - o, v = p[(i + 1) % n] - o;
    const double c = u.x() * v.y() - v.x() * u.y();
    a += c;
    cx += (u.x() + v.x()) * c;
    cy += (u.y() + v.y()) * c;
  }
  return o + Vec2(cx, cy) / (3.0 * a);
}

void make_ccw(Polygon& p) {
  if (signed_area(p) < 0) std::reverse(p.begin(), p.end());
}

namespace {
double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
bool segments_intersect(const Vec2& p1, const Vec2& p2, const Vec2& q1, const Vec2& q2) {
  const double d1 = cross(q2 - q1, p1 - q1), d2 = cross(q2 - q1, p2 - q1);
  const double d3 = cross(p2 - p1, q1 - p1), d4 = cross(p2 - p1, q2 - p1);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  auto on_seg = [](const Vec2& a, const Vec2& b, const Vec2& c) {
    return std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= c.y() &&
           c.y() <= std::max(a.y(), b.y());
  };
  if (d1 == 0 && on_seg(q1, q2, p1)) return true;
  if (d2 == 0 && on_seg(q1, q2, p2)) return true;
  if (d3 == 0 && on_seg(p1, p2, q1)) return true;
  if (d4 == 0 && on_seg(p1, p2, q2)) return true;
  return false;
}
}  // namespace

std::pair<int, int> find_self_intersection(const Polygon& p) {
  const int n = static_cast<int>(p.size());
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if (j == i + 1 || (i == 0 && j == n - 1)) continue;  // adjacent edges share a vertex
      if (segments_intersect(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return {i, j};
    }
  }
  return {-1, -1};
}

bool is_convex(const Polygon& p, double tol) {
  const size_t n = p.size();
  if (n < 3) return false;
  const double s = signed_area(p) > 0 ? 1.0 : -1.0;
  for (size_t i = 0; i < n; ++i) {
    const Vec2& a = p[i];
    const Vec2& b = p[(i + 1) % n];
    const Vec2& c = p[(i + 2) % n];
    if (s * cross(b - a, c - b) < -tol) return false;
  }
  return true;
}

Polygon clean_polygon(const Polygon& in, double tol) {
  Polygon p;
  for (const Vec2& v : in)
    if (p.empty() || (v - p.back()).norm() > tol) p.push_back(v);
  while (p.size() > 1 && (p.front() - p.back()).norm() <= tol) p.pop_back();
  bool changed = true;
  while (changed && p.size() > 3) {
    changed = false;
    for (size_t i = 0; i < p.size() && p.size() > 3; ++i) {
      const Vec2& a = p[(i + p.size() - 1) % p.size()];
      const Vec2& b = p[i];
      const Vec2& c = p[(i + 1) % p.size()];
      const double len = (c - a).norm();
      if (len > 0 && std::abs(cross(c - a, b - a)) / len <= tol && (b - a).dot(c - a) >= 0 &&
          (b - c).dot(a - c) >= 0) {
        p.erase(p.begin() + static_cast<long>(i));
        changed = true;
      }
    }
  }
  return p;
}

}  // namespace floesim
