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

// ---- convex_decompose: ear clipping, then Hertel-Mehlhorn merging ----------------------------------------------
// (Includes kept with the appended code so the file above stays untouched.)
#include <array>
#include <limits>
#include <map>

#include "pipeline/error.h"


namespace floesim {
namespace {

// Turn at b of the path a -> b -> c: > 0 left (convex for a CCW ring), 0 straight, < 0 reflex. The same expression
// as is_convex uses, so a piece merged under `turn >= -tol` passes is_convex(piece, tol) bit for bit.
double turn(const Vec2& a, const Vec2& b, const Vec2& c) { return cross(b - a, c - b); }

// q inside the CCW triangle (a, b, c); with `closed` a point on its boundary counts as inside.
bool in_triangle(const Vec2& q, const Vec2& a, const Vec2& b, const Vec2& c, bool closed) {
  const double d1 = cross(b - a, q - a), d2 = cross(c - b, q - b), d3 = cross(a - c, q - c);
  return closed ? (d1 >= 0 && d2 >= 0 && d3 >= 0) : (d1 > 0 && d2 > 0 && d3 > 0);
}

// Ear clipping of a simple CCW ring; returns CCW index triangles of non-zero area that tile it. Straight (collinear)
// vertices are never ear tips, and a vertex lying on a candidate ear's boundary blocks it, so collinear vertices end
// up as corners of proper triangles instead of zero-area slivers. If numerical trouble leaves no ear (a nearly
// degenerate or touching ring) the rules are relaxed step by step instead of failing.
std::vector<std::array<int, 3>> ear_clip(const Polygon& p) {
  const int n = static_cast<int>(p.size());
  std::vector<int> next(n), prev(n);
  for (int i = 0; i < n; ++i) {
    next[i] = (i + 1) % n;
    prev[i] = (i + n - 1) % n;
  }
  std::vector<std::array<int, 3>> tris;
  tris.reserve(n);
  auto is_ear = [&](int i, bool closed) {
    const int a = prev[i], c = next[i];
    if (turn(p[a], p[i], p[c]) <= 0) return false;
    for (int j = next[c]; j != a; j = next[j]) {
      const Vec2& q = p[j];
      if (q == p[a] || q == p[i] || q == p[c]) continue;  // a touching ring may repeat a position
      if (in_triangle(q, p[a], p[i], p[c], closed)) return false;
    }
    return true;
  };
  auto clip = [&](int i, bool emit) {
    const int a = prev[i], c = next[i];
    if (emit) tris.push_back({a, i, c});
    next[a] = c;
    prev[c] = a;
  };
  int remaining = n, cursor = 0;
  while (remaining > 3) {
    int found = -1;
    for (bool closed : {true, false}) {
      int i = cursor;
      for (int k = 0; k < remaining; ++k, i = next[i])
        if (is_ear(i, closed)) {
          found = i;
          break;
        }
      if (found >= 0) break;
    }
    bool emit = true;
    if (found < 0) {
      // No ear: drop a straight vertex (no area lost), else clip the most convex corner regardless.
      int i = cursor, best = -1;
      double best_turn = -std::numeric_limits<double>::infinity();
      for (int k = 0; k < remaining; ++k, i = next[i]) {
        const double t = turn(p[prev[i]], p[i], p[next[i]]);
        if (t == 0) {
          best = i;
          emit = false;
          break;
        }
        if (t > best_turn) best_turn = t, best = i;
      }
      found = best;
    }
    cursor = next[found];
    clip(found, emit);
    --remaining;
  }
  const int a = prev[cursor], c = next[cursor];
  if (turn(p[a], p[cursor], p[c]) > 0) tris.push_back({a, cursor, c});
  return tris;
}

}  // namespace

std::vector<Polygon> convex_decompose(const Polygon& in) {
  Polygon p;
  for (const Vec2& v : in)
    if (p.empty() || v != p.back()) p.push_back(v);
  while (p.size() > 1 && p.front() == p.back()) p.pop_back();
  FLOESIM_REQUIRE(p.size() >= 3, "convex_decompose: a polygon needs at least 3 distinct vertices, got ", p.size());
  for (const Vec2& v : p) FLOESIM_REQUIRE(v.allFinite(), "convex_decompose: polygon has a non-finite vertex");
  const double area = signed_area(p);
  FLOESIM_REQUIRE(area != 0, "convex_decompose: polygon has zero area");
  if (area < 0) std::reverse(p.begin(), p.end());  // tolerate clockwise input; pieces come back CCW
  if (is_convex(p)) return {p};

  constexpr double kTol = 1e-12;  // is_convex's default, so every piece passes is_convex(piece)
  const auto tris = ear_clip(p);

  // Pieces as index rings; `owner` maps each directed edge to the piece that has it. A diagonal is an edge whose
  // reverse belongs to another piece.
  std::vector<std::vector<int>> ring;
  std::map<std::pair<int, int>, int> owner;
  for (const auto& t : tris) {
    const int id = static_cast<int>(ring.size());
    ring.push_back({t[0], t[1], t[2]});
    for (int k = 0; k < 3; ++k) owner[{t[k], t[(k + 1) % 3]}] = id;
  }
  std::vector<std::pair<int, int>> diagonals;
  for (const auto& [e, id] : owner)
    if (e.first < e.second && owner.count({e.second, e.first})) diagonals.push_back(e);
  // Longest diagonals first: removing them first tends to leave fewer, rounder pieces. Ties by index: deterministic.
  std::stable_sort(diagonals.begin(), diagonals.end(), [&](const auto& a, const auto& b) {
    return (p[a.first] - p[a.second]).squaredNorm() > (p[b.first] - p[b.second]).squaredNorm();
  });

  auto rotate_to = [](const std::vector<int>& r, int start) {
    const auto it = std::find(r.begin(), r.end(), start);
    std::vector<int> out(it, r.end());
    out.insert(out.end(), r.begin(), it);
    return out;
  };
  std::vector<bool> alive(ring.size(), true);
  for (const auto& [u, v] : diagonals) {
    const auto pu = owner.find({u, v}), pv = owner.find({v, u});
    if (pu == owner.end() || pv == owner.end()) continue;
    const int P = pu->second, Q = pv->second;
    if (P == Q) continue;
    const std::vector<int> rp = rotate_to(ring[P], v);  // v ... u
    const std::vector<int> rq = rotate_to(ring[Q], u);  // u ... v
    if (rp.back() != u || rq.back() != v) continue;      // not a shared edge in both orders: leave it
    // Convexity only changes at u and v.
    const int before_u = rp[rp.size() - 2], after_u = rq[1];
    const int before_v = rq[rq.size() - 2], after_v = rp[1];
    if (turn(p[before_u], p[u], p[after_u]) < -kTol || turn(p[before_v], p[v], p[after_v]) < -kTol) continue;
    std::vector<int> merged = rp;
    merged.insert(merged.end(), rq.begin() + 1, rq.end() - 1);
    std::vector<int> sorted = merged;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) continue;  // would pinch at a vertex
    owner.erase({u, v});
    owner.erase({v, u});
    for (size_t k = 0; k < rq.size(); ++k) {
      const std::pair<int, int> e{rq[k], rq[(k + 1) % rq.size()]};
      if (e != std::pair<int, int>{v, u}) owner[e] = P;
    }
    ring[P] = std::move(merged);
    alive[Q] = false;
  }

  std::vector<Polygon> pieces;
  for (size_t i = 0; i < ring.size(); ++i) {
    if (!alive[i]) continue;
    Polygon piece;
    for (int k : ring[i]) piece.push_back(p[k]);
    pieces.push_back(std::move(piece));
  }
  return pieces;
}

}  // namespace floesim
