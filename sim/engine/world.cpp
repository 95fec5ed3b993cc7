#include "sim/engine/world.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "pipeline/error.h"
#include "sim/engine/clearing.h"
#include "sim/engine/ridge.h"

namespace floesim::sim {

const char* stage_name(int stage) {
  static const char* names[kStageCount] = {"collide", "forces", "solve", "integrate", "relax", "fracture", "sleep"};
  return names[stage];
}

namespace {

class StageTimer {
 public:
  explicit StageTimer(double& acc) : acc_(acc), t0_(std::chrono::steady_clock::now()) {}
  ~StageTimer() { acc_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }

 private:
  double& acc_;
  std::chrono::steady_clock::time_point t0_;
};

bool finite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

// The solver settings of the reference solver.reference names (double_cap, reverse_order or every_contact), with no
// reference of their own.
SolverOptions reference_settings(const SolverOptions& o) {
  SolverOptions v = o;
  if (o.reference == "double_cap") v.iterations *= 2, v.relax_iterations *= 2;
  else if (o.reference == "every_contact") v.skip_settled = 0;
  else v.reverse_order = !o.reverse_order;
  v.reference = "off";
  v.reference_horizon_s = 0;
  return v;
}

// What a branch of a world built on `model` is restored on (solver.reference_horizon_s): the same model with the
// reference's solver settings; null when the world has no branch.
std::shared_ptr<const Model> branch_base(const Model& model) {
  if (model.vessel < 0 || model.settings.reference_horizon_steps() <= 0) return nullptr;
  Model b = model;
  b.settings.solver = reference_settings(model.settings.solver);
  return std::make_shared<const Model>(std::move(b));
}

}  // namespace

World::World(Model built) : model_(std::move(built)), pool_(model_.settings.threads) {
  const Model& model = model_;
  const size_t n = model.bodies.size();
  base_bodies_ = n;
  const EngineSettings& o = model.settings;
  for (size_t r = 0; r < o.ridges.size(); ++r)
    layer_bottom_z_.push_back(ridge_section(o.ridges[r], o.ice.density_kg_m3, o.water.density_kg_m3,
                                            "simulate.ridges[" + std::to_string(r) + "]")
                                  .layer_bottom_z);
  // Floes rest only where nothing drives them faster than the sleep threshold: in still water (a current drives
  // every floe), under air still enough that the drift it gives a free floe, u_a sqrt(rho_a C_a / (rho_w C_f)) (its
  // top's air drag against its bottom's skin friction: 1.7 % of the air's speed for SAMS ice), stays below
  // sleep.linear_mps (in a drift run the still air moves past the ice at the drift), and never in vacuum (nothing
  // holds them). Only then do they start asleep at their hydrostatic equilibrium, and only then may they fall asleep.
  const double cf = o.water.skin_friction_cf;
  const double air_over_water = o.wind.air_density_kg_m3 * o.ice.air_drag_ca / (o.water.density_kg_m3 * cf);
  const double wind_drift =
      cf > 0 ? model.wind.norm() * std::sqrt(air_over_water) : std::numeric_limits<double>::infinity();
  sleep_allowed_ = o.sleep.enabled && o.water.enabled && model.current.squaredNorm() == 0 &&
                   (model.wind.squaredNorm() == 0 || wind_drift < o.sleep.linear_mps);
  const bool start_asleep = sleep_allowed_;
  state_.position.resize(n);
  state_.orientation.resize(n);
  state_.velocity.assign(n, Vec3::Zero());
  state_.angular_velocity.assign(n, Vec3::Zero());
  state_.awake.assign(n, start_asleep ? 0 : 1);
  state_.still_time_s.assign(n, 0.0);
  state_.heave_lowpass_mps.assign(n, 0.0);
  state_.alive.assign(n, 1);
  ended_s_.assign(n, std::numeric_limits<double>::infinity());
  for (const Body& b : model.bodies) next_floe_id_ = std::max(next_floe_id_, b.id + 1);
  floes_alive_ = model.floe_count();
  branch_base_ = branch_base(model);
  if (branch_base_) branch_every_ = o.reference_horizon_steps();
  for (size_t b = 0; b < n; ++b) {
    state_.position[b] = model.bodies[b].initial_position;
    state_.orientation[b] = model.bodies[b].initial_orientation;
    if (is_fixed_body(model.bodies[b])) state_.awake[b] = 0;  // a wall or level ice: never integrated
    if (model.bodies[b].start_awake) state_.awake[b] = 1;  // a ridge's rubble released, not yet settled
    // An established drift: floes start with the current's velocity (horizontal).
    if (model.bodies[b].kind == BodyKind::floe && !model.bodies[b].fixed && o.water.enabled &&
        o.water.floes_start_with_current)
      state_.velocity[b] = Vec3(model.current.x(), model.current.y(), 0);
  }
  if (model.vessel >= 0) {
    const int v = model.vessel;
    state_.awake[v] = 1;
    const Mat3 R = state_.orientation[v].toRotationMatrix();
    state_.velocity[v] = o.vessel.initial_speed_mps * R.col(0) + Vec3(model.current.x(), model.current.y(), 0);
    if (o.vessel.station_keeping.held()) state_.velocity[v] = -model.frame_velocity;  // at rest in the earth frame
    state_.heading_ref_rad = heading_of(R);
  }
  for (const StructureBody& sb : model.structures) {  // awake, at rest in the earth frame
    state_.awake[sb.body] = 1;
    state_.velocity[sb.body] = -model.frame_velocity;
  }
  state_.structure_dp_memory.assign(model.structures.size(), {});
  for (const FreezeBond& fb : model.initial_bonds)
    FLOESIM_REQUIRE(fb.body_a >= 0 && fb.body_a < fb.body_b && static_cast<size_t>(fb.body_b) < n &&
                        fb.area_m2 > 0,
                    "internal: a freeze bond between bodies ", fb.body_a, " and ", fb.body_b, " of ", n);
  state_.bonds = model.initial_bonds;
  std::stable_sort(state_.bonds.begin(), state_.bonds.end(), bond_pair_less);  // State::bonds' order
  // Inverse mass matrices (world) as the solver sees them; the forces stage refreshes those of awake bodies.
  solver_bodies_.inv_mass.assign(n, Mat3::Zero());
  solver_bodies_.inv_inertia_world.assign(n, Mat3::Zero());
  for (size_t b = 0; b < n; ++b) {
    const Mat3 R = state_.orientation[b].toRotationMatrix();
    solver_bodies_.inv_mass[b] = R * model.bodies[b].inv_mass_added.asDiagonal() * R.transpose();
  }
  external_.resize(n);
  island_.assign(n, 0);
  island_ok_.assign(n, 0);
  scratch_.resize(pool_.threads());
  collision_ = std::make_unique<CollisionWorld>(model_, state_, pool_);
}

World::~World() = default;

void World::sync() {
  std::vector<int> all(model_.bodies.size());
  for (size_t b = 0; b < all.size(); ++b) all[b] = static_cast<int>(b);
  collision_->update_bodies(state_, all);
  moved_.clear();
}

void World::wake(int body) {
  if (is_fixed_body(model_.bodies[body]) || !state_.alive[body]) return;  // fixed or gone: never move
  state_.awake[body] = 1;
  state_.still_time_s[body] = 0;
}

std::string World::body_name(int body) const {
  if (body == model_.vessel) return "the vessel";
  for (size_t k = 0; k < model_.structures.size(); ++k)
    if (body == model_.structures[k].body) return "structure " + model_.settings.structures[k].name;
  return "floe id " + std::to_string(model_.bodies[body].id);
}

void World::fail(int body, const std::string& what) const {
  std::ostringstream os;
  os << "numerical failure at step " << state_.step + 1 << " (t = " << state_.time_s + model_.settings.time_step_s
     << " s)";
  if (body >= 0) os << ", " << body_name(body);
  os << ": " << what
     << ". Nothing was written. Try a smaller time_step_s, more solver.iterations, or check the inputs.";
  throw Error(os.str());
}

void World::step() {
  if (branch_every_ > 0 && state_.step % branch_every_ == 0) start_branch();
  report_ = StepReport{};
  { StageTimer t(stage_seconds_[kCollide]); stage_collide(); }
  { StageTimer t(stage_seconds_[kForces]); stage_forces(); }
  { StageTimer t(stage_seconds_[kSolve]); stage_solve(); }
  { StageTimer t(stage_seconds_[kIntegrate]); stage_integrate(); }
  { StageTimer t(stage_seconds_[kRelax]); stage_relax(); }
  { StageTimer t(stage_seconds_[kFracture]); stage_fracture(); }
  { StageTimer t(stage_seconds_[kSleep]); stage_sleep(); }
  state_.time_s = (state_.step + 1) * model_.settings.time_step_s;  // no drift from repeated addition
  ++state_.step;
  if (branch_) step_branch();
}

void World::start_branch() {
  // Through the checkpoint's bytes: the restored world steps on bit for bit as this one would (tested), here on
  // the reference's settings. The old branch goes first, so that it is not copied into the new one.
  branch_.reset();
  ByteWriter w;
  save(w);
  ByteReader r(w.bytes(), "the solver.reference branch");
  branch_ = restore(*branch_base_, r);
}

void World::step_branch() {
  try {
    branch_->step();
  } catch (const Error& e) {
    throw Error(std::string("solver.reference branch (") + model_.settings.solver.reference + ", started at t = " +
                std::to_string((state_.step - 1) / branch_every_ * branch_every_ * model_.settings.time_step_s) +
                " s): " + e.what());
  }
  const int v = model_.vessel;
  const Vec3 surge = state_.orientation[v] * Vec3::UnitX();
  const Vec3 surge_branch = branch_->state_.orientation[v] * Vec3::UnitX();
  report_.surge_load_error_n =
      surge.dot(report_.ice_load.force) - surge_branch.dot(branch_->report_.ice_load.force);
}

void World::stage_collide() {
  collision_->update_bodies(state_, moved_);
  collision_->find_contacts(state_, contacts_);
  // A contact with an awake body wakes a sleeper (rubble: a touch that moves); its pose is current, its velocity zero.
  for (const Contact& c : contacts_) {
    if (!state_.awake[c.body_a] && touch_wakes(c.body_b, c.body_a, c.point)) wake(c.body_a);
    if (!state_.awake[c.body_b] && touch_wakes(c.body_a, c.body_b, c.point)) wake(c.body_b);
  }
  add_bond_rows();
  // A sleeping floe that a propeller jet reaches wakes: the water moves there (the jets of the last step).
  if (!jets_.empty())
    for (size_t b = 0; b < model_.bodies.size(); ++b)
      if (!state_.awake[b] && state_.alive[b] && model_.bodies[b].kind == BodyKind::floe &&
          floe_in_jets(model_.bodies[b], state_.position[b], jets_))
        wake(static_cast<int>(b));
  awake_list_.clear();
  for (size_t b = 0; b < model_.bodies.size(); ++b)
    if (state_.awake[b]) awake_list_.push_back(static_cast<int>(b));
}

bool World::touch_wakes(int toucher, int sleeper, const Vec3& at) const {
  const RidgePart part = model_.bodies[sleeper].ridge_part;
  if (part != RidgePart::keel && part != RidgePart::sail) return true;
  if (toucher < model_.hull_count()) return true;
  const Vec3 v = state_.velocity[toucher] + state_.angular_velocity[toucher].cross(at - state_.position[toucher]);
  return v.norm() >= model_.settings.sleep.linear_mps;
}

void World::add_bond_rows() {
  // A bond with an awake block that moves wakes the other (touch_wakes: the bond passes the push on, one bond further
  // each step); a bond between two sleepers costs nothing.
  const double dt = model_.settings.time_step_s;
  const FreezeBondOptions& fo = model_.settings.freeze_bonds;
  if (state_.bonds.empty()) return;
  // Blocks frozen together are held where they froze, their overlap of then included: their contacts do not push
  // them apart (which only the bond would resist, until it broke), they only keep them from closing further.
  for (Contact& c : contacts_) {
    if (c.gap >= 0) continue;
    FreezeBond key;
    key.body_a = c.body_a;
    key.body_b = c.body_b;
    if (std::binary_search(state_.bonds.begin(), state_.bonds.end(), key, bond_pair_less)) c.gap = 0;
  }
  for (size_t k = 0; k < state_.bonds.size(); ++k) {
    const FreezeBond& fb = state_.bonds[k];
    const int a = fb.body_a, b = fb.body_b;
    if (!state_.awake[a] && !state_.awake[b]) continue;
    if (!state_.alive[a] || !state_.alive[b]) continue;  // a block gone: the bond holds nothing
    const Vec3 pa = state_.position[a] + state_.orientation[a] * fb.anchor_a;
    const Vec3 pb = state_.position[b] + state_.orientation[b] * fb.anchor_b;
    if (!state_.awake[a] && touch_wakes(b, a, pa)) wake(a);
    if (!state_.awake[b] && touch_wakes(a, b, pb)) wake(b);
    Contact c;
    c.type = ContactType::bond;
    c.bond = static_cast<int>(k);
    c.body_a = a;
    c.body_b = b;
    c.part_a = model_.bodies[a].first_part;
    c.part_b = model_.bodies[b].first_part;
    c.point = 0.5 * (pa + pb);
    c.span_lo = c.span_hi = c.point;
    c.normal = state_.orientation[a] * fb.normal_a;
    c.bond_separation = pb - pa;
    c.gap = c.bond_separation.dot(c.normal);
    c.mu = 0;
    c.tension_limit = dt * fo.tensile_strength_pa * fb.area_m2;
    c.shear_limit = dt * fo.shear_strength_pa * fb.area_m2;
    contacts_.push_back(c);
  }
}

void World::break_bonds() {
  // A bond whose points have parted by break_opening_m (its strength could not hold them) has broken, for good.
  // Measured at the step's end poses of its awake blocks (a bond between sleepers has not moved).
  const double opening = model_.settings.freeze_bonds.break_opening_m;
  std::vector<uint8_t> broken(state_.bonds.size(), 0);
  int count = 0;
  for (const Contact& c : contacts_) {
    if (c.type != ContactType::bond) continue;
    const FreezeBond& fb = state_.bonds[c.bond];
    const Vec3 pa = state_.position[fb.body_a] + state_.orientation[fb.body_a] * fb.anchor_a;
    const Vec3 pb = state_.position[fb.body_b] + state_.orientation[fb.body_b] * fb.anchor_b;
    if ((pb - pa).norm() > opening) broken[c.bond] = 1, ++count;
  }
  report_.bonds_broken = count;
  if (count == 0) return;
  size_t kept = 0;
  for (size_t k = 0; k < state_.bonds.size(); ++k)
    if (!broken[k]) state_.bonds[kept++] = state_.bonds[k];
  state_.bonds.resize(kept);
  state_.bonds_broken += count;
}

void World::stage_forces() {
  const double dt = model_.settings.time_step_s;
  const bool water = model_.settings.water.enabled;
  auto kinematics = [&](int b) {
    BodyKinematics k;
    k.x = state_.position[b];
    k.q = state_.orientation[b];
    k.R = k.q.toRotationMatrix();
    k.v = state_.velocity[b];
    k.w = state_.angular_velocity[b];
    return k;
  };
  // Per body: external wrench, world inverse mass matrices, then the predicted velocities v* = v + dt M^-1 f.
  // M holds the added mass (PHYSICS.md §3.3: floes' heave along their normal and roll/pitch, the vessel's surge, sway,
  // heave, pitch and yaw), so it
  // acts against every force, the contact impulses of the solver included (the solver uses the same M^-1): the
  // added mass is implicit, not an explicit force. The added mass's Coriolis/Munk terms are neglected.
  auto advance = [&](int b, const BodyKinematics& k, const Wrench& w) {
    const Body& body = model_.bodies[b];
    Mat3 Ib = body.inertia;
    Ib.diagonal() += body.added_inertia;
    const Mat3 Iw = k.R * Ib * k.R.transpose();
    const Mat3 Iinv = k.R * body.inv_inertia_added * k.R.transpose();
    const Mat3 Minv = k.R * body.inv_mass_added.asDiagonal() * k.R.transpose();
    solver_bodies_.inv_inertia_world[b] = Iinv;
    solver_bodies_.inv_mass[b] = Minv;
    external_[b] = w;
    // Gyroscopic term w x (I w), explicit.
    state_.velocity[b] += dt * (Minv * w.force);
    state_.angular_velocity[b] += dt * (Iinv * (w.torque - k.w.cross(Iw * k.w)));
  };
  // The vessel on this thread (its controllers keep state).
  const int vessel = model_.vessel;
  // A floating hull body's water loads (buoyancy, damping, resistance, cross flow).
  auto hull_water = [&](const Body& body, const HullRef& h, const BodyKinematics& k) {
    Wrench w;
    if (!water) return w;
    w += buoyancy_force(model_, body, k, scratch_[0]);
    w += hydrostatic_damping(model_, body, k);
    w += vessel_resistance(model_, h, k);
    w += vessel_cross_flow(model_, h, k);
    return w;
  };
  if (vessel >= 0 && !model_.bodies[vessel].kinematic) {  // a fixed structure feels no force: it keeps its velocity
    const Body& body = model_.bodies[vessel];
    const BodyKinematics k = kinematics(vessel);
    Wrench total = gravity_force(model_, body);
    // A compliant (bottom-founded) structure's foundation holds it: no buoyancy or drag apart from its mode.
    if (!model_.settings.vessel.station_keeping.compliant_held())
      report_.hydro_load = hull_water(body, vessel_ref(model_), k);
    report_.wind_load = vessel_wind(model_, k);
    if (model_.settings.vessel.station_keeping.held()) {
      // A moored or DP structure: its mooring lines or thrusters take the place of propulsion and steering (its
      // thrusters' wash is not modelled).
      report_.propulsion_load = station_keeping_force(model_, vessel_ref(model_), k, state_.time_s, dt,
                                                      &state_.dp_memory, &report_.station_keeping);
    } else {
      report_.propulsion_load = vessel_propulsion(model_, k, state_.time_s, dt, state_.speed_error_integral,
                                                  report_.thrust_n);
      report_.propulsion_load += vessel_autopilot(model_, body, k, state_.heading_ref_rad);
      // The jets from the pose and thrust at the start of the step, for every floe's drag below. The vessel's own
      // jets leave its hull astern; their effect on the hull (thrust deduction) is in the resistance and thrust.
      propeller_jets(model_, k, report_.thrust_n, jets_);
    }
    total += report_.hydro_load;
    total += report_.wind_load;
    total += report_.propulsion_load;
    advance(vessel, k, total);
  }
  // The structures beside it: a moored or DP one as the vessel held above (no wind: see StructureOptions).
  report_.structures.resize(model_.structures.size());
  for (size_t s = 0; s < model_.structures.size(); ++s) {
    const int b = model_.structures[s].body;
    StructureReport& sr = report_.structures[s];
    sr.hydro_load = sr.station_keeping_load = Wrench();
    if (model_.bodies[b].kinematic) continue;
    const Body& body = model_.bodies[b];
    const BodyKinematics k = kinematics(b);
    const HullRef h = structure_ref(model_, static_cast<int>(s));
    if (!h.options.station_keeping.compliant_held()) sr.hydro_load = hull_water(body, h, k);
    sr.station_keeping_load = station_keeping_force(model_, h, k, state_.time_s, dt,
                                                    &state_.structure_dp_memory[s], &sr.station_keeping);
    Wrench total = gravity_force(model_, body);
    total += sr.hydro_load;
    total += sr.station_keeping_load;
    advance(b, k, total);
  }
  // Floes in parallel: each writes only its own slots.
  const int n = static_cast<int>(awake_list_.size());
  pool_.parallel_for(n, [&](int begin, int end, int worker) {
    ForceScratch& s = scratch_[worker];
    for (int i = begin; i < end; ++i) {
      const int b = awake_list_[i];
      if (b < model_.hull_count()) continue;
      const Body& body = model_.bodies[b];
      const BodyKinematics k = kinematics(b);
      Wrench w = gravity_force(model_, body);
      if (water) {
        w += buoyancy_force(model_, body, k, s);
        w += hydrostatic_damping(model_, body, k);
        w.force.z() += heave_radiation_force(body, k.v.z(), state_.heave_lowpass_mps[b], dt);
        w += floe_water_drag(model_, body, k, s, jets_);
      }
      w += floe_wind_drag(model_, body, k, s);
      advance(b, k, w);
    }
  });
}

void World::stage_solve() {
  const SolverOptions& o = model_.settings.solver;
  const double dt = model_.settings.time_step_s;
  islands_ = prepare_contacts(model_, solver_bodies_, state_, contacts_, dt);
  // A paired reference solve of the whole step starts where this one does: after the warm start.
  if (branch_every_ == 0 &&
      (o.reference == "double_cap" || o.reference == "reverse_order" || o.reference == "every_contact")) {
    reference_state_ = state_;
    reference_contacts_ = contacts_;
  }
  report_.solve = solve_contacts(model_, solver_bodies_, state_, contacts_, islands_, dt, true, o.iterations,
                                 o.tolerance_mps, &pool_);
}

void World::stage_integrate() {
  const double dt = model_.settings.time_step_s;
  for (int b : awake_list_) {
    state_.position[b] += dt * state_.velocity[b];
    const Vec3& w = state_.angular_velocity[b];
    Quat& q = state_.orientation[b];
    const Quat dq(0, 0.5 * dt * w.x(), 0.5 * dt * w.y(), 0.5 * dt * w.z());
    q.coeffs() += (dq * q).coeffs();
    q.normalize();
  }
  moved_ = awake_list_;
}

void World::stage_relax() {
  const SolverOptions& o = model_.settings.solver;
  const double dt = model_.settings.time_step_s;
  if (o.relax_iterations > 0)
    report_.relax = solve_contacts(model_, solver_bodies_, state_, contacts_, islands_, dt, false,
                                   o.relax_iterations, o.tolerance_mps, &pool_);
  store_impulses(model_, state_, contacts_);
  report_.contacts = static_cast<int>(contacts_.size());
  std::vector<Vec3>* parts = nullptr;  // a structure's parts' loads (a ship's are not recorded)
  if (model_.vessel >= 0 && model_.settings.vessel.station_keeping.held()) {
    report_.vessel_part_force_n.assign(model_.bodies[model_.vessel].part_count, Vec3::Zero());
    parts = &report_.vessel_part_force_n;
  }
  report_.ridge_load = RidgeLoad();
  report_.vessel_contacts = hull_ice_load(contacts_, model_.vessel, &report_.ice_load_rigid,
                                          &report_.ice_load_compliant, &report_.ice_load_level_ice, parts,
                                          &report_.ridge_load);
  report_.ice_load = report_.ice_load_rigid;
  report_.ice_load += report_.ice_load_compliant;
  for (size_t s = 0; s < model_.structures.size(); ++s) {
    StructureReport& sr = report_.structures[s];
    sr.part_force_n.assign(model_.structures[s].part_count, Vec3::Zero());
    Wrench rigid, compliant;
    sr.ice_load_level_ice = Wrench();
    sr.ridge_load = RidgeLoad();
    sr.contacts = hull_ice_load(contacts_, model_.structures[s].body, &rigid, &compliant, &sr.ice_load_level_ice,
                                &sr.part_force_n, &sr.ridge_load);
    sr.ice_load = rigid;
    sr.ice_load += compliant;
  }
  // What the solver's settings change in the recorded load (solver.reference, a diagnostic).
  report_.surge_load_error_n = std::numeric_limits<double>::quiet_NaN();
  if (o.reference != "off" && branch_every_ == 0 && model_.vessel >= 0) {
    const Vec3 surge = state_.orientation[model_.vessel] * Vec3::UnitX();
    report_.surge_load_error_n = surge.dot(report_.ice_load.force) - reference_surge_load(surge);
  }
  break_bonds();
  report_.bonds = static_cast<int>(state_.bonds.size());
}

double World::reference_surge_load(const Vec3& surge) {
  const SolverOptions& o = model_.settings.solver;
  const double dt = model_.settings.time_step_s;
  State s;
  std::vector<Contact> c;
  if (o.reference == "converged_relax") {
    // The relax pass continued on copies until converged: what its sweep cap left.
    s = state_;
    c = contacts_;
    solve_contacts(model_, solver_bodies_, s, c, islands_, dt, false, o.reference_sweeps, o.tolerance_mps * 1e-3,
                   &pool_);
  } else {
    // The step's solve and relax passes again, from the state the solve started from, with twice the caps, the
    // other sweep order or every contact in every sweep. The relax pass does not read positions, so the copy taken
    // before integration serves it.
    const SolverOptions v = reference_settings(o);
    s = std::move(reference_state_);
    c = std::move(reference_contacts_);
    solve_contacts(model_, solver_bodies_, s, c, islands_, dt, true, v.iterations, o.tolerance_mps, &pool_, &v);
    if (v.relax_iterations > 0)
      solve_contacts(model_, solver_bodies_, s, c, islands_, dt, false, v.relax_iterations, o.tolerance_mps, &pool_,
                     &v);
  }
  Wrench rigid, compliant;
  vessel_ice_load(c, &rigid, &compliant);
  return surge.dot(rigid.force + compliant.force);
}

int World::vessel_ice_load(const std::vector<Contact>& contacts, Wrench* rigid, Wrench* compliant,
                           Wrench* level_ice) const {
  return hull_ice_load(contacts, model_.vessel, rigid, compliant, level_ice, nullptr);
}

int World::hull_ice_load(const std::vector<Contact>& contacts, int body, Wrench* rigid, Wrench* compliant,
                         Wrench* level_ice, std::vector<Vec3>* part_force, RidgeLoad* ridge) const {
  // Contact loads on the body: impulse / dt, about its centre of mass (lever arms of the solve), split by contact
  // law (the seed filters compliant loads over 0.5 s and rigid ones over 20 s, PHYSICS.md §5); and, if asked, the
  // part from level ice tiles (breaking the sheet's edge, against clearing the pieces) and each part's force.
  const double dt = model_.settings.time_step_s;
  if (body < 0) return 0;  // no vessel (floes alone)
  const int first_part = model_.bodies[body].first_part;
  int n = 0;
  for (const Contact& c : contacts) {
    if (c.body_a != body && c.body_b != body) continue;
    ++n;
    const Vec3 p = (c.pn * c.normal + c.pt1 * c.t1 + c.pt2 * c.t2) / dt;  // on body b
    Wrench w;
    if (c.body_b == body) w.add_at(p, c.rb);
    else w.add_at(-p, c.ra);
    *(c.type == ContactType::rigid ? rigid : compliant) += w;
    const Body& other = model_.bodies[c.body_a == body ? c.body_b : c.body_a];
    if (level_ice && other.fixed) *level_ice += w;
    if (ridge && other.ridge_part == RidgePart::layer) ridge->layer += w;
    if (ridge && (other.ridge_part == RidgePart::keel || other.ridge_part == RidgePart::sail)) ridge->rubble += w;
    // A rig's blocks (the shear box's) are rubble of no ridge (ridge -1): no layer to lie below.
    if (ridge && other.ridge_part == RidgePart::keel && other.ridge >= 0 && c.point.z() < layer_bottom_z_[other.ridge])
      ridge->keel += w;
    if (part_force) (*part_force)[(c.body_a == body ? c.part_a : c.part_b) - first_part] += w.force;
  }
  return n;
}

void World::stage_fracture() {
  std::vector<FractureCut> cuts =
      find_fractures(model_, state_, contacts_, model_.settings.time_step_s, &state_.pair_loads);
  for (FractureCut& c : cuts) apply_fracture(c);
  // A fixed structure's crushed ice cleared from the tiles it crushes (sim/engine/clearing.h); a tile that broke
  // this step is not cleared (its contacts name a body no longer alive).
  std::vector<FractureCut> clearings = find_clearings(model_, state_, contacts_);
  for (FractureCut& c : clearings) apply_fracture(c);
  report_.fracture_events = static_cast<int>(cuts.size() + clearings.size());
}

void World::grow_body_arrays() {
  const size_t n = model_.bodies.size();
  state_.position.resize(n, Vec3::Zero());
  state_.orientation.resize(n, Quat::Identity());
  state_.velocity.resize(n, Vec3::Zero());
  state_.angular_velocity.resize(n, Vec3::Zero());
  state_.awake.resize(n, 1);
  state_.alive.resize(n, 1);
  state_.still_time_s.resize(n, 0.0);
  state_.heave_lowpass_mps.resize(n, 0.0);
  solver_bodies_.inv_mass.resize(n, Mat3::Zero());
  solver_bodies_.inv_inertia_world.resize(n, Mat3::Zero());
  external_.resize(n);
  island_.resize(n, 0);
  island_ok_.resize(n, 0);
  ended_s_.resize(n, std::numeric_limits<double>::infinity());
}

void World::apply_fracture(FractureCut& cut) {
  const int parent = cut.body;
  const Body parent_body = model_.bodies[parent];  // a copy: the table is about to grow
  const double t = (state_.step + 1) * model_.settings.time_step_s;
  const Vec3 x = state_.position[parent], v = state_.velocity[parent], w = state_.angular_velocity[parent];
  const Quat q = state_.orientation[parent];
  const Mat3 R = q.toRotationMatrix();
  const FractureOptions& fo = model_.settings.fracture;
  const double rho_i = model_.settings.ice.density_kg_m3, h = parent_body.thickness_m;
  FractureEvent& e = cut.event;
  // The floe leaves: no longer alive, awake or in the broad phase. Its contacts of this step stay in contacts_
  // (the sleep stage skips them); its warm-start entries are never matched again (its parts are gone).
  state_.alive[parent] = 0;
  state_.awake[parent] = 0;
  --floes_alive_;
  ended_s_[parent] = t;
  collision_->remove_body(parent);
  const int first_new = static_cast<int>(model_.bodies.size());
  for (size_t k = 0; k < cut.pieces.size(); ++k) {
    const Polygon& piece = cut.pieces[k];
    // Level ice: the wedge breaks free; what is left of the tile is still held by the sheet around it, unless it is
    // brash (a block left between cracks is loose ice, not sheet: held, it would stand in the hull's way as an
    // immovable block that no crack can cut any smaller).
    const bool fixed = parent_body.fixed && static_cast<int>(k) >= cut.wedge_pieces &&
                       !is_brash(piece, h, fo.min_piece_area_m2);
    if (fo.brash == "removed" && is_brash(piece, h, fo.min_piece_area_m2)) {
      // fracture.brash "removed": brash leaves the simulation, its mass counted. (With "rigid" it stays: a body
      // with rigid contacts, make_floe_body's Body::brash.)
      e.brash_mass_kg += rho_i * signed_area(piece) * h;
      continue;
    }
    const Vec2 c = centroid(piece);
    Polygon local;
    for (const Vec2& p : piece) local.push_back(p - c);
    const int id = next_floe_id_++;
    const int index = static_cast<int>(model_.bodies.size());
    // The piece where it was in the floe, with the floe's velocity field v + w x r (momentum kept exactly).
    const Vec3 r = R * Vec3(c.x(), c.y(), 0);
    PieceSpec spec;
    spec.outline = std::move(local);
    spec.thickness_m = h;
    spec.id = id;
    spec.parent_id = parent_body.id;
    spec.generation = parent_body.generation + 1;
    spec.origin_mode = e.mode;
    spec.created_s = t;
    spec.position = x + r;
    spec.orientation = q;
    spec.fixed = fixed;
    spec.ridge = parent_body.ridge;
    spec.ridge_part = parent_body.ridge_part;
    model_.bodies.push_back(make_piece_body(spec, index, model_.settings, model_.parts));
    grow_body_arrays();
    state_.position[index] = x + r;
    state_.orientation[index] = q;
    state_.velocity[index] = v + w.cross(r);
    state_.angular_velocity[index] = w;
    const Body& made = model_.bodies[index];
    if (made.brash) {
      // Brash turns as a block (its inertia floored, make_floe_body): its spin is set so that it carries the
      // angular momentum of the ice it is, I_true w (the event keeps angular momentum exactly).
      const Mat3 true_inertia = rho_i * mass_properties(made.buoyancy_mesh).inertia;
      state_.angular_velocity[index] = R * made.inertia.inverse() * true_inertia * R.transpose() * w;
    }
    // The water under the piece has the parent's heave history: the radiation filter carries on from the parent's
    // (starting it at 0 would give the piece a jolt of -G v_z at its birth).
    state_.heave_lowpass_mps[index] = state_.heave_lowpass_mps[parent];
    state_.awake[index] = fixed ? 0 : 1;
    solver_bodies_.inv_mass[index] = R * model_.bodies[index].inv_mass_added.asDiagonal() * R.transpose();
    solver_bodies_.inv_inertia_world[index] = R * model_.bodies[index].inv_inertia_added * R.transpose();
    e.child_ids.push_back(id);
    ++floes_alive_;
  }
  brash_mass_kg_ += e.brash_mass_kg;
  collision_->add_bodies(state_, first_new);
  events_.push_back(std::move(e));
}

Body make_piece_body(const PieceSpec& p, int body_index, const EngineSettings& o, std::vector<ConvexPart>& parts) {
  Body b = make_floe_body(p.outline, p.thickness_m, p.id, body_index, Vec2::Zero(), o, parts);
  b.parent_id = p.parent_id;
  b.generation = p.generation;
  b.origin_mode = p.origin_mode;
  b.created_s = p.created_s;
  b.initial_position = p.position;
  b.initial_orientation = p.orientation;
  if (p.fixed) hold_fixed(b);
  b.ridge = p.ridge;
  b.ridge_part = p.ridge_part;
  return b;
}

void World::stage_sleep() {
  const SleepOptions& s = model_.settings.sleep;
  const HealthOptions& h = model_.settings.health;
  const double dt = model_.settings.time_step_s;
  if (!std::isfinite(report_.solve.residual) || !std::isfinite(report_.relax.residual))
    fail(-1, "the contact solver diverged (residual is not finite)");
  report_.awake_floes = static_cast<int>(awake_list_.size()) - model_.hull_count();
  for (int b : awake_list_) {
    const RidgePart part = model_.bodies[b].ridge_part;
    report_.awake_rubble += part == RidgePart::keel || part == RidgePart::sail;
  }
  report_.floe_bodies = floes_alive_;
  for (int b : awake_list_) {
    if (!state_.alive[b]) continue;  // broke up in this step
    const Vec3& v = state_.velocity[b];
    const Vec3& w = state_.angular_velocity[b];
    if (!finite(state_.position[b]) || !finite(v) || !finite(w) || !std::isfinite(state_.orientation[b].w()))
      fail(b, "position or velocity is not finite");
    if (v.norm() > h.max_speed_mps)
      fail(b, "speed " + std::to_string(v.norm()) + " m/s exceeds health.max_speed_mps (energy blow-up)");
    if (w.norm() > h.max_angular_radps)
      fail(b, "angular speed " + std::to_string(w.norm()) + " rad/s exceeds health.max_angular_radps (blow-up)");
    if (b < model_.hull_count()) continue;
    const bool slow = v.norm() < s.linear_mps && w.norm() < s.angular_radps;
    state_.still_time_s[b] = slow ? state_.still_time_s[b] + dt : 0.0;
  }
  if (!sleep_allowed_) return;
  // Islands (Box2D's rule): the awake bodies joined by this step's contacts (a wall or level ice joins nothing). An
  // island falls asleep as a whole once every floe in it has been slow for sleep.time_s, and never while the vessel
  // is in it; so floes resting against each other sleep too, and a sleeper touched by an awake body wakes (collide).
  // A partition does not depend on the order of the unions: deterministic.
  auto find = [&](int b) {
    while (island_[b] != b) b = island_[b] = island_[island_[b]];
    return b;
  };
  for (int b : awake_list_) island_[b] = b;
  for (const Contact& c : contacts_) {
    if (is_fixed_body(model_.bodies[c.body_a]) || is_fixed_body(model_.bodies[c.body_b])) continue;
    if (!state_.alive[c.body_a] || !state_.alive[c.body_b]) continue;  // broke up in this step
    if (!state_.awake[c.body_a] || !state_.awake[c.body_b]) continue;  // resting rubble left asleep: a support
    const int ra = find(c.body_a), rb = find(c.body_b);
    if (ra != rb) island_[std::max(ra, rb)] = std::min(ra, rb);
  }
  for (int b : awake_list_) island_ok_[b] = 1;
  for (int b : awake_list_)
    if (b < model_.hull_count() || state_.still_time_s[b] < s.time_s) island_ok_[find(b)] = 0;
  // Far astern (sleep.freeze_astern_m): asleep at any speed; the island rule above no longer applies to it.
  // Astern is behind a ship's bow, farther than the distance from its centre; or behind a structure's motion through
  // the ice (downstream of it in the earth frame: against the drift), farther than the distance along that motion,
  // since the ice a structure breaks spreads beside it and still flows past it there. A structure at rest in the ice
  // has no astern. A body is frozen when it is far astern of every hull body.
  const int hulls = model_.hull_count();
  std::vector<Vec3> ahead(hulls, Vec3::Zero());  // zero: this hull has no astern (nothing is astern of all)
  const int ship = model_.settings.vessel.station_keeping.held() ? -1 : model_.vessel;  // the hull body that sails
  const Vec3 through_ice = -Vec3(model_.frame_velocity.x(), model_.frame_velocity.y(), 0);
  for (int hb = 0; hb < hulls; ++hb) {
    if (hb == ship) ahead[hb] = state_.orientation[hb] * Vec3::UnitX();
    else if (through_ice.norm() > 0) ahead[hb] = through_ice.normalized();
  }
  auto far_astern = [&](int b) {
    for (int hb = 0; hb < hulls; ++hb) {
      const Vec3 d = state_.position[b] - state_.position[hb];
      const double behind = -d.dot(ahead[hb]);
      if (ahead[hb].squaredNorm() == 0 || behind <= 0) return false;
      if ((hb == ship ? d.head<2>().norm() : behind) <= s.freeze_astern_m) return false;
    }
    return true;
  };
  const bool freeze = s.freeze_astern_m > 0 && hulls > 0;
  for (int b : awake_list_) {
    if (b < hulls || !state_.alive[b]) continue;
    if (!island_ok_[find(b)] && !(freeze && far_astern(b))) continue;
    state_.awake[b] = 0;
    state_.velocity[b].setZero();
    state_.angular_velocity[b].setZero();
    state_.heave_lowpass_mps[b] = 0;  // at rest, as its velocity: it wakes with no radiation memory
  }
}

double World::kinetic_energy() const {
  double e = 0;
  for (size_t b = 0; b < model_.bodies.size(); ++b) {
    if (!state_.alive[b]) continue;
    const Body& body = model_.bodies[b];
    const Mat3 R = state_.orientation[b].toRotationMatrix();
    const Vec3 wb = R.transpose() * state_.angular_velocity[b];
    e += 0.5 * body.mass_kg * state_.velocity[b].squaredNorm() + 0.5 * wb.dot(body.inertia * wb);
  }
  return e;
}

Vec3 World::linear_momentum() const {
  Vec3 p = Vec3::Zero();
  for (size_t b = 0; b < model_.bodies.size(); ++b)
    if (state_.alive[b]) p += model_.bodies[b].mass_kg * state_.velocity[b];
  return p;
}

}  // namespace floesim::sim

namespace floesim::sim {

namespace {

void put_vec3s(ByteWriter& w, const std::vector<Vec3>& v) {
  w.size(v.size());
  for (const Vec3& x : v) w.mat(x);
}
void get_vec3s(ByteReader& r, std::vector<Vec3>& v) {
  v.resize(r.size(3 * sizeof(double)));
  for (Vec3& x : v) r.mat(x);
}
void put_mat3s(ByteWriter& w, const std::vector<Mat3>& v) {
  w.size(v.size());
  for (const Mat3& x : v) w.mat(x);
}
void get_mat3s(ByteReader& r, std::vector<Mat3>& v) {
  v.resize(r.size(9 * sizeof(double)));
  for (Mat3& x : v) r.mat(x);
}

// No run has a coordinate or length beyond a million kilometres (a field in projected coordinates, UTM northings
// of 8e6 m, is far inside), and the broad phase's tree, which multiplies box extents, overflows to inf and crashes
// on boxes near the largest double (fuzz_checkpoint: a piece at z = 3.8e199).
constexpr double kMaxLength_m = 1e9;
template <class V>
bool within(const V& v, double bound) {
  return v.allFinite() && v.cwiseAbs().maxCoeff() <= bound;
}

// The per-body arrays of a state must match the body table; a checkpoint that says otherwise is damaged.
void require_bodies(const ByteReader& r, size_t got, size_t bodies, const char* what) {
  FLOESIM_REQUIRE(got == bodies, r.what(), ": damaged (", what, " for ", got, " bodies, the world has ", bodies, ")");
}

}  // namespace

void World::save(ByteWriter& w) const {
  // 1. The body table as built (a check) and the pieces appended since, as what made them.
  w.size(base_bodies_);
  w.size(model_.parts.size());
  w.size(model_.bodies.size() - base_bodies_);
  for (size_t k = base_bodies_; k < model_.bodies.size(); ++k) {
    const Body& b = model_.bodies[k];
    w.size(b.outline.size());
    for (const Vec2& p : b.outline) w.mat(p);
    w.pod(b.thickness_m);
    w.pod<int32_t>(b.id);
    w.pod<int32_t>(b.parent_id);
    w.pod<int32_t>(b.generation);
    w.pod<int32_t>(b.origin_mode);
    w.pod(b.created_s);
    w.mat(b.initial_position);
    w.quat(b.initial_orientation);
    w.pod<uint8_t>(b.fixed ? 1 : 0);
    w.pod<int32_t>(b.ridge);
    w.pod<uint8_t>(static_cast<uint8_t>(b.ridge_part));
  }
  // 2. The state.
  const State& s = state_;
  w.pod(s.time_s);
  w.pod<int64_t>(s.step);
  put_vec3s(w, s.position);
  w.size(s.orientation.size());
  for (const Quat& q : s.orientation) w.quat(q);
  put_vec3s(w, s.velocity);
  put_vec3s(w, s.angular_velocity);
  w.vec(s.awake);
  w.vec(s.alive);
  w.vec(s.still_time_s);
  w.vec(s.heave_lowpass_mps);
  w.size(s.contact_cache.size());
  for (const CachedContact& c : s.contact_cache) {
    for (int i : {c.body_a, c.part_a, c.body_b, c.part_b, c.row}) w.pod<int32_t>(i);
    w.mat(c.local_a);
    w.mat(c.impulse);
    w.pod<uint8_t>(static_cast<uint8_t>(c.type));
    w.mat(c.crush_normal_a);
    w.mat(c.crush_point_a);
    w.mat(c.crush_point_b);
  }
  w.size(s.pair_loads.size());
  for (const PairLoadHistory& l : s.pair_loads) {
    w.pod<int32_t>(l.floe);
    w.pod<int32_t>(l.other);
    w.mat(l.point);
    put_vec3s(w, l.force);
  }
  w.size(s.bonds.size());
  for (const FreezeBond& fb : s.bonds) {
    w.pod<int32_t>(fb.body_a);
    w.pod<int32_t>(fb.body_b);
    w.mat(fb.anchor_a);
    w.mat(fb.anchor_b);
    w.mat(fb.normal_a);
    w.pod(fb.area_m2);
    w.mat(fb.impulse_a);
  }
  w.pod<int64_t>(s.bonds_broken);
  w.pod(s.speed_error_integral);
  w.pod(s.heading_ref_rad);
  w.vec(s.dp_memory);
  w.size(s.structure_dp_memory.size());
  for (const std::vector<double>& m : s.structure_dp_memory) w.vec(m);
  // 3. What else carries over: mass matrices as the solver saw them, jets, the fracture record, moved bodies.
  put_mat3s(w, solver_bodies_.inv_mass);
  put_mat3s(w, solver_bodies_.inv_inertia_world);
  w.size(jets_.size());
  for (const PropellerJet& j : jets_) {
    w.mat(j.origin);
    w.mat(j.dir);
    w.pod(j.efflux_mps);
    w.pod(j.excess_mps);
    w.pod(j.d0_m);
  }
  w.size(events_.size());
  for (const FractureEvent& e : events_) {
    w.pod(e.time_s);
    w.pod<int32_t>(e.parent_id);
    w.pod<int32_t>(e.mode);
    w.pod<uint8_t>(e.at_structure ? 1 : 0);
    w.mat(e.force_n);
    w.pod(e.threshold_n);
    w.mat(e.point_m);
    w.pod(e.width_m);
    w.pod(e.theta_rad);
    w.pod(e.lc_m);
    w.pod(e.rb_m);
    w.pod(e.brash_mass_kg);
    std::vector<int32_t> children(e.child_ids.begin(), e.child_ids.end());
    w.vec(children);
  }
  w.vec(ended_s_);
  w.pod(brash_mass_kg_);
  w.pod<int32_t>(next_floe_id_);
  w.pod<int32_t>(floes_alive_);
  std::vector<int32_t> moved(moved_.begin(), moved_.end());
  w.vec(moved);
  for (double t : stage_seconds_) w.pod(t);
  // 4. The branch of solver.reference_horizon_s, if one runs (a world of its own, saved the same way).
  w.pod<uint8_t>(branch_ ? 1 : 0);
  if (branch_) branch_->save(w);
}

std::unique_ptr<World> World::restore(const Model& base, ByteReader& r) {
  // 1. The body table: the model as built must be the one saved (same inputs), then the pieces are remade.
  const size_t base_bodies = r.size(), parts = r.size(), pieces = r.size(1);
  FLOESIM_REQUIRE(base_bodies == base.bodies.size(), r.what(), ": made for a model of ", base_bodies,
                  " bodies, the inputs give ", base.bodies.size(), " (other inputs?)");
  Model m = base;
  for (size_t k = 0; k < pieces; ++k) {
    PieceSpec p;
    p.outline.resize(r.size(2 * sizeof(double)));
    for (Vec2& v : p.outline) r.mat(v);
    p.thickness_m = r.pod<double>();
    p.id = r.pod<int32_t>();
    p.parent_id = r.pod<int32_t>();
    p.generation = r.pod<int32_t>();
    p.origin_mode = r.pod<int32_t>();
    p.created_s = r.pod<double>();
    r.mat(p.position);
    p.orientation = r.quat();
    p.fixed = r.pod<uint8_t>() != 0;
    p.ridge = r.pod<int32_t>();
    const uint8_t part = r.pod<uint8_t>();
    FLOESIM_REQUIRE(p.ridge >= -1 && p.ridge < static_cast<int>(m.settings.ridges.size()) &&
                        part <= static_cast<uint8_t>(RidgePart::sail),
                    r.what(), ": damaged (piece ", p.id, " names ridge ", p.ridge, ", part ", int(part), ")");
    p.ridge_part = static_cast<RidgePart>(part);
    // Every number finite and every length within kMaxLength_m, the outline's area finite and positive (a NaN,
    // infinite or near-infinite box crashes the broad phase's tree), the orientation a unit quaternion, as a run
    // writes them.
    bool finite = std::isfinite(p.thickness_m) && p.thickness_m <= kMaxLength_m && std::isfinite(p.created_s) &&
                  within(p.position, kMaxLength_m) && p.orientation.coeffs().allFinite() &&
                  std::abs(p.orientation.norm() - 1) < 1e-9;
    for (const Vec2& v : p.outline) finite = finite && within(v, kMaxLength_m);
    FLOESIM_REQUIRE(finite && p.outline.size() >= 3 && std::isfinite(signed_area(p.outline)) &&
                        signed_area(p.outline) > 0 && p.thickness_m > 0,
                    r.what(), ": damaged (piece ", p.id, " has no valid outline, thickness or pose)");
    const int index = static_cast<int>(m.bodies.size());
    m.bodies.push_back(make_piece_body(p, index, m.settings, m.parts));
    const Body& b = m.bodies.back();
    FLOESIM_REQUIRE(std::isfinite(b.mass_kg) && b.mass_kg > 0 && b.inertia.allFinite() && b.inv_inertia.allFinite() &&
                        std::isfinite(b.section_radius),
                    r.what(), ": damaged (piece ", p.id, " has no finite mass properties)");
  }
  FLOESIM_REQUIRE(m.parts.size() == parts, r.what(), ": the remade body table has ", m.parts.size(),
                  " convex parts, the saved one had ", parts, " (other inputs, or another build of floesim?)");
  auto w = std::make_unique<World>(m);
  w->base_bodies_ = base_bodies;
  const size_t n = m.bodies.size();
  // 2. The state.
  State& s = w->state_;
  s.time_s = r.pod<double>();
  s.step = static_cast<long>(r.pod<int64_t>());
  get_vec3s(r, s.position);
  require_bodies(r, s.position.size(), n, "positions");
  s.orientation.resize(r.size(4 * sizeof(double)));
  for (Quat& q : s.orientation) q = r.quat();
  require_bodies(r, s.orientation.size(), n, "orientations");
  get_vec3s(r, s.velocity);
  require_bodies(r, s.velocity.size(), n, "velocities");
  get_vec3s(r, s.angular_velocity);
  require_bodies(r, s.angular_velocity.size(), n, "angular velocities");
  // A run's state is what its health check lets through (finite, speeds within health.max_speed_mps and
  // max_angular_radps), its positions within kMaxLength_m and its orientations unit quaternions; the broad phase is
  // built from these poses below.
  const HealthOptions& health = m.settings.health;
  for (size_t b = 0; b < n; ++b)
    FLOESIM_REQUIRE(within(s.position[b], kMaxLength_m) && s.velocity[b].allFinite() &&
                        s.velocity[b].norm() <= health.max_speed_mps && s.angular_velocity[b].allFinite() &&
                        s.angular_velocity[b].norm() <= health.max_angular_radps &&
                        s.orientation[b].coeffs().allFinite() && std::abs(s.orientation[b].norm() - 1) < 1e-9,
                    r.what(), ": damaged (body ", b, " has a state no run reaches: non-finite, beyond ", kMaxLength_m,
                    " m or the health limits, or an orientation that is not a rotation)");
  s.awake = r.vec<uint8_t>();
  require_bodies(r, s.awake.size(), n, "awake flags");
  s.alive = r.vec<uint8_t>();
  require_bodies(r, s.alive.size(), n, "alive flags");
  s.still_time_s = r.vec<double>();
  require_bodies(r, s.still_time_s.size(), n, "still times");
  s.heave_lowpass_mps = r.vec<double>();
  require_bodies(r, s.heave_lowpass_mps.size(), n, "heave filter states");
  for (size_t b = 0; b < n; ++b)
    FLOESIM_REQUIRE(std::isfinite(s.heave_lowpass_mps[b]) && std::abs(s.heave_lowpass_mps[b]) <= health.max_speed_mps,
                    r.what(), ": damaged (body ", b, " has a heave filter state no run reaches: non-finite or beyond "
                    "health.max_speed_mps)");
  s.contact_cache.resize(r.size(1));
  for (CachedContact& c : s.contact_cache) {
    for (int* i : {&c.body_a, &c.part_a, &c.body_b, &c.part_b, &c.row}) *i = r.pod<int32_t>();
    r.mat(c.local_a);
    r.mat(c.impulse);
    const uint8_t type = r.pod<uint8_t>();
    FLOESIM_REQUIRE(type <= static_cast<uint8_t>(ContactType::crushing), r.what(),
                    ": damaged (a cached contact of unknown type ", int(type), ")");
    c.type = static_cast<ContactType>(type);
    r.mat(c.crush_normal_a);
    r.mat(c.crush_point_a);
    r.mat(c.crush_point_b);
    FLOESIM_REQUIRE(c.body_a >= 0 && c.body_b >= 0 && static_cast<size_t>(c.body_a) < n &&
                        static_cast<size_t>(c.body_b) < n && c.part_a >= 0 && c.part_b >= 0 &&
                        static_cast<size_t>(c.part_a) < parts && static_cast<size_t>(c.part_b) < parts,
                    r.what(), ": damaged (a cached contact names a body or part that does not exist)");
  }
  s.pair_loads.resize(r.size(1));
  for (PairLoadHistory& l : s.pair_loads) {
    l.floe = r.pod<int32_t>();
    l.other = r.pod<int32_t>();
    r.mat(l.point);
    get_vec3s(r, l.force);
    FLOESIM_REQUIRE(l.floe >= 0 && l.other >= 0 && static_cast<size_t>(l.floe) < n &&
                        static_cast<size_t>(l.other) < n && !l.force.empty(),
                    r.what(), ": damaged (a fracture load history names a body that does not exist)");
  }
  s.bonds.resize(r.size(2 * sizeof(int32_t) + 13 * sizeof(double)));
  for (FreezeBond& fb : s.bonds) {
    fb.body_a = r.pod<int32_t>();
    fb.body_b = r.pod<int32_t>();
    r.mat(fb.anchor_a);
    r.mat(fb.anchor_b);
    r.mat(fb.normal_a);
    fb.area_m2 = r.pod<double>();
    r.mat(fb.impulse_a);
    FLOESIM_REQUIRE(fb.body_a >= 0 && fb.body_a < fb.body_b && static_cast<size_t>(fb.body_b) < n &&
                        fb.anchor_a.allFinite() && fb.anchor_b.allFinite() && fb.impulse_a.allFinite() &&
                        std::abs(fb.normal_a.norm() - 1) < 1e-9 && fb.area_m2 > 0 && std::isfinite(fb.area_m2),
                    r.what(), ": damaged (a freeze bond names a body that does not exist or has no area)");
  }
  s.bonds_broken = r.pod<int64_t>();
  FLOESIM_REQUIRE(s.bonds_broken >= 0, r.what(), ": damaged (a negative count of broken bonds)");
  s.speed_error_integral = r.pod<double>();
  s.heading_ref_rad = r.pod<double>();
  s.dp_memory = r.vec<double>();
  FLOESIM_REQUIRE(s.dp_memory.empty() || s.dp_memory.size() == static_cast<size_t>(DpController::kMemory), r.what(),
                  ": damaged (a DP controller's memory of ", s.dp_memory.size(), " values)");
  s.structure_dp_memory.resize(r.size(8));
  FLOESIM_REQUIRE(s.structure_dp_memory.size() == w->model_.structures.size(), r.what(), ": damaged (",
                  s.structure_dp_memory.size(), " structures' DP memories for ", w->model_.structures.size(),
                  " structures)");
  for (std::vector<double>& m : s.structure_dp_memory) {
    m = r.vec<double>();
    FLOESIM_REQUIRE(m.empty() || m.size() == static_cast<size_t>(DpController::kMemory), r.what(),
                    ": damaged (a DP controller's memory of ", m.size(), " values)");
  }
  // 3. The rest.
  get_mat3s(r, w->solver_bodies_.inv_mass);
  require_bodies(r, w->solver_bodies_.inv_mass.size(), n, "inverse masses");
  get_mat3s(r, w->solver_bodies_.inv_inertia_world);
  require_bodies(r, w->solver_bodies_.inv_inertia_world.size(), n, "inverse inertias");
  for (size_t b = 0; b < n; ++b)
    FLOESIM_REQUIRE(w->solver_bodies_.inv_mass[b].allFinite() && w->solver_bodies_.inv_inertia_world[b].allFinite(),
                    r.what(), ": damaged (body ", b, " has a non-finite inverse mass or inertia)");
  w->jets_.resize(r.size(1));
  for (PropellerJet& j : w->jets_) {
    r.mat(j.origin);
    r.mat(j.dir);
    j.efflux_mps = r.pod<double>();
    j.excess_mps = r.pod<double>();
    j.d0_m = r.pod<double>();
  }
  w->events_.resize(r.size(1));
  for (FractureEvent& e : w->events_) {
    e.time_s = r.pod<double>();
    e.parent_id = r.pod<int32_t>();
    e.mode = r.pod<int32_t>();
    e.at_structure = r.pod<uint8_t>() != 0;
    r.mat(e.force_n);
    e.threshold_n = r.pod<double>();
    r.mat(e.point_m);
    e.width_m = r.pod<double>();
    e.theta_rad = r.pod<double>();
    e.lc_m = r.pod<double>();
    e.rb_m = r.pod<double>();
    e.brash_mass_kg = r.pod<double>();
    const std::vector<int32_t> children = r.vec<int32_t>();
    e.child_ids.assign(children.begin(), children.end());
  }
  w->ended_s_ = r.vec<double>();
  require_bodies(r, w->ended_s_.size(), n, "end times");
  w->brash_mass_kg_ = r.pod<double>();
  w->next_floe_id_ = r.pod<int32_t>();
  w->floes_alive_ = r.pod<int32_t>();
  const std::vector<int32_t> moved = r.vec<int32_t>();
  for (int32_t b : moved)
    FLOESIM_REQUIRE(b >= 0 && static_cast<size_t>(b) < n, r.what(), ": damaged (a moved body does not exist)");
  w->moved_.assign(moved.begin(), moved.end());
  for (double& t : w->stage_seconds_) t = r.pod<double>();
  // 4. The branch: restored on the model as built (the constructor made its base of the grown table).
  w->branch_base_ = branch_base(base);
  if (r.pod<uint8_t>()) {
    FLOESIM_REQUIRE(w->branch_base_, r.what(), ": damaged (a solver.reference branch for a run that has none)");
    w->branch_ = restore(*w->branch_base_, r);
  }
  // 5. The broad phase from the restored poses and awake flags, without the bodies that have left the world.
  w->collision_ = std::make_unique<CollisionWorld>(w->model_, w->state_, w->pool_);
  for (size_t b = 0; b < n; ++b)
    if (!s.alive[b]) w->collision_->remove_body(static_cast<int>(b));
  return w;
}

}  // namespace floesim::sim
