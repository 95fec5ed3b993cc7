// The cases of cases/ are valid (the runner accepts them, and each simulate slice reads strictly as the simulate
// options), the runner's floes-given-directly route skips image and digitise, and the single-floe case does what
// its description says: the floe struck off-centre by the port bow shoulder turns counter-clockwise and is pushed
// to port.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "pipeline/floes_io.h"
#include "sim/vessel/hull.h"
#include "sim/simulate/simulate.h"
#include "sim/engine/world.h"
#include "tests/test_util.h"

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;
using floesim::tests::read_text;
const fs::path kSource = FLOESIM_SOURCE_DIR;
const fs::path kBin = FLOESIM_BIN_DIR;

using RunOutput = floesim::tests::CommandOutput;

RunOutput dry_run(const fs::path& case_dir, const fs::path& run_dir) {
  return floesim::tests::run_logged("'" + (kBin / "floesim").string() + "' run '" + case_dir.string() + "' --out '" +
                                        run_dir.string() + "' --dry-run",
                                    run_dir.string() + ".log");
}

fs::path temp_root() {
  const fs::path d = fs::temp_directory_path() / ("floesim_cases_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

TEST(SimCases, EveryCaseIsAcceptedAndItsSimulateSliceIsValid) {
  const fs::path root = temp_root();
  int n = 0;
  // Every case folder (a folder of cases/ with a case.json; sweeps have a sweep.json instead), in name order.
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(kSource / "cases"))
    if (fs::exists(e.path() / "case.json")) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    const fs::path dir = kSource / "cases" / name;
    const RunOutput r = dry_run(dir, root / name);
    EXPECT_EQ(r.code, 0) << name << ":\n" << r.text;
    const fs::path cfg = root / name / "config" / "simulate.json";
    ASSERT_TRUE(fs::exists(cfg)) << cfg;
    const SimulateOptions o = read_options<SimulateOptions>(load_json_file(cfg), cfg.string());
    EXPECT_GT(o.duration_s, 0);
    ++n;
  }
  EXPECT_GE(n, 6) << "cases/ holds at least the six run cases of the README's table";
  fs::remove_all(root);
}

// "floes": {"file": ...}: no synth or digitise stage; simulate reads the case's own file. Errors name the key.
TEST(SimCases, FloesGivenDirectlySkipImageAndDigitise) {
  const fs::path root = temp_root();
  const fs::path dir = kSource / "cases" / "single-floe-offcentre";
  ASSERT_EQ(dry_run(dir, root / "run").code, 0);
  const std::string ninja = read_text(root / "run" / "build.ninja");
  EXPECT_EQ(ninja.find("digitise"), std::string::npos);
  EXPECT_EQ(ninja.find("synth"), std::string::npos);
  EXPECT_NE(ninja.find((dir / "floes.geojson").lexically_normal().string()), std::string::npos);

  // Both an image and floes, digitise with floes, an unknown key under floes, a missing file: errors naming them.
  auto bad = [&](const std::string& json, const std::string& piece) {
    const fs::path c = root / "bad";
    fs::create_directories(c);
    std::ofstream(c / "case.json") << json;
    std::ofstream(c / "floes.geojson") << read_text(dir / "floes.geojson");
    const RunOutput r = dry_run(c, root / "bad_run");
    EXPECT_NE(r.code, 0) << json;
    EXPECT_NE(r.text.find(piece), std::string::npos) << "missing '" << piece << "' in: " << r.text;
  };
  bad(R"({"floes": {"file": "floes.geojson"}, "image": {"metres_per_pixel": 1, "synthetic": {}}, "hull": {"generate": {}}})",
      "exactly one of \"image\"");
  bad(R"({"floes": {"file": "floes.geojson"}, "digitise": {}, "hull": {"generate": {}}})", "\"digitise\" has no effect");
  bad(R"({"floes": {"file": "floes.geojson", "scale": 2}, "hull": {"generate": {}}})", "unknown key floes.scale");
  bad(R"({"floes": {"file": "nope.geojson"}, "hull": {"generate": {}}})", "nope.geojson");
  fs::remove_all(root);
}

// "hull": {"file": ..., placement options}: a hull stage (floesim-hull on the case's hull section, the file made
// absolute) places and cuts the mesh; simulate reads its hull.obj. floesim-hull --check-config validates the
// options strictly, naming the key.
TEST(SimCases, HullFileWithPlacementPlansAHullStageThatChecksItsOptions) {
  const fs::path root = temp_root();
  const fs::path dir = kSource / "cases" / "single-floe-offcentre";
  const fs::path c = root / "mesh_case";
  fs::create_directories(c);
  std::ofstream(c / "floes.geojson") << read_text(dir / "floes.geojson");
  std::ofstream(c / "box.obj") << "o box\nv 0 0 0\nv 4 0 0\nv 0 1 0\nv 4 1 0\nv 0 0 1\nv 4 0 1\nv 0 1 1\nv 4 1 1\n"
                                  "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\n"
                                  "f 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n";
  std::ofstream(c / "case.json") << R"({"floes": {"file": "floes.geojson"},
    "hull": {"file": "box.obj", "bow_direction": "-x", "waterline_z_m": 0.4, "scale": 2}})";
  const RunOutput r = dry_run(c, root / "run");
  ASSERT_EQ(r.code, 0) << r.text;
  const fs::path cfg = root / "run" / "config" / "hull.json";
  ASSERT_TRUE(fs::exists(cfg));
  const Json h = load_json_file(cfg);
  EXPECT_EQ(h["file"].get<std::string>(), (c / "box.obj").lexically_normal().string());
  EXPECT_EQ(h["bow_direction"].get<std::string>(), "-x");
  const std::string ninja = read_text(root / "run" / "build.ninja");
  EXPECT_NE(ninja.find("floesim-hull"), std::string::npos);
  EXPECT_NE(ninja.find("hull.obj"), std::string::npos);

  auto check_config = [&](const Json& j) {
    const fs::path f = root / "hull_check.json";
    std::ofstream(f) << j.dump();
    const fs::path log = root / "hull_check.log";
    const std::string cmd = "'" + (kBin / "floesim-hull").string() + "' --check-config --config '" + f.string() +
                            "' > '" + log.string() + "' 2>&1";
    const int status = std::system(cmd.c_str());
    return RunOutput{WIFEXITED(status) ? WEXITSTATUS(status) : 1, read_text(log)};
  };
  EXPECT_EQ(check_config(h).code, 0) << check_config(h).text;
  Json bad = h;
  bad["bow_direction"] = "forward";
  RunOutput b = check_config(bad);
  EXPECT_NE(b.code, 0);
  EXPECT_NE(b.text.find("bow_direction"), std::string::npos) << b.text;
  bad = h;
  bad["scale"] = -1;
  b = check_config(bad);
  EXPECT_NE(b.code, 0);
  EXPECT_NE(b.text.find("scale must be > 0"), std::string::npos) << b.text;
  bad = h;
  bad["waterline_m"] = 0.3;  // a typo: unknown keys are errors
  b = check_config(bad);
  EXPECT_NE(b.code, 0);
  EXPECT_NE(b.text.find("waterline_m"), std::string::npos) << b.text;
  fs::remove_all(root);
}

// The single-floe case (the seed's Fig. 8, coupled global splitting and local bending in an off-centre collision):
// a 20 m square floe, struck 4 m off its centre by the flat spoon bow, is too short for the wedge that the ~15 m wide
// load would bend, so it splits globally along the force line through the contact point, at C_s K_IC h sqrt(L) with
// L the 20 m chord (PHYSICS.md 2.2), into two unequal halves; each half, loaded over a narrower contact, then fails
// locally in bending at the bow (2.1). The ice mass is kept (pieces + brash).
TEST(SimCases, SingleFloeStruckOffCentreSplitsGloballyThenBendsLocally) {
  const fs::path dir = kSource / "cases" / "single-floe-offcentre";
  const Json c = load_json_file(dir / "case.json");
  SimulateOptions o = read_options<SimulateOptions>(c["simulate"], "case.json", "simulate");
  o.duration_s = 50;  // the strike (at ~43 s) and the failures it causes
  const FloeField field = read_floes(dir / "floes.geojson");
  ASSERT_EQ(field.floes.size(), 1u);
  const HullModel hull = hull_model_from_parts(generate_hull(HullGeneratorOptions{}));
  const Model m = build_model(field, &hull, o);
  ASSERT_EQ(m.floe_count(), 1);  // not removed: the vessel starts clear of it
  ASSERT_TRUE(m.settings.fracture.enabled);
  World w(m);
  for (long i = 0; i < o.steps(); ++i) w.step();

  const Model& wm = w.model();
  auto area_of = [&](int id) {
    for (const Body& b : wm.bodies)
      if (b.id == id) return b.section_area;
    return -1.0;
  };
  const std::vector<FractureEvent>& ev = w.fracture_events();
  ASSERT_GE(ev.size(), 3u);
  const FractureEvent& split = ev[0];
  std::printf("[measured] %zu events; the floe splits at t = %.2f s, F_H = %.0f kN against %.0f kN, into %.0f + %.0f "
              "m^2\n",
              ev.size(), split.time_s, split.force_n.head<2>().norm() / 1e3, split.threshold_n / 1e3,
              area_of(split.child_ids.at(0)), area_of(split.child_ids.at(1)));
  // The global split: the whole floe, at the bow, into two pieces that each keep a large share (not a wedge).
  EXPECT_EQ(split.parent_id, 1);
  EXPECT_EQ(split.mode, kFractureSplitting);
  EXPECT_TRUE(split.at_structure);
  ASSERT_EQ(split.child_ids.size(), 2u);
  for (int id : split.child_ids) EXPECT_GT(area_of(id), 0.25 * 400.0) << id;
  // The threshold is C_s K_IC h sqrt(L) for the chord through the square along the (nearly surge-wise) force: 20 m
  // head-on, 20/cos(phi) m at phi off the floe's axis; 5 % covers phi up to 17 degrees.
  const FractureOptions& fo = o.fracture;
  // The floe is free (no other contact presses it back), so its push is all inertia and drag: C_s,free.
  const double f_split_20m = fo.splitting_coefficient_free * fo.fracture_toughness_pa_sqrtm * 1.0 * std::sqrt(20.0);
  EXPECT_NEAR(split.threshold_n, f_split_20m, 0.05 * f_split_20m);
  EXPECT_GE(split.force_n.head<2>().norm(), split.threshold_n);
  // Then local bending of both halves at the bow.
  int halves_bent = 0;
  for (const FractureEvent& e : ev)
    for (int id : split.child_ids)
      halves_bent += e.parent_id == id && e.at_structure && e.mode == kFractureBending;
  EXPECT_EQ(halves_bent, 2);

  EXPECT_EQ(w.brash_mass_kg(), 0.0);  // brash is kept as bodies (fracture.brash "rigid")
  double mass = w.brash_mass_kg();
  for (size_t b = 0; b < wm.bodies.size(); ++b)
    if (wm.bodies[b].kind == BodyKind::floe && w.state().alive[b]) mass += wm.bodies[b].mass_kg;
  EXPECT_NEAR(mass, m.bodies[1].mass_kg, 1e-9 * m.bodies[1].mass_kg);
}


// The benchmark runs (briefly here; it is not a timed test): the generated Oden-size field has about a thousand
// floes at 60 % concentration, the 4x field four times the floes, and the last line is the realtime factor.
TEST(SimBench, GeneratedFieldsAndLastLine) {
  const fs::path root = temp_root();
  const fs::path log = root / "bench.log";
  const std::string cmd = "'" + (kBin / "floesim-bench").string() + "' --duration 2 --scales 1,4 > '" +
                          log.string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << read_text(log);
  const std::string out = read_text(log);
  std::istringstream in(out);
  std::string line, last;
  std::vector<int> floes;
  std::vector<double> conc;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
    int n = 0;
    double c = 0;
    const size_t f = line.find(" floes ("), k = line.find("concentration ");
    if (line.rfind("field ", 0) == 0 && f != std::string::npos && k != std::string::npos) {
      n = std::stoi(line.substr(line.rfind(' ', f - 1) + 1));
      c = std::stod(line.substr(k + 14));
      floes.push_back(n);
      conc.push_back(c);
    }
  }
  std::printf("[measured] fields: %d floes (c = %.3f), %d floes (c = %.3f); last line '%s'\n", floes.at(0), conc.at(0),
              floes.back(), conc.back(), last.c_str());
  // The Oden-size field under the four compared models (fracture off; at the hull only or with ice-ice failure,
  // brash removed or kept) and the defaults (the same field), then the 4x field with the defaults.
  ASSERT_EQ(floes.size(), 6u) << out;
  for (size_t i = 1; i < 5; ++i) EXPECT_EQ(floes[0], floes[i]);
  EXPECT_GT(floes[0], 700);
  EXPECT_LT(floes[0], 1300);
  EXPECT_NEAR(floes[5] / double(floes[0]), 4.0, 0.5);
  EXPECT_NE(out.find("\nfracture_speed_ratio "), std::string::npos) << out;
  EXPECT_NE(out.find("\nrigid_brash_speed_ratio "), std::string::npos) << out;
  EXPECT_NE(out.find("  fracture: "), std::string::npos) << out;
  for (double c : conc) EXPECT_NEAR(c, 0.60, 0.01);
  EXPECT_EQ(last.rfind("realtime_factor ", 0), 0u) << last;
  EXPECT_GT(std::stod(last.substr(16)), 0.0);
  fs::remove_all(root);
}

}  // namespace
}  // namespace floesim::sim
