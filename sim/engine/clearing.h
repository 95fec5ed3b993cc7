// Crushed ice cleared from a level ice sheet by a fixed structure (issue #34). A structure crushing the sheet's edge
// (a vertical cylinder, a caisson, the neck of a cone) makes no crack: the ice in front of it crushes and is
// extruded, and the structure advances into the space it leaves. The compliant contact (PHYSICS.md §1.8(c)) gives
// the crushing force from the overlap, but a tile's outline only changes by fracture, so without clearing the
// structure would tunnel into the tile and its overlap, once the structure were wholly inside, would press nowhere.
//
// So, after the fracture stage: for each level-ice tile a fixed structure crushes (a crushing contact between the
// two), the structure's section at the tile's mid-plane (each convex part cut by it) is compared with the tile.
// Where it has pushed into the tile deeper than level_ice.clearing_depth_m (the overlap's mean depth: its area over
// its width across the direction the structure presses, the contacts' normal impulses summed), the ice it overlaps
// there is cut out of the tile, with a fifth of that depth left in contact: the section moved back by it along the
// pressing direction is subtracted. On a sloping face the mid-plane is where the crushed edge's contact acts: above
// it the slope has left the ice, below it the ice still presses, and a wedge breaks off by bending long before much
// is cleared.
// The tile's rest stays fixed (what the sheet keeps); the cleared mass and any leftover that is a chip (is_chip) are
// the crushed ice, recorded as a fracture event of mode crushing (kFractureCrushing) with that mass.
// The edge left behind fits the structure's front, so the next steps' overlap is a crescent across the whole
// front: the crushing force p_c h w of a structure of width w, as in continuous crushing.
#pragma once
#include <vector>

#include "sim/engine/fracture.h"
#include "sim/engine/model.h"
#include "sim/engine/state.h"

namespace floesim::sim {

// The clearings of this step: one cut per tile (body: the tile; pieces: its outline less the cleared ice, in its
// body frame; wedge_pieces 0: every piece stays held by the sheet unless it is brash; event.mode kFractureCrushing,
// event.brash_mass_kg the crushed mass). Empty unless a hull body (the vessel, a structure) is fixed or compliant
// (Body::clears_ice). Deterministic: hull bodies, tiles and parts in index order.
std::vector<FractureCut> find_clearings(const Model& model, const State& state, const std::vector<Contact>& contacts);

// A convex part's footprint over the band zlo <= z <= zhi (world), in the world x-y plane: the convex hull of its
// vertices inside the band and of its edges' crossings of the band's planes; empty if it misses the band. With
// zlo = zhi it is the part's section by that plane.
Polygon part_band_footprint(const ConvexPart& part, const Vec3& position, const Quat& orientation, double zlo,
                            double zhi);

}  // namespace floesim::sim
