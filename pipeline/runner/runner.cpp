#include "pipeline/runner/runner.h"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <iostream>
#include <sstream>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/options.h"

#ifndef FLOESIM_NINJA
#define FLOESIM_NINJA "ninja"
#endif

namespace fs = std::filesystem;

namespace floesim::runner {
namespace {

// Ninja path escaping ($, space, colon) and POSIX shell quoting for the command lines.
std::string ninja_path(const fs::path& p) {
  std::string out;
  for (char c : p.string()) {
    if (c == '$' || c == ' ' || c == ':') out += '$';
    out += c;
  }
  return out;
}
std::string sh(const fs::path& p) {
  std::string s = p.string(), out = "'";
  for (char c : s) out += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  out += "'";
  // Ninja reads '$' in commands as its own escape.
  std::string esc;
  for (char c : out) {
    if (c == '$') esc += '$';
    esc += c;
  }
  return esc;
}

// Writes text only if the file's content differs, so its modification time marks real changes only.
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

struct Stage {
  std::string name, description;
  std::vector<fs::path> inputs, outputs;
  fs::path exe;
  std::string args;  // shell-quoted arguments
};

const Json& require_object(const Json& j, const std::string& key, const std::string& file) {
  FLOESIM_REQUIRE(j.contains(key), file, ": missing key \"", key, "\"");
  FLOESIM_REQUIRE(j.at(key).is_object(), file, ": \"", key, "\" must be an object, got ", j.at(key).dump());
  return j.at(key);
}

}  // namespace

std::vector<Artefact> prepare_run(const RunOptions& o) {
  const fs::path case_file = o.case_dir / "case.json";
  const std::string cf = case_file.string();
  FLOESIM_REQUIRE(fs::is_directory(o.case_dir), o.case_dir.string(), ": not a case folder (expected a folder holding case.json)");
  const Json c = load_json_file(case_file);
  FLOESIM_REQUIRE(c.is_object(), cf, ": the top level must be an object");
  const std::vector<std::string> known = {"description", "image", "digitise", "floes", "hull", "simulate", "render",
                                          "plot"};
  for (auto it = c.begin(); it != c.end(); ++it) {
    bool ok = false;
    for (auto& k : known) ok = ok || k == it.key();
    FLOESIM_REQUIRE(ok, cf, ": unknown key \"", it.key(),
                    "\" (known: description, image, digitise, floes, hull, simulate, render, plot)");
  }
  // Floes come from a photo (image + digitise) or directly from a floes GeoJSON the case owns ("floes": {"file"}).
  FLOESIM_REQUIRE(c.contains("image") != c.contains("floes"), cf,
                  ": give exactly one of \"image\" (a photo or synthetic image, digitised into floes) or \"floes\" "
                  "({\"file\": \"floes.geojson\"}: floe polygons given directly)");
  FLOESIM_REQUIRE(!(c.contains("floes") && c.contains("digitise")), cf,
                  ": \"digitise\" has no effect with \"floes\" (the floes are given directly): remove it");

  const fs::path run = fs::absolute(o.run_dir);
  const fs::path bin = o.bin_dir.empty() ? self_dir() : fs::absolute(o.bin_dir);
  const fs::path cfg = run / "config";
  ensure_directory(cfg);
  auto case_input = [&](const Json& j, const std::string& key, const std::string& where) {
    FLOESIM_REQUIRE(j.contains(key) && j.at(key).is_string(), cf, ": ", where, ".", key, " must be a file name");
    fs::path p = j.at(key).get<std::string>();
    if (p.is_relative()) p = fs::absolute(o.case_dir) / p;
    FLOESIM_REQUIRE(fs::exists(p), cf, ": ", where, ".", key, " names ", p.string(), ", which does not exist");
    return p.lexically_normal();
  };
  auto stage_config = [&](const std::string& stage, Json j) {
    fs::path p = cfg / (stage + ".json");
    write_if_changed(p, j.dump(2) + "\n");
    return p;
  };

  std::vector<Stage> stages;
  std::vector<Artefact> arts;

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
      const fs::path dir = run / "image";
      image_png = dir / "image.png";
      Stage st{"synth", "synthetic helicopter image from known floes", {stage_config("synth", s)},
               {image_png, dir / "truth.geojson", dir / "truth_labels.png"}, bin / "floesim-synth", ""};
      st.args = "--config " + sh(st.inputs[0]) + " --out " + sh(dir);
      stages.push_back(st);
      arts.push_back({"synth", "image/image.png", "synthetic helicopter image (8-bit grey)"});
      arts.push_back({"synth", "image/truth.geojson", "the true floe polygons (m)"});
    } else {
      image_png = case_input(image, "file", "image");
    }

    // --- digitise ---
    {
      Json d = c.contains("digitise") ? c["digitise"] : Json::object();
      FLOESIM_REQUIRE(d.is_object(), cf, ": digitise must be an object");
      const fs::path dir = run / "floes";
      Stage st{"digitise", "floe segmentation and polygons", {image_png, stage_config("digitise", d)},
               {dir / "floes.geojson", dir / "labels.png", dir / "overlay.png", dir / "stats.json",
                dir / "fsd.png", dir / "fsd.csv"},
               bin / "floesim-digitise", ""};
      std::ostringstream mp;
      mp.precision(17);
      mp << mpp;
      st.args = sh(image_png) + " --metres-per-pixel " + mp.str() + " --config " + sh(st.inputs[1]) + " --out " + sh(dir);
      stages.push_back(st);
      arts.push_back({"digitise", "floes/floes.geojson", "floe polygons, m (GeoJSON)"});
      arts.push_back({"digitise", "floes/labels.png", "16-bit label image, k = floe id"});
      arts.push_back({"digitise", "floes/overlay.png", "outlines on the photo"});
      arts.push_back({"digitise", "floes/stats.json", "count, concentration, size distribution"});
      arts.push_back({"digitise", "floes/fsd.png", "floe size distribution and power-law fit"});
      floes_file = dir / "floes.geojson";
    }
  }

  // --- hull: a user's mesh, or the parametric icebreaker ---
  fs::path hull_obj;
  {
    const Json& h = require_object(c, "hull", cf);
    FLOESIM_REQUIRE(h.contains("generate") != h.contains("file") && h.size() == 1, cf,
                    ": hull needs exactly one key: \"file\" (an OBJ or any mesh assimp reads) or \"generate\" "
                    "(options for floesim-hull)");
    if (h.contains("generate")) {
      const fs::path dir = run / "hull";
      hull_obj = dir / "hull.obj";
      Stage st{"hull", "parametric icebreaker hull", {stage_config("hull", h["generate"])}, {hull_obj},
               bin / "floesim-hull", ""};
      st.args = "--config " + sh(st.inputs[0]) + " --out " + sh(hull_obj);
      stages.push_back(st);
      arts.push_back({"hull", "hull/hull.obj", "hull as convex parts, m (OBJ)"});
    } else {
      hull_obj = case_input(h, "file", "hull");
    }
  }

  // --- simulate ---
  fs::path results;
  {
    Json s = c.contains("simulate") ? c["simulate"] : Json::object();
    FLOESIM_REQUIRE(s.is_object(), cf, ": simulate must be an object");
    const fs::path dir = run / "sim";
    results = dir / "results.h5";
    const fs::path floes = floes_file;
    Stage st{"simulate", "vessel transit simulation", {floes, hull_obj, stage_config("simulate", s)},
             {results, dir / "summary.json"}, bin / "floesim-simulate", ""};
    // A thrust time series named in the case is an input too.
    if (s.contains("vessel") && s["vessel"].is_object() && s["vessel"].contains("propulsion") &&
        s["vessel"]["propulsion"].is_object() && s["vessel"]["propulsion"].contains("thrust_file")) {
      fs::path tf = case_input(s["vessel"]["propulsion"], "thrust_file", "simulate.vessel.propulsion");
      s["vessel"]["propulsion"]["thrust_file"] = tf.string();
      st.inputs[2] = stage_config("simulate", s);
      st.inputs.push_back(tf);
    }
    st.args = "--floes " + sh(floes) + " --hull " + sh(hull_obj) + " --config " + sh(st.inputs[2]) + " --out " + sh(dir);
    stages.push_back(st);
    arts.push_back({"simulate", "sim/results.h5", "time series and floe states (HDF5)"});
    arts.push_back({"simulate", "sim/summary.json", "mean surge ice load and settings"});
  }

  // --- render and plot (independent of each other) ---
  {
    Json r = c.contains("render") ? c["render"] : Json::object();
    FLOESIM_REQUIRE(r.is_object(), cf, ": render must be an object");
    const fs::path mp4 = run / "video" / "transit.mp4";
    Stage st{"render", "off-screen frames and H.264 video", {results, stage_config("render", r)}, {mp4},
             bin / "floesim-render", ""};
    st.args = "--results " + sh(results) + " --config " + sh(st.inputs[1]) + " --out " + sh(mp4);
    stages.push_back(st);
    arts.push_back({"render", "video/transit.mp4", "rendered transit (H.264 MP4)"});
  }
  {
    Json p = c.contains("plot") ? c["plot"] : Json::object();
    FLOESIM_REQUIRE(p.is_object(), cf, ": plot must be an object");
    const fs::path dir = run / "plots";
    Stage st{"plot", "surge ice load plots", {results, stage_config("plot", p)},
             {dir / "surge_ice_load.png", dir / "surge_ice_load.svg", dir / "fracture_events.csv"},
             bin / "floesim-plot", ""};
    st.args = "--results " + sh(results) + " --config " + sh(st.inputs[1]) + " --out " + sh(dir);
    stages.push_back(st);
    arts.push_back({"plot", "plots/surge_ice_load.png", "surge ice load, moving average and mean (PNG)"});
    arts.push_back({"plot", "plots/surge_ice_load.svg", "the same (SVG)"});
    arts.push_back({"plot", "plots/fracture_events.csv", "every fracture event: time, mode, floe, force, children"});
  }

  // --- the Ninja file ---
  // Before a stage runs, its own outputs and everything downstream of them are removed: a failed stage then
  // leaves nothing that looks complete (stages also write each artefact under a temporary name).
  auto downstream_outputs = [&](size_t k) {
    std::vector<fs::path> dirty(stages[k].outputs);
    for (size_t j = k + 1; j < stages.size(); ++j) {
      bool depends = false;
      for (auto& in : stages[j].inputs)
        for (auto& d : dirty) depends = depends || in == d;
      if (depends) dirty.insert(dirty.end(), stages[j].outputs.begin(), stages[j].outputs.end());
    }
    return dirty;
  };
  std::ostringstream nf;
  nf << "# Generated by floesim run from " << fs::absolute(case_file).string() << "; do not edit.\n"
     << "ninja_required_version = 1.5\n\n"
     << "rule stage\n  command = $cmd\n  description = $desc\n\n";
  for (size_t k = 0; k < stages.size(); ++k) {
    const Stage& s = stages[k];
    std::string rm = "rm -f";
    for (auto& p : downstream_outputs(k)) rm += " " + sh(p);
    for (auto& p : s.outputs) ensure_directory(p.parent_path());
    nf << "build";
    for (auto& p : s.outputs) nf << " " << ninja_path(p);
    nf << ": stage";
    for (auto& p : s.inputs) nf << " " << ninja_path(p);
    nf << " | " << ninja_path(s.exe) << "\n";
    nf << "  cmd = " << rm << " && " << sh(s.exe) << " " << s.args << "\n";
    nf << "  desc = " << s.name << ": " << s.description << "\n\n";
  }
  write_if_changed(run / "build.ninja", nf.str());
  return arts;
}

std::vector<StageTiming> stage_timings(const fs::path& run_dir, fs::file_time_type since) {
  // The first output of each stage, in the order prepare_run lists them.
  const std::vector<std::pair<std::string, std::string>> firsts = {
      {"synth", "image/image.png"},   {"digitise", "floes/floes.geojson"}, {"hull", "hull/hull.obj"},
      {"simulate", "sim/results.h5"}, {"plot", "plots/surge_ice_load.png"}, {"render", "video/transit.mp4"}};
  std::map<std::string, double> last;  // output path -> wall seconds of its last build
  std::ifstream log(run_dir / ".ninja_log");
  std::string line;
  while (std::getline(log, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream is(line);
    long long start = 0, end = 0, mt = 0;
    std::string path;
    if (is >> start >> end >> mt) {
      is >> std::ws;
      std::getline(is, path, '\t');
      last[path] = (end - start) / 1000.0;
    }
  }
  std::vector<StageTiming> out;
  for (auto& [stage, rel] : firsts) {
    const fs::path p = run_dir / rel;
    auto it = last.find(p.string());
    if (it == last.end() || !fs::exists(p)) continue;
    out.push_back({stage, fs::last_write_time(p) >= since, it->second});
  }
  return out;
}

int run_case(const RunOptions& o) {
  const auto arts = prepare_run(o);
  // Outputs newer than this ran in this invocation (minus a margin for file systems with coarse times).
  const auto started = fs::file_time_type::clock::now() - std::chrono::milliseconds(5);
  const fs::path run = fs::absolute(o.run_dir);
  std::vector<std::string> args = {FLOESIM_NINJA, "-C", run.string(), "-f", "build.ninja"};
  if (o.jobs > 0) args.push_back("-j" + std::to_string(o.jobs));
  if (o.dry_run) args.push_back("-n");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::cout.flush();
  const pid_t pid = fork();
  FLOESIM_REQUIRE(pid >= 0, "cannot start ninja: fork failed");
  if (pid == 0) {
    execv(argv[0], argv.data());
    std::cerr << "floesim: cannot execute " << argv[0] << " (is ninja-build installed?)\n";
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 1;
  if (code != 0) {
    std::cerr << "floesim: the run stopped at a failed stage (see its message above). Its artefacts and those "
                 "downstream of it were removed. Stage settings come from "
              << (o.case_dir / "case.json").string() << " (written per stage to " << (run / "config").string()
              << ").\n";
    return code;
  }
  if (!o.dry_run) {
    std::cout << "\nStage wall times:\n";
    for (const auto& t : stage_timings(run, started)) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%8.2f s", t.wall_s);
      std::cout << "  " << t.stage << std::string(10 - std::min<size_t>(9, t.stage.size()), ' ')
                << (t.ran ? buf : "   up to date") << "\n";
    }
    std::cout << "\nArtefacts in " << run.string() << ":\n";
    for (auto& a : arts) std::cout << "  " << a.file << std::string(a.file.size() < 28 ? 28 - a.file.size() : 1, ' ') << a.content << "\n";
  }
  return 0;
}

}  // namespace floesim::runner
