// The simulate stage's checkpoint reader (sim/simulate/checkpoint.h Checkpointer::resume, and World::restore behind it):
// checkpoint.bin and its records-NNNNNN.bin chunks, each file a magic line, a payload and the payload's SHA-256.
//
// A mutated file almost never matches its SHA-256, so feeding raw bytes only fuzzes the hash check. The input is
// therefore a small container of files whose first byte picks how they are written:
//   mode 0      raw: each part is a whole file (magic, payload, hash) as it lies in the folder;
//   mode 1      sealed: each part is a payload, written with the magic and its correct SHA-256;
//   mode 2, 3   sealed and fixed up: as 1, and where the payload's layout allows, the run's key and the chunk hashes
//               that checkpoint.bin names are set to the right ones, so the parser behind them is what is fuzzed.
// Bit 2 of the first byte reads the files as the simulate stage does (spill_series: the series are counted, left
// on disk and read back through CheckpointSeries). Parts are separated by kSeparator: part 0 is checkpoint.bin,
// part k is records-00000k.bin.
//
// The model the checkpoints belong to is tests/sim/small_breaking_run.h (a coarse generated hull ramming small
// floes that break), and
// FLOESIM_FUZZ_WRITE_SEED=DIR writes seeds from a real checkpoint of it: a short simulate() with checkpoints on,
// stored both raw (mode 0) and as sealed payloads (mode 2). Then it exits.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "pipeline/provenance.h"
#include "pipeline/results_io.h"
#include "sim/simulate/checkpoint.h"
#include "sim/vessel/hull.h"
#include "sim/engine/model.h"
#include "sim/simulate/simulate.h"
#include "tests/sim/small_breaking_run.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;
using floesim::tests::read_text;
using namespace floesim;
using namespace floesim::sim;

namespace {

constexpr char kSeparator[] = "\n=floesim-fuzz-file=\n";
constexpr size_t kMaxParts = 8;  // checkpoint.bin and up to 7 chunks
constexpr char kCheckpointMagic[] = "floesim-checkpoint/9\n";
constexpr char kRecordsMagic[] = "floesim-checkpoint-records/1\n";
constexpr size_t kHashChars = 64;

// The run the checkpoints belong to (tests/sim/small_breaking_run.h, shared with sim_checkpoint_test).
using floesim::sim::testing::fresh_results;
using floesim::sim::testing::small_breaking_run_options;

const Model& the_model() {
  static const Model model = floesim::sim::testing::small_breaking_run();
  return model;
}

const nlohmann::json& the_provenance() {
  static const nlohmann::json p = {{"program", "fuzz_checkpoint"}, {"config", {{"duration_s", 0.4}}}};
  return p;
}

// Splits the container (after the mode byte) into its parts.
std::vector<std::string> split_parts(const std::string& s) {
  std::vector<std::string> parts;
  const std::string sep = kSeparator;
  size_t at = 0;
  while (parts.size() + 1 < kMaxParts) {
    const size_t k = s.find(sep, at);
    if (k == std::string::npos) break;
    parts.push_back(s.substr(at, k - at));
    at = k + sep.size();
  }
  parts.push_back(s.substr(at));
  return parts;
}

// The payload's leading string (u64 length + bytes: the run's key in both kinds of file) set to `key`; returns the
// offset after it, or npos if the payload is too short to hold one.
size_t set_leading_string(std::string& payload, size_t at, const std::string& key) {
  uint64_t n;
  if (payload.size() < at + sizeof n) return std::string::npos;
  std::memcpy(&n, payload.data() + at, sizeof n);
  if (n > payload.size() - at - sizeof n) return std::string::npos;
  const uint64_t k = key.size();
  payload.replace(at, sizeof n + n, std::string(reinterpret_cast<const char*>(&k), sizeof k) + key);
  return at + sizeof k + key.size();
}

// Skips one u64-length-prefixed string; npos if it runs past the end.
size_t skip_string(const std::string& payload, size_t at) {
  uint64_t n;
  if (at == std::string::npos || payload.size() < at + sizeof n) return std::string::npos;
  std::memcpy(&n, payload.data() + at, sizeof n);
  if (n > payload.size() - at - sizeof n) return std::string::npos;
  return at + sizeof n + n;
}

// checkpoint.bin's payload with the key and the chunk hashes it names set to those of `chunks` (as far as its
// layout reads: key, provenance, step, chunk count, one hash string per chunk).
void fix_up_checkpoint(std::string& payload, const std::string& key, const std::vector<std::string>& chunk_hashes) {
  size_t at = set_leading_string(payload, 0, key);
  at = skip_string(payload, at);  // provenance
  if (at == std::string::npos || payload.size() < at + 16) return;
  at += 8;  // step
  uint64_t n;
  std::memcpy(&n, payload.data() + at, sizeof n);
  at += sizeof n;
  for (uint64_t i = 0; i < n && i < chunk_hashes.size(); ++i) {
    at = set_leading_string(payload, at, chunk_hashes[i]);
    if (at == std::string::npos) return;
  }
}

void write_sealed(const fs::path& file, const char* magic, const std::string& payload) {
  const std::string text = magic + payload + sha256_bytes(payload);
  floesim::fuzz::write_input(file, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

fs::path records_file(const fs::path& dir, size_t k) {
  char name[32];
  std::snprintf(name, sizeof name, "records-%06zu.bin", k);
  return dir / name;
}


// FLOESIM_FUZZ_WRITE_SEED=DIR: a real checkpoint of the_model(), as seeds.
void write_seeds(const fs::path& dir) {
  const fs::path run = floesim::fuzz::temp_file(".seedrun");
  fs::remove_all(run);
  CheckpointPlan plan;
  plan.dir = run / "checkpoint";
  plan.provenance = the_provenance();
  RunStats stats;
  const Results r = simulate(small_breaking_run_options(), the_model(), stats, nullptr, &plan);
  std::vector<std::string> files = {read_text(plan.dir / "checkpoint.bin")};
  for (size_t k = 1; fs::exists(records_file(plan.dir, k)); ++k) files.push_back(read_text(records_file(plan.dir, k)));
  std::string raw(1, '\0'), sealed(1, '\2');
  for (size_t i = 0; i < files.size(); ++i) {
    const size_t magic = std::strlen(i == 0 ? kCheckpointMagic : kRecordsMagic);
    raw += (i ? kSeparator : "") + files[i];
    sealed += (i ? kSeparator : "") + files[i].substr(magic, files[i].size() - magic - kHashChars);
  }
  std::ofstream(dir / "checkpoint_raw.bin", std::ios::binary) << raw;
  std::ofstream(dir / "checkpoint_sealed.bin", std::ios::binary) << sealed;
  std::fprintf(stderr, "fuzz_checkpoint seeds: %zu files (checkpoints %d, fracture events %zu, last step %ld), "
               "%zu bytes raw\n", files.size(), stats.checkpoints, r.fracture_time_s.size(),
               static_cast<long>(r.steps()), raw.size());
  fs::remove_all(run);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* dir = std::getenv("FLOESIM_FUZZ_WRITE_SEED")) {
    write_seeds(dir);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const fs::path dir = floesim::fuzz::temp_file(".checkpoint");
  static const std::string key = checkpoint_key(the_provenance());
  const Model& model = the_model();
  if (size == 0) return 0;
  const int mode = data[0] & 3;
  const bool spill = data[0] & 4;  // the simulate stage's reading: series counted on disk, not read into memory
  std::vector<std::string> parts = split_parts(std::string(reinterpret_cast<const char*>(data) + 1, size - 1));

  fs::remove_all(dir);
  fs::create_directories(dir);
  if (mode == 0) {
    for (size_t i = 0; i < parts.size(); ++i)
      floesim::fuzz::write_input(i == 0 ? dir / "checkpoint.bin" : records_file(dir, i),
                                 reinterpret_cast<const uint8_t*>(parts[i].data()), parts[i].size());
  } else {
    std::vector<std::string> hashes;
    for (size_t i = 1; i < parts.size(); ++i) {
      if (mode >= 2) set_leading_string(parts[i], 0, key);
      hashes.push_back(sha256_bytes(parts[i]));
      write_sealed(records_file(dir, i), kRecordsMagic, parts[i]);
    }
    if (mode >= 2) fix_up_checkpoint(parts[0], key, hashes);
    write_sealed(dir / "checkpoint.bin", kCheckpointMagic, parts[0]);
  }

  floesim::fuzz::expect_ok_or_error([&] {
    Checkpointer cp(dir, the_provenance(), spill);
    Results r = fresh_results();
    RecorderSums sums;
    const std::unique_ptr<World> w = cp.resume(small_breaking_run_options(), model, r, sums, nullptr);
    if (!w) std::abort();  // checkpoint.bin was written: resume must read it or refuse it
    // What an accepted checkpoint promises simulate(), which goes on appending to these arrays and then writes them:
    // the world and the results at the same step, every series step x columns, frames indexing their states.
    const long step = w->state().step;
    if (step < 0 || cp.last_step() != step) std::abort();
    if (!spill) {
      for (const FieldSpec& f : series_fields())
        if (r.series.at(f.name).size() != static_cast<size_t>(step) * f.cols) std::abort();
    } else {
      // The series stay in the chunks: reading them back (as the stage does before writing its results) must give
      // every series whole; a checkpoint resume accepted but whose series cannot be read back is a finding.
      if (cp.series_steps_on_disk() != step) std::abort();
      r.series_first_step = static_cast<size_t>(step);
      try {
        const CheckpointSeries series(dir, the_provenance(), step, r);
        for (const FieldSpec& f : series_fields())
          if (series.get(f.name).size() != static_cast<size_t>(step) * f.cols) std::abort();
      } catch (const floesim::Error&) {
        std::abort();
      }
    }
    const size_t R = r.state_body_id.size();
    if (r.frame_offset.size() != r.frame_time_s.size() + 1 || r.frame_offset.front() != 0 ||
        r.frame_offset.back() != static_cast<int64_t>(R) || r.state_position_m.size() != 3 * R ||
        r.state_quaternion.size() != 4 * R || r.state_in_contact.size() != R)
      std::abort();
    for (size_t k = 0; k + 1 < r.frame_offset.size(); ++k)
      if (r.frame_offset[k] > r.frame_offset[k + 1]) std::abort();
    const size_t n = w->model().bodies.size();
    if (w->state().position.size() != n || w->state().alive.size() != n) std::abort();
    // Every stored row is of a body of the world (simulate rebuilds each body's last stored state from them).
    std::set<int32_t> ids;
    for (const Body& b : w->model().bodies)
      if (b.kind != BodyKind::wall) ids.insert(b.kind == BodyKind::vessel ? 0 : b.id);
    for (const int32_t id : r.state_body_id)
      if (!ids.count(id)) std::abort();
  });
  return 0;
}
