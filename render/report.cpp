#include "render/report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <openssl/evp.h>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/units.h"
#include "pipeline/provenance.h"

namespace floesim::render {

namespace fs = std::filesystem;

std::vector<ReferenceLoad> ReportOptions::all_references() const {
  std::vector<ReferenceLoad> r;
  if (reference_kN > 0) r.push_back({reference_label, reference_kN});
  r.insert(r.end(), references.begin(), references.end());
  return r;
}

ReportOptions read_report_options(const fs::path& config) {
  return read_options<ReportOptions>(load_json_file(config), config.string());
}

ReferenceComparison compare_to_reference(double mean_kN, const ReferenceLoad& ref) {
  ReferenceComparison c;
  c.label = ref.label;
  c.reference_kN = ref.kN;
  c.error_kN = mean_kN - ref.kN;
  c.error_percent = 100.0 * c.error_kN / ref.kN;
  return c;
}

std::string base64_encode(std::string_view bytes) {
  // EVP_EncodeBlock takes an int length: encode in chunks of a multiple of 3 bytes, so only the last pads.
  constexpr size_t kChunk = 3 * (1u << 20);
  std::string out;
  out.reserve(4 * ((bytes.size() + 2) / 3));
  std::string buf(4 * (kChunk / 3) + 1, '\0');
  for (size_t pos = 0; pos < bytes.size(); pos += kChunk) {
    const size_t n = std::min(kChunk, bytes.size() - pos);
    const int w = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(buf.data()),
                                  reinterpret_cast<const unsigned char*>(bytes.data() + pos), static_cast<int>(n));
    out.append(buf.data(), static_cast<size_t>(w));
  }
  return out;
}

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

namespace {

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw Error(p.string() + ": cannot read");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A load given in kN, as text in the display unit u (pipeline/units.h: N for a tank model, kN for a ship).
std::string load_in(double x_kN, const ForceUnit& u) {
  if (!std::isfinite(x_kN)) return "&ndash;";
  return load_number(1000.0 * x_kN / u.newtons);
}

// "13229000" as "13 229 000" (thin spaces between groups of three).
std::string grouped_digits(const std::string& whole) {
  std::string grouped;
  for (size_t k = 0; k < whole.size(); ++k) {
    if (k > 0 && (whole.size() - k) % 3 == 0) grouped += "&thinsp;";
    grouped += whole[k];
  }
  return grouped;
}

// A number for reading: 4 significant digits; from 10,000 on whole, in groups of three (13 229 000, not
// 1.323e+07); below 0.001 in powers of ten.
std::string readable_number(double x) {
  if (!std::isfinite(x)) return std::isnan(x) ? "&ndash;" : (x > 0 ? "&infin;" : "&minus;&infin;");
  if (std::abs(x) < 1e4 || std::abs(x) >= 1e15) {
    std::string t = fmt("%.4g", x);
    const size_t e = t.find('e');
    if (e == std::string::npos) return t;
    return t.substr(0, e) + "&times;10<sup>" + std::to_string(std::stoi(t.substr(e + 1))) + "</sup>";
  }
  const double digits = std::pow(10.0, std::floor(std::log10(std::abs(x))) - 3);
  return (x < 0 ? "&minus;" : "") + grouped_digits(fmt("%.0f", std::abs(std::round(x / digits) * digits)));
}

// A JSON scalar as table text: integers whole, other numbers for reading, strings escaped.
std::string scalar_text(const Json& v) {
  if (v.is_number_unsigned()) return grouped_digits(std::to_string(v.get<uint64_t>()));
  if (v.is_number_integer()) {
    const int64_t i = v.get<int64_t>();
    return (i < 0 ? "&minus;" : "") + grouped_digits(std::to_string(i < 0 ? -static_cast<uint64_t>(i) : i));
  }
  if (v.is_number()) return readable_number(v.get<double>());
  if (v.is_string()) return html_escape(v.get<std::string>());
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_null()) return "&ndash;";
  return html_escape(v.dump());
}

// A key as a reader's label: "hydrostatics.lcb_m" -> "hydrostatics: lcb (m)", "mean_peak_N" -> "mean peak (N)",
// "lines[3].fairlead_tension_N.max" -> "lines 3: fairlead tension (N): max". The unit suffixes of the project's
// keys become units; the rest of the underscores spaces.
std::string human_label(const std::string& key) {
  static const std::vector<std::pair<std::string, std::string>> units = {
      {"_kg_m3", "kg/m&sup3;"}, {"_m2", "m&sup2;"}, {"_m3", "m&sup3;"}, {"_mps", "m/s"}, {"_radps", "rad/s"},
      {"_deg", "&deg;"}, {"_rad", "rad"}, {"_kN", "kN"}, {"_N", "N"}, {"_Nm", "N m"}, {"_nm", "N m"}, {"_n", "N"},
      {"_pa", "Pa"}, {"_Pa", "Pa"}, {"_kg", "kg"}, {"_t", "t"}, {"_s", "s"}, {"_m", "m"}, {"_J", "J"}};
  std::vector<std::string> parts;
  std::string part;
  for (size_t i = 0; i < key.size(); ++i) {
    const char c = key[i];
    const bool decimal_point = c == '.' && i > 0 && i + 1 < key.size() &&
                               std::isdigit(static_cast<unsigned char>(key[i - 1])) &&
                               std::isdigit(static_cast<unsigned char>(key[i + 1]));  // "peak_0.5s_..."
    if ((c == '.' && !decimal_point) || c == '[') {
      parts.push_back(part);
      part.clear();
    } else if (c != ']') {
      part += c;
    }
  }
  parts.push_back(part);
  std::string label;
  for (std::string p : parts) {
    if (p.empty()) continue;
    std::string unit;
    for (const auto& [suffix, u] : units)
      if (p.size() > suffix.size() && p.compare(p.size() - suffix.size(), suffix.size(), suffix) == 0) {
        unit = u;
        p.resize(p.size() - suffix.size());
        break;
      }
    std::replace(p.begin(), p.end(), '_', ' ');
    if (!label.empty()) label += std::isdigit(static_cast<unsigned char>(p[0])) ? " " : ": ";
    label += html_escape(p) + (unit.empty() ? "" : " (" + unit + ")");
  }
  return label;
}

// Rows "label | value" for the scalars of a JSON object (nested objects and arrays are left to the settings).
std::string scalar_rows(const Json& obj, const std::string& prefix = "") {
  std::string rows;
  if (!obj.is_object()) return rows;
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    if (it.value().is_object() || it.value().is_array()) continue;
    rows += "<tr><th>" + human_label(prefix + it.key()) + "</th><td>" + scalar_text(it.value()) + "</td></tr>\n";
  }
  return rows;
}

// Rows for every scalar of a JSON object and of the objects and arrays inside it, labelled by their path
// ("cycles: mean peak (N)", "lines 3: fairlead tension (N): max").
std::string nested_rows(const Json& obj, const std::string& prefix = "") {
  std::string rows = scalar_rows(obj, prefix);
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    if (it.value().is_object()) rows += nested_rows(it.value(), prefix + it.key() + ".");
    if (it.value().is_array())
      for (size_t i = 0; i < it.value().size(); ++i) {
        const Json& e = it.value()[i];
        const std::string name = prefix + it.key() + "[" + std::to_string(i) + "]";
        if (e.is_object()) rows += nested_rows(e, name + ".");
        else rows += "<tr><th>" + human_label(name) + "</th><td>" + scalar_text(e) + "</td></tr>\n";
      }
  }
  return rows;
}

const Json* find(const Json& j, std::initializer_list<const char*> path) {
  const Json* p = &j;
  for (const char* k : path) {
    if (!p->is_object() || !p->contains(k)) return nullptr;
    p = &(*p)[k];
  }
  return p;
}

// find's value if it is an object (a section a stage may write as null: a structure's hull has no ship
// particulars), else null.
const Json* find_object(const Json& j, std::initializer_list<const char*> path) {
  const Json* p = find(j, path);
  return p && p->is_object() ? p : nullptr;
}

double number_or_nan(const Json& j, std::initializer_list<const char*> path) {
  const Json* p = find(j, path);
  return p && p->is_number() ? p->get<double>() : NAN;
}

struct Page {
  fs::path run;              // the folder reported on
  std::string kind = "run";  // what it is, for the box of missing artefacts: "run" or "sweep"
  std::vector<std::string> missing;
  std::vector<NamedInput> inputs;  // every artefact read, for the provenance

  // True if RUN/rel exists; else records it as missing ("rel (what)").
  bool have(const std::string& rel, const std::string& what) {
    if (fs::is_regular_file(run / rel)) return true;
    missing.push_back(rel + " (" + what + ")");
    return false;
  }
  std::string img(const fs::path& file, const std::string& role, const std::string& alt) {
    inputs.push_back({role, file});
    return "<img src=\"data:image/png;base64," + base64_encode(read_bytes(file)) + "\" alt=\"" + html_escape(alt) +
           "\">";
  }
  Json json(const std::string& rel, const std::string& role) {
    inputs.push_back({role, run / rel});
    return load_json_file(run / rel);
  }
};

// The case file the runner planned from, named on the first line of RUN/build.ninja ("Generated by floesim run
// from <case.json>; do not edit."); "" if absent.
fs::path case_file(const fs::path& run) {
  std::ifstream in(run / "build.ninja");
  std::string line;
  if (!in || !std::getline(in, line)) return {};
  const std::string key = "floesim run from ";
  const size_t a = line.find(key), b = line.rfind("; do not edit");
  if (a == std::string::npos || b == std::string::npos || b <= a + key.size()) return {};
  return line.substr(a + key.size(), b - a - key.size());
}

// A photo case has no image stage: its photo is the first argument of floesim-digitise in RUN/build.ninja.
fs::path photo_from_ninja(const fs::path& run) {
  std::ifstream in(run / "build.ninja");
  std::string line;
  const std::string key = "floesim-digitise' '";
  while (std::getline(in, line)) {
    const size_t a = line.find(key);
    if (a == std::string::npos) continue;
    const size_t s = a + key.size(), e = line.find('\'', s);
    if (e != std::string::npos) return line.substr(s, e - s);
  }
  return {};
}

const char* kStyle = R"(
body{font-family:system-ui,sans-serif;max-width:1200px;margin:1em auto;padding:0 1em;color:#222}
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}
table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #ccc;padding:.25em .6em;text-align:left}
td.n{text-align:right;font-variant-numeric:tabular-nums}
img,video{max-width:100%;height:auto;border:1px solid #ddd}
.pair{display:flex;gap:1em;flex-wrap:wrap}.pair figure{flex:1 1 400px;margin:0}.pair img{width:100%}
figcaption{font-size:.9em;color:#555}
.missing{border:2px solid #c60;background:#fff4e5;padding:.5em 1em}
.error{border:2px solid #c00;background:#fee;padding:.5em 1em}
pre{background:#f6f6f6;padding:.6em;overflow:auto;font-size:.85em}
.note{color:#555;font-size:.9em}
.warning{color:#8a4b00;font-weight:bold}
.wide{overflow-x:auto}
)";

// Marks the page: <html data-media="ok"> once every image has decoded and the video has decoded its first frame
// (readyState >= 2, HAVE_CURRENT_DATA; data-video then says its size and duration), else "failed: ..." and a
// visible error box (what a browser that cannot show an embedded file tells its reader).
const char* kMediaCheck = R"(
(function(){
  var imgs=[].slice.call(document.images), vids=[].slice.call(document.querySelectorAll('video'));
  var pending=imgs.length+vids.length, bad=[];
  function done(){ if(--pending>0) return;
    document.documentElement.setAttribute('data-media', bad.length ? 'failed: '+bad.join(', ') : 'ok');
    if(bad.length){ var e=document.getElementById('media-error');
      e.textContent='This browser could not show: '+bad.join(', '); e.hidden=false; } }
  if(!pending){ document.documentElement.setAttribute('data-media','ok'); return; }
  imgs.forEach(function(i){ var f=function(){ if(!(i.naturalWidth>0)) bad.push(i.alt); done(); };
    if(i.complete) f(); else { i.addEventListener('load',f); i.addEventListener('error',f); } });
  vids.forEach(function(v){ var seen=false;
    var ok=function(){ if(seen) return; seen=true;
      document.documentElement.setAttribute('data-video', v.videoWidth+'x'+v.videoHeight+' '+v.duration+' s');
      if(!(v.videoWidth>0)) bad.push('video'); done(); };
    if(v.readyState>=2){ ok(); return; }
    v.addEventListener('loadeddata',ok);
    v.addEventListener('error',function(){ if(seen) return; seen=true; bad.push('video'); done(); }); });
})();
)";

// The page around `body`: title, the media-error box, the box of missing artefacts, the provenance of every input
// the page read, the media check; written atomically. Returns its size in bytes.
uintmax_t write_page(const fs::path& out, const std::string& title, const std::string& body, const Page& pg,
                     const Json& resolved_config) {
  const Json prov = make_provenance("floesim-report", pg.inputs, resolved_config);
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" << html_escape(title)
       << "</title>\n<meta name=\"generator\" content=\"floesim-report " << version() << "\">\n<style>" << kStyle
       << "</style>\n</head>\n<body>\n<h1>" << html_escape(title) << "</h1>\n"
       << "<p class=\"error\" id=\"media-error\" hidden></p>\n";
  if (!pg.missing.empty()) {
    html << "<div class=\"missing\" id=\"missing\"><strong>Missing from this " << pg.kind << " (" << pg.missing.size()
         << "):</strong><ul>\n";
    for (const auto& m : pg.missing) html << "<li>" << html_escape(m) << "</li>\n";
    html << "</ul></div>\n";
  }
  html << body << "<h2>How this report was made</h2>\n<details><summary>provenance</summary><pre>"
       << html_escape(prov.dump(2)) << "</pre></details>\n<script>" << kMediaCheck << "</script>\n</body>\n</html>\n";
  const std::string text = html.str();
  if (out.has_parent_path()) ensure_directory(out.parent_path());
  write_text_atomic(out, text);
  return text.size();
}

// A case's description, "" if its file does not read (it may have changed since the run).
std::string case_description(const fs::path& case_json) {
  try {
    const Json c = load_json_file(case_json);
    if (c.contains("description") && c["description"].is_string()) return c["description"].get<std::string>();
  } catch (const Error&) {
  }
  return "";
}

// 1. The summary is the run: without it there is nothing to report. Checks the run folder and the summary's mean
// load, and returns the summary (read through pg, for the provenance).
Json read_run_summary(const fs::path& run_dir, Page& pg) {
  const fs::path summary_file = run_dir / "sim" / "summary.json";
  FLOESIM_REQUIRE(fs::is_directory(run_dir), run_dir.string(),
                  ": not a folder; give --run the output folder of `floesim run` (e.g. runs/<case>)");
  FLOESIM_REQUIRE(fs::is_regular_file(summary_file), summary_file.string(),
                  " is missing: the run has not simulated (run `floesim run <case> --out ", run_dir.string(),
                  "` first); no report written");
  Json summary = pg.json("sim/summary.json", "summary");
  const Json* mean_n = find(summary, {"mean_surge_ice_resistance_N"});
  FLOESIM_REQUIRE(mean_n && mean_n->is_number(), summary_file.string(),
                  ": mean_surge_ice_resistance_N is missing or not a number; rerun the simulate stage");
  return summary;
}

// 2. The numbers of the mean-load table into rs: mean, standard deviation, the applying moving average's peak, and
// the mean against every reference.
void mean_load_numbers(const Json& summary, const ReportOptions& o, ReportSummary& rs) {
  rs.mean_kN = find(summary, {"mean_surge_ice_resistance_N"})->get<double>() / 1000;
  rs.std_kN = number_or_nan(summary, {"std_surge_ice_load_N"}) / 1000;
  rs.half_width_kN = NAN;
  if (const Json* ci = find(summary, {"mean_surge_ice_load_interval"}); ci && ci->is_object()) {
    rs.half_width_kN = number_or_nan(*ci, {"half_width_N"}) / 1000;
    rs.interval_method = ci->value("method", "");
    rs.interval_meaningful = ci->value("meaningful", false);
    rs.interval_note = ci->value("note", "");
  }
  rs.moving_average_max_kN = NAN;
  if (const Json* ma = find(summary, {"moving_average_surge_ice_load"}); ma && ma->is_array()) {
    for (const Json& m : *ma)
      if (m.value("applies", false)) {
        rs.moving_average_max_kN = number_or_nan(m, {"max_resistance_N"}) / 1000;
        rs.moving_average_window_s = number_or_nan(m, {"window_s"});
      }
  }
  for (const ReferenceLoad& r : o.all_references()) rs.references.push_back(compare_to_reference(rs.mean_kN, r));
}

// 3. The page's title: the options' title, else one naming the case (the folder of its case.json), else the run
// folder.
std::string report_title(const ReportOptions& o, const std::string& run_name, const fs::path& case_json) {
  std::string title = o.title;
  if (title.empty())
    title = "floesim report: " + (case_json.empty() ? fs::path(run_name).filename().string()
                                                    : case_json.parent_path().filename().string());
  return title;
}

// A JSON file of the run, or null if it is absent or does not read (the section then says less, not wrong).
Json optional_json(Page& pg, const std::string& rel, const std::string& role) {
  if (!fs::is_regular_file(pg.run / rel)) return Json();
  try {
    return pg.json(rel, role);
  } catch (const Error&) {
    return Json();
  }
}

// "116 m", "2.00 m/s": a number with its unit, NaN as a dash.
std::string quantity(double x, const char* format, const char* unit) {
  return std::isfinite(x) ? html_escape(fmt(format, x)) + "&nbsp;" + unit : "&ndash;";
}

// How the vessel was driven, from the simulation's settings.
std::string propulsion_text(const Json& settings) {
  const Json* p = find(settings, {"vessel", "propulsion"});
  if (!p || !p->is_object()) return "&ndash;";
  const std::string mode = p->value("mode", "");
  if (mode == "speed")
    return "held at " + quantity(number_or_nan(*p, {"speed_mps"}), "%.2f", "m/s") + " (thrust by a PI controller, at most " +
           quantity(number_or_nan(*p, {"max_thrust_n"}) / 1e3, "%.0f", "kN") + ")";
  if (mode == "constant_thrust") return "constant thrust " + quantity(number_or_nan(*p, {"thrust_n"}) / 1e3, "%.0f", "kN");
  if (mode == "bollard_pull") return "bollard pull, " + quantity(number_or_nan(*p, {"thrust_n"}) / 1e3, "%.0f", "kN");
  if (mode == "thrust_series") return "thrust series from " + html_escape(p->value("thrust_file", std::string("?")));
  return html_escape(mode);
}

// A structure's run (station keeping other than propulsion): the body is held, the ice comes to it.
bool is_structure_run(const Json& settings) {
  const Json* sk = find(settings, {"vessel", "station_keeping"});
  return sk && sk->is_object() && sk->value("mode", std::string("propulsion")) != "propulsion";
}

// How a structure was held, from the simulation's settings.
std::string station_keeping_text(const Json& settings) {
  const Json* sk = find(settings, {"vessel", "station_keeping"});
  const std::string mode = sk->value("mode", std::string());
  if (mode == "fixed") return "fixed: it does not move in the earth frame";
  if (mode == "moored") {
    const Json* lines = find(*sk, {"lines"});
    return "moored by " + std::to_string(lines && lines->is_array() ? lines->size() : 0) + " catenary lines";
  }
  if (mode == "dp") return "dynamic positioning (a PID controller holding the station)";
  if (mode == "compliant")
    return "compliant: its first mode at " + quantity(number_or_nan(*sk, {"compliant", "natural_frequency_hz"}), "%.2g",
                                                      "Hz") +
           ", damping " + quantity(100 * number_or_nan(*sk, {"compliant", "damping_ratio"}), "%.2g", "%") +
           " of critical";
  return html_escape(mode);
}

// The ice's drift towards a structure, from the simulation's settings.
std::string drift_text(const Json& settings) {
  const double v = number_or_nan(settings, {"drift", "speed_mps"});
  if (!(v > 0)) return "none: the ice moves only as the water and the wind drive it";
  return quantity(v, "%.2f", "m/s") + " towards " +
         quantity(number_or_nan(settings, {"drift", "direction_deg"}), "%.0f", "&deg;") +
         " (from +x, counter-clockwise); the run is computed in the ice's frame";
}

// 3. Section "What was run" (the first screen): the case, the hull and its main particulars, the ice, how the
// vessel was driven and the speed it made (for a structure: how it was held and how the ice drifted), the simulated
// time and the steady part, each with a label a reader knows and its unit.
void case_section(std::ostream& body, const std::string& run_name, const fs::path& case_json, const Json& summary,
                  Page& pg) {
  std::vector<std::pair<std::string, std::string>> rows;
  if (const fs::path& cf = case_json; !cf.empty() && fs::is_regular_file(cf)) {
    try {
      const Json c = load_json_file(cf);
      if (c.contains("description") && c["description"].is_string())
        rows.push_back({"Case", html_escape(c["description"].get<std::string>())});
    } catch (const Error&) {
      // The case file changed since the run and no longer reads: the settings below are what ran.
    }
  }
  const Json settings = summary.value("settings", Json::object());
  const Json hull = optional_json(pg, "hull/hull.json", "hull particulars");
  // A ship's particulars; a structure's hull has none (floesim-hull says why), only its waterline's hydrostatics.
  const Json* pt = find_object(hull, {"particulars"});
  const Json* hy = find_object(hull, {"hydrostatics"});
  if (pt || hy) {
    const double length = pt ? number_or_nan(*pt, {"length_m"}) : number_or_nan(*hy, {"length_wl_m"});
    const double beam = pt ? number_or_nan(*pt, {"beam_m"}) : number_or_nan(*hy, {"beam_wl_m"});
    const double draught = pt ? number_or_nan(*pt, {"draught_m"}) : number_or_nan(*hy, {"draught_m"});
    std::string h = "length " + quantity(length, "%.1f", "m") + " at the waterline, beam " +
                    quantity(beam, "%.1f", "m") + ", draught " + quantity(draught, "%.1f", "m");
    const double disp = hy ? number_or_nan(*hy, {"displacement_t"}) : NAN;
    if (std::isfinite(disp)) h += ", displacement " + quantity(disp, "%.0f", "t");
    if (pt) h += "; stem angle " + quantity(number_or_nan(*pt, {"stem_angle_deg"}), "%.0f", "&deg;");
    rows.push_back({"Hull", h});
  }
  {
    const Json stats = optional_json(pg, "floes/stats.json", "floe statistics");
    std::string ice = scalar_text(summary.value("floes", Json())) + " floes";
    const double conc = number_or_nan(stats, {"ice_concentration"});
    if (std::isfinite(conc)) ice += ", concentration " + quantity(100 * conc, "%.0f", "%");
    const double h = number_or_nan(stats, {"provenance", "config", "options", "thickness_m"});
    if (std::isfinite(h)) ice += ", thickness " + quantity(h, "%.2f", "m");
    ice += "; flexural strength " +
           quantity(number_or_nan(settings, {"fracture", "flexural_strength_pa"}) / 1e3, "%.0f", "kPa") +
           ", crushing strength " + quantity(number_or_nan(settings, {"ice", "crushing_strength_pa"}) / 1e6, "%.2g", "MPa");
    rows.push_back({"Ice", ice});
  }
  if (is_structure_run(settings)) {
    rows.push_back({"Station keeping", station_keeping_text(settings)});
    rows.push_back({"Ice drift", drift_text(settings)});
  } else {
    rows.push_back({"Propulsion", propulsion_text(settings)});
    std::string v = quantity(number_or_nan(summary, {"mean_vessel_speed_mps"}), "%.2f", "m/s");
    const double hw = number_or_nan(summary, {"mean_vessel_speed_interval", "half_width_mps"});
    if (std::isfinite(hw)) v += " &plusmn; " + quantity(hw, "%.2f", "m/s") + " (95 %)";
    rows.push_back({"Mean speed in the steady part", v});
  }
  {
    std::string t = quantity(number_or_nan(settings, {"duration_s"}), "%g", "s") + " simulated, time step " +
                    quantity(number_or_nan(settings, {"time_step_s"}), "%g", "s");
    if (const Json* sp = find(summary, {"steady_part"}))
      t += "; steady part " + quantity(number_or_nan(*sp, {"from_s"}), "%g", "s") + " to " +
           quantity(number_or_nan(*sp, {"to_s"}), "%g", "s");
    rows.push_back({"Duration", t});
  }
  rows.push_back({"Contact model", scalar_text(summary.value("contact_model", Json()))});
  rows.push_back({"Run folder", html_escape(run_name)});
  if (!case_json.empty()) rows.push_back({"Case file", html_escape(case_json.string())});
  body << "<h2>What was run</h2>\n<table id=\"what-was-run\">\n";
  for (const auto& [label, value] : rows) body << "<tr><th>" << label << "</th><td>" << value << "</td></tr>\n";
  body << "</table>\n";
}

// 3. Section "Warnings": what the stages warned of (summary.json's warnings: the floes' maker's and simulate's; the
// video sidecar's: render's), on the first screen, so that a result built on a degenerate input is not read as a
// sound one.
void warnings_section(std::ostream& body, const Json& summary, const Json& video_sidecar) {
  Json w = summary.value("warnings", Json::array());
  if (!w.is_array()) w = Json::array();
  if (video_sidecar.is_object())
    for (const Json& line : video_sidecar.value("warnings", Json::array()))
      if (line.is_string()) w.push_back("render: " + line.get<std::string>());
  body << "<h2>Warnings</h2>\n";
  if (w.empty()) {
    body << "<p class=\"note\" id=\"no-warnings\">No stage warned.</p>\n";
    return;
  }
  body << "<ul id=\"warnings\">\n";
  for (const Json& line : w)
    body << "<li class=\"warning\">" << html_escape(line.is_string() ? line.get<std::string>() : line.dump())
         << "</li>\n";
  body << "</ul>\n";
}

// 3. Section "Mean loads", in the unit that suits their size and the references' (N for a tank model, kN for a
// ship), and the table of references.
void mean_loads_section(std::ostream& body, const ReportSummary& rs, bool structure) {
  // A ship meets the ice as a resistance; ice comes to a structure as a load (both are -Fx).
  const std::string load = structure ? "ice load on the structure (&minus;Fx" : "surge ice resistance (";
  double typical_kN = std::max(std::abs(rs.mean_kN), std::isfinite(rs.moving_average_max_kN)
                                                         ? std::abs(rs.moving_average_max_kN) : 0.0);
  for (const auto& c : rs.references) typical_kN = std::max(typical_kN, std::abs(c.reference_kN));
  const ForceUnit unit = force_unit_for(1000.0 * typical_kN);
  auto in_unit = [&](double x_kN) { return load_in(x_kN, unit); };
  const bool ci = std::isfinite(rs.half_width_kN);
  auto pm = [&](double hw_text_kN) { return ci ? " &plusmn; " + in_unit(hw_text_kN) : std::string(); };
  body << "<h2>Mean loads</h2>\n<table>\n<tr><th>quantity</th><th>" << unit.name << "</th></tr>\n"
       << "<tr><th>mean " << load << (structure ? ", " : "") << "steady part" << (ci ? ", &plusmn; 95 % interval" : "")
       << ")</th><td class=\"n\"><span id=\"mean-kN\">" << in_unit(rs.mean_kN) << "</span>"
       << pm(rs.half_width_kN)
       << "</td></tr>\n<tr><th>standard deviation of the surge ice load</th><td class=\"n\">" << in_unit(rs.std_kN)
       << "</td></tr>\n<tr><th>largest moving average of the " << (structure ? "ice load" : "resistance")
       << (std::isfinite(rs.moving_average_window_s) && rs.moving_average_window_s > 0
               ? " (" + fmt("%g", rs.moving_average_window_s) + " s window)"
               : std::string())
       << "</th><td class=\"n\">" << in_unit(rs.moving_average_max_kN) << "</td></tr>\n</table>\n";
  if (!rs.interval_method.empty())
    body << "<p class=\"note\" id=\"interval-method\">The interval: " << html_escape(rs.interval_method) << ".</p>\n";
  if (!rs.interval_note.empty())
    body << "<p class=\"warning\" id=\"interval-warning\">The run is too short for its interval: "
         << html_escape(rs.interval_note) << ".</p>\n";
  if (rs.references.empty()) {
    body << "<p class=\"note\">No reference value given (report config: <code>reference_kN</code>, "
            "<code>reference_label</code> or <code>references</code>).</p>\n";
  } else {
    body << "<table id=\"references\">\n<tr><th>reference</th><th>" << unit.name
         << "</th><th>simulated &minus; reference, " << unit.name << "</th><th>error, %</th></tr>\n";
    for (const auto& c : rs.references)
      body << "<tr><th>" << html_escape(c.label) << "</th><td class=\"n\">" << in_unit(c.reference_kN)
           << "</td><td class=\"n\">" << fmt("%+.1f", 1000.0 * c.error_kN / unit.newtons)
           << (ci ? " &plusmn; " + fmt("%.1f", 1000.0 * rs.half_width_kN / unit.newtons) : std::string())
           << "</td><td class=\"n\">" << fmt("%+.1f", c.error_percent)
           << (ci ? " &plusmn; " + fmt("%.1f", 100 * rs.half_width_kN / c.reference_kN) : std::string())
           << "</td></tr>\n";
    body << "</table>\n";
  }
}

// 3. Section "Surge ice load": the load plot and the count of fracture events from the plot's numbers.
void load_plot_section(std::ostream& body, const fs::path& run_dir, Page& pg, bool structure) {
  body << "<h2>Surge ice load</h2>\n";
  if (pg.have("plots/surge_ice_load.png", "load plot"))
    body << "<figure>" << pg.img(run_dir / "plots/surge_ice_load.png", "plot", "surge ice load plot")
         << "<figcaption>" << (structure ? "Ice load on the structure" : "Surge ice resistance")
         << " (&minus;Fx) against time, its moving average and the steady mean; fracture events at the "
         << (structure ? "structure" : "vessel") << " along the bottom.</figcaption></figure>\n";
  if (fs::is_regular_file(run_dir / "plots/plot.json")) {
    const Json pj = pg.json("plots/plot.json", "plot summary");
    if (const Json* fr = find(pj, {"fracture", "events"}))
      body << "<p class=\"note\">" << scalar_text(*fr) << " fracture events in plots/fracture_events.csv.</p>\n";
  } else {
    pg.missing.push_back("plots/plot.json (plot numbers)");
  }
}

// 3. The table of the identification's numbers (identify/identified.json, `ij`) into rs and the page: the
// identified mean, and against the known simulated load (round trip) or the simulated mean.
void identified_table(std::ostream& body, const Json& ij, ReportSummary& rs) {
  rs.identified_kN = number_or_nan(ij, {"mean_surge_ice_resistance_n"}) / 1000;
  const Json* w = find(ij, {"mean_window_s"});
  const std::string window = w && w->is_array() && w->size() == 2
                                 ? fmt("%g", (*w)[0].get<double>()) + " to " + fmt("%g", (*w)[1].get<double>()) + " s"
                                 : std::string("?");
  // The unit of the mean loads above (N for a tank model, kN for a ship).
  const ForceUnit unit = force_unit_for(1000.0 * std::max(std::abs(rs.mean_kN), std::abs(rs.identified_kN)));
  auto in_unit = [&](double x_kN) { return load_in(x_kN, unit); };
  body << "<table id=\"identified\">\n<tr><th>quantity</th><th>" << unit.name << "</th></tr>\n"
       << "<tr><th>identified mean surge ice resistance (" << window << ")</th><td class=\"n\" "
       << "id=\"identified-kN\">" << in_unit(rs.identified_kN) << "</td></tr>\n";
  if (const Json* k = find(ij, {"known_load"})) {
    rs.identified_known_kN = number_or_nan(*k, {"mean_surge_ice_resistance_n"}) / 1000;
    rs.identified_error_percent = -number_or_nan(*k, {"surge_error_percent"});
    body << "<tr><th>the simulated load over the same window</th><td class=\"n\">"
         << in_unit(rs.identified_known_kN) << "</td></tr>\n<tr><th>identified &minus; simulated</th><td "
         << "class=\"n\">" << fmt("%+.1f", 1000.0 * (rs.identified_kN - rs.identified_known_kN) / unit.newtons)
         << " (" << fmt("%+.2f", rs.identified_error_percent)
         << " %)</td></tr>\n<tr><th>RMS error of the filtered series (standard deviation of the simulated "
            "one)</th><td class=\"n\">"
         << in_unit(number_or_nan(*k, {"output_rate_surge_rms_error_n"}) / 1000) << " ("
         << in_unit(number_or_nan(*k, {"output_rate_surge_known_sd_n"}) / 1000) << ")</td></tr>\n";
  } else {
    body << "<tr><th>simulated &minus; identified</th><td class=\"n\">"
         << fmt("%+.1f", 1000.0 * (rs.mean_kN - rs.identified_kN) / unit.newtons) << " ("
         << fmt("%+.1f", 100 * (rs.mean_kN - rs.identified_kN) / rs.identified_kN) << " %)</td></tr>\n";
  }
  body << "</table>\n";
}

// 3. Section "Ice load identified from the ship's data", only when the case's "identify" section ran the
// identification (config/identify.json is its settings): what the data are, the numbers, the plot.
void identified_section(std::ostream& body, const fs::path& run_dir, Page& pg, ReportSummary& rs) {
  if (!fs::exists(run_dir / "config/identify.json")) return;
  body << "<h2>Ice load identified from the ship's data</h2>\n";
  const bool round_trip = fs::exists(run_dir / "config/shipdata.json");
  body << "<p class=\"note\">"
       << (round_trip ? "The data are the simulated ship's, as a ship would record them (shipdata/measured.csv, "
                        "sensor settings in config/shipdata.json), identified with the simulated ship's own "
                        "model (shipdata/measured.json): the round trip checks the identification against the "
                        "known simulated load."
                      : "The data are the ship's measured data named in the case (identify.measured).")
       << " The model is M &nu;&#775; = &tau;<sub>thr</sub> + &tau;<sub>hyd</sub> + &tau;<sub>wind</sub> + "
          "&tau;<sub>ice</sub> in surge, sway and yaw, solved for &tau;<sub>ice</sub> (PHYSICS.md &sect;4.4).</p>\n";
  if (pg.have("identify/identified.json", "identification numbers"))
    identified_table(body, pg.json("identify/identified.json", "identification numbers"), rs);
  if (pg.have("plots/identified_load.png", "identified load plot"))
    body << "<figure>" << pg.img(run_dir / "plots/identified_load.png", "identified", "identified load plot")
         << "<figcaption>The identified surge ice resistance at the identification's output rate"
         << (round_trip ? " and the simulated one averaged over the same intervals" : "")
         << ", with their means over the identification's window.</figcaption></figure>\n";
}

// 3. The digitisation's statistics (floes/stats.json) as a table, with the power-law fits.
void floe_stats_table(std::ostream& body, Page& pg) {
  const Json st = pg.json("floes/stats.json", "floe statistics");
  body << "<table>\n" << scalar_rows(st);
  if (const Json* img = find(st, {"image"})) body << scalar_rows(*img, "image.");
  for (const auto& [fit, name] : {std::pair{"mle", "maximum likelihood"}, {"truncated_mle", "maximum likelihood, "
                                                                                        "truncated at the largest floe"}})
    if (const Json* a = find(st, {"power_law", fit}))
      body << "<tr><th>power-law exponent (" << name << ")</th><td>" << scalar_text(a->value("alpha", Json()))
           << " &plusmn; " << scalar_text(a->value("alpha_stderr", Json())) << " (n = "
           << scalar_text(a->value("n", Json())) << ", smallest diameter fitted "
           << scalar_text(a->value("d_min_m", Json())) << " m)</td></tr>\n";
  body << "</table>\n";
}

// 3. Section "Ice field": input image and digitised field side by side, statistics, size distribution. A case
// that gives its floes directly ("floes": {"file"}) has neither, and that is no gap in the run (the runner wrote
// no digitise settings).
void ice_field_section(std::ostream& body, const fs::path& run_dir, Page& pg) {
  body << "<h2>Ice field</h2>\n";
  if (!fs::exists(run_dir / "config/digitise.json")) {
    body << "<p>The floes were given directly (case key <code>floes.file</code>): no image was digitised.</p>\n";
    return;
  }
  body << "<div class=\"pair\">\n";
  fs::path photo = run_dir / "image/image.png";
  if (!fs::is_regular_file(photo) && !fs::exists(run_dir / "config/synth.json")) {
    const fs::path p = photo_from_ninja(run_dir);
    if (!p.empty()) photo = p;
  }
  if (fs::is_regular_file(photo) && photo.extension() == ".png")
    body << "<figure>" << pg.img(photo, "image", "input image") << "<figcaption>Input image ("
         << html_escape(photo.filename().string()) << ")</figcaption></figure>\n";
  else
    pg.missing.push_back((fs::is_regular_file(photo) ? photo.string() + " (input photo: not a PNG, not embedded)"
                                                     : std::string("image/image.png (input image)")));
  if (pg.have("floes/overlay.png", "digitised field"))
    body << "<figure>" << pg.img(run_dir / "floes/overlay.png", "overlay", "digitised field")
         << "<figcaption>Digitised floes (outlines and ids on the image)</figcaption></figure>\n";
  body << "</div>\n";
  if (pg.have("floes/stats.json", "digitisation statistics")) floe_stats_table(body, pg);
  if (pg.have("floes/fsd.png", "floe size distribution plot"))
    body << "<figure>" << pg.img(run_dir / "floes/fsd.png", "fsd", "floe size distribution")
         << "<figcaption>Floe size distribution and power-law fit</figcaption></figure>\n";
}

// 3. Section "Hull": the vessel's numbers from the summary and the hull sidecar's (hydrostatics, placement,
// waterline, particulars).
void hull_section(std::ostream& body, const fs::path& run_dir, const Json& summary, Page& pg) {
  body << "<h2>Hull</h2>\n<table>\n";
  if (const Json* v = find(summary, {"vessel"})) body << scalar_rows(*v);
  if (fs::is_regular_file(run_dir / "hull/hull.json")) {
    const Json h = pg.json("hull/hull.json", "hull sidecar");
    // What the simulation's vessel summary already gave (the waterline beam, length, draught, ...) is shown once.
    if (const Json* hy = find_object(h, {"hydrostatics"})) {
      Json rest = *hy;
      if (const Json* v = find(summary, {"vessel"}))
        for (auto it = v->begin(); it != v->end(); ++it) rest.erase(it.key());
      if (rest.contains("volume_m3") && find(summary, {"vessel", "displacement_m3"})) rest.erase("volume_m3");
      body << scalar_rows(rest, "hydrostatics.");
    }
    // A user's mesh: how it was placed and where it floats (floesim-hull's report).
    if (const Json* pl = find_object(h, {"placement"})) body << scalar_rows(*pl, "placement.");
    if (const Json* wl = find_object(h, {"waterline"})) body << scalar_rows(*wl, "waterline.");
    // The angles and lengths the level-ice resistance formulas take (floesim-resistance).
    // The particulars' length, beam and draught are the hydrostatics' (waterline) ones: shown once.
    if (const Json* pa = find_object(h, {"particulars"})) {
      Json rest = *pa;
      for (const char* k : {"length_m", "beam_m", "draught_m"}) rest.erase(k);
      body << scalar_rows(rest, "particulars.");
    }
    body << scalar_rows(h);
  } else if (fs::exists(run_dir / "config/hull.json")) {
    pg.missing.push_back("hull/hull.json (hull particulars)");
  }
  body << "</table>\n";
}

// 3. Section "Fracture": the summary's fracture numbers (events, piece sizes).
void fracture_section(std::ostream& body, const Json& summary) {
  body << "<h2>Fracture</h2>\n";
  if (const Json* fr = find(summary, {"fracture"})) {
    body << "<table>\n" << scalar_rows(*fr);
    if (const Json* ev = find(*fr, {"events"})) body << scalar_rows(*ev, "events.");
    for (const char* d : {"piece_equivalent_diameter_m", "piece_area_m2"})
      if (const Json* q = find(*fr, {d})) body << scalar_rows(*q, std::string(d) + ".");
    body << "</table>\n";
  } else {
    body << "<p class=\"note\">The summary has no fracture section (a run from before fracture was "
            "modelled).</p>\n";
  }
}

// 3. Section "Structure" for a structure as the case's hull body (summary.json "structure") and one per structure
// beside the vessel ("structures"): its load plot, its loads raw and filtered, their cycles and period, the rubble on
// it, how it is held.
void structure_section(std::ostream& body, const fs::path& run_dir, const Json& summary, Page& pg) {
  auto one = [&](const Json& st, const std::string& title, const std::string& id, const std::string& group) {
    body << "<h2>" << html_escape(title) << "</h2>\n";
    const std::string plot = "plots/structure_" + group + "_load.png";
    if (pg.have(plot, "structure load plot"))
      body << "<figure>" << pg.img(run_dir / plot, "plot", "ice load on " + group)
           << "<figcaption>The ice's horizontal load along the structure's heading and its vertical load, each step "
              "and through the 0.5 s moving average.</figcaption></figure>\n";
    body << "<p>The ice's action on the structure, along the ice's drift "
            "(horizontal), across it (transverse) and vertical, in N, and the overturning moment about the "
            "structure's axis at the water line, in N m; filtered: "
         << html_escape(st.value("filter", Json::object()).value("kind", std::string())) << " over "
         << scalar_text(st.value("filter", Json::object()).value("window_s", Json())) << " s.</p>\n"
         << "<table id=\"" << id << "\">\n" << nested_rows(st) << "</table>\n";
  };
  if (const Json* st = find(summary, {"structure"})) one(*st, "Structure", "structure", "vessel");
  if (const Json* list = find(summary, {"structures"}); list && list->is_array())
    for (size_t k = 0; k < list->size(); ++k) {
      const std::string name = (*list)[k].value("name", "structure " + std::to_string(k));
      one((*list)[k], "Structure " + name, "structure-" + std::to_string(k), name);
    }
}

// ", plays 5x real time (25 frames per second, one per 0.2 s simulated)" from the video's sidecar; "" without one.
std::string playback_note(const Json& side) {
  const double speed = number_or_nan(side, {"playback_speed"}), fps = number_or_nan(side, {"fps"});
  if (!std::isfinite(speed) || !std::isfinite(fps)) return "";
  return fmt("; it plays %.3g", speed) + "&times; real time (" + fmt("%g", fps) + " frames per second, one per " +
         fmt("%.3g", speed / fps) + " s simulated)";
}

// 3. Section "Video": embedded up to max_video_mb, else named beside the page; its size and embedding into rs.
void video_section(std::ostream& body, const fs::path& run_dir, const Json& sidecar, const ReportOptions& o, Page& pg,
                   ReportSummary& rs) {
  body << "<h2>Video</h2>\n";
  const fs::path video = run_dir / "video/transit.mp4";
  if (fs::is_regular_file(video)) {
    rs.video_bytes = fs::file_size(video);
    const std::string size = fmt("%.2f MB", rs.video_bytes / 1e6);
    if (rs.video_bytes <= o.max_video_mb * 1e6) {
      pg.inputs.push_back({"video", video});
      body << "<video controls preload=\"auto\" src=\"data:video/mp4;base64,"
           << base64_encode(read_bytes(video)) << "\"></video>\n<p class=\"note\">video/transit.mp4, " << size
           << ", embedded" << playback_note(sidecar) << ".</p>\n";
      rs.video_embedded = true;
    } else {
      body << "<p class=\"missing\" id=\"video-not-embedded\">The video video/transit.mp4 (" << size
           << ") is larger than max_video_mb = " << fmt("%g", o.max_video_mb)
           << " MB and is not embedded: open it beside this page" << playback_note(sidecar) << ".</p>\n";
    }
  } else {
    pg.missing.push_back("video/transit.mp4 (video)");
    body << "<p class=\"missing\" id=\"video-missing\">The video is missing (video/transit.mp4).</p>\n";
  }
}

// 3. Section "Settings": every stage's config/*.json in name order, and the simulation settings as resolved.
void settings_section(std::ostream& body, const fs::path& run_dir, const Json& summary, Page& pg) {
  body << "<h2>Settings</h2>\n";
  std::vector<fs::path> configs;
  if (fs::is_directory(run_dir / "config"))
    for (const auto& e : fs::directory_iterator(run_dir / "config"))
      if (e.path().extension() == ".json") configs.push_back(e.path());
  std::sort(configs.begin(), configs.end());
  if (configs.empty()) pg.missing.push_back("config/*.json (the stages' settings)");
  for (const fs::path& c : configs) {
    const Json j = pg.json("config/" + c.filename().string(), "config");
    body << "<details open><summary>config/" << html_escape(c.filename().string()) << "</summary><pre>"
         << html_escape(j.dump(2)) << "</pre></details>\n";
  }
  if (const Json* s = find(summary, {"settings"}))
    body << "<details><summary>simulation settings as resolved (sim/summary.json)</summary><pre>"
         << html_escape(s->dump(2)) << "</pre></details>\n";
}

}  // namespace

ReportSummary write_report(const fs::path& run_dir, const ReportOptions& o, const fs::path& out,
                           const Json& resolved_config) {
  ReportSummary rs;
  rs.out = out;
  Page pg;
  pg.run = run_dir;

  // 1. The summary is the run: without it there is nothing to report.
  const Json summary = read_run_summary(run_dir, pg);

  // 2. The numbers of the mean-load table.
  mean_load_numbers(summary, o, rs);

  // 3. The sections, each from its artefact; a missing one is named in the box at the top.
  std::ostringstream body;
  const std::string run_name = fs::absolute(run_dir).lexically_normal().string();
  const fs::path case_json = case_file(run_dir).lexically_normal();
  const std::string title = report_title(o, run_name, case_json);
  case_section(body, run_name, case_json, summary, pg);
  const Json video_sidecar = optional_json(pg, "video/transit.json", "video sidecar");  // read once: a provenance input
  warnings_section(body, summary, video_sidecar);
  const bool structure = is_structure_run(summary.value("settings", Json::object()));
  mean_loads_section(body, rs, structure);
  load_plot_section(body, run_dir, pg, structure);
  identified_section(body, run_dir, pg, rs);
  ice_field_section(body, run_dir, pg);
  hull_section(body, run_dir, summary, pg);
  structure_section(body, run_dir, summary, pg);
  fracture_section(body, summary);
  video_section(body, run_dir, video_sidecar, o, pg, rs);
  settings_section(body, run_dir, summary, pg);

  // 4. Provenance of the page, then the page: the missing box first.
  rs.missing = pg.missing;
  rs.bytes = write_page(out, title, body.str(), pg, resolved_config);
  return rs;
}

ReportSummary write_report(const fs::path& run_dir, const fs::path& config, const fs::path& out) {
  const ReportOptions o = config.empty() ? ReportOptions{} : read_report_options(config);
  return write_report(run_dir, o, out, options_to_json(o));
}

SweepReportSummary write_sweep_report(const fs::path& sweep_dir, const ReportOptions& o, const fs::path& out,
                                      const Json& resolved_config) {
  SweepReportSummary rs;
  rs.out = out;
  Page pg;
  pg.run = sweep_dir;
  pg.kind = "sweep";
  FLOESIM_REQUIRE(fs::is_directory(sweep_dir), sweep_dir.string(),
                  ": not a folder; give --sweep the output folder of `floesim sweep` (e.g. runs/<sweep>)");
  FLOESIM_REQUIRE(fs::is_regular_file(sweep_dir / "sweep.json"), (sweep_dir / "sweep.json").string(),
                  " is missing: the sweep has not been gathered (run `floesim sweep` to the end first); no report "
                  "written");
  const Json sw = pg.json("sweep.json", "gathered sweep");
  FLOESIM_REQUIRE(sw.value("format", "") == "floesim-sweep-results/1", (sweep_dir / "sweep.json").string(),
                  ": format is not floesim-sweep-results/1; regather with this version's floesim-gather");
  const Json plan = fs::is_regular_file(sweep_dir / "plan.json") ? pg.json("plan.json", "sweep plan") : Json::object();
  const std::string name = sw.value("name", sweep_dir.filename().string());
  const std::string title = o.title.empty() ? "floesim sweep report: " + name : o.title;
  const std::vector<ReferenceLoad> refs = o.all_references();

  std::ostringstream body;
  // The sweep: what it varies, over which case.
  body << "<h2>Sweep</h2>\n<table>\n<tr><th>sweep folder</th><td>"
       << html_escape(fs::absolute(sweep_dir).lexically_normal().string()) << "</td></tr>\n";
  const std::string sweep_file = sw.value("sweep_file", "");
  if (!sweep_file.empty()) {
    body << "<tr><th>sweep file</th><td>" << html_escape(sweep_file) << "</td></tr>\n";
    if (const std::string d = case_description(sweep_file); !d.empty())
      body << "<tr><th>description</th><td>" << html_escape(d) << "</td></tr>\n";
  }
  if (const std::string base = plan.value("base_case", ""); !base.empty()) {
    body << "<tr><th>base case</th><td>" << html_escape(base) << "</td></tr>\n";
    if (const std::string d = case_description(fs::path(base) / "case.json"); !d.empty())
      body << "<tr><th>base case description</th><td>" << html_escape(d) << "</td></tr>\n";
  }
  // Each axis by the name its option's description gives it (the key, for a sweep gathered before labels), the
  // key and the option's meaning in a tooltip.
  std::vector<std::string> axis_keys, axis_labels;
  if (sw.contains("axes") && sw["axes"].is_array())
    for (const Json& a : sw["axes"]) {
      axis_keys.push_back(a.value("key", ""));
      axis_labels.push_back(a.value("label", axis_keys.back()));
      std::string values;
      for (const Json& v : a.value("values", Json::array())) values += (values.empty() ? "" : ", ") + scalar_text(v);
      body << "<tr><th title=\"" << html_escape(axis_keys.back() + ": " + a.value("doc", "")) << "\">"
           << html_escape(axis_labels.back()) << "</th><td>varied over " << values << "</td></tr>\n";
    }
  if (const Json& e = sw.value("ensemble", Json()); e.is_object()) {
    // "3 members at each grid point, each with another floe field and start (0.001 m apart)".
    std::string vary;
    for (const Json& v : e.value("vary", Json::array())) {
      if (!v.is_string()) continue;
      const std::string what = v == "field_seed" ? "floe field" : v.get<std::string>();
      vary += (vary.empty() ? "" : " and ") + what;
    }
    const Json size = e.value("size", Json());
    std::string text = scalar_text(size) + (size == 1 ? " member" : " members") + " at each grid point";
    if (!vary.empty()) text += ", each with another " + html_escape(vary);
    if (const Json& step = e.value("start_step_m", Json()); step.is_number() && vary.find("start") != std::string::npos)
      text += " (starts " + readable_number(step.get<double>()) + " m apart)";
    body << "<tr><th title=\"ensemble\">ensemble</th><td>" << text << "</td></tr>\n";
  }
  body << "</table>\n";

  // The ensemble means, one row per grid point, each against the references.
  body << "<h2>Mean surge ice resistance per grid point</h2>\n<table id=\"grid-points\">\n<tr>";
  for (size_t a = 0; a < axis_keys.size(); ++a)
    body << "<th title=\"" << html_escape(axis_keys[a]) << "\">" << html_escape(axis_labels[a]) << "</th>";
  // One unit for the table, from the largest mean (N for a tank model, kN for a ship).
  double typical_kN = 0;
  if (sw.contains("grid_points") && sw["grid_points"].is_array())
    for (const Json& g : sw["grid_points"])
      if (const double m = number_or_nan(g, {"mean_kN"}); std::isfinite(m)) typical_kN = std::max(typical_kN, std::abs(m));
  const ForceUnit unit = force_unit_for(1000.0 * typical_kN);
  auto in_unit = [&](double x_kN) { return load_in(x_kN, unit); };
  body << "<th>members ok</th><th>mean, " << unit.name << "</th><th>standard deviation, " << unit.name
       << "</th><th>95 % interval, " << unit.name << "</th>";
  for (const ReferenceLoad& r : refs)
    body << "<th>against " << html_escape(r.label) << " (" << load_text(1000.0 * r.kN, unit) << "), %</th>";
  body << "</tr>\n";
  if (sw.contains("grid_points") && sw["grid_points"].is_array())
    for (const Json& g : sw["grid_points"]) {
      ++rs.grid_points;
      body << "<tr>";
      for (const std::string& k : axis_keys)
        body << "<td>" << scalar_text(g.contains("axes") ? g["axes"].value(k, Json()) : Json()) << "</td>";
      const double mean = number_or_nan(g, {"mean_kN"}), ci = number_or_nan(g, {"ci95_half_width_kN"});
      body << "<td class=\"n\">" << scalar_text(g.value("n_ok", Json())) << " / "
           << scalar_text(g.value("n_members", Json())) << "</td><td class=\"n\">" << in_unit(mean)
           << "</td><td class=\"n\">" << in_unit(number_or_nan(g, {"std_kN"})) << "</td><td class=\"n\">"
           << (std::isfinite(ci) ? "&plusmn; " + in_unit(ci) : in_unit(ci)) << "</td>";
      for (const ReferenceLoad& r : refs) {
        const ReferenceComparison c = compare_to_reference(mean, r);
        body << "<td class=\"n\">" << (std::isfinite(c.error_percent) ? fmt("%+.1f", c.error_percent) : "&ndash;");
        if (std::isfinite(ci)) body << " &plusmn; " << fmt("%.1f", 100 * ci / r.kN);
        body << "</td>";
      }
      body << "</tr>\n";
    }
  body << "</table>\n";
  if (refs.empty())
    body << "<p class=\"note\">No reference value given (the base case's <code>report</code> section: "
            "<code>references</code>).</p>\n";

  // The gathered plots, as the gather lists them.
  body << "<h2>Plots</h2>\n";
  size_t plots = 0;
  if (sw.contains("files") && sw["files"].is_array())
    for (const Json& f : sw["files"]) {
      const std::string file = f.is_string() ? f.get<std::string>() : "";
      if (fs::path(file).extension() != ".png") continue;
      if (!pg.have(file, "gathered plot")) continue;
      body << "<figure>" << pg.img(sweep_dir / file, "plot " + file, file) << "<figcaption>"
           << html_escape(file) << "</figcaption></figure>\n";
      ++plots;
    }
  if (plots == 0) pg.missing.push_back("*.png (the gather's plots)");

  // Every member, with the gather's columns (the error text goes to the list of failures below).
  body << "<h2>Members</h2>\n<div class=\"wide\"><table id=\"members\">\n<tr>";
  std::vector<std::string> columns;
  if (sw.contains("columns") && sw["columns"].is_array())
    for (const Json& c : sw["columns"])
      if (c.is_string() && c.get<std::string>() != "error") columns.push_back(c.get<std::string>());
  // Headed by the axes' labels and the other columns' words, each with its key in a tooltip.
  for (const std::string& c : columns) {
    const auto axis = std::find(axis_keys.begin(), axis_keys.end(), c);
    const std::string label = axis != axis_keys.end() ? html_escape(axis_labels[axis - axis_keys.begin()]) : human_label(c);
    body << "<th title=\"" << html_escape(c) << "\">" << label << "</th>";
  }
  body << "</tr>\n";
  std::ostringstream failures;
  if (sw.contains("members") && sw["members"].is_array())
    for (const Json& m : sw["members"]) {
      ++rs.members;
      const bool ok = m.value("status", "") == "ok";
      body << "<tr>";
      for (const std::string& c : columns) {
        const Json v = m.value(c, Json());
        body << "<td" << (v.is_number() ? " class=\"n\"" : "") << ">" << scalar_text(v) << "</td>";
      }
      body << "</tr>\n";
      if (!ok) {
        ++rs.failed;
        failures << "<li><strong>" << html_escape(m.value("member", "?")) << "</strong>: <pre>"
                 << html_escape(m.value("error", "")) << "</pre></li>\n";
      }
    }
  body << "</table></div>\n";
  if (rs.failed > 0)
    body << "<div class=\"missing\" id=\"failed-members\"><strong>" << rs.failed
         << " member(s) failed</strong> and are left out of the means:<ul>\n" << failures.str() << "</ul></div>\n";
  if (sw.contains("units") && sw["units"].is_object())
    body << "<details><summary>what the columns mean (sweep.json units)</summary><table>\n" << scalar_rows(sw["units"])
         << "</table></details>\n";

  rs.missing = pg.missing;
  rs.bytes = write_page(out, title, body.str(), pg, resolved_config);
  return rs;
}

}  // namespace floesim::render
