#include "sim/simulate/summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "pipeline/error.h"
#include "pipeline/ice_resistance.h"
#include "pipeline/signal.h"
#include "sim/engine/fracture.h"
#include "sim/engine/fracture_laws.h"

namespace floesim::sim {

namespace {

// The load windows of the seed paper (§5): 0.5 s for compliant contacts, 20 s for rigid ones.
constexpr double kCompliantWindowS = 0.5;
constexpr double kRigidWindowS = 20.0;

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
  int count[5] = {0, 0, 0, 0, 0}, at_vessel = 0;
  for (size_t e = 0; e < r.fracture_mode.size(); ++e) {
    ++count[std::clamp(r.fracture_mode[e], 0, 4)];
    at_vessel += r.fracture_at_structure[e];
  }
  f["events"] = {{"bending", count[kFractureBending]}, {"radial", count[kFractureRadial]},
                 {"splitting", count[kFractureSplitting]}, {"crushing_cleared", count[kFractureCrushing]},
                 {"total", r.fracture_mode.size()}, {"at_vessel", at_vessel}};
  std::map<int32_t, double> area, thickness;  // by floe id
  std::map<int32_t, bool> tile;                // by floe id: a level ice tile
  double start = 0, end = 0, brash = 0, brash_kept = 0;
  int brash_bodies = 0;
  std::vector<double> piece_area, piece_diameter, piece_over_lc;
  const double rho_w_g_pieces = o.water.density_kg_m3 * o.water.gravity_mps2;
  for (size_t k = 0; k < r.floe_id.size(); ++k) {
    Polygon p;
    for (int64_t i = r.floe_vertex_offset[k]; i < r.floe_vertex_offset[k + 1]; ++i)
      p.emplace_back(r.floe_vertices_m[2 * i], r.floe_vertices_m[2 * i + 1]);
    const double a = signed_area(p), m = o.ice.density_kg_m3 * a * r.floe_thickness_m[k];
    area[r.floe_id[k]] = a;
    thickness[r.floe_id[k]] = r.floe_thickness_m[k];
    if (r.floe_parent_id[k] < 0) start += m;
    const bool sheet = !r.floe_level_ice.empty() && r.floe_level_ice[k];
    tile[r.floe_id[k]] = sheet;
    if (std::isinf(r.floe_ended_s[k])) {
      end += m;
      if (!sheet && o.fracture.brash == "rigid" && is_brash(p, r.floe_thickness_m[k], o.fracture.min_piece_area_m2)) {
        ++brash_bodies;
        brash_kept += m;
      }
    }
    // Pieces: the floes fracture made (a wedge off a level ice tile is one; what the tile keeps is still sheet).
    if (r.floe_parent_id[k] >= 0 && !sheet) {
      piece_area.push_back(a);
      piece_diameter.push_back(std::sqrt(4 * a / kPi));
      if (rho_w_g_pieces > 0)
        piece_over_lc.push_back(std::sqrt(a) / characteristic_length_m(o.fracture.youngs_modulus_pa,
                                                                      o.fracture.poisson_ratio,
                                                                      r.floe_thickness_m[k], rho_w_g_pieces));
    }
  }
  // Events on the sheet not at the vessel: its edge yielding to the ice pressed against or under it (§10).
  int sheet_edge = 0;
  for (size_t e = 0; e < r.fracture_mode.size(); ++e)
    if (!r.fracture_at_structure[e] && tile[r.fracture_parent_id[e]]) ++sheet_edge;
  f["events"]["sheet_edge_by_ice"] = sheet_edge;
  // Mass removed: brash (fracture.brash "removed"), and the crushed ice a fixed structure cleared from the sheet.
  double crushed = 0;
  for (size_t e = 0; e < r.fracture_mode.size(); ++e)
    (r.fracture_mode[e] == kFractureCrushing ? crushed : brash) += r.fracture_brash_mass_kg[e];
  f["pieces_created"] = piece_area.size();
  f["ice_mass_start_kg"] = start;
  f["ice_mass_end_kg"] = end + brash + crushed;
  f["ice_mass_in_bodies_end_kg"] = end;
  f["brash_removed_kg"] = brash;
  f["crushed_cleared_kg"] = crushed;
  f["min_piece_area_m2"] = o.fracture.min_piece_area_m2;
  f["brash"] = {{"mode", o.fracture.brash}, {"bodies_at_end", brash_bodies}, {"mass_at_end_kg", brash_kept}};
  f["piece_area_m2"] = distribution(piece_area);
  f["piece_equivalent_diameter_m"] = distribution(piece_diameter);
  // sqrt(area) / l_c of the pieces, against the cusps icebreakers leave (0.1-0.3 l_c, PHYSICS.md §2.1).
  f["piece_size_over_lc"] = distribution(piece_over_lc);
  // Wedges: R_b of fracture.piece_size for each event's theta and width (static: without the speed correction),
  // against the smallest child of the event (the wedge: the floe it broke from is longer than the wedge by the
  // finite-floe rule, so the remainder is the larger piece). An event with one child and brash removed lost its
  // wedge to brash (a sliver cut beside an earlier crack): its only child is the remainder, not a piece, so it is
  // counted apart instead (in level ice it would otherwise put the tile's size among the pieces).
  std::vector<double> rb, wedge_size, wedge_ratio;
  int wedge_brash = 0;
  const double rho_w_g = o.water.density_kg_m3 * o.water.gravity_mps2;
  for (size_t e = 0; e < r.fracture_mode.size(); ++e) {
    if (r.fracture_mode[e] == kFractureSplitting || r.fracture_mode[e] == kFractureCrushing || rho_w_g <= 0) continue;
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

nlohmann::json level_ice_summary(const SimulateOptions& o, const Model& model, const Results& r) {
  return level_ice_summary(o, model, r, ResultsSeries(r));
}

nlohmann::json level_ice_summary(const SimulateOptions& o, const Model& model, const Results& r,
                                 const SeriesSource& series) {
  nlohmann::json j;
  const int v = model.vessel;
  std::vector<int> tiles;
  for (size_t b = 0; b < model.built_bodies; ++b)  // the sheet as built (what fracture left of a tile is a piece)
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
    if (t[i] < o.steady_start_s - 0.5 * o.time_step_s) continue;
    sum_all -= all[6 * i];
    sum_sheet -= sheet[6 * i];
    n += 1;
  }
  if (n > 0)
    j["resistance_split"] = {{"from_s", o.steady_start_s},
                             {"breaking_sheet_N", sum_sheet / n},
                             {"clearing_pieces_N", (sum_all - sum_sheet) / n},
                             {"breaking_share", sum_all != 0 ? sum_sheet / sum_all : 0.0}};
  return j;
}

nlohmann::json mean_interval_json(const std::vector<double>& x, double dt_s, double mean, const std::string& unit) {
  if (x.empty()) return {{"meaningful", false}, {"note", "no samples in the steady part: no interval"}};
  const MeanInterval m = mean_interval(x, dt_s);
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  char method[400];
  std::snprintf(method, sizeof method,
                "batch means: the steady part (%zu samples) cut into %zu consecutive batches of %zu samples (%.4g s; "
                "the %zu left over dropped at its start), the standard error the batch means' standard deviation "
                "over sqrt(%zu), the %.0f %% interval the mean +- Student's t (%zu degrees of freedom) times it",
                m.samples, m.batches, m.batch_samples, m.batch_s, m.dropped_samples, m.batches, 100 * m.level,
                m.batches - 1);
  nlohmann::json j = {{"method", method},
                      {"level", m.level},
                      {"batches", m.batches},
                      {"batch_s", m.batch_s},
                      {"standard_error_" + unit, number(m.standard_error)},
                      {"half_width_" + unit, number(m.half_width)},
                      {"low_" + unit, number(mean - m.half_width)},
                      {"high_" + unit, number(mean + m.half_width)},
                      {"t_quantile", number(m.t_quantile)},
                      {"batch_lag1_autocorrelation", number(m.batch_lag1)},
                      {"meaningful", m.meaningful}};
  if (!m.meaningful) j["note"] = m.note;
  return j;
}

nlohmann::json summarize(const SimulateOptions& o, const Model& model, const Results& r) {
  return summarize(o, model, r, ResultsSeries(r));
}

nlohmann::json summarize(const SimulateOptions& o, const Model& model, const Results& r, const SeriesSource& series) {
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
  std::vector<double> u;  // the surge speed over the steady part (column 0), for its interval
  {
    const std::vector<double> v = series.get("vessel_velocity_mps");
    const size_t cols = static_cast<size_t>(series_field("vessel_velocity_mps").cols);
    for (size_t i = first; i < steps; ++i) u.push_back(v[cols * i]);
  }
  double speed = 0;
  for (double x : u) speed += x;
  const double thrust = steady_sum("propulsion_load");
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
  // The resistance's interval is the load's, negated: the same half width.
  s["mean_surge_ice_load_interval"] = mean_interval_json(fx, o.time_step_s, mean, "N");
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
  {
    // §5 for a run of both laws: each part over its own window (rigid 20 s, compliant 0.5 s), then summed; whole
    // 20 s windows only.
    std::vector<double> rigid, compliant;
    {
      const std::vector<double> x = series.get("ice_load_rigid");
      for (size_t i = first; i < steps; ++i) rigid.push_back(x[6 * i]);
    }
    {
      const std::vector<double> x = series.get("ice_load_compliant");
      for (size_t i = first; i < steps; ++i) compliant.push_back(x[6 * i]);
    }
    const size_t nr = static_cast<size_t>(std::lround(kRigidWindowS / o.time_step_s));
    const size_t nc = static_cast<size_t>(std::lround(kCompliantWindowS / o.time_step_s));
    const std::vector<double> a = moving_average_centred(rigid, nr), b = moving_average_centred(compliant, nc);
    const auto [f0, f1] = full_window_range(rigid.size(), nr);
    nlohmann::json j = {{"window_s", kRigidWindowS},
                        {"compliant_window_s", kCompliantWindowS},
                        {"kind", "rigid part over 20 s + compliant part over 0.5 s, summed"},
                        {"applies", model_kind == "mixed"}};
    if (f0 >= f1) {
      j["note"] = "the steady part is shorter than the window";
      for (const char* k : {"max_N", "min_N", "max_resistance_N", "std_N"}) j[k] = nullptr;
    } else {
      double lo = 1e300, hi = -1e300, m = 0, v2 = 0;
      for (size_t i = f0; i < f1; ++i) {
        const double y = a[i] + b[i];
        lo = std::min(lo, y), hi = std::max(hi, y), m += y;
      }
      m /= static_cast<double>(f1 - f0);
      for (size_t i = f0; i < f1; ++i) v2 += (a[i] + b[i] - m) * (a[i] + b[i] - m);
      j["max_N"] = hi;
      j["min_N"] = lo;
      j["max_resistance_N"] = -lo;
      j["std_N"] = std::sqrt(v2 / static_cast<double>(f1 - f0));
    }
    windows.push_back(j);
  }
  s["moving_average_surge_ice_load"] = windows;
  s["contact_model"] = model_kind;
  s["contact_laws"] = {{"ice_structure", o.contact.ice_structure}, {"ice_ice", o.contact.ice_ice}};
  s["mean_vessel_speed_mps"] = speed / n;
  s["mean_vessel_speed_interval"] = mean_interval_json(u, o.time_step_s, speed / n, "mps");
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
  s["floes"] = model.built_floe_count();
  s["removed_floes"] = model.removed_floe_ids.size();
  s["removed_floe_ids"] = model.removed_floe_ids;
  s["small_floe_overlaps"] = model.small_overlaps;
  s["fracture"] = fracture_summary(o, r);
  s["level_ice"] = level_ice_summary(o, model, r, series);
  if (o.vessel.station_keeping.held()) s["structure"] = structure_summary(o, model, r, series);
  if (!model.structures.empty()) {
    s["structures"] = nlohmann::json::array();
    for (size_t k = 0; k < model.structures.size(); ++k)
      s["structures"].push_back(listed_structure_summary(o, model, r, series, k));
  }
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
                  ittc57_resistance(o.vessel.propulsion.speed_mps, ittc57_of(vp, o))}};
  return s;
}

}  // namespace floesim::sim
