// Contact mechanics as physical invariants, for rigid and compliant (crushing) floe-floe contacts: a floe resting
// on another carries its weight through the contact; colliding floes in vacuum conserve linear momentum and do not
// gain energy.
#include <gtest/gtest.h>

#include <cmath>

#include "pipeline/geometry2d.h"
#include "sim/geometry/polygon3d.h"
#include "sim/engine/world.h"
#include "sim_fixtures.h"

namespace floesim::sim {
namespace {

using testing::floe_options;
using testing::rect_floe;
using testing::contact_force_on;


// A small floe put on top of a big floating one sits above the water (no buoyancy): the contact carries exactly
// its weight m g. The pair settles to a common heave equilibrium with the big floe deeper by m_small/(rho_w A_big).
// Both contact laws: a compliant (crushing) contact below its crushing force behaves as a rigid one, with one row
// at the centroid of the overlap instead of a 4-point manifold (its centroid moves under a tilting floe and
// rights it).
class SimContactLaw : public ::testing::TestWithParam<const char*> {};

TEST_P(SimContactLaw, FloeOnFloeCarriesItsWeight) {
  FloeField field;
  field.floes = {rect_floe(1, 0, 0, 20, 20, 1.0), rect_floe(2, 30, 0, 4, 4, 0.5)};
  SimulateOptions o = floe_options();
  o.contact.ice_ice = GetParam();
  const Model m = build_model(field, nullptr, o);
  World w(m);
  State& s = w.mutable_state();
  const double freeboard_big = s.position[0].z() + 0.5;
  s.position[1] = Vec3(10, 10, freeboard_big + 0.25);  // small floe's bottom on the big floe's top
  w.sync();
  Vec3 mean = Vec3::Zero();
  int n = 0;
  for (int i = 0; i < 1500; ++i) {
    w.step();
    if (i >= 1000) {
      mean += contact_force_on(w, 1);
      ++n;
    }
  }
  mean /= n;
  const double weight = m.bodies[1].mass_kg * 9.81;
  std::printf("[measured] %s: contact force on the top floe %.2f N (weight %.2f N, %+.4f %%), horizontal %.3g N\n",
              GetParam(), mean.z(), weight, 100 * (mean.z() / weight - 1), std::hypot(mean.x(), mean.y()));
  EXPECT_NEAR(mean.z() / weight, 1.0, 1e-3);
  EXPECT_LT(std::hypot(mean.x(), mean.y()), 1e-3 * weight);
  // The top floe stays level on top (a single contact point would let it tip over).
  const Vec3 up = w.state().orientation[1] * Vec3::UnitZ();
  EXPECT_GT(up.z(), 0.9999);
  // Heave equilibrium of the big floe carries the extra weight.
  const double extra = m.bodies[1].mass_kg / (o.water.density_kg_m3 * 400);
  const double sink = (m.bodies[0].initial_position.z() - w.state().position[0].z());
  std::printf("[measured] big floe sinks %.5f m, theory %.5f m\n", sink, extra);
  EXPECT_NEAR(sink, extra, 2e-3);
}

// No water, no gravity: two spinning floes collide obliquely. Linear momentum is conserved to round-off and the
// kinetic energy does not grow (contacts are inelastic; the relax pass removes push-out energy).
TEST_P(SimContactLaw, CollisionConservesMomentumInVacuum) {
  FloeField field;
  field.floes = {rect_floe(1, 0, 0, 6, 5, 1.0), rect_floe(2, 8, 1.5, 4, 4, 0.8)};
  SimulateOptions o = floe_options();
  o.contact.ice_ice = GetParam();
  o.water.enabled = false;
  o.water.gravity_mps2 = 0;
  const Model m = build_model(field, nullptr, o);
  World w(m);
  State& s = w.mutable_state();
  s.position[1].z() = s.position[0].z();
  s.velocity[0] = Vec3(1.0, 0.1, 0);
  s.velocity[1] = Vec3(-0.8, 0, 0);
  s.angular_velocity[0] = Vec3(0, 0, 0.2);
  s.angular_velocity[1] = Vec3(0, 0, -0.3);
  w.sync();
  const Vec3 p0 = w.linear_momentum();
  const double e0 = w.kinetic_energy();
  int contact_steps = 0;
  for (int i = 0; i < 400; ++i) {
    w.step();
    contact_steps += !w.contacts().empty();
  }
  const Vec3 p1 = w.linear_momentum();
  const double e1 = w.kinetic_energy();
  std::printf("[measured] %s: %d steps in contact; |dp|/|p| = %.3g; kinetic energy %.1f -> %.1f J\n", GetParam(),
              contact_steps, (p1 - p0).norm() / p0.norm(), e0, e1);
  EXPECT_GT(contact_steps, 0);
  EXPECT_LT((p1 - p0).norm(), 1e-9 * p0.norm());
  EXPECT_LE(e1, e0 * (1 + 1e-9));
  EXPECT_GT(w.state().velocity[1].x(), -0.8 + 0.1);  // the collision did change the motion
}

INSTANTIATE_TEST_SUITE_P(Laws, SimContactLaw, ::testing::Values("rigid", "compliant"));

}  // namespace
}  // namespace floesim::sim

namespace floesim::sim {
namespace {

// Faces shared by two parts of one body are not surfaces: an L-shaped floe (two convex pieces) has exactly one
// shared face per piece; the generated hull's sections share their cut planes with their neighbours.
TEST(SimContact, SharedFacesAreMarked) {
  FloeField field;
  Floe l;
  l.id = 1;
  l.thickness_m = 1;
  l.outline = {Vec2(0, 0), Vec2(10, 0), Vec2(10, 4), Vec2(4, 4), Vec2(4, 10), Vec2(0, 10)};
  field.floes = {l};
  SimulateOptions o;
  const HullModel hull = testing::coarse_hull(8);
  o.vessel.x_m = 500;  // away from the floe
  const Model m = build_model(field, &hull, o);
  auto shared = [&](int body) {
    int n = 0;
    const Body& b = m.bodies[body];
    for (int p = b.first_part; p < b.first_part + b.part_count; ++p)
      for (uint8_t f : m.parts[p].face_internal) n += f;
    return n;
  };
  ASSERT_EQ(m.bodies[1].part_count, 2);
  EXPECT_EQ(shared(1), 2);
  EXPECT_EQ(shared(0), 2 * (m.bodies[0].part_count - 1));
}

// The broad phase's candidate pairs (a grid over the awake parts, FCL's tree for awake against sleeping) against a
// second algorithm: every pair of parts of two bodies tested, their exact boxes from the poses the step starts
// from. Up to 900 floes (those that leave 0.5 m to the others), half of them L-shaped (several convex parts each,
// whose seams must not pair), rotated so that their boxes overlap their neighbours' (the floes themselves do not
// touch); a quarter asleep, so that the three kinds of pairs (awake-awake, awake-asleep, asleep-asleep: none) all
// occur.
TEST(BroadPhase, CandidatePairsAreEveryPartPairWhoseBoxesOverlap) {
  FloeField field;
  uint64_t h = 12345;
  auto next = [&] {  // deterministic uniform [0, 1)
    h = h * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(h >> 11) * 0x1.0p-53;
  };
  auto vertices_clear = [](const Polygon& a, const Polygon& b) {  // every vertex of a 0.5 m from b's edges
    for (const Vec2& v : a)
      for (size_t e = 0; e < b.size(); ++e)
        if (point_segment_distance(v, b[e], b[(e + 1) % b.size()]) <= 0.5) return false;
    return true;
  };
  std::vector<Vec2> centre;
  std::vector<double> radius;
  for (int k = 0; k < 900; ++k) {
    const double cx = 10.0 * (k % 30), cy = 10.0 * (k / 30), a = 2 * kPi * next(), s = 4 + 3 * next();
    std::vector<Vec2> shape = k % 2 ? std::vector<Vec2>{{-1, -1}, {1, -1}, {1, 0}, {0, 0}, {0, 1}, {-1, 1}}
                                    : std::vector<Vec2>{{-1, -0.5}, {1, -0.5}, {1, 0.5}, {-1, 0.5}};
    Floe f;
    f.id = k + 1;
    for (const Vec2& q : shape)
      f.outline.push_back(Vec2(cx + s * (std::cos(a) * q.x() - std::sin(a) * q.y()),
                               cy + s * (std::sin(a) * q.x() + std::cos(a) * q.y())));
    // Kept only if it leaves 0.5 m to every floe kept so far (the floes must not overlap; their boxes may).
    bool clear = true;
    for (size_t j = 0; j < field.floes.size() && clear; ++j) {
      if ((centre[j] - Vec2(cx, cy)).norm() > radius[j] + s * std::sqrt(2.0) + 0.5) continue;
      const Polygon& g = field.floes[j].outline;
      clear = polygon_intersection(f.outline, g).empty() && vertices_clear(f.outline, g) &&
              vertices_clear(g, f.outline);
    }
    if (!clear) continue;
    f.area_m2 = signed_area(f.outline);
    f.thickness_m = 1.0;
    field.floes.push_back(f);
    centre.push_back(Vec2(cx, cy));
    radius.push_back(s * std::sqrt(2.0));
  }
  SimulateOptions o = floe_options();
  o.fracture.enabled = false;
  const Model m = build_model(field, nullptr, o);
  ASSERT_GT(m.parts.size(), m.bodies.size() + 50);  // the L-shapes are cut into convex parts
  World w(m);
  State& st = w.mutable_state();
  for (size_t b = 0; b < m.bodies.size(); ++b) st.awake[b] = b % 4 != 0;
  w.sync();
  const State start = w.state();
  w.step();
  // Brute force over all part pairs, boxes from the start poses.
  std::vector<Vec3> lo(m.parts.size()), hi(m.parts.size());
  for (size_t p = 0; p < m.parts.size(); ++p) {
    const int b = m.parts[p].body;
    const Mat3 R = start.orientation[b].toRotationMatrix();
    lo[p] = Vec3::Constant(1e300), hi[p] = Vec3::Constant(-1e300);
    for (const Vec3& v : m.parts[p].vertices) {
      const Vec3 x = start.position[b] + R * v;
      lo[p] = lo[p].cwiseMin(x), hi[p] = hi[p].cwiseMax(x);
    }
  }
  long expected = 0, awake_awake = 0, with_sleeper = 0;
  for (size_t p = 0; p < m.parts.size(); ++p)
    for (size_t q = p + 1; q < m.parts.size(); ++q) {
      const int bp = m.parts[p].body, bq = m.parts[q].body;
      if (bp == bq || (!start.awake[bp] && !start.awake[bq])) continue;
      if ((lo[p].array() > hi[q].array()).any() || (lo[q].array() > hi[p].array()).any()) continue;
      ++expected;
      (start.awake[bp] && start.awake[bq] ? awake_awake : with_sleeper)++;
    }
  std::printf("[measured] %zu parts of %zu floes: %ld candidate pairs (%ld awake-awake, %ld with a sleeper), "
              "brute force %ld\n", m.parts.size(), m.bodies.size(), w.collision_stats().broadphase_pairs, awake_awake,
              with_sleeper, expected);
  EXPECT_GT(awake_awake, 100);
  EXPECT_GT(with_sleeper, 50);
  EXPECT_EQ(w.collision_stats().broadphase_pairs, expected);
}

// The two row halves of a crushing contact's surface (split_polygon_plane): a 2 m x 1 m rectangle, tilted out of
// the horizontal, cut by a plane across it. The halves' areas and centroids are the closed-form rectangles', they
// add up to the whole, and a cut through a vertex puts that vertex in both halves.
TEST(SplitPolygonPlane, HalvesOfATiltedRectangleAreTheClosedFormRectangles) {
  // Rectangle [0, 2] x [0, 1] in its own frame, placed by a rotation about x by 30 degrees and a shift.
  const double c30 = std::cos(kPi / 6), s30 = std::sin(kPi / 6);
  auto place = [&](double x, double y) { return Vec3(3.0 + x, -1.0 + c30 * y, 0.5 + s30 * y); };
  const std::vector<Vec3> rect = {place(0, 0), place(2, 0), place(2, 1), place(0, 1)};
  std::vector<Vec3> below, above;
  // The plane x = 3.5 (0.5 m into the rectangle): halves of 0.5 and 1.5 m^2.
  split_polygon_plane(rect.data(), 4, Vec3::UnitX(), 3.5, below, above);
  const AreaCentroid b = polygon_area_centroid(below.data(), static_cast<int>(below.size()));
  const AreaCentroid a = polygon_area_centroid(above.data(), static_cast<int>(above.size()));
  EXPECT_NEAR(b.area, 0.5, 1e-12);
  EXPECT_NEAR(a.area, 1.5, 1e-12);
  EXPECT_NEAR((b.centroid - place(0.25, 0.5)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((a.centroid - place(1.25, 0.5)).norm(), 0.0, 1e-12);
  // The plane through the diagonal from (0, 0) to (2, 1) (normal in the rectangle's plane): two triangles of 1 m^2
  // with centroids at the mean of their corners; both corners on the plane are in both halves.
  const Vec3 d = rect[2] - rect[0];
  const Vec3 face_normal = (rect[1] - rect[0]).cross(rect[3] - rect[0]).normalized();
  const Vec3 u = face_normal.cross(d).normalized();
  split_polygon_plane(rect.data(), 4, u, u.dot(rect[0]), below, above);
  const AreaCentroid tb = polygon_area_centroid(below.data(), static_cast<int>(below.size()));
  const AreaCentroid ta = polygon_area_centroid(above.data(), static_cast<int>(above.size()));
  EXPECT_NEAR(tb.area, 1.0, 1e-12);
  EXPECT_NEAR(ta.area, 1.0, 1e-12);
  const Vec3 t1 = (rect[0] + rect[1] + rect[2]) / 3.0, t2 = (rect[0] + rect[2] + rect[3]) / 3.0;
  // Which triangle is below depends on the sign of u; each half is one of the two.
  const double e1 = std::min((tb.centroid - t1).norm(), (tb.centroid - t2).norm());
  const double e2 = std::min((ta.centroid - t1).norm(), (ta.centroid - t2).norm());
  EXPECT_LT(e1, 1e-9);
  EXPECT_LT(e2, 1e-9);
  EXPECT_GT((tb.centroid - ta.centroid).norm(), 0.1);
  // A plane that misses the polygon leaves it whole on one side and nothing on the other.
  split_polygon_plane(rect.data(), 4, Vec3::UnitX(), 10.0, below, above);
  EXPECT_EQ(below.size(), 4u);
  EXPECT_TRUE(above.empty());
}

}  // namespace
}  // namespace floesim::sim
