// The time step (Box2D-style list of named, timed stages) over an immutable Model and a mutable State:
//
//   collide    broad phase for the bodies that moved, narrow phase + manifolds (rigid pairs) or clipped overlap
//              patches (compliant pairs); awake bodies wake sleepers they touch
//   forces     external forces on awake bodies (gravity, buoyancy, damping, drag, resistance, propulsion, steering,
//              wind) -> predicted velocities v* = v + dt M^-1 f
//   solve      contact rows, warm start, PGS: rigid rows with the ERP bias, crushing rows with the compliant law
//              (PHYSICS.md §1.8(c): rigid below p_c(A) A, crushing above it, never pushed out)
//   integrate  semi-implicit Euler: x += dt v, q += dt/2 [0, w] q (normalised)
//   relax      PGS without push-out bias, so that resolving overlap leaves no velocity (crushing rows keep their
//              law, which never pushes out); impulses and crushed depths stored for the next step; the vessel's
//              loads by contact law
//   fracture   the converged contact forces against the closed-form failure loads (PHYSICS.md §2): a floe that
//              fails leaves the world and its pieces enter it as new bodies (sim/engine/fracture.h)
//   sleep      islands of floes joined by contacts fall asleep together at rest; health checks (NaN, blow-up)
//
// The world owns its model: the body table only grows (pieces are appended, a broken floe stays in the table but
// not alive), so the collision, solver, sleeping and recording stages all see new bodies the same way.
//
// Loads on the vessel are recorded per step in StepReport (world frame; the recorder turns them to body axes).
#pragma once
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/binary.h"
#include "sim/engine/collision.h"
#include "sim/engine/forces.h"
#include "sim/engine/fracture.h"
#include "sim/engine/model.h"
#include "sim/engine/parallel.h"
#include "sim/engine/solver.h"
#include "sim/engine/state.h"

namespace floesim::sim {

enum Stage { kCollide, kForces, kSolve, kIntegrate, kRelax, kFracture, kSleep, kStageCount };
const char* stage_name(int stage);

// The part of a hull body's ice load from ridges (world frame, about its centre of mass): from the rubble of their
// keels and sails, and from their consolidated layers (the pieces broken from them included). Of the rubble's, the
// keel's: keel blocks touching the body below their layer's underside (as designed: -h_c rho_i / rho_w), the
// unconsolidated rubble under the layer that Dolgopolov's F_K integrates (PHYSICS.md 9.3); rubble at the layer's
// level (blocks risen into the channel the body breaks, the sail) is carried by the layer's push, not the keel's.
struct RidgeLoad {
  Wrench rubble, layer;
  Wrench keel;  // part of rubble
};

// The loads on a structure beside the vessel in one step (world frame, about its centre of mass) and how it is held.
struct StructureReport {
  int contacts = 0;
  Wrench ice_load;            // every contact
  Wrench ice_load_level_ice;  // the part from level ice tiles
  RidgeLoad ridge_load;       // the part from ridges
  Wrench hydro_load, station_keeping_load;
  StationKeeping station_keeping;
  std::vector<Vec3> part_force_n;  // the ice's force on each of its convex parts (in the order of its parts)
};

// What one step did and the loads on the vessel (world frame, about its centre of mass).
struct StepReport {
  int contacts = 0, vessel_contacts = 0;
  int awake_floes = 0;
  int awake_rubble = 0;      // of them, blocks of ridges' rubble (keels and sails)
  int fracture_events = 0;   // floes broken in this step
  int floe_bodies = 0;       // floe bodies alive at the end of the step
  int bonds = 0;             // freeze bonds left at the end of the step
  int bonds_broken = 0;      // freeze bonds broken in this step
  SolverReport solve, relax;
  // Vessel surge ice load minus the same from the reference of solver.reference (the relax pass converged, twice
  // the sweep caps, the other sweep order or every contact in every sweep: the step solved again, or with
  // solver.reference_horizon_s the branch world's step), N; NaN when not measured.
  double surge_load_error_n = 0;
  Wrench ice_load, ice_load_rigid, ice_load_compliant;
  Wrench ice_load_level_ice;  // part of ice_load from contacts with level ice tiles (breaking the sheet's edge)
  RidgeLoad ridge_load;       // part of ice_load from ridges
  Wrench hydro_load, wind_load, propulsion_load;  // propulsion_load: a moored or DP body's station keeping
  double thrust_n = 0;
  StationKeeping station_keeping;  // a moored or DP body: its offset, heading change, demanded and delivered force
  std::vector<StructureReport> structures;  // Model::structures, in order
  std::vector<Vec3> vessel_part_force_n;    // a held vessel's (a structure's): the ice's force on each convex part
};

class World {
 public:
  // The world owns its model (move it in, or pass a copy to keep one as built): its body table grows as ice breaks,
  // pieces appended after the model's built bodies (Model::built_bodies), which never change.
  explicit World(Model model);
  ~World();

  // Advances one time step. Throws floesim::Error with a diagnosis (step, time, body) on numerical failure.
  void step();

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  // For tests and set-up: edit the state, then call sync() so that the broad phase sees the new poses.
  State& mutable_state() { return state_; }
  void sync();
  void wake(int body);

  const StepReport& report() const { return report_; }
  const std::vector<Contact>& contacts() const { return contacts_; }
  // The propeller jets of the last step's forces stage (from the vessel's pose and thrust at its start).
  const std::vector<PropellerJet>& jets() const { return jets_; }
  // The external wrench on each awake body this step (forces stage: gravity, water, wind, propulsion), world.
  const std::vector<Wrench>& external_wrenches() const { return external_; }
  // Every fracture event so far, in time order (children ids are floe ids of bodies in model()).
  const std::vector<FractureEvent>& fracture_events() const { return events_; }
  // When each body left the world (broken up or removed), s; +inf while alive. Indexed like model().bodies.
  const std::vector<double>& ended_s() const { return ended_s_; }
  // Mass of ice removed so far, kg: brash (pieces is_brash() rejected: below fracture.min_piece_area_m2 or slivers,
  // with fracture.brash "removed") and the crushed ice a fixed structure cleared (sim/engine/clearing.h).
  double brash_mass_kg() const { return brash_mass_kg_; }
  const CollisionStats& collision_stats() const { return collision_->stats(); }
  // Accumulated wall time per stage (s).
  const std::array<double, kStageCount>& stage_seconds() const { return stage_seconds_; }

  // Kinetic energy of all bodies alive (J) and their total linear momentum (N s).
  double kinetic_energy() const;
  Vec3 linear_momentum() const;

  // Checkpoints (sim/simulate/checkpoint.h). save() writes everything of the world that carries over from one step to the
  // next: the pieces fracture appended to the body table (as what made them: outline, thickness, id, lineage, pose
  // at birth), the state (poses, velocities, awake, alive and still times, the warm-start cache with the crushed
  // depths, the controllers' integrals), the solver's mass matrices, the last step's propeller jets (they wake
  // sleepers in the next collide), the fracture record and the bodies that moved last (the next broad-phase
  // refresh), and the wall time per stage. restore() rebuilds the same world from `base`, the model as
  // build_model made it from the same inputs: the pieces are remade by the function the fracture stage uses, and
  // the collision world is rebuilt from the poses (its pairs do not depend on its trees' history: exact boxes,
  // pairs sorted). The restored world steps on bit for bit as the saved one would have.
  void save(ByteWriter& w) const;
  static std::unique_ptr<World> restore(const Model& base, ByteReader& r);

 private:
  void stage_collide();
  void stage_forces();
  void stage_solve();
  void stage_integrate();
  void stage_relax();
  void stage_fracture();
  void stage_sleep();
  // Whether awake body `toucher` wakes `sleeper` where they touch (`at`, world): always, unless the sleeper is a
  // ridge's rubble, which only a hull body or a toucher moving there at sleep.linear_mps or faster wakes. Resting
  // rubble is a dense pile: a touch that does not move would otherwise wake the whole keel, block by block, and keep
  // it awake beside the hull. A sleeper left asleep holds still in the solve, as a support.
  bool touch_wakes(int toucher, int sleeper, const Vec3& at) const;
  // Collide: a solver row for each freeze bond with an awake block (waking the other by touch_wakes).
  void add_bond_rows();
  // Relax: removes the bonds whose impulse reached their strength this step.
  void break_bonds();
  // Sums the contact loads on the vessel (world frame, about its centre of mass) by contact law, and the part from
  // level ice tiles if `level_ice` is given; returns how many contacts touch it.
  int vessel_ice_load(const std::vector<Contact>& contacts, Wrench* rigid, Wrench* compliant,
                      Wrench* level_ice = nullptr) const;
  // The same for any hull body (the vessel's or a structure's), and the force on each of its parts (part_force, if
  // given: sized to its part count) and the parts from ridges (ridge, if given: their keels' and sails' rubble,
  // their consolidated layers and the pieces broken from them).
  int hull_ice_load(const std::vector<Contact>& contacts, int body, Wrench* rigid, Wrench* compliant,
                    Wrench* level_ice, std::vector<Vec3>* part_force, RidgeLoad* ridge = nullptr) const;
  // Replaces the floe of `cut` by its pieces (bodies appended at the floe's pose and velocity field) and records
  // the event.
  void apply_fracture(FractureCut& cut);
  // Grows the per-body arrays to the body table's size (new bodies awake, at rest in their own frame).
  void grow_body_arrays();
  [[noreturn]] void fail(int body, const std::string& what) const;
  // The vessel's surge ice load (along `surge`) from the reference solve of solver.reference, on copies.
  double reference_surge_load(const Vec3& surge);
  // solver.reference_horizon_s: replaces the branch by a copy of this world (as it is between two steps) that
  // steps with the reference's settings; and steps it with this world, recording the difference of the loads.
  void start_branch();
  void step_branch();
  std::string body_name(int body) const;

  Model model_;
  State state_;
  ThreadPool pool_;
  std::unique_ptr<CollisionWorld> collision_;
  std::vector<Contact> contacts_;
  State reference_state_;                   // solver.reference: the state and contacts the step's solve started
  std::vector<Contact> reference_contacts_;  // from (double_cap, reverse_order, every_contact)
  ContactIslands islands_;          // of contacts_ (solve stage), for the solve, relax and reference passes
  std::vector<int> awake_list_;     // bodies integrated this step (ascending)
  std::vector<int> moved_;          // bodies integrated in the previous step (broad phase refresh)
  std::vector<int> island_;         // sleep stage: union-find parent of each awake body (contact islands)
  std::vector<uint8_t> island_ok_;  // sleep stage: per island root, every member has been still long enough
  std::vector<PropellerJet> jets_;  // this step's propeller jets (forces stage, before the floes)
  std::vector<Wrench> external_;    // per body, this step
  std::vector<ForceScratch> scratch_;
  SolverBodies solver_bodies_;
  StepReport report_;
  bool sleep_allowed_ = false;
  std::vector<FractureEvent> events_;
  std::vector<double> ended_s_;
  double brash_mass_kg_ = 0;
  int next_floe_id_ = 1;            // ids of new pieces: above every id the world has seen, never reused
  int floes_alive_ = 0;             // floe bodies alive (changes only in the fracture stage)
  std::array<double, kStageCount> stage_seconds_{};
  size_t base_bodies_ = 0;          // bodies of the model as built; pieces come after them
  std::vector<double> layer_bottom_z_;  // per ridge (settings.ridges): its consolidated layer's underside as designed
  // solver.reference_horizon_s: the model as built with the reference's solver settings (what a branch is restored
  // on), the branch of the current window, and the window's length in steps (0: no branch).
  std::shared_ptr<const Model> branch_base_;
  std::unique_ptr<World> branch_;
  long branch_every_ = 0;
};

// What makes a piece of a broken floe: its outline in its own body frame (centred on its centroid), thickness, id,
// lineage, pose at birth, and whether it stays held by a level-ice sheet. make_piece_body turns it into the body the
// world appends; the fracture stage and the restore from a checkpoint both use it, so they make the same body to
// the bit.
struct PieceSpec {
  Polygon outline;
  double thickness_m = 0;
  int id = 0, parent_id = -1, generation = 0, origin_mode = 0;
  double created_s = 0;
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();
  bool fixed = false;  // level ice: the rest of a tile, still held by the sheet (hold_fixed)
  int ridge = -1;      // a piece of a ridge's consolidated layer keeps the layer's tags (Body::ridge)
  RidgePart ridge_part = RidgePart::none;
};
Body make_piece_body(const PieceSpec& p, int body_index, const EngineSettings& o, std::vector<ConvexPart>& parts);

}  // namespace floesim::sim
