// Ridge geometry (issue #36, PHYSICS.md §9; sim/engine/ridge.h): the cross-section of §9.1's first-year ridge by hand
// and by its physics (a freely floating layer, sides at the keel angle); the keel's macro-porosity measured two ways
// (the blocks' volumes, the envelope's voxels) on arrangements of known solid volume; the blocks released for
// settling (the ice they carry, none overlapping, keel under and sail over the layer, the same for the same seed);
// bad input named by its key; a block released under the layer rising to rest against it; settling a keel, a free
// ridge's hydrostatics; freeze bonds holding and breaking at their strength; the punch rig's buoyant plug; the shear
// box's balance at rest.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "pipeline/error.h"
#include "pipeline/options.h"
#include "sim/engine/ridge.h"
#include "sim/engine/ridge_build.h"
#include "sim/engine/ridge_punch.h"
#include "sim/engine/ridge_shear_box.h"
#include "sim/engine/world.h"
#include "sim/vessel/hull.h"
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

// A small ridge along y at x = 0: keel 3 m deep and 10 m wide at 45 deg under a 0.8 m layer, a 0.8 m sail at 30 deg,
// blocks 0.3 m thick and 0.5-1.0 m across.
RidgeOptions small_ridge(double y0, double y1) {
  RidgeOptions r;
  r.line = {{0, y0}, {0, y1}};
  r.sail_height_m = 0.8;
  r.keel_depth_m = 3.0;
  r.keel_width_m = 10;
  r.keel_angle_deg = 45;
  r.sail_angle_deg = 30;
  r.consolidated_thickness_m = 0.8;
  r.block_thickness_m = 0.3;
  r.block_size_m = {0.5, 1.0};
  return r;
}

// Options for settling a ridge in a strip of level ice h thick over [-x, x] x [-y, y] in tiles of `tile` m, walls at
// its ends (north, south) so that no rubble floats off there; fracture off.
SimulateOptions strip_options(double x, double y, double h, double tile) {
  SimulateOptions o = testing::floe_options();
  o.fracture.enabled = false;
  o.level_ice.extent_m = {-x, -y, x, y};
  o.level_ice.thickness_m = h;
  o.level_ice.tile_m = tile;
  o.domain.extent_m = {-x, -y, x, y};
  o.domain.walls = {"north", "south"};
  return o;
}

// The settling tests' keel: small_ridge's 2.2 m deep and 7 m wide under a 0.6 m layer, a 0.6 m sail.
RidgeOptions settling_ridge(double y0, double y1) {
  RidgeOptions r = small_ridge(y0, y1);
  r.keel_depth_m = 2.2;
  r.keel_width_m = 7;
  r.sail_height_m = 0.6;
  r.consolidated_thickness_m = 0.6;
  return r;
}

// A case's ridge (settings.ridges) in a model: its consolidated layer cut out of the level ice sheet along its line
// (h_c thick, the sheet's ice elsewhere), its rubble as released blocks carrying (1 - e) of the keel's and the sail's
// envelopes, all of it ice: the model's ice is the sheet's plus the rubble's.
TEST(RidgeModel, TheLayerIsCutOutOfTheSheetAndTheRubbleCarriesTheRidgesIce) {
  SimulateOptions o = testing::floe_options();
  o.level_ice.extent_m = {-40, -10, 40, 10};
  o.level_ice.thickness_m = 0.5;
  o.level_ice.tile_m = 20;
  o.ridges = {small_ridge(-10, 10)};
  const Model m = build_model(FloeField{}, nullptr, o);
  // By hand: the layer floats 0.8 x 900/1025 = 0.702439 m deep, so the keel is 2.297561 m deep under it, its bottom
  // 10 - 2 x 2.297561 = 5.404878 m wide, its section 17.69683 m^2; the sail rises 0.702439 m over the layer's top
  // (0.097561 m), its base 2 x 0.702439 / tan 30 = 2.433321 m, its section 0.854626 m^2. Over 20 m at e = 0.3 the
  // rubble is 247.7556 m^3 of keel and 11.96476 m^3 of sail, each overshot by less than one block (0.3 m^3).
  double layer_m2 = 0, sheet_m2 = 0, keel_m3 = 0, sail_m3 = 0, ice_kg = 0;
  int keel_blocks = 0, sail_blocks = 0;
  bool rubble_out_of_place = false;
  for (const Body& b : m.bodies) {
    if (b.kind != BodyKind::floe) continue;
    ice_kg += b.mass_kg;
    const double volume = b.section_area * b.thickness_m, z = b.initial_position.z();
    if (b.ridge_part == RidgePart::layer) {
      EXPECT_TRUE(b.fixed);
      EXPECT_DOUBLE_EQ(b.thickness_m, 0.8);
      layer_m2 += b.section_area;
    } else if (b.ridge_part == RidgePart::keel) {
      EXPECT_TRUE(b.brash);
      ++keel_blocks, keel_m3 += volume;
      rubble_out_of_place = rubble_out_of_place || z + 0.15 > -0.702439 || std::abs(b.initial_position.x()) > 5;
    } else if (b.ridge_part == RidgePart::sail) {
      EXPECT_TRUE(b.brash);
      ++sail_blocks, sail_m3 += volume;
      rubble_out_of_place = rubble_out_of_place || z - 0.15 < 0.097561;
    } else {
      EXPECT_TRUE(b.fixed);
      EXPECT_DOUBLE_EQ(b.thickness_m, 0.5);
      sheet_m2 += b.section_area;
    }
  }
  std::printf("[measured] %d keel blocks (%.3f m^3), %d sail blocks (%.3f m^3); layer %.3f m^2, sheet %.3f m^2\n",
              keel_blocks, keel_m3, sail_blocks, sail_m3, layer_m2, sheet_m2);
  EXPECT_NEAR(layer_m2, 10 * 20, 1e-9);
  EXPECT_NEAR(sheet_m2, 80 * 20 - 10 * 20, 1e-9);
  EXPECT_GE(keel_m3, 247.7556 - 1e-3);
  EXPECT_LT(keel_m3, 247.7556 + 0.3);
  EXPECT_GE(sail_m3, 11.96476 - 1e-4);
  EXPECT_LT(sail_m3, 11.96476 + 0.3);
  EXPECT_FALSE(rubble_out_of_place);  // the keel's under the layer inside its width, the sail's over it
  EXPECT_NEAR(ice_kg, kIce * (200 * 0.8 + 1400 * 0.5 + keel_m3 + sail_m3), 1e-9 * ice_kg);
  // Released out of equilibrium, the rubble starts awake; the sheet never is.
  const World w(m);
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const RidgePart p = m.bodies[b].ridge_part;
    EXPECT_EQ(w.state().awake[b] != 0, p == RidgePart::keel || p == RidgePart::sail);
  }
}

// A keel built as the ocean builds it (issue #36 item 2): the blocks released under a fixed layer float up and come
// to rest against it, the sail's fall onto it. At rest the contacts press the sheet up with the keel's net buoyancy
// less the sail's weight, the closed form of the blocks' volumes.
TEST(RidgeSettling, AKeelSettlesUnderItsLayerWhichCarriesItsNetBuoyancy) {
  SimulateOptions o = strip_options(15, 3, 0.5, 10);
  o.ridges = {settling_ridge(-3, 3)};
  World w(build_model(FloeField{}, nullptr, o));
  const Model& m = w.model();
  const double layer_bottom = -0.6 * kIce / kWater, layer_top = 0.6 + layer_bottom;
  double deepest_released = 0, net_n = 0;
  const double g = o.water.gravity_mps2;
  for (const Body& b : m.bodies) {
    if (b.ridge_part == RidgePart::keel) {
      deepest_released = std::max(deepest_released, -b.initial_position.z() + 0.15);
      net_n += (kWater - kIce) * g * b.section_area * b.thickness_m;
    }
    if (b.ridge_part == RidgePart::sail) net_n -= kIce * g * b.section_area * b.thickness_m;
  }
  for (int k = 0; k < 3000; ++k) w.step();
  const RidgeBuilt built = measure_ridge(m, w.state(), 0, 0.05);
  // The rubble's vertical push up on the fixed sheet (its tiles and the layer's) over the last step.
  double push = 0;
  for (const Contact& c : w.contacts()) {
    const double p = (c.pn * c.normal.z() + c.pt1 * c.t1.z() + c.pt2 * c.t2.z()) / o.time_step_s;  // on b, from a
    if (m.bodies[c.body_b].fixed && m.bodies[c.body_b].kind == BodyKind::floe) push += p;
    if (m.bodies[c.body_a].fixed && m.bodies[c.body_a].kind == BodyKind::floe) push -= p;
  }
  bool above_layer = false, below_layer = false;
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const Body& body = m.bodies[b];
    const double top = w.state().position[b].z() + 0.5 * std::hypot(body.thickness_m, 2 * body.section_radius);
    const double bottom = w.state().position[b].z() - 0.5 * std::hypot(body.thickness_m, 2 * body.section_radius);
    if (body.ridge_part == RidgePart::keel) above_layer = above_layer || bottom > layer_bottom;
    if (body.ridge_part == RidgePart::sail) below_layer = below_layer || top < layer_top;
  }
  std::printf("[measured] %d blocks settled in 30 s: fastest %.2e m/s; keel %.2f m deep (released to %.2f m), "
              "%.2f m^2 (%.2f m^2 sail); porosity in the keel as built %.3f by volume, %.3f by voxels; the rubble "
              "presses the sheet up with %.1f N against %.1f N by its volumes\n",
              built.blocks, built.max_block_speed_mps, built.keel_depth_m, deepest_released, built.keel_area_m2,
              built.sail_area_m2, built.porosity_by_volume, built.porosity_by_voxels, push, net_n);
  EXPECT_LT(built.max_block_speed_mps, 0.02);                        // at rest
  EXPECT_LT(built.keel_depth_m, deepest_released - 0.3);             // it rose
  EXPECT_LE(built.keel_depth_middle_m, built.keel_depth_m);          // the profile's deepest is not below any block
  EXPECT_GT(built.keel_depth_m, -layer_bottom + 0.3);                // and stays a keel
  EXPECT_FALSE(above_layer);                                         // no keel block came through the layer
  EXPECT_FALSE(below_layer);                                         // no sail block fell through it
  EXPECT_NEAR(built.porosity_by_volume, built.porosity_by_voxels, 0.03);
  EXPECT_NEAR(push, net_n, 0.01 * net_n);
}

// A ridge that no sheet holds floats freely: its layer is a free floe, and once its rubble has settled (settle_ridges)
// the whole ridge floats at rest, so its ice under the waterline over that above it is rho_i / (rho_w - rho_i) = 7.2
// (PHYSICS.md §9.1's hydrostatic check: the sail's weight carried by the keel's net buoyancy). The settled poses are
// the run's model's, matched by id, and its blocks no longer start awake. A free ridge keeps a drift of a few cm/s
// from its settling (and blocks that came out from under the layer float off), which quadratic drag stops slowly:
// rest here is below 5 cm/s.
TEST(RidgeSettling, AFreeFloatingRidgeSettlesToItsHydrostaticRatio) {
  SimulateOptions o = testing::floe_options();
  o.fracture.enabled = false;
  o.ridge_settling.rest_speed_mps = 0.05;
  o.ridges = {settling_ridge(-3, 3)};
  Model m = build_model(FloeField{}, nullptr, o);
  const RidgeSettling settled = settle_ridges(FloeField{}, m, nullptr);
  ASSERT_EQ(settled.ridges.size(), 1u);
  const RidgeBuilt& b = settled.ridges[0];
  const double ratio = b.ice_below_m3 / b.ice_above_m3;
  std::printf("[measured] free ridge of %d blocks settled in %.1f s: ice under / over the waterline %.4f (%.2f / %.2f "
              "m^3) against %.4f; keel %.2f m deep, porosity %.3f by volume, %.3f by voxels\n",
              b.blocks, settled.time_s, ratio, b.ice_below_m3, b.ice_above_m3, kIce / (kWater - kIce), b.keel_depth_m,
              b.porosity_by_volume, b.porosity_by_voxels);
  EXPECT_NEAR(ratio, kIce / (kWater - kIce), 0.01 * kIce / (kWater - kIce));
  const Model released = build_model(FloeField{}, nullptr, o);
  int moved = 0;
  for (size_t k = 0; k < m.bodies.size(); ++k) {
    if (m.bodies[k].ridge_part != RidgePart::keel && m.bodies[k].ridge_part != RidgePart::sail) continue;
    EXPECT_FALSE(m.bodies[k].start_awake);
    moved += (m.bodies[k].initial_position - released.bodies[k].initial_position).norm() > 0.1;
  }
  EXPECT_GT(moved, b.blocks / 2);  // the run starts from the settled rubble, not the released
}

// Settling packs each ridge's rubble without friction until its keel is as porous as designed (PHYSICS.md 9.5:
// released blocks settled until the macro-porosity is 0.25-0.35), then lets it rest with friction: the keel as
// built is as porous as designed within 0.03 by both measures (block volume over the envelope, and voxels), and
// the same keel settled with friction from the start is looser (jammed where its blocks first met).
TEST(RidgeSettling, RubblePacksWithoutFrictionToTheDesignedPorosity) {
  SimulateOptions o = strip_options(20, 2, 0.5, 10);
  RidgeOptions r = settling_ridge(-2, 2);
  r.keel_depth_m = 3.5;
  r.keel_width_m = 12;
  r.keel_angle_deg = 30;
  o.ridges = {r};
  auto settle = [&](double pack_max_s) {
    o.ridge_settling.pack_max_s = pack_max_s;
    Model m = build_model(FloeField{}, nullptr, o);
    return settle_ridges(FloeField{}, m, nullptr);
  };
  const RidgeSettling packed = settle(60), jammed = settle(0);
  const RidgeBuilt &p = packed.ridges.at(0), &j = jammed.ridges.at(0);
  std::printf("[measured] %d blocks: packed without friction for %.1f s, porosity as built %.3f by volume, %.3f by "
              "voxels (designed %.2f); settled with friction from the start %.3f, %.3f\n",
              p.blocks, p.packed_s, p.porosity_by_volume, p.porosity_by_voxels, r.porosity, j.porosity_by_volume,
              j.porosity_by_voxels);
  EXPECT_GT(p.packed_s, 0.0);
  EXPECT_LT(p.packed_s, 60.0);  // it reached the designed porosity
  EXPECT_NEAR(p.porosity_by_volume, r.porosity, 0.03);
  EXPECT_NEAR(p.porosity_by_voxels, r.porosity, 0.03);
  EXPECT_EQ(j.packed_s, 0.0);
  EXPECT_GT(j.porosity_by_volume, p.porosity_by_volume + 0.02);
}

// Ridges along a route (simulate.ridge_field): over a long route the count per km is the stated density less what
// the rule against overlapping layers drops, the keel depths are the stated exponential (its mean above the cut-off
// within a few standard errors), widths and sails follow the depth by §9.1's ratios, and the same seed gives the
// same ridges.
TEST(RidgeField, RidgesAlongARouteFollowTheirDensityAndDepthDistribution) {
  RidgeFieldOptions f;
  f.density_per_km = 5;
  f.route_x_m = {0, 200000};  // 200 km
  f.keel_depth_min_m = 2;
  f.keel_depth_mean_m = 4;
  f.keel_depth_max_m = 60;
  const std::vector<RidgeOptions> ridges = ridge_field_ridges(f);
  double sum = 0, last_edge = -1e300;
  bool overlap = false, ratios = true;
  for (const RidgeOptions& r : ridges) {
    sum += r.keel_depth_m - 2;
    overlap = overlap || r.line[0].x_m - 0.5 * r.keel_width_m < last_edge;
    last_edge = r.line[0].x_m + 0.5 * r.keel_width_m;
    ratios = ratios && std::abs(r.keel_width_m - 3.9 * r.keel_depth_m) < 1e-9 &&
             std::abs(r.sail_height_m - r.keel_depth_m / 4.4) < 1e-9;
  }
  const double n = static_cast<double>(ridges.size()), mean = sum / n;
  // By hand: spacings of mean 200 m, and a ridge dropped when its layer (3.9 x depth wide, 15.6 m on average) would
  // overlap the one before: about 1 - exp(-15.6 / 200) = 7.5 % of them, so about 925 ridges in 200 km.
  std::printf("[measured] %zu ridges over 200 km (%.2f per km); keel depth above the cut-off %.3f m (mean 2)\n",
              ridges.size(), n / 200, mean);
  EXPECT_NEAR(n / 200, 5 * 0.925, 0.25);             // Poisson count: s.d. 0.15 per km
  EXPECT_NEAR(mean, 2.0, 4 * 2.0 / std::sqrt(n));    // an exponential's s.d. is its mean
  EXPECT_FALSE(overlap);
  EXPECT_TRUE(ratios);
  const std::vector<RidgeOptions> again = ridge_field_ridges(f);
  ASSERT_EQ(again.size(), ridges.size());
  EXPECT_EQ(again.back().line[0].x_m, ridges.back().line[0].x_m);
  f.seed = 2;
  EXPECT_NE(ridge_field_ridges(f).front().line[0].x_m, ridges.front().line[0].x_m);
}

// The same ridge settles to the same poses, bit for bit, on one thread and on two (the engine's results do not
// depend on the thread count), and a run from them is the same again.
TEST(RidgeSettling, SettlingIsBitIdenticalOnAnyThreadCount) {
  SimulateOptions o = strip_options(10, 2, 0.4, 4);
  RidgeOptions r = small_ridge(-2, 2);
  r.keel_depth_m = 1.6;
  r.keel_width_m = 5;
  r.sail_height_m = 0;
  r.consolidated_thickness_m = 0.5;
  r.block_thickness_m = 0.25;
  r.block_size_m = {0.5, 0.8};
  o.ridges = {r};
  o.freeze_bonds.tensile_strength_pa = 2e3;  // frozen once settled, and stepped with the run
  o.freeze_bonds.shear_strength_pa = 1e3;
  auto settled = [&](int threads) {
    SimulateOptions t = o;
    t.threads = threads;
    Model m = build_model(FloeField{}, nullptr, t);
    const RidgeSettling s = settle_ridges(FloeField{}, m, nullptr);
    World w(m);
    for (int k = 0; k < 100; ++k) w.step();
    return std::make_pair(s, w.state());
  };
  const auto one = settled(1), two = settled(2);
  std::printf("[measured] %d blocks settled in %.2f s, %d freeze bonds, %zu left after 1 s\n", one.first.blocks,
              one.first.time_s, one.first.bonds, one.second.bonds.size());
  EXPECT_GT(one.first.blocks, 20);
  EXPECT_GT(one.first.bonds, one.first.blocks / 2);  // most blocks touch two others or more
  EXPECT_EQ(one.first.bonds, two.first.bonds);
  EXPECT_EQ(one.second.bonds.size(), two.second.bonds.size());
  EXPECT_EQ(one.second.bonds_broken, two.second.bonds_broken);
  EXPECT_EQ(one.first.steps, two.first.steps);
  ASSERT_EQ(one.second.position.size(), two.second.position.size());
  for (size_t b = 0; b < one.second.position.size(); ++b) {
    EXPECT_EQ(one.second.position[b], two.second.position[b]) << "body " << b;
    EXPECT_EQ(one.second.orientation[b].coeffs(), two.second.orientation[b].coeffs()) << "body " << b;
  }
  EXPECT_EQ(one.first.ridges[0].porosity_by_voxels, two.first.ridges[0].porosity_by_voxels);
}

// Two 1 x 1 x 0.5 m blocks of rubble floating side by side, touching over the face x = 0 (1 m x 0.5 m), frozen
// together where they touch (freeze_touching), then pulled by opposite forces at their centres: `dir` x (apart) or y
// (in shear), F each, for 100 steps. Returns the bonds left and how far the blocks moved apart along dir.
struct PullResult {
  size_t bonds_before = 0, bonds_after = 0;
  double area_m2 = 0, moved_m = 0;
};
PullResult pull_bonded_pair(const Vec3& dir, double force_n, double tensile_pa, double shear_pa) {
  SimulateOptions o = testing::floe_options();
  o.fracture.min_piece_area_m2 = 2;  // 1 m^2 blocks are brash: rigid contacts, as rubble
  o.freeze_bonds.tensile_strength_pa = tensile_pa;
  o.freeze_bonds.shear_strength_pa = shear_pa;
  FloeField field;
  field.floes.push_back(testing::rect_floe(1, -1, -0.5, 1, 1, 0.5));
  field.floes.push_back(testing::rect_floe(2, -0.005, -0.5, 1, 1, 0.5));  // 5 mm into the first: touching
  World w(build_model(field, nullptr, o));
  const int a = 0, b = 1;
  EXPECT_TRUE(w.model().bodies[a].brash && w.model().bodies[b].brash);
  const State before = w.state();
  w.step();
  PullResult r;
  w.mutable_state().bonds =
      freeze_touching(w.model(), before, w.contacts(), std::vector<uint8_t>(2, 1), o.freeze_bonds);
  r.bonds_before = w.state().bonds.size();
  for (const FreezeBond& fb : w.state().bonds) r.area_m2 += fb.area_m2;
  const double x0 = dir.dot(w.state().position[b] - w.state().position[a]), dt = o.time_step_s;
  // The forces act at the bond's point (on the line of the face), so that they make no couple.
  const FreezeBond bond = w.state().bonds.at(0);
  auto push = [&](int body, const Vec3& f) {
    State& s = w.mutable_state();
    const Vec3 arm = s.orientation[body] * (body == bond.body_a ? bond.anchor_a : bond.anchor_b);
    const Mat3 R = s.orientation[body].toRotationMatrix();
    const Body& bd = w.model().bodies[body];
    s.velocity[body] += f * dt / bd.mass_kg;
    s.angular_velocity[body] += R * bd.inv_inertia_added * R.transpose() * arm.cross(f) * dt;
  };
  for (int k = 0; k < 100; ++k) {
    push(a, -force_n * dir);
    push(b, force_n * dir);
    w.step();
  }
  r.bonds_after = w.state().bonds.size();
  r.moved_m = dir.dot(w.state().position[b] - w.state().position[a]) - x0;
  return r;
}

TEST(FreezeBonds, TwoBlocksHoldBelowTheirStrengthAndBreakAboveIt) {
  const double sigma_t = 20e3, tau = 10e3;  // Pa
  // By hand: the face they froze over is 1 m x 0.5 m; in tension it holds sigma_t A = 10 kN, in shear tau A = 5 kN
  // (sheared, their forces' couple is taken by the bond's tension and the contact's compression at the face's end).
  const double area = 0.5;
  const Vec3 apart = Vec3::UnitX(), along = Vec3::UnitY();
  const PullResult hold_t = pull_bonded_pair(apart, 0.9 * sigma_t * area, sigma_t, 10 * tau);
  const PullResult break_t = pull_bonded_pair(apart, 1.1 * sigma_t * area, sigma_t, 10 * tau);
  const PullResult hold_s = pull_bonded_pair(along, 0.9 * tau * area, 10 * sigma_t, tau);
  const PullResult break_s = pull_bonded_pair(along, 1.1 * tau * area, 10 * sigma_t, tau);
  std::printf("[measured] %zu bonds over %.4f m^2; in tension at 0.9 / 1.1 of sigma_t A: %zu / %zu bonds left, moved "
              "%.2e / %.3f m; in shear at 0.9 / 1.1 of tau A: %zu / %zu left, moved %.2e / %.3f m\n",
              hold_t.bonds_before, hold_t.area_m2, hold_t.bonds_after, break_t.bonds_after, hold_t.moved_m,
              break_t.moved_m, hold_s.bonds_after, break_s.bonds_after, hold_s.moved_m, break_s.moved_m);
  EXPECT_EQ(hold_t.bonds_before, 1u);  // one bond for the pair
  EXPECT_NEAR(hold_t.area_m2, area, 1e-6);
  for (const PullResult* r : {&hold_t, &hold_s}) {
    EXPECT_EQ(r->bonds_after, r->bonds_before);
    EXPECT_LT(std::abs(r->moved_m), 0.005);  // within break_opening_m: held
  }
  for (const PullResult* r : {&break_t, &break_s}) {
    EXPECT_EQ(r->bonds_after, 0u);
    EXPECT_GT(r->moved_m, 0.05);  // free: F / m t^2 / 2 = 0.3 m less the water's drag
  }
}

// A structure's load from a ridge's keel is the rubble's below its layer's underside (PHYSICS.md 9.3: F_K integrates
// the unconsolidated rubble under the consolidated layer); a block at the layer's level is rubble, not keel. In a
// vacuum without gravity two blocks of a ridge with a 1 m layer (underside -0.878 m) drift onto a fixed 10 m caisson:
// one 3 m deep, one at the waterline. The contacts are the only forces, so the keel's impulse on the caisson is the
// deep block's loss of momentum, and the rubble's the two blocks' together.
TEST(RidgeLoad, TheKeelsPartIsTheRubbleTouchingBelowTheLayer) {
  SimulateOptions o = testing::floe_options();
  o.vessel.station_keeping.mode = "fixed";
  o.water.enabled = false;
  o.water.gravity_mps2 = 0;
  o.fracture.enabled = false;
  FloeField field;
  field.floes.push_back(testing::rect_floe(1, 7, -4, 2, 2, 0.5));  // deep: at z = -3 m
  field.floes.push_back(testing::rect_floe(2, 7, 2, 2, 2, 0.5));   // shallow: at z = -0.2 m
  StructureShapeOptions shape;
  shape.shape = "caisson";
  shape.waterline_width_m = 10;
  shape.depth_m = 6;
  shape.height_m = 8;
  const HullModel caisson = hull_model_from_parts(generate_structure(shape));
  Model m = build_model(field, &caisson, o);
  RidgeOptions ridge = small_ridge(-10, 10);
  ridge.consolidated_thickness_m = 1.0;
  m.settings.ridges.push_back(ridge);
  const int deep = 1, shallow = 2;
  for (int b : {deep, shallow}) {
    m.bodies[b].ridge = 0;
    m.bodies[b].ridge_part = RidgePart::keel;
  }
  m.bodies[deep].initial_position.z() = -3.0;
  m.bodies[shallow].initial_position.z() = -0.2;
  World w(m);
  for (int b : {deep, shallow}) w.mutable_state().velocity[b] = Vec3(-1.0, 0, 0);
  auto momentum = [&](int b) { return Vec3(w.model().bodies[b].mass_kg * w.state().velocity[b]); };
  const Vec3 deep0 = momentum(deep), shallow0 = momentum(shallow);
  Vec3 keel = Vec3::Zero(), rubble = Vec3::Zero();
  for (int k = 0; k < 600; ++k) {
    w.step();
    keel += o.time_step_s * w.report().ridge_load.keel.force;
    rubble += o.time_step_s * w.report().ridge_load.rubble.force;
  }
  const Vec3 lost_deep = deep0 - momentum(deep), lost_shallow = shallow0 - momentum(shallow);
  std::printf("[measured] keel impulse %.1f N s (deep block's loss %.1f), rubble %.1f N s (both blocks' %.1f)\n",
              -keel.x(), -lost_deep.x(), -rubble.x(), -(lost_deep + lost_shallow).x());
  ASSERT_GT(lost_deep.norm(), 0.5 * deep0.norm()) << "the deep block hit the caisson";
  ASSERT_GT(lost_shallow.norm(), 0.5 * shallow0.norm()) << "the shallow block hit the caisson";
  EXPECT_LT((keel - lost_deep).norm(), 1e-9 * deep0.norm());
  EXPECT_LT((rubble - lost_deep - lost_shallow).norm(), 1e-9 * deep0.norm());
}

// The punch rig of sim/bench/ridge-punch on a shallow keel: at rest, the rubble's net buoyancy (rho_w - rho_i) g V of
// its blocks is held down by the punch, the sheet and the walls together (its balance at rest: what the punch
// carries of it depends on how the column under it leans on its neighbours); pushed down, the plug's sides resist
// and the punch's load rises above what it carried at rest.
TEST(RidgePunch, TheRubbleIsHeldAtRestAndThePlugResists) {
  PunchSpec p;
  p.keel_depth_m = 2.0;
  p.travel_m = 0.1;
  p.rest_s = 1.0;
  p.window_s = 0.2;
  const PunchResult r = punch_test(p, nullptr);
  std::printf("[measured] punch on a %d-block keel %.2f m under the sheet (porosity %.3f): held down with %.1f kN "
              "against its net buoyancy %.1f kN; the punch's share F_0 %.1f kN (a free column: %.1f kN); peak "
              "%.1f kN at %.3f m, tau %.0f Pa\n",
              r.blocks, r.plug_height_m, r.porosity, r.held_down_n / 1e3, r.rubble_buoyancy_n / 1e3, r.f0_n / 1e3,
              r.f0_by_hand_n / 1e3, r.fpeak_n / 1e3, r.peak_at_m, r.tau_pa);
  EXPECT_GT(r.blocks, 100);
  EXPECT_NEAR(r.held_down_n, r.rubble_buoyancy_n, 0.01 * r.rubble_buoyancy_n);
  EXPECT_GT(r.f0_n, 0);
  EXPECT_GT(r.fpeak_n, 1.2 * r.f0_n);
  EXPECT_GT(r.tau_pa, 0);
}

// The shear box of sim/bench/ridge-shear-box, small: consolidated and at rest, the rubble's net buoyancy
// (rho_w - rho_i) g V of its blocks and the loading plate's push are held by the top frame (its balance at rest);
// sheared, the rubble resists with more than the blocks' own friction (a granular assembly's friction angle is never
// below its grains' contact friction, atan 0.15 = 8.5 deg here); the same sample frozen resists more than unfrozen.
TEST(ShearBox, TheSampleIsHeldAtRestAndResistsMoreThanItsBlocksFriction) {
  ShearBoxSpec p;
  p.box_m = 4.0;
  p.sample_height_m = 1.6;
  p.normal_stress_pa = 4000;
  p.travel_m = 0.2;
  p.peak_within_m = 0.2;
  p.speed_mps = 0.05;
  p.window_s = 0.2;
  p.bonds_pa = {0, 100000};
  const ShearBoxResult r = shear_box_test(p, nullptr);
  ASSERT_EQ(r.shears.size(), 2u);
  const ShearTest &loose = r.shears[0], &frozen = r.shears[1];
  std::printf("[measured] shear box of %d blocks, sample %.2f m high (porosity %.3f): the top frame holds %.1f kN "
              "against the buoyancy and the plate's push %.1f kN; normal stress %.0f Pa consolidated; peak shear "
              "stress %.0f Pa at %.0f Pa, with %d bonds of 100 kPa %.0f Pa at %.0f Pa (%ld broken)\n",
              r.blocks, r.sample_height_m, r.porosity, r.held_down_n / 1e3, r.pushed_up_n / 1e3,
              r.sigma_consolidated_pa, loose.tau_peak_pa, loose.sigma_at_peak_pa, frozen.bonds, frozen.tau_peak_pa,
              frozen.sigma_at_peak_pa, frozen.bonds_broken);
  EXPECT_GT(r.blocks, 20);
  EXPECT_GT(r.pushed_up_n, r.buoyancy_n);  // the plate pushes
  EXPECT_NEAR(r.held_down_n, r.pushed_up_n, 0.01 * r.pushed_up_n);
  EXPECT_GT(r.porosity, 0);
  EXPECT_LT(r.porosity, 1);
  EXPECT_EQ(loose.bonds, 0);
  EXPECT_GT(loose.tau_peak_pa, 0.15 * loose.sigma_at_peak_pa);
  EXPECT_GT(frozen.bonds, r.blocks / 2);  // most blocks touch two others or more
  EXPECT_GT(frozen.tau_peak_pa, loose.tau_peak_pa);
}

TEST(ShearBox, BadSpecNamesTheField) {
  ShearBoxSpec small;
  small.box_m = 2.0;  // the largest block is 1.6 m
  expect_error([&] { shear_box_test(small, nullptr); }, {"box_m", "largest block"});
  ShearBoxSpec far;
  far.travel_m = 5.0;
  expect_error([&] { shear_box_test(far, nullptr); }, {"travel_m"});
  ShearBoxSpec late;
  late.travel_m = 0.2;  // the peak is read within 0.3 m
  expect_error([&] { shear_box_test(late, nullptr); }, {"peak_within_m", "travel_m"});
  ShearBoxSpec negative;
  negative.bonds_pa = {0, -1};
  expect_error([&] { shear_box_test(negative, nullptr); }, {"bonds_pa"});
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
  // Freeze bonds with one strength but not the other.
  expect_error([&] { read_options<FreezeBondOptions>({{"tensile_strength_pa", 1e4}}, "case.json"); },
               {"case.json", "shear_strength_pa", "both"});
  // A ridge running off the sheet's edge (its layer half on the sheet): named, with the fix.
  SimulateOptions o = testing::floe_options();
  o.level_ice.extent_m = {-40, -10, 40, 10};
  o.level_ice.tile_m = 20;
  o.ridges = {small_ridge(-30, 10)};
  expect_error([&] { build_model(FloeField{}, nullptr, o); }, {"ridges[0]", "segment 0", "sheet"});
}

}  // namespace
}  // namespace floesim::sim
