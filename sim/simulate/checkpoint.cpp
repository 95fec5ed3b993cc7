#include "sim/simulate/checkpoint.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "pipeline/atomic_file.h"
#include "pipeline/binary.h"
#include "pipeline/error.h"
#include "pipeline/interrupt.h"
#include "pipeline/options.h"
#include "pipeline/provenance.h"

namespace floesim::sim {

namespace fs = std::filesystem;

namespace {

constexpr const char* kCheckpointMagic = "floesim-checkpoint/9\n";
constexpr const char* kRecordsMagic = "floesim-checkpoint-records/1\n";
constexpr size_t kHashChars = 64;  // SHA-256, hex

// The arrays the recorder appends to at every step or frame, in a fixed order: every series of the layout, then the
// frames and their body states, then the structures' series (by name). A checkpoint stores their tails since the
// previous one.
template <class R, class F>
void for_each_recorded(R& r, F&& f) {
  for (const FieldSpec& s : series_fields()) f(s.name, r.series.at(s.name));
  f("frame_time_s", r.frame_time_s);
  f("frame_offset", r.frame_offset);
  f("state_body_id", r.state_body_id);
  f("state_position_m", r.state_position_m);
  f("state_quaternion", r.state_quaternion);
  f("state_in_contact", r.state_in_contact);
  for (auto& [name, v] : r.structure_series) f(name.c_str(), v);  // kept whole, as the frames
}

// The recorded arrays that are series: the first ones of for_each_recorded.
bool is_series(size_t array) { return array < series_fields().size(); }

std::vector<size_t> recorded_sizes(const Results& r) {
  std::vector<size_t> n;
  for_each_recorded(r, [&](const char*, const auto& v) { n.push_back(v.size()); });
  return n;
}

// A file = magic line + payload + the payload's SHA-256 (hex), written atomically and forced to disk.
std::string write_blob(const fs::path& file, const char* magic, const std::string& payload) {
  const std::string hash = sha256_bytes(payload);
  write_text_atomic(file, magic + payload + hash);
  return hash;
}

// The payload of a blob file, checked against its magic and its SHA-256; `expected_hash` (if not empty) must match.
std::string read_blob(const fs::path& file, const char* magic, const std::string& expected_hash = "") {
  std::ifstream in(file, std::ios::binary);
  FLOESIM_REQUIRE(in, file.string(), ": cannot read the checkpoint file");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str(), m = magic;
  FLOESIM_REQUIRE(text.size() >= m.size() + kHashChars && text.compare(0, m.size(), m) == 0, file.string(),
                  ": not a floesim checkpoint file of this format (", m.substr(0, m.size() - 1),
                  "); delete the checkpoint folder, or run without --resume");
  std::string payload = text.substr(m.size(), text.size() - m.size() - kHashChars);
  const std::string hash = text.substr(text.size() - kHashChars);
  FLOESIM_REQUIRE(sha256_bytes(payload) == hash, file.string(),
                  ": damaged (its content does not match its SHA-256); delete the checkpoint folder, or run "
                  "without --resume");
  FLOESIM_REQUIRE(expected_hash.empty() || hash == expected_hash, file.string(),
                  ": is not the chunk the checkpoint names (a leftover of another run?); delete the checkpoint "
                  "folder, or run without --resume");
  return payload;
}

fs::path records_file(const fs::path& dir, size_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "records-%06zu.bin", index);
  return dir / name;
}

// Flattened leaves of a JSON document: "config.vessel.speed_mps" -> "2.0".
void flatten(const nlohmann::json& j, const std::string& at, std::map<std::string, std::string>& out) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) flatten(*it, at.empty() ? it.key() : at + "." + it.key(), out);
  } else if (j.is_array() && !j.empty() && j.front().is_object()) {
    for (size_t i = 0; i < j.size(); ++i) flatten(j[i], at + "[" + std::to_string(i) + "]", out);
  } else {
    out[at] = j.dump();
  }
}

// What differs between two provenances, as "key: then -> now" lines (at most a handful).
std::string differences(const nlohmann::json& then, const nlohmann::json& now) {
  std::map<std::string, std::string> a, b;
  flatten(then, "", a);
  flatten(now, "", b);
  std::vector<std::string> lines;
  for (const auto& [k, v] : a) {
    auto it = b.find(k);
    if (it == b.end()) lines.push_back(k + ": " + v + " -> (absent)");
    else if (it->second != v) lines.push_back(k + ": " + v + " -> " + it->second);
  }
  for (const auto& [k, v] : b)
    if (!a.count(k)) lines.push_back(k + ": (absent) -> " + v);
  std::string out;
  for (size_t i = 0; i < lines.size() && i < 8; ++i) out += "\n  " + lines[i];
  if (lines.size() > 8) out += "\n  ... and " + std::to_string(lines.size() - 8) + " more";
  return out;
}

// The provenance without what changes no result: the settings threads and checkpoint_interval_s, and the settings
// file itself (its name and hash: what it sets is in "config", resolved).
nlohmann::json keyed(nlohmann::json p) {
  if (p.contains("config") && p["config"].is_object()) {
    p["config"].erase("threads");
    p["config"].erase("checkpoint_interval_s");
  }
  if (p.contains("inputs") && p["inputs"].is_array()) {
    nlohmann::json kept = nlohmann::json::array();
    for (const auto& in : p["inputs"])
      if (!(in.is_object() && in.value("role", "") == "config")) kept.push_back(in);
    p["inputs"] = kept;
  }
  return p;
}

// The results read back must be those of a run at `step`: simulate() goes on appending to them, and the results
// writer and every reader after it index the frames' states through frame_offset. Equal totals (the marks) do not
// say that the arrays agree with each other. `series_values`: each series' values read (in memory or on disk).
void require_results_at_step(const Results& r, const std::vector<size_t>& series_values, long step, long every,
                             const std::string& file) {
  const auto damaged = [&](const std::string& what) {
    return Error(file + ": damaged (" + what + "); delete the checkpoint folder, or run without --resume");
  };
  if (step < 0) throw damaged("negative step " + std::to_string(step));
  for (size_t k = 0; k < series_fields().size(); ++k) {
    const FieldSpec& f = series_fields()[k];
    if (series_values[k] != static_cast<size_t>(step) * f.cols)
      throw damaged(std::string("the series ") + f.name + " holds " + std::to_string(series_values[k]) +
                    " values, a run at step " + std::to_string(step) + " has " +
                    std::to_string(static_cast<size_t>(step) * f.cols));
  }
  const size_t frames = every > 0 ? static_cast<size_t>(step / every) : 0, R = r.state_body_id.size();
  if (r.frame_time_s.size() != frames || r.frame_offset.size() != frames + 1)
    throw damaged("it holds " + std::to_string(r.frame_time_s.size()) + " frames, a run at step " +
                  std::to_string(step) + " has " + std::to_string(frames));
  if (r.frame_offset.front() != 0 || r.frame_offset.back() != static_cast<int64_t>(R) ||
      !std::is_sorted(r.frame_offset.begin(), r.frame_offset.end()))
    throw damaged("the frames' offsets do not index their body states");
  if (r.state_position_m.size() != 3 * R || r.state_quaternion.size() != 4 * R || r.state_in_contact.size() != R)
    throw damaged("the frames' body states are of unequal lengths");
}

}  // namespace

std::string checkpoint_key(const nlohmann::json& provenance) { return sha256_bytes(keyed(provenance).dump()); }

void remove_checkpoint(const fs::path& dir) {
  // checkpoint.bin first: a kill during the removal then leaves no checkpoint rather than one naming chunks that
  // are gone (the order of a folder's entries is the file system's).
  std::error_code ec;
  fs::remove(dir / "checkpoint.bin", ec);
  fs::remove(dir / "checkpoint.json", ec);
  fs::remove_all(dir, ec);
}

Checkpointer::Checkpointer(fs::path dir, nlohmann::json provenance, bool spill_series)
    : dir_(std::move(dir)), provenance_(std::move(provenance)), key_(checkpoint_key(provenance_)),
      spill_series_(spill_series) {
  // Temporaries of a checkpoint write that was killed (one simulate runs in a folder at a time).
  remove_stale_temporaries(dir_);
}

void Checkpointer::start_fresh(const Results& r, std::ostream* log) {
  marks_ = recorded_sizes(r);
  on_disk_.assign(marks_.size(), 0);
  const fs::path info = dir_ / "checkpoint.json";
  if (log && fs::exists(info)) {
    std::string at;
    try {
      at = " at t = " + load_json_file(info).at("time_s").dump() + " s";
    } catch (const std::exception&) {
    }
    *log << "  note: " << dir_.string() << " holds a checkpoint" << at
         << "; starting from t = 0 (without --resume); it is replaced by this run's first checkpoint\n";
  }
}

std::unique_ptr<World> Checkpointer::resume(const SimulateOptions& o, const Model& model, Results& r, RecorderSums& sums,
                                            std::ostream* log) {
  const fs::path file = dir_ / "checkpoint.bin";
  if (!fs::exists(file)) {
    if (log) *log << "  --resume: no checkpoint in " << dir_.string() << "; starting from t = 0\n";
    start_fresh(r, log);
    return nullptr;
  }
  const std::string payload = read_blob(file, kCheckpointMagic);
  ByteReader in(payload, file.string());
  const std::string key = in.str(), provenance_text = in.str();
  if (key != key_) {
    const nlohmann::json then = nlohmann::json::parse(provenance_text, nullptr, false);
    throw Error(file.string() + ": this checkpoint was written from other inputs or settings than this run's, so "
                "resuming it would not give this run's results. What differs (checkpoint -> now):" +
                (then.is_discarded() ? std::string("\n  (unreadable)") : differences(keyed(then), keyed(provenance_))) +
                "\nRun without --resume to start from t = 0 (the checkpoint is then replaced), or resume with the "
                "inputs and settings it was made from.");
  }
  const long step = static_cast<long>(in.pod<int64_t>());
  const size_t chunks = in.size(kHashChars);
  std::vector<std::string> hashes;
  for (size_t i = 0; i < chunks; ++i) hashes.push_back(in.str());
  const std::vector<uint64_t> marks = in.vec<uint64_t>();
  for (double* x : {&sums.awake, &sums.contacts, &sums.iterations, &sums.pairs, &sums.touching, &sums.edges,
                    &sums.crushing, &sums.record_s, &sums.wall_s})
    *x = in.pod<double>();

  // The results so far: the chunks in order, each checked against the hash the checkpoint names (with
  // spill_series, the series are only counted: CheckpointSeries reads them when the results are written).
  std::vector<size_t> on_disk(marks.size(), 0);
  for (size_t i = 0; i < chunks; ++i) {
    const fs::path rf = records_file(dir_, i + 1);
    FLOESIM_REQUIRE(fs::exists(rf), rf.string(), ": missing; the checkpoint needs it (delete the checkpoint folder, "
                    "or run without --resume)");
    const std::string rp = read_blob(rf, kRecordsMagic, hashes[i]);
    ByteReader rr(rp, rf.string());
    FLOESIM_REQUIRE(rr.str() == key_ && rr.size() == i + 1, rf.string(), ": belongs to another run");
    rr.pod<int64_t>();  // first and last step, for people reading the file
    rr.pod<int64_t>();
    size_t k = 0;
    for_each_recorded(r, [&](const char* name, auto& v) {
      FLOESIM_REQUIRE(rr.str() == name, rf.string(), ": damaged (expected the array ", name, ")");
      if (spill_series_ && is_series(k) && k < on_disk.size())
        on_disk[k] += rr.template vec_skip<typename std::decay_t<decltype(v)>::value_type>();
      else
        rr.vec_append(v);
      ++k;
    });
    FLOESIM_REQUIRE(rr.done(), rf.string(), ": damaged (bytes after the last array)");
  }
  std::vector<size_t> sizes = recorded_sizes(r);
  FLOESIM_REQUIRE(sizes.size() == marks.size(), file.string(), ": damaged (it records ", marks.size(),
                  " arrays, this version ", sizes.size(), ")");
  for (size_t k = 0; k < sizes.size(); ++k) sizes[k] += on_disk[k];
  FLOESIM_REQUIRE(std::equal(sizes.begin(), sizes.end(), marks.begin()), file.string(),
                  ": damaged (its chunks do not add up to the results it recorded)");

  require_results_at_step(r, sizes, step, o.output_every(), file.string());

  std::unique_ptr<World> world = World::restore(model, in);
  FLOESIM_REQUIRE(in.done(), file.string(), ": damaged (bytes after the world)");
  FLOESIM_REQUIRE(world->state().step == step, file.string(), ": damaged (its world is at another step)");
  // The frames store bodies of this world (the vessel as 0, floes and pieces by id): simulate rebuilds each body's
  // last stored state from them (layout /7 stores only what changed).
  {
    std::set<int32_t> ids;
    for (const Body& b : world->model().bodies)
      if (b.kind != BodyKind::wall) ids.insert(b.kind == BodyKind::vessel ? 0 : b.id);
    for (const int32_t id : r.state_body_id)
      FLOESIM_REQUIRE(ids.count(id), file.string(), ": damaged (a frame stores body ", id,
                      ", which its world does not have); delete the checkpoint folder, or run without --resume");
  }
  // Chunks after the last one named: a checkpoint that was being written when the run stopped.
  for (size_t i = chunks + 1; fs::exists(records_file(dir_, i)); ++i) fs::remove(records_file(dir_, i));
  marks_ = sizes;
  on_disk_ = on_disk;
  chunks_ = hashes;
  last_step_ = step;
  replaced_old_ = true;
  if (log)
    *log << "  --resume: continuing from the checkpoint at t = " << world->state().time_s << " s (step " << step
         << ") in " << dir_.string() << "\n";
  return world;
}

void Checkpointer::save(const World& world, Results& r, const RecorderSums& sums) {
  try {
    ensure_directory(dir_);
    if (!replaced_old_) {
      // A fresh run's first checkpoint replaces whatever checkpoint the folder held.
      remove_checkpoint(dir_);
      ensure_directory(dir_);
      replaced_old_ = true;
    }
    const long step = world.state().step;
    // 1. The records since the last checkpoint, as a new chunk.
    ByteWriter rec;
    rec.str(key_);
    rec.size(chunks_.size() + 1);
    rec.pod<int64_t>(last_step_ + 1);
    rec.pod<int64_t>(step);
    size_t i = 0;
    std::vector<size_t> sizes;  // each array's values so far, in memory or on disk
    for_each_recorded(r, [&](const char* name, const auto& v) {
      rec.str(name);
      rec.vec(v, marks_[i] - on_disk_[i]);
      sizes.push_back(on_disk_[i] + v.size());
      ++i;
    });
    const std::string hash = write_blob(records_file(dir_, chunks_.size() + 1), kRecordsMagic, rec.bytes());
    // 2. The world and the list of chunks: this rename is the moment the new checkpoint exists.
    std::vector<std::string> chunks = chunks_;
    chunks.push_back(hash);
    ByteWriter w;
    w.str(key_);
    w.str(provenance_.dump());
    w.pod<int64_t>(step);
    w.size(chunks.size());
    for (const std::string& h : chunks) w.str(h);
    std::vector<uint64_t> marks(sizes.begin(), sizes.end());
    w.vec(marks);
    for (double x : {sums.awake, sums.contacts, sums.iterations, sums.pairs, sums.touching, sums.edges,
                     sums.crushing, sums.record_s, sums.wall_s})
      w.pod(x);
    world.save(w);
    write_blob(dir_ / "checkpoint.bin", kCheckpointMagic, w.bytes());
    chunks_ = std::move(chunks);
    marks_ = std::move(sizes);
    last_step_ = step;
    if (spill_series_) {  // the chunk holds them now: out of memory
      for (size_t k = 0; k < series_fields().size(); ++k) {
        r.series.at(series_fields()[k].name).clear();
        on_disk_[k] = marks_[k];
      }
      r.series_first_step = static_cast<size_t>(step);
    }
    // 3. For people and the runner's messages.
    const nlohmann::json info = {{"format", "floesim-checkpoint/4"},
                                 {"time_s", world.state().time_s},
                                 {"step", step},
                                 {"chunks", chunks_.size()},
                                 {"key", key_},
                                 {"resume", "floesim-simulate ... --resume, or floesim run CASE --resume"}};
    write_text_atomic(dir_ / "checkpoint.json", info.dump(2) + "\n");
  } catch (const Interrupted&) {
    throw;
  } catch (const Error& e) {
    throw Error(std::string("writing the checkpoint: ") + e.what() +
                " (or set simulate.checkpoint_interval_s = 0 to run without checkpoints)");
  }
}

CheckpointSeries::CheckpointSeries(const fs::path& dir, const nlohmann::json& provenance, long steps_on_disk,
                                   const Results& tail)
    : tail_(tail), steps_on_disk_(static_cast<size_t>(std::max(0L, steps_on_disk))) {
  FLOESIM_REQUIRE(tail.series_first_step == steps_on_disk_, "internal: the series in memory start at step ",
                  tail.series_first_step, ", not at the ", steps_on_disk_, " steps on disk");
  if (steps_on_disk_ == 0) return;
  const fs::path file = dir / "checkpoint.bin";
  const auto gone = [&](const std::string& what) {
    return Error(file.string() + ": " + what + "; the run's series before it cannot be read back (the checkpoint "
                 "folder must stay as the run left it until its results are written): run again");
  };
  if (!fs::exists(file)) throw gone("missing");
  const std::string payload = read_blob(file, kCheckpointMagic);
  ByteReader in(payload, file.string());
  if (in.str() != checkpoint_key(provenance)) throw gone("is another run's checkpoint");
  in.str();  // the provenance
  if (in.pod<int64_t>() != static_cast<int64_t>(steps_on_disk_)) throw gone("is at another step than this run's last");
  const size_t chunks = in.size(kHashChars);
  std::vector<std::string> hashes;
  for (size_t i = 0; i < chunks; ++i) hashes.push_back(in.str());
  const size_t header = std::string(kRecordsMagic).size();
  for (size_t i = 0; i < chunks; ++i) {
    const fs::path rf = records_file(dir, i + 1);
    if (!fs::exists(rf)) throw gone(rf.filename().string() + " is missing");
    const std::string rp = read_blob(rf, kRecordsMagic, hashes[i]);
    ByteReader rr(rp, rf.string());
    rr.str();  // the key, the chunk's number, its first and last step
    rr.size();
    rr.pod<int64_t>();
    rr.pod<int64_t>();
    for (const FieldSpec& f : series_fields()) {  // the series come first in a chunk (for_each_recorded)
      FLOESIM_REQUIRE(rr.str() == f.name, rf.string(), ": damaged (expected the array ", f.name, ")");
      size_t at = 0;
      const size_t n = rr.vec_skip<double>(&at);
      segments_[f.name].push_back({rf, header + at, n});
    }
  }
  for (const FieldSpec& f : series_fields()) {
    size_t n = 0;
    for (const Segment& s : segments_[f.name]) n += s.count;
    if (n != steps_on_disk_ * f.cols)
      throw gone(std::string("its chunks hold ") + std::to_string(n) + " values of " + f.name + ", not " +
                 std::to_string(steps_on_disk_) + " x " + std::to_string(f.cols));
  }
}

size_t CheckpointSeries::steps() const { return steps_on_disk_ + tail_.steps(); }

std::vector<double> CheckpointSeries::get(const std::string& name) const {
  const FieldSpec& f = series_field(name);
  std::vector<double> v;
  v.reserve(steps() * f.cols);
  const auto it = segments_.find(name);
  if (it != segments_.end())
    for (const Segment& s : it->second) {
      std::ifstream in(s.file, std::ios::binary);
      in.seekg(static_cast<std::streamoff>(s.offset));
      const size_t at = v.size();
      v.resize(at + s.count);
      in.read(reinterpret_cast<char*>(v.data() + at), static_cast<std::streamsize>(s.count * sizeof(double)));
      FLOESIM_REQUIRE(in, s.file.string(), ": cannot read back the series ", name, " (the file changed or went away "
                      "while the run was writing its results): run again");
    }
  const std::vector<double>& t = tail_.get(name);
  v.insert(v.end(), t.begin(), t.end());
  return v;
}

}  // namespace floesim::sim
