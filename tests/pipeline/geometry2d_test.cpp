// convex_decompose: pieces are convex, counter-clockwise and tile the input (areas add up exactly).
// Cutting floes: boolean operations, line splits, chords and sectors against closed forms; area conservation,
// orientation, simplicity, no overlap and determinism on random polygons.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>

#include "pipeline/error.h"
#include "pipeline/geometry2d.h"

#ifndef FLOESIM_SHARED_DATA_DIR
#error "FLOESIM_SHARED_DATA_DIR must be defined by the build"
#endif

namespace floesim {
namespace {


// Checks the decomposition's contract and returns the number of pieces.
size_t check_decomposition(const Polygon& p, const std::string& what) {
  const std::vector<Polygon> pieces = convex_decompose(p);
  double sum = 0;
  for (const Polygon& q : pieces) {
    EXPECT_GE(q.size(), 3u) << what;
    EXPECT_GT(signed_area(q), 0) << what << ": a piece is not counter-clockwise";
    EXPECT_TRUE(is_convex(q)) << what << ": a piece is not convex";
    // No sliver: a piece's area is not round-off against its size (a solid cannot be made of a zero-area piece).
    double perimeter = 0;
    for (size_t i = 0; i < q.size(); ++i) perimeter += (q[(i + 1) % q.size()] - q[i]).norm();
    EXPECT_GT(signed_area(q), 1e-9 * perimeter * perimeter) << what << ": a zero-area sliver";
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

TEST(ConvexDecompose, DigitisedOutlineWithRunsOfCollinearVerticesGivesNoSliver) {
  // A floe the digitiser traced at the edge of a synthetic image (cases/long-transit, floe 1714; pixel grid of
  // 1.1794 m, centred on the vertices' mean as the model does): its diagonal runs of collinear vertices turn by a few
  // ulps after the shift, and an ear over one became a zero-area triangle, which stopped the simulation.
  Polygon p = {{7969.7955000000002, 533.08879999999999}, {7963.8985000000002, 530.73000000000002}, {7958.0015000000003, 526.01239999999996}, {7952.1045000000004, 523.65359999999998}, {7946.2075000000004, 518.93600000000004}, {7945.0281000000004, 518.93600000000004}, {7920.8504000000003, 494.75830000000002}, {7919.6710000000003, 491.2201}, {7918.4916000000003, 490.04070000000002}, {7918.4916000000003, 487.68189999999998}, {7917.3122000000003, 486.5025}, {7917.3122000000003, 482.96429999999998}, {7916.1328000000003, 481.78489999999999}, {7916.1328000000003, 478.24669999999998}, {7914.9534000000003, 477.06729999999999}, {7914.9534000000003, 474.70850000000002}, {7913.7740000000003, 473.52910000000003}, {7913.7740000000003, 469.99090000000001}, {7912.5946000000004, 468.81150000000002}, {7912.5946000000004, 466.45269999999999}, {7911.4152000000004, 465.27330000000001}, {7911.4152000000004, 461.73509999999999}, {7910.2358000000004, 460.5557}, {7910.2358000000004, 457.01749999999998}, {7909.0564000000004, 455.8381}, {7909.0564000000004, 453.47930000000002}, {7907.8770000000004, 452.29989999999998}, {7909.0564000000004, 451.12049999999999}, {7909.0564000000004, 449.94110000000001}, {7917.9018999999998, 441.09559999999999}, {7919.0812999999998, 441.09559999999999}, {7931.4650000000001, 428.71190000000001}, {7931.4650000000001, 427.53250000000003}, {7942.0796, 414.5591}, {7942.0796, 413.37970000000001}, {7944.4384, 411.02089999999998}, {7944.4384, 409.8415}, {7947.9766, 406.30329999999998}, {7947.9766, 405.12389999999999}, {7953.8735999999999, 398.04750000000001}, {7953.8735999999999, 396.86810000000003}, {7956.2323999999999, 394.5093}, {7956.8221000000003, 392.74020000000002}, {7961.5397000000003, 392.74020000000002}, {7962.7191000000003, 391.56080000000003}, {7963.8985000000002, 391.56080000000003}, {7965.0779000000002, 392.74020000000002}, {7966.2573000000002, 391.56080000000003}, {7967.4367000000002, 392.74020000000002}, {7998.1010999999999, 392.74020000000002}, {8003.4084000000003, 398.04750000000001}, {8003.4084000000003, 399.2269}, {8009.3054000000002, 406.30329999999998}, {8009.3054000000002, 407.48270000000002}, {8019.9200000000001, 420.45609999999999}, {8019.9200000000001, 530.14030000000002}, {8019.3302999999996, 530.73000000000002}, {8013.4332999999997, 530.73000000000002}, {8012.2538999999997, 531.90940000000001}, {8001.6392999999998, 531.90940000000001}, {8000.4598999999998, 533.08879999999999}, {7989.8453, 533.08879999999999}, {7988.6659, 534.26819999999998}, {7979.2307000000001, 534.26819999999998}, {7978.0513000000001, 535.44759999999997}, {7972.1543000000001, 535.44759999999997}};
  Vec2 c(0, 0);
  for (const Vec2& v : p) c += v;
  c /= static_cast<double>(p.size());
  for (Vec2& v : p) v -= c;
  check_decomposition(p, "digitised floe");
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


// ---- Cutting floes ------------------------------------------------------------------------------------------------

double total_area(const std::vector<Polygon>& pieces) {
  double a = 0;
  for (const Polygon& q : pieces) a += signed_area(q);
  return a;
}

// The contract every result of the cutting functions keeps: at least a triangle, CCW, simple.
void check_pieces(const std::vector<Polygon>& pieces, const std::string& what) {
  for (const Polygon& q : pieces) {
    EXPECT_GE(q.size(), 3u) << what;
    EXPECT_GT(signed_area(q), 0) << what << ": a piece is not counter-clockwise";
    EXPECT_EQ(find_self_intersection(q).first, -1) << what << ": a piece is not simple";
  }
}

// Pieces of one cut must not overlap: every pairwise intersection has (near) zero area. `tol` is an area.
void check_disjoint(const std::vector<Polygon>& pieces, double tol, const std::string& what) {
  for (size_t i = 0; i < pieces.size(); ++i)
    for (size_t j = i + 1; j < pieces.size(); ++j)
      EXPECT_LE(total_area(polygon_intersection(pieces[i], pieces[j], 0.0)), tol) << what << ": pieces overlap";
}

// Random polygon, star-shaped about `c`: n vertices at increasing angles and radii in [r0, r1].
Polygon random_star(std::mt19937& rng, const Vec2& c, int n, double r0, double r1) {
  std::uniform_real_distribution<double> U(0, 1);
  Polygon p;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * kPi * (i + 0.8 * U(rng)) / n, r = r0 + (r1 - r0) * U(rng);
    p.emplace_back(c.x() + r * std::cos(a), c.y() + r * std::sin(a));
  }
  return p;
}

TEST(SplitByLine, SquareCutByDiagonal) {
  const Polygon square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const LineSplit s = split_by_line(square, Vec2(0, 0), Vec2(1, 1));
  ASSERT_EQ(s.left.size(), 1u);
  ASSERT_EQ(s.right.size(), 1u);
  // The diagonal's end points are the square's own corners, so the halves are exact: no new vertex, no round-off.
  // Rings start at their lexicographically smallest vertex and run counter-clockwise.
  EXPECT_EQ(s.left[0], (Polygon{{0, 0}, {1, 1}, {0, 1}}));
  EXPECT_EQ(s.right[0], (Polygon{{0, 0}, {1, 0}, {1, 1}}));
  EXPECT_EQ(signed_area(s.left[0]), 0.5);
  EXPECT_EQ(signed_area(s.right[0]), 0.5);
  // The other direction swaps the sides; a clockwise input gives the same pieces.
  const LineSplit r = split_by_line(Polygon(square.rbegin(), square.rend()), Vec2(1, 1), Vec2(-1, -1));
  EXPECT_EQ(r.left, s.right);
  EXPECT_EQ(r.right, s.left);
}

TEST(SplitByLine, LShapeCutTwiceGivesThreePieces) {
  // The line x + y = 2.5 crosses both arms of the L (area 5): it cuts off the tip of each arm, a trapezoid of
  // heights 1 and widths 0.5 and 1.5 (area 1), and leaves the corner (area 3) on its right.
  const Polygon l{{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 3}, {0, 3}};
  const Vec2 point(1.25, 1.25), dir(1, -1);  // cross(dir, x - point) = x + y - 2.5
  const LineSplit s = split_by_line(l, point, dir);
  ASSERT_EQ(s.left.size(), 2u);
  ASSERT_EQ(s.right.size(), 1u);
  check_pieces(s.left, "L left");
  check_pieces(s.right, "L right");
  for (const Polygon& q : s.left) EXPECT_NEAR(signed_area(q), 1.0, 1e-14);
  EXPECT_NEAR(signed_area(s.right[0]), 3.0, 1e-14);
  for (const Polygon& q : s.left)
    for (const Vec2& v : q) EXPECT_GE(v.x() + v.y(), 2.5 - 1e-14);
  for (const Vec2& v : s.right[0]) EXPECT_LE(v.x() + v.y(), 2.5 + 1e-14);
  // Pieces sorted by their first (smallest) vertex: the left arm's tip (x = 0) before the bottom arm's (x = 1.5).
  EXPECT_NEAR(s.left[0][0].x(), 0.0, 1e-15);
  EXPECT_NEAR(s.left[1][0].x(), 1.5, 1e-15);
  EXPECT_EQ(s.right[0].size(), 6u);  // (0,0) (2.5,0) (1.5,1) (1,1) (1,1.5) (0,2.5)
}

TEST(SplitByLine, LinesThroughVerticesAndAlongEdges) {
  // An M: the rectangle [0,4] x [0,3] less the notch (1,3) (2,1) (3,3), of area 12 - 2. The line y = 1 touches the
  // notch's tip: above it, two pieces of area 3 that touch at the tip; below, the strip [0,4] x [0,1].
  const Polygon m{{0, 0}, {4, 0}, {4, 3}, {3, 3}, {2, 1}, {1, 3}, {0, 3}};
  for (const double sign : {1.0, -1.0}) {  // either direction: the tip then counts as on the left or on the right
    const LineSplit s = split_by_line(m, Vec2(2, 1), Vec2(sign, 0));
    const std::vector<Polygon>& above = sign > 0 ? s.left : s.right;
    const std::vector<Polygon>& below = sign > 0 ? s.right : s.left;
    ASSERT_EQ(above.size(), 2u) << sign;
    ASSERT_EQ(below.size(), 1u) << sign;
    EXPECT_EQ(above[0], (Polygon{{0, 1}, {2, 1}, {1, 3}, {0, 3}})) << sign;
    EXPECT_EQ(above[1], (Polygon{{2, 1}, {4, 1}, {4, 3}, {3, 3}})) << sign;
    EXPECT_EQ(below[0], (Polygon{{0, 0}, {4, 0}, {4, 1}, {0, 1}})) << sign;
  }
  // The L's notch floor y = 1, through the reflex corner: the vertical arm above, the bottom arm below.
  const Polygon l{{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 3}, {0, 3}};
  for (const double sign : {1.0, -1.0}) {
    const LineSplit s = split_by_line(l, Vec2(1, 1), Vec2(sign, 0));
    const std::vector<Polygon>& above = sign > 0 ? s.left : s.right;
    const std::vector<Polygon>& below = sign > 0 ? s.right : s.left;
    ASSERT_EQ(above.size(), 1u) << sign;
    ASSERT_EQ(below.size(), 1u) << sign;
    EXPECT_EQ(above[0], (Polygon{{0, 1}, {1, 1}, {1, 3}, {0, 3}})) << sign;
    EXPECT_EQ(below[0], (Polygon{{0, 0}, {3, 0}, {3, 1}, {0, 1}})) << sign;
  }
  // Along an edge, or touching a corner only: the polygon is whole on one side, nothing on the other.
  const Polygon square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const auto& [point, dir] : {std::pair{Vec2(0.5, 0), Vec2(1, 0)}, std::pair{Vec2(0.5, 0), Vec2(-1, 0)},
                                   std::pair{Vec2(1, 1), Vec2(1, -1)}, std::pair{Vec2(1, 1), Vec2(-1, 1)}}) {
    const LineSplit s = split_by_line(square, point, dir);
    EXPECT_EQ(s.left.size() + s.right.size(), 1u);
    EXPECT_EQ((s.left.empty() ? s.right : s.left)[0], square);
  }
}

TEST(BooleanOps, SquareAndSector) {
  // Sector of radius r = 1.2 and half-angle pi/4 about +x, apex at the centre of the square [0,2]^2: the square's
  // right edge x = 2 cuts it. In polar coordinates about the apex, the part inside the square is bounded by the
  // edge for |phi| <= phi0 = acos(1/r) and by the arc beyond, so its area is tan(phi0) + r^2 (pi/4 - phi0).
  const double r = 1.2, half = kPi / 4;
  const int n = 1024;
  const Polygon square{{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  const Polygon sector = circular_sector(Vec2(1, 1), Vec2(1, 0), half, r, n);
  const double phi0 = std::acos(1 / r);
  const double exact = std::tan(phi0) + r * r * (half - phi0);
  // The polygon's arc is made of chords, inside the circle: the clipped area differs from the circular one by less
  // than the polygon's whole deficit against the circular sector.
  const double deficit = 0.5 * r * r * (2 * half - n * std::sin(2 * half / n));
  const auto in = polygon_intersection(square, sector);
  const auto out = polygon_difference(square, sector);
  ASSERT_EQ(in.size(), 1u);
  ASSERT_EQ(out.size(), 1u);
  check_pieces(in, "square n sector");
  check_pieces(out, "square \\ sector");
  EXPECT_NEAR(total_area(in), exact, deficit);
  EXPECT_LT(total_area(in), exact);
  EXPECT_NEAR(total_area(out), 4 - exact, deficit);
  // The two share their cut vertices, so they add up to the square to round-off.
  EXPECT_NEAR(total_area(in) + total_area(out), 4.0, 4 * 1e-14);
  check_disjoint({in[0], out[0]}, 1e-12, "square/sector");
  // Intersection is symmetric.
  EXPECT_NEAR(total_area(polygon_intersection(sector, square)), total_area(in), 1e-14);
}

TEST(BooleanOps, HoleAndBadInputThrow) {
  const Polygon big{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  const Polygon small{{4, 4}, {6, 4}, {6, 6}, {4, 6}};
  // Removing an inner piece would leave a floe with a hole: an error, which callers treat as "no cut".
  EXPECT_THROW(polygon_difference(big, small), Error);
  EXPECT_THROW(cut_polygon(big, small), Error);
  // ... unless the hole is below the sliver threshold.
  EXPECT_EQ(polygon_difference(big, small, 5.0).size(), 1u);
  EXPECT_EQ(polygon_intersection(big, small), (std::vector<Polygon>{small}));
  const Polygon bowtie{{0, 0}, {1, 1}, {1, 0}, {0, 1}};
  EXPECT_THROW(polygon_intersection(bowtie, big), Error);
  EXPECT_THROW(polygon_difference(big, Polygon{{0, 0}, {1, 0}}), Error);
  EXPECT_THROW(split_by_line(big, Vec2(1, 1), Vec2(0, 0)), Error);
  // Disjoint polygons: nothing in common, the difference is the first polygon.
  const Polygon far{{20, 0}, {21, 0}, {21, 1}};
  EXPECT_TRUE(polygon_intersection(big, far).empty());
  EXPECT_EQ(polygon_difference(big, far), (std::vector<Polygon>{big}));
}

TEST(BooleanOps, RandomPolygonsConserveArea) {
  // 200 random star-shaped polygons: split by a random line (through a point near the centre, through a vertex, or
  // through two vertices), cut by another random polygon whose centre lies outside the first (so a \ b can have no
  // hole: b reaches the outside), and cut by each of their own pieces.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0, 1);
  const Vec2 c(100, -50);
  int two_sided_splits = 0, multi_piece_splits = 0, overlapping_pairs = 0, own_piece_cuts = 0, own_piece_errors = 0;
  for (int k = 0; k < 200; ++k) {
    const std::string what = "case " + std::to_string(k);
    const Polygon a = random_star(rng, c, 5 + static_cast<int>(U(rng) * 60), 5, 25);
    const double area = signed_area(a);
    ASSERT_EQ(find_self_intersection(a).first, -1) << what;

    Vec2 point = c + Vec2(10 * U(rng) - 5, 10 * U(rng) - 5);
    const double phi = 2 * kPi * U(rng);
    Vec2 dir(std::cos(phi), std::sin(phi));
    // Degenerate lines too, as a crack from a contact at a vertex makes them: through one vertex, through two.
    const size_t i = static_cast<size_t>(U(rng) * a.size()), j = (i + 2 + a.size() / 2) % a.size();
    if (k % 4 == 1) point = a[i];
    if (k % 4 == 2) point = a[i], dir = a[j] - a[i];
    const LineSplit s = split_by_line(a, point, dir, 0.0);
    check_pieces(s.left, what + " left");
    check_pieces(s.right, what + " right");
    EXPECT_NEAR(total_area(s.left) + total_area(s.right), area, 1e-9 * area) << what;
    // Each side's vertices lie on its side of the line (a vertex within 1e-9 m of it counts as on it).
    for (const Polygon& q : s.left)
      for (const Vec2& v : q) EXPECT_GE(dir.x() * (v.y() - point.y()) - dir.y() * (v.x() - point.x()), -1e-9) << what;
    for (const Polygon& q : s.right)
      for (const Vec2& v : q) EXPECT_LE(dir.x() * (v.y() - point.y()) - dir.y() * (v.x() - point.x()), 1e-9) << what;
    std::vector<Polygon> all = s.left;
    all.insert(all.end(), s.right.begin(), s.right.end());
    check_disjoint(all, 1e-9 * area, what + " split");
    multi_piece_splits += all.size() > 2;
    two_sided_splits += !s.left.empty() && !s.right.empty();

    const double beta = 2 * kPi * U(rng);
    const Vec2 cb = c + 26 * Vec2(std::cos(beta), std::sin(beta));
    const Polygon b = random_star(rng, cb, 5 + static_cast<int>(U(rng) * 60), 5, 25);
    const auto in = polygon_intersection(a, b, 0.0);
    const auto out = polygon_difference(a, b, 0.0);
    const PolygonCut cut_ab = cut_polygon(a, b, 0.0);
    EXPECT_TRUE(cut_ab.inside == in && cut_ab.outside == out) << what;
    check_pieces(in, what + " a n b");
    check_pieces(out, what + " a \\ b");
    // Shared cut vertices: the two results tile a to round-off.
    EXPECT_NEAR(total_area(in) + total_area(out), area, 1e-12 * area) << what;
    std::vector<Polygon> cut = in;
    cut.insert(cut.end(), out.begin(), out.end());
    check_disjoint(cut, 1e-9 * area, what + " a n b, a \\ b");
    // Cutting a by one of its own pieces (vertices on a's edges to within an ulp, edges shared) is the nearly
    // degenerate case: the piece comes back, or, where Boost's overlay fails, an error; never a wrong answer.
    for (const std::vector<Polygon>* side : {&s.left, &s.right})
      for (const Polygon& piece : *side) {
        try {
          const PolygonCut back = cut_polygon(a, piece, 0.0);
          EXPECT_NEAR(total_area(back.inside), signed_area(piece), 1e-9 * area) << what;
          EXPECT_NEAR(total_area(back.outside), area - signed_area(piece), 1e-9 * area) << what;
          ++own_piece_cuts;
        } catch (const Error&) {
          ++own_piece_errors;
        }
      }
    overlapping_pairs += !in.empty();

    // Deterministic: the same input gives the same bits.
    const LineSplit s2 = split_by_line(a, point, dir, 0.0);
    EXPECT_TRUE(s2.left == s.left && s2.right == s.right) << what;
    EXPECT_TRUE(polygon_difference(a, b, 0.0) == out) << what;
    if (HasFailure()) return;
  }
  // The random cases exercise what they are meant to: non-convex splits and real overlaps.
  EXPECT_GT(two_sided_splits, 180);
  EXPECT_GT(multi_piece_splits, 20);
  EXPECT_GT(overlapping_pairs, 100);
  EXPECT_LT(own_piece_errors, own_piece_cuts / 100 + 1) << own_piece_cuts << " cuts by own pieces";
}

TEST(ChordLength, SquareAndLShape) {
  const Polygon square{{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  EXPECT_NEAR(chord_length(square, Vec2(1, 1), Vec2(1, 0)), 2.0, 1e-15);
  EXPECT_NEAR(chord_length(square, Vec2(1, 1), Vec2(1, 1)), 2 * std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(chord_length(square, Vec2(0.5, 1.5), Vec2(-3, 0)), 2.0, 1e-15);  // length of dir is irrelevant
  // A point on the boundary: the chord that starts there, whichever way dir points.
  EXPECT_NEAR(chord_length(square, Vec2(0, 1), Vec2(1, 0)), 2.0, 1e-15);
  EXPECT_NEAR(chord_length(square, Vec2(0, 1), Vec2(-1, 0)), 2.0, 1e-15);
  EXPECT_NEAR(chord_length(square, Vec2(0, 0), Vec2(1, 1)), 2 * std::sqrt(2.0), 1e-15);  // corner to corner
  EXPECT_NEAR(chord_length(square, Vec2(1, 0), Vec2(1, 0)), 2.0, 1e-15);  // along an edge: the edge
  EXPECT_EQ(chord_length(square, Vec2(0, 0), Vec2(1, -1)), 0.0);         // grazing a corner
  EXPECT_EQ(chord_length(square, Vec2(3, 1), Vec2(1, 0)), 0.0);          // outside
  // L shape: the line x + y = 2.5 (direction (-1, 1)) runs through the bottom arm from (2.5, 0) to (1.5, 1), leaves
  // the L across its notch and re-enters the vertical arm from (1, 1.5) to (0, 2.5): two chords of sqrt(2) each.
  const Polygon l{{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 3}, {0, 3}};
  const Vec2 d(-1, 1);
  EXPECT_NEAR(chord_length(l, Vec2(2, 0.5), d), std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(chord_length(l, Vec2(0.5, 2), d), std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(chord_length(l, Vec2(2.5, 0), d), std::sqrt(2.0), 1e-15);
  EXPECT_EQ(chord_length(l, Vec2(1.25, 1.25), d), 0.0);  // in the notch
  // Through the reflex corner along the notch's floor: the whole width of the bottom arm.
  EXPECT_NEAR(chord_length(l, Vec2(0.5, 1), Vec2(1, 0)), 3.0, 1e-15);
}

TEST(CircularSector, ShapeAndArea) {
  const Vec2 apex(3, -2);
  const double r = 5, half = 0.6;
  const int n = 7;
  const Polygon s = circular_sector(apex, Vec2(0, 2), half, r, n);  // axis +y, not unit
  ASSERT_EQ(s.size(), static_cast<size_t>(n + 2));
  EXPECT_EQ(s[0], apex);
  EXPECT_TRUE(is_convex(s));
  // n isosceles triangles of apex angle 2 half / n.
  EXPECT_NEAR(signed_area(s), 0.5 * r * r * n * std::sin(2 * half / n), 1e-13);
  for (int k = 1; k <= n + 1; ++k) EXPECT_NEAR((s[k] - apex).norm(), r, 1e-14);
  // The arc runs from -half to +half about the axis (+y): the first arc vertex is on the right (x > apex.x).
  EXPECT_NEAR(s[1].x() - apex.x(), r * std::sin(half), 1e-14);
  EXPECT_NEAR(s[n + 1].x() - apex.x(), -r * std::sin(half), 1e-14);
  // A half disc is still a valid convex polygon.
  const Polygon hd = circular_sector(Vec2(0, 0), Vec2(1, 0), kPi / 2, 1, 64);
  EXPECT_GT(signed_area(hd), 0);
  EXPECT_TRUE(is_convex(hd));
  EXPECT_THROW(circular_sector(apex, Vec2(1, 0), 0, r, n), Error);
  EXPECT_THROW(circular_sector(apex, Vec2(1, 0), 1.6, r, n), Error);
  EXPECT_THROW(circular_sector(apex, Vec2(0, 0), half, r, n), Error);
  EXPECT_THROW(circular_sector(apex, Vec2(1, 0), half, -1, n), Error);
  EXPECT_THROW(circular_sector(apex, Vec2(1, 0), half, r, 0), Error);
}

TEST(EqualAreaWedge, ReachAreaAndShape) {
  // For each half-angle: the tip on the axis at r, the area of the circular sector r^2 half (the closed form, not
  // the polygon's own formula: against the 4096-chord sector's area), convex, CCW, symmetric about the axis.
  const Vec2 apex(3, -2), axis(0, 2);  // axis +y, not unit
  const double r = 5;
  for (double half : {0.2, kPi / 8, kPi / 6, kPi / 4, 1.4, kPi / 2}) {
    const Polygon k = equal_area_wedge(apex, axis, half, r);
    ASSERT_EQ(k.size(), 4u);
    EXPECT_EQ(k[0], apex);
    EXPECT_NEAR(k[2].x() - apex.x(), 0.0, 1e-14);
    EXPECT_NEAR(k[2].y() - apex.y(), r, 1e-14);
    EXPECT_NEAR(signed_area(k), r * r * half, 1e-12 * r * r);
    EXPECT_NEAR(signed_area(k), signed_area(circular_sector(apex, axis, half, r, 4096)), 1e-6 * r * r);
    EXPECT_TRUE(is_convex(k, 1e-9)) << half;
    EXPECT_NEAR(k[1].x() - apex.x(), -(k[3].x() - apex.x()), 1e-14);
    EXPECT_NEAR(k[1].y(), k[3].y(), 1e-14);
  }
  EXPECT_THROW(equal_area_wedge(apex, axis, 0, r), Error);
  EXPECT_THROW(equal_area_wedge(apex, axis, 1.6, r), Error);
  EXPECT_THROW(equal_area_wedge(apex, Vec2(0, 0), 0.5, r), Error);
  EXPECT_THROW(equal_area_wedge(apex, axis, 0.5, 0), Error);
}

TEST(ConvexHull2d, PointsInsideASquareAndOnItsEdgesLeaveItsFourCorners) {
  // Random points inside [0, 4] x [0, 3], others on its edges (collinear: dropped), repeats, and the corners: the
  // hull is the rectangle, counter-clockwise from the lowest-leftmost corner.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.01, 0.99);
  Polygon pts;
  for (int i = 0; i < 300; ++i) pts.push_back({4 * u(rng), 3 * u(rng)});
  for (int i = 0; i < 20; ++i) pts.push_back({4 * u(rng), 0.0}), pts.push_back({4.0, 3 * u(rng)});
  for (const Vec2& c : {Vec2(4, 3), Vec2(0, 0), Vec2(0, 3), Vec2(4, 0), Vec2(0, 0)}) pts.push_back(c);
  const Polygon h = convex_hull_2d(pts);
  ASSERT_EQ(h.size(), 4u);
  EXPECT_EQ(h[0], Vec2(0, 0));
  EXPECT_EQ(h[1], Vec2(4, 0));
  EXPECT_EQ(h[2], Vec2(4, 3));
  EXPECT_EQ(h[3], Vec2(0, 3));
  EXPECT_DOUBLE_EQ(signed_area(h), 12.0);
  EXPECT_EQ(convex_hull_2d({Vec2(1, 1), Vec2(2, 2)}).size(), 2u);  // fewer than three points: returned as they are
}

}  // namespace
}  // namespace floesim
