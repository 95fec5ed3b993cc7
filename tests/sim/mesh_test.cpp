// Mesh mass properties, water-plane clipping, convex hulls and extrusion against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include <Eigen/Geometry>

#include "pipeline/error.h"
#include "sim/geometry/mesh.h"
#include "pipeline/geometry2d.h"

namespace floesim::sim {
namespace {


// Axis-aligned box [0,a] x [0,b] x [0,c], outward triangles.
TriMesh box(double a, double b, double c) {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1 ? a : 0, i & 2 ? b : 0, i & 4 ? c : 0);
  // Faces as quads (CCW from outside), two triangles each.
  const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

TriMesh transformed(TriMesh m, const Mat3& R, const Vec3& t) {
  for (Vec3& v : m.vertices) v = R * v + t;
  return m;
}

// Every directed edge has its reverse exactly once: closed, consistently oriented, edge-manifold.
bool closed(const TriMesh& m) {
  std::map<std::pair<int, int>, int> e;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++e[{t[k], t[(k + 1) % 3]}];
  for (const auto& [k, n] : e)
    if (n != 1 || !e.count({k.second, k.first}) || e.at({k.second, k.first}) != 1) return false;
  return true;
}

TEST(MassProperties, Box) {
  const double a = 2, b = 3, c = 5;
  const MassProperties mp = mass_properties(box(a, b, c));
  const double V = a * b * c;
  EXPECT_NEAR(mp.volume, V, 1e-12 * V);
  EXPECT_NEAR((mp.centroid - Vec3(a / 2, b / 2, c / 2)).norm(), 0, 1e-12);
  EXPECT_NEAR(mp.inertia(0, 0), V * (b * b + c * c) / 12, 1e-10);
  EXPECT_NEAR(mp.inertia(1, 1), V * (a * a + c * c) / 12, 1e-10);
  EXPECT_NEAR(mp.inertia(2, 2), V * (a * a + b * b) / 12, 1e-10);
  EXPECT_NEAR(mp.inertia(0, 1), 0, 1e-10);
  EXPECT_NEAR(mp.inertia(1, 2), 0, 1e-10);
  EXPECT_NEAR(mp.inertia(0, 2), 0, 1e-10);
}

TEST(MassProperties, InwardFacingGivesNegativeVolume) {
  TriMesh m = box(1, 1, 1);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  EXPECT_NEAR(mass_properties(m).volume, -1.0, 1e-12);
}

TEST(MassProperties, Tetrahedron) {
  // Unit right tetrahedron: V = 1/6, centroid (1/4, 1/4, 1/4); about the centroid
  // int x^2 = 1/60 - V/16 = 1/160, int xy = 1/120 - V/16 = -1/480, so Ixx = 2/160 and Ixy = -int xy = 1/480.
  TriMesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const MassProperties mp = mass_properties(m);
  EXPECT_NEAR(mp.volume, 1.0 / 6, 1e-15);
  EXPECT_NEAR((mp.centroid - Vec3::Constant(0.25)).norm(), 0, 1e-15);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(mp.inertia(i, i), 1.0 / 80, 1e-15);
    for (int j = 0; j < 3; ++j)
      if (j != i) {
        EXPECT_NEAR(mp.inertia(i, j), 1.0 / 480, 1e-15);
      }
  }
}

TEST(MassProperties, RotatedTranslatedBoxIsInvariant) {
  // Moved far from the origin and rotated: volume unchanged, centroid moved with it, inertia about the centroid
  // rotated as R I R^T (the parallel-axis shift to the centroid is done internally).
  const Mat3 R = (Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())).toRotationMatrix();
  const Vec3 t(1000, -2000, 30);
  const TriMesh b = box(2, 3, 5);
  const MassProperties m0 = mass_properties(b), m1 = mass_properties(transformed(b, R, t));
  EXPECT_NEAR(m1.volume, 30, 1e-9);
  EXPECT_NEAR((m1.centroid - (R * m0.centroid + t)).norm(), 0, 1e-9);
  EXPECT_NEAR((m1.inertia - R * m0.inertia * R.transpose()).norm(), 0, 1e-7);
}

TEST(SubmergedPart, BoxFloatingAtDepth) {
  // 4 x 2 x 3 box, bottom at z = -1.25: submerged 4 * 2 * 1.25, centre at half the depth, waterplane 8.
  const TriMesh b = transformed(box(4, 2, 3), Mat3::Identity(), Vec3(-1, 5, -1.25));
  const Submerged s = submerged_part(b.vertices, b.triangles, 0.0);
  EXPECT_NEAR(s.volume, 10.0, 1e-12);
  EXPECT_NEAR((s.centroid - Vec3(1, 6, -0.625)).norm(), 0, 1e-12);
  EXPECT_NEAR(s.waterplane_area, 8.0, 1e-12);
  // Fully submerged (plane above the top) and fully dry.
  EXPECT_NEAR(submerged_part(b.vertices, b.triangles, 10.0).volume, 24.0, 1e-12);
  EXPECT_NEAR(submerged_part(b.vertices, b.triangles, 10.0).waterplane_area, 0.0, 1e-12);
  EXPECT_NEAR(submerged_part(b.vertices, b.triangles, -5.0).volume, 0.0, 1e-12);
}

TEST(SubmergedPart, TiltedBoxClosedForm) {
  // Unit cube rolled by theta about x (through its centre), centre at height h: the immersed part of each
  // section y-z is a trapezoid. With c = cos, s = sin, the waterline crosses the cube faces y = +-1/2 at depths;
  // for small tilt (both edges wet) the immersed volume is (1/2 - h / c) per unit... compute exactly instead:
  // volume = integral over the cube of [z < 0] with z = h + s*y' + c*z' (y', z' body coordinates in [-1/2, 1/2]).
  // For |s| + |c| small enough that the plane cuts the two vertical faces, V = 1/2 - h / c, waterplane = 1 / c,
  // and the centre of buoyancy in body y' is -tan(theta) / (12 (1/2 - h/c)) * (1/... ) -> checked via moments.
  const double theta = 0.3, h = 0.1;
  const Mat3 R = Eigen::AngleAxisd(theta, Vec3::UnitX()).toRotationMatrix();
  const TriMesh cube = transformed(transformed(box(1, 1, 1), Mat3::Identity(), Vec3::Constant(-0.5)), R, Vec3(0, 0, h));
  const Submerged s = submerged_part(cube.vertices, cube.triangles, 0.0);
  const double c = std::cos(theta), sn = std::sin(theta);
  // The plane z = 0 in body coordinates: z' = -(h + sn y') / c, which stays within (-1/2, 1/2) for |y'| <= 1/2.
  ASSERT_LT((h + 0.5 * sn) / c, 0.5);
  const double V = 0.5 - h / c;  // mean of (z' + 1/2) over y' in [-1/2, 1/2]
  EXPECT_NEAR(s.volume, V, 1e-12);
  EXPECT_NEAR(s.waterplane_area, 1.0 / c, 1e-12);
  // Centroid in body coordinates from the trapezoid: depth(y') = 1/2 - (h + sn y') / c.
  // y'-moment = int y' depth dy' = -sn / (12 c); z'-moment = int (depth^2 / 2 - depth / 2) dy'.
  const double my = -sn / (12 * c);
  const double k0 = 0.5 - h / c, k1 = -sn / c;  // depth = k0 + k1 y'
  const double mz = 0.5 * (k0 * k0 + k1 * k1 / 12) - 0.5 * k0;
  const Vec3 body(0, my / V, mz / V);
  EXPECT_NEAR((s.centroid - (R * body + Vec3(0, 0, h))).norm(), 0, 1e-12);
}

TEST(SubmergedPart, ExtrudedSlabVolumeIsAreaTimesDepth) {
  // A non-convex floe outline extruded 2 m thick, floating 1.8 m deep.
  std::vector<Eigen::Vector2d> p{{0, 0}, {6, 0}, {6, 4}, {4, 4}, {4, 1.5}, {2, 1.5}, {2, 4}, {0, 4}};
  double area = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const auto &a = p[i], &b = p[(i + 1) % p.size()];
    area += 0.5 * (a.x() * b.y() - b.x() * a.y());
  }
  ASSERT_NEAR(area, 19.0, 1e-12);
  const TriMesh slab = extrude_polygon(p, -1.8, 2.0);
  EXPECT_TRUE(closed(slab));
  const MassProperties mp = mass_properties(slab);
  EXPECT_NEAR(mp.volume, 38.0, 1e-12);
  const Submerged s = submerged_part(slab.vertices, slab.triangles, 0.0);
  EXPECT_NEAR(s.volume, area * 1.8, 1e-12);
  EXPECT_NEAR(s.waterplane_area, area, 1e-12);
  EXPECT_NEAR(s.centroid.z(), -0.9, 1e-12);
  EXPECT_NEAR(mp.centroid.z(), -0.8, 1e-12);
}

TEST(ConvexHull, RandomPointsAreInsideAndHullIsClosedConvex) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> N(0, 1);
  std::vector<Vec3> pts;
  for (int i = 0; i < 2000; ++i) pts.emplace_back(3 * N(rng), N(rng), 0.5 * N(rng) + 100);
  const TriMesh h = convex_hull(pts);
  EXPECT_TRUE(closed(h));
  EXPECT_TRUE(is_convex(h, 1e-9));
  EXPECT_GT(mass_properties(h).volume, 0);
  // No input point outside any face by more than the hull's tolerance (1e-7 of its size).
  double worst = -1e300;
  for (const auto& t : h.triangles) {
    const Vec3 n = (h.vertices[t[1]] - h.vertices[t[0]]).cross(h.vertices[t[2]] - h.vertices[t[0]]).normalized();
    for (const Vec3& p : pts) worst = std::max(worst, n.dot(p - h.vertices[t[0]]));
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(ConvexHull, CubeWithPointsOnItsFacesAndEdges) {
  // A 3 x 3 x 3 lattice (corners, edge midpoints, face centres, centre) plus random points on the faces: only the
  // 8 corners are hull vertices, the volume is exactly the cube's.
  std::vector<Vec3> pts;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) pts.emplace_back(i, j, k);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0, 2);
  for (int i = 0; i < 600; ++i) {
    Vec3 p(U(rng), U(rng), U(rng));
    p[i % 3] = (i / 3) % 2 ? 2.0 : 0.0;
    pts.push_back(p);
  }
  const TriMesh h = convex_hull(pts);
  EXPECT_TRUE(closed(h));
  EXPECT_TRUE(is_convex(h, 1e-12));
  EXPECT_EQ(h.vertices.size(), 8u);
  EXPECT_EQ(h.triangles.size(), 12u);
  EXPECT_NEAR(mass_properties(h).volume, 8.0, 1e-12);
}

TEST(ConvexHull, ShipLikeSectionsWithManyCoplanarPoints) {
  // Two parallel planar sections of 200 points each (a ship-section-like outline with collinear runs): the hull is
  // a closed convex prismatoid; its volume follows the prismatoid formula (h/6)(A0 + 4 Am + A1) for sections that
  // are scaled copies: here equal sections, so V = A h.
  std::vector<Vec3> pts;
  for (double x : {0.0, 3.5})
    for (int i = 0; i < 200; ++i) {
      const double a = 2 * kPi * i / 200;
      double y = 10 * std::cos(a), z = 6 * std::sin(a);
      y = std::clamp(y, -8.0, 8.0);  // flat sides: many collinear points
      z = std::max(z, -5.0);         // flat bottom
      pts.emplace_back(x, y, z);
    }
  const TriMesh h = convex_hull(pts);
  EXPECT_TRUE(closed(h));
  EXPECT_TRUE(is_convex(h, 1e-9));
  // Section area from the 2-D hull of the same points (shoelace over the ordered outline, which is convex).
  double A = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec3 &p = pts[i], &q = pts[(i + 1) % 200];
    A += 0.5 * (p.y() * q.z() - q.y() * p.z());
  }
  EXPECT_NEAR(mass_properties(h).volume, A * 3.5, 1e-9 * A * 3.5);
}

TEST(ConvexHull, DegeneratePointsAreAnError) {
  std::vector<Vec3> flat{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.5, 0}};
  EXPECT_THROW(convex_hull(flat), Error);
  EXPECT_THROW(convex_hull({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}), Error);
}

TEST(IsConvex, DetectsADent) {
  TriMesh b = box(1, 1, 1);
  EXPECT_TRUE(is_convex(b));
  // Push a top corner down below the top face's other corners: the mesh is no longer convex.
  TriMesh dented = b;
  dented.vertices[7].z() = 0.5;
  EXPECT_FALSE(is_convex(dented, 1e-6));
  std::vector<Eigen::Vector2d> l{{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 3}, {0, 3}};
  EXPECT_FALSE(is_convex(extrude_polygon(l, 0, 1), 1e-6));
}

}  // namespace
}  // namespace floesim::sim
