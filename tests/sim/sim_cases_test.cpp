// The cases of cases/ are valid (the runner accepts them, and each simulate slice reads strictly as the simulate
// options), the runner's floes-given-directly route skips image and digitise, and the single-floe case does what
// its description says: the floe struck off-centre by the port bow shoulder turns counter-clockwise and is pushed
// to port.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "pipeline/floes_io.h"
#include "sim/hull.h"
#include "sim/simulate.h"
#include "sim/world.h"

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;
const fs::path kSource = FLOESIM_SOURCE_DIR;
const fs::path kBin = FLOESIM_BIN_DIR;

struct RunOutput {
  int code;
  std::string text;
};

RunOutput dry_run(const fs::path& case_dir, const fs::path& run_dir) {
  const fs::path log = run_dir.string() + ".log";
  const std::string cmd = "'" + (kBin / "floesim").string() + "' run '" + case_dir.string() + "' --out '" +
                          run_dir.string() + "' --dry-run > '" + log.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 1, ss.str()};
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

fs::path temp_root() {
  const fs::path d = fs::temp_directory_path() / ("floesim_cases_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

TEST(SimCases, EveryCaseIsAcceptedAndItsSimulateSliceIsValid) {
  const fs::path root = temp_root();
  int n = 0;
  for (const char* name : {"default", "oden-transit", "oden-current-45", "single-floe-offcentre"}) {
    const fs::path dir = kSource / "cases" / name;
    ASSERT_TRUE(fs::exists(dir / "case.json")) << dir;
    const RunOutput r = dry_run(dir, root / name);
    EXPECT_EQ(r.code, 0) << name << ":\n" << r.text;
    const fs::path cfg = root / name / "config" / "simulate.json";
    ASSERT_TRUE(fs::exists(cfg)) << cfg;
    const SimulateOptions o = read_options<SimulateOptions>(load_json_file(cfg), cfg.string());
    EXPECT_GT(o.duration_s, 0);
    ++n;
  }
  EXPECT_EQ(n, 4);
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

// The single-floe case: struck on its south-west part by the port bow shoulder (the floe's centre is to port of
// the track), the floe is pushed ahead and to port and turns counter-clockwise (the contact force acts south of its
// centre: a positive yaw moment); the vessel carries the crushing load only while they touch.
TEST(SimCases, SingleFloeStruckOffCentreTurnsAndIsPushedToPort) {
  const fs::path dir = kSource / "cases" / "single-floe-offcentre";
  const Json c = load_json_file(dir / "case.json");
  SimulateOptions o = read_options<SimulateOptions>(c["simulate"], "case.json", "simulate");
  o.duration_s = 60;  // the strike and the turn (the case runs on to show the floe shed along the side)
  const FloeField field = read_floes(dir / "floes.geojson");
  ASSERT_EQ(field.floes.size(), 1u);
  HullModel hull;
  hull.parts = generate_hull(HullGeneratorOptions{});
  for (const TriMesh& p : hull.parts) {
    const int off = static_cast<int>(hull.surface.vertices.size());
    hull.surface.vertices.insert(hull.surface.vertices.end(), p.vertices.begin(), p.vertices.end());
    for (auto t : p.triangles) hull.surface.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
  }
  const Model m = build_model(field, &hull, o);
  ASSERT_EQ(m.floe_count(), 1);  // not removed: the vessel starts clear of it
  World w(m);
  const Vec3 x0 = w.state().position[1];
  double peak = 0;
  int contact_steps = 0;
  for (long i = 0; i < o.steps(); ++i) {
    w.step();
    if (w.report().vessel_contacts > 0) ++contact_steps;
    peak = std::max(peak, -w.report().ice_load.force.dot(w.state().orientation[0] * Vec3::UnitX()));
  }
  const Mat3 R = w.state().orientation[1].toRotationMatrix();
  const double yaw = std::atan2(R(1, 0), R(0, 0)) * 180 / 3.14159265358979323846;
  const Vec3 d = w.state().position[1] - x0;
  std::printf("[measured] %d steps in contact, peak surge ice load %.0f kN; floe moved (%.1f, %.1f) m, yaw %+.1f deg\n",
              contact_steps, peak / 1e3, d.x(), d.y(), yaw);
  EXPECT_GT(contact_steps, 300);  // several seconds of contact
  EXPECT_GT(d.x(), 20);           // pushed ahead
  EXPECT_GT(d.y(), 5);            // and to port
  EXPECT_GT(yaw, 10);             // turned counter-clockwise
  EXPECT_LT(peak, 2e7);           // compliant contact: bounded (sigma_c x the contact area of a 1 m thick edge)
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
              floes.at(1), conc.at(1), last.c_str());
  ASSERT_EQ(floes.size(), 2u) << out;
  EXPECT_GT(floes[0], 700);
  EXPECT_LT(floes[0], 1300);
  EXPECT_NEAR(floes[1] / double(floes[0]), 4.0, 0.5);
  for (double c : conc) EXPECT_NEAR(c, 0.60, 0.01);
  EXPECT_EQ(last.rfind("realtime_factor ", 0), 0u) << last;
  EXPECT_GT(std::stod(last.substr(16)), 0.0);
  fs::remove_all(root);
}

}  // namespace
}  // namespace floesim::sim
