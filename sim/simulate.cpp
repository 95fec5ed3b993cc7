#include "sim/simulate.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <sys/resource.h>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/floes_io.h"
#include "pipeline/ice_resistance.h"
#include "pipeline/interrupt.h"
#include "pipeline/provenance.h"
#include "pipeline/signal.h"
#include "pipeline/units.h"
#include "sim/checkpoint.h"
#include "sim/fracture.h"
#include "sim/fracture_laws.h"
#include "sim/world.h"

namespace floesim::sim {

namespace fs = std::filesystem;

namespace {

// The load windows of the seed paper (§5): 0.5 s for compliant contacts, 20 s for rigid ones.
constexpr double kCompliantWindowS = 0.5;
constexpr double kRigidWindowS = 20.0;

// A wrench in body axes as the 6 columns Fx Fy Fz Mx My Mz.
void push_body_wrench(std::vector<double>& col, const Mat3& R, const Wrench& w) {
  const Vec3 f = R.transpose() * w.force, m = R.transpose() * w.torque;
  col.insert(col.end(), {f.x(), f.y(), f.z(), m.x(), m.y(), m.z()});
}

// The contact law behind the vessel's ice load, which decides the filter window of its plots (PHYSICS.md §5):
// "rigid" or "compliant" when every recorded vessel contact load is of that kind, "mixed" when both occur. A run
// without vessel contacts reports the law its ice-structure pairs would have had.
std::string vessel_contact_model(const Model& model, const Results& r) {
  bool rigid = false, compliant = false;
  for (double x : r.get("ice_load_rigid")) rigid = rigid || x != 0;
  for (double x : r.get("ice_load_compliant")) compliant = compliant || x != 0;
  if (rigid && compliant) return "mixed";
  if (rigid) return "rigid";
  if (compliant) return "compliant";
  return model.options.contact.ice_structure;
}

// The world's fracture events into the /fracture table of the results.
void record_fracture_events(const std::vector<FractureEvent>& events, Results& r) {
  for (const FractureEvent& e : events) {
    r.fracture_time_s.push_back(e.time_s);
    r.fracture_parent_id.push_back(e.parent_id);
    r.fracture_mode.push_back(e.mode);
    r.fracture_at_structure.push_back(e.at_structure ? 1 : 0);
    r.fracture_force_n.insert(r.fracture_force_n.end(), {e.force_n.x(), e.force_n.y(), e.force_n.z()});
    r.fracture_threshold_n.push_back(e.threshold_n);
    r.fracture_point_m.insert(r.fracture_point_m.end(), {e.point_m.x(), e.point_m.y(), e.point_m.z()});
    r.fracture_width_m.push_back(e.width_m);
    r.fracture_theta_rad.push_back(e.theta_rad);
    r.fracture_brash_mass_kg.push_back(e.brash_mass_kg);
    r.fracture_child_id.insert(r.fracture_child_id.end(), e.child_ids.begin(), e.child_ids.end());
    r.fracture_child_offset.push_back(static_cast<int64_t>(r.fracture_child_id.size()));
  }
}

// Quantiles of a sample (nearest rank), for the piece size distribution.
nlohmann::json distribution(std::vector<double> x) {
  if (x.empty()) return {{"count", 0}};
  std::sort(x.begin(), x.end());
  auto q = [&](double p) { return x[static_cast<size_t>(std::lround(p * (x.size() - 1)))]; };
  double mean = 0;
  for (double v : x) mean += v;
  return {{"count", x.size()}, {"min", x.front()}, {"p10", q(0.1)}, {"p50", q(0.5)}, {"p90", q(0.9)},
          {"max", x.back()}, {"mean", mean / x.size()}};
}

// The summary's fracture object, from the results alone: events per mode, pieces, ice mass at the start and the
// end (bodies alive + brash removed: ice is neither made nor lost), the size distribution of the pieces, and for
// the wedges (bending, radial) the load-to-crack distance R_b of PHYSICS.md §2.1 against the pieces' size.
nlohmann::json fracture_summary(const SimulateOptions& o, const Results& r) {
  nlohmann::json f;
  f["enabled"] = o.fracture.enabled;
  f["at_ice_ice_contacts"] = o.fracture.ice_ice;
  int count[4] = {0, 0, 0, 0}, at_vessel = 0;
  for (size_t e = 0; e < r.fracture_mode.size(); ++e) {
    ++count[std::clamp(r.fracture_mode[e], 0, 3)];
    at_vessel += r.fracture_at_structure[e];
  }
  f["events"] = {{"bending", count[kFractureBending]}, {"radial", count[kFractureRadial]},
                 {"splitting", count[kFractureSplitting]}, {"total", r.fracture_mode.size()},
                 {"at_vessel", at_vessel}};
  std::map<int32_t, double> area, thickness;  // by floe id
  double start = 0, end = 0, brash = 0;
  std::vector<double> piece_area, piece_diameter;
  for (size_t k = 0; k < r.floe_id.size(); ++k) {
    Polygon p;
    for (int64_t i = r.floe_vertex_offset[k]; i < r.floe_vertex_offset[k + 1]; ++i)
      p.emplace_back(r.floe_vertices_m[2 * i], r.floe_vertices_m[2 * i + 1]);
    const double a = signed_area(p), m = o.ice.density_kg_m3 * a * r.floe_thickness_m[k];
    area[r.floe_id[k]] = a;
    thickness[r.floe_id[k]] = r.floe_thickness_m[k];
    if (r.floe_parent_id[k] < 0) start += m;
    if (std::isinf(r.floe_ended_s[k])) end += m;
    // Pieces: the floes fracture made (a wedge off a level ice tile is one; what the tile keeps is still sheet).
    const bool sheet = !r.floe_level_ice.empty() && r.floe_level_ice[k];
    if (r.floe_parent_id[k] >= 0 && !sheet) {
      piece_area.push_back(a);
      piece_diameter.push_back(std::sqrt(4 * a / kPi));
    }
  }
  for (double b : r.fracture_brash_mass_kg) brash += b;
  f["pieces_created"] = piece_area.size();
  f["ice_mass_start_kg"] = start;
  f["ice_mass_end_kg"] = end + brash;
  f["ice_mass_in_bodies_end_kg"] = end;
  f["brash_removed_kg"] = brash;
  f["min_piece_area_m2"] = o.fracture.min_piece_area_m2;
  f["piece_area_m2"] = distribution(piece_area);
  f["piece_equivalent_diameter_m"] = distribution(piece_diameter);
  // Wedges: R_b of fracture.piece_size for each event's theta and width (static: without the speed correction),
  // against the smallest child of the event (the wedge: the floe it broke from is longer than the wedge by the
  // finite-floe rule, so the remainder is the larger piece). An event with one child and brash removed lost its
  // wedge to brash (a sliver cut beside an earlier crack): its only child is the remainder, not a piece, so it is
  // counted apart instead (in level ice it would otherwise put the tile's size among the pieces).
  std::vector<double> rb, wedge_size, wedge_ratio;
  int wedge_brash = 0;
  const double rho_w_g = o.water.density_kg_m3 * o.water.gravity_mps2;
  for (size_t e = 0; e < r.fracture_mode.size(); ++e) {
    if (r.fracture_mode[e] == kFractureSplitting || rho_w_g <= 0) continue;
    const double h = thickness[r.fracture_parent_id[e]];
    const double lc = characteristic_length_m(o.fracture.youngs_modulus_pa, o.fracture.poisson_ratio, h, rho_w_g);
    const double theta = r.fracture_theta_rad[e], w = r.fracture_width_m[e];
    const double rb_e = static_piece_rb_m(
        o.fracture, wedge_failure(theta, o.fracture.flexural_strength_pa, h, w / (theta * lc)).rb_over_lc, lc);
    double smallest = 0;
    for (int64_t i = r.fracture_child_offset[e]; i < r.fracture_child_offset[e + 1]; ++i) {
      const double a = area[r.fracture_child_id[i]];
      if (smallest == 0 || a < smallest) smallest = a;
    }
    if (smallest <= 0) continue;
    rb.push_back(rb_e);
    if (r.fracture_child_offset[e + 1] - r.fracture_child_offset[e] == 1 && r.fracture_brash_mass_kg[e] > 0) {
      ++wedge_brash;
      continue;
    }
    wedge_size.push_back(std::sqrt(smallest));
    // The wedge's area if the floe were wider than it: the sector of angle theta between radii a and a + R_b.
    const double a0 = w / theta;
    wedge_ratio.push_back(smallest / (0.5 * theta * ((a0 + rb_e) * (a0 + rb_e) - a0 * a0)));
  }
  f["wedges"] = {{"piece_size", o.fracture.piece_size},
                 {"rb_m", distribution(rb)},
                 {"events_wedge_to_brash", wedge_brash},
                 {"sqrt_piece_area_m", distribution(wedge_size)},
                 {"piece_area_over_sector_area", distribution(wedge_ratio)}};
  return f;
}

}  // namespace

nlohmann::json level_ice_summary(const Model& model, const Results& r) {
  return level_ice_summary(model, r, ResultsSeries(r));
}

nlohmann::json level_ice_summary(const Model& model, const Results& r, const SeriesSource& series) {
  nlohmann::json j;
  const int v = model.vessel;
  std::vector<int> tiles;
  for (size_t b = 0; b < model.bodies.size(); ++b)
    if (model.bodies[b].fixed) tiles.push_back(static_cast<int>(b));
  j["tiles_start"] = tiles.size();
  if (tiles.empty() || v < 0 || r.frames() == 0) return j;
  const Body& vb = model.bodies[v];
  const Vec3 heading = vb.initial_orientation * Vec3::UnitX();
  const Vec2 along = Vec2(heading.x(), heading.y()).normalized(), across(-along.y(), along.x());
  const Vec2 start = vb.initial_position.head<2>();
  auto to_track = [&](const Vec2& p) { return Vec2(along.dot(p - start), across.dot(p - start)); };
  const double beam = model.vessel_info.beam_wl_m;
  const double far = 1e6;
  auto world = [&](double u, double w) { return Vec2(start + u * along + w * across); };
  auto placed = [](const Polygon& outline, const Vec2& at) {
    Polygon w;
    for (const Vec2& p : outline) w.push_back(p + at);
    return w;
  };
  // The vessel's path: the band half a beam either side of its start line.
  const Polygon path = {world(-far, -beam / 2), world(far, -beam / 2), world(far, beam / 2), world(-far, beam / 2)};
  double sheet_area = 0, u_edge = std::numeric_limits<double>::infinity();
  for (int b : tiles) {
    const Body& t = model.bodies[b];
    sheet_area += t.section_area;
    for (const Polygon& piece : polygon_intersection(placed(t.outline, t.initial_position.head<2>()), path))
      for (const Vec2& p : piece) u_edge = std::min(u_edge, to_track(p).x());
  }
  j["sheet_area_start_m2"] = sheet_area;
  // The sheet's ice as the level-ice resistance formulas take it (PHYSICS.md §6; a sweep's gather evaluates them
  // beside the simulated mean): the area-weighted mean thickness of the sheet and the material of the run.
  double h_area = 0;
  for (int b : tiles) h_area += model.bodies[b].thickness_m * model.bodies[b].section_area;
  const SimulateOptions& o = model.options;
  LevelIce ice;
  ice.thickness_m = h_area / sheet_area;
  ice.flexural_strength_pa = o.fracture.flexural_strength_pa;
  ice.youngs_modulus_pa = o.fracture.youngs_modulus_pa;
  ice.poisson_ratio = o.fracture.poisson_ratio;
  ice.ice_density_kg_m3 = o.ice.density_kg_m3;
  ice.water_density_kg_m3 = o.water.density_kg_m3;
  ice.gravity_mps2 = o.water.gravity_mps2;
  ice.friction = o.ice.mu_ice_structure;
  j["ice"] = level_ice_json(ice);
  // The vessel at the end (last frame) and the tiles alive then.
  FrameReplay replay(r, "the results");
  replay.seek(r.frames() - 1);
  double u_end = -std::numeric_limits<double>::infinity();
  std::map<int32_t, Vec2> end_position;
  for (const int64_t row : replay.rows()) {
    const Vec2 x(r.state_position_m[3 * row], r.state_position_m[3 * row + 1]);
    if (r.state_body_id[row] == 0) u_end = to_track(x).x();
    else end_position[r.state_body_id[row]] = x;
  }
  nlohmann::json channel = {{"beam_m", beam}};
  if (std::isfinite(u_edge) && u_end > u_edge + 1.0) {
    // The window as a polygon in the world: the strip between u_edge and u_end, as wide as the sheet could be.
    const Polygon strip = {world(u_edge, -far), world(u_end, -far), world(u_end, far), world(u_edge, far)};
    auto area_in_strip = [&](const Polygon& outline, const Vec2& at) {
      double a = 0;
      for (const Polygon& piece : polygon_intersection(placed(outline, at), strip)) a += signed_area(piece);
      return a;
    };
    double before = 0, after = 0;
    for (int b : tiles) before += area_in_strip(model.bodies[b].outline, model.bodies[b].initial_position.head<2>());
    for (size_t g = 0; g < r.floe_id.size(); ++g) {
      if (r.floe_level_ice.size() != r.floe_id.size() || !r.floe_level_ice[g]) continue;
      const auto it = end_position.find(r.floe_id[g]);
      if (it == end_position.end()) continue;  // broken up before the end
      Polygon p;
      for (int64_t i = r.floe_vertex_offset[g]; i < r.floe_vertex_offset[g + 1]; ++i)
        p.emplace_back(r.floe_vertices_m[2 * i], r.floe_vertices_m[2 * i + 1]);
      after += area_in_strip(p, it->second);
    }
    const double length = u_end - u_edge;
    channel["from_m"] = u_edge;
    channel["to_m"] = u_end;
    channel["broken_area_m2"] = before - after;
    channel["mean_width_m"] = (before - after) / length;
    channel["width_over_beam"] = (before - after) / length / beam;
  } else {
    channel["note"] = "the vessel's centre of mass did not reach the sheet: no channel behind midship yet";
  }
  j["channel"] = channel;
  // The mean surge ice resistance over the steady part, split by what the hull touched: the sheet's tiles (breaking
  // its edge: crushing until the wedges fail in bending) and the floes and broken pieces (clearing, turning and
  // submerging them, with their friction).
  if (series.steps() == 0) return j;
  const std::vector<double> t = series.get("time_s"), all = series.get("ice_load"),
                            sheet = series.get("ice_load_level_ice");
  double sum_all = 0, sum_sheet = 0, n = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    if (t[i] < model.options.steady_start_s - 0.5 * model.options.time_step_s) continue;
    sum_all -= all[6 * i];
    sum_sheet -= sheet[6 * i];
    n += 1;
  }
  if (n > 0)
    j["resistance_split"] = {{"from_s", model.options.steady_start_s},
                             {"breaking_sheet_N", sum_sheet / n},
                             {"clearing_pieces_N", (sum_all - sum_sheet) / n},
                             {"breaking_share", sum_all != 0 ? sum_sheet / sum_all : 0.0}};
  return j;
}

namespace {

// The per-step scalar series and where each comes from in the step report (the vessel's state and loads are
// written by hand: they need its pose). write_results checks that every series of the layout was recorded.
struct ScalarSeries {
  const char* name;
  double (*get)(const StepReport&);
};
constexpr ScalarSeries kScalarSeries[] = {
    {"contact_count", [](const StepReport& r) { return double(r.contacts); }},
    {"vessel_contact_count", [](const StepReport& r) { return double(r.vessel_contacts); }},
    {"solver_iterations", [](const StepReport& r) { return double(r.solve.iterations); }},
    {"solver_residual", [](const StepReport& r) { return r.solve.residual; }},
    {"awake_floes", [](const StepReport& r) { return double(r.awake_floes); }},
    {"fracture_events", [](const StepReport& r) { return double(r.fracture_events); }},
    {"floe_bodies", [](const StepReport& r) { return double(r.floe_bodies); }},
    {"solver_subspace_solves", [](const StepReport& r) { return double(r.solve.subspace_solves); }},
    {"solver_capped", [](const StepReport& r) { return r.solve.capped ? 1.0 : 0.0; }},
    {"solver_complementarity", [](const StepReport& r) { return r.solve.complementarity; }},
    {"relax_iterations", [](const StepReport& r) { return double(r.relax.iterations); }},
    {"relax_residual", [](const StepReport& r) { return r.relax.residual; }},
    {"relax_capped", [](const StepReport& r) { return r.relax.capped ? 1.0 : 0.0; }},
    {"relax_complementarity", [](const StepReport& r) { return r.relax.complementarity; }},
    {"solver_surge_load_error", [](const StepReport& r) { return r.surge_load_error_n; }},
};

// A body's id in the results layout: 0 for the vessel, its floe id otherwise.
int32_t results_id(const Body& b) { return b.kind == BodyKind::vessel ? 0 : b.id; }

// The last stored state of each body (world body-table index), so that a frame stores only the bodies that changed
// (layout /7): a sleeping field costs nothing per frame. Rebuilt from the results on resume, which hold every row
// stored so far, so a resumed run stores exactly what an uninterrupted one does.
class StoredStates {
 public:
  StoredStates(const World& w, const Results& r) {
    const Model& m = w.model();
    std::map<int32_t, size_t> index;
    for (size_t b = 0; b < m.bodies.size(); ++b)
      if (m.bodies[b].kind != BodyKind::wall) index[results_id(m.bodies[b])] = b;
    last_.resize(m.bodies.size());
    for (size_t row = 0; row < r.state_body_id.size(); ++row) {
      const auto it = index.find(r.state_body_id[row]);
      FLOESIM_REQUIRE(it != index.end(), "internal: stored state of body ", r.state_body_id[row], " not in the world");
      const double* x = &r.state_position_m[3 * row];
      const double* q = &r.state_quaternion[4 * row];
      last_[it->second] = {Vec3(x[0], x[1], x[2]), Quat(q[0], q[1], q[2], q[3]), r.state_in_contact[row], true};
    }
  }
  // True if body b is new or its pose or contact flag differs from its last stored row; then remembers this one.
  bool changed(size_t b, const Vec3& x, const Quat& q, int8_t in_contact) {
    if (b >= last_.size()) last_.resize(b + 1);  // pieces made since the last frame
    Last& l = last_[b];
    if (l.stored && l.x == x && l.q.coeffs() == q.coeffs() && l.in_contact == in_contact) return false;
    l = {x, q, in_contact, true};
    return true;
  }

 private:
  struct Last {
    Vec3 x = Vec3::Zero();
    Quat q = Quat::Identity();
    int8_t in_contact = 0;
    bool stored = false;
  };
  std::vector<Last> last_;
};

// Kinetic energy of the floes and pieces (translation and rotation, without added mass); sleeping and fixed bodies
// have none.
double ice_kinetic_energy(const World& w) {
  const Model& m = w.model();
  const State& s = w.state();
  double e = 0;
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const Body& body = m.bodies[b];
    if (body.kind != BodyKind::floe || !s.alive[b] || !s.awake[b]) continue;
    const Vec3 wb = s.orientation[b].conjugate() * s.angular_velocity[b];
    e += 0.5 * body.mass_kg * s.velocity[b].squaredNorm() + 0.5 * wb.dot(body.inertia * wb);
  }
  return e;
}

}  // namespace

Results simulate(const Model& model, RunStats& stats, std::ostream* progress, const CheckpointPlan* checkpoints) {
  FLOESIM_REQUIRE(model.vessel >= 0, "simulate: the model has no vessel");
  const SimulateOptions& o = model.options;
  const long steps = o.steps(), every = o.output_every();
  Results r;
  // Direct references to the series columns: no map look-up per step, one reservation up front (for the whole
  // run, or for one checkpoint interval when the checkpoints take the series out of memory).
  const long checkpoint_every = o.checkpoint_every();
  const bool spill = checkpoints && checkpoints->spill_series && checkpoint_every > 0;
  const long rows_held = spill ? std::min(steps, checkpoint_every) : steps;
  std::map<std::string, std::vector<double>*> col;
  for (const FieldSpec& f : series_fields()) {
    auto& v = r.series[f.name];
    v.reserve(static_cast<size_t>(rows_held) * f.cols);
    col[f.name] = &v;
  }
  auto& c_time = *col["time_s"];
  auto& c_pos = *col["vessel_position_m"];
  auto& c_quat = *col["vessel_quaternion_wxyz"];
  auto& c_vel = *col["vessel_velocity_mps"];
  auto& c_omega = *col["vessel_angular_velocity_radps"];
  auto& c_ice = *col["ice_load"];
  auto& c_ice_rigid = *col["ice_load_rigid"];
  auto& c_ice_compliant = *col["ice_load_compliant"];
  auto& c_ice_level_ice = *col["ice_load_level_ice"];
  auto& c_hydro = *col["hydro_load"];
  auto& c_wind = *col["wind_load"];
  auto& c_prop = *col["propulsion_load"];
  std::vector<std::vector<double>*> c_scalar;  // kScalarSeries' columns, looked up once
  for (const ScalarSeries& f : kScalarSeries) c_scalar.push_back(col.at(f.name));
  auto& c_kinetic = *col["ice_kinetic_energy"];
  // The states grow with the ice that moves (a frame stores only what changed: no reservation by field size).
  r.frame_offset.push_back(0);
  r.frame_time_s.reserve(static_cast<size_t>(steps / every));
  std::vector<int8_t> pressed;  // per body: pressed against the vessel in this step (frames only)

  // The world: fresh, or continued from a checkpoint (sim/checkpoint.h) with the results recorded up to it.
  RecorderSums sums;
  std::unique_ptr<Checkpointer> cp;
  std::unique_ptr<World> world;
  if (checkpoints) {
    cp = std::make_unique<Checkpointer>(checkpoints->dir, checkpoints->provenance, spill);
    if (checkpoints->resume) world = cp->resume(model, r, sums, progress);
    else cp->start_fresh(r, progress);
  }
  if (!world) world = std::make_unique<World>(model);
  if (cp) r.series_first_step = static_cast<size_t>(cp->series_steps_on_disk());
  StoredStates stored(*world, r);
  const long first = world->state().step + 1;
  stats.resumed_at_step = first - 1;

  const auto t0 = std::chrono::steady_clock::now();
  auto wall_now = [&] { return sums.wall_s + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  const int v = model.vessel;
  {
    // SIGINT/SIGTERM stop the loop between two steps (pipeline/interrupt.h); with checkpoints on, the step reached
    // is checkpointed first, so that --resume loses nothing.
    InterruptPolling polling;
    for (long k = first; k <= steps; ++k) {
      if (interrupt_signal()) {
        std::string where;
        if (cp && checkpoint_every > 0 && world->state().step > cp->last_step()) {
          sums.wall_s = wall_now();
          cp->save(*world, r, sums);
        }
        if (cp && cp->last_step() > 0) {
          std::ostringstream os;
          os << "checkpoint at t = " << world->state().time_s << " s in " << cp->dir().string()
             << ": --resume continues from it";
          where = os.str();
        }
        throw Interrupted(interrupt_signal(), where);
      }
      World& w = *world;
      w.step();
      const auto tr = std::chrono::steady_clock::now();
      const State& s = w.state();
      const StepReport& rep = w.report();
      const Mat3 R = s.orientation[v].toRotationMatrix();
      const Quat& q = s.orientation[v];
      const Vec3 vb = R.transpose() * s.velocity[v], wb = R.transpose() * s.angular_velocity[v];
      c_time.push_back(s.time_s);
      c_pos.insert(c_pos.end(), {s.position[v].x(), s.position[v].y(), s.position[v].z()});
      c_quat.insert(c_quat.end(), {q.w(), q.x(), q.y(), q.z()});
      c_vel.insert(c_vel.end(), {vb.x(), vb.y(), vb.z()});
      c_omega.insert(c_omega.end(), {wb.x(), wb.y(), wb.z()});
      push_body_wrench(c_ice, R, rep.ice_load);
      push_body_wrench(c_ice_rigid, R, rep.ice_load_rigid);
      push_body_wrench(c_ice_compliant, R, rep.ice_load_compliant);
      push_body_wrench(c_ice_level_ice, R, rep.ice_load_level_ice);
      push_body_wrench(c_hydro, R, rep.hydro_load);
      push_body_wrench(c_wind, R, rep.wind_load);
      push_body_wrench(c_prop, R, rep.propulsion_load);
      for (size_t i = 0; i < c_scalar.size(); ++i) c_scalar[i]->push_back(kScalarSeries[i].get(rep));
      c_kinetic.push_back(ice_kinetic_energy(w));
      sums.awake += rep.awake_floes;
      sums.contacts += rep.contacts;
      sums.iterations += rep.solve.iterations;
      sums.pairs += w.collision_stats().broadphase_pairs;
      sums.touching += w.collision_stats().narrowphase_hits;
      sums.edges += w.collision_stats().edge_contacts;
      sums.crushing += w.collision_stats().crushing_contacts;
      // Frames at t = k * output_interval (k >= 1): the vessel and the bodies that are new or changed since they
      // were last stored (layout /7), vessel first (body id 0), pieces in the order they were made.
      if (k % every == 0) {
        r.frame_time_s.push_back(s.time_s);
        const Model& wm = w.model();
        // Floes the vessel pressed on in this step: a vessel contact that carried a normal impulse (speculative
        // contacts that stayed open carry none). Read only: the results stay what they were without this.
        pressed.assign(wm.bodies.size(), 0);
        for (const Contact& c : w.contacts())
          if (c.pn > 0 && (c.body_a == v || c.body_b == v)) pressed[size_t(c.body_a == v ? c.body_b : c.body_a)] = 1;
        for (size_t b = 0; b < wm.bodies.size(); ++b) {
          const Body& body = wm.bodies[b];
          if (body.kind == BodyKind::wall || !s.alive[b]) continue;  // walls are fixed: not in the results layout
          if (!stored.changed(b, s.position[b], s.orientation[b], pressed[b]) && body.kind != BodyKind::vessel)
            continue;
          r.state_body_id.push_back(results_id(body));
          const Vec3& x = s.position[b];
          const Quat& qb = s.orientation[b];
          r.state_position_m.insert(r.state_position_m.end(), {x.x(), x.y(), x.z()});
          r.state_quaternion.insert(r.state_quaternion.end(), {qb.w(), qb.x(), qb.y(), qb.z()});
          r.state_in_contact.push_back(pressed[b]);
        }
        r.frame_offset.push_back(static_cast<int64_t>(r.state_body_id.size()));
      }
      sums.record_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - tr).count();
      // A checkpoint every checkpoint_interval_s of simulated time (not after the last step: the results follow).
      if (cp && checkpoint_every > 0 && k % checkpoint_every == 0 && k < steps) {
        const double before = sums.wall_s;
        sums.wall_s = wall_now();
        const auto tc = std::chrono::steady_clock::now();
        cp->save(w, r, sums);
        stats.checkpoint_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
        ++stats.checkpoints;
        sums.wall_s = before;
      }
      if (progress && (k * 10) % steps < 10 && k != steps) {
        *progress << "  t = " << std::fixed << std::setprecision(1) << s.time_s << " s  (" << (k * 100) / steps
                  << " %, " << std::setprecision(1) << wall_now() << " s wall, awake floes " << rep.awake_floes
                  << ", contacts " << rep.contacts << ")" << std::defaultfloat << std::endl;
      }
    }
  }
  const World& world_end = *world;
  stats.wall_s = wall_now();
  for (int i = 0; i < kStageCount; ++i) stats.stage_s[i] = world_end.stage_seconds()[i];
  stats.stage_s[kStageCount] = sums.record_s;
  stats.steps = steps;
  stats.mean_awake_floes = sums.awake / steps;
  stats.mean_contacts = sums.contacts / steps;
  stats.mean_iterations = sums.iterations / steps;
  stats.mean_pairs = sums.pairs / steps;
  stats.mean_touching = sums.touching / steps;
  stats.mean_edge_pairs = sums.edges / steps;
  stats.mean_crushing_pairs = sums.crushing / steps;

  // Geometry: the outline of every floe that ever existed (pieces included) in its body frame, with its thickness
  // and lineage; the hull surface in the vessel body frame.
  const Model& wm = world_end.model();
  r.floe_vertex_offset.push_back(0);
  for (size_t k = 0; k < wm.bodies.size(); ++k) {
    const Body& b = wm.bodies[k];
    if (b.kind != BodyKind::floe) continue;
    r.floe_id.push_back(b.id);
    r.floe_thickness_m.push_back(b.thickness_m);
    r.floe_level_ice.push_back(b.fixed ? 1 : 0);
    for (const Vec2& p : b.outline) r.floe_vertices_m.insert(r.floe_vertices_m.end(), {p.x(), p.y()});
    r.floe_vertex_offset.push_back(static_cast<int64_t>(r.floe_vertices_m.size() / 2));
    r.floe_parent_id.push_back(b.parent_id);
    r.floe_generation.push_back(b.generation);
    r.floe_origin_mode.push_back(b.origin_mode);
    r.floe_created_s.push_back(b.created_s);
    r.floe_ended_s.push_back(world_end.ended_s()[k]);
  }
  record_fracture_events(world_end.fracture_events(), r);
  const TriMesh& hull = model.bodies[v].buoyancy_mesh;
  for (const Vec3& p : hull.vertices) r.hull_vertices_m.insert(r.hull_vertices_m.end(), {p.x(), p.y(), p.z()});
  for (const auto& t : hull.triangles) r.hull_triangles.insert(r.hull_triangles.end(), {t[0], t[1], t[2]});

  r.attributes["time_step_s"] = o.time_step_s;
  r.attributes["duration_s"] = o.duration_s;
  r.attributes["output_interval_s"] = o.output_interval_s;
  r.attributes["steady_start_s"] = o.steady_start_s;
  r.attributes["contact_model"] = vessel_contact_model(model, r);
  r.attributes["contact_ice_structure"] = o.contact.ice_structure;
  r.attributes["contact_ice_ice"] = o.contact.ice_ice;
  r.attributes["frames_at"] = "t = k * output_interval_s, k = 1 .. duration_s / output_interval_s";
  return r;
}

namespace {

// How well the contact solver did over the whole run (every step, not only the steady part: an unconverged step
// during the start-up is as wrong as any other), for the solve and for the relax pass whose impulses are the
// recorded loads.
nlohmann::json solver_summary(const SolverOptions& o, const SeriesSource& series) {
  auto pass = [&](const char* prefix) {
    const std::string p = prefix;
    const std::vector<double> sweeps = series.get(p + "_iterations"), resid = series.get(p + "_residual"),
                              capped = series.get(p + "_capped"), viol = series.get(p + "_complementarity");
    const size_t n = sweeps.size();
    double sum = 0, most = 0, rmax = 0, ncap = 0, vmax = 0, vsum = 0;
    for (size_t i = 0; i < n; ++i) {
      sum += sweeps[i];
      most = std::max(most, sweeps[i]);
      rmax = std::max(rmax, resid[i]);
      ncap += capped[i];
      vmax = std::max(vmax, viol[i]);
      vsum += viol[i];
    }
    const double d = std::max<double>(1, static_cast<double>(n));
    return nlohmann::json{{"mean_sweeps", sum / d},
                          {"max_sweeps", most},
                          {"max_residual_mps", rmax},
                          {"capped_step_fraction", ncap / d},
                          {"max_complementarity_mps", vmax},
                          {"mean_complementarity_mps", vsum / d}};
  };
  nlohmann::json j = pass("solver");
  const std::vector<double> sub = series.get("solver_subspace_solves");
  double subs = 0;
  for (double x : sub) subs += x;
  j["method"] = o.method;
  j["sweep_cap"] = o.iterations;
  j["tolerance_mps"] = o.tolerance_mps;
  j["subspace_solves_per_step"] = subs / std::max<double>(1, static_cast<double>(sub.size()));
  j["relax"] = pass("relax");
  return j;
}

}  // namespace

nlohmann::json summarize(const Model& model, const Results& r) { return summarize(model, r, ResultsSeries(r)); }

nlohmann::json summarize(const Model& model, const Results& r, const SeriesSource& series) {
  const SimulateOptions& o = model.options;
  // Steady part: rows with t >= steady_start_s (within half a step).
  const size_t steps = series.steps();
  size_t first = 0;
  {
    const std::vector<double> t = series.get("time_s");
    while (first < steps && t[first] < o.steady_start_s - 0.5 * o.time_step_s) ++first;
  }
  // One series in memory at a time (a long run's are read back from disk): column 0 of `name` summed over the
  // steady part.
  auto steady_sum = [&](const char* name) {
    const std::vector<double> x = series.get(name);
    const size_t cols = static_cast<size_t>(series_field(name).cols);
    double sum = 0;
    for (size_t i = first; i < steps; ++i) sum += x[cols * i];
    return sum;
  };
  std::vector<double> fx;  // the surge ice load over the steady part
  {
    const std::vector<double> ice = series.get("ice_load");
    for (size_t i = first; i < steps; ++i) fx.push_back(ice[6 * i]);
  }
  const double fx_rigid = steady_sum("ice_load_rigid"), fx_compliant = steady_sum("ice_load_compliant");
  const double speed = steady_sum("vessel_velocity_mps"), thrust = steady_sum("propulsion_load");
  const double aw = steady_sum("awake_floes"), co = steady_sum("contact_count"), vc = steady_sum("vessel_contact_count");
  const double n = static_cast<double>(fx.size());
  FLOESIM_REQUIRE(n > 0, "internal: no steady samples");
  double mean = 0;
  for (double x : fx) mean += x;
  mean /= n;
  double var = 0;
  for (double x : fx) var += (x - mean) * (x - mean);
  const double sd = std::sqrt(var / n);

  nlohmann::json s;
  s["mean_surge_ice_load_N"] = mean;
  s["mean_surge_ice_resistance_N"] = -mean;
  s["std_surge_ice_load_N"] = sd;
  // The same mean split by contact law (they add up to the mean above).
  s["mean_surge_ice_load_rigid_N"] = fx_rigid / n;
  s["mean_surge_ice_load_compliant_N"] = fx_compliant / n;
  const std::string model_kind = r.attributes.value("contact_model", o.contact.ice_structure);
  s["steady_part"] = {{"from_s", o.steady_start_s}, {"to_s", o.duration_s}, {"samples", fx.size()}};
  nlohmann::json windows = nlohmann::json::array();
  for (double w : {kCompliantWindowS, kRigidWindowS}) {
    const size_t nw = static_cast<size_t>(std::lround(w / o.time_step_s));
    const std::vector<double> ma = moving_average_full_windows(fx, nw);
    const std::string kind = w == kRigidWindowS ? "rigid" : "compliant";
    nlohmann::json j = {{"window_s", w}, {"samples", nw}, {"kind", kind},
                        // the window the seed uses for this run's vessel contacts (rigid: 20 s, else 0.5 s)
                        {"applies", (model_kind == "rigid") == (kind == "rigid")}};
    if (ma.empty()) {
      j["note"] = "the steady part is shorter than the window";
      j["max_N"] = nullptr;
      j["min_N"] = nullptr;
      j["max_resistance_N"] = nullptr;
      j["std_N"] = nullptr;
    } else {
      const auto [lo, hi] = std::minmax_element(ma.begin(), ma.end());
      j["max_N"] = *hi;
      j["min_N"] = *lo;
      j["max_resistance_N"] = -*lo;  // the largest filtered resistance (most negative surge load)
      double m = 0, v2 = 0;
      for (double x : ma) m += x;
      m /= static_cast<double>(ma.size());
      for (double x : ma) v2 += (x - m) * (x - m);
      j["std_N"] = std::sqrt(v2 / static_cast<double>(ma.size()));  // spread of the filtered signal
    }
    windows.push_back(j);
  }
  s["moving_average_surge_ice_load"] = windows;
  s["contact_model"] = model_kind;
  s["contact_laws"] = {{"ice_structure", o.contact.ice_structure}, {"ice_ice", o.contact.ice_ice}};
  s["mean_vessel_speed_mps"] = speed / n;
  s["mean_thrust_N"] = thrust / n;
  s["mean_awake_floes"] = aw / n;
  s["mean_contacts"] = co / n;
  s["mean_vessel_contacts"] = vc / n;
  s["solver"] = solver_summary(o.solver, series);
  // What the solver's settings change in the mean load (solver.reference): recorded minus the reference, over the
  // steady part, against the mean surge ice load.
  const bool reference = o.solver.reference != "off";
  const std::vector<double> err = reference ? series.get("solver_surge_load_error") : std::vector<double>();
  if (reference && err.size() == steps) {
    double e = 0, ea = 0, emax = 0;
    for (size_t i = first; i < steps; ++i) {
      e += err[i];
      ea += std::abs(err[i]);
      emax = std::max(emax, std::abs(err[i]));
    }
    nlohmann::json& j = s["solver"]["surge_load_error"];
    j = {{"reference", o.solver.reference},
         {"reference_sweeps", o.solver.reference_sweeps},
         {"horizon_s", o.solver.reference_horizon_s},
         {"mean_N", e / n},
         {"mean_abs_N", ea / n},
         {"max_abs_N", emax},
         {"mean_over_mean_load", mean != 0 ? (e / n) / mean : 0.0}};
    // With a branch: each whole window inside the steady part gives one mean difference. The windows start from
    // the run's own trajectory on fresh copies, so their differences scatter about the setting's effect nearly
    // independently: their standard error says how well the run pins the effect.
    const size_t h = static_cast<size_t>(o.reference_horizon_steps());
    if (h > 0) {
      std::vector<double> wm;
      for (size_t k = (first + h - 1) / h; (k + 1) * h <= steps; ++k) {
        double sum = 0;
        for (size_t i = k * h; i < (k + 1) * h; ++i) sum += err[i];
        wm.push_back(sum / static_cast<double>(h));
      }
      double m = 0, v2 = 0;
      for (double x : wm) m += x;
      if (!wm.empty()) m /= static_cast<double>(wm.size());
      for (double x : wm) v2 += (x - m) * (x - m);
      const double se = wm.size() > 1 ? std::sqrt(v2 / static_cast<double>(wm.size() - 1) / wm.size()) : 0.0;
      j["windows"] = wm.size();
      j["window_mean_N"] = m;
      j["window_se_N"] = wm.size() > 1 ? nlohmann::json(se) : nlohmann::json(nullptr);
      j["window_mean_over_mean_load"] = mean != 0 ? m / mean : 0.0;
    }
  }
  s["steps"] = steps;
  s["frames"] = r.frames();
  s["floes"] = model.floe_count();
  s["removed_floes"] = model.removed_floe_ids.size();
  s["removed_floe_ids"] = model.removed_floe_ids;
  s["small_floe_overlaps"] = model.small_overlaps;
  s["fracture"] = fracture_summary(o, r);
  s["level_ice"] = level_ice_summary(model, r, series);
  const VesselParticulars& vp = model.vessel_info;
  s["vessel"] = {{"mass_kg", vp.mass_kg},
                 {"length_oa_m", vp.length_oa_m},
                 {"length_wl_m", vp.length_wl_m},
                 {"beam_wl_m", vp.beam_wl_m},
                 {"draught_m", vp.draught_m},
                 {"displacement_m3", vp.displacement_m3},
                 {"wetted_surface_m2", vp.wetted_surface_m2},
                 {"gm_transverse_m", vp.gm_transverse_m},
                 {"gm_longitudinal_m", vp.gm_longitudinal_m},
                 {"radii_of_gyration_m", {vp.radii_of_gyration_m.x(), vp.radii_of_gyration_m.y(),
                                          vp.radii_of_gyration_m.z()}},
                 {"open_water_resistance_at_target_N",
                  ittc57_resistance(o.vessel.propulsion.speed_mps, vp, o)}};
  return s;
}

std::string run_simulate(const fs::path& floes_file, const fs::path& hull_file, const fs::path& config_file,
                         const fs::path& out_dir, bool resume) {
  // 1. Inputs: options (strict), thrust series path relative to the config file, floes, hull.
  const Json cfg = load_json_file(config_file);
  SimulateOptions o = read_options<SimulateOptions>(cfg, config_file.string());
  std::vector<NamedInput> inputs = {{"floes", floes_file}, {"hull", hull_file}, {"config", config_file}};
  if (o.vessel.propulsion.mode == "thrust_series") {
    fs::path tf = o.vessel.propulsion.thrust_file;
    if (tf.is_relative()) tf = config_file.parent_path() / tf;
    o.vessel.propulsion.thrust_file = tf.string();
    inputs.push_back({"thrust_series", tf});
  }
  const FloeField field = read_floes(floes_file);
  const HullModel hull = load_hull(hull_file, o.hull);
  try {  // the stage floats the hull as the file has it: one entirely above or below the water is a placement error
    require_floating(hull, hull_file.string());
  } catch (const Error& e) {
    throw Error(std::string(e.what()) + ". floesim-simulate takes the hull frame as the file has it (bow +x, "
                "waterline z = 0): place a CAD mesh with the hull options (case \"hull\": {\"file\", \"waterline_z_m\", "
                "\"up_direction\", \"bow_direction\", \"scale\"}, or floesim-hull) first");
  }
  const Model model = build_model(field, &hull, o);

  std::ostringstream out;
  out << "floesim-simulate: " << model.floe_count() << " floes in " << model.parts.size() << " convex parts ("
      << model.removed_floe_ids.size()
      << " removed: they overlapped the vessel's initial footprint";
  if (model.small_overlaps) out << "; " << model.small_overlaps << " small floe-floe overlaps left to the solver";
  out << "), vessel ";
  if (model.vessel_info.mass_kg < 1e4) out << std::lround(model.vessel_info.mass_kg) << " kg";  // a tank model
  else out << model.vessel_info.mass_kg / 1e3 << " t";
  out << ", L_wl " << model.vessel_info.length_wl_m
      << " m, GM_T " << model.vessel_info.gm_transverse_m << " m\n";
  std::cout << out.str() << std::flush;

  // 2. Simulate (throws on numerical failure: nothing is written), with checkpoints in out_dir/checkpoint. The
  // output folder is checked first: a run of hours must not end at a folder it cannot write.
  ensure_directory(out_dir);
  const Json prov = make_provenance("floesim-simulate", inputs, options_to_json(o));
  CheckpointPlan checkpoints;
  checkpoints.dir = out_dir / "checkpoint";
  checkpoints.provenance = prov;
  checkpoints.resume = resume;
  checkpoints.spill_series = true;
  RunStats stats;
  Results results = simulate(model, stats, &std::cout, &checkpoints);
  results.attributes["provenance"] = prov;
  // The series before the last checkpoint are read back from its chunks, one at a time.
  const CheckpointSeries series(checkpoints.dir, prov, static_cast<long>(results.series_first_step), results);
  nlohmann::json summary = summarize(model, results, series);
  summary["settings"] = options_to_json(o);
  summary["provenance"] = prov;

  // 3. Artefacts, atomically; then the checkpoint has served.
  write_results(out_dir / "results.h5", results, series);
  write_text_atomic(out_dir / "summary.json", summary.dump(2) + "\n");
  remove_checkpoint(checkpoints.dir);

  // 4. The report (wall time lives here, not in the artefacts).
  std::ostringstream rep;
  const double ms = 1e3 * stats.wall_s / stats.steps;
  rep << std::fixed << std::setprecision(2);
  rep << "floes " << model.floe_count() << ", steps " << stats.steps << ", wall " << stats.wall_s << " s, "
      << ms << " ms/step, " << o.duration_s / stats.wall_s << " simulated s per wall s\n";
  if (stats.resumed_at_step > 0)
    rep << "resumed at step " << stats.resumed_at_step << " (t = " << stats.resumed_at_step * o.time_step_s
        << " s); the wall time includes the run before\n";
  if (stats.checkpoints > 0)
    rep << stats.checkpoints << " checkpoints written (every " << o.checkpoint_interval_s << " s of simulated time), "
        << 1e3 * stats.checkpoint_s / stats.checkpoints << " ms each on average\n";
  rep << "mean awake floes " << stats.mean_awake_floes << ", mean contacts " << stats.mean_contacts
      << ", mean solver sweeps " << stats.mean_iterations << "\n";
  rep << "mean part pairs per step: " << stats.mean_pairs << " from the broad phase, " << stats.mean_touching
      << " touching (" << stats.mean_edge_pairs << " edge-on-edge, single point; " << stats.mean_crushing_pairs
      << " crushing, two rows)\n";
  rep << "stage times (ms/step):";
  for (int i = 0; i <= kStageCount; ++i)
    rep << " " << (i < kStageCount ? stage_name(i) : "record") << " " << std::setprecision(3)
        << 1e3 * stats.stage_s[i] / stats.steps;
  rep << "\n" << std::setprecision(1);
  {  // in the unit that suits the loads' size: N for a tank model, kN for a ship
    const double load_n = summary["mean_surge_ice_load_N"].get<double>();
    const ForceUnit u = force_unit_for(load_n);
    rep << "mean surge ice load " << load_text(load_n, u) << " (resistance "
        << load_text(summary["mean_surge_ice_resistance_N"].get<double>(), u) << ")";
  }
  rep << " from t = " << o.steady_start_s
      << " s, mean speed " << std::setprecision(3) << summary["mean_vessel_speed_mps"].get<double>() << " m/s\n";
  const nlohmann::json& fr = summary["fracture"];
  if (fr["enabled"].get<bool>())
    rep << "fracture: " << fr["events"]["total"] << " events (bending " << fr["events"]["bending"] << ", radial "
        << fr["events"]["radial"] << ", splitting " << fr["events"]["splitting"] << "), " << fr["pieces_created"]
        << " pieces, " << std::setprecision(4) << fr["brash_removed_kg"].get<double>() / 1e3
        << " t of brash removed\n";
  rep << "wrote " << (out_dir / "results.h5").string() << " (" << std::setprecision(1)
      << std::filesystem::file_size(out_dir / "results.h5") / 1e6 << " MB, " << results.state_body_id.size()
      << " stored body states in " << results.frames() << " frames) and " << (out_dir / "summary.json").string()
      << "\n";
  // Peak resident memory of this process (getrusage: kB on Linux), for sizing long runs and cluster jobs.
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) == 0) rep << "peak memory " << usage.ru_maxrss / 1024.0 << " MB\n";
  return rep.str();
}

}  // namespace floesim::sim
