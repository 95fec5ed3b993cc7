#include "render/gather.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/ice_resistance.h"
#include "pipeline/provenance.h"
#include "pipeline/units.h"
#include "render/gnuplot.h"
#include "render/plot.h"

namespace floesim::render {

namespace fs = std::filesystem;

namespace {

constexpr double kConfidence = 0.95;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---- Reading the plan ----

// Collects every problem of a plan, each with its key path, and throws them together (like OptionReader).
class PlanChecker {
 public:
  PlanChecker(std::string file, fs::path dir) : file_(std::move(file)), dir_(std::move(dir)) {}

  void problem(const std::string& where, const std::string& what) { problems_.push_back(where + " " + what); }

  // o[key] if o is an object holding it, else nullptr (and a problem if `required`).
  const Json* find(const Json& o, const std::string& where, const char* key, bool required, const char* hint) {
    if (o.is_object() && o.contains(key)) return &o[key];
    if (required) problem(path(where, key), std::string("is missing") + hint);
    return nullptr;
  }
  bool text(const Json& o, const std::string& where, const char* key, std::string& out, bool required,
            const char* hint = "") {
    const Json* j = find(o, where, key, required, hint);
    if (!j) return false;
    if (!j->is_string() || j->get<std::string>().empty()) {
      problem(path(where, key), "must be a non-empty string, got " + j->dump());
      return false;
    }
    out = j->get<std::string>();
    return true;
  }
  // A path; relative ones are taken from the plan's folder.
  bool file(const Json& o, const std::string& where, const char* key, fs::path& out, bool required,
            const char* hint = "") {
    std::string s;
    if (!text(o, where, key, s, required, hint)) return false;
    out = fs::path(s).is_relative() ? dir_ / s : fs::path(s);
    return true;
  }
  bool index(const Json& o, const std::string& where, const char* key, size_t& out) {
    const Json* j = find(o, where, key, true, "");
    if (!j) return false;
    if (!j->is_number_integer() || j->get<int64_t>() < 0) {
      problem(path(where, key), "must be an integer >= 0, got " + j->dump());
      return false;
    }
    out = j->get<size_t>();
    return true;
  }
  // An object of key -> scalar (number, string or boolean).
  bool scalars(const Json& o, const std::string& where, const char* key, Json& out, bool required) {
    const Json* j = find(o, where, key, required, "");
    if (!j) return false;
    if (!j->is_object()) {
      problem(path(where, key), "must be an object of key -> value, got " + j->dump());
      return false;
    }
    bool ok = true;
    for (auto it = j->begin(); it != j->end(); ++it)
      if (!(it->is_number() || it->is_string() || it->is_boolean())) {
        problem(path(path(where, key), it.key().c_str()), "must be a number, a string or a boolean, got " +
                                                               it->dump());
        ok = false;
      }
    if (ok) out = *j;
    return ok;
  }

  void finish() const {
    if (problems_.empty()) return;
    std::ostringstream os;
    os << file_ << ": " << problems_.size() << " problem" << (problems_.size() > 1 ? "s" : "")
       << " in the sweep plan:";
    for (const auto& p : problems_) os << "\n  - " << p;
    throw Error(os.str());
  }

  static std::string path(const std::string& where, const char* key) {
    return where.empty() ? key : where + "." + key;
  }
  static std::string item(const std::string& where, size_t i) { return where + "[" + std::to_string(i) + "]"; }

 private:
  std::string file_;
  fs::path dir_;
  std::vector<std::string> problems_;
};

// A value as text: strings as they are, numbers and booleans as JSON writes them.
std::string value_text(const Json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

}  // namespace

SweepPlan read_sweep_plan(const fs::path& file) {
  const Json j = load_json_file(file);
  const std::string f = file.string();
  FLOESIM_REQUIRE(j.is_object(), f, ": a sweep plan must be a JSON object");
  // The format first: a plan of another format would only give misleading problems below.
  FLOESIM_REQUIRE(j.contains("format") && j["format"].is_string(), f, ": format is missing; expected \"",
                  kSweepPlanFormat, "\" (is this a plan written by floesim sweep?)");
  const std::string format = j["format"].get<std::string>();
  FLOESIM_REQUIRE(format == kSweepPlanFormat, f, ": format is \"", format, "\"; this floesim-gather reads \"",
                  kSweepPlanFormat, "\" (rerun floesim sweep with this build, or gather with the build that wrote "
                  "the plan)");

  PlanChecker c(f, file.parent_path());
  SweepPlan p;
  c.text(j, "", "name", p.name, true, " (the sweep's name)");
  c.text(j, "", "sweep_file", p.sweep_file, false);
  if (j.contains("ensemble")) p.ensemble = j["ensemble"];

  // 1. Axes: unique keys, non-empty lists of scalar values.
  std::set<std::string> axis_keys;
  if (const Json* axes = c.find(j, "", "axes", true, " (use [] for a pure ensemble)")) {
    if (!axes->is_array()) c.problem("axes", "must be an array, got " + axes->dump());
    for (size_t i = 0; axes->is_array() && i < axes->size(); ++i) {
      const std::string w = PlanChecker::item("axes", i);
      PlanAxis a;
      if (!c.text((*axes)[i], w, "key", a.key, true)) continue;
      if (!axis_keys.insert(a.key).second) c.problem(PlanChecker::path(w, "key"), "\"" + a.key + "\" repeats an axis");
      const Json* v = c.find((*axes)[i], w, "values", true, "");
      if (v && (!v->is_array() || v->empty())) c.problem(PlanChecker::path(w, "values"), "must be a non-empty array");
      for (size_t k = 0; v && v->is_array() && k < v->size(); ++k) {
        const Json& x = (*v)[k];
        if (!(x.is_number() || x.is_string() || x.is_boolean()))
          c.problem(PlanChecker::item(PlanChecker::path(w, "values"), k),
                    "must be a number, a string or a boolean, got " + x.dump());
        else
          a.values.push_back(x);
      }
      p.axes.push_back(std::move(a));
    }
  }
  // Every axis key with a value from its list, and nothing else.
  auto check_axis_values = [&](const Json& values, const std::string& where) {
    for (const PlanAxis& a : p.axes) {
      if (!values.contains(a.key)) {
        c.problem(where, "has no value for the axis \"" + a.key + "\"");
        continue;
      }
      if (std::find(a.values.begin(), a.values.end(), values[a.key]) == a.values.end())
        c.problem(PlanChecker::path(where, a.key.c_str()),
                  "is " + values[a.key].dump() + ", which is not among the axis's values");
    }
    for (auto it = values.begin(); it != values.end(); ++it)
      if (!axis_keys.count(it.key())) c.problem(where, "has a value for \"" + it.key() + "\", which is not an axis");
  };

  // 2. Grid points, listed in index order (members refer to them by index).
  if (const Json* gps = c.find(j, "", "grid_points", true, "")) {
    if (!gps->is_array() || gps->empty()) c.problem("grid_points", "must be a non-empty array");
    for (size_t i = 0; gps->is_array() && i < gps->size(); ++i) {
      const std::string w = PlanChecker::item("grid_points", i);
      PlanGridPoint g;
      if (c.index((*gps)[i], w, "index", g.index) && g.index != i)
        c.problem(PlanChecker::path(w, "index"), "is " + std::to_string(g.index) +
                                                     "; grid points must be listed in index order (0, 1, 2, ...)");
      if (c.scalars((*gps)[i], w, "axes", g.axes, true)) check_axis_values(g.axes, PlanChecker::path(w, "axes"));
      p.grid_points.push_back(std::move(g));
    }
    if (p.axes.empty() && p.grid_points.size() > 1)
      c.problem("grid_points", "has " + std::to_string(p.grid_points.size()) +
                                   " points, but with no axes (a pure ensemble) there is exactly one");
  }

  // 3. Members.
  std::set<std::string> ids;
  if (const Json* ms = c.find(j, "", "members", true, "")) {
    if (!ms->is_array() || ms->empty()) c.problem("members", "must be a non-empty array");
    for (size_t i = 0; ms->is_array() && i < ms->size(); ++i) {
      const Json& mj = (*ms)[i];
      const std::string w = PlanChecker::item("members", i);
      if (!mj.is_object()) {
        c.problem(w, "must be an object, got " + mj.dump());
        continue;
      }
      PlanMember m;
      if (c.text(mj, w, "id", m.id, true) && !ids.insert(m.id).second)
        c.problem(PlanChecker::path(w, "id"), "\"" + m.id + "\" repeats a member id");
      if (c.index(mj, w, "grid_point", m.grid_point) && m.grid_point >= p.grid_points.size())
        c.problem(PlanChecker::path(w, "grid_point"),
                  "is " + std::to_string(m.grid_point) + ", but the grid points are 0 to " +
                      std::to_string(static_cast<long long>(p.grid_points.size()) - 1));
      c.index(mj, w, "ensemble_index", m.ensemble_index);
      if (c.scalars(mj, w, "axes", m.axes, true) && m.grid_point < p.grid_points.size() &&
          m.axes != p.grid_points[m.grid_point].axes)
        c.problem(PlanChecker::path(w, "axes"), "are " + m.axes.dump() + ", but its grid point " +
                                                    std::to_string(m.grid_point) + " has " +
                                                    p.grid_points[m.grid_point].axes.dump());
      if (c.scalars(mj, w, "seeds", m.seeds, false))
        for (auto it = m.seeds.begin(); it != m.seeds.end(); ++it)
          if (axis_keys.count(it.key()))
            c.problem(PlanChecker::path(w, "seeds"), "sets \"" + it.key() + "\", which is also an axis");
      c.file(mj, w, "dir", m.dir, false);
      c.file(mj, w, "summary", m.summary, true, " (the path of the member's summary.json)");
      c.file(mj, w, "results", m.results, true, " (the path of the member's results.h5)");
      if (const Json* st = c.find(mj, w, "stages", false, "")) {
        if (!st->is_array()) c.problem(PlanChecker::path(w, "stages"), "must be an array, got " + st->dump());
        for (size_t k = 0; st->is_array() && k < st->size(); ++k) {
          const Json& sj = (*st)[k];
          const std::string ws = PlanChecker::item(PlanChecker::path(w, "stages"), k);
          PlanStage s;
          c.text(sj, ws, "name", s.name, true);
          c.file(sj, ws, "log", s.log, false);
          c.file(sj, ws, "wall_ms", s.wall_ms, false);
          if (const Json* out = c.find(sj, ws, "outputs", true, " (the files the stage makes)")) {
            if (!out->is_array()) c.problem(PlanChecker::path(ws, "outputs"), "must be an array of paths");
            for (size_t o = 0; out->is_array() && o < out->size(); ++o) {
              const Json& oj = (*out)[o];
              if (!oj.is_string() || oj.get<std::string>().empty()) {
                c.problem(PlanChecker::item(PlanChecker::path(ws, "outputs"), o),
                          "must be a non-empty string, got " + oj.dump());
                continue;
              }
              const fs::path op = oj.get<std::string>();
              s.outputs.push_back(op.is_relative() ? file.parent_path() / op : op);
            }
          }
          m.stages.push_back(std::move(s));
        }
      }
      p.members.push_back(std::move(m));
    }
  }
  c.finish();
  return p;
}

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
  st.batch_means_se_kN = x.size() >= batches ? batch_means_standard_error(x, batches) : kNaN;
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

// ---- Writing ----

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

std::string fmt(const char* f, double a) {
  char b[64];
  std::snprintf(b, sizeof b, f, a);
  return b;
}

// A file name part from a key: "simulate.vessel.y_m" -> "simulate_vessel_y_m".
std::string file_part(const std::string& key) {
  std::string s = key;
  for (char& ch : s)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-')) ch = '_';
  return s;
}

const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
const char* colour(size_t i) { return kColours[i % (sizeof kColours / sizeof *kColours)]; }

// One plot's files: the images (committed with the rest) and its working files (never committed, so removed).
struct PlotFiles {
  PlotFiles(const fs::path& dir, const std::string& stem)
      : png(dir / (stem + ".png")),
        svg(dir / (stem + ".svg")),
        data(dir / (stem + ".plot-data.txt")),
        script(dir / (stem + ".plot.gp")),
        log(dir / (stem + ".gnuplot.log")),
        stem(stem) {}
  AtomicFile png, svg, data, script, log;
  std::string stem;

  // The terminal lines around `body` (the set-up and the plot command), PNG then the same plot as SVG.
  void draw(const std::string& body, const std::string& data_text) {
    write_text_atomic_tmp(data, data_text);
    std::ostringstream gp;
    gp << "set encoding utf8\n"
       << "set terminal pngcairo size 1100,700 enhanced font 'DejaVu Sans,11' linewidth 1.0\n"
       << "set output " << gnuplot_quoted(png.tmp().string()) << "\n"
       << "set border lc rgb '#404040'\n"
       << "set grid xtics ytics lc rgb '#d9d9d9' lw 1 dt 1\n"
       << "set key outside below center horizontal samplen 2.5\n"
       << "set style textbox opaque fillcolor rgb 'white' border lc rgb '#b0b0b0' margins 4,3\n"
       << "data = " << gnuplot_quoted(data.tmp().string()) << "\n"
       << body << "\n"
       << "set terminal svg size 1100,700 dynamic enhanced font 'DejaVu Sans,11' background rgb 'white'\n"
       << "set output " << gnuplot_quoted(svg.tmp().string()) << "\n"
       << "replot\n"
       << "unset output\n";
    write_text_atomic_tmp(script, gp.str());
    run_gnuplot(script.tmp(), log.tmp(), {png.tmp(), svg.tmp()}, png.path().string());
  }
  static void write_text_atomic_tmp(const AtomicFile& f, const std::string& text) {
    write_file_checked(f.tmp(), text, f.path());
  }
};

std::string ci_text(const ConfidenceInterval& ci, double scale = 1.0) {
  if (ci.n == 0) return "no member ok";
  if (ci.n == 1) return fmt("%.4g", scale * ci.mean) + " (one member: no interval)";
  return fmt("%.4g", scale * ci.mean) + " ± " + fmt("%.3g", scale * ci.half_width);
}

// The plots' load unit (pipeline/units.h: N for a sweep of tank models, kN for ships) from the members' means, in
// kN; and the factor from kN to it.
ForceUnit plot_unit(const GatherResult& g, double* kN_to_unit) {
  double typical_kN = 0;
  for (const MemberResult& m : g.members)
    if (m.ok && std::isfinite(m.mean_resistance_kN)) typical_kN = std::max(typical_kN, std::abs(m.mean_resistance_kN));
  const ForceUnit u = force_unit_for(1000.0 * typical_kN);
  *kN_to_unit = 1000.0 / u.newtons;
  return u;
}

// Mean resistance against axis k: a line per combination of the other axes' values, 95 % CI error bars, the
// members as open circles. Non-numeric axes are categories, placed in the plan's order.
void draw_axis_plot(const SweepPlan& plan, const GatherResult& g, size_t k, PlotFiles& f) {
  const PlanAxis& ax = plan.axes[k];
  const bool numeric = std::all_of(ax.values.begin(), ax.values.end(), [](const Json& v) { return v.is_number(); });
  auto x_of = [&](const Json& v) {
    return numeric ? v.get<double>()
                   : static_cast<double>(std::find(ax.values.begin(), ax.values.end(), v) - ax.values.begin());
  };
  // 1. Lines: grid points grouped by their other axes' values, in order of first appearance.
  std::vector<std::string> labels;
  std::vector<std::vector<size_t>> lines;
  for (const GridPointResult& gp : g.grid_points) {
    std::string label;
    for (size_t a = 0; a < plan.axes.size(); ++a)
      if (a != k)
        label += (label.empty() ? "" : ", ") + plan.axes[a].key + " = " + value_text(gp.axes[plan.axes[a].key]);
    if (label.empty()) label = "ensemble mean";
    const size_t i = std::find(labels.begin(), labels.end(), label) - labels.begin();
    if (i == labels.size()) labels.push_back(label), lines.emplace_back();
    lines[i].push_back(gp.index);
  }
  // 2. Data: per line, a block of (x, mean, low, high) sorted by x, then a block of its members (x, mean). A grid
  // point without an interval (one ok member) has its bar collapsed onto the mean; one without ok members is left
  // out.
  double to_unit = 1;
  const ForceUnit unit = plot_unit(g, &to_unit);
  std::ostringstream data, plot;
  int block = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    std::vector<const GridPointResult*> pts;
    for (size_t gi : lines[i])
      if (g.grid_points[gi].ci.n > 0) pts.push_back(&g.grid_points[gi]);
    if (pts.empty()) continue;
    std::sort(pts.begin(), pts.end(),
              [&](auto* a, auto* b) { return x_of(a->axes[ax.key]) < x_of(b->axes[ax.key]); });
    if (block > 0) data << "\n\n";
    for (const GridPointResult* p : pts) {
      const double hw = p->ci.n >= 2 ? p->ci.half_width : 0.0;
      data << fmt("%.10g", x_of(p->axes[ax.key])) << ' ' << fmt("%.10g", to_unit * p->ci.mean) << ' '
           << fmt("%.10g", to_unit * (p->ci.mean - hw)) << ' ' << fmt("%.10g", to_unit * (p->ci.mean + hw)) << '\n';
    }
    data << "\n\n";
    for (const GridPointResult* p : pts)
      for (const MemberResult& m : g.members)
        if (m.ok && m.grid_point == p->index)
          data << fmt("%.10g", x_of(p->axes[ax.key])) << ' ' << fmt("%.10g", to_unit * m.mean_resistance_kN) << '\n';
    plot << (block == 0 ? "plot data" : ", \\\n  data") << " index " << block
         << " using 1:2:3:4 with yerrorlines lc rgb '" << colour(i) << "' lw 2 pt 7 ps 1.2 title "
         << gnuplot_quoted(labels[i]) << " noenhanced, \\\n  data index " << block + 1
         << " using 1:2 with points lc rgb '" << colour(i) << "' pt 6 ps 0.8 notitle";
    block += 2;
  }
  plot << ", \\\n  NaN with points lc rgb '#606060' pt 6 ps 0.8 title 'members'";
  // 3. Axes: a tic at every value of the axis, labelled as in the plan.
  double lo = 0, hi = static_cast<double>(ax.values.size()) - 1;
  if (numeric) {
    lo = hi = ax.values.front().get<double>();
    for (const Json& v : ax.values) lo = std::min(lo, v.get<double>()), hi = std::max(hi, v.get<double>());
  }
  const double pad = hi > lo ? 0.08 * (hi - lo) : std::max(0.5, 0.1 * std::abs(lo));
  std::string tics;
  for (const Json& v : ax.values)
    tics += (tics.empty() ? "" : ", ") + gnuplot_quoted(value_text(v)) + " " + fmt("%.10g", x_of(v));
  std::ostringstream body;
  body << "set title " << gnuplot_quoted(plan.name + ": ice resistance against " + ax.key) << " noenhanced font ',14'\n"
       << "set xlabel " << gnuplot_quoted(ax.key) << " noenhanced\n"
       << "set ylabel 'Mean ice resistance (" << unit.name << "): ensemble mean and 95 % confidence interval'\n"
       << "set xtics (" << tics << ") noenhanced\n"
       << "set xrange [" << fmt("%.10g", lo - pad) << ":" << fmt("%.10g", hi + pad) << "]\n"
       << "set yrange [*:*]\n"
       << plot.str();
  f.draw(body.str(), data.str());
}

// Level ice: each member's mean resistance with its 95 % interval (1.96 batch-means standard errors) against its
// mean speed, a colour per sheet thickness (the axis "simulate.level_ice.thickness_m" if the sweep has it, else
// one colour), with Lindqvist (solid) and Riska (dashed) at the same speeds.
void draw_level_ice_plot(const SweepPlan& plan, const GatherResult& g, PlotFiles& f) {
  const std::string hkey = "simulate.level_ice.thickness_m";
  std::vector<std::string> groups;
  std::vector<std::vector<const MemberResult*>> members;
  for (size_t i = 0; i < g.members.size(); ++i) {
    const MemberResult& m = g.members[i];
    if (!m.ok || !m.level_ice) continue;
    const Json& axes = plan.members[i].axes;
    const std::string label = axes.contains(hkey) ? "h = " + value_text(axes[hkey]) + " m" : "level ice";
    const size_t k = std::find(groups.begin(), groups.end(), label) - groups.begin();
    if (k == groups.size()) groups.push_back(label), members.emplace_back();
    members[k].push_back(&m);
  }
  double to_unit = 1;
  const ForceUnit unit = plot_unit(g, &to_unit);
  std::ostringstream data, plot;
  for (size_t k = 0; k < groups.size(); ++k) {
    std::sort(members[k].begin(), members[k].end(),
              [](auto* a, auto* b) { return a->mean_speed_mps < b->mean_speed_mps; });
    if (k > 0) data << "\n\n";
    for (const MemberResult* m : members[k]) {
      const double hw = 1.96 * m->series.batch_means_se_kN;
      data << fmt("%.10g", m->mean_speed_mps) << ' ' << fmt("%.10g", to_unit * m->mean_resistance_kN) << ' '
           << fmt("%.10g", to_unit * (m->mean_resistance_kN - hw)) << ' '
           << fmt("%.10g", to_unit * (m->mean_resistance_kN + hw)) << ' ' << fmt("%.10g", to_unit * m->lindqvist_kN)
           << ' ' << fmt("%.10g", to_unit * m->riska_kN) << '\n';
    }
    plot << (k == 0 ? "plot data" : ", \\\n  data") << " index " << k << " using 1:2:3:4 with yerrorlines lc rgb '"
         << colour(k) << "' lw 2 pt 7 ps 1.2 title " << gnuplot_quoted("simulated, " + groups[k])
         << ", \\\n  data index " << k << " using 1:5 with lines lc rgb '" << colour(k)
         << "' lw 1.5 dt 1 title 'Lindqvist', \\\n  data index " << k << " using 1:6 with lines lc rgb '"
         << colour(k) << "' lw 1.5 dt 2 title 'Riska'";
  }
  std::ostringstream body;
  body << "set title " << gnuplot_quoted(plan.name + ": level-ice resistance against Lindqvist and Riska")
       << " noenhanced font ',14'\n"
       << "set xlabel 'Mean speed (m/s)'\n"
       << "set ylabel 'Mean ice resistance (" << unit.name << "), 95 % interval (batch means)'\n"
       << "set xrange [0:*]\nset yrange [0:*]\n"
       << plot.str();
  f.draw(body.str(), data.str());
}

// A pure ensemble: each member's mean resistance, and the ensemble mean with its 95 % interval as a band.
void draw_ensemble_plot(const SweepPlan& plan, const GatherResult& g, PlotFiles& f) {
  const ConfidenceInterval& ci = g.grid_points.front().ci;
  double to_unit = 1;
  const ForceUnit unit = plot_unit(g, &to_unit);
  double x0 = 1e300, x1 = -1e300;
  std::ostringstream data;
  for (const MemberResult& m : g.members)
    if (m.ok) {
      const double x = static_cast<double>(m.ensemble_index);
      x0 = std::min(x0, x), x1 = std::max(x1, x);
      data << fmt("%.10g", x) << ' ' << fmt("%.10g", to_unit * m.mean_resistance_kN) << '\n';
    }
  const double hw = ci.n >= 2 ? ci.half_width : 0.0;
  data << "\n\n";
  for (double x : {x0 - 0.5, x1 + 0.5})
    data << fmt("%.10g", x) << ' ' << fmt("%.10g", to_unit * ci.mean) << ' ' << fmt("%.10g", to_unit * (ci.mean - hw)) << ' '
         << fmt("%.10g", to_unit * (ci.mean + hw)) << '\n';
  std::ostringstream body;
  body << "set title " << gnuplot_quoted(plan.name + ": mean ice resistance of each ensemble member")
       << " noenhanced font ',14'\n"
       << "set xlabel 'Ensemble member (index)'\n"
       << "set ylabel 'Mean ice resistance (" << unit.name << ")'\n"
       << "set xrange [" << fmt("%.10g", x0 - 0.7) << ":" << fmt("%.10g", x1 + 0.7) << "]\n"
       << (x1 - x0 <= 30 ? "set xtics 1\n" : "");
  body << "plot ";
  if (ci.n >= 2)
    body << "data index 1 using 1:3:4 with filledcurves lc rgb '#c6dbef' fs solid 0.6 noborder title "
         << gnuplot_quoted("95 % interval of the ensemble mean (Student t, " + std::to_string(ci.n) + " members)")
         << ", \\\n  ";
  body << "data index 1 using 1:2 with lines lc rgb '#d1232a' lw 2.5 dt (8,4) title "
       << gnuplot_quoted("ensemble mean: " + ci_text(ci, to_unit) + " " + unit.name) << " noenhanced, \\\n"
       << "  data index 0 using 1:2 with points lc rgb '#1f77b4' pt 7 ps 1.3 title 'members'";
  f.draw(body.str(), data.str());
}

// The running mean of one member from the steady start, with the final mean +- 2 batch-means standard errors:
// if the curve is still leaving the band near the end, the run was too short for its mean.
void draw_running_mean(const MemberResult& m, const SteadyResistance& s, PlotFiles& f) {
  // In the unit that suits the member's mean (N for a tank model, kN for a ship).
  const ForceUnit unit = force_unit_for(1000.0 * m.series.mean_kN);
  const double to_unit = 1000.0 / unit.newtons;
  std::vector<double> rm = running_mean(s.resistance_kN);
  for (double& v : rm) v *= to_unit;
  const size_t n = rm.size();
  const double mean = to_unit * m.series.mean_kN, se = to_unit * m.series.batch_means_se_kN;
  const bool band = std::isfinite(se);
  // For the drawing only: a few thousand points show a running mean (it is smooth once past its first samples).
  const size_t stride = std::max<size_t>(1, n / 4000);
  std::ostringstream data;
  for (size_t i = 0; i < n; i += stride) data << fmt("%.10g", s.time_s[i]) << ' ' << fmt("%.10g", rm[i]) << '\n';
  if ((n - 1) % stride != 0) data << fmt("%.10g", s.time_s[n - 1]) << ' ' << fmt("%.10g", rm[n - 1]) << '\n';
  data << "\n\n";
  const double lo = band ? mean - 2 * se : mean, hi = band ? mean + 2 * se : mean;
  for (double t : {s.time_s.front(), s.time_s.back()})
    data << fmt("%.10g", t) << ' ' << fmt("%.10g", mean) << ' ' << fmt("%.10g", lo) << ' ' << fmt("%.10g", hi)
         << '\n';
  // The first samples of a running mean swing widely (one spike is the whole mean at first): the y range covers
  // the curve from a tenth of the steady part on, and the band, so the end, which decides, stays readable.
  double y0 = lo, y1 = hi;
  for (size_t i = n / 10; i < n; ++i) y0 = std::min(y0, rm[i]), y1 = std::max(y1, rm[i]);
  const double pad = std::max(0.15 * (y1 - y0), 1e-3 * std::max(1.0, std::abs(mean)));
  bool clipped = false;
  for (size_t i = 0; i < n / 10; ++i) clipped = clipped || rm[i] < y0 - pad || rm[i] > y1 + pad;
  std::ostringstream body;
  body << "set title " << gnuplot_quoted("Running mean of the ice resistance: " + m.id) << " noenhanced font ',14'\n"
       << "set xlabel 'Time (s)'\n"
       << "set ylabel 'Running mean of the ice resistance −F_x (" << unit.name << ")'\n"
       << "set xrange [" << fmt("%.10g", s.time_s.front()) << ":"
       << fmt("%.10g", std::max(s.time_s.back(), s.time_s.front() + s.time_step_s)) << "]\n"
       << "set yrange [" << fmt("%.10g", y0 - pad) << ":" << fmt("%.10g", y1 + pad) << "]\n";
  if (clipped)
    body << "set label 1 'the first samples of the running mean are off the scale' at graph 0.99, graph 0.96 right "
            "boxed noenhanced font ',9' tc rgb '#505050' front\n";
  body << "plot ";
  if (band)
    body << "data index 1 using 1:3:4 with filledcurves lc rgb '#c6dbef' fs solid 0.6 noborder title "
         << gnuplot_quoted("final mean ± 2 standard errors (batch means, " + std::to_string(m.series.batches) +
                           " batches): " + fmt("%.4g", mean) + " ± " + fmt("%.3g", 2 * se) + " " + unit.name)
         << " noenhanced, \\\n  ";
  body << "data index 1 using 1:2 with lines lc rgb '#d1232a' lw 2 dt (8,4) title "
       << gnuplot_quoted("final mean: " + fmt("%.4g", mean) + " " + unit.name) << " noenhanced, \\\n"
       << "  data index 0 using 1:2 with lines lc rgb '#101010' lw 2 title "
       << gnuplot_quoted("running mean from the steady start, t ≥ " + fmt("%g", s.steady_start_s) + " s")
       << " noenhanced";
  f.draw(body.str(), data.str());
}

}  // namespace

GatherResult gather_sweep(const SweepPlan& plan, const fs::path& plan_file, const fs::path& out_dir) {
  GatherResult g;
  // 1. Columns: the member, its axis values, what its ensemble seeded (union over members, sorted), the results.
  std::set<std::string> seed_keys;
  for (const PlanMember& m : plan.members)
    for (auto it = m.seeds.begin(); it != m.seeds.end(); ++it) seed_keys.insert(it.key());
  g.columns = {"member", "grid_point", "ensemble_index"};
  for (const PlanAxis& a : plan.axes) g.columns.push_back(a.key);
  g.columns.insert(g.columns.end(), seed_keys.begin(), seed_keys.end());
  g.columns.insert(g.columns.end(), kResultColumns.begin(), kResultColumns.end());

  // 2. The members, in plan order; the first ok one's series is kept for the running-mean plot.
  SteadyResistance first_series;
  const MemberResult* first_ok = nullptr;
  g.members.reserve(plan.members.size());  // first_ok points into it
  for (const PlanMember& pm : plan.members) {
    SteadyResistance s;
    g.members.push_back(gather_member(pm, s));
    if (g.members.back().ok && !first_ok) first_ok = &g.members.back(), first_series = std::move(s);
  }

  // Level ice: the formulas beside the simulated means (columns only when a member ran in level ice).
  const bool level_ice = std::any_of(g.members.begin(), g.members.end(), [](const MemberResult& m) {
    return m.level_ice;
  });
  if (level_ice) g.columns.insert(g.columns.end(), kLevelIceColumns.begin(), kLevelIceColumns.end());

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
    g.grid_points.push_back(std::move(gp));
  }

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
  ensure_directory(out_dir);
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
    for (const std::string& key : seed_keys) {
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
    if (level_ice)
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
    if (level_ice) {
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
                    {"ci95_half_width_kN", json_number(gp.ci.half_width)},
                    {"t_quantile", json_number(gp.ci.t_quantile)}});
  Json axes = Json::array();
  for (const PlanAxis& a : plan.axes) axes.push_back({{"key", a.key}, {"values", a.values}});

  // 6. Plots (they need an ok member), each checked; then everything into place together.
  std::vector<std::unique_ptr<PlotFiles>> plots;
  if (first_ok) {
    if (plan.axes.empty()) {
      plots.push_back(std::make_unique<PlotFiles>(out_dir, "ensemble"));
      draw_ensemble_plot(plan, g, *plots.back());
    }
    std::set<std::string> stems;
    for (size_t k = 0; k < plan.axes.size(); ++k) {
      std::string stem = "resistance_vs_" + file_part(plan.axes[k].key);
      if (!stems.insert(stem).second) stem += "_" + std::to_string(k);  // two keys that differ only in punctuation
      plots.push_back(std::make_unique<PlotFiles>(out_dir, stem));
      draw_axis_plot(plan, g, k, *plots.back());
    }
    if (level_ice) {
      plots.push_back(std::make_unique<PlotFiles>(out_dir, "level_ice_resistance"));
      draw_level_ice_plot(plan, g, *plots.back());
    }
    plots.push_back(std::make_unique<PlotFiles>(out_dir, "running_mean"));
    draw_running_mean(*first_ok, first_series, *plots.back());
  }
  g.files = {"sweep.csv", "sweep.json"};
  for (const auto& p : plots) g.files.insert(g.files.end(), {p->stem + ".png", p->stem + ".svg"});

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
        {"ci95_half_width_kN", "kN: Student t 0.975 quantile (n_ok - 1 degrees of freedom) x std / sqrt(n_ok)"}}},
      {"members", rows},
      {"grid_points", grid},
      {"failed", failed},
      {"files", g.files},
      {"provenance", provenance},
  };
  AtomicFile csv_file(out_dir / "sweep.csv"), json_file(out_dir / "sweep.json");
  PlotFiles::write_text_atomic_tmp(csv_file, csv.str());
  PlotFiles::write_text_atomic_tmp(json_file, out.dump(2) + "\n");
  csv_file.commit();
  json_file.commit();
  for (auto& p : plots) p->png.commit(), p->svg.commit();
  return g;
}

GatherResult gather_sweep(const fs::path& plan_file, const fs::path& out_dir) {
  return gather_sweep(read_sweep_plan(plan_file), plan_file, out_dir);
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
    r.push_back(ci_text(gp.ci));
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

}  // namespace floesim::render
