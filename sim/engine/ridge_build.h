// Building a ridge (issue #36 items 2 and 4, PHYSICS.md §9.1 and §9.5): its released rubble settled by buoyancy and
// gravity before the run, and what its settled blocks and its consolidated layer make, measured in a world's state.
// The rubble's envelope is found, not assumed: the keel's bottom and the sail's top across the line are read from
// voxels of the blocks themselves, and the porosity is measured inside that envelope, two ways.
#pragma once
#include <ostream>
#include <vector>

#include "pipeline/floes_io.h"
#include "sim/engine/model.h"
#include "sim/engine/state.h"

namespace floesim::sim {

struct RidgeBuilt {
  int blocks = 0;                      // keel and sail blocks alive
  double keel_depth_m = 0;             // deepest point of any keel block below the waterline
  // The keel's depth away from its ends, where rubble slumps lengthwise: the deepest point of its bottom profile
  // over the middle half of the line (each column's deepest keel block voxel, averaged along the line).
  double keel_depth_middle_m = 0;
  double sail_height_m = 0;            // highest point of any sail block above the waterline (0: no sail blocks)
  double layer_bottom_z = 0, layer_top_z = 0;  // of the layer as it floats now (its tiles' mean)
  // Across the line (s, m, left of its direction; bins of voxel_m): the keel's bottom z (the mean over the line of
  // each column's deepest keel block voxel; the layer's bottom where no block is) and the sail's top z (the layer's top
  // where none).
  std::vector<double> profile_s_m, keel_bottom_z, sail_top_z;
  // Cross-sections (m^2) of the envelopes as built: the keel in each column from the ice's underside (the layer's
  // bottom within its width; beside it, where rubble spread under thinner ice, the highest keel block) down to its
  // deepest keel block; the sail between the layer's top and its top profile.
  double keel_area_m2 = 0, sail_area_m2 = 0;
  // Macro-porosity of the keel inside its envelope as built: by volume, 1 - (the keel blocks' volume) / (the
  // envelope's volume); by voxels, the share of the envelope's voxels no block holds. They differ by the voxels'
  // resolution of the envelope's edge.
  double porosity_by_volume = 0, porosity_by_voxels = 0;
  // The ridge's ice (layer and blocks) under and over the waterline: a ridge that floats freely and is at rest
  // has their ratio rho_i / (rho_w - rho_i) (PHYSICS.md §9.1).
  double ice_below_m3 = 0, ice_above_m3 = 0;
  double max_block_speed_mps = 0;      // the fastest block (at rest: settled)
  double packed_s = 0;                 // how long its rubble packed without friction (settle_ridges)
};

// Measures ridge `ridge` (its index in settings.ridges) in `state`, over its line's first segment (a straight ridge;
// blocks beyond the segment's ends left out), on voxels of edge voxel_m.
RidgeBuilt measure_ridge(const Model& model, const State& state, int ridge, double voxel_m);

// Freeze bonds (PHYSICS.md §9.5) between the bodies of `freezes` (per body: may freeze) that touch in `contacts`
// (rigid contacts found at the poses of `state`): each touching pair becomes one bond at the mean of its contact
// points, held as a material point of each block, along the mean of their normals, over the pair's contact area (the
// polygon of its points in the contact plane, at least o.min_area_m2).
std::vector<FreezeBond> freeze_touching(const Model& model, const State& state, const std::vector<Contact>& contacts,
                                        const std::vector<uint8_t>& freezes, const FreezeBondOptions& o);

// What settling did: how long it took (simulated and wall), each ridge as built (settings.ridges' order) and how many
// freeze bonds the settled rubble made.
struct RidgeSettling {
  double time_s = 0, wall_s = 0;
  long steps = 0;
  int blocks = 0;
  int bonds = 0;
  std::vector<RidgeBuilt> ridges;
};

// Settles the rubble of `model`'s ridges (settings.ridge_settling) in a world of its own: the same floes and
// settings (and threads) without the hull bodies, with fracture off, in still water and air in the ice's frame (the
// case's current and wind act from the run's start). Each ridge's blocks first pack without friction among
// themselves until its keel is as porous as designed (RidgeOptions::porosity, measured every second) or for
// pack_max_s; then it steps with friction until every block has been at rest for rest_time_s
// (a block touching nothing counts by its heave and turning alone: one that came out from under the ice drifts on),
// then gives `model`'s blocks their settled poses (matched by id) and lets them start asleep, freezes the blocks
// that touch together and to their consolidated layer (settings.freeze_bonds: Model::initial_bonds) and measures
// each ridge. Throws floesim::Error naming ridge_settling.max_s when the rubble is not at rest by then. `progress`: a
// line every 10 s of settling (null: none). Deterministic: the same inputs and threads give the same poses.
RidgeSettling settle_ridges(const FloeField& field, Model& model, std::ostream* progress);

}  // namespace floesim::sim
