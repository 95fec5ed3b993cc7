// Contact generation. Broad phase: FCL's dynamic AABB tree over all convex parts, updated only for the bodies that
// moved, with exact (not bounding-sphere) boxes; a separating face axis (SAT over both parts' face normals) then
// rejects most box-overlapping neighbours cheaply. Narrow phase by contact law (options.contact):
//  - rigid pairs: fcl::collide with libccd (GST_LIBCCD; GST_INDEP is broken for convex shapes here) decides whether
//    two parts touch and gives a normal hint; the contact manifold (up to 4 points) is then built by clipping the
//    incident face against the reference face (the face axis of least overlap), which keeps flat resting contacts
//    and slab edges stable. Pairs that are edge-on-edge (FCL's depth clearly below every face overlap) keep FCL's
//    single point.
//  - compliant (crushing) pairs: the overlap polyhedron of the two convex parts, by clipping each part's faces
//    against the other's planes (convex_overlap below). Its boundary splits into the faces of a inside b and the
//    faces of b inside a; their vector areas give the nominal contact area (the overlap projected on the contact
//    plane), the normal and the centroid, all continuous functions of the poses (no chatter as contacts slide or
//    faces change). The contact surface is cut in two halves across its width at that centroid, one row each (so
//    the contact resists a floe turning into it), and the pair keeps its crushed depth from step to step (crushed
//    ice does not come back). GJK is not needed: an empty overlap is the answer "apart".
#pragma once
#include <array>
#include <memory>
#include <vector>

#include "sim/engine/model.h"
#include "sim/engine/parallel.h"
#include "sim/engine/state.h"

namespace floesim::sim {

// One row of a crushing contact: a half of the contact surface (cut by the plane through the patch centroid normal
// to the horizontal tangent z x n), at its centroid, with its share of the nominal area now and after the secant's
// step. The rows' areas add up to the patch's.
struct PatchRow {
  int half = 0;                 // 0: (z x n).(x - centroid) < 0, 1: >= 0
  Vec3 point = Vec3::Zero();
  double area_m2 = 0, area_end_m2 = 0;
};

// The overlap of two convex parts and what a crushing contact needs of it.
struct ContactPatch {
  bool valid = false;       // false: no overlap of measurable area (the parts do not press on each other)
  Vec3 point = Vec3::Zero();    // force application point: centroid of the contact surface
  Vec3 normal = Vec3::UnitZ();  // unit, from a to b
  double area_m2 = 0;       // nominal contact area A: the overlap projected on the contact plane
  // dA/d(delta) by forward difference over area_step_m of penetration (delta along the normal): the secant
  // (A(delta + step) - A) / step, >= 0; area_end_m2 = max(A, A(delta + step)).
  double area_slope_m = 0;
  double area_end_m2 = 0;
  double area_step_m = 0;
  double volume_m3 = 0;     // overlap volume (diagnostics; mean depth = volume / area)
  // The contact surface's extreme points along the horizontal tangent z x normal (its width, PHYSICS.md §2.1).
  Vec3 span_lo = Vec3::Zero(), span_hi = Vec3::Zero();
  std::array<PatchRow, 2> rows;  // the non-empty halves (row_count of them)
  int row_count = 0;
};

// Which side of the overlap carries the contact surface. A structure (the vessel) is hard: the crushing happens on
// its surface, so a's faces inside b give the area, normal and point. Between two floes neither side is
// privileged: the two sides are averaged.
enum class PatchSide { a_is_structure, symmetric };

// The patch of parts pa and pb placed at (xa, qa) and (xb, qb). Faces shared with another part of the same body
// (face_internal) bound the overlap but are not contact surface: they are left out of the area, normal and point,
// so that a floe straddling two hull sections gets from each section exactly its share of the hull surface.
// eps: penetration step of the finite difference dA/d(delta). (The collision stage uses the larger of eps and the
// penetration the current approach speed adds in one time step.)
ContactPatch convex_overlap(const ConvexPart& pa, const Vec3& xa, const Quat& qa, const ConvexPart& pb,
                            const Vec3& xb, const Quat& qb, PatchSide side, double eps);

struct CollisionStats {
  long broadphase_pairs = 0;   // AABB-overlapping part pairs with at least one awake body
  long narrowphase_hits = 0;   // part pairs that touch
  long edge_contacts = 0;      // pairs that kept FCL's single point
  long crushing_contacts = 0;  // compliant (crushing) contacts: one per body pair and direction
};

class CollisionWorld {
 public:
  CollisionWorld(const Model& model, const State& state, ThreadPool& pool);
  ~CollisionWorld();
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  // Moves the parts of the listed bodies to their poses in `state` and refreshes the broad phase for them only.
  void update_bodies(const State& state, const std::vector<int>& moved);
  // The body table grew (fracture): the bodies from first_new on, with their parts, enter the broad phase at their
  // poses in `state` (in the tree their awake flag says).
  void add_bodies(const State& state, int first_new);
  // Body b left the world (broken up or removed as brash): its parts leave the broad phase for good.
  void remove_body(int b);
  // Contacts of the current poses, sorted by (body_a, body_b, part_a, part_b, point order; a crushing contact under
  // its first part pair); pairs of two sleeping bodies are skipped. Solver fields are left for the solver to fill.
  void find_contacts(const State& state, std::vector<Contact>& out);
  const CollisionStats& stats() const { return stats_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  CollisionStats stats_;
};

}  // namespace floesim::sim
