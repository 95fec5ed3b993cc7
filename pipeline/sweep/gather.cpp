#include "pipeline/sweep/gather.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "pipeline/error.h"
#include "pipeline/ice_resistance.h"
#include "pipeline/load_series.h"
#include "pipeline/provenance.h"
#include "pipeline/units.h"

namespace floesim::sweep {

namespace fs = std::filesystem;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

SteadyResistance steady_resistance(const Results& r, const std::string& source) {
  SteadyResistance s;
  const std::vector<double>& t = r.get("time_s");
  const std::vector<double> res = surge_ice_resistance_kN(r, source);
  s.time_step_s = uniform_step(t, (source + ": series time_s").c_str());
  s.steady_start_s = recorded_steady_start_s(r, source);
  // The predicate of mean_from, which the plot stage averages with: the same samples, in the same order.
  for (size_t i = 0; i < t.size(); ++i)
    if (t[i] >= s.steady_start_s) s.time_s.push_back(t[i]), s.resistance_kN.push_back(res[i]);
  FLOESIM_REQUIRE(!s.time_s.empty(), source, ": no samples at or after the steady start ", s.steady_start_s,
                  " s (the series ends at ", t.back(), " s)");
  return s;
}

ResistanceStats resistance_stats(const SteadyResistance& s, size_t batches, double peak_window_s) {
  ResistanceStats st;
  const std::vector<double>& x = s.resistance_kN;
  st.steady_start_s = s.steady_start_s;
  st.time_step_s = s.time_step_s;
  st.samples = x.size();
  st.mean_kN = mean_from(s.time_s, x, s.steady_start_s).mean;
  st.batches = batches;
  st.batch_samples = x.size() / batches;
  st.dropped_samples = x.size() - batches * st.batch_samples;
  st.interval = mean_interval(x, s.time_step_s > 0 ? s.time_step_s : 1.0, batches, kConfidence);
  st.batch_means_se_kN = st.interval.standard_error;
  // The peak of the moving average over the steady part itself: windows reaching into the start-up transient
  // would mix it in.
  st.peak_window_s = peak_window_s;
  st.peak_window_samples = window_samples(peak_window_s, s.time_step_s);
  const std::vector<double> ma = moving_average_centred(x, st.peak_window_samples);
  const auto [f0, f1] = full_window_range(x.size(), st.peak_window_samples);
  st.peak_kN = f0 < f1 ? *std::max_element(ma.begin() + static_cast<long>(f0), ma.begin() + static_cast<long>(f1))
                       : kNaN;
  return st;
}

namespace {

// ---- One member ----

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

// The last `n` non-empty lines of a log, joined with " | " (one CSV cell, one line).
std::string log_tail(const fs::path& log, size_t n) {
  std::istringstream in(read_text(log));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    if (!trim(line).empty()) lines.push_back(trim(line));
  std::string out;
  for (size_t i = lines.size() > n ? lines.size() - n : 0; i < lines.size(); ++i)
    out += (out.empty() ? "" : " | ") + lines[i];
  return out;
}

// Milliseconds from a wall_ms file; -1 if it is absent or does not hold one integer >= 0 (then it is not counted:
// a missing time must not make the member fail).
long long read_wall_ms(const fs::path& p) {
  std::error_code ec;
  if (p.empty() || !fs::is_regular_file(p, ec)) return -1;
  const std::string s = trim(read_text(p));
  if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos || s.size() > 15) return -1;
  return std::stoll(s);
}

double summary_number(const Json& s, const char* key, const fs::path& file) {
  FLOESIM_REQUIRE(s.contains(key) && s[key].is_number(), file.string(), ": ", key,
                  s.contains(key) ? " is not a number" : " is missing", " (was it written by floesim-simulate?)");
  return s[key].get<double>();
}

// Fracture event counts: 0 when the summary has no fracture section or fracture was disabled.
void fracture_counts(const Json& s, const fs::path& file, MemberResult& m) {
  if (!s.contains("fracture")) return;
  const Json& f = s["fracture"];
  FLOESIM_REQUIRE(f.is_object(), file.string(), ": fracture must be an object");
  if (f.contains("enabled")) {
    FLOESIM_REQUIRE(f["enabled"].is_boolean(), file.string(), ": fracture.enabled must be true or false");
    if (!f["enabled"].get<bool>()) return;
  }
  if (!f.contains("events")) return;
  const Json& e = f["events"];
  FLOESIM_REQUIRE(e.is_object(), file.string(), ": fracture.events must be an object");
  for (auto [key, out] : {std::pair<const char*, int64_t*>{"bending", &m.fracture_bending},
                          {"radial", &m.fracture_radial},
                          {"splitting", &m.fracture_splitting}}) {
    if (!e.contains(key)) continue;
    FLOESIM_REQUIRE(e[key].is_number_integer(), file.string(), ": fracture.events.", key,
                    " must be an integer, got ", e[key].dump());
    *out = e[key].get<int64_t>();
  }
}

// Level ice: both formulas at the member's mean speed, for its hull and the sheet's ice as the summary gives it
// (the area-weighted mean thickness). A hull the formulas cannot take (a bulb: Lindqvist refuses phi >= 90 deg) or a
// hull.json without particulars leaves them NaN with the reason; the member stays ok.
void level_ice_reference(const Json& s, const PlanMember& pm, MemberResult& m) {
  m.lindqvist_kN = m.riska_kN = m.channel_width_over_beam = kNaN;
  if (!s.contains("level_ice") || !s["level_ice"].is_object() || !s["level_ice"].contains("ice")) return;
  m.level_ice = true;
  const Json& li = s["level_ice"];
  if (li.contains("channel") && li["channel"].is_object() && li["channel"].contains("width_over_beam") &&
      li["channel"]["width_over_beam"].is_number())
    m.channel_width_over_beam = li["channel"]["width_over_beam"].get<double>();
  try {
    fs::path hull_json;
    for (const PlanStage& st : pm.stages)
      if (st.name == "hull")
        for (const fs::path& o : st.outputs)
          if (o.extension() == ".obj") hull_json = fs::path(o).replace_extension(".json");
    FLOESIM_REQUIRE(!hull_json.empty(), "the plan gives member ", pm.id, " no hull stage with an OBJ");
    const LevelIce l = level_ice_from_json(li["ice"], pm.summary.string() + ": level_ice.ice");
    const IceHull hull = read_ice_hull(hull_json);
    m.lindqvist_kN = lindqvist(hull, l, m.mean_speed_mps).total_n / 1000.0;
    m.riska_kN = riska(hull, l.thickness_m, m.mean_speed_mps).total_n / 1000.0;
  } catch (const Error& e) {
    m.lindqvist_kN = m.riska_kN = kNaN;
    m.reference_error = e.what();
  }
}

MemberResult gather_member(const PlanMember& pm, SteadyResistance& series) {
  MemberResult m;
  m.id = pm.id;
  m.grid_point = pm.grid_point;
  m.ensemble_index = pm.ensemble_index;

  // 1. Wall time: the stages that recorded one (also for a failed member: how long it ran).
  long long ms = 0;
  bool timed = false;
  for (const PlanStage& s : pm.stages)
    if (const long long w = read_wall_ms(s.wall_ms); w >= 0) ms += w, timed = true;
  m.wall_s = timed ? static_cast<double>(ms) / 1000.0 : kNaN;

  // 2. The summary and the results; any problem makes the member failed, not the gather.
  std::string read_error;
  try {
    const Json s = load_json_file(pm.summary);
    FLOESIM_REQUIRE(s.is_object(), pm.summary.string(), ": a summary must be a JSON object");
    m.mean_resistance_kN = summary_number(s, "mean_surge_ice_resistance_N", pm.summary) / 1000.0;
    m.mean_speed_mps = summary_number(s, "mean_vessel_speed_mps", pm.summary);
    fracture_counts(s, pm.summary, m);
    level_ice_reference(s, pm, m);
    const Results r = read_results(pm.results, /*with_states=*/false);
    series = steady_resistance(r, pm.results.string());
    m.series = resistance_stats(series);
    m.ok = true;
    return m;
  } catch (const Error& e) {
    read_error = e.what();
  }

  // 3. Failed: why. The first stage (in run order) that did not make all its outputs and left a log says it.
  m.mean_resistance_kN = m.mean_speed_mps = kNaN;
  m.lindqvist_kN = m.riska_kN = m.channel_width_over_beam = kNaN;
  m.fracture_bending = m.fracture_radial = m.fracture_splitting = 0;
  m.series = ResistanceStats{};
  m.series.mean_kN = m.series.batch_means_se_kN = m.series.peak_kN = kNaN;
  std::error_code ec;
  for (const PlanStage& s : pm.stages) {
    const bool complete =
        std::all_of(s.outputs.begin(), s.outputs.end(), [&](const fs::path& o) { return fs::exists(o, ec); });
    if (complete || s.log.empty() || !fs::is_regular_file(s.log, ec)) continue;
    m.failed_stage = s.name;
    m.failed_log = s.log;
    m.error = log_tail(s.log, kErrorLogLines);
    if (m.error.empty()) m.error = "stage " + s.name + " did not finish and its log " + s.log.string() + " is empty";
    return m;
  }
  // No stage says why: the files are there but unreadable (say what is wrong with them), or nothing ran.
  m.error = fs::exists(pm.summary, ec) && fs::exists(pm.results, ec) ? read_error : "not run";
  return m;
}

// ---- The tables ----

// Shortest text that reads back as the same double (as nlohmann::json writes it: a member's mean speed reads
// byte for byte as in its summary.json); empty for NaN (a failed member, or no value).
std::string number_text(double x) { return std::isfinite(x) ? Json(x).dump() : std::string(); }
Json json_number(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

// RFC 4180: a field with a comma, quote or line break is quoted, quotes doubled; `always` quotes a non-empty one.
std::string csv_field(const std::string& s, bool always = false) {
  if (s.empty() || (!always && s.find_first_of(",\"\r\n") == std::string::npos)) return s;
  std::string out = "\"";
  for (char ch : s) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

const std::vector<std::string> kResultColumns = {
    "mean_surge_ice_resistance_kN", "batch_means_se_kN", "mean_speed_mps",   "peak_0.5s_resistance_kN",
    "fracture_bending",             "fracture_radial",   "fracture_splitting", "wall_s",
    "status",                       "error"};
// Level ice sweeps (a member's summary has level_ice.ice): PHYSICS.md §6's formulas at the member's mean speed.
const std::vector<std::string> kLevelIceColumns = {"lindqvist_kN",  "riska_kN", "ratio_to_lindqvist",
                                                   "ratio_to_riska", "channel_width_over_beam", "reference_error"};

}  // namespace

std::string ci_text(const ConfidenceInterval& ci, double scale) {
  if (ci.n == 0) return "no member ok";
  if (ci.n == 1) return fmt("%.4g", scale * ci.mean) + " (one member: no interval)";
  return fmt("%.4g", scale * ci.mean) + " ± " + fmt("%.3g", scale * ci.half_width);
}

GatherResult gather_members(const SweepPlan& plan) {
  GatherResult g;
  // 1. Columns: the member, its axis values, what its ensemble seeded (union over members, sorted), the results.
  std::set<std::string> seed_keys;
  for (const PlanMember& m : plan.members)
    for (auto it = m.seeds.begin(); it != m.seeds.end(); ++it) seed_keys.insert(it.key());
  g.seed_keys.assign(seed_keys.begin(), seed_keys.end());
  g.columns = {"member", "grid_point", "ensemble_index"};
  for (const PlanAxis& a : plan.axes) g.columns.push_back(a.key);
  g.columns.insert(g.columns.end(), seed_keys.begin(), seed_keys.end());
  g.columns.insert(g.columns.end(), kResultColumns.begin(), kResultColumns.end());

  // 2. The members, in plan order; the first ok one's series is kept for the running-mean plot.
  for (const PlanMember& pm : plan.members) {
    SteadyResistance s;
    g.members.push_back(gather_member(pm, s));
    if (g.members.back().ok && g.first_ok < 0) {
      g.first_ok = static_cast<int>(g.members.size()) - 1;
      g.first_series = std::move(s);
    }
  }

  // Level ice: the formulas beside the simulated means (columns only when a member ran in level ice).
  g.level_ice = std::any_of(g.members.begin(), g.members.end(), [](const MemberResult& m) {
    return m.level_ice;
  });
  if (g.level_ice) g.columns.insert(g.columns.end(), kLevelIceColumns.begin(), kLevelIceColumns.end());

  // 3. Ensemble statistics per grid point, over its ok members (the ensemble members are independent runs).
  for (const PlanGridPoint& p : plan.grid_points) {
    GridPointResult gp;
    gp.index = p.index;
    gp.axes = p.axes;
    std::vector<double> means;
    for (const MemberResult& m : g.members)
      if (m.grid_point == p.index) {
        ++gp.n_members;
        if (m.ok) means.push_back(m.mean_resistance_kN);
      }
    gp.ci = student_t_interval(means, kConfidence);
    gp.half_width_kN = gp.ci.half_width;
    gp.interval_method = gp.ci.n >= 2 ? "Student t over the ok members" : "none: no member ok";
    if (gp.ci.n == 1)
      for (const MemberResult& m : g.members)
        if (m.grid_point == p.index && m.ok) {
          gp.half_width_kN = m.series.interval.half_width;
          gp.interval_method = "batch means of its one member" +
                               (m.series.interval.meaningful ? std::string() : " (" + m.series.interval.note + ")");
        }
    g.grid_points.push_back(std::move(gp));
  }

  return g;
}

SweepTables sweep_tables(const SweepPlan& plan, const fs::path& plan_file, const GatherResult& g) {
  // 4. Provenance: the plan, and the summary and results of every member gathered.
  std::vector<NamedInput> inputs = {{"plan", plan_file}};
  for (size_t i = 0; i < plan.members.size(); ++i)
    if (g.members[i].ok) {
      inputs.push_back({"summary " + plan.members[i].id, plan.members[i].summary});
      inputs.push_back({"results " + plan.members[i].id, plan.members[i].results});
    }
  const Json config = {{"batch_means_batches", kBatchMeansBatches},
                       {"peak_window_s", kPeakWindowS},
                       {"confidence", kConfidence},
                       {"error_log_lines", kErrorLogLines}};
  const Json provenance = make_provenance("floesim-gather", inputs, config);

  // 5. The table, as CSV and JSON rows.
  std::ostringstream csv;
  for (size_t c = 0; c < g.columns.size(); ++c) csv << (c ? "," : "") << csv_field(g.columns[c]);
  csv << '\n';
  Json rows = Json::array(), failed = Json::array();
  for (size_t i = 0; i < plan.members.size(); ++i) {
    const PlanMember& pm = plan.members[i];
    const MemberResult& m = g.members[i];
    std::vector<std::string> cells = {csv_field(m.id), std::to_string(m.grid_point),
                                      std::to_string(m.ensemble_index)};
    Json row = {{"member", m.id}, {"grid_point", m.grid_point}, {"ensemble_index", m.ensemble_index}};
    for (const PlanAxis& a : plan.axes) {
      cells.push_back(csv_field(value_text(pm.axes[a.key])));
      row[a.key] = pm.axes[a.key];
    }
    for (const std::string& key : g.seed_keys) {
      const bool has = pm.seeds.contains(key);
      cells.push_back(has ? csv_field(value_text(pm.seeds[key])) : std::string());
      row[key] = has ? pm.seeds[key] : Json(nullptr);
    }
    auto count = [&](int64_t v) { return m.ok ? std::to_string(v) : std::string(); };
    cells.insert(cells.end(), {number_text(m.mean_resistance_kN), number_text(m.series.batch_means_se_kN),
                               number_text(m.mean_speed_mps), number_text(m.series.peak_kN),
                               count(m.fracture_bending), count(m.fracture_radial), count(m.fracture_splitting),
                               number_text(m.wall_s), m.ok ? "ok" : "failed", csv_field(m.error, true)});
    const double to_l = m.mean_resistance_kN / m.lindqvist_kN, to_r = m.mean_resistance_kN / m.riska_kN;
    if (g.level_ice)
      cells.insert(cells.end(), {number_text(m.lindqvist_kN), number_text(m.riska_kN), number_text(to_l),
                                 number_text(to_r), number_text(m.channel_width_over_beam),
                                 csv_field(m.reference_error, true)});
    for (size_t c = 0; c < cells.size(); ++c) csv << (c ? "," : "") << cells[c];
    csv << '\n';
    row["mean_surge_ice_resistance_kN"] = json_number(m.mean_resistance_kN);
    row["batch_means_se_kN"] = json_number(m.series.batch_means_se_kN);
    row["mean_speed_mps"] = json_number(m.mean_speed_mps);
    row["peak_0.5s_resistance_kN"] = json_number(m.series.peak_kN);
    row["fracture_bending"] = m.ok ? Json(m.fracture_bending) : Json(nullptr);
    row["fracture_radial"] = m.ok ? Json(m.fracture_radial) : Json(nullptr);
    row["fracture_splitting"] = m.ok ? Json(m.fracture_splitting) : Json(nullptr);
    row["wall_s"] = json_number(m.wall_s);
    row["status"] = m.ok ? "ok" : "failed";
    row["error"] = m.error;
    if (g.level_ice) {
      row["lindqvist_kN"] = json_number(m.lindqvist_kN);
      row["riska_kN"] = json_number(m.riska_kN);
      row["ratio_to_lindqvist"] = json_number(to_l);
      row["ratio_to_riska"] = json_number(to_r);
      row["channel_width_over_beam"] = json_number(m.channel_width_over_beam);
      row["reference_error"] = m.reference_error;
    }
    // Not a CSV column: how the standard error and the peak were taken from the series.
    if (m.ok)
      row["steady_series"] = {{"steady_start_s", m.series.steady_start_s},
                              {"time_step_s", m.series.time_step_s},
                              {"samples", m.series.samples},
                              {"mean_kN", m.series.mean_kN},
                              {"batches", m.series.batches},
                              {"batch_samples", m.series.batch_samples},
                              {"dropped_samples_at_start", m.series.dropped_samples},
                              {"peak_window_s", m.series.peak_window_s},
                              {"peak_window_samples", m.series.peak_window_samples}};
    rows.push_back(row);
    if (!m.ok)
      failed.push_back({{"member", m.id},
                        {"error", m.error},
                        {"stage", m.failed_stage.empty() ? Json(nullptr) : Json(m.failed_stage)},
                        {"log", m.failed_log.empty() ? Json(nullptr) : Json(m.failed_log.string())}});
  }
  Json grid = Json::array();
  for (const GridPointResult& gp : g.grid_points)
    grid.push_back({{"index", gp.index},
                    {"axes", gp.axes},
                    {"n_members", gp.n_members},
                    {"n_ok", gp.ci.n},
                    {"mean_kN", json_number(gp.ci.mean)},
                    {"std_kN", json_number(gp.ci.std)},
                    {"ci95_half_width_kN", json_number(gp.half_width_kN)},
                    {"interval", gp.interval_method},
                    {"t_quantile", json_number(gp.ci.t_quantile)}});
  Json axes = Json::array();
  for (const PlanAxis& a : plan.axes)
    axes.push_back({{"key", a.key}, {"label", axis_title(a)}, {"unit", a.unit}, {"doc", a.doc}, {"values", a.values}});

  const Json out = {
      {"format", "floesim-sweep-results/1"},
      {"name", plan.name},
      {"sweep_file", plan.sweep_file},
      {"axes", axes},
      {"ensemble", plan.ensemble},
      {"columns", g.columns},
      {"units",
       {{"mean_surge_ice_resistance_kN", "kN: summary.json mean_surge_ice_resistance_N / 1000"},
        {"batch_means_se_kN",
         "kN: standard error of that mean by batch means over the steady part of -Fx (" +
             std::to_string(kBatchMeansBatches) + " equal batches, the remainder dropped at the start)"},
        {"mean_speed_mps", "m/s: summary.json mean_vessel_speed_mps"},
        {"peak_0.5s_resistance_kN", "kN: largest 0.5 s centred moving average over the steady part, full windows"},
        {"wall_s", "s: sum of the stages' recorded wall times"},
        {"ci95_half_width_kN",
         "kN: Student t 0.975 quantile (n_ok - 1 degrees of freedom) x std / sqrt(n_ok); for a point of one ok "
         "member, its batch-means interval (t with batches - 1 degrees of freedom x batch_means_se_kN)"}}},
      {"members", rows},
      {"grid_points", grid},
      {"failed", failed},
      {"files", g.files},
      {"provenance", provenance},
  };
  return {csv.str(), out.dump(2) + "\n"};
}

std::string gather_table(const SweepPlan& plan, const GatherResult& g) {
  size_t ok = 0;
  for (const MemberResult& m : g.members) ok += m.ok;
  std::ostringstream os;
  os << "sweep " << plan.name << ": " << g.grid_points.size() << " grid point" << (g.grid_points.size() == 1 ? "" : "s")
     << ", " << g.members.size() << " member" << (g.members.size() == 1 ? "" : "s") << ": " << ok << " ok, "
     << g.members.size() - ok << " failed\n";
  // Columns: grid point, one per axis, mean +- 95 % CI, ok/n; each as wide as its widest cell.
  std::vector<std::vector<std::string>> rows = {{"grid"}};
  for (const PlanAxis& a : plan.axes) rows[0].push_back(a.key);
  rows[0].insert(rows[0].end(), {"mean resistance ± 95 % CI (kN)", "ok/n"});
  for (const GridPointResult& gp : g.grid_points) {
    std::vector<std::string> r = {std::to_string(gp.index)};
    for (const PlanAxis& a : plan.axes) r.push_back(value_text(gp.axes[a.key]));
    r.push_back(gp.ci.n == 1 && std::isfinite(gp.half_width_kN)
                    ? fmt("%.4g", gp.ci.mean) + " ± " + fmt("%.3g", gp.half_width_kN) + " (one member: batch means)"
                    : ci_text(gp.ci));
    r.push_back(std::to_string(gp.ci.n) + "/" + std::to_string(gp.n_members));
    rows.push_back(r);
  }
  // Widths in characters, not bytes ("±" is two bytes in UTF-8).
  auto width = [](const std::string& s) {
    return static_cast<size_t>(std::count_if(s.begin(), s.end(), [](char ch) { return (ch & 0xC0) != 0x80; }));
  };
  std::vector<size_t> w(rows[0].size(), 0);
  for (const auto& r : rows)
    for (size_t c = 0; c < r.size(); ++c) w[c] = std::max(w[c], width(r[c]));
  for (const auto& r : rows) {
    std::string line;
    for (size_t c = 0; c < r.size(); ++c)
      line += r[c] + (c + 1 < r.size() ? std::string(w[c] - width(r[c]) + 2, ' ') : "");
    os << "  " << line << '\n';
  }
  if (ok < g.members.size()) {
    os << "failed members:\n";
    for (const MemberResult& m : g.members)
      if (!m.ok) os << "  " << m.id << (m.failed_stage.empty() ? "" : " (" + m.failed_stage + ")") << ": " << m.error
                    << '\n';
  }
  return os.str();
}

}  // namespace floesim::sweep
