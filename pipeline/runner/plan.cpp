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
  if (stage.rfind("structure-", 0) == 0) return stage;  // a structure's mesh (case "structures"): its own folder
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
  if (Json* list = at(c, "structures"))
    if (list->is_array())
      for (Json& e : *list) fix(at(e, "hull"), "file");
  fix(at(c, "identify"), "measured");
  if (Json* s = at(c, "simulate"))
    if (Json* v = at(*s, "vessel")) fix(at(*v, "propulsion"), "thrust_file");
}

namespace {

// Plans a case's stages, one step per stage family (in data-flow order), each adding its stages to `plan` with the
// content key of its settings and inputs.
class CasePlanner {
 public:
  CasePlanner(const Json& c, const std::string& where, const fs::path& case_dir, const fs::path& bin,
              const StageLayout& layout)
      : c_(c), cf_(where), case_dir_(case_dir), bin_(bin), layout_(layout) {}

  // 1. The case's top level: known keys only; floes from a photo or given directly.
  void check_top_level() const {
    FLOESIM_REQUIRE(c_.is_object(), cf_, ": the top level must be an object");
    const std::vector<std::string> known = {"description", "image",    "digitise", "floes", "hull",  "structures",
                                            "simulate",    "identify", "render",   "plot",  "report"};
    for (auto it = c_.begin(); it != c_.end(); ++it) {
      bool ok = false;
      for (auto& k : known) ok = ok || k == it.key();
      FLOESIM_REQUIRE(ok, cf_, ": unknown key \"", it.key(),
                      "\" (known: description, image, digitise, floes, hull, structures, simulate, identify, "
                      "render, plot, report)");
    }
    // Floes come from a photo (image + digitise) or directly from a floes GeoJSON the case owns ("floes": {"file"}).
    FLOESIM_REQUIRE(c_.contains("image") != c_.contains("floes"), cf_,
                    ": give exactly one of \"image\" (a photo or synthetic image, digitised into floes) or \"floes\" "
                    "({\"file\": \"floes.geojson\"}: floe polygons given directly)");
    FLOESIM_REQUIRE(!(c_.contains("floes") && c_.contains("digitise")), cf_,
                    ": \"digitise\" has no effect with \"floes\" (the floes are given directly): remove it");
  }

  // 2. The floes: the case's GeoJSON as it is, or a photo (the case's, or a synthetic one) digitised.
  void plan_floes() {
    if (c_.contains("floes")) {
      const Json& fl = require_object(c_, "floes", cf_);
      for (auto it = fl.begin(); it != fl.end(); ++it)
        FLOESIM_REQUIRE(it.key() == "file", cf_, ": unknown key floes.", it.key(), " (known: file)");
      floes_file_ = case_input(fl, "file", "floes");
      return;
    }
    const Json& image = require_object(c_, "image", cf_);
    for (auto it = image.begin(); it != image.end(); ++it)
      FLOESIM_REQUIRE(it.key() == "metres_per_pixel" || it.key() == "synthetic" || it.key() == "file", cf_,
                      ": unknown key image.", it.key(), " (known: metres_per_pixel, file, synthetic)");
    FLOESIM_REQUIRE(image.contains("metres_per_pixel") && image["metres_per_pixel"].is_number() &&
                        image["metres_per_pixel"].get<double>() > 0,
                    cf_, ": image.metres_per_pixel must be a number > 0 (the ground size of one pixel)");
    const double mpp = image["metres_per_pixel"].get<double>();
    FLOESIM_REQUIRE(image.contains("synthetic") != image.contains("file"), cf_,
                    ": image needs exactly one of \"file\" (a photo) or \"synthetic\" (options for floesim-synth)");
    const fs::path image_png = image.contains("synthetic") ? plan_synth(image, mpp) : case_input(image, "file", "image");
    plan_digitise(image_png, mpp);
  }

  // 3. The hull: a user's mesh placed and cut into convex parts, or the parametric icebreaker.
  void plan_hull() { hull_obj_ = plan_hull_stage(require_object(c_, "hull", cf_), "hull", "hull"); }

  // 3. The structures beside the vessel (case "structures": [{"name", "hull": {...} as the case's hull, and the
  // simulate options of a structure}]): each one's mesh by a stage of its own ("structure-NAME"), its options into
  // simulate.structures with the mesh as its hull_file.
  void plan_structures() {
    if (!c_.contains("structures")) return;
    const Json& list = c_["structures"];
    FLOESIM_REQUIRE(list.is_array() && !list.empty(), cf_, ": structures must be a non-empty list of "
                    "{\"name\", \"hull\": {...}, and the structure's simulate options}");
    for (size_t k = 0; k < list.size(); ++k) {
      const std::string key = "structures[" + std::to_string(k) + "]";
      const Json& e = list[k];
      FLOESIM_REQUIRE(e.is_object() && e.contains("name") && e["name"].is_string() && e.contains("hull"), cf_, ": ",
                      key, " needs \"name\" (a string) and \"hull\" (as the case's hull: file, generate or "
                      "structure)");
      const std::string name = e["name"].get<std::string>();
      FLOESIM_REQUIRE(!name.empty() && name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                              "0123456789-_") == std::string::npos,
                      cf_, ": ", key, ".name \"", name, "\" may hold only letters, digits, '-' and '_'");
      FLOESIM_REQUIRE(!e.contains("hull_file"), cf_, ": ", key, ".hull_file is set by the runner from ", key,
                      ".hull: remove it");
      const fs::path obj = plan_hull_stage(require_object(e, "hull", cf_ + ": " + key), "structure-" + name,
                                           key + ".hull");
      Json options = e;
      options.erase("hull");
      options["hull_file"] = obj.string();
      structures_.push_back(options);
      structure_objs_.push_back(obj);
    }
  }

  // A hull stage: floesim-hull makes `stage`/hull.obj from the hull section `h` (the case's "key").
  fs::path plan_hull_stage(const Json& h, const std::string& stage, const std::string& key) {
    const std::string folder = run_folder(stage);
    FLOESIM_REQUIRE(int(h.contains("generate")) + int(h.contains("file")) + int(h.contains("structure")) == 1, cf_,
                    ": ", key, " needs exactly one of \"file\" (an OBJ or any mesh assimp reads, with its placement "
                    "options beside it), \"generate\" (options for floesim-hull's parametric icebreaker) or "
                    "\"structure\" (floesim-hull's structure from parameters: cone, cylinder, caisson)");
    FLOESIM_REQUIRE(!h.contains("generate") || h.size() == 1, cf_, ": ", key,
                    ".generate takes no keys beside it (the placement options go with \"file\")");
    FLOESIM_REQUIRE(!h.contains("structure") || h.size() == 1, cf_, ": ", key,
                    ".structure takes no keys beside it (the placement options go with \"file\")");
    PlannedStage* st = nullptr;
    if (h.contains("structure")) {
      // A structure from parameters: floesim-hull's config is {"structure": {...}}.
      st = add(stage, "hull", "structure from parameters", Json{{"structure", h["structure"]}}, {}, {"hull.obj"},
               "floesim-hull");
      plan_.artefacts.push_back({stage, folder + "/hull.obj", "the structure as convex parts, m (OBJ)"});
    } else if (h.contains("generate")) {
      st = add(stage, "hull.generate", "parametric icebreaker hull", h["generate"], {}, {"hull.obj"}, "floesim-hull");
      plan_.artefacts.push_back({stage, folder + "/hull.obj", "hull as convex parts, m (OBJ)"});
    } else {
      // The user's mesh: floesim-hull places it (scale, up_direction, bow_direction, waterline_z_m, origin_m), cuts
      // it into convex parts, reports what it did in hull.json and refuses a hull that does not float. Its settings
      // are the hull section as it stands (the file's path made absolute), checked by the stage itself.
      Json settings = h;
      const fs::path mesh = case_input(h, "file", key);
      settings["file"] = mesh.string();
      st = add(stage, "hull", "user's hull mesh placed and cut into convex parts", settings, {mesh}, {"hull.obj"},
               "floesim-hull");
      plan_.artefacts.push_back({stage, folder + "/hull.obj", "hull as convex parts in the hull frame, m (OBJ)"});
    }
    st->args = {"--config", st->config.string(), "--out", st->outputs[0].string()};
    return st->outputs[0];
  }

  // 4. The simulation, with the thrust time series the case may name as one more input.
  void plan_simulate() {
    Json s = section("simulate");
    std::vector<fs::path> inputs = {floes_file_, hull_obj_};
    if (!structures_.empty()) {
      FLOESIM_REQUIRE(!s.contains("structures"), cf_, ": give the structures as the case's \"structures\" (each "
                      "with its \"hull\"), not as simulate.structures");
      s["structures"] = structures_;
      inputs.insert(inputs.end(), structure_objs_.begin(), structure_objs_.end());
    }
    // A thrust time series named in the case is an input too (its path made absolute for the stage).
    if (s.contains("vessel") && s["vessel"].is_object() && s["vessel"].contains("propulsion") &&
        s["vessel"]["propulsion"].is_object() && s["vessel"]["propulsion"].contains("thrust_file")) {
      const fs::path tf = case_input(s["vessel"]["propulsion"], "thrust_file", "simulate.vessel.propulsion");
      s["vessel"]["propulsion"]["thrust_file"] = tf.string();
      inputs.push_back(tf);
    }
    PlannedStage* st = add("simulate", "simulate", "vessel transit simulation", s, inputs,
                           {"results.h5", "summary.json"}, "floesim-simulate");
    st->args = {"--floes", floes_file_.string(), "--hull", hull_obj_.string(), "--config", st->config.string(),
                "--out", st->dir.string()};
    st->resumable = true;
    plan_.results = st->outputs[0];
    plan_.summary = st->outputs[1];
    plan_.artefacts.push_back({"simulate", "sim/results.h5", "time series and floe states (HDF5)"});
    plan_.artefacts.push_back({"simulate", "sim/summary.json", "mean surge ice load and settings"});
  }

  // 5. Identify: the ice load back-calculated from a ship's data, as full-scale loads are (PHYSICS.md §4.4). From
  // the case's measured data ("measured": a CSV, "config": its identify options), or, with no "measured", from the
  // simulated ship itself (the round trip): floesim-shipdata turns the transit into the data the ship would have
  // recorded, with the sensor noise its "shipdata" options give, and the identify config of the simulated ship,
  // which identify then uses.
  void plan_identify() {
    if (!c_.contains("identify")) return;
    const Json& id = require_object(c_, "identify", cf_);
    for (auto it = id.begin(); it != id.end(); ++it)
      FLOESIM_REQUIRE(it.key() == "measured" || it.key() == "config" || it.key() == "shipdata", cf_,
                      ": unknown key identify.", it.key(),
                      " (known: measured, config: a ship's data and its identify options; shipdata: the sensor "
                      "options of the round trip from the simulated ship)");
    for (const char* k : {"config", "shipdata"})
      FLOESIM_REQUIRE(!id.contains(k) || id[k].is_object(), cf_, ": identify.", k, " must be an object");
    PlannedStage* st = id.contains("measured") ? plan_identify_measured(id) : plan_identify_round_trip(id);
    identify_dir_ = st->dir;
    plan_.artefacts.push_back({"identify", "identify/identified.csv", "identified ice load at 2 Hz (and the known "
                                                                      "load when the data carried one)"});
    plan_.artefacts.push_back({"identify", "identify/identified.json", "identified mean ice loads (and their error "
                                                                       "against the known load)"});
  }

  // 6. The video (when asked) and the load plots, independent of each other.
  void plan_render(bool render) {
    Json r = section("render");
    if (!render) return;
    PlannedStage* st = add("render", "render", "off-screen frames and H.264 video", r, {plan_.results},
                           {"transit.mp4"}, "floesim-render");
    st->args = {"--results", plan_.results.string(), "--config", st->config.string(), "--out",
                st->outputs[0].string()};
    video_ = st->outputs[0];
    plan_.artefacts.push_back({"render", "video/transit.mp4", "rendered transit (H.264 MP4)"});
  }
  void plan_plot() {
    Json p = section("plot");
    std::vector<fs::path> inputs = {plan_.results};
    std::vector<std::string> outputs = {"surge_ice_load.png", "surge_ice_load.svg", "fracture_events.csv"};
    // Each structure's load plot: the vessel's hull body when it is one ("vessel"), and the structures beside it.
    std::vector<std::string> structures;
    const Json sim = section("simulate");
    if (sim.contains("vessel") && sim["vessel"].is_object() && sim["vessel"].contains("station_keeping") &&
        sim["vessel"]["station_keeping"].is_object() &&
        sim["vessel"]["station_keeping"].value("mode", std::string("propulsion")) != "propulsion")
      structures.push_back("vessel");
    for (const Json& e : structures_) structures.push_back(e["name"].get<std::string>());
    for (const std::string& name : structures) outputs.push_back("structure_" + name + "_load.png");
    if (!identify_dir_.empty()) {
      inputs.push_back(identify_dir_ / "identified.csv");
      inputs.push_back(identify_dir_ / "identified.json");
      outputs.push_back("identified_load.png");
    }
    PlannedStage* st = add("plot", "plot", "surge ice load plots", p, inputs, outputs, "floesim-plot");
    st->args = {"--results", plan_.results.string(), "--config", st->config.string(), "--out", st->dir.string()};
    if (!identify_dir_.empty()) {
      st->args.push_back("--identified");
      st->args.push_back(identify_dir_.string());
      plan_.artefacts.push_back(
          {"plot", "plots/identified_load.png", "identified against simulated surge ice load, same filter (PNG)"});
    }
    plot_png_ = st->outputs[0];
    plan_.artefacts.push_back({"plot", "plots/surge_ice_load.png", "surge ice load, moving average and mean (PNG)"});
    plan_.artefacts.push_back({"plot", "plots/surge_ice_load.svg", "the same (SVG)"});
    plan_.artefacts.push_back(
        {"plot", "plots/fracture_events.csv", "every fracture event: time, mode, floe, force, children"});
    for (const std::string& name : structures)
      plan_.artefacts.push_back({"plot", "plots/structure_" + name + "_load.png",
                                 "the ice's horizontal and vertical load on " + name + ", raw and filtered (PNG)"});
  }

  // 7. The report: one self-contained page over the run folder (only a run's: it reads the folder's layout). It
  // reads the whole run folder; the summary, the plot and the video are what make it stale (every other artefact
  // it shows lies upstream of the summary).
  void plan_report(bool render, bool report) {
    Json r = section("report");
    if (!(render && report)) return;
    std::vector<fs::path> inputs = {plan_.summary, plot_png_, video_};
    if (!identify_dir_.empty()) inputs.push_back(identify_dir_ / "identified.json");
    PlannedStage* st =
        add("report", "report", "self-contained HTML report", r, inputs, {"report.html"}, "floesim-report");
    st->args = {"--run", st->dir.parent_path().string(), "--config", st->config.string(), "--out",
                st->outputs[0].string()};
    plan_.artefacts.push_back({"report", "report/report.html", "the run on one page: case, loads, plots, field, "
                                                               "hull, fracture, settings, video (HTML)"});
  }

  CasePlan take() { return std::move(plan_); }

 private:
  // A stage's section of the case: an object, or {} when absent.
  Json section(const char* key) const {
    Json s = c_.contains(key) ? c_[key] : Json::object();
    FLOESIM_REQUIRE(s.is_object(), cf_, ": ", key, " must be an object");
    return s;
  }

  // A file the case owns: a name, relative to the case folder, of a file that exists.
  fs::path case_input(const Json& j, const std::string& key, const std::string& where) const {
    FLOESIM_REQUIRE(j.contains(key) && j.at(key).is_string(), cf_, ": ", where, ".", key, " must be a file name");
    fs::path p = j.at(key).get<std::string>();
    if (p.is_relative()) p = fs::absolute(case_dir_) / p;
    FLOESIM_REQUIRE(fs::exists(p), cf_, ": ", where, ".", key, " names ", p.string(), ", which does not exist");
    // A folder (".", "") was hashed as if empty, and a device (/dev/zero) was hashed forever: only a file will do.
    std::error_code ec;
    FLOESIM_REQUIRE(fs::is_regular_file(p, ec), cf_, ": ", where, ".", key, " names ", p.string(),
                    ", which is not a file (a folder or a device?): name the file itself");
    return p.lexically_normal();
  }

  // What each input file is, for the content keys: another stage's output (that stage's key and the file's name)
  // or a file of the case (its SHA-256).
  std::string identify(const fs::path& p) {
    auto it = identity_.find(p);
    if (it != identity_.end()) return it->second;
    return identity_[p] = "file " + sha256_file(p);
  }

  // Adds a stage: its key from its name, settings and inputs; then its folder, settings file and outputs.
  // `section` is the key path of its settings in the case file.
  PlannedStage* add(const std::string& name, const std::string& section, const std::string& description,
                    const Json& settings, std::vector<fs::path> inputs, const std::vector<std::string>& output_names,
                    const char* exe) {
    PlannedStage s;
    s.name = name;
    s.section = section;
    s.description = description;
    s.config_text = settings.dump(2) + "\n";
    std::string id = name + "\n" + s.config_text;
    for (const fs::path& p : inputs) id += identify(p) + "\n";
    s.key = sha256_bytes(id).substr(0, 16);
    s.dir = layout_.dir(name, s.key);
    s.config = layout_.config(name, s.key);
    inputs.push_back(s.config);
    s.inputs = inputs;
    for (const std::string& f : output_names) {
      s.outputs.push_back(s.dir / f);
      identity_[s.outputs.back()] = "stage " + s.key + " " + f;
    }
    s.exe = bin_ / exe;
    plan_.stages.push_back(s);
    return &plan_.stages.back();
  }

  fs::path plan_synth(const Json& image, double mpp) {
    Json s = image["synthetic"];
    FLOESIM_REQUIRE(s.is_object(), cf_, ": image.synthetic must be an object");
    FLOESIM_REQUIRE(!s.contains("metres_per_pixel"), cf_,
                    ": image.synthetic.metres_per_pixel: set the scale once, in image.metres_per_pixel");
    s["metres_per_pixel"] = mpp;
    PlannedStage* st = add("synth", "image.synthetic", "synthetic helicopter image from known floes", s, {},
                           {"image.png", "truth.geojson", "truth_labels.png"}, "floesim-synth");
    st->args = {"--config", st->config.string(), "--out", st->dir.string()};
    plan_.artefacts.push_back({"synth", "image/" + st->outputs[0].filename().string(),
                               "synthetic helicopter image (8-bit grey)"});
    plan_.artefacts.push_back({"synth", "image/truth.geojson", "the true floe polygons (m)"});
    return st->outputs[0];
  }

  void plan_digitise(const fs::path& image_png, double mpp) {
    Json d = c_.contains("digitise") ? c_["digitise"] : Json::object();
    FLOESIM_REQUIRE(d.is_object(), cf_, ": digitise must be an object");
    PlannedStage* st = add("digitise", "digitise", "floe segmentation and polygons", d, {image_png},
                           {"floes.geojson", "labels.png", "overlay.png", "stats.json", "fsd.png", "fsd.csv",
                            "overlay.pgw", "overlay.prj", "labels.pgw", "labels.prj"},
                           "floesim-digitise");
    st->args = {image_png.string(), "--metres-per-pixel", number(mpp), "--config", st->config.string(), "--out",
                st->dir.string()};
    floes_file_ = st->outputs[0];
    plan_.artefacts.push_back({"digitise", "floes/floes.geojson", "floe polygons, m (GeoJSON)"});
    plan_.artefacts.push_back({"digitise", "floes/labels.png", "16-bit label image, k = floe id"});
    plan_.artefacts.push_back({"digitise", "floes/overlay.png", "outlines on the photo"});
    plan_.artefacts.push_back({"digitise", "floes/stats.json", "count, concentration, size distribution"});
    plan_.artefacts.push_back({"digitise", "floes/fsd.png", "floe size distribution and power-law fit"});
  }

  PlannedStage* plan_identify_measured(const Json& id) {
    FLOESIM_REQUIRE(!id.contains("shipdata"), cf_,
                    ": identify.shipdata has no effect with identify.measured (the data are the ship's, not made "
                    "from the simulation): remove it");
    const fs::path measured = case_input(id, "measured", "identify");
    PlannedStage* st = add("identify", "identify.config", "ice load identified from the measured ship data",
                           id.contains("config") ? id["config"] : Json::object(), {measured},
                           {"identified.csv", "identified.json"}, "floesim-identify");
    st->args = {"--measured", measured.string(), "--config", st->config.string(), "--out", st->dir.string()};
    return st;
  }

  PlannedStage* plan_identify_round_trip(const Json& id) {
    FLOESIM_REQUIRE(!id.contains("config"), cf_,
                    ": identify.config is for a ship's measured data (identify.measured); the round trip "
                    "identifies with the simulated ship's own config: remove it");
    PlannedStage* sd = add("shipdata", "identify.shipdata", "the simulated ship's data as a ship would record them",
                           id.contains("shipdata") ? id["shipdata"] : Json::object(), {plan_.results, plan_.summary},
                           {"measured.csv", "measured.json"}, "floesim-shipdata");
    sd->args = {"--results", plan_.results.string(), "--summary", plan_.summary.string(), "--config",
                sd->config.string(), "--out", sd->outputs[0].string()};
    plan_.artefacts.push_back({"shipdata", "shipdata/measured.csv",
                               "the simulated ship's data as recorded (velocities, accelerations, thrust, wind)"});
    const fs::path measured = sd->outputs[0], ship_config = sd->outputs[1];
    // Its own settings file stays empty: the config is the simulated ship's, which shipdata wrote.
    PlannedStage* st = add("identify", "", "ice load identified from the simulated ship's data", Json::object(),
                           {measured, ship_config}, {"identified.csv", "identified.json"}, "floesim-identify");
    st->args = {"--measured", measured.string(), "--config", ship_config.string(), "--out", st->dir.string()};
    return st;
  }

  const Json& c_;
  const std::string& cf_;
  const fs::path& case_dir_;
  const fs::path& bin_;
  const StageLayout& layout_;
  CasePlan plan_;
  std::map<fs::path, std::string> identity_;
  fs::path floes_file_, hull_obj_, identify_dir_, video_, plot_png_;
  Json structures_ = Json::array();       // simulate.structures, from the case's "structures"
  std::vector<fs::path> structure_objs_;  // their meshes
};

}  // namespace

CasePlan plan_case(const Json& c, const std::string& where, const fs::path& case_dir, const fs::path& bin,
                   const StageLayout& layout, bool render, bool report) {
  CasePlanner p(c, where, case_dir, bin, layout);
  p.check_top_level();
  p.plan_floes();
  p.plan_hull();
  p.plan_structures();
  p.plan_simulate();
  p.plan_identify();
  p.plan_render(render);
  p.plan_plot();
  p.plan_report(render, report);
  return p.take();
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
