// The surge ice load series as every stage that reports it reads it from results.h5 (the plot, the video's strip
// chart, a sweep's statistics), so that all of them average the same samples alike: the resistance signal, the
// contact law the simulation recorded and its moving-average window (PHYSICS.md §5), the steady start.
#pragma once
#include <string>
#include <vector>

#include "pipeline/results_io.h"

namespace floesim {

// The signal the plot stage averages, shared with the sweep statistics so that both report the same mean: ice
// resistance = -Fx (ice_load column 0, body x, surge) in kN, one sample per step. Error naming `source` if the
// series is malformed or not finite (the simulation blew up).
std::vector<double> surge_ice_resistance_kN(const Results& r, const std::string& source);
// The contact model the simulation recorded (results attribute contact_model: rigid, compliant or mixed; "rigid" if
// absent).
std::string recorded_contact_model(const Results& r, const std::string& source);
// The centred moving average "auto" means (PHYSICS.md §5; the seed's windows): the rigid part of the surge ice
// resistance (results series ice_load_rigid) averaged over 20 s plus the compliant part (ice_load_compliant) over
// 0.5 s, each filtered and then summed, in kN; `window_s` the longest window in use (20 s if any rigid load was
// recorded, else 0.5 s: whole windows start and end that far from the run's ends) and `text` what was done, for
// labels. A run of one contact law is its one window over the whole load.
struct FilteredLoad {
  std::vector<double> kN;
  double window_s = 0;
  std::string text;
};
FilteredLoad auto_filtered_surge_ice_resistance_kN(const Results& r, const std::string& source);

// The steady start the simulation recorded (results attribute steady_start_s), 0 if absent.
double recorded_steady_start_s(const Results& r, const std::string& source);

}  // namespace floesim
