#include "sim/simulate/ridge_summary.h"

#include <algorithm>
#include <cmath>

#include "pipeline/signal.h"

namespace floesim::sim {

namespace {

double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

nlohmann::json ridge_as_built(const RidgeBuilt& b, double ice_density, double water_density) {
  nlohmann::json j = {{"blocks", b.blocks},
                      {"keel_depth_m", b.keel_depth_m},
                      {"keel_depth_middle_m", b.keel_depth_middle_m},
                      {"sail_height_m", b.sail_height_m},
                      {"layer_bottom_z_m", b.layer_bottom_z},
                      {"layer_top_z_m", b.layer_top_z},
                      {"keel_area_m2", b.keel_area_m2},
                      {"sail_area_m2", b.sail_area_m2},
                      {"keel_over_sail_area", b.sail_area_m2 > 0 ? nlohmann::json(b.keel_area_m2 / b.sail_area_m2)
                                                                 : nlohmann::json(nullptr)},
                      {"porosity_by_volume", b.porosity_by_volume},
                      {"porosity_by_voxels", b.porosity_by_voxels},
                      {"fastest_block_mps", b.max_block_speed_mps},
                      {"packed_frictionless_s", b.packed_s}};
  j["hydrostatics"] = {
      {"what", "the ridge's ice (layer and blocks) under the waterline over that above it, against "
               "rho_i / (rho_w - rho_i), which a ridge floating freely at rest has (PHYSICS.md 9.1); a layer held "
               "by the sheet carries the rest"},
      {"ice_below_m3", b.ice_below_m3},
      {"ice_above_m3", b.ice_above_m3},
      {"ratio", b.ice_above_m3 > 0 ? nlohmann::json(b.ice_below_m3 / b.ice_above_m3) : nlohmann::json(nullptr)},
      {"free_floating_ratio", ice_density / (water_density - ice_density)}};
  j["profile"] = {{"s_m", b.profile_s_m}, {"keel_bottom_z_m", b.keel_bottom_z}, {"sail_top_z_m", b.sail_top_z}};
  return j;
}

// The hull body's passage through a ridge, for a ship: where its bow is across the ridge (the distance past the near
// edge of the layer, along the line's normal toward the far side), how far it got, when its bow came through the far
// edge, and while any of its hull was in the layer's width (from its bow's entry to its stern's exit) its speed and
// the surge loads from all ice, the ridge's rubble and its layer; stopped: slower than 0.05 m/s in there.
nlohmann::json ship_in_ridge(const Model& model, const RidgeOptions& r, const SeriesSource& series) {
  const Body& hull = model.bodies[model.vessel];
  double bow_x = -1e300, stern_x = 1e300;
  for (const Vec3& v : hull.buoyancy_mesh.vertices) bow_x = std::max(bow_x, v.x()), stern_x = std::min(stern_x, v.x());
  const Vec2 a(r.line[0].x_m, r.line[0].y_m), b(r.line[1].x_m, r.line[1].y_m);
  const Vec2 t = (b - a).normalized();
  Vec2 n(-t.y(), t.x());
  const std::vector<double> time = series.get("time_s"), pos = series.get("vessel_position_m"),
                            q = series.get("vessel_quaternion_wxyz"), vel = series.get("vessel_velocity_mps"),
                            rubble = series.get("ice_load_ridge_rubble"), layer = series.get("ice_load_ridge_layer"),
                            ice = series.get("ice_load");
  const size_t steps = time.size();
  if (steps == 0) return nullptr;
  auto bow_s = [&](size_t k) {
    const Quat qk(q[4 * k], q[4 * k + 1], q[4 * k + 2], q[4 * k + 3]);
    const Vec3 bow = Vec3(pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]) + qk * Vec3(bow_x, 0, 0);
    return (Vec2(bow.x(), bow.y()) - a).dot(n);
  };
  if (bow_s(0) > 0) n = -n;  // toward the far side from where the ship starts
  const double half = 0.5 * r.keel_width_m, length = bow_x - stern_x;
  double reach = -1e300, through_t = -1, stop_t = -1;
  std::vector<double> speed_in, rubble_in, layer_in, total_in;
  // The work the hull does on the layer's ice and on the rubble while it is in the ridge (the surge load against
  // the surge speed, over each step's time), and the distances it sails there: along its track and across the
  // ridge (along the line's normal).
  double layer_work = 0, rubble_work = 0, track_m = 0, across_m = 0;
  long previous = -1;
  for (size_t k = 0; k < steps; ++k) {
    const double pen = bow_s(k) + half;  // past the near edge
    reach = std::max(reach, pen);
    if (through_t < 0 && pen > r.keel_width_m) through_t = time[k];
    if (pen < 0 || pen > r.keel_width_m + length) continue;  // no part of the hull in the layer's width
    const double u = vel[3 * k];
    speed_in.push_back(u);
    rubble_in.push_back(rubble[6 * k]);
    layer_in.push_back(layer[6 * k]);
    total_in.push_back(ice[6 * k]);
    if (stop_t < 0 && u < 0.05 && time[k] > 1.0) stop_t = time[k];
    if (previous >= 0 && static_cast<size_t>(previous) == k - 1) {
      const double dt = time[k] - time[k - 1];
      layer_work -= 0.5 * dt * (layer[6 * k] * u + layer[6 * (k - 1)] * vel[3 * (k - 1)]);
      rubble_work -= 0.5 * dt * (rubble[6 * k] * u + rubble[6 * (k - 1)] * vel[3 * (k - 1)]);
      track_m += std::hypot(pos[3 * k] - pos[3 * (k - 1)], pos[3 * k + 1] - pos[3 * (k - 1) + 1]);
      across_m += bow_s(k) - bow_s(k - 1);
    }
    previous = static_cast<long>(k);
  }
  auto or_null = [](double x) { return x >= 0 ? nlohmann::json(x) : nlohmann::json(nullptr); };
  nlohmann::json j = {{"what", "the hull's passage across the layer's width (penetration: the bow's distance past its "
                               "near edge along the line's normal; in the ridge: from the bow's entry to the stern's "
                               "exit); surge loads in body axes, negative astern; work per metre: the work done on "
                               "the layer's ice (on the rubble) in the ridge over the ridge's width along the track, "
                               "a resistance"},
                      {"through", through_t >= 0},
                      {"bow_through_at_s", or_null(through_t)},
                      {"penetration_max_m", through_t >= 0 ? r.keel_width_m : reach},
                      {"stopped_at_s", or_null(stop_t)}};
  if (!speed_in.empty()) {
    j["in_ridge"] = {{"steps", speed_in.size()},
                     {"mean_speed_mps", mean_of(speed_in)},
                     {"min_speed_mps", *std::min_element(speed_in.begin(), speed_in.end())},
                     {"mean_surge_ice_load_N", mean_of(total_in)},
                     {"mean_surge_rubble_load_N", mean_of(rubble_in)},
                     {"mean_surge_layer_load_N", mean_of(layer_in)},
                     {"min_surge_rubble_load_N", *std::min_element(rubble_in.begin(), rubble_in.end())}};
    // Per metre of ridge crossed along the track (its width along the normal, times track over across): in level
    // ice the work per metre advanced is the mean resistance, so the layer's equals Lindqvist's at h_c if the layer
    // breaks as level ice does, whatever its width (each metre of it is broken and its pieces pushed along the whole
    // hull while the hull is in the ridge). Only for a hull that came through.
    if (through_t >= 0 && across_m > 0) {
      const double crossed = r.keel_width_m * track_m / across_m;
      j["in_ridge"]["crossed_along_track_m"] = crossed;
      j["in_ridge"]["layer_work_per_metre_N"] = layer_work / crossed;
      j["in_ridge"]["rubble_work_per_metre_N"] = rubble_work / crossed;
    }
  }
  return j;
}

// A held hull body (a structure): the horizontal loads from the ridges' rubble and layers, their largest raw and
// through the 1 s moving average (the keel's load is quasi-static: PHYSICS.md 9.3's F_K is a static bound).
nlohmann::json structure_in_ridges(const SimulateOptions& o, const SeriesSource& series) {
  const std::vector<double> rubble = series.get("ice_load_ridge_rubble"), layer = series.get("ice_load_ridge_layer"),
                            keel = series.get("ice_load_ridge_keel");
  const size_t steps = series.steps();
  std::vector<double> hr(steps), hl(steps), hk(steps);
  for (size_t k = 0; k < steps; ++k) {
    hr[k] = std::hypot(rubble[6 * k], rubble[6 * k + 1]);
    hl[k] = std::hypot(layer[6 * k], layer[6 * k + 1]);
    hk[k] = std::hypot(keel[6 * k], keel[6 * k + 1]);
  }
  const size_t window = std::max<size_t>(1, static_cast<size_t>(std::lround(1.0 / o.time_step_s)));
  auto peak = [](const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); };
  return {{"what", "horizontal ice force on the structure from the ridges' rubble (keels, sails), of it from the keels "
                   "below their layers' undersides (Dolgopolov's F_K), and from their consolidated layers (with their "
                   "pieces): largest raw and largest 1 s moving average"},
          {"max_rubble_N", peak(hr)},
          {"max_rubble_1s_N", peak(moving_average_full_windows(hr, window))},
          {"max_keel_N", peak(hk)},
          {"max_keel_1s_N", peak(moving_average_full_windows(hk, window))},
          {"max_layer_N", peak(hl)},
          {"max_layer_1s_N", peak(moving_average_full_windows(hl, window))}};
}

}  // namespace

nlohmann::json ridge_summary(const SimulateOptions& o, const Model& model, const RidgeSettling& settled,
                             const SeriesSource& series, const State& end) {
  nlohmann::json list = nlohmann::json::array();
  const double rho_i = o.ice.density_kg_m3, rho_w = o.water.density_kg_m3;
  const std::vector<RidgeOptions>& ridges = model.settings.ridges;  // the ridge field's among them
  for (size_t k = 0; k < ridges.size(); ++k) {
    const RidgeOptions& r = ridges[k];
    const RidgeSection s = ridge_section(r, rho_i, rho_w, "ridges[" + std::to_string(k) + "]");
    nlohmann::json j;
    nlohmann::json line = nlohmann::json::array();
    for (const RidgePoint& p : r.line) line.push_back({p.x_m, p.y_m});
    j["design"] = {{"line_m", line},
                   {"keel_depth_m", r.keel_depth_m},
                   {"keel_width_m", r.keel_width_m},
                   {"sail_height_m", r.sail_height_m},
                   {"consolidated_thickness_m", r.consolidated_thickness_m},
                   {"porosity", r.porosity},
                   {"keel_area_m2", s.keel_area_m2},
                   {"sail_area_m2", s.sail_area_m2}};
    if (k < settled.ridges.size()) j["as_built"] = ridge_as_built(settled.ridges[k], rho_i, rho_w);
    if (model.vessel >= 0 && !o.vessel.station_keeping.held()) j["ship"] = ship_in_ridge(model, r, series);
    list.push_back(std::move(j));
  }
  nlohmann::json out = {{"settling", {{"time_s", settled.time_s}, {"steps", settled.steps},
                                      {"blocks", settled.blocks}}},
                        {"ridges", list}};
  if (o.freeze_bonds.enabled())
    out["freeze_bonds"] = {{"tensile_strength_pa", o.freeze_bonds.tensile_strength_pa},
                           {"shear_strength_pa", o.freeze_bonds.shear_strength_pa},
                           {"formed", settled.bonds},
                           {"broken", end.bonds_broken},
                           {"left_at_end", end.bonds.size()}};
  if (model.vessel >= 0 && o.vessel.station_keeping.held()) out["structure_loads"] = structure_in_ridges(o, series);
  return out;
}

}  // namespace floesim::sim
