// The simulate stage: floes + hull + options -> results.h5 (pipeline/results_io.h layout) and summary.json.
// The loop is here; what a step records is the Recorder's (recorder.h), what a run sums up the summary's
// (summary.h), checkpoints the Checkpointer's (checkpoint.h).
#pragma once
#include <filesystem>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "pipeline/results_io.h"
#include "sim/engine/model.h"
#include "sim/simulate/options.h"
#include "sim/simulate/summary.h"

namespace floesim::sim {

class World;  // sim/engine/world.h

// Run statistics that are not artefacts (wall time is not deterministic): printed by the stage.
struct RunStats {
  double wall_s = 0;
  double stage_s[8] = {};     // per World stage, then the recorder
  double mean_awake_floes = 0, mean_contacts = 0, mean_iterations = 0;
  double mean_awake_rubble = 0;  // of the awake floes, blocks of ridges' rubble
  double mean_pairs = 0, mean_touching = 0, mean_edge_pairs = 0;  // broad-phase pairs, touching pairs, edge ones
  double mean_crushing_pairs = 0;  // touching pairs with a compliant (crushing) contact
  long steps = 0;
  long resumed_at_step = 0;        // the checkpoint this process continued from (0: from the start)
  int checkpoints = 0;             // written by this process
  double checkpoint_s = 0;         // their wall time
};

// Checkpoints of a run (sim/simulate/checkpoint.h): where, and whether to continue from the one there.
struct CheckpointPlan {
  std::filesystem::path dir;         // OUT/checkpoint
  nlohmann::json provenance;         // the stage's provenance: identifies the run (its inputs and settings)
  bool resume = false;               // continue from the checkpoint in dir (if there is one of this run)
  // The series rows written to a checkpoint leave memory (Results::series then starts at series_first_step; read
  // the whole series through CheckpointSeries, sim/simulate/checkpoint.h, before the checkpoint folder is removed): a long
  // run's memory then holds one checkpoint interval of them, not 0.65 kB for every step.
  bool spill_series = false;
};

// Simulates the model for o.duration_s: a world that owns the model (moved in; pass a copy to keep one) steps it,
// or continues it from a checkpoint, and a Recorder (sim/simulate/recorder.h) records every series per step, the
// body states at t = k * output_interval_s (k = 1..N, exactly duration / output_interval frames) and the geometry.
// `model` is the model build_model made with `o`. `progress` (may be null) receives a line every 10 % of the run.
// Needs a vessel in the model. With `checkpoints`, writes a checkpoint every o.checkpoint_interval_s of simulated
// time (if > 0) and when stopped by a signal, and resumes from one if asked: the results are the same to the bit
// either way. SIGINT/SIGTERM stop it between two steps with Interrupted (pipeline/interrupt.h). `world` (may be
// null) receives the world at the end, with its model (the summary's).
Results simulate(const SimulateOptions& o, Model model, RunStats& stats, std::ostream* progress = nullptr,
                 const CheckpointPlan* checkpoints = nullptr, std::unique_ptr<World>* world = nullptr);

// The stage: reads the inputs, builds the model, simulates, writes out_dir/results.h5 and out_dir/summary.json
// atomically (nothing is written on error) and returns the report printed on stdout. Checkpoints go to
// out_dir/checkpoint and are removed once the results are written; `resume` continues from the one there.
std::string run_simulate(const std::filesystem::path& floes_file, const std::filesystem::path& hull_file,
                         const std::filesystem::path& config_file, const std::filesystem::path& out_dir,
                         bool resume = false);

}  // namespace floesim::sim
