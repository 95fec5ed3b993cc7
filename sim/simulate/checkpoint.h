// Checkpoints of the simulate stage (simulate.checkpoint_interval_s; PHYSICS-free: this is bookkeeping). A long
// simulation writes, every interval of simulated time and when it is stopped by a signal, enough to continue later
// (`floesim-simulate --resume`, `floesim run --resume`) with results byte-identical to a run never stopped:
//
//   OUT/checkpoint/records-NNNNNN.bin  the per-step series and stored frames recorded since the previous checkpoint
//                                      (the results so far are the concatenation of these chunks, each written once:
//                                      a long run's checkpoints do not rewrite its history; the stage keeps
//                                      only the series since the last chunk in memory and reads the rest back
//                                      from the chunks when it writes its results: CheckpointSeries below)
//   OUT/checkpoint/checkpoint.bin      the world after the last checkpointed step (World::save: body table with the
//                                      pieces, state, warm-start cache, ...), the recorder's running sums, the list
//                                      of chunks with their SHA-256, and the run's key
//   OUT/checkpoint/checkpoint.json     the same step and time for people and for the runner's messages
//
// Every file is written under a temporary name, forced to disk and renamed (pipeline/atomic_file.h), records first,
// checkpoint.bin last: whatever moment the process dies, checkpoint.bin names only chunks that are complete, and
// the previous checkpoint stays valid until the new one replaces it. Each file ends with the SHA-256 of its content.
//
// The run's key is the SHA-256 of the stage's provenance (program version, input files' SHA-256, resolved options)
// without `threads` and `checkpoint_interval_s`, which change no result (determinism across thread counts is
// tested), and without the settings file's own hash (what it sets is in the resolved options): a checkpoint of
// other inputs or settings is refused, naming what differs.
#pragma once
#include <filesystem>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/results_io.h"
#include "sim/engine/world.h"
#include "sim/simulate/options.h"
#include "sim/simulate/recorder.h"

namespace floesim::sim {

// The key of a run from its provenance (see above).
std::string checkpoint_key(const nlohmann::json& provenance);

// Removes a checkpoint folder, checkpoint.bin first (whenever the removal is cut short, what is left is either a
// whole checkpoint or none).
void remove_checkpoint(const std::filesystem::path& dir);

class Checkpointer {
 public:
  // `dir`: OUT/checkpoint; `provenance`: the stage's (make_provenance), whose key identifies the run.
  // `spill_series`: the per-step series written to a chunk leave memory (save empties Results::series, resume reads
  // none back): a long run's memory then holds one checkpoint interval of them; CheckpointSeries reads them back.
  Checkpointer(std::filesystem::path dir, nlohmann::json provenance, bool spill_series = false);

  // Resume: the world after the last checkpointed step, with the results recorded up to it appended to `r` (which
  // holds the empty series of a fresh run; with spill_series, the series stay on disk and only the frames are
  // appended) and the sums restored; null if there is no checkpoint (said on `log`).
  // Error if the checkpoint is of other inputs or settings (naming the differences), or damaged.
  std::unique_ptr<World> resume(const SimulateOptions& o, const Model& model, Results& r, RecorderSums& sums,
                                std::ostream* log);

  // A fresh start: notes on `log` a checkpoint left in the folder (kept until this run's first checkpoint
  // replaces it, so that a run started without --resume by mistake can still be stopped and resumed).
  void start_fresh(const Results& r, std::ostream* log);

  // Writes a checkpoint after the world's last step (the results recorded up to it, the sums). With spill_series,
  // the series rows it wrote then leave r.series (which holds only the rows since the last checkpoint).
  void save(const World& world, Results& r, const RecorderSums& sums);

  long last_step() const { return last_step_; }
  // Steps whose series are on disk in the chunks and no longer in memory (0 without spill_series).
  long series_steps_on_disk() const { return spill_series_ ? last_step_ : 0; }
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  nlohmann::json provenance_;
  std::string key_;
  bool spill_series_ = false;
  std::vector<size_t> marks_;          // sizes of the recorded arrays at the last checkpoint
  std::vector<size_t> on_disk_;        // values of each recorded array not in memory (before Results' first)
  std::vector<std::string> chunks_;    // SHA-256 of each records chunk, in order
  long last_step_ = 0;
  bool replaced_old_ = false;          // the folder's earlier content has been cleared (fresh start)
};

// The series of a run whose Checkpointer spilled them: the rows of the first `steps_on_disk` steps from the chunks
// of the checkpoint in `dir` (that of the run `provenance` names, at that step; every chunk is checked against its
// SHA-256 once, here), then the rows in `tail`.series. Error, naming the file, if the checkpoint is not that or its
// chunks are damaged or gone.
class CheckpointSeries final : public SeriesSource {
 public:
  CheckpointSeries(const std::filesystem::path& dir, const nlohmann::json& provenance, long steps_on_disk,
                   const Results& tail);
  size_t steps() const override;
  std::vector<double> get(const std::string& name) const override;

 private:
  struct Segment {
    std::filesystem::path file;
    size_t offset;  // bytes from the start of the file to the first value
    size_t count;   // values
  };
  const Results& tail_;
  size_t steps_on_disk_ = 0;
  std::map<std::string, std::vector<Segment>> segments_;  // series name -> its values in each chunk, in order
};

}  // namespace floesim::sim
