// Contact generation, kept in one place so that a later issue can replace the manifold with overlap-polygon
// clipping (contact area for crushing). Broad phase: FCL's dynamic AABB tree over all convex parts, updated only for
// the bodies that moved, with exact (not bounding-sphere) boxes. Narrow phase: fcl::collide with libccd
// (GST_LIBCCD; GST_INDEP is broken for convex shapes here) decides whether two parts touch and gives a normal hint;
// the contact manifold (up to 4 points) is then built by clipping the incident face against the reference face
// (the face axis of least overlap), which keeps flat resting contacts and slab edges stable. Pairs that are
// edge-on-edge (FCL's depth clearly below every face overlap) keep FCL's single point.
#pragma once
#include <memory>
#include <vector>

#include "sim/model.h"
#include "sim/parallel.h"
#include "sim/state.h"

namespace floesim::sim {

struct CollisionStats {
  long broadphase_pairs = 0;   // AABB-overlapping part pairs with at least one awake body
  long narrowphase_hits = 0;   // part pairs that touch
  long edge_contacts = 0;      // pairs that kept FCL's single point
};

class CollisionWorld {
 public:
  CollisionWorld(const Model& model, const State& state, ThreadPool& pool);
  ~CollisionWorld();
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  // Moves the parts of the listed bodies to their poses in `state` and refreshes the broad phase for them only.
  void update_bodies(const State& state, const std::vector<int>& moved);
  // Contacts of the current poses, sorted by (body_a, part_a, body_b, part_b, point order); pairs of two sleeping
  // bodies are skipped. Solver fields are left for the solver to fill.
  void find_contacts(const State& state, std::vector<Contact>& out);
  const CollisionStats& stats() const { return stats_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  CollisionStats stats_;
};

}  // namespace floesim::sim
