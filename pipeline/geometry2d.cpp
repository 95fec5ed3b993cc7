#include "pipeline/geometry2d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <tuple>

// Boost 1.74's geometry includes a header Boost itself deprecated (a #pragma message on every build); not ours.
#define BOOST_ALLOW_DEPRECATED_HEADERS
// No rescaling: by default Boost 1.74 snaps overlay computations to an integer grid of ~1e-7 of the extent, which
// moves cut vertices by that much (a square cut along its diagonal gained a 8e-7 m sliver vertex). Without it the
// cut vertices are the floating-point intersections of the two segments, and vertices of the inputs stay exact.
#define BOOST_GEOMETRY_NO_ROBUSTNESS
#include <boost/geometry.hpp>

#include "pipeline/error.h"

namespace floesim {

double point_segment_distance(const Vec2& v, const Vec2& p, const Vec2& q) {
  const Vec2 e = q - p;
  const double l2 = e.squaredNorm();
  const double t = l2 > 0 ? std::clamp((v - p).dot(e) / l2, 0.0, 1.0) : 0.0;
  return (v - (p + t * e)).norm();
}

Polygon convex_hull_2d(Polygon pts) {
  std::sort(pts.begin(), pts.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  // (b - a) x (c - a): > 0 for a left turn a -> b -> c.
  auto turn = [](const Vec2& a, const Vec2& b, const Vec2& c) {
    return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
  };
  Polygon h(2 * pts.size());
  size_t k = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && turn(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && turn(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  h.resize(k - 1);
  return h;
}

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

namespace floesim {
namespace {

// Turn at b of the path a -> b -> c: > 0 left (convex for a CCW ring), 0 straight, < 0 reflex. The same expression
// as is_convex uses, so a piece merged under `turn >= -tol` passes is_convex(piece, tol) bit for bit.
double turn(const Vec2& a, const Vec2& b, const Vec2& c) { return cross(b - a, c - b); }

// The path a -> b -> c is straight to round-off: its turn is below 1e-12 of |ab| |bc| (the sine of the angle). A
// digitised outline has runs of collinear pixel-grid vertices whose computed turn is a few ulps off zero, either
// side; an ear over one of them would be a zero-area sliver, which no convex solid can be made of.
bool straight(const Vec2& a, const Vec2& b, const Vec2& c) {
  return std::abs(turn(a, b, c)) <= 1e-12 * (b - a).norm() * (c - b).norm();
}

// q inside the CCW triangle (a, b, c); with `closed` a point on its boundary counts as inside.
bool in_triangle(const Vec2& q, const Vec2& a, const Vec2& b, const Vec2& c, bool closed) {
  const double d1 = cross(b - a, q - a), d2 = cross(c - b, q - b), d3 = cross(a - c, q - c);
  return closed ? (d1 >= 0 && d2 >= 0 && d3 >= 0) : (d1 > 0 && d2 > 0 && d3 > 0);
}

// Ear clipping of a simple CCW ring; returns CCW index triangles of non-zero area that tile it. Straight (collinear,
// to round-off) vertices are never ear tips, and a vertex lying on a candidate ear's boundary blocks it, so collinear vertices end
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
    if (turn(p[a], p[i], p[c]) <= 0 || straight(p[a], p[i], p[c])) return false;
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
        if (straight(p[prev[i]], p[i], p[next[i]])) {
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
  if (turn(p[a], p[cursor], p[c]) > 0 && !straight(p[a], p[cursor], p[c])) tris.push_back({a, cursor, c});
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

// ---- Cutting floes: boolean operations (Boost.Geometry), line split, chords, sectors -----------------------------
namespace floesim {
namespace {

namespace bg = boost::geometry;
// Closed CCW rings: Boost's overlay is exercised most with closed rings, and CCW is our orientation.
using BgPoint = bg::model::d2::point_xy<double>;
using BgPolygon = bg::model::polygon<BgPoint, /*ClockWise=*/false, /*Closed=*/true>;
using BgMulti = bg::model::multi_polygon<BgPolygon>;

// An input ring with repeated vertices dropped (consecutive and closing), checked for finite coordinates and size.
Polygon distinct_ring(const Polygon& in, const char* what) {
  Polygon ring;
  for (const Vec2& v : in) {
    FLOESIM_REQUIRE(v.allFinite(), what, ": polygon has a non-finite vertex");
    if (ring.empty() || v != ring.back()) ring.push_back(v);
  }
  while (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
  FLOESIM_REQUIRE(ring.size() >= 3, what, ": a polygon needs at least 3 distinct vertices, got ", ring.size());
  return ring;
}

// The ring as Boost's polygon, oriented and closed, and checked: a self-intersecting ring makes an overlay
// meaningless, so say so instead of returning garbage.
BgPolygon to_boost(const Polygon& ring, const char* what) {
  BgPolygon g;
  for (const Vec2& v : ring) bg::append(g.outer(), BgPoint(v.x(), v.y()));
  bg::append(g.outer(), BgPoint(ring[0].x(), ring[0].y()));
  bg::correct(g);  // orientation (either is accepted) and closure
  std::string why;
  FLOESIM_REQUIRE(bg::is_valid(g, why), what, ": input polygon is not simple (", why, ")");
  return g;
}

// Largest coordinate magnitude or extent of the rings: round-off of anything computed from them scales with it.
double coordinate_scale(const Polygon& a, const Polygon& b) {
  Vec2 lo = a[0], hi = a[0];
  for (const Polygon* p : {&a, &b})
    for (const Vec2& v : *p) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return std::max({lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff(), (hi - lo).maxCoeff()});
}

bool lex_less(const Vec2& u, const Vec2& v) { return u.x() < v.x() || (u.x() == v.x() && u.y() < v.y()); }

// Puts each vertex of an overlay's result where it belongs. Boost computes the crossing of an edge of a with an edge
// of b afresh in every operation, from the segments in the order and orientation that operation sees them
// (difference reverses b), so a n b and a \ b may place the same cut vertex a few ulps apart, and an input vertex
// on the other polygon's edge may come back as a computed crossing near it. The pieces would then not tile a
// exactly, nor touch exactly (and a later overlay of two such pieces is misjudged). So a vertex within round-off of
// an input vertex becomes that vertex, and any other becomes the crossing of the nearest edge of a with the nearest
// edge of b, computed by one formula from the two segments in a canonical order: the same bits in every operation.
class Snapper {
 public:
  Snapper(const Polygon& a, const Polygon& b) : a_(a), b_(b) {
    vertices_ = a;
    vertices_.insert(vertices_.end(), b.begin(), b.end());
    std::sort(vertices_.begin(), vertices_.end(), lex_less);
    const double scale = coordinate_scale(a, b);
    vertex_tol_ = 1e-12 * scale;
    crossing_tol_ = 1e-9 * scale;
  }

  Vec2 operator()(const Vec2& v) const {
    // An input vertex (exactly, or within round-off).
    auto it = std::lower_bound(vertices_.begin(), vertices_.end(), Vec2(v.x() - vertex_tol_, -HUGE_VAL), lex_less);
    const Vec2* best = nullptr;
    double best_d = vertex_tol_;
    for (; it != vertices_.end() && it->x() <= v.x() + vertex_tol_; ++it) {
      const double d = (*it - v).cwiseAbs().maxCoeff();
      if (d <= best_d) best = &*it, best_d = d;
    }
    if (best) return *best;
    // A crossing of an edge of a with an edge of b.
    const auto [pa, qa] = nearest_edge(a_, v);
    const auto [pb, qb] = nearest_edge(b_, v);
    std::array<Vec2, 2> s{pa, qa}, r{pb, qb};
    if (lex_less(s[1], s[0])) std::swap(s[0], s[1]);
    if (lex_less(r[1], r[0])) std::swap(r[0], r[1]);
    if (lex_less(r[0], s[0]) || (r[0] == s[0] && lex_less(r[1], s[1]))) std::swap(s, r);
    const Vec2 es = s[1] - s[0], er = r[1] - r[0];
    const double den = cross(es, er);
    if (den == 0) return v;  // parallel: Boost's own point is all there is
    const Vec2 x = s[0] + (cross(r[0] - s[0], er) / den) * es;
    // Only if it is the crossing Boost found (not a far one of nearly parallel edges).
    return (x - v).norm() <= crossing_tol_ ? x : v;
  }

 private:
  static std::pair<Vec2, Vec2> nearest_edge(const Polygon& p, const Vec2& v) {
    size_t best = 0;
    double best_d = HUGE_VAL;
    for (size_t i = 0; i < p.size(); ++i) {
      const double d = point_segment_distance(v, p[i], p[(i + 1) % p.size()]);
      if (d < best_d) best = i, best_d = d;
    }
    return {p[best], p[(best + 1) % p.size()]};
  }

  const Polygon& a_;
  const Polygon& b_;
  std::vector<Vec2> vertices_;  // of a and b, sorted by lex_less
  double vertex_tol_ = 0, crossing_tol_ = 0;
};

// Puts the vertices of q that lie on an edge of p (within tol, away from its ends) into that edge, in order.
void insert_touching(Polygon& p, const Polygon& q, double tol) {
  Polygon out;
  std::vector<std::pair<double, Vec2>> on;
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec2 u = p[i], v = p[(i + 1) % p.size()], e = v - u;
    out.push_back(u);
    on.clear();
    for (const Vec2& w : q)
      if ((w - u).norm() > tol && (w - v).norm() > tol && point_segment_distance(w, u, v) <= tol)
        on.emplace_back((w - u).dot(e) / e.squaredNorm(), w);
    std::sort(on.begin(), on.end(), [](const auto& x, const auto& y) {
      return x.first < y.first || (x.first == y.first && lex_less(x.second, y.second));
    });
    for (const auto& tw : on)
      if (tw.second != out.back()) out.push_back(tw.second);
  }
  p = std::move(out);
}

// The two operands of an overlay, made consistent with each other before Boost sees them. Boost 1.74's
// floating-point overlay misjudges a vertex of one polygon that lies on an edge of the other but misses it by an
// ulp, as the vertices of a piece cut from a floe lie on the floe's edges (the area of a \ piece came out at twice
// a's). So a vertex within round-off of the other polygon's vertex becomes that vertex, and one on the other's edge
// becomes a vertex of that edge too: touching is then exact, which Boost decides correctly.
struct Overlay {
  Polygon a, b;
  BgPolygon bg_a, bg_b;
};

Overlay make_overlay(const Polygon& a_in, const Polygon& b_in, const char* what) {
  Overlay o;
  o.a = distinct_ring(a_in, what);
  o.b = distinct_ring(b_in, what);
  const double tol = 1e-10 * coordinate_scale(o.a, o.b);
  for (Vec2& w : o.b)
    for (const Vec2& v : o.a)
      if ((w - v).cwiseAbs().maxCoeff() <= tol) {
        w = v;
        break;
      }
  o.b = distinct_ring(o.b, what);
  const Polygon a0 = o.a;
  insert_touching(o.a, o.b, tol);
  insert_touching(o.b, a0, tol);
  o.bg_a = to_boost(o.a, what);
  o.bg_b = to_boost(o.b, what);
  return o;
}

double ring_area(const BgPolygon::ring_type& r) { return std::abs(bg::area(r)); }

// Removes the tips of zero-width spikes (the path runs out and straight back, within tol metres) and repeated
// vertices. Splitting along a line that runs through a vertex or along an edge leaves such spikes.
Polygon remove_spikes(Polygon p, double tol) {
  bool changed = true;
  while (changed && p.size() >= 3) {
    changed = false;
    for (size_t i = 0; i < p.size() && p.size() >= 3; ++i) {
      const Vec2& a = p[(i + p.size() - 1) % p.size()];
      const Vec2& b = p[i];
      const Vec2& c = p[(i + 1) % p.size()];
      const double len = (c - a).norm();
      const bool repeat = (b - a).norm() <= tol;
      const bool spike = (b - a).dot(c - b) < 0 && (len == 0 || std::abs(cross(c - a, b - a)) / len <= tol);
      if (repeat || spike) {
        p.erase(p.begin() + static_cast<long>(i));
        changed = true;
      }
    }
  }
  return p;
}

// Splits a ring at each vertex it passes twice: two pieces that touch at a point (a line through a reflex vertex,
// say) can come back as one ring pinched there, which is not a simple polygon but two simple ones.
void split_pinches(const Polygon& p, std::vector<Polygon>& out) {
  std::vector<size_t> order(p.size());
  for (size_t k = 0; k < p.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(),
            [&](size_t u, size_t v) { return lex_less(p[u], p[v]) || (p[u] == p[v] && u < v); });
  for (size_t k = 0; k + 1 < order.size(); ++k) {
    if (p[order[k]] != p[order[k + 1]]) continue;
    const size_t i = order[k], j = order[k + 1];  // i < j
    Polygon loop(p.begin() + static_cast<long>(i), p.begin() + static_cast<long>(j));
    Polygon rest(p.begin() + static_cast<long>(j), p.end());
    rest.insert(rest.end(), p.begin(), p.begin() + static_cast<long>(i));
    split_pinches(loop, out);
    split_pinches(rest, out);
    return;
  }
  out.push_back(p);
}

// What a result leaves out of its pieces, so that a cut can still be checked against the whole: slivers dropped
// (area to add back) and holes (area inside a piece's outer ring that is not part of it).
struct Leftover {
  double dropped = 0, holes = 0;
};

// Candidate rings (CCW where they are pieces) as the results we promise: spikes and pinches resolved, cleaned,
// slivers (below min_area_m2, or of zero width) dropped, simple, each starting at its smallest vertex, sorted. A
// clockwise loop that is not a sliver is a hole touching the outer ring.
std::vector<Polygon> finish(const std::vector<Polygon>& candidates, double min_area_m2, const char* what,
                            Leftover& left) {
  std::vector<Polygon> out, rings;
  for (const Polygon& c : candidates) {
    rings.clear();
    split_pinches(remove_spikes(c, 1e-9), rings);
    for (Polygon& q : rings) {
      q = clean_polygon(q);
      if (q.size() < 3) continue;
      const double area = signed_area(q);
      // A ring no wider than clean_polygon's 1e-9 m has an area below 1e-9 m times its extent: a zero-width
      // sliver, whatever its sign, never a piece or a hole.
      Vec2 lo = q[0], hi = q[0];
      for (const Vec2& v : q) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      const double sliver = std::max(min_area_m2, 1e-9 * (hi - lo).maxCoeff());
      if (area < -sliver) {
        left.holes -= area;
        continue;
      }
      if (area < sliver) {
        left.dropped += area;
        continue;
      }
      // Boost 1.74's floating-point overlay can, in nearly degenerate configurations, return a self-intersecting
      // ring; a caller gets an error (no cut) rather than such a floe.
      BgPolygon check;
      for (const Vec2& v : q) bg::append(check.outer(), BgPoint(v.x(), v.y()));
      bg::append(check.outer(), BgPoint(q[0].x(), q[0].y()));
      std::string why;
      FLOESIM_REQUIRE(bg::is_valid(check, why), what, ": the result is not a simple polygon (", why, ")");
      std::rotate(q.begin(), std::min_element(q.begin(), q.end(), lex_less), q.end());
      out.push_back(std::move(q));
    }
  }
  // Pieces have disjoint interiors, so their smallest vertices differ unless two pieces touch there; the vertex
  // count and then the second vertex break such ties.
  std::sort(out.begin(), out.end(), [](const Polygon& u, const Polygon& v) {
    auto key = [](const Polygon& q) { return std::make_tuple(q[0].x(), q[0].y(), q.size(), q[1].x(), q[1].y()); };
    return key(u) < key(v);
  });
  return out;
}

// Boost's result as our polygons: holes counted, closing vertex dropped, vertices snapped, then finish().
std::vector<Polygon> from_boost(const BgMulti& m, const Snapper& snap, double min_area_m2, const char* what,
                                Leftover& left) {
  std::vector<Polygon> candidates;
  for (const BgPolygon& g : m) {
    for (const auto& hole : g.inners()) {
      // A hole below min_area_m2 is a sliver: the piece keeps its outer ring, which counts the hole's area.
      const double h = ring_area(hole);
      if (h < min_area_m2)
        left.dropped -= h;
      else
        left.holes += h;
    }
    Polygon p;
    const auto& r = g.outer();
    for (size_t i = 0; i + 1 < r.size(); ++i) p.push_back(snap(Vec2(bg::get<0>(r[i]), bg::get<1>(r[i]))));
    candidates.push_back(std::move(p));
  }
  return finish(candidates, min_area_m2, what, left);
}

double total_area(const std::vector<Polygon>& pieces) {
  double a = 0;
  for (const Polygon& q : pieces) a += signed_area(q);
  return a;
}

// The pieces of one cut must tile the polygon: a floating-point overlay that went wrong in a nearly degenerate
// configuration shows up here, and the caller gets an error (no cut) instead of ice created or lost.
void require_tiling(double whole, double pieces, const Leftover& left, const char* what) {
  const double net = pieces + left.dropped - left.holes;
  FLOESIM_REQUIRE(std::abs(net - whole) <= 1e-9 * std::abs(whole), what, ": the pieces do not add up to the polygon (",
                  pieces, " + ", left.dropped, " dropped - ", left.holes, " holes vs ", whole, " m^2)");
}

// Intersection and difference from one prepared overlay, snapped alike and checked to tile a (holes included).
struct CheckedCut {
  PolygonCut cut;
  Leftover in, out;
};

CheckedCut checked_cut(const Polygon& a, const Polygon& b, double min_area_m2, const char* what) {
  const Overlay o = make_overlay(a, b, what);
  const Snapper snap(o.a, o.b);
  BgMulti in, out;
  bg::intersection(o.bg_a, o.bg_b, in);
  bg::difference(o.bg_a, o.bg_b, out);
  CheckedCut c;
  c.cut.inside = from_boost(in, snap, min_area_m2, what, c.in);
  c.cut.outside = from_boost(out, snap, min_area_m2, what, c.out);
  const Leftover both{c.in.dropped + c.out.dropped, c.in.holes + c.out.holes};
  require_tiling(std::abs(signed_area(o.a)), total_area(c.cut.inside) + total_area(c.cut.outside), both, what);
  return c;
}

void require_no_hole(const Leftover& left, const char* what) {
  FLOESIM_REQUIRE(left.holes == 0, what, ": the result has a hole of ", left.holes, " m^2");
}

}  // namespace

// Both parts are always computed: the check that they tile a is what catches a failed overlay, and it costs one
// more overlay per cut, which is rare.
std::vector<Polygon> polygon_intersection(const Polygon& a, const Polygon& b, double min_area_m2) {
  CheckedCut c = checked_cut(a, b, min_area_m2, "polygon_intersection");
  require_no_hole(c.in, "polygon_intersection");
  return std::move(c.cut.inside);
}

std::vector<Polygon> polygon_difference(const Polygon& a, const Polygon& b, double min_area_m2) {
  CheckedCut c = checked_cut(a, b, min_area_m2, "polygon_difference");
  require_no_hole(c.out, "polygon_difference");
  return std::move(c.cut.outside);
}

PolygonCut cut_polygon(const Polygon& a, const Polygon& b, double min_area_m2) {
  CheckedCut c = checked_cut(a, b, min_area_m2, "cut_polygon");
  require_no_hole(c.in, "cut_polygon");
  require_no_hole(c.out, "cut_polygon");
  return std::move(c.cut);
}

LineSplit split_by_line(const Polygon& in, const Vec2& point, const Vec2& dir, double min_area_m2) {
  FLOESIM_REQUIRE(point.allFinite() && dir.allFinite() && dir.norm() > 0,
                  "split_by_line: the line needs a finite point and a non-zero direction");
  // Our own walk rather than an overlay with a half-plane: Boost 1.74's floating-point overlay misjudges a line
  // through a vertex (the half-plane's edge then misses the vertex by an ulp), which is exactly where cracks from
  // contacts at vertices run. Here every decision is the sign of one number per vertex, computed once.
  Polygon p = distinct_ring(in, "split_by_line");
  to_boost(p, "split_by_line");  // validates: simple
  make_ccw(p);
  const size_t n = p.size();
  const Vec2 d = dir.normalized();
  std::vector<double> s(n), t(n);  // signed distance to the line (> 0 left) and position along it
  for (size_t i = 0; i < n; ++i) {
    s[i] = cross(d, p[i] - point), t[i] = d.dot(p[i] - point);
    // Within clean_polygon's 1e-9 m is on the line: a vertex an ulp to one side would leave a piece with a neck of
    // that width (valid, but a trap for any later overlay); on the line, the pinch is resolved below.
    if (std::abs(s[i]) <= 1e-9) s[i] = 0;
  }
  // Simulation of simplicity: a vertex on the line (s = 0) counts as left, as if the line were moved right by an
  // infinitesimal amount. No vertex is then on the line, every crossing is a proper one, and along the line the
  // crossings alternate between leaving and entering the polygon (Jordan). Zero-width spikes and sliver pieces
  // that the infinitesimal move creates are removed by finish().
  auto is_left = [&](size_t i) { return s[i] >= 0; };

  // The ring with each crossing inserted in its edge. A crossing is computed from its edge's left end point a, so
  // one on a vertex (s_a = 0) is that vertex exactly.
  struct Node {
    Vec2 x;
    size_t vertex;  // index into p, or n for a crossing
    double t = 0, slope = 0;
    size_t partner = 0;
  };
  std::vector<Node> ring;
  std::vector<size_t> crossings;
  for (size_t i = 0; i < n; ++i) {
    ring.push_back({p[i], i});
    const size_t j = (i + 1) % n;
    if (is_left(i) == is_left(j)) continue;
    const size_t a = is_left(i) ? i : j, b = is_left(i) ? j : i;
    const double lambda = s[a] / (s[a] - s[b]);
    Node c{p[a] + lambda * (p[b] - p[a]), n};
    c.t = t[a] + lambda * (t[b] - t[a]);
    // How the crossing moves along the line as the line moves right by eps: orders crossings at the same t (two
    // edges through one vertex on the line) the way the displaced line meets them.
    c.slope = (t[b] - t[a]) / (s[a] - s[b]);
    crossings.push_back(ring.size());
    ring.push_back(c);
  }
  // Along the line, crossings pair up as the ends of the chords inside the polygon.
  std::sort(crossings.begin(), crossings.end(), [&](size_t u, size_t v) {
    return ring[u].t < ring[v].t || (ring[u].t == ring[v].t && ring[u].slope < ring[v].slope);
  });
  for (size_t k = 0; k + 1 < crossings.size(); k += 2) {
    ring[crossings[k]].partner = crossings[k + 1];
    ring[crossings[k + 1]].partner = crossings[k];
  }
  // Vertices on the line, by position: one inside a chord is a point where a piece's chord edge touches the piece
  // again (or the other side's piece); putting it on the chord edge lets finish() split the pinch there.
  std::vector<size_t> on_line;
  for (size_t i = 0; i < n; ++i)
    if (s[i] == 0) on_line.push_back(i);
  std::sort(on_line.begin(), on_line.end(), [&](size_t u, size_t v) { return t[u] < t[v]; });

  // Walk each side: along the ring while on the side; at a crossing (always a way out, since the walk only comes
  // from the side's vertices) along the chord to its partner (a way back in), and on along the ring.
  std::vector<Polygon> left, right;
  std::vector<bool> visited(ring.size(), false);
  const size_t m = ring.size();
  for (size_t start = 0; start < m; ++start) {
    if (ring[start].vertex == n || visited[start]) continue;
    const bool side = is_left(ring[start].vertex);
    Polygon piece;
    size_t cur = start;
    for (size_t steps = 0;; ++steps) {
      FLOESIM_REQUIRE(steps <= 2 * m, "split_by_line: internal error, a piece does not close");
      visited[cur] = true;
      piece.push_back(ring[cur].x);
      if (ring[cur].vertex == n) {
        const size_t y = ring[cur].partner;
        const double t0 = ring[cur].t, t1 = ring[y].t;
        auto inside = [&](size_t i) { return std::min(t0, t1) < t[i] && t[i] < std::max(t0, t1); };
        if (t0 < t1) {
          for (size_t i : on_line)
            if (inside(i)) piece.push_back(p[i]);
        } else {
          for (auto it = on_line.rbegin(); it != on_line.rend(); ++it)
            if (inside(*it)) piece.push_back(p[*it]);
        }
        visited[y] = true;
        piece.push_back(ring[y].x);
        cur = (y + 1) % m;
      } else {
        cur = (cur + 1) % m;
      }
      if (cur == start) break;
    }
    (side ? left : right).push_back(std::move(piece));
  }
  Leftover leftover;
  LineSplit out{finish(left, min_area_m2, "split_by_line", leftover),
                finish(right, min_area_m2, "split_by_line", leftover)};
  require_no_hole(leftover, "split_by_line");  // a side of a line has no hole; this would be a bug
  require_tiling(signed_area(p), total_area(out.left) + total_area(out.right), leftover, "split_by_line");
  return out;
}

double chord_length(const Polygon& p, const Vec2& point, const Vec2& dir) {
  FLOESIM_REQUIRE(point.allFinite() && dir.allFinite() && dir.norm() > 0,
                  "chord_length: the line needs a finite point and a non-zero direction");
  FLOESIM_REQUIRE(p.size() >= 3, "chord_length: a polygon needs at least 3 vertices, got ", p.size());
  constexpr double kOnTol = 1e-9;  // m: a point this close to a crossing counts as on the boundary
  const Vec2 d = dir.normalized();
  const size_t n = p.size();
  double best = 0;
  std::vector<double> t;
  // The line is displaced infinitesimally to one side, then to the other: a vertex on the line counts as lying
  // on the far side, so every crossing is proper and, sorted along the line, crossings alternate entry and exit
  // (Jordan). A line grazing a vertex or running along an edge is inside for one displacement and outside (or
  // of zero length) for the other; the longer chord is the one the closed polygon contains.
  for (const bool zero_is_left : {true, false}) {
    t.clear();
    for (size_t i = 0; i < n; ++i) {
      const Vec2 u = p[i] - point, v = p[(i + 1) % n] - point;
      const double su = cross(d, u), sv = cross(d, v);
      const bool lu = zero_is_left ? su >= 0 : su > 0, lv = zero_is_left ? sv >= 0 : sv > 0;
      if (lu == lv) continue;
      const double tu = d.dot(u), tv = d.dot(v);
      t.push_back(tu + (tv - tu) * (su / (su - sv)));
    }
    std::sort(t.begin(), t.end());
    for (size_t k = 0; k + 1 < t.size(); k += 2)
      if (t[k] <= kOnTol && t[k + 1] >= -kOnTol) best = std::max(best, t[k + 1] - t[k]);
  }
  return best;
}

Polygon circular_sector(const Vec2& apex, const Vec2& axis, double half_angle_rad, double radius_m, int segments) {
  FLOESIM_REQUIRE(apex.allFinite() && axis.allFinite() && axis.norm() > 0,
                  "circular_sector: needs a finite apex and a non-zero axis");
  FLOESIM_REQUIRE(half_angle_rad > 0 && half_angle_rad <= 1.57079632679489661923,
                  "circular_sector: half-angle must be in (0, pi/2], got ", half_angle_rad);
  FLOESIM_REQUIRE(radius_m > 0 && std::isfinite(radius_m), "circular_sector: radius must be > 0, got ", radius_m);
  FLOESIM_REQUIRE(segments >= 1, "circular_sector: needs at least one arc segment, got ", segments);
  const Vec2 x = axis.normalized(), y(-x.y(), x.x());
  Polygon s;
  s.reserve(static_cast<size_t>(segments) + 2);
  s.push_back(apex);
  for (int k = 0; k <= segments; ++k) {
    // (2k - segments) is exact, so the arc is symmetric about the axis bit for bit.
    const double phi = half_angle_rad * (2 * k - segments) / segments;
    s.push_back(apex + radius_m * (std::cos(phi) * x + std::sin(phi) * y));
  }
  return s;
}

Polygon equal_area_wedge(const Vec2& apex, const Vec2& axis, double half_angle_rad, double radius_m) {
  FLOESIM_REQUIRE(apex.allFinite() && axis.allFinite() && axis.norm() > 0,
                  "equal_area_wedge: needs a finite apex and a non-zero axis");
  FLOESIM_REQUIRE(half_angle_rad > 0 && half_angle_rad <= 1.57079632679489661923,
                  "equal_area_wedge: half-angle must be in (0, pi/2], got ", half_angle_rad);
  FLOESIM_REQUIRE(radius_m > 0 && std::isfinite(radius_m), "equal_area_wedge: radius must be > 0, got ", radius_m);
  const Vec2 x = axis.normalized(), y(-x.y(), x.x());
  // Two triangles (apex, side end, tip) of area r r' sin(half) / 2 each: equal to the sector's r^2 half.
  const double side = radius_m * half_angle_rad / std::sin(half_angle_rad);
  const double c = std::cos(half_angle_rad), s = std::sin(half_angle_rad);
  return {apex, apex + side * (c * x - s * y), apex + radius_m * x, apex + side * (c * x + s * y)};
}

}  // namespace floesim
