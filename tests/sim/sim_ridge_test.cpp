// Ridge geometry (issue #36, PHYSICS.md §9; sim/engine/ridge.h): the cross-section of §9.1's first-year ridge by hand
// and by its physics (a freely floating layer, sides at the keel angle); the keel's macro-porosity measured two ways
// (the blocks' volumes, the envelope's voxels) on arrangements of known solid volume; the blocks released for
// settling (the ice they carry, none overlapping, keel under and sail over the layer, the same for the same seed);
// bad input named by its key; a block released under the layer rising to rest against it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "pipeline/error.h"
#include "pipeline/options.h"
#include "sim/engine/ridge.h"
#include "tests/sim/sim_fixtures.h"

namespace floesim::sim {
namespace {

using testing::expect_error;

constexpr double kIce = 900, kWater = 1025;

// §9.1's first-year ridge: sail 1.5 m, keel draft 4.4 x 1.5 = 6.6 m, keel width 3.9 x 6.6 = 25.7 m; a 1 m
// consolidated layer; keel sides at 30 deg, sail at 21 deg; 60 m straight along y.
RidgeOptions first_year() {
  RidgeOptions r;
  r.line = {{100, -30}, {100, 30}};
  return r;
}

TEST(RidgeSection, FirstYearRidgeByHand) {
  const RidgeSection s = ridge_section(first_year(), kIce, kWater, "test");
  // By hand: layer draft 1 x 900/1025 = 0.87805 m; keel 6.6 - 0.87805 = 5.72195 m deep under it; each side runs
  // 5.72195 / tan 30 = 9.91071 m, so the bottom is 25.7 - 19.82142 = 5.87858 m wide and the keel's section
  // (25.7 + 5.87858) / 2 x 5.72195 = 90.3455 m^2; the sail 1.5 - 0.12195 = 1.37805 m over the layer, its base
  // 2 x 1.37805 / tan 21 = 7.17988 m and its section 4.94711 m^2.
  EXPECT_NEAR(s.layer_bottom_z, -0.878049, 1e-6);
  EXPECT_NEAR(s.keel_bottom_width_m, 5.878580, 1e-6);
  EXPECT_NEAR(s.keel_area_m2, 90.34555, 1e-5);
  EXPECT_NEAR(s.sail_base_width_m, 7.179880, 1e-6);
  EXPECT_NEAR(s.sail_area_m2, 4.947112, 1e-6);
  // Its physics: the layer floats freely (draft / thickness = rho_i / rho_w) and the keel's sides slope at 30 deg.
  EXPECT_NEAR(s.layer_top_z - s.layer_bottom_z, 1.0, 1e-12);
  EXPECT_NEAR(-s.layer_bottom_z / 1.0, kIce / kWater, 1e-12);
  const double side = std::atan2(s.layer_bottom_z - s.keel_bottom_z,
                                 0.5 * (s.keel_top_width_m - s.keel_bottom_width_m)) * 180 / kPi;
  EXPECT_NEAR(side, 30.0, 1e-9);
}

// Blocks of known volume in the keel's envelope: a regular pattern of boxes turned by 30 deg, all inside it.
std::vector<RidgeBlock> pattern(const RidgeSection& s, double& volume) {
  std::vector<RidgeBlock> blocks;
  volume = 0;
  for (int layer = 0; layer < 4; ++layer)
    for (int i = -2; i <= 2; ++i)
      for (int j = 0; j < 10; ++j) {
        RidgeBlock k;
        k.centre = Vec2(100 + 2.2 * i, -27 + 6.0 * j);
        k.z = s.layer_bottom_z - 0.4 - 1.0 * layer;
        k.size_x = 1.8, k.size_y = 1.2, k.thickness = 0.5;
        k.yaw_rad = kPi / 6;
        blocks.push_back(k);
        volume += 1.8 * 1.2 * 0.5;
      }
  return blocks;
}

TEST(KeelPorosity, TheBlocksVolumesAndTheEnvelopesVoxelsAgree) {
  const RidgeSection s = ridge_section(first_year(), kIce, kWater, "test");
  double solid = 0;
  const std::vector<RidgeBlock> blocks = pattern(s, solid);
  const KeelPorosity p = keel_porosity(blocks, s, Vec2(100, -30), Vec2(100, 30), 0.05);
  // Every block lies wholly inside, so by volume the porosity is exact: 1 - 200 x 1.08 / (90.3455 x 60).
  EXPECT_NEAR(p.blocks_in_envelope_m3, solid, 1e-9);
  EXPECT_NEAR(p.by_volume, 1 - solid / (s.keel_area_m2 * 60), 1e-12);
  // The voxels (5 cm) see the same solid within a percent of the envelope's volume.
  std::printf("[measured] pattern of 200 blocks: porosity by volume %.5f, by 5 cm voxels %.5f\n", p.by_volume,
              p.by_voxels);
  EXPECT_NEAR(p.by_voxels, p.by_volume, 0.01);
  // An empty keel is all pores, both ways; the envelope's volume is its section times the length.
  const KeelPorosity none = keel_porosity({}, s, Vec2(100, -30), Vec2(100, 30), 0.1);
  EXPECT_DOUBLE_EQ(none.by_volume, 1.0);
  EXPECT_DOUBLE_EQ(none.by_voxels, 1.0);
  EXPECT_NEAR(none.envelope_m3, 90.34555 * 60, 1e-3);
  // A block half out of the keel (through its bottom) counts by half, both ways.
  RidgeBlock half;
  half.centre = Vec2(100, 0);
  half.z = s.keel_bottom_z;
  half.size_x = half.size_y = 2.0, half.thickness = 1.0;
  const KeelPorosity h = keel_porosity({half}, s, Vec2(100, -30), Vec2(100, 30), 0.05);
  EXPECT_NEAR(h.blocks_in_envelope_m3, 2.0, 1e-9);
  EXPECT_NEAR(1 - h.by_voxels, 2.0 / h.envelope_m3, 0.05 * 2.0 / h.envelope_m3);
}

TEST(RidgeBlocks, ReleasedBlocksCarryTheRidgesIceWithoutOverlap) {
  const RidgeOptions r = first_year();
  const RidgeSection s = ridge_section(r, kIce, kWater, "test");
  const std::vector<RidgeBlock> blocks = release_blocks(r, s);
  double keel = 0, sail = 0, largest = 0;
  for (const RidgeBlock& k : blocks) {
    const double v = k.size_x * k.size_y * k.thickness;
    (k.keel ? keel : sail) += v;
    largest = std::max(largest, v);
    EXPECT_GE(std::min(k.size_x, k.size_y), r.block_size_m[0]);
    EXPECT_LE(std::max(k.size_x, k.size_y), r.block_size_m[1]);
    // Keel blocks start under the layer (to float up), sail blocks over it (to fall onto it).
    if (k.keel)
      EXPECT_LT(k.z + 0.5 * k.thickness, s.layer_bottom_z);
    else
      EXPECT_GT(k.z - 0.5 * k.thickness, s.layer_top_z);
  }
  std::printf("[measured] first-year ridge, 60 m: %zu blocks released, keel %.1f m^3, sail %.1f m^3\n",
              blocks.size(), keel, sail);
  // (1 - e) of each envelope over the 60 m, to within the last block.
  EXPECT_GE(keel, 0.7 * s.keel_area_m2 * 60);
  EXPECT_LT(keel, 0.7 * s.keel_area_m2 * 60 + largest);
  EXPECT_GE(sail, 0.7 * s.sail_area_m2 * 60);
  EXPECT_LT(sail, 0.7 * s.sail_area_m2 * 60 + largest);
  // No two blocks overlap: no corner or centre of one lies in another (blocks are boxes of one thickness at about
  // one height per layer, so an overlap shows at a corner or a centre at mid-thickness).
  for (size_t i = 0; i < blocks.size(); ++i)
    for (size_t j = 0; j < blocks.size(); ++j) {
      if (i == j || (blocks[i].centre - blocks[j].centre).norm() > 2 * r.block_size_m[1]) continue;
      const RidgeBlock& a = blocks[i];
      const double c = std::cos(a.yaw_rad), sn = std::sin(a.yaw_rad);
      for (double fx : {-0.5, 0.0, 0.5})
        for (double fy : {-0.5, 0.0, 0.5}) {
          const Vec2 p =
              a.centre + Vec2(c * fx * a.size_x - sn * fy * a.size_y, sn * fx * a.size_x + c * fy * a.size_y);
          ASSERT_FALSE(block_contains(blocks[j], p, a.z)) << "blocks " << i << " and " << j;
        }
    }
  // The same options give the same blocks; another seed others.
  const std::vector<RidgeBlock> again = release_blocks(r, s);
  ASSERT_EQ(again.size(), blocks.size());
  for (size_t i = 0; i < blocks.size(); ++i) {
    EXPECT_EQ(again[i].centre, blocks[i].centre);
    EXPECT_EQ(again[i].yaw_rad, blocks[i].yaw_rad);
  }
  RidgeOptions other = r;
  other.seed = 2;
  EXPECT_NE(release_blocks(other, s).front().size_x, blocks.front().size_x);
}

// How a keel is built (issue #36 item 2): a block released under the consolidated layer floats up and comes to rest
// against its underside. A 2 m x 2 m x 0.5 m block 3 m deep under a 1 m sheet (one fixed tile): at rest its top
// touches the layer's bottom, z = -0.87805 - 0.25 m, and the contact carries its net buoyancy (rho_w - rho_i) g V.
TEST(RidgeSettling, ABlockReleasedUnderTheLayerRisesAndRestsAgainstIt) {
  SimulateOptions o = testing::floe_options();
  o.fracture.enabled = false;
  o.level_ice.extent_m = {-20, -20, 20, 20};
  o.level_ice.thickness_m = 1.0;
  o.level_ice.tile_m = 40;
  FloeField field;
  field.floes.push_back(testing::rect_floe(1, 29, -1, 2, 2, 0.5));  // beside the sheet: plan overlaps are refused
  Model m = build_model(field, nullptr, o);
  int block = -1;
  for (size_t b = 0; b < m.bodies.size(); ++b)
    if (m.bodies[b].kind == BodyKind::floe && !m.bodies[b].fixed) block = static_cast<int>(b);
  ASSERT_GE(block, 0);
  m.bodies[block].initial_position = Vec3(0, 0, -3.0);  // released under the sheet's middle
  World w(m);
  const double rest_z = -1.0 * kIce / kWater - 0.25;
  double max_up = 0;
  for (int k = 0; k < 4000; ++k) {
    w.step();
    max_up = std::max(max_up, w.state().velocity[block].z());
  }
  const Vec3& x = w.state().position[block];
  // The contacts' vertical push on the block over the last step (impulses / dt) against its net buoyancy.
  double push = 0;
  for (const Contact& c : w.contacts()) {
    const double p = c.pn * c.normal.z() + c.pt1 * c.t1.z() + c.pt2 * c.t2.z();  // on b, from a
    if (c.body_b == block) push += p;
    if (c.body_a == block) push -= p;
  }
  push /= o.time_step_s;
  const double net = (kWater - kIce) * o.water.gravity_mps2 * 2.0;  // V = 2 x 2 x 0.5 m^3
  std::printf("[measured] block at rest: z %.4f m (by hand %.4f), largest rising speed %.3f m/s, |v| %.2e m/s; "
              "the layer pushes it down with %.1f N against its net buoyancy %.1f N\n",
              x.z(), rest_z, max_up, w.state().velocity[block].norm(), -push, net);
  EXPECT_GT(max_up, 0.05);  // it rose
  // Against the layer: its impact at the rising speed crushed a few millimetres of the layer's underside.
  EXPECT_NEAR(x.z(), rest_z, 0.01);
  EXPECT_LT(w.state().velocity[block].norm(), 1e-3);  // at rest
  EXPECT_NEAR(x.x(), 0.0, 0.05);                      // straight up
  EXPECT_NEAR(-push, net, 0.01 * net);                // the layer carries its net buoyancy
}

TEST(RidgeSection, BadInputNamesTheKey) {
  RidgeOptions shallow = first_year();
  shallow.keel_depth_m = 0.5;  // the 1 m layer floats 0.88 m deep
  expect_error([&] { ridge_section(shallow, kIce, kWater, "ridge.json"); }, {"ridge.json", "keel_depth_m"});
  RidgeOptions narrow = first_year();
  narrow.keel_width_m = 10;  // needs 19.8 m at 30 deg
  expect_error([&] { ridge_section(narrow, kIce, kWater, "ridge.json"); }, {"keel_width_m", "keel_angle_deg"});
  RidgeOptions big = first_year();
  big.block_thickness_m = 6;
  expect_error([&] { ridge_section(big, kIce, kWater, "ridge.json"); }, {"block_thickness_m"});
  // The options' own checks: a porosity outside (0, 1), a one-point line, an unknown key.
  const nlohmann::json line = nlohmann::json::array({{{"x_m", 0}, {"y_m", 0}}, {{"x_m", 0}, {"y_m", 50}}});
  expect_error([&] { read_options<RidgeOptions>({{"line", line}, {"porosity", 1.2}}, "ridge.json"); },
               {"ridge.json", "porosity"});
  expect_error([&] { read_options<RidgeOptions>({{"line", {{{"x_m", 0}, {"y_m", 0}}}}}, "ridge.json"); },
               {"line", "two points"});
  expect_error([&] { read_options<RidgeOptions>({{"line", line}, {"keel_draught_m", 6}}, "ridge.json"); },
               {"keel_draught_m"});
}

}  // namespace
}  // namespace floesim::sim
