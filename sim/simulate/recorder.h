// The recorder of the simulate stage: after each step of the world it appends the step's row to every series of
// the results layout (pipeline/results_io.h), stores a frame of the bodies that changed at every output interval
// and sums the run's statistics; at the end it adds the geometry of every floe that ever existed, the fracture
// table and the run's attributes. It reads the world and writes the results: nothing of the world changes.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/results_io.h"
#include "sim/engine/world.h"
#include "sim/simulate/options.h"

namespace floesim::sim {

// Sums over the steps for the run's statistics (RunStats), carried in checkpoints.
struct RecorderSums {
  double awake = 0, awake_rubble = 0, contacts = 0, iterations = 0, pairs = 0, touching = 0, edges = 0, crushing = 0;
  double record_s = 0;  // wall time of the recording, s
  double wall_s = 0;    // wall time of the steps before this process's first, s
};

class Recorder {
 public:
  // Reserves the series columns of `r` for `rows_held` steps and its frames for the whole run, and the series of
  // the model's structures (and lists them in r's attributes).
  Recorder(const SimulateOptions& o, const Model& model, Results& r, long rows_held);
  ~Recorder();

  // Takes up the bodies' last stored states from the results (none for a fresh run; every row up to the checkpoint
  // when resumed, so that a resumed run stores exactly what an uninterrupted one does).
  void attach(const World& w);

  // Records step k (1-based) that the world has just made: the series row, the sums, and a frame when k is a
  // multiple of the output interval (the vessel and the bodies that are new or changed since they were stored).
  void record_step(const World& w, long k);

  // After the last step: the outline, thickness and lineage of every floe that ever existed, the fracture events,
  // the hull surface and the run's attributes.
  void finish(const World& w);

  RecorderSums& sums() { return sums_; }

 private:
  void add_structures(const Model& m);     // their series (empty) and list, from the constructor
  void record_structures(const World& w);  // the step's row of each structure's series
  class StoredStates;
  const SimulateOptions& o_;
  Results& r_;
  long every_;
  // Direct references to the series columns: no map look-up per step.
  std::vector<double>*c_time_, *c_pos_, *c_quat_, *c_vel_, *c_omega_, *c_kinetic_;
  std::vector<double>*c_offset_, *c_demanded_, *c_delivered_;
  std::vector<std::vector<double>*> c_loads_;   // the wrench series, in the order of kLoadSeries
  std::vector<std::vector<double>*> c_scalar_;  // the scalar series, in the order of kScalarSeries
  std::vector<int8_t> pressed_;                 // per body: pressed against the vessel in this step (frames only)
  // The structures beside the vessel: per structure, its fields' columns in the order of structure_fields().
  std::vector<std::vector<std::vector<double>*>> c_structures_;
  std::unique_ptr<StoredStates> stored_;  // from attach()
  RecorderSums sums_;
};

}  // namespace floesim::sim
