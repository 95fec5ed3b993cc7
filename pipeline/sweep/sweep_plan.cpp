#include "pipeline/sweep/sweep_plan.h"

#include <algorithm>
#include <cctype>
#include <set>
#include <sstream>

#include "pipeline/error.h"

namespace floesim::sweep {

namespace fs = std::filesystem;

namespace {

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

}  // namespace

std::string value_text(const Json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

namespace {

bool all_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

// A key's words: "level_ice" -> "level ice"; a unit suffix dropped ("thickness_m" -> "thickness").
std::string words(std::string key) {
  for (const char* suffix : {"_mps", "_m2", "_m", "_s", "_deg", "_pa", "_n", "_kg", "_kn", "_hz", "_rpm", "_w"})
    if (const std::string x = suffix; key.size() > x.size() && key.compare(key.size() - x.size(), x.size(), x) == 0) {
      key.resize(key.size() - x.size());
      break;
    }
  std::replace(key.begin(), key.end(), '_', ' ');
  return key;
}

}  // namespace

std::string list_item_path(const std::string& field) {
  std::string out, segment;
  auto flush = [&] {
    const bool index = all_digits(segment);
    out += index ? "[]" : (out.empty() ? "" : ".") + segment;
    segment.clear();
  };
  for (char ch : field) {
    if (ch == '.') flush();
    else segment += ch;
  }
  flush();
  return out;
}

std::string axis_label(const std::string& field, const std::string& unit, const std::string& doc) {
  // The sections it is in: "vessel.propulsion" -> "vessel propulsion"; a list item "ridges.0" -> "ridge 1".
  std::vector<std::string> parts;
  for (size_t start = 0;;) {
    const size_t dot = field.find('.', start);
    parts.push_back(field.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  std::string context;
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    const std::string& p = parts[i];
    if (all_digits(p) && p.size() < 10) {
      if (!context.empty() && context.back() == 's') context.pop_back();  // "ridges 1" reads "ridge 1"
      context += " " + std::to_string(std::stoul(p) + 1);
    } else {
      context += (context.empty() ? "" : " ") + words(p);
    }
  }
  // A meaning that starts by restating the key ("speed: prescribed forward speed through the water" for speed_mps)
  // is read from after it.
  std::string head = doc;
  if (const size_t colon = head.find(": "); colon != std::string::npos && head.substr(0, colon) == words(parts.back()))
    head = head.substr(colon + 2);
  size_t cut = std::string::npos;
  for (const char* sep : {": ", " (", "; ", ", "}) cut = std::min(cut, head.find(sep));
  if (cut != std::string::npos) head.resize(cut);
  if (head.empty()) head = words(parts.back());
  std::string label = context.empty() ? head : context + ": " + head;
  if (!unit.empty() && unit != "-") label += " (" + unit + ")";
  return label;
}

Json sweep_plan_json(const SweepPlan& p) {
  Json axes = Json::array(), grid = Json::array(), members = Json::array();
  for (const PlanAxis& a : p.axes) {
    Json axis = {{"key", a.key}, {"paths", a.paths}, {"values", a.values}};
    for (const auto& [name, text] : {std::pair{"label", &a.label}, {"unit", &a.unit}, {"doc", &a.doc}})
      if (!text->empty()) axis[name] = *text;
    axes.push_back(std::move(axis));
  }
  for (const PlanGridPoint& g : p.grid_points) grid.push_back({{"index", g.index}, {"axes", g.axes}});
  for (const PlanMember& m : p.members) {
    Json stages = Json::array();
    for (const PlanStage& s : m.stages) {
      Json outs = Json::array();
      for (const fs::path& o : s.outputs) outs.push_back(o.string());
      stages.push_back({{"name", s.name},
                        {"dir", s.dir.string()},
                        {"outputs", outs},
                        {"log", s.log.string()},
                        {"wall_ms", s.wall_ms.string()}});
    }
    members.push_back({{"id", m.id},
                       {"grid_point", m.grid_point},
                       {"ensemble_index", m.ensemble_index},
                       {"axes", m.axes},
                       {"seeds", m.seeds},
                       {"dir", m.dir.string()},
                       {"summary", m.summary.string()},
                       {"results", m.results.string()},
                       {"stages", stages}});
  }
  return {{"format", kSweepPlanFormat},
          {"name", p.name},
          {"sweep_file", p.sweep_file},
          {"base_case", p.base_case},
          {"axes", axes},
          {"combine", p.combine},
          {"ensemble", p.ensemble},
          {"grid_points", grid},
          {"members", members}};
}

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
  c.text(j, "", "base_case", p.base_case, false);
  c.text(j, "", "combine", p.combine, false);
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
      c.text((*axes)[i], w, "label", a.label, false);
      c.text((*axes)[i], w, "unit", a.unit, false);
      c.text((*axes)[i], w, "doc", a.doc, false);
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
          c.file(sj, ws, "dir", s.dir, false);
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

}  // namespace floesim::sweep
