// The plots of a sweep and the floesim-gather stage: the statistics of pipeline/sweep/gather.h (sweep.csv,
// sweep.json) with the mean ice resistance against each axis (95 % confidence intervals, the members as points),
// against Lindqvist and Riska for level ice, the ensemble of a pure ensemble, and the running mean of one member
// (was the run long enough?). floesim-gather is a thin main over gather_sweep().
#pragma once
#include <filesystem>

#include "pipeline/sweep/gather.h"

namespace floesim::render {

// Writes OUT/sweep.csv, OUT/sweep.json and the plots (PNG and SVG): resistance_vs_<axis>.* per axis (or
// ensemble.* for a pure ensemble), level_ice_resistance.* for level ice and running_mean.* for the first ok member;
// plots need at least one ok member. Each file appears only when all are complete. Failed members do not make it
// fail; a broken plan or a plotting failure does. `plan_file` is hashed into the provenance.
sweep::GatherResult gather_sweep(const sweep::SweepPlan& plan, const std::filesystem::path& plan_file,
                                 const std::filesystem::path& out_dir);
sweep::GatherResult gather_sweep(const std::filesystem::path& plan_file, const std::filesystem::path& out_dir);

}  // namespace floesim::render
