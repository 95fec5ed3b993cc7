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

// The single-floe case (the seed's Fig. 8, off-centre collision): struck on its south-west part by the port bow
// shoulder (the floe's centre is to port of the track), the floe fails locally in bending at the flared bow (a wedge
// breaks off, and the broken ice under the bow breaks further), and what is left of it (by far the largest piece) is
// pushed ahead and to port and turns counter-clockwise (the contact force acts south of its centre); the ice mass
// is kept (pieces + brash); the vessel carries the crushing load only while they touch.
TEST(SimCases, SingleFloeStruckOffCentreBendsAtTheBowAndIsPushedToPort) {
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
  ASSERT_TRUE(m.options.fracture.enabled);
  World w(m);
  const Vec3 x0 = w.state().position[1];
  double peak = 0;
  int contact_steps = 0;
  for (long i = 0; i < o.steps(); ++i) {
    w.step();
    if (w.report().vessel_contacts > 0) ++contact_steps;
    peak = std::max(peak, -w.report().ice_load.force.dot(w.state().orientation[0] * Vec3::UnitX()));
  }
  // The largest floe alive at the end, and the ice mass (alive + brash) against the floe's.
  const Model& wm = w.model();
  int big = -1;
  double mass = w.brash_mass_kg();
  for (size_t b = 0; b < wm.bodies.size(); ++b) {
    if (wm.bodies[b].kind != BodyKind::floe || !w.state().alive[b]) continue;
    mass += wm.bodies[b].mass_kg;
    if (big < 0 || wm.bodies[b].section_area > wm.bodies[big].section_area) big = static_cast<int>(b);
  }
  ASSERT_GE(big, 0);
  int bending_of_floe1 = 0;
  for (const FractureEvent& e : w.fracture_events())
    bending_of_floe1 += e.parent_id == 1 && e.at_structure && e.mode != kFractureSplitting;
  const Mat3 R = w.state().orientation[big].toRotationMatrix();
  const double yaw = std::atan2(R(1, 0), R(0, 0)) * 180 / kPi;
  const Vec3 d = w.state().position[big] - x0;
  std::printf("[measured] %d steps in contact, peak surge ice load %.0f kN, %zu fracture events; largest piece "
              "(%.0f of %.0f m^2) moved (%.1f, %.1f) m, yaw %+.1f deg\n",
              contact_steps, peak / 1e3, w.fracture_events().size(), wm.bodies[big].section_area,
              m.bodies[1].section_area, d.x(), d.y(), yaw);
  EXPECT_GT(contact_steps, 100);                     // a second or more of contact
  EXPECT_EQ(bending_of_floe1, 1);                    // the floe itself fails once, in bending at the bow
  EXPECT_GT(wm.bodies[big].section_area, 0.9 * m.bodies[1].section_area);  // the wedges are small (l_c = 14.6 m)
  EXPECT_NEAR(mass, m.bodies[1].mass_kg, 1e-9 * m.bodies[1].mass_kg);
  EXPECT_GT(d.x(), 10);                              // pushed ahead
  EXPECT_GT(d.y(), 5);                               // and to port
  EXPECT_GT(yaw, 10);                                // turned counter-clockwise
  EXPECT_LT(peak, 2e7);  // compliant contact: bounded (sigma_c x the contact area of a 1 m thick edge)
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
              floes.at(2), conc.at(2), last.c_str());
  // The Oden-size field without and with fracture (the same field), then the 4x field with fracture.
  ASSERT_EQ(floes.size(), 3u) << out;
  EXPECT_EQ(floes[0], floes[1]);
  EXPECT_GT(floes[0], 700);
  EXPECT_LT(floes[0], 1300);
  EXPECT_NEAR(floes[2] / double(floes[0]), 4.0, 0.5);
  EXPECT_NE(out.find("\nfracture_speed_ratio "), std::string::npos) << out;
  EXPECT_NE(out.find("  fracture: "), std::string::npos) << out;
  for (double c : conc) EXPECT_NEAR(c, 0.60, 0.01);
  EXPECT_EQ(last.rfind("realtime_factor ", 0), 0u) << last;
  EXPECT_GT(std::stod(last.substr(16)), 0.0);
  fs::remove_all(root);
}

}  // namespace
}  // namespace floesim::sim
