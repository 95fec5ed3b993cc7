// The statistics of a sweep: after `floesim sweep` has run the members of a sweep (the points of a grid of case
// values, each run as an ensemble of seeds), the gather reads the sweep's plan (pipeline/sweep/sweep_plan.h),
// every member's summary and results, and makes one table (sweep.csv, sweep.json) with each member's steady mean,
// its batch-means standard error and peak, and a Student t interval per grid point; for level ice, Lindqvist's and
// Riska's resistance beside the simulated mean. Members that failed are listed with the tail of their failed
// stage's log; they do not stop the gather. The plots of a sweep are render/'s (render/sweep_plots.h).
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/options.h"
#include "pipeline/results_io.h"
#include "pipeline/signal.h"
#include "pipeline/sweep/sweep_plan.h"

namespace floesim::sweep {

// The interval's level and the batches of a member's batch-means standard error: pipeline/signal.h's, as each run's
// summary.json has them.
inline constexpr double kConfidence = kMeanConfidence;
inline constexpr size_t kBatchMeansBatches = kMeanBatches;
// Window of the peak resistance: PHYSICS.md §5's moving average for compliant contacts.
inline constexpr double kPeakWindowS = 0.5;
// Non-empty log lines quoted for a failed member.
inline constexpr size_t kErrorLogLines = 3;

// ---- One member's resistance series ----

// The steady part of the surge ice resistance, exactly as the plot stage averages it: -Fx of the ice load in kN
// (surge_ice_resistance_kN) at the samples with t >= the results attribute steady_start_s (0 if absent).
struct SteadyResistance {
  double steady_start_s = 0;
  double time_step_s = 0;
  std::vector<double> time_s;
  std::vector<double> resistance_kN;
};
// Error naming `source` if the series is malformed or has no sample at or after the steady start.
SteadyResistance steady_resistance(const Results& r, const std::string& source);

struct ResistanceStats {
  double steady_start_s = 0;
  double time_step_s = 0;
  size_t samples = 0;
  double mean_kN = 0;                // the plot stage's mean, bit for bit
  size_t batches = 0;
  size_t batch_samples = 0;          // floor(samples / batches)
  size_t dropped_samples = 0;        // the remainder, dropped at the start of the steady part
  double batch_means_se_kN = 0;      // NaN if samples < batches
  MeanInterval interval;             // the same batches: the 95 % interval, whether it means anything
  double peak_window_s = 0;
  size_t peak_window_samples = 0;
  double peak_kN = 0;                // largest centred moving average, full windows only; NaN if none fits
};
ResistanceStats resistance_stats(const SteadyResistance& s, size_t batches = kBatchMeansBatches,
                                 double peak_window_s = kPeakWindowS);

// ---- Gathering ----

struct MemberResult {
  std::string id;
  size_t grid_point = 0;
  size_t ensemble_index = 0;
  bool ok = false;            // summary.json and results.h5 both readable
  std::string error;          // failed: the last non-empty lines of the failed stage's log, or "not run"
  std::string failed_stage;   // the stage whose log `error` quotes ("" if none)
  std::filesystem::path failed_log;
  // From summary.json (NaN / 0 for a failed member).
  double mean_resistance_kN = 0;   // mean_surge_ice_resistance_N / 1000
  double mean_speed_mps = 0;       // mean_vessel_speed_mps
  int64_t fracture_bending = 0, fracture_radial = 0, fracture_splitting = 0;
  ResistanceStats series;          // from results.h5
  double wall_s = 0;               // sum of the stages' wall_ms / 1000; NaN if none was recorded
  // Level ice (issue #10; summary.json has level_ice.ice): Lindqvist's and Riska's resistance (PHYSICS.md §6) for
  // the member's hull (its hull stage's hull.json), ice and mean speed, and the channel's width over the beam.
  bool level_ice = false;
  double lindqvist_kN = 0, riska_kN = 0, channel_width_over_beam = 0;  // NaN when not known
  std::string reference_error;     // why the formulas could not be evaluated ("" if they were)
};

struct GridPointResult {
  size_t index = 0;
  Json axes = Json::object();
  size_t n_members = 0;
  ConfidenceInterval ci;  // of the ok members' mean resistance (kN); ci.n = number of ok members
  // The point's 95 % interval (kN): over its ok members (ci) when there are two or more; with one, that member's own
  // batch-means interval (its summary.json's); NaN without.
  double half_width_kN = 0;
  std::string interval_method;
};

struct GatherResult {
  std::vector<std::string> columns;  // of sweep.csv
  std::vector<MemberResult> members;  // in plan order
  std::vector<GridPointResult> grid_points;
  std::vector<std::string> seed_keys;  // what the ensembles seeded (union over members, sorted)
  bool level_ice = false;              // a member ran in level ice: the formulas' columns are in the table
  int first_ok = -1;                   // the first ok member (-1: none), and its steady series (running-mean plot)
  SteadyResistance first_series;
  std::vector<std::string> files;  // written into the output directory (sweep.csv, sweep.json and the plots)
};

// The members' results and the statistics per grid point: reads every member's summary.json and results.h5 (a
// member that failed is listed with why, from its failed stage's log; it does not stop the gather).
GatherResult gather_members(const SweepPlan& plan);

// sweep.csv and sweep.json of the gathered members: every member's row (its axes, seeds and results), the grid
// points' statistics, the failed members, and the provenance (`plan_file` and every gathered member's files
// hashed). sweep.json lists g.files.
struct SweepTables {
  std::string csv, json;
};
SweepTables sweep_tables(const SweepPlan& plan, const std::filesystem::path& plan_file, const GatherResult& g);

// The short report floesim-gather prints: per grid point mean +- 95 % CI and ok/n, then the failed members.
std::string gather_table(const SweepPlan& plan, const GatherResult& g);

// "mean ± 95 % half width" as gather_table and the plots print it.
std::string ci_text(const ConfidenceInterval& ci, double scale = 1.0);

}  // namespace floesim::sweep
