// The small run whose checkpoints the checkpoint tests and the fuzz_checkpoint harness read (no gtest here: the
// harness links libFuzzer, not gtest). A generated hull 40 m long at 4 m/s over the first two of four 0.3 m floes
// (the model removes the floes the vessel starts on) and against the other two, which it breaks at once; 0.4 s
// with a checkpoint every 0.1 s (the last at step 30), so the last checkpoint holds pieces in its body table,
// fracture events and cached contacts.
#pragma once
#include "pipeline/floes_io.h"
#include "pipeline/results_io.h"
#include "sim/vessel/hull.h"
#include "sim/engine/model.h"
#include "sim/simulate/options.h"

namespace floesim::sim::testing {

inline SimulateOptions small_breaking_run_options() {
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
  return o;
}

inline Model small_breaking_run() {
  HullGeneratorOptions g;
  g.length_m = 40, g.beam_m = 9, g.reamer_beam_m = 11, g.draught_m = 3, g.depth_m = 6, g.sections = 6;
  const HullModel h = hull_model_from_parts(generate_hull(g));
  FloeField f;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      Floe fl;
      fl.id = 1 + 2 * i + j;
      const double x0 = 21 * i, y0 = -20 + 21 * j;
      fl.outline = {Vec2(x0, y0), Vec2(x0 + 20, y0), Vec2(x0 + 20, y0 + 19), Vec2(x0, y0 + 19)};
      fl.area_m2 = 20 * 19;
      fl.thickness_m = 0.3;
      f.floes.push_back(fl);
    }
  return build_model(f, &h, small_breaking_run_options());
}

// A fresh run's results before the first step, as simulate() holds them when it resumes a checkpoint.
inline Results fresh_results() {
  Results r;
  for (const FieldSpec& f : series_fields()) r.series[f.name];
  r.frame_offset.push_back(0);
  return r;
}

}  // namespace floesim::sim::testing
