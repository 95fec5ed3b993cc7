#include "pipeline/runner/plan.h"

#include <fstream>
#include <map>
#include <sstream>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/options.h"
#include "pipeline/provenance.h"

namespace fs = std::filesystem;

namespace floesim::runner {
namespace {

// Ninja path escaping ($, space, colon), and '$' in command lines.
std::string ninja_path(const fs::path& p) {
  std::string out;
  for (char c : p.string()) {
    if (c == '$' || c == ' ' || c == ':') out += '$';
    out += c;
  }
  return out;
}
std::string ninja_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '$') out += '$';
    out += c;
  }
  return out;
}

const Json& require_object(const Json& j, const std::string& key, const std::string& file) {
  FLOESIM_REQUIRE(j.contains(key), file, ": missing key \"", key, "\"");
  FLOESIM_REQUIRE(j.at(key).is_object(), file, ": \"", key, "\" must be an object, got ", j.at(key).dump());
  return j.at(key);
}

std::string number(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

}  // namespace

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string shell_command(const PlannedStage& s) {
  std::string cmd = shell_quote(s.exe.string());
  for (const std::string& a : s.args) cmd += " " + shell_quote(a);
  if (s.resumable) cmd += " ${FLOESIM_RESUME:+--resume}";  // POSIX sh: the word only when the variable is set
  return cmd;
}

void write_if_changed(const fs::path& file, const std::string& text) {
  if (fs::exists(file)) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    if (ss.str() == text) return;
  }
  write_text_atomic(file, text);
}

fs::path self_dir() {
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::current_path() : p.parent_path();
}

std::string run_folder(const std::string& stage) {
  static const std::map<std::string, std::string> folder = {{"synth", "image"},  {"digitise", "floes"},
                                                            {"hull", "hull"},    {"simulate", "sim"},
                                                            {"shipdata", "shipdata"}, {"identify", "identify"},
                                                            {"render", "video"}, {"plot", "plots"},
                                                            {"report", "report"}};
  return folder.at(stage);
}

void absolute_case_files(Json& c, const fs::path& case_dir) {
  auto fix = [&](Json* j, const char* key) {
    if (j && j->is_object() && j->contains(key) && (*j)[key].is_string()) {
      const fs::path p = (*j)[key].get<std::string>();
      if (p.is_relative()) (*j)[key] = (fs::absolute(case_dir) / p).lexically_normal().string();
    }
  };
  auto at = [](Json& j, const char* key) { return j.is_object() && j.contains(key) ? &j[key] : nullptr; };
  fix(at(c, "image"), "file");
  fix(at(c, "floes"), "file");
  fix(at(c, "hull"), "file");
  fix(at(c, "identify"), "measured");
  if (Json* s = at(c, "simulate"))
    if (Json* v = at(*s, "vessel")) fix(at(*v, "propulsion"), "thrust_file");
}

CasePlan plan_case(const Json& c, const std::string& where, const fs::path& case_dir, const fs::path& bin,
                   const StageLayout& layout, bool render, bool report) {
  const std::string& cf = where;
  FLOESIM_REQUIRE(c.is_object(), cf, ": the top level must be an object");
  const std::vector<std::string> known = {"description", "image", "digitise", "floes", "hull", "simulate", "identify",
                                          "render", "plot", "report"};
  for (auto it = c.begin(); it != c.end(); ++it) {
    bool ok = false;
    for (auto& k : known) ok = ok || k == it.key();
    FLOESIM_REQUIRE(ok, cf, ": unknown key \"", it.key(),
                    "\" (known: description, image, digitise, floes, hull, simulate, identify, render, plot, report)");
  }
  // Floes come from a photo (image + digitise) or directly from a floes GeoJSON the case owns ("floes": {"file"}).
  FLOESIM_REQUIRE(c.contains("image") != c.contains("floes"), cf,
                  ": give exactly one of \"image\" (a photo or synthetic image, digitised into floes) or \"floes\" "
                  "({\"file\": \"floes.geojson\"}: floe polygons given directly)");
  FLOESIM_REQUIRE(!(c.contains("floes") && c.contains("digitise")), cf,
                  ": \"digitise\" has no effect with \"floes\" (the floes are given directly): remove it");

  auto case_input = [&](const Json& j, const std::string& key, const std::string& where) {
    FLOESIM_REQUIRE(j.contains(key) && j.at(key).is_string(), cf, ": ", where, ".", key, " must be a file name");
    fs::path p = j.at(key).get<std::string>();
    if (p.is_relative()) p = fs::absolute(case_dir) / p;
    FLOESIM_REQUIRE(fs::exists(p), cf, ": ", where, ".", key, " names ", p.string(), ", which does not exist");
    // A folder (".", "") was hashed as if empty, and a device (/dev/zero) was hashed forever: only a file will do.
    std::error_code ec;
    FLOESIM_REQUIRE(fs::is_regular_file(p, ec), cf, ": ", where, ".", key, " names ", p.string(),
                    ", which is not a file (a folder or a device?): name the file itself");
    return p.lexically_normal();
  };

  CasePlan plan;
  // What each input file is, for the content keys: another stage's output (that stage's key and the file's name)
  // or a file of the case (its SHA-256).
  std::map<fs::path, std::string> identity;
  auto identify = [&](const fs::path& p) {
    auto it = identity.find(p);
    if (it != identity.end()) return it->second;
    return identity[p] = "file " + sha256_file(p);
  };
  // Adds a stage: its key from its name, settings and inputs; then its folder, settings file and outputs.
  auto add = [&](const std::string& name, const std::string& description, const Json& settings,
                 std::vector<fs::path> inputs, const std::vector<std::string>& output_names, const char* exe) {
    PlannedStage s;
    s.name = name;
    s.description = description;
    s.config_text = settings.dump(2) + "\n";
    std::string id = name + "\n" + s.config_text;
    for (const fs::path& p : inputs) id += identify(p) + "\n";
    s.key = sha256_bytes(id).substr(0, 16);
    s.dir = layout.dir(name, s.key);
    s.config = layout.config(name, s.key);
    inputs.push_back(s.config);
    s.inputs = inputs;
    for (const std::string& f : output_names) {
      s.outputs.push_back(s.dir / f);
      identity[s.outputs.back()] = "stage " + s.key + " " + f;
    }
    s.exe = bin / exe;
    plan.stages.push_back(s);
    return &plan.stages.back();
  };
  auto rel = [&](const fs::path& p, const std::string& base) { return base + "/" + p.filename().string(); };

  // --- floes given directly: the case's GeoJSON goes to simulate as it is (no image, no digitise stage) ---
  fs::path floes_file;
  if (c.contains("floes")) {
    const Json& fl = require_object(c, "floes", cf);
    for (auto it = fl.begin(); it != fl.end(); ++it)
      FLOESIM_REQUIRE(it.key() == "file", cf, ": unknown key floes.", it.key(), " (known: file)");
    floes_file = case_input(fl, "file", "floes");
  } else {
    // --- image: a photo the case owns, or a synthetic one made from known floes ---
    const Json& image = require_object(c, "image", cf);
    for (auto it = image.begin(); it != image.end(); ++it)
      FLOESIM_REQUIRE(it.key() == "metres_per_pixel" || it.key() == "synthetic" || it.key() == "file", cf,
                      ": unknown key image.", it.key(), " (known: metres_per_pixel, file, synthetic)");
    FLOESIM_REQUIRE(image.contains("metres_per_pixel") && image["metres_per_pixel"].is_number() &&
                        image["metres_per_pixel"].get<double>() > 0,
                    cf, ": image.metres_per_pixel must be a number > 0 (the ground size of one pixel)");
    const double mpp = image["metres_per_pixel"].get<double>();
    FLOESIM_REQUIRE(image.contains("synthetic") != image.contains("file"), cf,
                    ": image needs exactly one of \"file\" (a photo) or \"synthetic\" (options for floesim-synth)");
    fs::path image_png;
    if (image.contains("synthetic")) {
      Json s = image["synthetic"];
      FLOESIM_REQUIRE(s.is_object(), cf, ": image.synthetic must be an object");
      FLOESIM_REQUIRE(!s.contains("metres_per_pixel"), cf,
                      ": image.synthetic.metres_per_pixel: set the scale once, in image.metres_per_pixel");
      s["metres_per_pixel"] = mpp;
      PlannedStage* st = add("synth", "synthetic helicopter image from known floes", s, {},
                             {"image.png", "truth.geojson", "truth_labels.png"}, "floesim-synth");
      st->args = {"--config", st->config.string(), "--out", st->dir.string()};
      image_png = st->outputs[0];
      plan.artefacts.push_back({"synth", rel(image_png, "image"), "synthetic helicopter image (8-bit grey)"});
      plan.artefacts.push_back({"synth", "image/truth.geojson", "the true floe polygons (m)"});
    } else {
      image_png = case_input(image, "file", "image");
    }

    // --- digitise ---
    Json d = c.contains("digitise") ? c["digitise"] : Json::object();
    FLOESIM_REQUIRE(d.is_object(), cf, ": digitise must be an object");
    PlannedStage* st = add("digitise", "floe segmentation and polygons", d, {image_png},
                           {"floes.geojson", "labels.png", "overlay.png", "stats.json", "fsd.png", "fsd.csv"},
                           "floesim-digitise");
    st->args = {image_png.string(), "--metres-per-pixel", number(mpp), "--config", st->config.string(), "--out",
                st->dir.string()};
    floes_file = st->outputs[0];
    plan.artefacts.push_back({"digitise", "floes/floes.geojson", "floe polygons, m (GeoJSON)"});
    plan.artefacts.push_back({"digitise", "floes/labels.png", "16-bit label image, k = floe id"});
    plan.artefacts.push_back({"digitise", "floes/overlay.png", "outlines on the photo"});
    plan.artefacts.push_back({"digitise", "floes/stats.json", "count, concentration, size distribution"});
    plan.artefacts.push_back({"digitise", "floes/fsd.png", "floe size distribution and power-law fit"});
  }

  // --- hull: a user's mesh, or the parametric icebreaker ---
  fs::path hull_obj;
  {
    const Json& h = require_object(c, "hull", cf);
    FLOESIM_REQUIRE(h.contains("generate") != h.contains("file"), cf,
                    ": hull needs exactly one of \"file\" (an OBJ or any mesh assimp reads, with its placement "
                    "options beside it) or \"generate\" (options for floesim-hull's parametric icebreaker)");
    FLOESIM_REQUIRE(!h.contains("generate") || h.size() == 1, cf,
                    ": hull.generate takes no keys beside it (the placement options go with \"file\")");
    if (h.contains("generate")) {
      PlannedStage* st = add("hull", "parametric icebreaker hull", h["generate"], {}, {"hull.obj"}, "floesim-hull");
      hull_obj = st->outputs[0];
      st->args = {"--config", st->config.string(), "--out", hull_obj.string()};
      plan.artefacts.push_back({"hull", "hull/hull.obj", "hull as convex parts, m (OBJ)"});
    } else {
      // The user's mesh: floesim-hull places it (scale, up_direction, bow_direction, waterline_z_m, origin_m), cuts it into
      // convex parts, reports what it did in hull.json and refuses a hull that does not float. Its settings are the
      // case's hull section as it stands (the file's path made absolute), checked by the stage itself.
      Json settings = h;
      const fs::path mesh = case_input(h, "file", "hull");
      settings["file"] = mesh.string();
      PlannedStage* st = add("hull", "user's hull mesh placed and cut into convex parts", settings, {mesh},
                             {"hull.obj"}, "floesim-hull");
      hull_obj = st->outputs[0];
      st->args = {"--config", st->config.string(), "--out", hull_obj.string()};
      plan.artefacts.push_back({"hull", "hull/hull.obj", "hull as convex parts in the hull frame, m (OBJ)"});
    }
  }

  // --- simulate ---
  {
    Json s = c.contains("simulate") ? c["simulate"] : Json::object();
    FLOESIM_REQUIRE(s.is_object(), cf, ": simulate must be an object");
    std::vector<fs::path> inputs = {floes_file, hull_obj};
    // A thrust time series named in the case is an input too (its path made absolute for the stage).
    if (s.contains("vessel") && s["vessel"].is_object() && s["vessel"].contains("propulsion") &&
        s["vessel"]["propulsion"].is_object() && s["vessel"]["propulsion"].contains("thrust_file")) {
      const fs::path tf = case_input(s["vessel"]["propulsion"], "thrust_file", "simulate.vessel.propulsion");
      s["vessel"]["propulsion"]["thrust_file"] = tf.string();
      inputs.push_back(tf);
    }
    PlannedStage* st = add("simulate", "vessel transit simulation", s, inputs, {"results.h5", "summary.json"},
                           "floesim-simulate");
    st->args = {"--floes", floes_file.string(), "--hull", hull_obj.string(), "--config", st->config.string(),
                "--out", st->dir.string()};
    st->resumable = true;
    plan.results = st->outputs[0];
    plan.summary = st->outputs[1];
    plan.artefacts.push_back({"simulate", "sim/results.h5", "time series and floe states (HDF5)"});
    plan.artefacts.push_back({"simulate", "sim/summary.json", "mean surge ice load and settings"});
  }

  // --- identify: the ice load back-calculated from a ship's data, as full-scale loads are (PHYSICS.md §4.4) ---
  // From the case's measured data ("measured": a CSV, "config": its identify options), or, with no "measured",
  // from the simulated ship itself (the round trip): floesim-shipdata turns the transit into the data the ship
  // would have recorded, with the sensor noise its "shipdata" options give, and the identify config of the
  // simulated ship, which identify then uses.
  fs::path identify_dir;
  if (c.contains("identify")) {
    const Json& id = require_object(c, "identify", cf);
    for (auto it = id.begin(); it != id.end(); ++it)
      FLOESIM_REQUIRE(it.key() == "measured" || it.key() == "config" || it.key() == "shipdata", cf,
                      ": unknown key identify.", it.key(),
                      " (known: measured, config: a ship's data and its identify options; shipdata: the sensor "
                      "options of the round trip from the simulated ship)");
    for (const char* k : {"config", "shipdata"})
      FLOESIM_REQUIRE(!id.contains(k) || id[k].is_object(), cf, ": identify.", k, " must be an object");
    PlannedStage* st = nullptr;
    if (id.contains("measured")) {
      FLOESIM_REQUIRE(!id.contains("shipdata"), cf,
                      ": identify.shipdata has no effect with identify.measured (the data are the ship's, not made "
                      "from the simulation): remove it");
      const fs::path measured = case_input(id, "measured", "identify");
      st = add("identify", "ice load identified from the measured ship data",
               id.contains("config") ? id["config"] : Json::object(), {measured},
               {"identified.csv", "identified.json"}, "floesim-identify");
      st->args = {"--measured", measured.string(), "--config", st->config.string(), "--out", st->dir.string()};
    } else {
      FLOESIM_REQUIRE(!id.contains("config"), cf,
                      ": identify.config is for a ship's measured data (identify.measured); the round trip "
                      "identifies with the simulated ship's own config: remove it");
      PlannedStage* sd = add("shipdata", "the simulated ship's data as a ship would record them",
                             id.contains("shipdata") ? id["shipdata"] : Json::object(), {plan.results, plan.summary},
                             {"measured.csv", "measured.json"}, "floesim-shipdata");
      sd->args = {"--results", plan.results.string(), "--summary", plan.summary.string(), "--config",
                  sd->config.string(), "--out", sd->outputs[0].string()};
      plan.artefacts.push_back({"shipdata", "shipdata/measured.csv",
                                "the simulated ship's data as recorded (velocities, accelerations, thrust, wind)"});
      const fs::path measured = sd->outputs[0], ship_config = sd->outputs[1];
      // Its own settings file stays empty: the config is the simulated ship's, which shipdata wrote.
      st = add("identify", "ice load identified from the simulated ship's data", Json::object(),
               {measured, ship_config}, {"identified.csv", "identified.json"}, "floesim-identify");
      st->args = {"--measured", measured.string(), "--config", ship_config.string(), "--out", st->dir.string()};
    }
    identify_dir = st->dir;
    plan.artefacts.push_back({"identify", "identify/identified.csv", "identified ice load at 2 Hz (and the known "
                                                                     "load when the data carried one)"});
    plan.artefacts.push_back({"identify", "identify/identified.json", "identified mean ice loads (and their error "
                                                                      "against the known load)"});
  }

  // --- render and plot (independent of each other) ---
  fs::path video, plot_png;
  {
    Json r = c.contains("render") ? c["render"] : Json::object();
    FLOESIM_REQUIRE(r.is_object(), cf, ": render must be an object");
    if (render) {
      PlannedStage* st = add("render", "off-screen frames and H.264 video", r, {plan.results}, {"transit.mp4"},
                             "floesim-render");
      st->args = {"--results", plan.results.string(), "--config", st->config.string(), "--out",
                  st->outputs[0].string()};
      video = st->outputs[0];
      plan.artefacts.push_back({"render", "video/transit.mp4", "rendered transit (H.264 MP4)"});
    }
  }
  {
    Json p = c.contains("plot") ? c["plot"] : Json::object();
    FLOESIM_REQUIRE(p.is_object(), cf, ": plot must be an object");
    std::vector<fs::path> inputs = {plan.results};
    std::vector<std::string> outputs = {"surge_ice_load.png", "surge_ice_load.svg", "fracture_events.csv"};
    if (!identify_dir.empty()) {
      inputs.push_back(identify_dir / "identified.csv");
      inputs.push_back(identify_dir / "identified.json");
      outputs.push_back("identified_load.png");
    }
    PlannedStage* st = add("plot", "surge ice load plots", p, inputs, outputs, "floesim-plot");
    st->args = {"--results", plan.results.string(), "--config", st->config.string(), "--out", st->dir.string()};
    if (!identify_dir.empty()) {
      st->args.push_back("--identified");
      st->args.push_back(identify_dir.string());
      plan.artefacts.push_back(
          {"plot", "plots/identified_load.png", "identified against simulated surge ice load, same filter (PNG)"});
    }
    plot_png = st->outputs[0];
    plan.artefacts.push_back({"plot", "plots/surge_ice_load.png", "surge ice load, moving average and mean (PNG)"});
    plan.artefacts.push_back({"plot", "plots/surge_ice_load.svg", "the same (SVG)"});
    plan.artefacts.push_back(
        {"plot", "plots/fracture_events.csv", "every fracture event: time, mode, floe, force, children"});
  }

  // --- report: one self-contained page over the run folder (only a run's: it reads the folder's layout) ---
  {
    Json r = c.contains("report") ? c["report"] : Json::object();
    FLOESIM_REQUIRE(r.is_object(), cf, ": report must be an object");
    if (render && report) {
      // It reads the whole run folder; the summary, the plot and the video are what make it stale (every other
      // artefact it shows lies upstream of the summary).
      std::vector<fs::path> inputs = {plan.summary, plot_png, video};
      if (!identify_dir.empty()) inputs.push_back(identify_dir / "identified.json");
      PlannedStage* st = add("report", "self-contained HTML report", r, inputs, {"report.html"}, "floesim-report");
      st->args = {"--run", st->dir.parent_path().string(), "--config", st->config.string(), "--out",
                  st->outputs[0].string()};
      plan.artefacts.push_back({"report", "report/report.html", "the run on one page: case, loads, plots, field, "
                                                                "hull, fracture, settings, video (HTML)"});
    }
  }
  return plan;
}

std::string stage_script(const std::vector<PlannedStage>& stages, size_t k, StageOutput output) {
  // Stage k's outputs and everything downstream of them (the list is in dependency order).
  std::vector<fs::path> dirty(stages[k].outputs);
  for (size_t j = k + 1; j < stages.size(); ++j) {
    bool depends = false;
    for (auto& in : stages[j].inputs)
      for (auto& d : dirty) depends = depends || in == d;
    if (depends) dirty.insert(dirty.end(), stages[j].outputs.begin(), stages[j].outputs.end());
  }
  const PlannedStage& s = stages[k];
  // AtomicFile's temporaries (".tmp-<pid>-<name>") a killed run of this stage left; the glob stays unquoted.
  const std::string stale = " " + shell_quote(s.dir.string()) + "/.tmp-*";
  if (output == StageOutput::console) {
    std::string rm = "rm -f";
    for (auto& p : dirty) rm += " " + shell_quote(p.string());
    return rm + stale + " && " + shell_command(s);
  }
  // A sweep's stage is shared by members that come and go: the list of what lies downstream of it is a file
  // beside it (written with its settings), so that a new member does not change its command and rerun it.
  std::string list;
  for (auto& p : dirty) list += p.string() + "\n";
  write_if_changed(s.dir / "downstream.txt", list);
  const std::string log = shell_quote((s.dir / "log.txt").string()), wall = shell_quote((s.dir / "wall_ms").string());
  const std::string rm = "tr '\\n' '\\0' < " + shell_quote((s.dir / "downstream.txt").string()) +
                         " | xargs -0 rm -f && rm -f " + wall + stale;
  // POSIX sh: the wall time from date +%s%N (GNU date: nanoseconds), written after the stage whatever its outcome,
  // under a temporary name renamed into place (a kill never leaves an empty wall_ms that gather would misread).
  const std::string wall_tmp = shell_quote((s.dir / ".tmp-0-wall_ms").string());
  return rm + " && t0=$(date +%s%N) && { " + shell_command(s) + " > " + log +
         " 2>&1; rc=$?; echo $(( ($(date +%s%N) - t0) / 1000000 )) > " + wall_tmp + " && mv -f " + wall_tmp + " " +
         wall + "; [ $rc -eq 0 ] || { tail -n 15 " + log + " >&2; exit $rc; }; }";
}

void write_ninja(const fs::path& file, const std::string& header, const std::vector<PlannedStage>& stages,
                 const std::vector<std::string>& descriptions, StageOutput output) {
  std::ostringstream nf;
  nf << header << "ninja_required_version = 1.5\n\n"
     << "rule stage\n  command = $cmd\n  description = $desc\n\n";
  for (size_t k = 0; k < stages.size(); ++k) {
    const PlannedStage& s = stages[k];
    for (auto& p : s.outputs) ensure_directory(p.parent_path());
    nf << "build";
    for (auto& p : s.outputs) nf << " " << ninja_path(p);
    nf << ": stage";
    for (auto& p : s.inputs) nf << " " << ninja_path(p);
    nf << " | " << ninja_path(s.exe) << "\n";
    nf << "  cmd = " << ninja_escape(stage_script(stages, k, output)) << "\n";
    nf << "  desc = " << descriptions[k] << "\n\n";
  }
  write_if_changed(file, nf.str());
}

}  // namespace floesim::runner
