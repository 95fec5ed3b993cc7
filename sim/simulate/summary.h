// summary.json of the simulate stage: the steady means of the loads and the vessel's motion, the moving averages
// of PHYSICS.md §5, how the solver did, fracture and level ice, from the results alone (and the model as built, for
// what the inputs were).
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/results_io.h"
#include "sim/engine/model.h"
#include "sim/simulate/options.h"

namespace floesim::sim {

// Summary statistics of the results (steady part from o.steady_start_s); the series from `series` (one at a time)
// or from results.series. `model` is the model as built or the world's that ran it: only its built bodies are read
// (the input floes, the vessel and the sheet; Model::built_bodies).
nlohmann::json summarize(const SimulateOptions& o, const Model& model, const Results& results,
                         const SeriesSource& series);
nlohmann::json summarize(const SimulateOptions& o, const Model& model, const Results& results);

// The uncertainty of a steady mean in summary.json (issue #37; pipeline/signal.h's mean_interval): the batch-means
// standard error and the 95 % interval around `mean` (the summary's own mean of `x`), the batches, the test of
// their independence and, when the run is too short for the interval to mean anything, why. `unit` suffixes the
// keys (standard_error_N, low_N, ...).
nlohmann::json mean_interval_json(const std::vector<double>& x, double dt_s, double mean, const std::string& unit);

// Level ice (summary.json "level_ice"): the sheet's tiles and area at the start and the channel the vessel broke:
// from the sheet's edge on its path to its centre of mass in the last frame (behind midship the channel is formed),
// the sheet area lost there over that length is the channel's mean width, against the waterline beam.
nlohmann::json level_ice_summary(const SimulateOptions& o, const Model& model, const Results& results,
                                 const SeriesSource& series);
nlohmann::json level_ice_summary(const SimulateOptions& o, const Model& model, const Results& results);

// A fixed structure (summary.json "structure", vessel.station_keeping.mode "fixed"): the ice's action along its drift
// (-Fx in the structure's axes, x facing the ice that comes), transverse, vertical and overturning, raw and through
// the 0.5 s filter of PHYSICS.md §5; the filtered load's cycles (mean of per-cycle peaks, mean period) and dominant
// period against h/v; the rubble height the run shows near the structure (for Croasdale's F_H, §8.2).
nlohmann::json structure_summary(const SimulateOptions& o, const Model& model, const Results& results,
                                 const SeriesSource& series);
// summary.json "structures"[k]: the same for structure k beside the vessel (simulate.structures), from its series
// (/structures/NAME), with each part's share of the horizontal load and each mooring line's recorded tension.
nlohmann::json listed_structure_summary(const SimulateOptions& o, const Model& model, const Results& results,
                                        const SeriesSource& series, size_t k);

}  // namespace floesim::sim
