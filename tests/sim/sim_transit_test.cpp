// The simulate stage end to end on tiny cases: a short transit of the generated hull through ~20 floes, the
// results layout (rows per step, frames at the output interval), and byte-identical reruns.
#include <gtest/gtest.h>

#include <cstring>

#include <cmath>
#include <fstream>
#include <iterator>

#include "pipeline/provenance.h"
#include "sim/simulate.h"
#include "sim/world.h"
#include "sim_fixtures.h"

namespace floesim::sim {
namespace {

using testing::coarse_hull;
using testing::rect_floe;
using testing::temp_dir;

// 20 square floes (7 m, gaps of 1.5 m) in a 4 x 5 block ahead of a bow that starts at x ~ 54 m.
FloeField floe_block(double x0 = 60) {
  FloeField field;
  int id = 1;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 5; ++j) field.floes.push_back(rect_floe(id++, x0 + i * 8.5, -21 + j * 8.5, 7, 7, 1.0));
  return field;
}

TEST(SimTransit, VesselPushesFloesAndLayoutIsExact) {
  const HullModel hull = coarse_hull(8);
  SimulateOptions o;
  o.duration_s = 20;
  o.steady_start_s = 5;
  o.output_interval_s = 0.2;
  const Model m = build_model(floe_block(), &hull, o);
  ASSERT_EQ(m.floe_count(), 20);
  RunStats stats;
  const Results r = simulate(m, stats);
  // Exactly duration / dt rows and duration / output_interval frames, at t = k * output_interval, k = 1..N.
  ASSERT_EQ(r.steps(), 2000u);
  ASSERT_EQ(r.frames(), 100u);
  EXPECT_NEAR(r.frame_time_s.front(), 0.2, 1e-12);
  EXPECT_NEAR(r.frame_time_s.back(), 20.0, 1e-12);
  EXPECT_NEAR(r.get("time_s").back(), 20.0, 1e-12);
  for (const FieldSpec& f : series_fields()) EXPECT_EQ(r.get(f.name).size(), 2000u * f.cols) << f.name;
  EXPECT_EQ(r.frame_offset.back(), static_cast<int64_t>(100 * 21));
  EXPECT_EQ(r.floe_id.size(), 20u);
  EXPECT_EQ(r.state_body_id[0], 0);

  const nlohmann::json s = summarize(m, r);
  const double mean_fx = s["mean_surge_ice_load_N"];
  std::printf("[measured] mean surge ice load %.1f kN, mean speed %.3f m/s, mean vessel contacts %.2f, "
              "mean sweeps %.1f, %.3f ms/step\n",
              mean_fx / 1e3, s["mean_vessel_speed_mps"].get<double>(), s["mean_vessel_contacts"].get<double>(),
              s["solver"]["mean_sweeps"].get<double>(), 1e3 * stats.wall_s / stats.steps);
  EXPECT_LT(mean_fx, 0);  // ice resists the vessel
  EXPECT_GT(s["mean_vessel_contacts"].get<double>(), 0.5);
  EXPECT_NEAR(s["mean_vessel_speed_mps"].get<double>(), 2.0, 0.1);  // the speed controller holds 2 m/s
  // The vessel pushed floes: several moved forward by metres.
  int pushed = 0;
  const size_t last = r.frames() - 1;
  for (int64_t i = r.frame_offset[last]; i < r.frame_offset[last + 1]; ++i) {
    const int id = r.state_body_id[i];
    if (id == 0) continue;
    const Body& b = m.bodies[i - r.frame_offset[last]];
    ASSERT_EQ(b.id, id);
    if (r.state_position_m[3 * i] - b.initial_position.x() > 2.0) ++pushed;
  }
  std::printf("[measured] %d of 20 floes pushed forward by more than 2 m\n", pushed);
  EXPECT_GE(pushed, 3);
}

std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Writes a tiny case (floes right at the bow, so contacts start at once) and returns the config path.
std::filesystem::path write_case(const std::filesystem::path& dir, int threads) {
  FloeField field = floe_block(52);
  write_floes(dir / "floes.geojson", field);
  HullGeneratorOptions g;
  g.sections = 8;
  write_obj(dir / "hull.obj", generate_hull(g), "test hull");
  nlohmann::json cfg = {{"duration_s", 4.0}, {"steady_start_s", 1.0}, {"output_interval_s", 0.5},
                        {"threads", threads}, {"vessel", {{"x_m", 5.0}}}};
  std::ofstream(dir / "simulate.json") << cfg.dump(2);
  return dir / "simulate.json";
}

TEST(SimTransit, RerunsAreByteIdentical) {
  const auto dir = temp_dir("determinism");
  const auto cfg = write_case(dir, 1);
  run_simulate(dir / "floes.geojson", dir / "hull.obj", cfg, dir / "a");
  run_simulate(dir / "floes.geojson", dir / "hull.obj", cfg, dir / "b");
  const std::string a = file_bytes(dir / "a" / "results.h5"), b = file_bytes(dir / "b" / "results.h5");
  ASSERT_GT(a.size(), 1000u);
  std::printf("[measured] results.h5 sha256 %s (run 1) %s (run 2)\n", sha256_bytes(a).substr(0, 16).c_str(),
              sha256_bytes(b).substr(0, 16).c_str());
  EXPECT_TRUE(a == b);
  EXPECT_EQ(file_bytes(dir / "a" / "summary.json"), file_bytes(dir / "b" / "summary.json"));
  const Results ra = read_results(dir / "a" / "results.h5");
  double contacts = 0;
  for (double c : ra.get("vessel_contact_count")) contacts += c;
  EXPECT_GT(contacts, 0);  // the case does exercise contacts

  // Two threads give the same numbers (only the recorded configuration differs).
  const auto dir2 = temp_dir("determinism_threads");
  const auto cfg2 = write_case(dir2, 2);
  run_simulate(dir2 / "floes.geojson", dir2 / "hull.obj", cfg2, dir2 / "c");
  const Results rc = read_results(dir2 / "c" / "results.h5");
  // Bit for bit (memcmp, not ==: a series not measured is NaN, and NaN == NaN is false).
  auto same_bits = [](const std::vector<double>& x, const std::vector<double>& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(double)) == 0;
  };
  for (const FieldSpec& f : series_fields()) EXPECT_TRUE(same_bits(ra.get(f.name), rc.get(f.name))) << f.name;
  EXPECT_TRUE(ra.state_position_m == rc.state_position_m);
  EXPECT_TRUE(ra.state_quaternion == rc.state_quaternion);
}

}  // namespace
}  // namespace floesim::sim
