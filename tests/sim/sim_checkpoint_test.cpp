// The checkpoint reader (sim/checkpoint.h) against files whose SHA-256 is right but whose content is not what a run
// writes (what fuzz_checkpoint feeds it, re-sealed): refused with a message naming the file, never accepted into a
// world and results that disagree. The run: a small generated hull at 4 m/s into 0.3 m floes that break at once,
// 0.4 s with a checkpoint every 0.1 s (the last at step 30).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "pipeline/provenance.h"
#include "sim/checkpoint.h"
#include "sim/simulate.h"
#include "tests/sim/sim_fixtures.h"

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;

Model small_breaking_run() {
  SimulateOptions o;
  o.duration_s = 0.4;
  o.output_interval_s = 0.05;
  o.checkpoint_interval_s = 0.1;
  o.steady_start_s = 0;
  o.sleep.enabled = false;
  o.vessel.propulsion.mode = "speed";
  o.vessel.propulsion.speed_mps = 4;
  o.vessel.initial_speed_mps = 4;
  o.vessel.x_m = 5;
  HullGeneratorOptions g;
  g.length_m = 40, g.beam_m = 9, g.reamer_beam_m = 11, g.draught_m = 3, g.depth_m = 6, g.sections = 6;
  HullModel h;
  h.parts = generate_hull(g);
  h.surface = h.parts[0];
  for (size_t k = 1; k < h.parts.size(); ++k) {
    const int off = static_cast<int>(h.surface.vertices.size());
    h.surface.vertices.insert(h.surface.vertices.end(), h.parts[k].vertices.begin(), h.parts[k].vertices.end());
    for (auto t : h.parts[k].triangles) h.surface.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
  }
  FloeField f;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) f.floes.push_back(testing::rect_floe(1 + 2 * i + j, 21 * i, -20 + 21 * j, 20, 19, 0.3));
  return build_model(f, &h, o);
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A checkpoint file's payload (between its magic line and its SHA-256), and the file written back sealed.
std::string payload_of(const std::string& file_text, const std::string& magic) {
  return file_text.substr(magic.size(), file_text.size() - magic.size() - 64);
}
void seal(const fs::path& p, const std::string& magic, const std::string& payload) {
  std::ofstream(p, std::ios::binary) << magic << payload << sha256_bytes(payload);
}

Results fresh_results() {
  Results r;
  for (const FieldSpec& f : series_fields()) r.series[f.name];
  r.frame_offset.push_back(0);
  return r;
}

TEST(Checkpoint, ResealedChunkWhoseFrameOffsetsDoNotIndexTheirStatesIsRefused) {
  const fs::path dir = testing::temp_dir("checkpoint_reseal") / "checkpoint";
  const Model model = small_breaking_run();
  const nlohmann::json provenance = {{"program", "sim_checkpoint_test"}};
  CheckpointPlan plan{dir, provenance, false};
  RunStats stats;
  const Results full = simulate(model, stats, nullptr, &plan);
  ASSERT_EQ(stats.checkpoints, 3);  // at 0.1, 0.2 and 0.3 s; none after the last step
  ASSERT_GT(full.fracture_time_s.size(), 0u) << "the run must break ice before its last checkpoint";

  // As written, it resumes: step 30, 30 rows per series, 6 frames (every 5 steps).
  {
    Checkpointer cp(dir, provenance);
    Results r = fresh_results();
    RecorderSums sums;
    const auto w = cp.resume(model, r, sums, nullptr);
    ASSERT_TRUE(w);
    EXPECT_EQ(w->state().step, 30);
    EXPECT_EQ(r.series.at("time_s").size(), 30u);
    EXPECT_EQ(r.frame_time_s.size(), 6u);
    EXPECT_GT(w->model().bodies.size(), model.bodies.size());  // the pieces are remade
  }

  // The second chunk's frame offsets made to decrease, the chunk re-sealed and the checkpoint re-sealed naming its
  // new hash: the hashes all agree, the array sizes add up, and the frames no longer index their states.
  const std::string rmagic = "floesim-checkpoint-records/1\n", cmagic = "floesim-checkpoint/1\n";
  const fs::path chunk = dir / "records-000002.bin";
  const std::string old_text = read_text(chunk);
  std::string p = payload_of(old_text, rmagic);
  const std::string name = "frame_offset";
  const size_t at = p.find(name);
  ASSERT_NE(at, std::string::npos);
  uint64_t n;
  std::memcpy(&n, p.data() + at + name.size(), 8);
  ASSERT_GE(n, 2u);
  const int64_t bad = 1;  // the chunk's first frame offset, far below the states already recorded
  std::memcpy(&p[at + name.size() + 8], &bad, 8);
  seal(chunk, rmagic, p);
  std::string c = payload_of(read_text(dir / "checkpoint.bin"), cmagic);
  const std::string old_hash = old_text.substr(old_text.size() - 64), new_hash = sha256_bytes(p);
  const size_t h = c.find(old_hash);
  ASSERT_NE(h, std::string::npos);
  c.replace(h, 64, new_hash);
  seal(dir / "checkpoint.bin", cmagic, c);

  Checkpointer cp(dir, provenance);
  Results r = fresh_results();
  RecorderSums sums;
  testing::expect_error([&] { cp.resume(model, r, sums, nullptr); },
                        {"checkpoint.bin", "damaged (the frames' offsets do not index their body states)",
                         "delete the checkpoint folder, or run without --resume"});
  fs::remove_all(dir.parent_path());
}

}  // namespace
}  // namespace floesim::sim
