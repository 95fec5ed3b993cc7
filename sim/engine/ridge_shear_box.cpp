#include "sim/engine/ridge_shear_box.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <iomanip>

#include "pipeline/error.h"
#include "pipeline/floes_io.h"
#include "sim/engine/model.h"
#include "sim/engine/ridge_build.h"
#include "sim/engine/world.h"
#include "sim/geometry/mesh.h"
#include "sim/vessel/hull.h"

namespace floesim::sim {

namespace {

constexpr double kWall = 0.3;       // the frames' walls and the plates, thick
constexpr double kGap = 0.05;       // between the two frames at the shear plane
constexpr double kClear = 0.05;     // the loading plate's clearance to the bottom frame's walls, each side
constexpr double kTopZ = -0.5;      // the top plate's underside: the whole sample under water
constexpr double kAbove = 0.5;      // the frames' posts reach this far over the water line
constexpr double kRestMps = 0.01;   // a block at rest (m/s, and rad/s)
constexpr double kRestS = 2.0;      // every block at rest this long: settled
constexpr double kServoMps = 0.05;  // the loading plate's fastest
constexpr double kPackS = 30;       // the frictionless consolidation's length
constexpr double kConsolidateS = 60;  // the consolidation with friction's longest
constexpr double kApproachMps = 0.3;  // the loading plate's speed up to the rubble, touching nothing
constexpr double kServoBand = 0.1;  // consolidated: the normal stress (1 s mean) within this share of the one asked for

// A box [x0, x1] x [y0, y1] x [z0, z1].
TriMesh box(double x0, double x1, double y0, double y1, double z0, double z1) {
  return extrude_polygon({Vec2(x0, y0), Vec2(x1, y0), Vec2(x1, y1), Vec2(x0, y1)}, z0, z1 - z0);
}

// The four walls of a frame of inner half side h, between z0 and z1. The walls across y reach halfway into those
// across x: walls that only met would share a face, which the parts of one body do not collide with (a cut between
// parts, mark_shared_faces), and blocks would pass through the walls' inner faces.
std::vector<TriMesh> walls(double h, double z0, double z1) {
  const double o = h + kWall, m = h + 0.5 * kWall;
  return {box(h, o, -o, o, z0, z1), box(-o, -h, -o, o, z0, z1), box(-m, m, h, o, z0, z1), box(-m, m, -o, -h, z0, z1)};
}

// Two thin posts at (-x, 0) and (x, 0) from z0 to over the water: a body wholly under water has no water line to be
// a hull, so each moving part of the rig stands on a pair, out of the rubble's reach. A pair, so that the body's
// centre stays on the box's axis (a hull body stands with its centre where its options put it).
std::vector<TriMesh> posts(double x, double z0) {
  return {box(-x - 0.1, -x + 0.1, -0.1, 0.1, z0, kAbove), box(x - 0.1, x + 0.1, -0.1, 0.1, z0, kAbove)};
}

struct Rig {
  double half = 0, plane_z = 0, plate_top_z = 0;
  EngineSettings settings;
  std::vector<RidgeBlock> blocks;
  HullModel top, bottom, plate;
};

// The rig's geometry: the blocks released as a ridge's keel across the box (its line along y, as wide as the box,
// sides at 85 deg), shifted down under the top plate; the frames and the loading plate round them.
Rig make_rig(const ShearBoxSpec& p) {
  FLOESIM_REQUIRE(p.box_m >= 2 * p.block_max_m, "shear box: box_m (", p.box_m, " m) must be at least twice the "
                  "largest block (", p.block_max_m, " m)");
  FLOESIM_REQUIRE(p.sample_height_m >= 4 * p.block_thickness_m, "shear box: sample_height_m (", p.sample_height_m,
                  " m) must hold at least two blocks' thickness (", p.block_thickness_m, " m) on each side of the plane");
  FLOESIM_REQUIRE(p.porosity > 0 && p.porosity < 1, "shear box: porosity must be in (0, 1), got ", p.porosity);
  FLOESIM_REQUIRE(p.normal_stress_pa > 0, "shear box: normal_stress_pa must be > 0, got ", p.normal_stress_pa);
  FLOESIM_REQUIRE(p.speed_mps > 0 && p.travel_m > 0 && p.travel_m < 0.5 * p.box_m && p.window_s > 0,
                  "shear box: speed_mps, travel_m (< box_m / 2) and window_s must be > 0");
  FLOESIM_REQUIRE(p.peak_within_m > 0 && p.peak_within_m <= p.travel_m, "shear box: peak_within_m (",
                  p.peak_within_m, " m) must be > 0 and at most travel_m (", p.travel_m, " m)");
  FLOESIM_REQUIRE(!p.bonds_pa.empty(), "shear box: bonds_pa must list at least one bond strength (0: no bonds)");
  for (double b : p.bonds_pa)
    FLOESIM_REQUIRE(b >= 0 && std::isfinite(b), "shear box: bonds_pa must be >= 0 (0: no bonds), got ", b);
  Rig rig;
  rig.half = 0.5 * p.box_m;
  rig.plane_z = kTopZ - 0.5 * p.sample_height_m;
  EngineSettings& o = rig.settings;
  o.threads = p.threads;
  o.sleep.enabled = false;
  o.fracture.enabled = false;
  RidgeOptions r;
  r.line = {{0, -rig.half}, {0, rig.half}};
  r.sail_height_m = 0;
  r.consolidated_thickness_m = 0.1;
  r.keel_depth_m = r.consolidated_thickness_m + p.sample_height_m;
  r.keel_width_m = p.box_m;
  r.keel_angle_deg = 85;
  r.block_thickness_m = p.block_thickness_m;
  r.block_size_m = {p.block_min_m, p.block_max_m};
  r.seed = p.seed;
  const double rho_i = o.ice.density_kg_m3, rho_w = o.water.density_kg_m3;
  const RidgeSection section = ridge_section(r, rho_i, rho_w, "shear box");
  // As many blocks as fill the sample at the porosity expected of it.
  r.porosity = 1 - (1 - p.porosity) * p.box_m * p.sample_height_m / section.keel_area_m2;
  FLOESIM_REQUIRE(r.porosity > 0 && r.porosity < 1, "internal: shear box release porosity ", r.porosity);
  rig.blocks = release_blocks(r, section);
  const double dz = kTopZ - 0.02 - section.layer_bottom_z;
  double deepest = kTopZ;
  for (RidgeBlock& k : rig.blocks) {
    k.z += dz;
    deepest = std::min(deepest, k.z - 0.5 * k.thickness);
  }
  rig.plate_top_z = deepest - 0.3;
  const double bottom_z = rig.plate_top_z - kWall - 0.5;
  // The top frame: its plate and its walls down to the plane (up through the water line).
  std::vector<TriMesh> top = walls(rig.half, rig.plane_z + 0.5 * kGap, kAbove);
  top.push_back(box(-rig.half - kWall, rig.half + kWall, -rig.half - kWall, rig.half + kWall, kTopZ, kTopZ + kWall));
  rig.top = hull_model_from_parts(std::move(top));
  // The bottom frame: its walls from under the loading plate up to the plane, and its posts beyond them.
  std::vector<TriMesh> bottom = walls(rig.half, bottom_z, rig.plane_z - 0.5 * kGap);
  for (TriMesh& q : posts(rig.half + kWall + 3, bottom_z)) bottom.push_back(std::move(q));
  rig.bottom = hull_model_from_parts(std::move(bottom));
  // The loading plate, and its posts beyond the walls.
  const double in = rig.half - kClear;
  std::vector<TriMesh> plate = {box(-in, in, -in, in, rig.plate_top_z - kWall, rig.plate_top_z)};
  for (TriMesh& q : posts(rig.half + kWall + 2, rig.plate_top_z - kWall)) plate.push_back(std::move(q));
  rig.plate = hull_model_from_parts(std::move(plate));
  o.vessel.station_keeping.mode = "fixed";
  for (const char* name : {"bottom-frame", "loading-plate"}) {
    StructureOptions s;
    s.name = name;
    s.body.station_keeping.mode = "fixed";
    o.structures.push_back(s);
  }
  return rig;
}

// The world: the top frame as the vessel (body 0), the bottom frame and the loading plate as structures 0 and 1
// (bodies 1, 2), then the blocks, tagged as a keel's rubble.
Model rig_model(const Rig& rig) {
  Model m = build_model(FloeField{}, &rig.top, rig.settings, {rig.bottom, rig.plate});
  // Each hull body's frame where the rig drew it: on the box's axis.
  for (const Station* s : {&m.station, &m.structures.at(0).station, &m.structures.at(1).station})
    FLOESIM_REQUIRE(std::abs(s->position.x()) < 1e-9 && std::abs(s->position.y()) < 1e-9,
                    "internal: a shear box body stands off the box's axis, at ", s->position.x(), ", ",
                    s->position.y(), " m");
  int id = 1;
  for (const RidgeBlock& k : rig.blocks) {
    Body b = make_rubble_block(k, id++, static_cast<int>(m.bodies.size()), rig.settings, m.parts);
    b.ridge_part = RidgePart::keel;
    m.bodies.push_back(std::move(b));
  }
  m.built_bodies = m.bodies.size();
  return m;
}

// `model` with every body where `state` has it (the rig's stages run in worlds of their own settings).
Model posed(Model model, const State& state) {
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    model.bodies[b].initial_position = state.position[b];
    model.bodies[b].initial_orientation = state.orientation[b];
  }
  return model;
}

// A moving mean over the last `n` values.
class Window {
 public:
  explicit Window(long n) : n_(std::max(1L, n)) {}
  double add(double x) {
    v_.push_back(x);
    sum_ += x;
    if (static_cast<long>(v_.size()) > n_) sum_ -= v_.front(), v_.pop_front();
    return mean();
  }
  double mean() const { return v_.empty() ? 0.0 : sum_ / static_cast<double>(v_.size()); }
  bool full() const { return static_cast<long>(v_.size()) == n_; }

 private:
  long n_;
  std::deque<double> v_;
  double sum_ = 0;
};

// One world of the rig and what the stages need of it: the bodies' roles, the stresses on the shear plane, the
// servo on the loading plate.
class RigWorld {
 public:
  RigWorld(const Rig& rig, Model model, const ShearBoxSpec& p, std::ostream* progress)
      : rig_(rig), p_(p), progress_(progress), w_(std::move(model)), servo_(std::lround(0.2 / dt())),
        held_(std::lround(1.0 / dt())), top_load_(std::lround(1.0 / dt())), push_load_(std::lround(1.0 / dt())) {
    const Model& m = w_.model();
    top_ = m.vessel;
    frame_ = m.structures.at(0).body;
    plate_ = m.structures.at(1).body;
    first_ = static_cast<int>(m.bodies.size() - rig.blocks.size());
    end_ = static_cast<int>(m.bodies.size());
    buoyant_ = (rig.settings.water.density_kg_m3 - rig.settings.ice.density_kg_m3) * rig.settings.water.gravity_mps2;
  }
  World& world() { return w_; }
  double dt() const { return rig_.settings.time_step_s; }
  int first_block() const { return first_; }
  int plate() const { return plate_; }
  double blocks_volume() const {
    double v = 0;
    for (int b = first_; b < end_; ++b) v += block_volume(b);
    return v;
  }
  double buoyancy_per_m3() const { return buoyant_; }
  double fastest() const {
    double f = 0;
    for (int b = first_; b < end_; ++b)
      f = std::max({f, w_.state().velocity[b].norm(), w_.state().angular_velocity[b].norm()});
    return f;
  }
  // The deepest point of any block.
  double deepest() const {
    double z = kTopZ;
    for (int b = first_; b < end_; ++b) {
      const Mat3 R = w_.state().orientation[b].toRotationMatrix();
      for (const Vec3& v : w_.model().bodies[b].buoyancy_mesh.vertices)
        z = std::min(z, (w_.state().position[b] + R * v).z());
    }
    return z;
  }
  // The loading plate's top, where it is now (its first part is the plate, in its body frame).
  double plate_top_z() const {
    const ConvexPart& part = w_.model().parts[w_.model().bodies[plate_].first_part];
    double top = -1e300;
    for (const Vec3& v : part.vertices) top = std::max(top, v.z());
    return w_.state().position[plate_].z() + top;
  }
  // Moves the loading plate up to `z_top` (its top) by hand: nothing may be in its way.
  void raise_plate_to(double z_top) {
    const double dz = z_top - plate_top_z();
    w_.mutable_state().position[plate_].z() += dz;
    w_.sync();
  }
  // One step with the bottom frame and the plate moving along x at vx, the plate in z by the servo.
  void step(double vx) {
    State& s = w_.mutable_state();
    s.velocity[top_].setZero();
    s.velocity[frame_] = Vec3(vx, 0, 0);
    s.velocity[plate_] = Vec3(vx, 0, vz_);
    w_.step();
  }
  // The normal stress on the plane over `area`: the plate's push, the net buoyancy of the blocks whose centre is
  // under the plane, less what the rubble hangs on the bottom frame's walls.
  double sigma(double area) const {
    double below = 0;
    for (int b = first_; b < end_; ++b)
      if (w_.state().position[b].z() < rig_.plane_z) below += block_volume(b);
    const double push = -w_.report().structures[1].ice_load.force.z();
    const double hung = w_.report().structures[0].ice_load.force.z();
    return (push + buoyant_ * below - hung) / area;
  }
  // The horizontal load on the bottom frame and the plate (the rubble's resistance to their motion along +x).
  double shear_force() const {
    return -(w_.report().structures[0].ice_load.force.x() + w_.report().structures[1].ice_load.force.x());
  }
  // The servo: the plate's next speed from the normal stress measured now (over a short window), in proportion to
  // its shortfall against the one asked for, at most kServoMps; touching nothing, kApproachMps up.
  void servo(double sigma) {
    held_.add(sigma);
    const double e = (p_.normal_stress_pa - servo_.add(sigma)) / p_.normal_stress_pa;
    const bool touching = w_.report().structures[1].contacts > 0;
    vz_ = touching ? kServoMps * std::clamp(e, -1.0, 1.0) : kApproachMps;
  }
  bool holding() const {
    return held_.full() && std::abs(held_.mean() - p_.normal_stress_pa) < kServoBand * p_.normal_stress_pa;
  }
  double sigma_held() const { return held_.mean(); }
  // Steps (still frames) until the blocks are at rest (and, with `servoed`, the plate holds the normal stress) for
  // kRestS; `what` names the stage in the progress lines and the error.
  // The vertical loads' balance over the last second: the top frame's load, and the blocks' net buoyancy with
  // the plate's push less what hangs on the bottom frame.
  void add_balance(double buoyancy) {
    const StepReport& rp = w_.report();
    top_load_.add(rp.ice_load.force.z());
    push_load_.add(buoyancy - rp.structures[1].ice_load.force.z() - rp.structures[0].ice_load.force.z());
  }
  double held_down() const { return top_load_.mean(); }
  double pushed_up() const { return push_load_.mean(); }
  // Steps with still frames until the blocks are at rest (and, with `servoed`, the plate holds the normal stress)
  // for kRestS. By `max_s`: with `required`, an error; else the stage ends there (a small sample under a load slips
  // now and then and may never be still for kRestS). Returns whether it came to rest.
  bool settle(bool servoed, const char* what, double max_s, bool required) {
    const long rest_steps = std::lround(kRestS / dt()), max_steps = std::lround(max_s / dt());
    const double buoyancy = buoyant_ * blocks_volume();
    long at_rest = 0, steps = 0;
    while (at_rest < rest_steps) {
      if (++steps > max_steps) {
        FLOESIM_REQUIRE(!required, "shear box: ", what, " has not come to rest after ", max_s,
                        " s (max_settle_s; normal stress ", p_.normal_stress_pa, " Pa)");
        return false;
      }
      step(0);
      if (servoed) servo(sigma(p_.box_m * p_.box_m));
      add_balance(buoyancy);
      at_rest = (!servoed || holding()) && fastest() < kRestMps ? at_rest + 1 : 0;
      say(what);
    }
    return true;
  }
  void say(const char* what) const {
    const long every = std::max(1L, std::lround(5.0 / dt()));
    if (progress_ && w_.state().step % every == 0)
      *progress_ << "  t " << std::fixed << std::setprecision(1) << w_.state().time_s << " s: " << what
                 << ", fastest block " << std::setprecision(3) << fastest() << " m/s, normal stress "
                 << std::setprecision(0) << held_.mean() << " Pa" << std::defaultfloat << std::endl;
  }

 private:
  double block_volume(int b) const {
    return w_.model().bodies[b].section_area * w_.model().bodies[b].thickness_m;
  }
  const Rig& rig_;
  const ShearBoxSpec& p_;
  std::ostream* progress_;
  World w_;
  Window servo_, held_;  // the normal stress over the servo's window, and over a second
  Window top_load_, push_load_;  // add_balance's, over a second
  double vz_ = 0, buoyant_ = 0;
  int top_ = 0, frame_ = 0, plate_ = 0, first_ = 0, end_ = 0;
};

// The consolidated sample (at rest in `consolidated`) frozen with bonds of `bonds_pa` (0: none) and sheared: the
// bottom frame and the plate along +x, the stresses over the shear plane's area then.
ShearTest shear(const Rig& consolidated_rig, const State& consolidated, double bonds_pa, const ShearBoxSpec& p,
                std::ostream* progress) {
  Rig rig = consolidated_rig;
  rig.settings.freeze_bonds.tensile_strength_pa = bonds_pa;
  rig.settings.freeze_bonds.shear_strength_pa = bonds_pa;
  RigWorld t(rig, posed(rig_model(rig), consolidated), p, progress);
  World& w = t.world();
  const double a = p.box_m, plate_z0 = w.state().position[t.plate()].z();
  ShearTest r;
  r.bonds_pa = bonds_pa;
  // Freeze bonds between the blocks that touch, at the poses the next step finds them in (every shear takes that
  // step, bonds or none, so that the shears of one sample start alike).
  const State before = w.state();
  t.step(0);
  t.servo(t.sigma(a * a));
  if (rig.settings.freeze_bonds.enabled()) {
    std::vector<uint8_t> freezes(w.model().bodies.size(), 0);
    for (size_t b = t.first_block(); b < freezes.size(); ++b) freezes[b] = 1;
    std::vector<FreezeBond> bonds =
        freeze_touching(w.model(), before, w.contacts(), freezes, rig.settings.freeze_bonds);
    std::stable_sort(bonds.begin(), bonds.end(), bond_pair_less);
    r.bonds = static_cast<int>(bonds.size());
    w.mutable_state().bonds = std::move(bonds);
  }
  const double dt = t.dt();
  const long shear_steps = std::lround(p.travel_m / p.speed_mps / dt);
  Window tau_w(std::lround(p.window_s / dt)), sigma_w(std::lround(p.window_s / dt));
  r.tau_peak_pa = -1e300;
  double tau_sum = 0, sigma_sum = 0, sigma_all = 0;
  long tail = 0;
  for (long k = 0; k < shear_steps; ++k) {
    t.step(p.speed_mps);
    const double d = (k + 1) * dt * p.speed_mps, area = a * (a - d);
    const double sigma = t.sigma(area);
    t.servo(sigma);
    const double tau = t.shear_force() / area;
    r.travel_m.push_back(d);
    r.tau_pa.push_back(tau);
    r.sigma_pa.push_back(sigma);
    r.plate_rise_m.push_back(w.state().position[t.plate()].z() - plate_z0);
    const double tm = tau_w.add(tau), sm = sigma_w.add(sigma);
    if (tau_w.full() && d <= p.peak_within_m && tm > r.tau_peak_pa)
      r.tau_peak_pa = tm, r.sigma_at_peak_pa = sm, r.peak_at_m = d;
    sigma_all += sigma;
    if (4 * k >= 3 * shear_steps) tau_sum += tau, sigma_sum += sigma, ++tail;
    t.say("shearing");
  }
  r.tau_residual_pa = tail > 0 ? tau_sum / static_cast<double>(tail) : 0;
  r.sigma_residual_pa = tail > 0 ? sigma_sum / static_cast<double>(tail) : 0;
  r.sigma_mean_pa = sigma_all / static_cast<double>(std::max(1L, shear_steps));
  r.bonds_broken = w.state().bonds_broken;
  return r;
}

}  // namespace

ShearBoxResult shear_box_test(const ShearBoxSpec& p, std::ostream* progress) {
  const Rig rig = make_rig(p);
  ShearBoxResult r;
  r.blocks = static_cast<int>(rig.blocks.size());
  const double a = p.box_m;
  // 1. The blocks rise against the top plate and come to rest (with friction: frictionless blocks under a plate
  // slide on for minutes).
  RigWorld rise(rig, rig_model(rig), p, progress);
  rise.settle(false, "rising", p.max_settle_s, true);
  r.rise_s = rise.world().state().time_s;
  rise.raise_plate_to(rise.deepest() - 0.05);
  // 2. The sample consolidated without friction under the normal stress for kPackS (frictionless blocks under a load
  // never quite come to rest), so that the blocks pack as a keel's do by long creep, not jammed loose where they
  // first met (with friction at once the sample stays at a porosity near 0.6); then with friction until it rests (or
  // for kConsolidateS).
  Rig frictionless = rig;
  frictionless.settings.ice.mu_ice_ice = 0;
  frictionless.settings.ice.mu_ice_structure = 0;
  RigWorld pack(frictionless, posed(rig_model(frictionless), rise.world().state()), p, progress);
  for (long k = std::lround(kPackS / pack.dt()); k > 0; --k) {
    pack.step(0);
    pack.servo(pack.sigma(a * a));
    pack.say("packing (frictionless)");
  }
  RigWorld t(rig, posed(rig_model(rig), pack.world().state()), p, progress);
  r.consolidated_at_rest = t.settle(true, "consolidating", kConsolidateS, false);
  r.consolidate_s = pack.world().state().time_s + t.world().state().time_s;
  r.sigma_consolidated_pa = t.sigma_held();
  const double volume = t.blocks_volume();
  r.buoyancy_n = t.buoyancy_per_m3() * volume;
  r.sample_height_m = kTopZ - t.plate_top_z();
  r.plane_depth_m = kTopZ - rig.plane_z;
  r.porosity = 1 - volume / (a * a * r.sample_height_m);
  r.held_down_n = t.held_down();
  r.pushed_up_n = t.pushed_up();
  for (double bonds_pa : p.bonds_pa) r.shears.push_back(shear(rig, t.world().state(), bonds_pa, p, progress));
  return r;
}

}  // namespace floesim::sim
