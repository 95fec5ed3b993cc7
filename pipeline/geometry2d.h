// Plane polygon utilities shared by digitise (writing floes) and simulate (reading them).
#pragma once
#include <vector>

#include <Eigen/Core>

namespace floesim {

using Vec2 = Eigen::Vector2d;
using Polygon = std::vector<Vec2>;  // open ring (last vertex != first)

inline constexpr double kPi = 3.14159265358979323846;  // the one copy (geometry, hydrodynamics, imaging, tests)
// The farthest from the origin a floe vertex, the vessel or a rectangle of the options may be, m. Projected
// coordinates such as UTM (northings up to 10,000 km) fit; beyond it a position is a mistake, and a far larger
// one overflows the bounding volumes of the collision detection (fuzz_checkpoint found such a crash in fcl).
inline constexpr double kMaxWorldCoordinateM = 1e7;

double point_segment_distance(const Vec2& v, const Vec2& p, const Vec2& q);  // to the segment pq
double signed_area(const Polygon& p);  // > 0 for counter-clockwise
// Counter-clockwise convex hull (Andrew's monotone chain), collinear points dropped (the one copy: synth's convex
// floes, the outline of a hull's waterplane).
Polygon convex_hull_2d(Polygon pts);
Vec2 centroid(const Polygon& p);        // area centroid; requires non-zero area
void make_ccw(Polygon& p);
// Index pair (i, j) of two non-adjacent edges that intersect, or (-1, -1) if the ring is simple.
std::pair<int, int> find_self_intersection(const Polygon& p);
bool is_convex(const Polygon& p, double tol = 1e-12);
// Removes repeated vertices and vertices on a straight line (within tol metres of the chord).
Polygon clean_polygon(const Polygon& p, double tol = 1e-9);
// Splits a simple CCW polygon into convex CCW pieces that tile it exactly (ear-clipping triangulation, then
// Hertel-Mehlhorn merging of diagonals: at most 4x the optimal number of pieces). A convex input comes back whole.
std::vector<Polygon> convex_decompose(const Polygon& ccw_simple_polygon);

// ---- Cutting floes (Boost.Geometry inside; no Boost type appears here) ----
// Boolean operations on simple polygons (either orientation; a self-intersecting input throws floesim::Error).
// Results: simple CCW polygons, cleaned (clean_polygon), pieces below min_area_m2 (or of zero width) dropped, each
// ring starting at its lexicographically smallest (x, y) vertex and the pieces sorted by that vertex, so the same
// input gives the same output bits. Two pieces that touch at a point are two pieces. A result with a hole throws
// floesim::Error (callers treat it as "no cut"). The intersection and the difference of the same pair share their
// cut vertices bit for bit, so area(a) = area(a n b) + area(a \ b) to round-off; that is checked on every call
// (both are computed), and a violation throws floesim::Error: Boost 1.74's floating-point overlay can fail in a
// nearly degenerate configuration (a polygon whose vertices lie on the other's edges to within an ulp, such as a
// piece cut from it), and a failed cut must be no cut rather than ice created or lost.
std::vector<Polygon> polygon_intersection(const Polygon& a, const Polygon& b, double min_area_m2 = 1e-9);
std::vector<Polygon> polygon_difference(const Polygon& a, const Polygon& b, double min_area_m2 = 1e-9);
// Both of the above from one overlay, for a caller that keeps both parts (a floe and the piece broken off it).
struct PolygonCut {
  std::vector<Polygon> inside, outside;  // a n b, a \ b
};
PolygonCut cut_polygon(const Polygon& a, const Polygon& b, double min_area_m2 = 1e-9);
// Splits a simple polygon by the infinite line through `point` with direction `dir`: pieces left of the line
// (cross(dir, x - point) > 0) and right of it, cleaned and ordered as above; a vertex within 1e-9 m of the line is
// on it. Not an overlay but a walk along the ring with one side test per vertex, so it is robust for lines through
// vertices and along edges. The areas add up to the polygon's to round-off (checked, else floesim::Error).
struct LineSplit {
  std::vector<Polygon> left, right;
};
LineSplit split_by_line(const Polygon& p, const Vec2& point, const Vec2& dir, double min_area_m2 = 1e-9);
// Length of the part of the line through `point` along `dir` that lies inside p and contains `point` (the chord a
// crack from `point` along dir would cut); 0 if point is outside. If `point` is on the boundary, the chord that
// starts there and goes into the polygon. "On" means within 1e-9 m (clean_polygon's default tolerance); a line
// running along a boundary edge counts that edge as inside.
double chord_length(const Polygon& p, const Vec2& point, const Vec2& dir);
// A circular sector as a convex CCW polygon: apex, direction of its axis (normalised here), half-angle (0, pi/2],
// radius, and the arc as `segments` chords (vertices: the apex, then the arc from -half_angle to +half_angle). The
// arc's vertices lie on the circle, so the polygon is inside the true sector.
Polygon circular_sector(const Vec2& apex, const Vec2& axis, double half_angle_rad, double radius_m, int segments);
// The circular sector's stand-in with the fewest vertices: a convex kite (apex, right end, tip, left end) whose tip
// lies on the axis at `radius_m` and whose two sides of half-angle `half_angle_rad` (0, pi/2] are long enough,
// r' = r half / sin(half), that its area is the sector's, r^2 half. A fracture's wedge cut as this kite reaches
// as far and weighs as much as the sector; the floe it leaves has a notch of 3 reflex corners instead of an arc's
// many, hence few convex parts (sim/engine/fracture.cpp).
Polygon equal_area_wedge(const Vec2& apex, const Vec2& axis, double half_angle_rad, double radius_m);

}  // namespace floesim
