#include "sim/simulate/recorder.h"

#include <chrono>

#include "pipeline/error.h"

namespace floesim::sim {

namespace {

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
  return model.settings.contact.ice_structure;
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

// The per-step wrench series (six columns each, body axes) and the load of the step report each comes from.
struct LoadSeries {
  const char* name;
  const Wrench& (*load)(const StepReport&);
};
constexpr LoadSeries kLoadSeries[] = {
    {"ice_load", [](const StepReport& r) -> const Wrench& { return r.ice_load; }},
    {"ice_load_rigid", [](const StepReport& r) -> const Wrench& { return r.ice_load_rigid; }},
    {"ice_load_compliant", [](const StepReport& r) -> const Wrench& { return r.ice_load_compliant; }},
    {"ice_load_level_ice", [](const StepReport& r) -> const Wrench& { return r.ice_load_level_ice; }},
    {"ice_load_ridge_rubble", [](const StepReport& r) -> const Wrench& { return r.ridge_load.rubble; }},
    {"ice_load_ridge_layer", [](const StepReport& r) -> const Wrench& { return r.ridge_load.layer; }},
    {"ice_load_ridge_keel", [](const StepReport& r) -> const Wrench& { return r.ridge_load.keel; }},
    {"hydro_load", [](const StepReport& r) -> const Wrench& { return r.hydro_load; }},
    {"wind_load", [](const StepReport& r) -> const Wrench& { return r.wind_load; }},
    {"propulsion_load", [](const StepReport& r) -> const Wrench& { return r.propulsion_load; }},
};

// A body's id in the results layout: 0 for the vessel, its floe id otherwise.
int32_t results_id(const Body& b) { return b.kind == BodyKind::vessel ? 0 : b.id; }

// A structure beside the vessel: recorded under /structures, not in the frames.
bool is_structure(const Model& m, size_t b) {
  return static_cast<int>(b) < m.hull_count() && static_cast<int>(b) != m.vessel;
}

// A structure recorded under /structures: the case's hull body when it is held (named "vessel"), then each structure
// beside it (Model::structures, under its own name).
struct RecordedStructure {
  std::string name;
  int body = -1;
  int index = -1;  // into Model::structures and StepReport::structures; -1: the vessel's hull body
  const StationKeepingOptions* keeping = nullptr;
  const Station* station = nullptr;
  double waterline_width_m = 0;
};

std::vector<RecordedStructure> recorded_structures(const SimulateOptions& o, const Model& m) {
  std::vector<RecordedStructure> list;
  if (m.vessel >= 0 && o.vessel.station_keeping.held())
    list.push_back({"vessel", m.vessel, -1, &o.vessel.station_keeping, &m.station, m.vessel_info.beam_wl_m});
  for (size_t k = 0; k < m.structures.size(); ++k)
    list.push_back({o.structures[k].name, m.structures[k].body, static_cast<int>(k),
                    &o.structures[k].body.station_keeping, &m.structures[k].station,
                    m.structures[k].info.beam_wl_m});
  return list;
}

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

// The last stored state of each body (world body-table index), so that a frame stores only the bodies that changed
// (layout /7): a sleeping field costs nothing per frame. Rebuilt from the results on resume, which hold every row
// stored so far, so a resumed run stores exactly what an uninterrupted one does.
class Recorder::StoredStates {
 public:
  StoredStates(const World& w, const Results& r) {
    const Model& m = w.model();
    std::map<int32_t, size_t> index;
    for (size_t b = 0; b < m.bodies.size(); ++b)
      if (m.bodies[b].kind != BodyKind::wall && !is_structure(m, b)) index[results_id(m.bodies[b])] = b;
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


Recorder::Recorder(const SimulateOptions& o, const Model& model, Results& r, long rows_held)
    : o_(o), r_(r), every_(o.output_every()) {
  // One reservation up front (for the whole run, or for one checkpoint interval when the checkpoints take the
  // series out of memory).
  std::map<std::string, std::vector<double>*> col;
  for (const FieldSpec& f : series_fields()) {
    auto& v = r.series[f.name];
    v.reserve(static_cast<size_t>(rows_held) * f.cols);
    col[f.name] = &v;
  }
  c_time_ = col.at("time_s");
  c_pos_ = col.at("vessel_position_m");
  c_quat_ = col.at("vessel_quaternion_wxyz");
  c_vel_ = col.at("vessel_velocity_mps");
  c_omega_ = col.at("vessel_angular_velocity_radps");
  c_kinetic_ = col.at("ice_kinetic_energy");
  c_offset_ = col.at("station_offset");
  c_demanded_ = col.at("station_keeping_demanded");
  c_delivered_ = col.at("station_keeping_delivered");
  for (const LoadSeries& f : kLoadSeries) c_loads_.push_back(col.at(f.name));
  for (const ScalarSeries& f : kScalarSeries) c_scalar_.push_back(col.at(f.name));
  // The states grow with the ice that moves (a frame stores only what changed: no reservation by field size).
  r.frame_offset.push_back(0);
  r.frame_time_s.reserve(static_cast<size_t>(o.steps() / every_));
  add_structures(model);
}

Recorder::~Recorder() = default;

void Recorder::attach(const World& w) { stored_ = std::make_unique<StoredStates>(w, r_); }

void Recorder::add_structures(const Model& m) {
  // The structures' series (kept whole: a checkpoint carries them as it does the frames) and their list.
  nlohmann::json list = nlohmann::json::array();
  c_structures_.clear();
  for (const RecordedStructure& rs : recorded_structures(o_, m)) {
    const int parts = m.bodies[rs.body].part_count;
    nlohmann::json columns = nlohmann::json::object();
    std::vector<std::vector<double>*> c;
    for (const StructureField& f : structure_fields()) {
      const std::string field = f.name;
      size_t cols = 3;
      if (field == "quaternion_wxyz") cols = 4;
      if (field == "line_tension_n") cols = rs.keeping->lines.size();  // none: no field
      if (field == "part_force_n") cols = 3 * static_cast<size_t>(parts);
      if (cols == 0) {
        c.push_back(nullptr);
        continue;
      }
      columns[field] = cols;
      std::vector<double>& v = r_.structure_series[rs.name + "/" + field];
      v.reserve(static_cast<size_t>(o_.steps()) * cols);
      c.push_back(&v);
    }
    c_structures_.push_back(std::move(c));
    const Station& st = *rs.station;
    list.push_back({{"name", rs.name},
                    {"body", rs.index < 0 ? "vessel" : "structure"},
                    {"kind", rs.keeping->mode},
                    {"reference_point_body_m", {st.reference_point_body.x(), st.reference_point_body.y(),
                                                st.reference_point_body.z()}},
                    {"station_m", {st.position.x(), st.position.y(), st.position.z()}},
                    {"station_heading_deg", st.heading_rad * 180 / kPi},
                    {"waterline_width_m", rs.waterline_width_m},
                    {"parts", parts},
                    {"run_frame_velocity_mps", {m.frame_velocity.x(), m.frame_velocity.y(), m.frame_velocity.z()}},
                    {"columns", columns}});
  }
  if (!list.empty()) r_.attributes["structures"] = list;
}

void Recorder::record_structures(const World& w) {
  const Model& m = w.model();
  const State& s = w.state();
  const StepReport& rep = w.report();
  size_t at = 0;
  for (const RecordedStructure& rs : recorded_structures(o_, m)) {
    const int b = rs.body;
    // The vessel's hull body reports its loads as the vessel's; a structure beside it in its own report.
    const StructureReport* sr = rs.index >= 0 ? &rep.structures[rs.index] : nullptr;
    const Wrench& ice = sr ? sr->ice_load : rep.ice_load;
    const Wrench& level_ice = sr ? sr->ice_load_level_ice : rep.ice_load_level_ice;
    const RidgeLoad& ridge = sr ? sr->ridge_load : rep.ridge_load;
    const Wrench& water = sr ? sr->hydro_load : rep.hydro_load;
    const Wrench& keeping = sr ? sr->station_keeping_load : rep.propulsion_load;
    const StationKeeping& sk = sr ? sr->station_keeping : rep.station_keeping;
    const std::vector<Vec3>& parts = sr ? sr->part_force_n : rep.vessel_part_force_n;
    const Vec3 x = s.position[b] + s.time_s * m.frame_velocity;  // earth frame
    const Vec3 v = s.velocity[b] + m.frame_velocity;
    const Quat& q = s.orientation[b];
    const Vec3 ref = q * rs.station->reference_point_body;  // from the centre of mass
    const Vec3 moment = ice.torque - ref.cross(ice.force);
    std::vector<std::vector<double>*>& c = c_structures_[at++];
    size_t i = 0;
    auto put = [&](std::initializer_list<double> row) {
      if (c[i]) c[i]->insert(c[i]->end(), row);
      ++i;
    };
    put({x.x(), x.y(), x.z()});
    put({q.w(), q.x(), q.y(), q.z()});
    put({v.x(), v.y(), v.z()});
    put({ice.force.x(), ice.force.y(), ice.force.z()});
    put({moment.x(), moment.y(), moment.z()});
    put({level_ice.force.x(), level_ice.force.y(), level_ice.force.z()});
    put({ridge.rubble.force.x(), ridge.rubble.force.y(), ridge.rubble.force.z()});
    put({ridge.layer.force.x(), ridge.layer.force.y(), ridge.layer.force.z()});
    put({ridge.keel.force.x(), ridge.keel.force.y(), ridge.keel.force.z()});
    put({water.force.x(), water.force.y(), water.force.z()});
    put({keeping.force.x(), keeping.force.y(), keeping.force.z()});
    put({sk.offset.x(), sk.offset.y(), sk.heading_change_rad});
    put({sk.demanded[0], sk.demanded[1], sk.demanded[2]});
    put({sk.delivered[0], sk.delivered[1], sk.delivered[2]});
    if (c[i]) {  // line tensions (a moored structure's, every step)
      FLOESIM_REQUIRE(sk.line_tension_n.size() == rs.keeping->lines.size(), "internal: structure ", rs.name,
                      " reported ", sk.line_tension_n.size(), " line tensions");
      c[i]->insert(c[i]->end(), sk.line_tension_n.begin(), sk.line_tension_n.end());
    }
    ++i;
    FLOESIM_REQUIRE(parts.size() == static_cast<size_t>(m.bodies[b].part_count), "internal: structure ", rs.name,
                    " reported the forces of ", parts.size(), " parts");
    for (const Vec3& f : parts) c[i]->insert(c[i]->end(), {f.x(), f.y(), f.z()});
  }
}

void Recorder::record_step(const World& w, long k) {
  const auto t0 = std::chrono::steady_clock::now();
  const int v = w.model().vessel;
  const State& s = w.state();
  const StepReport& rep = w.report();
  // 1. The series row: the vessel's state (body axes), the loads on it (body axes), the step's scalars.
  const Mat3 R = s.orientation[v].toRotationMatrix();
  const Quat& q = s.orientation[v];
  const Vec3 vb = R.transpose() * s.velocity[v], wb = R.transpose() * s.angular_velocity[v];
  c_time_->push_back(s.time_s);
  c_pos_->insert(c_pos_->end(), {s.position[v].x(), s.position[v].y(), s.position[v].z()});
  c_quat_->insert(c_quat_->end(), {q.w(), q.x(), q.y(), q.z()});
  c_vel_->insert(c_vel_->end(), {vb.x(), vb.y(), vb.z()});
  c_omega_->insert(c_omega_->end(), {wb.x(), wb.y(), wb.z()});
  for (size_t i = 0; i < c_loads_.size(); ++i) push_body_wrench(*c_loads_[i], R, kLoadSeries[i].load(rep));
  for (size_t i = 0; i < c_scalar_.size(); ++i) c_scalar_[i]->push_back(kScalarSeries[i].get(rep));
  c_kinetic_->push_back(ice_kinetic_energy(w));
  const StationKeeping& sk = rep.station_keeping;
  c_offset_->insert(c_offset_->end(), {sk.offset.x(), sk.offset.y(), sk.heading_change_rad});
  c_demanded_->insert(c_demanded_->end(), {sk.demanded[0], sk.demanded[1], sk.demanded[2]});
  c_delivered_->insert(c_delivered_->end(), {sk.delivered[0], sk.delivered[1], sk.delivered[2]});
  record_structures(w);
  // 2. The run's sums.
  sums_.awake += rep.awake_floes;
  sums_.awake_rubble += rep.awake_rubble;
  sums_.contacts += rep.contacts;
  sums_.iterations += rep.solve.iterations;
  sums_.pairs += w.collision_stats().broadphase_pairs;
  sums_.touching += w.collision_stats().narrowphase_hits;
  sums_.edges += w.collision_stats().edge_contacts;
  sums_.crushing += w.collision_stats().crushing_contacts;
  // 3. Frames at t = k * output_interval (k >= 1): the vessel and the bodies that are new or changed since they
  // were last stored (layout /7), vessel first (body id 0), pieces in the order they were made.
  if (k % every_ == 0) {
    r_.frame_time_s.push_back(s.time_s);
    const Model& wm = w.model();
    // Floes the vessel pressed on in this step: a vessel contact that carried a normal impulse (speculative
    // contacts that stayed open carry none). Read only: the results stay what they were without this.
    pressed_.assign(wm.bodies.size(), 0);
    for (const Contact& c : w.contacts())
      if (c.pn > 0 && (c.body_a == v || c.body_b == v)) pressed_[size_t(c.body_a == v ? c.body_b : c.body_a)] = 1;
    for (size_t b = 0; b < wm.bodies.size(); ++b) {
      const Body& body = wm.bodies[b];
      // Walls are fixed: not in the results layout; the structures are in /structures.
      if (body.kind == BodyKind::wall || !s.alive[b] || is_structure(wm, b)) continue;
      if (!stored_->changed(b, s.position[b], s.orientation[b], pressed_[b]) && body.kind != BodyKind::vessel)
        continue;
      r_.state_body_id.push_back(results_id(body));
      const Vec3& x = s.position[b];
      const Quat& qb = s.orientation[b];
      r_.state_position_m.insert(r_.state_position_m.end(), {x.x(), x.y(), x.z()});
      r_.state_quaternion.insert(r_.state_quaternion.end(), {qb.w(), qb.x(), qb.y(), qb.z()});
      r_.state_in_contact.push_back(pressed_[b]);
    }
    r_.frame_offset.push_back(static_cast<int64_t>(r_.state_body_id.size()));
  }
  sums_.record_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void Recorder::finish(const World& w) {
  Results& r = r_;
  // Geometry: the outline of every floe that ever existed (pieces included) in its body frame, with its thickness
  // and lineage; the hull surface in the vessel body frame.
  const Model& wm = w.model();
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
    r.floe_ended_s.push_back(w.ended_s()[k]);
  }
  record_fracture_events(w.fracture_events(), r);
  const TriMesh& hull = wm.bodies[wm.vessel].buoyancy_mesh;
  for (const Vec3& p : hull.vertices) r.hull_vertices_m.insert(r.hull_vertices_m.end(), {p.x(), p.y(), p.z()});
  for (const auto& t : hull.triangles) r.hull_triangles.insert(r.hull_triangles.end(), {t[0], t[1], t[2]});
  for (const RecordedStructure& rs : recorded_structures(o_, wm)) {
    const TriMesh& mesh = wm.bodies[rs.body].buoyancy_mesh;
    std::vector<double>& v = r.structure_hull_vertices_m[rs.name];
    std::vector<int32_t>& t = r.structure_hull_triangles[rs.name];
    v.clear();
    t.clear();
    for (const Vec3& p : mesh.vertices) v.insert(v.end(), {p.x(), p.y(), p.z()});
    for (const auto& tri : mesh.triangles) t.insert(t.end(), {tri[0], tri[1], tri[2]});
  }

  r.attributes["time_step_s"] = o_.time_step_s;
  r.attributes["duration_s"] = o_.duration_s;
  r.attributes["output_interval_s"] = o_.output_interval_s;
  r.attributes["steady_start_s"] = o_.steady_start_s;
  r.attributes["contact_model"] = vessel_contact_model(wm, r);
  r.attributes["contact_ice_structure"] = o_.contact.ice_structure;
  r.attributes["contact_ice_ice"] = o_.contact.ice_ice;
  r.attributes["frames_at"] = "t = k * output_interval_s, k = 1 .. duration_s / output_interval_s";
}

}  // namespace floesim::sim
