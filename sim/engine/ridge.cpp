#include "sim/engine/ridge.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "pipeline/error.h"

namespace floesim::sim {

namespace {

// A draw in [0, 1) from the generator's 53 high bits (the same on every platform, unlike the standard
// distributions).
double unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

}  // namespace

RidgeSection ridge_section(const RidgeOptions& r, double ice_density, double water_density, const std::string& where) {
  FLOESIM_REQUIRE(ice_density > 0 && water_density > ice_density, where,
                  ": ice.density_kg_m3 must be below water.density_kg_m3 for a ridge to float");
  RidgeSection s;
  const double hc = r.consolidated_thickness_m;
  s.layer_bottom_z = -hc * ice_density / water_density;
  s.layer_top_z = s.layer_bottom_z + hc;
  s.keel_bottom_z = -r.keel_depth_m;
  FLOESIM_REQUIRE(r.keel_depth_m > -s.layer_bottom_z, where, ": keel_depth_m ", r.keel_depth_m,
                  " m does not reach below the consolidated layer (its bottom is ", -s.layer_bottom_z,
                  " m below the waterline for consolidated_thickness_m ", hc, "): deepen the keel or thin the layer");
  const double depth = s.layer_bottom_z - s.keel_bottom_z;  // of the keel below the layer
  const double run = depth / std::tan(r.keel_angle_deg * kPi / 180);
  s.keel_top_width_m = r.keel_width_m;
  s.keel_bottom_width_m = r.keel_width_m - 2 * run;
  FLOESIM_REQUIRE(s.keel_bottom_width_m >= 0, where, ": keel_width_m ", r.keel_width_m, " m is too narrow for a keel ",
                  depth, " m deep under the layer with sides at keel_angle_deg ", r.keel_angle_deg,
                  ": it needs at least ", 2 * run, " m (widen it, or steepen keel_angle_deg)");
  s.keel_area_m2 = 0.5 * (s.keel_top_width_m + s.keel_bottom_width_m) * depth;
  const double sail = std::max(0.0, r.sail_height_m - s.layer_top_z);  // above the layer's top
  s.sail_base_width_m = sail > 0 ? 2 * sail / std::tan(r.sail_angle_deg * kPi / 180) : 0.0;
  s.sail_area_m2 = 0.5 * s.sail_base_width_m * sail;
  FLOESIM_REQUIRE(s.sail_base_width_m <= r.keel_width_m, where, ": the sail (sail_height_m ", r.sail_height_m,
                  " at sail_angle_deg ", r.sail_angle_deg, ") is ", s.sail_base_width_m,
                  " m wide at its base, wider than the consolidated layer (keel_width_m ", r.keel_width_m, ")");
  const double largest = r.block_size_m.size() == 2 ? r.block_size_m[1] : 0.0;
  FLOESIM_REQUIRE(r.block_thickness_m < depth && largest <= s.keel_top_width_m, where,
                  ": blocks of block_size_m up to ", largest, " m and block_thickness_m ", r.block_thickness_m,
                  " m do not fit a keel ", s.keel_top_width_m, " m wide and ", depth,
                  " m deep under the layer: make them smaller");
  FLOESIM_REQUIRE(r.line.size() >= 2, where, ": line needs at least two points");
  for (size_t i = 1; i < r.line.size(); ++i) {
    const double len = std::hypot(r.line[i].x_m - r.line[i - 1].x_m, r.line[i].y_m - r.line[i - 1].y_m);
    FLOESIM_REQUIRE(len >= largest, where, ": line segment ", i - 1, "-", i, " is ", len,
                    " m long, shorter than the largest block (block_size_m ", largest, ")");
  }
  return s;
}

std::vector<RidgeBlock> release_blocks(const RidgeOptions& r, const RidgeSection& section) {
  std::vector<RidgeBlock> out;
  std::mt19937_64 rng(static_cast<std::uint64_t>(r.seed));
  const double lo = r.block_size_m[0], hi = r.block_size_m[1], h = r.block_thickness_m;
  auto draw_size = [&] { return lo * std::pow(hi / lo, unit(rng)); };
  // A cell holds any block at any yaw: the largest block's diagonal, and its thickness, plus a tenth.
  const double cell = 1.1 * std::sqrt(2.0) * hi, cell_z = 1.1 * h;
  for (size_t seg = 1; seg < r.line.size(); ++seg) {
    const Vec2 a(r.line[seg - 1].x_m, r.line[seg - 1].y_m), b(r.line[seg].x_m, r.line[seg].y_m);
    const double length = (b - a).norm();
    const Vec2 t = (b - a) / length, n(-t.y(), t.x());  // along, across (to the left)
    const int along = std::max(1, static_cast<int>(std::floor(length / cell)));
    const double pitch = length / along;
    // The keel's blocks below the layer, then the sail's above it: layer after layer away from the layer, each
    // layer across the width, then along the segment.
    for (bool keel : {true, false}) {
      const double width = keel ? section.keel_top_width_m : section.sail_base_width_m;
      const double target = (1 - r.porosity) * (keel ? section.keel_area_m2 : section.sail_area_m2) * length;
      if (!(target > 0)) continue;
      const int across = std::max(1, static_cast<int>(std::floor(width / cell)));
      const double pitch_s = width / across;
      double volume = 0;
      for (int layer = 0; volume < target; ++layer) {
        const double z = keel ? section.layer_bottom_z - (layer + 0.5) * cell_z
                              : section.layer_top_z + (layer + 0.5) * cell_z;
        for (int j = 0; j < along && volume < target; ++j)
          for (int i = 0; i < across && volume < target; ++i) {
            RidgeBlock k;
            k.keel = keel;
            k.size_x = draw_size();
            k.size_y = draw_size();
            k.thickness = h;
            k.yaw_rad = 2 * kPi * unit(rng);
            // Its footprint's half extents along the cell's axes at that yaw, and the slack left in the cell.
            const double c = std::abs(std::cos(k.yaw_rad)), s = std::abs(std::sin(k.yaw_rad));
            const double ex = 0.5 * (k.size_x * c + k.size_y * s), ey = 0.5 * (k.size_x * s + k.size_y * c);
            const double slack_t = std::max(0.0, 0.5 * std::min(pitch, cell) - ex);
            const double slack_s = std::max(0.0, 0.5 * std::min(pitch_s, cell) - ey);
            const double u = (j + 0.5) * pitch + slack_t * (2 * unit(rng) - 1);
            const double v = -0.5 * width + (i + 0.5) * pitch_s + slack_s * (2 * unit(rng) - 1);
            k.centre = a + u * t + v * n;
            k.z = z + 0.05 * h * (2 * unit(rng) - 1);
            k.yaw_rad += std::atan2(t.y(), t.x());  // the block's axes were drawn in the segment's frame
            out.push_back(k);
            volume += k.size_x * k.size_y * h;
          }
      }
    }
  }
  return out;
}

std::vector<RidgeOptions> ridge_field_ridges(const RidgeFieldOptions& f) {
  std::vector<RidgeOptions> out;
  if (!(f.density_per_km > 0)) return out;
  std::mt19937_64 rng(static_cast<std::uint64_t>(f.seed) ^ 0x9e3779b97f4a7c15ULL);
  const double spacing = 1000.0 / f.density_per_km, scale = f.keel_depth_mean_m - f.keel_depth_min_m;
  double x = f.route_x_m[0], last_edge = -1e300;
  for (int k = 0; k < 100000; ++k) {
    x += -spacing * std::log(1 - unit(rng));
    double depth = f.keel_depth_max_m + 1;
    while (depth > f.keel_depth_max_m) depth = f.keel_depth_min_m - scale * std::log(1 - unit(rng));
    const double width = f.width_over_depth * depth;
    if (x - 0.5 * width < last_edge) continue;  // its layer would overlap the one before: not a ridge of its own
    if (x + 0.5 * width > f.route_x_m[1]) break;
    RidgeOptions r;
    r.line = {{x, f.across_y_m[0]}, {x, f.across_y_m[1]}};
    r.keel_depth_m = depth;
    r.keel_width_m = width;
    r.sail_height_m = depth / f.depth_over_sail;
    r.consolidated_thickness_m = f.consolidated_thickness_m;
    r.keel_angle_deg = f.keel_angle_deg;
    r.sail_angle_deg = f.sail_angle_deg;
    r.porosity = f.porosity;
    r.block_thickness_m = f.block_thickness_m;
    r.block_size_m = f.block_size_m;
    r.seed = f.seed + static_cast<int>(out.size()) + 1;
    out.push_back(r);
    last_edge = x + 0.5 * width;
  }
  return out;
}

bool block_contains(const RidgeBlock& k, const Vec2& p, double z) {
  if (std::abs(z - k.z) > 0.5 * k.thickness) return false;
  const Vec2 d = p - k.centre;
  const double c = std::cos(k.yaw_rad), s = std::sin(k.yaw_rad);
  return std::abs(c * d.x() + s * d.y()) <= 0.5 * k.size_x && std::abs(-s * d.x() + c * d.y()) <= 0.5 * k.size_y;
}

namespace {

// Whether (s, t, z) in the segment frame lies in the keel's envelope (the trapezoid swept over t in [0, length]).
bool in_envelope(const RidgeSection& e, double length, double s, double t, double z) {
  if (t < 0 || t > length || z > e.layer_bottom_z || z < e.keel_bottom_z) return false;
  const double f = (z - e.keel_bottom_z) / (e.layer_bottom_z - e.keel_bottom_z);  // 0 at the bottom, 1 at the top
  return std::abs(s) <= 0.5 * (e.keel_bottom_width_m + f * (e.keel_top_width_m - e.keel_bottom_width_m));
}

}  // namespace

KeelPorosity keel_porosity(const std::vector<RidgeBlock>& blocks, const RidgeSection& e, const Vec2& a, const Vec2& b,
                           double voxel_m) {
  FLOESIM_REQUIRE(voxel_m > 0, "keel_porosity: the voxel edge must be > 0, got ", voxel_m);
  const double length = (b - a).norm();
  FLOESIM_REQUIRE(length > 0, "keel_porosity: the segment has no length");
  const Vec2 t = (b - a) / length, n(-t.y(), t.x());
  auto frame = [&](const Vec2& p, double& s, double& u) {
    s = (p - a).dot(n);
    u = (p - a).dot(t);
  };
  KeelPorosity r;
  r.envelope_m3 = e.keel_area_m2 * length;
  // 1. By the blocks' volumes: each block sampled on a 12 x 12 x 4 grid of its own volume's cell centres (exact for
  // a block wholly inside or outside).
  constexpr int kN = 12, kNz = 4;
  for (const RidgeBlock& k : blocks) {
    const double c = std::cos(k.yaw_rad), sn = std::sin(k.yaw_rad);
    int inside = 0;
    for (int i = 0; i < kN; ++i)
      for (int j = 0; j < kN; ++j) {
        const double lx = ((i + 0.5) / kN - 0.5) * k.size_x, ly = ((j + 0.5) / kN - 0.5) * k.size_y;
        const Vec2 p = k.centre + Vec2(c * lx - sn * ly, sn * lx + c * ly);
        double s, u;
        frame(p, s, u);
        for (int q = 0; q < kNz; ++q)
          inside += in_envelope(e, length, s, u, k.z + ((q + 0.5) / kNz - 0.5) * k.thickness);
      }
    r.blocks_in_envelope_m3 += k.size_x * k.size_y * k.thickness * inside / (kN * kN * kNz);
  }
  r.by_volume = 1 - r.blocks_in_envelope_m3 / r.envelope_m3;
  // 2. By voxels of the envelope: centres on a grid over its box in the segment frame; candidates per voxel from a
  // coarse bucket grid of the blocks' plan boxes.
  const double half = 0.5 * e.keel_top_width_m;
  const int ns = static_cast<int>(std::ceil(2 * half / voxel_m)), nt = static_cast<int>(std::ceil(length / voxel_m));
  const int nz = static_cast<int>(std::ceil((e.layer_bottom_z - e.keel_bottom_z) / voxel_m));
  const double bucket = 2.0;  // m, along t
  const int nb = static_cast<int>(std::ceil(length / bucket)) + 1;
  std::vector<std::vector<int>> buckets(nb);
  for (size_t i = 0; i < blocks.size(); ++i) {
    double s, u;
    frame(blocks[i].centre, s, u);
    const double reach = 0.5 * std::hypot(blocks[i].size_x, blocks[i].size_y);
    const int b0 = std::max(0, static_cast<int>(std::floor((u - reach) / bucket)));
    const int b1 = std::min(nb - 1, static_cast<int>(std::floor((u + reach) / bucket)));
    for (int q = b0; q <= b1; ++q) buckets[q].push_back(static_cast<int>(i));
  }
  long in_env = 0, solid = 0;
  for (int it = 0; it < nt; ++it) {
    const double u = (it + 0.5) * length / nt;
    const std::vector<int>& cand = buckets[std::min(nb - 1, static_cast<int>(u / bucket))];
    for (int is = 0; is < ns; ++is) {
      const double s = -half + (is + 0.5) * 2 * half / ns;
      const Vec2 p = a + u * t + s * n;
      for (int iz = 0; iz < nz; ++iz) {
        const double z = e.keel_bottom_z + (iz + 0.5) * (e.layer_bottom_z - e.keel_bottom_z) / nz;
        if (!in_envelope(e, length, s, u, z)) continue;
        ++in_env;
        for (int k : cand)
          if (block_contains(blocks[k], p, z)) {
            ++solid;
            break;
          }
      }
    }
  }
  r.by_voxels = in_env > 0 ? 1 - static_cast<double>(solid) / static_cast<double>(in_env) : 1.0;
  return r;
}

}  // namespace floesim::sim
