// The model of a simulation (MuJoCo's mjModel idea): bodies addressed by integer index, their convex collision
// parts, mass properties, hydrostatic data and the vessel's particulars. Everything that changes in time lives in
// State (sim/engine/state.h). Built once from the floes artefact, the hull and the options. The body and part tables only
// grow: when ice breaks, the world appends the pieces as new bodies (sim/engine/fracture.h); an entry, once made, never
// changes (a broken floe stays in the table, marked dead in State::alive), so indices stay valid for a whole run.
#pragma once
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pipeline/floes_io.h"
#include "sim/vessel/hull.h"
#include "sim/geometry/mesh.h"
#include "sim/engine/settings.h"
#include "sim/engine/state.h"
#include "sim/vessel/open_water.h"

namespace floesim::sim {

using Quat = Eigen::Quaterniond;

// A convex polyhedron in its body's frame (origin = body centre of mass): the unit of collision.
struct ConvexPart {
  int body = -1;
  std::vector<Vec3> vertices;
  std::vector<std::vector<int>> faces;  // planar faces, counter-clockwise seen from outside (coplanar triangles merged)
  std::vector<Vec3> face_normal;        // outward unit normals
  std::vector<uint8_t> face_internal;   // 1: the face is shared with another part of the same body (not a surface
                                        // of the body: never a contact reference face)
  double bounding_radius = 0;           // about the body origin (for cheap rejection tests)
};

// wall: a fixed body (infinite mass, never awake, no forces) bounding the domain (options.domain).
enum class BodyKind : uint8_t { vessel, floe, wall };

// What a floe is of a ridge (settings.ridges, issue #36): a tile of its consolidated layer (or a piece broken from
// one), a block of its keel's rubble or of its sail's.
enum class RidgePart : uint8_t { none, layer, keel, sail };

// One planar face of a floe slab for the drag model: indices into Body::drag_vertices.
struct DragFace {
  int first = 0, count = 0;  // into Body::drag_face_index
  Vec3 normal = Vec3::Zero();  // outward, body frame
  double area = 0;             // m^2
  Vec3 centroid = Vec3::Zero();  // body frame (used as is when the whole face is under water)
  int side = -1;                 // side wall between ring vertices side and side + 1 (-1: top or bottom)
};

// Contacts of one body pair whose surfaces come within this of each other press on the ice as one load: one crushing
// contact (collide) and one fracture load of a level ice tile (fracture). Twice the ice thickness h, at least 1 m:
// closer than that, thin-plate theory does not tell two loads apart.
inline double load_join_distance_m(double thickness_m) { return std::max(2 * thickness_m, 1.0); }

struct Body {
  BodyKind kind = BodyKind::floe;
  int id = 0;              // 0 = vessel, else the floe id of the input file (pieces: new ids, never reused)
  // Lineage (floes): the id of the floe this piece broke from (-1: input floe), its generation (0: input floe),
  // how it was made (FractureMode of pipeline/results_io.h, 0: input) and when (s).
  int parent_id = -1;
  int generation = 0;
  int origin_mode = 0;
  double created_s = 0;
  double mass_kg = 0, inv_mass = 0;
  Mat3 inertia = Mat3::Zero();      // body frame, about the centre of mass, kg m^2
  Mat3 inv_inertia = Mat3::Zero();
  // Added mass (PHYSICS.md §3.3), body axes: translational (surge, sway, heave; kg) and rotational (roll, pitch,
  // yaw; kg m^2). It enters the mass matrix only (inertia against every force, contacts included), never the
  // weight. Inverses with it: inv_mass_added (translational, body axes) and inv_inertia_added (body frame).
  Vec3 added_mass = Vec3::Zero();
  Vec3 added_inertia = Vec3::Zero();
  Vec3 inv_mass_added = Vec3::Zero();   // 1 / (m + A_ii), body axes (0 for walls)
  Mat3 inv_inertia_added = Mat3::Zero();  // (I + diag(added_inertia))^-1, body frame
  int first_part = 0, part_count = 0;  // into Model::parts
  TriMesh buoyancy_mesh;               // closed surface in the body frame, clipped at z = 0 for buoyancy
  // Drag model of floes: the slab's faces (top, bottom, sides) over a ring of vertices in the body frame.
  std::vector<Vec3> drag_vertices;
  std::vector<int> drag_face_index;
  std::vector<DragFace> drag_faces;
  int top_face = -1;                   // index into drag_faces of the top face (wind on floes)
  double thickness_m = 0;              // floes
  // Floes: plan-section properties about the centre of mass (exact prism buoyancy without clipping).
  double section_area = 0;             // m^2
  double section_sxx = 0, section_syy = 0, section_sxy = 0;  // integrals of x^2, y^2, xy over the section, m^4
  double section_radius = 0;           // largest distance of an outline vertex from the centre, m
  Polygon outline;                     // floes: CCW outline in the body frame (x, y)
  // Linear damping coefficients from the hydrostatic stiffness at equilibrium and the damping ratios.
  double heave_damping = 0;            // N s/m, along world z
  double roll_damping = 0;             // N m s/rad, about body x
  double pitch_damping = 0;            // N m s/rad, about body y
  // Floes, water.floe_heave_damping "radiation" (heave_radiation_force): the gain G on the high-passed heave
  // velocity (N s/m) and the filter's corner frequency w_c (rad/s); G = 0: none (then heave_damping acts).
  double heave_radiation_gain = 0;
  double heave_radiation_corner_radps = 0;
  Vec3 initial_position = Vec3::Zero();
  Quat initial_orientation = Quat::Identity();
  // Level ice (issue #10): a tile of a sheet, held by the ice around it (hold_fixed). Like a wall it has infinite
  // mass (inverse masses 0), is never awake and feels no force, so the sheet costs nothing per step until something
  // moving touches it; unlike a wall it is ice: it keeps its mass for the ice balance, is recorded, and fracture
  // breaks wedges off it (bending and radial cracking; a sheet does not split in-plane). What is left of a tile
  // stays fixed; the wedges are free floes.
  bool fixed = false;
  // Brash (fracture.brash "rigid"): a floe smaller than fracture.min_piece_area_m2 or narrower than it is thick
  // (is_brash). A block, not a plate: its contacts are rigid (one manifold per part pair, no crushing rows; the seed's
  // cheap small fragments, PHYSICS.md §1.7) and it never breaks; pressed on a plate it loads it as any piece does.
  bool brash = false;
  // Its rigid contacts' ceiling (brash only): the force that crushes the block's face, p_c h w, w its mean plan
  // width 4 A / perimeter (Metrikin's rigid contact with an ice crushing constraint, PHYSICS.md §1.7). Without it a
  // block squeezed between the hull and the sheet would take whatever impulse keeps them apart and spin off.
  double brash_crush_force_n = 0;
  // A fixed structure (vessel.station_keeping.mode "fixed", issue #34): it moves at its set velocity (zero, or minus
  // the drift in the ice's frame) and nothing moves it: inverse masses 0, no forces, always awake (it touches the
  // ice it reaches); its contact impulses are the load it carries.
  bool kinematic = false;
  // A structure whose crushed ice is cleared from the level ice it presses into (sim/engine/clearing.h): a fixed or a
  // compliant (bottom-founded) one.
  bool clears_ice = false;
  // Of a ridge (issue #36): its index in settings.ridges (-1: none) and what it is of it. A keel or sail block is
  // brash (rigid contacts, never broken) that starts awake where it was released, to be settled by buoyancy and
  // gravity; a layer tile is level ice h_c thick, and the pieces broken from it keep its tags.
  int ridge = -1;
  RidgePart ridge_part = RidgePart::none;
  // Starts awake even where floes start asleep: rubble released out of equilibrium, not yet settled.
  bool start_awake = false;
  // Its contacts with other such bodies slide without friction: a ridge's rubble while it packs (settle_ridges,
  // sim/engine/ridge_build.h). Never set in a run's model.
  bool frictionless = false;
};

// What the vessel model needs of the hull, computed from the mesh at the design waterline (z = 0).
struct VesselParticulars {
  double length_oa_m = 0, length_wl_m = 0, beam_wl_m = 0, draught_m = 0;
  double displacement_m3 = 0, wetted_surface_m2 = 0, waterplane_area_m2 = 0;
  double mass_kg = 0;
  Vec3 centre_of_mass_hull = Vec3::Zero();  // in the hull (OBJ) frame
  Vec3 radii_of_gyration_m = Vec3::Zero();
  double gm_transverse_m = 0, gm_longitudinal_m = 0;  // metacentric heights from the clipped hull
  std::vector<double> strip_x_m;      // stations of the cross-flow (sway/yaw) damping strips, body frame
  std::vector<double> strip_beam_m;   // waterline beam at each station (heave/pitch added mass)
  double strip_length_m = 0;          // length of one strip
};

// A propeller of the vessel (options.vessel.propellers) in the vessel's body frame.
struct Propeller {
  Vec3 position = Vec3::Zero();  // centre of the disc, body frame (about the centre of mass)
  Vec3 axis = Vec3::UnitX();     // unit, the direction of the thrust it gives
  double diameter_m = 0;
  double thrust_share = 0;
};

// Where a hull body held by station keeping (vessel.station_keeping or a structure's, issue #34) belongs: its
// reference point (the hull frame's origin, a structure's axis at the water line) in the body frame, where it is and
// how it heads at the station (the start; earth frame), and a moored body's mooring legs (fairleads from the
// reference point, body axes at the station; anchors on the seabed relative to the station).
struct Station {
  Vec3 reference_point_body = Vec3::Zero();
  Vec3 position = Vec3::Zero();
  double heading_rad = 0;
  std::vector<MooringLeg> mooring;
  DpControllerSettings dp;  // a DP body's controller: gains from its mass and added mass, limits, observer
  double spring_npm = 0, damper_nspm = 0;  // a compliant body's first mode: k = m w_n^2, c = 2 zeta m w_n
};

// A structure beside the vessel (settings.structures[k]): its body, what the hull model gives it and its station.
struct StructureBody {
  int body = -1;  // index into Model::bodies
  VesselParticulars info;
  Station station;
  int part_count = 0;  // its convex parts: Model::parts[bodies[body].first_part ...]
};

struct Model {
  EngineSettings settings;  // the physics settings it was built with (sim/engine/settings.h)
  std::vector<Body> bodies;   // vessel first (if any), then the floes in input order
  std::vector<ConvexPart> parts;
  int vessel = -1;            // index of the vessel body, -1 if none (tests of floes alone)
  VesselParticulars vessel_info;
  std::vector<int> removed_floe_ids;  // floes that overlapped the vessel's initial footprint
  int small_overlaps = 0;             // floe pairs overlapping below the error threshold (digitisation noise)
  Vec3 gravity = Vec3::Zero();
  Vec3 current = Vec3::Zero();        // water velocity, world
  Vec3 wind = Vec3::Zero();           // air velocity, world
  // The velocity of the frame the run is computed in, relative to the earth: the ice's drift (settings.drift), or
  // zero. current and wind above are relative to this frame; an earth-frame position is x + frame_velocity t.
  Vec3 frame_velocity = Vec3::Zero();
  std::vector<double> thrust_time_s, thrust_n;  // thrust_series mode
  std::vector<Propeller> propellers;            // their jets wash the floes (forces.h, PropellerJet)

  Station station;  // the vessel's, when it is a structure (vessel.station_keeping held)
  // The structures beside it (settings.structures, in order): bodies right after the vessel's, before the floes.
  std::vector<StructureBody> structures;

  // Freeze bonds the run starts with (settle_ridges freezes the settled rubble, settings.freeze_bonds): a world's
  // State::bonds begin as these.
  std::vector<FreezeBond> initial_bonds;

  int wall_count = 0;                 // domain walls, the last bodies of the model as built
  // The bodies build_model made: the vessel, the input floes (and level ice tiles) and the walls. A world appends
  // the pieces of broken ice after them and never changes these entries, so the first built_bodies of a world's
  // table are the model as built.
  size_t built_bodies = 0;
  // Floe bodies in the table: the input floes of a built model; in a world's grown table, every piece too (dead or
  // alive).
  int floe_count() const { return static_cast<int>(bodies.size()) - hull_count() - wall_count; }
  // The input floes (and level ice tiles) alone, in a built model or a world's grown table alike.
  int built_floe_count() const { return static_cast<int>(built_bodies) - hull_count() - wall_count; }
  // The hull bodies, the model's first: the vessel's (if any) and the structures'.
  int hull_count() const { return (vessel >= 0 ? 1 : 0) + static_cast<int>(structures.size()); }
};

// Builds the model. `hull` may be null (floes only). Checks the inputs (thickness, overlaps) and throws
// floesim::Error naming the floe ids. Floes overlapping the vessel's initial footprint are removed. Domain walls
// (options.domain) come last; a floe or the vessel overlapping one is an error.
// `structures`: the meshes of options.structures, in order (their bodies follow the vessel's).
Model build_model(const FloeField& floes, const HullModel* hull, const EngineSettings& options,
                  const std::vector<HullModel>& structures = {});

// Reads a thrust series CSV ("time_s,thrust_N" header, strictly increasing times); errors name the line.
void read_thrust_series(const std::string& file, std::vector<double>& time_s, std::vector<double>& thrust_n);

// The vessel's ITTC-57 open-water resistance line (sim/vessel/open_water.h) from its particulars and the settings'
// water and form factor.
Ittc57 ittc57_of(const VesselParticulars& v, const EngineSettings& o);
// The same for any hull body with its options (a structure's: settings.structures[k].body).
Ittc57 ittc57_of(const VesselParticulars& v, const VesselOptions& vo, const EngineSettings& o);

// A floe body: a slab of thickness h over `outline` (CCW, body frame: centred on its area centroid, which is the
// body origin), at hydrostatic equilibrium at plan position `centre`, with mass and inertia from polygon x h x
// rho_i, added mass, damping and drag faces from the options. Its convex parts (convex decomposition of the
// outline) are appended to `parts` with body index `body_index`; first_part/part_count point at them.
Body make_floe_body(const Polygon& outline, double thickness_m, int id, int body_index, const Vec2& centre,
                    const EngineSettings& o, std::vector<ConvexPart>& parts);

// A block of rubble as released (sim/engine/ridge.h) as a body: a floe body of the block's box, where it was released
// (under water or over the ice, out of equilibrium: it starts awake), brash (rigid contacts, its crushing force p_c h
// times its plan width 4 A / perimeter as their ceiling, never broken). Its outline in its body frame is
// rubble_block_outline's.
Body make_rubble_block(const RidgeBlock& k, int id, int body_index, const EngineSettings& o,
                       std::vector<ConvexPart>& parts);
Polygon rubble_block_outline(const RidgeBlock& k);

// Whether a floe's outline is brash rather than a plate: smaller than min_area_m2, or narrower than the ice is thick
// (plan width 4 A / perimeter below h: a block, whose tiny inertia about its long axis the crushing rows of a plate
// would only destabilise).
bool is_brash(const Polygon& outline, double thickness_m, double min_area_m2);
// The length of an outline's boundary, m.
double perimeter_m(const Polygon& outline);

// A body the solver and the integrator never move: a domain wall or a tile of level ice.
inline bool is_fixed_body(const Body& b) { return b.kind == BodyKind::wall || b.fixed; }

// Makes a floe body a fixed tile of level ice: inverse masses and inertias 0 (Body::fixed); a tile is never brash.
void hold_fixed(Body& b);

// Convex part from a closed convex triangle mesh (body frame): merges coplanar triangles into faces.
ConvexPart make_convex_part(const TriMesh& mesh, int body);
// Marks the faces that two parts of one body share (opposite normals in the same plane, overlapping): the cut
// planes between hull sections and the diagonals of a floe's convex decomposition.
void mark_shared_faces(std::vector<ConvexPart>& parts, int first, int count);

}  // namespace floesim::sim
