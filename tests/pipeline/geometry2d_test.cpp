// convex_decompose: pieces are convex, counter-clockwise and tile the input (areas add up exactly).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>

#include "pipeline/geometry2d.h"

#ifndef FLOESIM_SHARED_DATA_DIR
#error "FLOESIM_SHARED_DATA_DIR must be defined by the build"
#endif

namespace floesim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Checks the decomposition's contract and returns the number of pieces.
size_t check_decomposition(const Polygon& p, const std::string& what) {
  const std::vector<Polygon> pieces = convex_decompose(p);
  double sum = 0;
  for (const Polygon& q : pieces) {
    EXPECT_GE(q.size(), 3u) << what;
    EXPECT_GT(signed_area(q), 0) << what << ": a piece is not counter-clockwise";
    EXPECT_TRUE(is_convex(q)) << what << ": a piece is not convex";
    sum += signed_area(q);
  }
  const double a = std::abs(signed_area(p));
  EXPECT_NEAR(sum, a, 1e-9 * a) << what << ": pieces do not tile the polygon";
  return pieces.size();
}

TEST(ConvexDecompose, ConvexInputComesBackWhole) {
  const Polygon square{{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  const auto pieces = convex_decompose(square);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].size(), 4u);
  EXPECT_DOUBLE_EQ(signed_area(pieces[0]), 4.0);
  // Collinear vertices on the edges do not make it non-convex.
  const Polygon with_midpoints{{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {0, 2}};
  ASSERT_EQ(convex_decompose(with_midpoints).size(), 1u);
  // Clockwise input is accepted and comes back counter-clockwise.
  Polygon cw(square.rbegin(), square.rend());
  const auto back = convex_decompose(cw);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_DOUBLE_EQ(signed_area(back[0]), 4.0);
}

TEST(ConvexDecompose, LShapeGivesTwoPieces) {
  const Polygon l{{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 3}, {0, 3}};
  EXPECT_EQ(check_decomposition(l, "L"), 2u);
}

TEST(ConvexDecompose, StarPolygon) {
  // A five-pointed star (simple, 10 vertices, 5 reflex): at least 3 convex pieces are needed (each reflex vertex
  // must be resolved), Hertel-Mehlhorn guarantees at most 4x optimal.
  Polygon star;
  for (int i = 0; i < 10; ++i) {
    const double r = i % 2 ? 0.4 : 1.0, a = kPi / 2 + i * kPi / 5;
    star.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  const size_t n = check_decomposition(star, "star");
  EXPECT_GE(n, 3u);
  EXPECT_LE(n, 10u);
}

TEST(ConvexDecompose, CombWithCollinearVertices) {
  // A comb: a base 10 x 1 with five teeth of width 1 and height 2 on top, and 11 collinear vertices along the
  // base's bottom edge.
  Polygon comb;
  for (int i = 0; i <= 10; ++i) comb.emplace_back(i, 0);
  for (int t = 4; t >= 0; --t) {  // tooth t spans x in [2t+1, 2t+2], right to left
    comb.emplace_back(2 * t + 2, 3);
    comb.emplace_back(2 * t + 1, 3);
    comb.emplace_back(2 * t + 1, 1);
    comb.emplace_back(2 * t, 1);
  }
  ASSERT_EQ(find_self_intersection(comb).first, -1);
  ASSERT_GT(signed_area(comb), 0);
  const size_t n = check_decomposition(comb, "comb");
  EXPECT_GE(n, 5u);  // five teeth cannot share a convex piece
}

TEST(ConvexDecompose, RandomStarShapedPolygons) {
  // 1000 random radial polygons of 10..200 vertices, some with collinear midpoints and axis-aligned staircases
  // like digitised outlines.
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> U(0, 1);
  int tested[3] = {0, 0, 0};  // plain, collinear midpoints, staircase
  for (int k = 0; k < 1000; ++k) {
    const int n = 10 + static_cast<int>(U(rng) * 190);
    Polygon p;
    for (int i = 0; i < n; ++i) {
      const double a = 2 * kPi * (i + 0.3 * U(rng)) / n, r = 5 + 20 * U(rng);
      p.emplace_back(100 + r * std::cos(a), -50 + r * std::sin(a));
    }
    if (k % 3 == 1) {  // collinear midpoints on every other edge
      Polygon q;
      for (int i = 0; i < n; ++i) {
        q.push_back(p[i]);
        if (i % 2 == 0) q.push_back(0.5 * (p[i] + p[(i + 1) % n]));
      }
      p = q;
    } else if (k % 3 == 2) {
      // Pixel-contour-like: an x-monotone orthogonal polygon (column skylines above and below a baseline) on a
      // 1.1794 m grid; equal neighbouring columns leave collinear vertices.
      const int cols = 5 + n / 4;
      std::uniform_int_distribution<int> H(1, 12);
      std::vector<int> top(cols), bot(cols);
      for (int i = 0; i < cols; ++i) top[i] = H(rng), bot[i] = -H(rng);
      const double g = 1.1794;
      p.clear();
      for (int i = 0; i < cols; ++i) p.emplace_back(100 + g * i, -50 + g * bot[i]), p.emplace_back(100 + g * (i + 1), -50 + g * bot[i]);
      for (int i = cols - 1; i >= 0; --i) p.emplace_back(100 + g * (i + 1), -50 + g * top[i]), p.emplace_back(100 + g * i, -50 + g * top[i]);
      Polygon q;  // drop the repeated corner where neighbouring columns are equal; keep the collinear vertices
      for (const Vec2& v : p)
        if (q.empty() || v != q.back()) q.push_back(v);
      p = q;
    }
    ASSERT_EQ(find_self_intersection(p).first, -1);
    check_decomposition(p, "random polygon " + std::to_string(k));
    ++tested[k % 3];
    if (HasFailure()) return;
  }
  for (int kind = 0; kind < 3; ++kind) EXPECT_GT(tested[kind], 250) << "kind " << kind;
}

TEST(ConvexDecompose, RealDigitisedFloes) {
  // Floe outlines segmented from NRC ice-tank video: pixel staircases with many collinear vertices.
  const std::string file = std::string(FLOESIM_SHARED_DATA_DIR) + "/nrc_tank_floes/nrc_oeb_2023_floes_vertices.csv";
  std::ifstream in(file);
  ASSERT_TRUE(in) << "test data missing: " << file << " (FLOESIM_SHARED_DATA_DIR must hold ../shared/data)";
  std::map<int, Polygon> floes;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string f[4];
    for (auto& x : f) std::getline(s, x, ',');
    floes[std::stoi(f[0])].emplace_back(std::stod(f[2]), std::stod(f[3]));
  }
  ASSERT_GT(floes.size(), 400u);
  int tested = 0;
  size_t pieces = 0;
  for (auto& [id, p] : floes) {
    make_ccw(p);
    if (p.size() < 3 || find_self_intersection(p).first != -1) continue;  // the contract needs a simple ring
    pieces += check_decomposition(p, "NRC floe " + std::to_string(id));
    ++tested;
    if (HasFailure()) return;
  }
  EXPECT_GT(tested, 400);
  EXPECT_GE(pieces, static_cast<size_t>(tested));
}

}  // namespace
}  // namespace floesim
