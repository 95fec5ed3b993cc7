// Ice ridges (issue #36, PHYSICS.md §9): a ridge's cross-section (a consolidated layer, the keel of rubble under it
// and the sail over it), the blocks of rubble released around the layer to be settled by buoyancy and gravity, and
// the macro-porosity of a set of blocks in the keel's envelope, measured two ways. Geometry only: the world that
// settles the blocks is built from these.
//
// Frame of one straight segment of the ridge line: s across the line (positive to the left of the direction of
// travel from the segment's first point), t along it from that point, z up from the calm waterline.
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include "pipeline/geometry2d.h"
#include "pipeline/options.h"

namespace floesim::sim {

struct RidgePoint {
  double x_m = 0, y_m = 0;
  template <class V>
  void visit(V& v) {
    auto finite =
        Check<double>([](const double& x) -> std::string { return std::isfinite(x) ? "" : "must be finite"; });
    v.field("x_m", x_m, "m", "x of a point of the ridge line", finite);
    v.field("y_m", y_m, "m", "y of a point of the ridge line", finite);
  }
};

// The checks a ridge's rubble takes wherever it is given: a macro-porosity in (0, 1), and block sizes [min, max]
// with 0 < min <= max.
inline Check<double> porosity_range() {
  return Check<double>([](const double& e) -> std::string { return e > 0 && e < 1 ? "" : "must be in (0, 1)"; });
}
inline Check<std::vector<double>> block_size_range() {
  return Check<std::vector<double>>([](const std::vector<double>& a) -> std::string {
    if (a.size() != 2) return "must be [min, max]";
    if (!(a[0] > 0 && a[1] >= a[0] && std::isfinite(a[1]))) return "must be 0 < min <= max";
    return "";
  });
}

// One ridge. Its cross-section: a consolidated layer of thickness h_c floating freely (draft h_c rho_i / rho_w)
// and keel_width_m wide; under it a keel whose sides slope at keel_angle_deg down to keel_depth_m below the
// waterline (a trapezoid; its bottom at least 0 wide); over it a sail, a triangle of sail_height_m with sides at
// sail_angle_deg. The rubble: blocks block_thickness_m thick, each plan side drawn log-uniformly from block_size_m.
struct RidgeOptions {
  std::vector<RidgePoint> line;
  double sail_height_m = 1.5;
  double keel_depth_m = 6.6;
  double keel_width_m = 25.7;
  double keel_angle_deg = 30;
  double sail_angle_deg = 21;
  double consolidated_thickness_m = 1.0;
  double porosity = 0.3;
  double block_thickness_m = 0.5;
  std::vector<double> block_size_m = {0.5, 2.5};
  int seed = 1;
  template <class V>
  void visit(V& v) {
    v.list("line", line, "the ridge line: [{\"x_m\", \"y_m\"}, ...], at least two points, straight between them");
    v.field("sail_height_m", sail_height_m, "m", "sail height above the waterline (0: no sail)", non_negative());
    v.field("keel_depth_m", keel_depth_m, "m", "keel draft: its deepest point below the waterline", positive());
    v.field("keel_width_m", keel_width_m, "m", "keel width under the consolidated layer (and the layer's width)",
            positive());
    v.field("keel_angle_deg", keel_angle_deg, "deg", "slope of the keel's sides from the horizontal",
            in_range(5, 85));
    v.field("sail_angle_deg", sail_angle_deg, "deg", "slope of the sail's sides from the horizontal", in_range(5, 85));
    v.field("consolidated_thickness_m", consolidated_thickness_m, "m",
            "thickness h_c of the refrozen layer at the waterline (a level sheet broken by the fracture module)",
            positive());
    v.field("porosity", porosity, "-", "macro-porosity e of keel and sail (0.25-0.35 measured)",
            porosity_range());
    v.field("block_thickness_m", block_thickness_m, "m", "thickness of the rubble blocks (about the parent ice's)",
            positive());
    v.field("block_size_m", block_size_m, "m", "[min, max] of a block's plan sides, drawn log-uniformly",
            block_size_range());
    v.field("seed", seed, "-", "seed of the blocks' sizes and placement", int_in_range(0, 2147483647));
    if (line.size() < 2) v.problem("line", "needs at least two points");
  }
};

// Ridges along a route at a stated density (issue #36 item 1): their positions a Poisson process along x over
// route_x_m (exponential spacings of mean 1000 / density_per_km, a ridge's layer never overlapping the one before),
// each straight across y over across_y_m; keel depths drawn from an exponential distribution of mean
// keel_depth_mean_m above keel_depth_min_m, cut at keel_depth_max_m (Wadhams' keel-draft statistics); width, sail
// and consolidated layer from the depth by the ratios of PHYSICS.md §9.1. The same seed gives the same ridges.
struct RidgeFieldOptions {
  double density_per_km = 0;  // 0: none
  std::vector<double> route_x_m = {0, 1000};
  std::vector<double> across_y_m = {-50, 50};
  double keel_depth_min_m = 3.0;
  double keel_depth_mean_m = 4.5;
  double keel_depth_max_m = 10.0;
  double width_over_depth = 3.9;
  double depth_over_sail = 4.4;
  double consolidated_thickness_m = 1.0;
  double keel_angle_deg = 30;
  double sail_angle_deg = 21;
  double porosity = 0.3;
  double block_thickness_m = 0.5;
  std::vector<double> block_size_m = {0.5, 2.5};
  int seed = 1;
  template <class V>
  void visit(V& v) {
    auto range = [](bool increasing) {
      return Check<std::vector<double>>([increasing](const std::vector<double>& a) -> std::string {
        if (a.size() != 2 || !std::isfinite(a[0]) || !std::isfinite(a[1])) return "must be [from, to], finite";
        if (increasing && !(a[1] > a[0])) return "needs from < to";
        return "";
      });
    };
    v.field("density_per_km", density_per_km, "1/km", "mean ridges per km of route (0: none)", in_range(0, 100));
    v.field("route_x_m", route_x_m, "m", "[from, to] along x where ridges lie", range(true));
    v.field("across_y_m", across_y_m, "m", "[from, to] across: each ridge's line runs over it at its x", range(true));
    v.field("keel_depth_min_m", keel_depth_min_m, "m", "smallest keel depth (the exponential's cut-off)", positive());
    v.field("keel_depth_mean_m", keel_depth_mean_m, "m",
            "mean keel depth: min plus the exponential's mean", positive());
    v.field("keel_depth_max_m", keel_depth_max_m, "m", "deepest keel (draws beyond are drawn again)", positive());
    v.field("width_over_depth", width_over_depth, "-", "keel width over keel depth (3.9, PHYSICS.md 9.1)",
            positive());
    v.field("depth_over_sail", depth_over_sail, "-", "keel depth over sail height (4.4 first-year)", positive());
    v.field("consolidated_thickness_m", consolidated_thickness_m, "m", "each ridge's consolidated layer thickness",
            positive());
    v.field("keel_angle_deg", keel_angle_deg, "deg", "slope of the keels' sides", in_range(5, 85));
    v.field("sail_angle_deg", sail_angle_deg, "deg", "slope of the sails' sides", in_range(5, 85));
    v.field("porosity", porosity, "-", "macro-porosity of keels and sails", porosity_range());
    v.field("block_thickness_m", block_thickness_m, "m", "thickness of the rubble blocks", positive());
    v.field("block_size_m", block_size_m, "m", "[min, max] of a block's plan sides, drawn log-uniformly",
            block_size_range());
    v.field("seed", seed, "-", "seed of the ridges' places and sizes (and of their blocks)",
            int_in_range(0, 2147483647));
    if (keel_depth_mean_m <= keel_depth_min_m) v.problem("keel_depth_mean_m", "must exceed keel_depth_min_m");
    if (keel_depth_max_m <= keel_depth_mean_m) v.problem("keel_depth_max_m", "must exceed keel_depth_mean_m");
  }
};

// The ridges of a ridge field, in order along x.
std::vector<RidgeOptions> ridge_field_ridges(const RidgeFieldOptions& f);

// How the ridges' rubble is settled before a run (settle_ridges, sim/engine/ridge_build.h): in still water, each
// ridge's first packed without friction until its keel is as porous as designed (its porosity; at most pack_max_s),
// then all with friction until every block has been slower than rest_speed_mps (and turning slower than
// rest_speed_mps per metre) for rest_time_s; the ridge as built is then measured on voxels of edge voxel_m.
struct RidgeSettlingOptions {
  double pack_max_s = 60;
  double max_s = 300;
  double rest_speed_mps = 0.01;
  double rest_time_s = 2.0;
  double voxel_m = 0.1;
  template <class V>
  void visit(V& v) {
    v.field("pack_max_s", pack_max_s, "s",
            "the longest a ridge's rubble packs without friction, as a keel packs by creep and waves, before it is "
            "as porous as designed (0: friction from the start)",
            non_negative());
    v.field("max_s", max_s, "s", "simulated time the rubble may take to come to rest (not at rest by then: an error)",
            positive());
    v.field("rest_speed_mps", rest_speed_mps, "m/s",
            "a block is at rest below this speed (and below this many rad/s of turning)", positive());
    v.field("rest_time_s", rest_time_s, "s", "every block at rest this long: the ridge is built", positive());
    v.field("voxel_m", voxel_m, "m", "voxel edge of the ridge's measurement as built (profiles, porosity)",
            in_range(0.01, 1));
  }
};

// Freeze bonds between the ridges' blocks (PHYSICS.md §9.5, issue #36 item 2): once the rubble has settled, every
// pair of blocks that touch freezes together, and every block touching its consolidated layer freezes to it (a bond
// to a tile of the layer holds until the tile breaks), one bond at the middle of their contact over its area (the
// polygon of its points, at least min_area_m2: blocks that meet at an edge or a corner freeze over that). One bond
// per pair, not one per contact point: between rigid blocks the points' shares of a load are not determined (any
// shares that balance will do), and the contact solver's would break a pair point by point below its strength. A
// bond pulls in tension with at most tensile_strength_pa and in shear with at most shear_strength_pa over its area,
// and pushes without limit; it takes no moment (the pair's contact points do, in compression). Loaded beyond its
// strength it cannot hold its two points together: once they have parted (opened or slid) by break_opening_m it has
// broken, for good. Off while both strengths are 0.
struct FreezeBondOptions {
  double tensile_strength_pa = 0;
  double shear_strength_pa = 0;
  double min_area_m2 = 0.01;
  double break_opening_m = 0.005;
  bool enabled() const { return tensile_strength_pa > 0; }
  template <class V>
  void visit(V& v) {
    v.field("tensile_strength_pa", tensile_strength_pa, "Pa",
            "a freeze bond's tensile strength sigma_t over its area (0 with shear_strength_pa 0: no bonds)",
            non_negative());
    v.field("shear_strength_pa", shear_strength_pa, "Pa", "a freeze bond's shear strength tau over its area",
            non_negative());
    v.field("min_area_m2", min_area_m2, "m^2",
            "the area a pair of blocks touching at an edge or a corner freezes over (the least of any pair)",
            positive());
    v.field("break_opening_m", break_opening_m, "m",
            "a bond whose two points have parted (opened or slid) this far has broken", positive());
    if ((tensile_strength_pa > 0) != (shear_strength_pa > 0))
      v.problem("shear_strength_pa", "freeze bonds need both strengths > 0 (or both 0: no bonds)");
  }
};

// The cross-section of a ridge as given (before settling), in the segment frame; water and ice densities from the
// simulation's settings.
struct RidgeSection {
  double layer_top_z = 0, layer_bottom_z = 0;  // the consolidated layer floating freely
  double keel_top_width_m = 0, keel_bottom_width_m = 0;
  double keel_bottom_z = 0;                    // -keel_depth_m
  double keel_area_m2 = 0;                     // below the layer
  double sail_base_width_m = 0;
  double sail_area_m2 = 0;                     // above the layer
};
// Checks the ridge against its densities (a keel shallower than the layer's bottom, a keel too narrow for its depth
// and angle, blocks larger than the keel) and throws floesim::Error naming `where` and the key.
RidgeSection ridge_section(const RidgeOptions& r, double ice_density, double water_density, const std::string& where);

// A block of rubble as released: a box of `size` (plan sides x, y and thickness z in its own axes) turned by `yaw_rad`
// about the vertical, in world coordinates.
struct RidgeBlock {
  Vec2 centre = Vec2::Zero();
  double z = 0;
  double size_x = 0, size_y = 0, thickness = 0;
  double yaw_rad = 0;
  bool keel = true;  // false: a sail block
};

// The blocks of rubble of a ridge: (1 - e) times the keel's (and the sail's) envelope volume over the line, in blocks
// drawn by the seed, released in a loose lattice (cells the size of the largest block plus a tenth, each block
// turned at random and set at random in its cell) under the consolidated layer across the keel's top width and
// downwards (the keel's blocks, to float up), and over the layer across the sail's base and upwards (the sail's, to
// fall onto it). Segment by segment along the line, in order; the same options give the same blocks.
std::vector<RidgeBlock> release_blocks(const RidgeOptions& r, const RidgeSection& section);

// The keel's envelope along one segment [a, b] of the line: the trapezoid of `section` swept along it.
// Macro-porosity of `blocks` in it, two ways: 1 - (volume of the blocks' parts inside the envelope) / (envelope
// volume) by the blocks' volumes (blocks wholly inside count whole, the others by a fine sampling of their own
// volume), and by voxels: the share of the envelope's voxels (edge `voxel_m`) whose centre lies in no block.
struct KeelPorosity {
  double by_volume = 0, by_voxels = 0;
  double envelope_m3 = 0, blocks_in_envelope_m3 = 0;
};
KeelPorosity keel_porosity(const std::vector<RidgeBlock>& blocks, const RidgeSection& section, const Vec2& a,
                           const Vec2& b, double voxel_m);

// Whether world point (p, z) lies inside block k (its box, turned by its yaw).
bool block_contains(const RidgeBlock& k, const Vec2& p, double z);

}  // namespace floesim::sim
