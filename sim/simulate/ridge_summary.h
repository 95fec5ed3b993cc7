// summary.json "ridges" (issue #36): each ridge as designed and as built (settle_ridges' measurement: profiles,
// areas, porosity two ways, hydrostatics), a ship's passage through it (how far its bow got, whether it came through
// or stopped, its speed and the loads from rubble and layer while its bow was in the ridge), for a held structure the
// largest loads from the ridges' rubble and layers, and the freeze bonds made and broken (`end`: the run's last
// state).
#pragma once
#include <nlohmann/json.hpp>

#include "pipeline/results_io.h"
#include "sim/engine/model.h"
#include "sim/engine/ridge_build.h"
#include "sim/simulate/options.h"

namespace floesim::sim {

nlohmann::json ridge_summary(const SimulateOptions& o, const Model& model, const RidgeSettling& settled,
                             const SeriesSource& series, const State& end);

}  // namespace floesim::sim
