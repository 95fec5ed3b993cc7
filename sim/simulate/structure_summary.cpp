// summary.json "structure": what an engineer checks a structure's ice load and station keeping by (PHYSICS.md §8).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "pipeline/error.h"
#include "pipeline/signal.h"
#include "pipeline/station_keeping.h"
#include "sim/simulate/summary.h"

namespace floesim::sim {

namespace {

// PHYSICS.md §5: compliant contacts are read through a 0.5 s centred moving average.
constexpr double kFilterS = 0.5;
// The band of load periods searched for the dominant one, in h/v (PHYSICS.md §8.2.4: breaks of 3-12 h): wide
// enough that a period outside the expected 4-12 h/v is found, not clipped.
constexpr double kPeriodBandLoHV = 1.0, kPeriodBandHiHV = 30.0;

struct Stats {
  double mean = 0, std = 0, max = 0, min = 0;
};
Stats stats_of(const std::vector<double>& x) {
  Stats s;
  if (x.empty()) return s;
  for (double v : x) s.mean += v;
  s.mean /= static_cast<double>(x.size());
  for (double v : x) s.std += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(s.std / static_cast<double>(x.size()));
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  s.min = *lo;
  s.max = *hi;
  return s;
}

nlohmann::json stats_json(const Stats& s) {
  return {{"mean", s.mean}, {"std", s.std}, {"max", s.max}, {"min", s.min}};
}

// The highest ice within `radius` of the structure's axis at each stored frame of the steady part (the rubble and
// ride-up pile, PHYSICS.md §8.2's h_r, measured from the water line): every alive floe's slab corners, posed.
// `axis_at(frame)`: the structure's axis at the water line at that frame, in the frames' (the run's) frame.
template <class AxisAt>
std::vector<double> rubble_heights(const Results& r, double from_s, double radius, AxisAt&& axis_at) {
  std::vector<double> heights;
  if (r.frames() == 0) return heights;
  FrameReplay replay(r, "the results");
  for (size_t f = 0; f < r.frames(); ++f) {
    replay.seek(f);
    if (r.frame_time_s[f] < from_s) continue;
    const Vec3 axis = axis_at(replay, f);
    double top = 0;                   // open water: nothing above the water line
    const std::vector<int64_t>& rows = replay.rows();
    const std::vector<int32_t>& floes = replay.floes();
    for (size_t k = 0; k < rows.size(); ++k) {
      const int32_t g = floes[k];
      if (g < 0) continue;  // the structure itself
      const int64_t row = rows[k];
      const Vec3 x(r.state_position_m[3 * row], r.state_position_m[3 * row + 1], r.state_position_m[3 * row + 2]);
      const Quat q(r.state_quaternion[4 * row], r.state_quaternion[4 * row + 1], r.state_quaternion[4 * row + 2],
                   r.state_quaternion[4 * row + 3]);
      const double h = r.floe_thickness_m[g];
      for (int64_t i = r.floe_vertex_offset[g]; i < r.floe_vertex_offset[g + 1]; ++i)
        for (double z : {-0.5 * h, 0.5 * h}) {
          const Vec3 p = x + q * Vec3(r.floe_vertices_m[2 * i], r.floe_vertices_m[2 * i + 1], z);
          if ((p - axis).head<2>().norm() <= radius) top = std::max(top, p.z());
        }
    }
    heights.push_back(top);
  }
  return heights;
}

// Where every hull body was at a recorded step, in the run's frame: the vessel slot first (vessel_position_m is in
// the run's frame), then the structures beside it (their position_m series are in the earth's).
class HullTracks {
 public:
  HullTracks(const SimulateOptions& o, const Model& model, const Results& r, const SeriesSource& series)
      : o_(o), frame_velocity_(model.frame_velocity), vessel_(series.get("vessel_position_m")) {
    for (const StructureOptions& so : o.structures) {
      const auto it = r.structure_series.find(so.name + "/position_m");
      FLOESIM_REQUIRE(it != r.structure_series.end(), "internal: no series ", so.name, "/position_m");
      listed_.push_back(&it->second);
    }
  }
  // The hull body nearest p at time t: 0 the vessel slot, 1 + k the k-th structure beside it.
  size_t nearest(const Vec2& p, double t) const {
    const size_t rows = vessel_.size() / 3;
    if (rows == 0) return 0;
    const long row = std::lround(t / o_.time_step_s) - 1;
    const size_t i = static_cast<size_t>(std::clamp<long>(row, 0, static_cast<long>(rows) - 1));
    size_t best = 0;
    double best_d = (Vec2(vessel_[3 * i], vessel_[3 * i + 1]) - p).norm();
    for (size_t k = 0; k < listed_.size(); ++k) {
      const std::vector<double>& x = *listed_[k];
      const Vec2 at = Vec2(x[3 * i], x[3 * i + 1]) - t * frame_velocity_.head<2>();
      if ((at - p).norm() < best_d) best_d = (at - p).norm(), best = k + 1;
    }
    return best;
  }

 private:
  const SimulateOptions& o_;
  Vec3 frame_velocity_;
  std::vector<double> vessel_;
  std::vector<const std::vector<double>*> listed_;
};

// The break length (PHYSICS.md §8.2.4: the load period of flexural failure is the break length over the drift
// speed): the extent along the drift of each piece a level ice sheet lost in the steady part, in a break nearer
// hull body `self` than any other (HullTracks). A piece keeps its tile's axes, which are the run's, and the sheet
// rests in the run's frame, so its outline's extent along the drift is how far the break reached into the sheet.
// The median (a crack beside an earlier one leaves a sliver) and the mean; over h, the period in h/v.
nlohmann::json break_length_json(const SimulateOptions& o, const Results& r, const HullTracks& tracks, size_t self) {
  const Vec2 d = o.drift.velocity();
  if (d.norm() <= 0 || r.floe_level_ice.size() != r.floe_id.size()) return nullptr;
  const Vec2 along = d.normalized();
  std::map<int32_t, size_t> row_of;
  for (size_t g = 0; g < r.floe_id.size(); ++g) row_of[r.floe_id[g]] = g;
  std::vector<double> lengths;
  for (size_t e = 0; e < r.fracture_time_s.size(); ++e) {
    const double t = r.fracture_time_s[e];
    const auto parent = row_of.find(r.fracture_parent_id[e]);
    if (t < o.steady_start_s || parent == row_of.end() || !r.floe_level_ice[parent->second]) continue;
    if (tracks.nearest(Vec2(r.fracture_point_m[3 * e], r.fracture_point_m[3 * e + 1]), t) != self) continue;
    for (int64_t c = r.fracture_child_offset[e]; c < r.fracture_child_offset[e + 1]; ++c) {
      const auto child = row_of.find(r.fracture_child_id[c]);
      if (child == row_of.end() || r.floe_level_ice[child->second]) continue;  // the sheet that is left
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (int64_t i = r.floe_vertex_offset[child->second]; i < r.floe_vertex_offset[child->second + 1]; ++i) {
        const double u = along.dot(Vec2(r.floe_vertices_m[2 * i], r.floe_vertices_m[2 * i + 1]));
        lo = std::min(lo, u);
        hi = std::max(hi, u);
      }
      lengths.push_back(hi - lo);
    }
  }
  const double h = o.level_ice.thickness_m;
  nlohmann::json j = {{"pieces", lengths.size()},
                      {"what", "the extent along the drift of the pieces the sheet lost near this structure in the "
                               "steady part; the load period of flexural failure is the break length over the drift "
                               "speed, so in h/v it is the break length over h"}};
  if (lengths.empty()) return j;
  std::sort(lengths.begin(), lengths.end());
  const size_t n = lengths.size();
  const double median = n % 2 ? lengths[n / 2] : 0.5 * (lengths[n / 2 - 1] + lengths[n / 2]);
  j["median_m"] = median;
  j["mean_m"] = stats_of(lengths).mean;
  j["period_over_h_per_v"] = median / h;
  return j;
}

// The offset from the station (x, y: series `off` [steps x 3], x, y and the heading's change) over the steady part:
// each component's, the distance's and the heading change's statistics.
nlohmann::json offsets_json(const std::vector<double>& off, size_t first, size_t steps) {
  std::vector<double> dx, dy, dist, dpsi;
  for (size_t i = first; i < steps; ++i) {
    dx.push_back(off[3 * i]);
    dy.push_back(off[3 * i + 1]);
    dist.push_back(std::hypot(off[3 * i], off[3 * i + 1]));
    dpsi.push_back(off[3 * i + 2] * 180 / kPi);
  }
  return {{"offset_x_m", stats_json(stats_of(dx))},
          {"offset_y_m", stats_json(stats_of(dy))},
          {"offset_m", stats_json(stats_of(dist))},
          {"heading_change_deg", stats_json(stats_of(dpsi))}};
}

// A moored or DP structure: its offset and heading change, the force balance along the drift (PHYSICS.md §8.4.3:
// the mean station-keeping force against the mean ice, water and wind loads, earth frame), and each mooring line's
// tension (quasi-static: from the recorded offset, PHYSICS.md §8.4.1) or the DP thrusters' use of their limits.
nlohmann::json station_keeping_summary(const SimulateOptions& o, const Model& model, const SeriesSource& series,
                                       size_t first) {
  const size_t steps = series.steps();
  const std::vector<double> off = series.get("station_offset");
  nlohmann::json j = offsets_json(off, first, steps);
  // 1. The balance along the drift (or the station's x axis without one): each load turned into the earth frame.
  const Vec2 drift = o.drift.velocity();
  const double a = model.station.heading_rad;
  const Vec3 along = drift.norm() > 0 ? Vec3(drift.x(), drift.y(), 0).normalized() : Vec3(std::cos(a), std::sin(a), 0);
  const std::vector<double> quat = series.get("vessel_quaternion_wxyz");
  const double n = static_cast<double>(steps - first);
  auto mean_along = [&](const char* name) {
    const std::vector<double> f = series.get(name);
    double sum = 0;
    for (size_t i = first; i < steps; ++i) {
      const Quat q(quat[4 * i], quat[4 * i + 1], quat[4 * i + 2], quat[4 * i + 3]);
      sum += along.dot(q * Vec3(f[6 * i], f[6 * i + 1], f[6 * i + 2]));
    }
    return sum / n;
  };
  const double ice = mean_along("ice_load"), water = mean_along("hydro_load"), wind = mean_along("wind_load");
  const double held = mean_along("propulsion_load");
  // What the forces left over changed the body's momentum (with its added mass, body axes): over a window of a few
  // natural periods the mean of a swinging body's inertia force is not quite zero.
  const std::vector<double> vel = series.get("vessel_velocity_mps");
  const Body& body = model.bodies[model.vessel];
  auto momentum = [&](size_t i) {
    const Quat q(quat[4 * i], quat[4 * i + 1], quat[4 * i + 2], quat[4 * i + 3]);
    const Vec3 vb(vel[3 * i], vel[3 * i + 1], vel[3 * i + 2]);
    return along.dot(q * (Vec3::Constant(body.mass_kg) + body.added_mass).cwiseProduct(vb));
  };
  const double window = o.time_step_s * n;
  const double inertia = steps > first ? (momentum(steps - 1) - momentum(first)) / window : 0.0;
  j["force_balance_along_drift_N"] = {{"ice", ice},
                                      {"water", water},
                                      {"wind", wind},
                                      {"station_keeping", held},
                                      {"residual", ice + water + wind + held},
                                      {"momentum_change_per_time", inertia},
                                      {"station_keeping_over_loads", -held / (ice + water + wind)}};
  // 2. The lines' tensions at the recorded offsets, or the thrusters' use of their limits.
  const StationKeepingOptions& sk = o.vessel.station_keeping;
  if (sk.moored()) {
    const double c0 = std::cos(a), s0 = std::sin(a);
    std::vector<Stats> h(model.station.mooring.size()), t(model.station.mooring.size());
    std::vector<std::vector<double>> hs(model.station.mooring.size()), ts(model.station.mooring.size());
    for (size_t i = first; i < steps; ++i) {
      const double ex = off[3 * i], ey = off[3 * i + 1];
      const SpreadState sp =
          spread_at_pose(model.station.mooring, c0 * ex + s0 * ey, -s0 * ex + c0 * ey, off[3 * i + 2]);
      for (size_t l = 0; l < sp.lines.size(); ++l) {
        hs[l].push_back(sp.lines[l].horizontal_tension_n);
        ts[l].push_back(sp.lines[l].fairlead_tension_n);
      }
    }
    nlohmann::json lines = nlohmann::json::array();
    double largest = 0;
    for (size_t l = 0; l < hs.size(); ++l) {
      const Stats sh = stats_of(hs[l]), st = stats_of(ts[l]);
      largest = std::max(largest, st.max);
      lines.push_back({{"azimuth_deg", sk.lines[l].azimuth_deg},
                       {"horizontal_tension_N", stats_json(sh)},
                       {"fairlead_tension_N", stats_json(st)}});
    }
    j["lines"] = lines;
    j["largest_fairlead_tension_N"] = largest;
  } else {
    const std::vector<double> dem = series.get("station_keeping_demanded");
    const std::vector<double> del = series.get("station_keeping_delivered");
    const double limit[3] = {sk.dp.max_force_x_n, sk.dp.max_force_y_n, sk.dp.max_moment_z_nm};
    const char* axis[3] = {"surge", "sway", "yaw"};
    for (int k = 0; k < 3; ++k) {
      double use = 0, ask = 0;
      size_t saturated = 0;
      for (size_t i = first; i < steps; ++i) {
        use = std::max(use, std::abs(del[3 * i + k]) / limit[k]);
        ask = std::max(ask, std::abs(dem[3 * i + k]) / limit[k]);
        saturated += std::abs(dem[3 * i + k]) > limit[k];
      }
      j["thrusters"][axis[k]] = {{"largest_delivered_over_limit", use},
                                 {"largest_demanded_over_limit", ask},
                                 {"share_of_steps_saturated", static_cast<double>(saturated) / n}};
    }
  }
  return j;
}

// The load cycles of a filtered load (pipeline/signal.h load_cycles: the count, the mean of the per-cycle peaks, the
// mean period) and its autocorrelation's dominant period; with a drift in a level ice sheet both periods over h/v
// (PHYSICS.md §8.2.4's 4-12), the dominant one searched over 1-30 h/v.
nlohmann::json cycles_json(const std::vector<double>& f, const SimulateOptions& o, size_t nw) {
  auto number = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  nlohmann::json j;
  if (f.empty()) return j;
  const LoadCycles c = load_cycles(f, o.time_step_s);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  j["count"] = c.peak.size();
  j["mean_peak_N"] = number(c.peak.empty() ? nan : c.mean_peak);
  j["mean_period_s"] = number(c.peak.empty() ? nan : c.mean_period_s);
  const double h = o.level_ice.thickness_m, v = o.drift.speed_mps;
  if (v > 0 && !o.level_ice.extent_m.empty()) {
    // On the filtered load decimated to a tenth of the filter window (it holds nothing faster).
    const size_t every = std::max<size_t>(1, nw / 10);
    std::vector<double> coarse;
    for (size_t i = 0; i < f.size(); i += every) coarse.push_back(f[i]);
    const double dt = every * o.time_step_s, span = dt * static_cast<double>(coarse.size());
    const double lo = kPeriodBandLoHV * h / v, hi = std::min(kPeriodBandHiHV * h / v, span / 2);
    const double p = lo < hi ? dominant_period_s(coarse, dt, lo, hi) : nan;
    j["dominant_period_s"] = number(p);
    j["dominant_period_band_s"] = {lo, hi};
    j["period_over_h_per_v"] = {{"cycles", number(c.peak.empty() ? nan : c.mean_period_s * v / h)},
                                {"dominant", number(p * v / h)},
                                {"thickness_m", h}};
  }
  return j;
}

// Each convex part's share of the horizontal load (x along `heading_rad`, into the ice) from a structure's
// part_force_n series: its mean, its mean share of the whole and its largest filtered value.
nlohmann::json parts_json(const std::vector<double>& parts, int count, double heading_rad, size_t first, size_t steps,
                          size_t nw) {
  const double c = std::cos(heading_rad), s = std::sin(heading_rad);
  const size_t n = 3 * static_cast<size_t>(count);
  double total = 0;
  std::vector<Stats> mean(count);
  std::vector<std::vector<double>> h(count);
  for (int p = 0; p < count; ++p)
    for (size_t i = first; i < steps; ++i) h[p].push_back(-(c * parts[n * i + 3 * p] + s * parts[n * i + 3 * p + 1]));
  for (int p = 0; p < count; ++p) total += stats_of(h[p]).mean;
  nlohmann::json list = nlohmann::json::array();
  for (int p = 0; p < count; ++p) {
    const Stats sh = stats_of(h[p]), sf = stats_of(moving_average_full_windows(h[p], nw));
    list.push_back({{"part", p},
                    {"horizontal_load_mean_N", sh.mean},
                    {"share_of_mean", total != 0 ? sh.mean / total : 0.0},
                    {"horizontal_load_filtered_max_N", sf.max}});
  }
  return list;
}

// A compliant structure's sway over the steady part (PHYSICS.md 8.3): its velocity over the earth along `along`, its
// amplitude sqrt(2) x the standard deviation (a sine's) and its frequency by the up-crossings of its mean, the
// offset along it, and the natural frequency it is compared with (a structure locked in sways at it with a velocity
// amplitude about the ice's speed).
nlohmann::json sway_json(const std::vector<double>& velocity, const std::vector<double>& offset, const Vec2& along,
                         size_t first, size_t steps, double dt, const CompliantOptions& c) {
  std::vector<double> u, x;
  for (size_t i = first; i < steps; ++i) {
    u.push_back(along.dot(Vec2(velocity[3 * i], velocity[3 * i + 1])));
    x.push_back(along.dot(Vec2(offset[3 * i], offset[3 * i + 1])));
  }
  const Stats su = stats_of(u), sx = stats_of(x);
  size_t up = 0;
  for (size_t i = 1; i < u.size(); ++i) up += u[i - 1] < su.mean && u[i] >= su.mean;
  const double span = dt * static_cast<double>(u.size());
  return {{"velocity_amplitude_mps", std::sqrt(2.0) * su.std},
          {"frequency_hz", span > 0 ? static_cast<double>(up) / span : 0.0},
          {"natural_frequency_hz", c.natural_frequency_hz},
          {"offset_along_drift_m", stats_json(sx)},
          {"what", "the structure's velocity over the earth along the drift: its amplitude (sqrt 2 x its standard "
                   "deviation) and frequency (up-crossings of its mean), and its offset from the station"}};
}

// The unit vector along the ice's drift (earth frame), or along the station's heading without one.
Vec2 drift_along(const SimulateOptions& o, double heading_rad) {
  const Vec2 d = o.drift.velocity();
  return d.norm() > 0 ? Vec2(d.normalized()) : Vec2(std::cos(heading_rad), std::sin(heading_rad));
}

// The loads' part of a structure's summary into j, over the steady part: the horizontal load along the drift fh,
// raw and through the filter (the filter and the steady part stated), the transverse fy, vertical fv and overturning
// my; the horizontal load's cycles; and with level ice (`sheet`, its part from the sheet's tiles) the breaking.
void add_loads_json(const std::vector<double>& fh, const std::vector<double>& fy, const std::vector<double>& fv,
                    const std::vector<double>& my, const std::vector<double>& sheet, const SimulateOptions& o,
                    size_t nw, nlohmann::json& j) {
  const std::vector<double> fh_f = moving_average_full_windows(fh, nw);
  j["filter"] = {{"kind", "centred moving average of the compliant contacts' load (PHYSICS.md 5)"},
                 {"window_s", kFilterS}};
  j["steady_part"] = {{"from_s", o.steady_start_s}, {"to_s", o.duration_s}, {"samples", fh.size()}};
  j["horizontal_load_N"] = stats_json(stats_of(fh));
  j["horizontal_load_mean_interval"] = mean_interval_json(fh, o.time_step_s, stats_of(fh).mean, "N");
  j["horizontal_load_filtered_N"] = stats_json(stats_of(fh_f));
  j["transverse_load_N"] = stats_json(stats_of(fy));
  j["vertical_load_N"] = stats_json(stats_of(fv));
  j["overturning_moment_y_Nm"] = stats_json(stats_of(my));
  j["cycles"] = cycles_json(fh_f, o, nw);
  if (!o.level_ice.extent_m.empty()) {
    const std::vector<double> sheet_f = moving_average_full_windows(sheet, nw);
    j["breaking"] = {{"what", "the part of the horizontal load from the level ice sheet's tiles (ice_load_level_ice): "
                              "the structure breaking the sheet's edge, without the rubble and the broken pieces"},
                     {"load_N", stats_json(stats_of(sheet))},
                     {"load_filtered_N", stats_json(stats_of(sheet_f))},
                     {"cycles", cycles_json(sheet_f, o, nw)}};
  }
}

// The steady part's first step: the first at or after steady_start_s.
size_t steady_first(const SimulateOptions& o, const SeriesSource& series) {
  const std::vector<double> t = series.get("time_s");
  size_t first = 0;
  while (first < t.size() && t[first] < o.steady_start_s - 0.5 * o.time_step_s) ++first;
  return first;
}

}  // namespace

nlohmann::json listed_structure_summary(const SimulateOptions& o, const Model& model, const Results& r,
                                        const SeriesSource& series, size_t k) {
  const StructureOptions& so = o.structures[k];
  const StructureBody& sb = model.structures[k];
  const size_t steps = series.steps(), first = steady_first(o, series);
  auto field = [&](const char* f) -> const std::vector<double>& {
    const auto it = r.structure_series.find(so.name + "/" + f);
    FLOESIM_REQUIRE(it != r.structure_series.end(), "internal: no series ", so.name, "/", f);
    return it->second;
  };
  const std::vector<double>& ice = field("ice_force_n");
  const std::vector<double>& mom = field("ice_moment_nm");
  const std::vector<double>& sheet_series = field("level_ice_force_n");
  // 1. The load in the structure's axes (its heading at the station: x into the ice that comes), earth axes turned.
  const double a = sb.station.heading_rad, c = std::cos(a), s = std::sin(a);
  std::vector<double> fh, fy, fv, my, sheet;
  for (size_t i = first; i < steps; ++i) {
    fh.push_back(-(c * ice[3 * i] + s * ice[3 * i + 1]));
    fy.push_back(-s * ice[3 * i] + c * ice[3 * i + 1]);
    fv.push_back(ice[3 * i + 2]);
    my.push_back(-s * mom[3 * i] + c * mom[3 * i + 1]);
    sheet.push_back(-(c * sheet_series[3 * i] + s * sheet_series[3 * i + 1]));
  }
  const size_t nw = window_samples(kFilterS, o.time_step_s);
  nlohmann::json j;
  j["name"] = so.name;
  j["kind"] = so.body.station_keeping.mode;
  j["reference_point"] = "the structure's axis at the water line (the hull frame's origin)";
  j["axes"] = "the structure's at its station: x along its heading (into the ice that comes), z up";
  add_loads_json(fh, fy, fv, my, sheet, o, nw, j);
  if (j.contains("breaking"))
    j["breaking"]["break_length"] = break_length_json(o, r, HullTracks(o, model, r, series), k + 1);
  // 2. Each part's share.
  j["parts"] = parts_json(field("part_force_n"), sb.part_count, a, first, steps, nw);
  // 3. The rubble: the highest ice within the waterline width of its axis, per stored frame.
  const std::vector<double>& pos = field("position_m");
  const std::vector<double>& quat = field("quaternion_wxyz");
  const double every = o.output_interval_s / o.time_step_s, radius = sb.info.beam_wl_m;
  const Stats hr = stats_of(rubble_heights(r, o.steady_start_s, radius, [&](const FrameReplay&, size_t f) {
    const size_t i = static_cast<size_t>(std::lround((static_cast<double>(f) + 1) * every)) - 1;  // its step's row
    const Quat q(quat[4 * i], quat[4 * i + 1], quat[4 * i + 2], quat[4 * i + 3]);
    const Vec3 x = Vec3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]) - r.frame_time_s[f] * model.frame_velocity;
    return Vec3(x + q * sb.station.reference_point_body);
  }));
  j["rubble_height_m"] = {{"mean", hr.mean}, {"max", hr.max}, {"within_m_of_axis", radius}};
  // 4. How it is held: offsets, the force balance along the drift, the lines' tensions or the thrusters' use; a
  // compliant one's sway.
  const StationKeepingOptions& sk = so.body.station_keeping;
  if (sk.compliant_held()) {
    const Vec2 d = drift_along(o, a);
    j["sway"] = sway_json(field("velocity_mps"), field("offset"), d, first, steps, o.time_step_s, sk.compliant);
  }
  if (sk.moored() || sk.dp_held()) {
    nlohmann::json h = offsets_json(field("offset"), first, steps);
    const Vec2 drift = o.drift.velocity();
    const Vec3 along = drift.norm() > 0 ? Vec3(drift.x(), drift.y(), 0).normalized() : Vec3(c, s, 0);
    const double n = static_cast<double>(steps - first);
    auto mean_along = [&](const std::vector<double>& f) {
      double sum = 0;
      for (size_t i = first; i < steps; ++i) sum += along.dot(Vec3(f[3 * i], f[3 * i + 1], f[3 * i + 2]));
      return sum / n;
    };
    const double ice_m = mean_along(ice), water = mean_along(field("water_force_n"));
    const double held = mean_along(field("station_keeping_force_n"));
    h["force_balance_along_drift_N"] = {{"ice", ice_m},
                                        {"water", water},
                                        {"station_keeping", held},
                                        {"residual", ice_m + water + held},
                                        {"station_keeping_over_loads", -held / (ice_m + water)}};
    if (sk.moored()) {
      const std::vector<double>& t = field("line_tension_n");
      const size_t L = sk.lines.size();
      nlohmann::json lines = nlohmann::json::array();
      double largest = 0;
      for (size_t l = 0; l < L; ++l) {
        std::vector<double> tl;
        for (size_t i = first; i < steps; ++i) tl.push_back(t[L * i + l]);
        const Stats st = stats_of(tl);
        largest = std::max(largest, st.max);
        lines.push_back({{"azimuth_deg", sk.lines[l].azimuth_deg}, {"fairlead_tension_N", stats_json(st)}});
      }
      h["lines"] = lines;
      h["largest_fairlead_tension_N"] = largest;
    } else {
      const std::vector<double>& dem = field("station_keeping_demanded");
      const std::vector<double>& del = field("station_keeping_delivered");
      const double limit[3] = {sk.dp.max_force_x_n, sk.dp.max_force_y_n, sk.dp.max_moment_z_nm};
      const char* axis[3] = {"surge", "sway", "yaw"};
      for (int q = 0; q < 3; ++q) {
        double use = 0, ask = 0;
        for (size_t i = first; i < steps; ++i) {
          use = std::max(use, std::abs(del[3 * i + q]) / limit[q]);
          ask = std::max(ask, std::abs(dem[3 * i + q]) / limit[q]);
        }
        h["thrusters"][axis[q]] = {{"largest_delivered_over_limit", use}, {"largest_demanded_over_limit", ask}};
      }
    }
    j["station_keeping"] = h;
  }
  return j;
}

nlohmann::json structure_summary(const SimulateOptions& o, const Model& model, const Results& r,
                                 const SeriesSource& series) {
  nlohmann::json j;
  const size_t steps = series.steps();
  size_t first = 0;
  {
    const std::vector<double> t = series.get("time_s");
    while (first < steps && t[first] < o.steady_start_s - 0.5 * o.time_step_s) ++first;
  }
  const Vec3 com = model.vessel_info.centre_of_mass_hull;  // body axes are the hull frame's, about this point
  // 1. The load in the structure's axes (x into the ice that comes), about its axis at the water line: the ice's
  // action along its drift is -Fx, the vertical Fz, the overturning moment about y My + (com x F)_y.
  std::vector<double> fh, fv, fy, my;
  {
    const std::vector<double> ice = series.get("ice_load");
    for (size_t i = first; i < steps; ++i) {
      const Vec3 F(ice[6 * i], ice[6 * i + 1], ice[6 * i + 2]);
      const Vec3 M = Vec3(ice[6 * i + 3], ice[6 * i + 4], ice[6 * i + 5]) + com.cross(F);
      fh.push_back(-F.x());
      fy.push_back(F.y());
      fv.push_back(F.z());
      my.push_back(M.y());
    }
  }
  const size_t nw = window_samples(kFilterS, o.time_step_s);
  j["kind"] = o.vessel.station_keeping.mode;
  j["reference_point"] = "the structure's axis at the water line (the hull frame's origin)";
  j["drift_speed_mps"] = o.drift.speed_mps;
  // 2. Load cycles of the filtered horizontal load, and of its part from the level ice sheet (breaking its edge:
  // the cycles of §8.2.4), each against (4-12) h/v.
  std::vector<double> sheet;
  if (!o.level_ice.extent_m.empty()) {
    const std::vector<double> li = series.get("ice_load_level_ice");
    for (size_t i = first; i < steps; ++i) sheet.push_back(-li[6 * i]);
  }
  add_loads_json(fh, fy, fv, my, sheet, o, nw, j);
  if (j.contains("breaking"))
    j["breaking"]["break_length"] = break_length_json(o, r, HullTracks(o, model, r, series), 0);
  // 3. How far across the drift the ice broke, against the sheet's sides: the sides are held (fixed tiles), so they
  // leave no artefact in the loads while no crack comes near them.
  const std::vector<double>& e = o.level_ice.extent_m;
  if (!e.empty() && o.drift.speed_mps > 0) {
    const Vec2 d = o.drift.velocity().normalized(), across(-d.y(), d.x());
    const Vec2 axis = model.station.position.head<2>();
    double farthest = 0;
    for (size_t k = 0; k < r.fracture_time_s.size(); ++k)
      farthest = std::max(farthest, std::abs(across.dot(Vec2(r.fracture_point_m[3 * k], r.fracture_point_m[3 * k + 1]) -
                                                          axis)));
    double side = std::numeric_limits<double>::infinity();  // the nearer side of the sheet across the drift
    for (const Vec2& c : {Vec2(e[0], e[1]), Vec2(e[2], e[1]), Vec2(e[2], e[3]), Vec2(e[0], e[3])})
      side = std::min(side, std::abs(across.dot(c - axis)));
    j["sheet_sides"] = {{"farthest_fracture_across_drift_m", farthest},
                        {"nearer_side_across_drift_m", side},
                        {"margin_m", side - farthest}};
  }
  // 4. The rubble the run shows: the highest ice within the waterline width of the axis, per stored frame.
  const double radius = model.vessel_info.beam_wl_m;
  const Stats hr = stats_of(rubble_heights(r, o.steady_start_s, radius, [&](const FrameReplay& replay, size_t) {
    const int64_t vr = replay.vessel_row();
    const Vec3 xs(r.state_position_m[3 * vr], r.state_position_m[3 * vr + 1], r.state_position_m[3 * vr + 2]);
    const Quat qs(r.state_quaternion[4 * vr], r.state_quaternion[4 * vr + 1], r.state_quaternion[4 * vr + 2],
                  r.state_quaternion[4 * vr + 3]);
    return Vec3(xs - qs * com);  // the hull frame's origin: the structure's axis at the water line
  }));
  j["rubble_height_m"] = {{"mean", hr.mean}, {"max", hr.max}, {"within_m_of_axis", radius},
                          {"what", "the highest ice above the water line near the structure, per stored frame"}};
  // 5. Each convex part's share (the frustum and the neck of a cone), from its recorded loads.
  if (const auto it = r.structure_series.find("vessel/part_force_n"); it != r.structure_series.end())
    j["parts"] = parts_json(it->second, model.bodies[model.vessel].part_count, model.station.heading_rad, first, steps,
                            nw);
  if (o.vessel.station_keeping.moored() || o.vessel.station_keeping.dp_held())
    j["station_keeping"] = station_keeping_summary(o, model, series, first);
  if (o.vessel.station_keeping.compliant_held()) {
    const auto v = r.structure_series.find("vessel/velocity_mps"), x = r.structure_series.find("vessel/offset");
    if (v != r.structure_series.end() && x != r.structure_series.end())
      j["sway"] = sway_json(v->second, x->second, drift_along(o, model.station.heading_rad), first, steps,
                            o.time_step_s, o.vessel.station_keeping.compliant);
  }
  return j;
}

}  // namespace floesim::sim
