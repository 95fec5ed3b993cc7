// Plane polygon utilities shared by digitise (writing floes) and simulate (reading them).
#pragma once
#include <vector>

#include <Eigen/Core>

namespace floesim {

using Vec2 = Eigen::Vector2d;
using Polygon = std::vector<Vec2>;  // open ring (last vertex != first)

double signed_area(const Polygon& p);  // > 0 for counter-clockwise
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

}  // namespace floesim
