// The checkpoint reader (sim/simulate/checkpoint.h) against files whose SHA-256 is right but whose content is not what a run
// writes (what fuzz_checkpoint feeds it, re-sealed): refused with a message naming the file, never accepted into a
// world and results that disagree. The run: tests/sim/small_breaking_run.h (checkpoints at steps 10, 20 and 30).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "pipeline/provenance.h"
#include "sim/simulate/checkpoint.h"
#include "sim/simulate/simulate.h"
#include "tests/sim/sim_fixtures.h"
#include "tests/sim/small_breaking_run.h"
#include "tests/test_util.h"

namespace floesim::sim {
namespace {

namespace fs = std::filesystem;
using floesim::tests::read_text;

using testing::fresh_results;
using testing::small_breaking_run;

// A checkpoint file's payload (between its magic line and its SHA-256), and the file written back sealed.
std::string payload_of(const std::string& file_text, const std::string& magic) {
  return file_text.substr(magic.size(), file_text.size() - magic.size() - 64);
}
void seal(const fs::path& p, const std::string& magic, const std::string& payload) {
  std::ofstream(p, std::ios::binary) << magic << payload << sha256_bytes(payload);
}


const char kRecordsMagic[] = "floesim-checkpoint-records/1\n";
const char kCheckpointMagic[] = "floesim-checkpoint/9\n";

// Element `index` of the array `name` in a records chunk set to `value` (of the array's element type T), the chunk
// re-sealed and checkpoint.bin re-sealed naming its new hash: the hashes all agree and the array sizes still add up.
template <class T>
void reseal_with(const fs::path& dir, const char* chunk_name, const std::string& name, size_t index, T value) {
  const fs::path chunk = dir / chunk_name;
  const std::string old_text = read_text(chunk);
  std::string p = payload_of(old_text, kRecordsMagic);
  const size_t at = p.find(name);
  ASSERT_NE(at, std::string::npos) << name;
  uint64_t n;
  std::memcpy(&n, p.data() + at + name.size(), 8);
  ASSERT_LT(index, n) << name;
  std::memcpy(&p[at + name.size() + 8 + index * sizeof(T)], &value, sizeof(T));
  seal(chunk, kRecordsMagic, p);
  std::string c = payload_of(read_text(dir / "checkpoint.bin"), kCheckpointMagic);
  const size_t h = c.find(old_text.substr(old_text.size() - 64));
  ASSERT_NE(h, std::string::npos);
  c.replace(h, 64, sha256_bytes(p));
  seal(dir / "checkpoint.bin", kCheckpointMagic, c);
}

class Checkpoint : public ::testing::Test {
 protected:
  void SetUp() override {
    // A folder per test: ctest runs the fixture's tests as parallel processes.
    dir_ = testing::temp_dir(std::string("checkpoint_") +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name()) / "checkpoint";
    CheckpointPlan plan{dir_, provenance_, false};
    RunStats stats;
    full_ = simulate(options_, model_, stats, nullptr, &plan);
    ASSERT_EQ(stats.checkpoints, 3);  // at 0.1, 0.2 and 0.3 s; none after the last step
    ASSERT_GT(full_.fracture_time_s.size(), 0u) << "the run must break ice before its last checkpoint";
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }
  std::unique_ptr<World> resume(Results& r) {
    Checkpointer cp(dir_, provenance_);
    RecorderSums sums;
    return cp.resume(options_, model_, r, sums, nullptr);
  }
  void expect_refused(std::initializer_list<const char*> pieces) {
    Results r = fresh_results();
    testing::expect_error([&] { resume(r); }, pieces);
  }

  const SimulateOptions options_ = testing::small_breaking_run_options();
  const Model model_ = small_breaking_run();
  const nlohmann::json provenance_ = {{"program", "sim_checkpoint_test"}};
  fs::path dir_;
  Results full_;  // the run with every series in memory
};

TEST_F(Checkpoint, AsWrittenItResumesAtItsLastStep) {
  // Step 30 (0.3 s at 0.01 s), 30 rows per series, 6 frames (every 5 steps), the pieces remade.
  Results r = fresh_results();
  const auto w = resume(r);
  ASSERT_TRUE(w);
  EXPECT_EQ(w->state().step, 30);
  EXPECT_EQ(r.series.at("time_s").size(), 30u);
  EXPECT_EQ(r.frame_time_s.size(), 6u);
  EXPECT_GT(w->model().bodies.size(), model_.bodies.size());
}

TEST_F(Checkpoint, ResealedChunkWhoseFrameOffsetsDoNotIndexTheirStatesIsRefused) {
  // The second chunk's first frame offset set to 1, far below the states already recorded (accepted before the
  // reader checked the results against its step).
  reseal_with<int64_t>(dir_, "records-000002.bin", "frame_offset", 0, 1);
  expect_refused({"checkpoint.bin", "damaged (the frames' offsets do not index their body states)",
                  "delete the checkpoint folder, or run without --resume"});
}

TEST_F(Checkpoint, ResealedChunkStoringABodyTheWorldDoesNotHaveIsRefused) {
  // A stored row of body 999 (there are 4 floes and their pieces): simulate would fail on it as an internal error.
  reseal_with<int32_t>(dir_, "records-000001.bin", "state_body_id", 1, 999);
  expect_refused({"checkpoint.bin", "damaged (a frame stores body 999, which its world does not have)"});
}

// checkpoint.bin's payload after the list of chunks and the marks and sums: where World::save begins (the body
// table's counts, then the pieces).
size_t world_offset(const std::string& c) {
  size_t at = 0;
  auto u64 = [&](size_t where) {
    uint64_t v;
    std::memcpy(&v, c.data() + where, 8);
    return static_cast<size_t>(v);
  };
  at += 8 + u64(at);  // key
  at += 8 + u64(at);  // provenance
  at += 8;            // step
  const size_t chunks = u64(at);
  at += 8;
  for (size_t k = 0; k < chunks; ++k) at += 8 + u64(at);
  at += 8 + 8 * u64(at);  // marks
  return at + 9 * 8;      // the recorder's sums
}

// checkpoint.bin re-sealed with one number of its first piece replaced: `field` 0 is the position's z, 1 the
// orientation's x.
void reseal_first_piece(const fs::path& dir, int field, double value) {
  std::string c = payload_of(read_text(dir / "checkpoint.bin"), kCheckpointMagic);
  size_t at = world_offset(c);
  uint64_t pieces, vertices;
  std::memcpy(&pieces, c.data() + at + 16, 8);
  ASSERT_GT(pieces, 0u);
  at += 24;
  std::memcpy(&vertices, c.data() + at, 8);
  // The first piece: outline, thickness, 4 ints, created_s, then the position (x, y, z) and the quaternion (x, y, z, w).
  const size_t position = at + 8 + 16 * vertices + 8 + 16 + 8, quaternion = position + 24;
  double z, w;
  std::memcpy(&z, c.data() + position + 16, 8);
  std::memcpy(&w, c.data() + quaternion + 24, 8);
  ASSERT_LT(std::abs(z), 1.0) << "not the height of a floating piece";
  ASSERT_GT(std::abs(w), 0.5) << "not the orientation of a piece turned about z by less than 120 deg";
  std::memcpy(&c[field == 0 ? position + 16 : quaternion], &value, 8);
  seal(dir / "checkpoint.bin", kCheckpointMagic, c);
}

// Where the heave radiation filter's states (State::heave_lowpass_mps, one double per body) start in checkpoint.bin:
// after the body table (counts, then each piece: outline, thickness, 4 ints, created_s, position, quaternion,
// fixed, its ridge and ridge part) and the state arrays before it (time, step, positions, orientations, velocities, angular velocities, awake,
// alive, still times). Returns the offset of its count.
size_t heave_filter_offset(const std::string& c) {
  auto u64 = [&](size_t where) {
    uint64_t v;
    std::memcpy(&v, c.data() + where, 8);
    return static_cast<size_t>(v);
  };
  size_t at = world_offset(c);
  const size_t pieces = u64(at + 16);
  at += 24;
  for (size_t k = 0; k < pieces; ++k) at += 8 + 16 * u64(at) + 8 + 16 + 8 + 24 + 32 + 1 + 4 + 1;
  at += 16;                     // time, step
  at += 8 + 24 * u64(at);       // positions
  at += 8 + 32 * u64(at);       // orientations
  at += 8 + 24 * u64(at);       // velocities
  at += 8 + 24 * u64(at);       // angular velocities
  at += 8 + u64(at);            // awake
  at += 8 + u64(at);            // alive
  at += 8 + 8 * u64(at);        // still times
  return at;
}

// The radiation filter's state is part of what a checkpoint carries (a resumed run equal to the bit needs it; the
// floes heave as the bow meets them, so some are not 0), and one no run reaches (NaN) is refused.
TEST_F(Checkpoint, HeaveFilterStatesAreSavedAndADamagedOneIsRefused) {
  std::string c = payload_of(read_text(dir_ / "checkpoint.bin"), kCheckpointMagic);
  const size_t at = heave_filter_offset(c);
  uint64_t n;
  std::memcpy(&n, c.data() + at, 8);
  ASSERT_LT(at + 8, c.size());
  const auto w = [&] {
    Results r = fresh_results();
    return resume(r);
  }();
  ASSERT_EQ(n, w->state().heave_lowpass_mps.size()) << "the layout walked here is not the one saved";
  double largest = 0;
  for (size_t b = 0; b < n; ++b) {
    double u;
    std::memcpy(&u, c.data() + at + 8 + 8 * b, 8);
    EXPECT_EQ(u, w->state().heave_lowpass_mps[b]);
    largest = std::max(largest, std::abs(u));
  }
  std::printf("[measured] largest heave filter state saved: %.3g m/s over %zu bodies\n", largest, size_t(n));
  EXPECT_GT(largest, 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(&c[at + 8], &nan, 8);
  seal(dir_ / "checkpoint.bin", kCheckpointMagic, c);
  expect_refused({"checkpoint.bin", "damaged (body 0 has a heave filter state no run reaches"});
}

// What fuzz_checkpoint found twice (crashes/fuzz_checkpoint/): a piece remade with a non-finite pose (an infinite
// quaternion component) or one near the largest double (z = 3.8e199) gave a box that crashed the build of the broad
// phase's tree (SEGV in fcl's HierarchyTree::bottomup).
TEST_F(Checkpoint, ResealedPieceWithAnInfiniteOrientationIsRefused) {
  reseal_first_piece(dir_, 1, std::numeric_limits<double>::infinity());
  expect_refused({"checkpoint.bin", "damaged (piece", "has no valid outline, thickness or pose)"});
}

TEST_F(Checkpoint, ResealedPieceBeyondAnyFieldIsRefused) {
  reseal_first_piece(dir_, 0, 3.763892008866656e+199);
  expect_refused({"checkpoint.bin", "damaged (piece", "has no valid outline, thickness or pose)"});
}

// A run whose checkpoints take its series out of memory (what the simulate stage does, so that a long transit's
// memory does not grow by 0.65 kB per step): it holds only the steps since its last checkpoint, and reads the rest
// back from the chunks equal to the bit to the run that held them all; the results file written through them is the
// same file, byte for byte, and so is the summary.
TEST_F(Checkpoint, SpilledSeriesReadBackEqualTheSeriesHeldInMemory) {
  const fs::path dir = dir_.parent_path() / "spilled";
  CheckpointPlan plan{dir, provenance_, false, true};
  RunStats stats;
  const Results tail = simulate(options_, model_, stats, nullptr, &plan);
  EXPECT_EQ(tail.series_first_step, 30u);  // the last checkpoint
  EXPECT_EQ(tail.steps(), 10u);            // steps 31 to 40
  EXPECT_LE(tail.series.at("ice_load").capacity(), 10u * 6) << "reserved for the whole run, not one interval";
  const CheckpointSeries series(dir, provenance_, 30, tail);
  ASSERT_EQ(series.steps(), 40u);
  for (const FieldSpec& f : series_fields()) {
    const std::vector<double> a = series.get(f.name), &b = full_.series.at(f.name);
    ASSERT_EQ(a.size(), b.size()) << f.name;
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0) << f.name;
  }
  EXPECT_EQ(summarize(options_, model_, tail, series).dump(), summarize(options_, model_, full_).dump());
  write_results(dir_.parent_path() / "spilled.h5", tail, series);
  write_results(dir_.parent_path() / "held.h5", full_);
  EXPECT_TRUE(read_text(dir_.parent_path() / "spilled.h5") == read_text(dir_.parent_path() / "held.h5"));
  // Without the rows on disk, the results cannot stand for the run: the functions that take them whole refuse.
  testing::expect_error([&] { summarize(options_, model_, tail); }, {"internal: these results hold the series from step 30"});
  testing::expect_error([&] { CheckpointSeries(dir, provenance_, 20, tail); },
                        {"internal: the series in memory start at step 30"});
  testing::expect_error([&] { CheckpointSeries(dir, {{"program", "another"}}, 30, tail); },
                        {"checkpoint.bin: is another run's checkpoint"});
}

// Resumed with its series left on disk, a run appends only the frames; the series are counted, not read, and the
// checkpoint's chunks still add up (a chunk that lost a series value is damaged, not silently short).
TEST_F(Checkpoint, ResumedWithSpilledSeriesItReadsOnlyTheFrames) {
  Results r = fresh_results();
  Checkpointer cp(dir_, provenance_, true);
  RecorderSums sums;
  const auto w = cp.resume(options_, model_, r, sums, nullptr);
  ASSERT_TRUE(w);
  EXPECT_EQ(cp.series_steps_on_disk(), 30);
  EXPECT_TRUE(r.series.at("time_s").empty());
  EXPECT_EQ(r.frame_time_s.size(), 6u);
}

}  // namespace
}  // namespace floesim::sim
