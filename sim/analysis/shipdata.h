// The shipdata stage (issue #11, the round trip): a simulated transit (results.h5 and its summary.json) -> the
// measured-data CSV a ship would record, which floesim-identify reads, and a sidecar identify config that describes
// the simulated ship (mass with added mass, ITTC-57 particulars, wind), so that identification can be checked
// against the known simulated ice load.
//
// Axes and signs are those of floesim-simulate and floesim-identify: body axes x forward, y to port, z up; loads on
// the ship.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "pipeline/options.h"
#include "pipeline/results_io.h"
#include "sim/analysis/identify.h"

namespace floesim::sim {

// Sensor errors added to the recorded motion: Gaussian white noise (standard deviation) plus a constant bias, per
// axis. Defaults: no noise, no bias (the data are then the simulator's own numbers).
struct ShipDataNoiseOptions {
  double surge_sd_mps2 = 0;      // IMU surge acceleration noise
  double sway_sd_mps2 = 0;       // IMU sway acceleration noise
  double yaw_sd_radps2 = 0;      // yaw angular acceleration noise
  double surge_bias_mps2 = 0;    // IMU surge acceleration bias
  double sway_bias_mps2 = 0;     // IMU sway acceleration bias
  double yaw_bias_radps2 = 0;    // yaw angular acceleration bias
  double velocity_sd_mps = 0;    // noise on u and v (speed log / GNSS)
  double yaw_rate_sd_radps = 0;  // noise on r (gyro)
  template <class V>
  void visit(V& v) {
    v.field("surge_sd_mps2", surge_sd_mps2, "m/s^2", "standard deviation of the white noise on du", non_negative());
    v.field("sway_sd_mps2", sway_sd_mps2, "m/s^2", "standard deviation of the white noise on dv", non_negative());
    v.field("yaw_sd_radps2", yaw_sd_radps2, "rad/s^2", "standard deviation of the white noise on dr",
            non_negative());
    v.field("surge_bias_mps2", surge_bias_mps2, "m/s^2", "constant bias added to du");
    v.field("sway_bias_mps2", sway_bias_mps2, "m/s^2", "constant bias added to dv");
    v.field("yaw_bias_radps2", yaw_bias_radps2, "rad/s^2", "constant bias added to dr");
    v.field("velocity_sd_mps", velocity_sd_mps, "m/s", "standard deviation of the white noise on u and v",
            non_negative());
    v.field("yaw_rate_sd_radps", yaw_rate_sd_radps, "rad/s", "standard deviation of the white noise on r",
            non_negative());
  }
};

struct ShipDataOptions {
  ShipDataNoiseOptions noise;
  int seed = 1;                      // of the std::mt19937_64 drawing the noise (same seed, same file)
  int every = 1;                     // write every k-th simulated step (1 = every step)
  bool write_accelerations = true;   // du/dv/dr columns (false: identify differentiates the velocities)
  bool truth_columns = true;         // also write the simulated ice load (sim_ice_*), which identify ignores
  template <class V>
  void visit(V& v) {
    v.section("noise", noise, "IMU and velocity noise and bias (default none)");
    v.field("seed", seed, "-", "seed of the noise generator (std::mt19937_64)", int_in_range(0, 2147483647));
    v.field("every", every, "-", "write every k-th simulated step", positive_int());
    v.field("write_accelerations", write_accelerations, "-",
            "write du_mps2, dv_mps2, dr_radps2 (backward differences of the recorded body velocities, the "
            "simulator's own step, plus the IMU noise); false = leave them to identify's differentiation");
    v.field("truth_columns", truth_columns, "-",
            "also write sim_ice_surge_n, sim_ice_sway_n, sim_ice_yaw_nm (the simulated ice load; identify "
            "ignores extra columns)");
    const ShipDataNoiseOptions& e = noise;
    if (!write_accelerations && (e.surge_sd_mps2 != 0 || e.sway_sd_mps2 != 0 || e.yaw_sd_radps2 != 0 ||
                                 e.surge_bias_mps2 != 0 || e.sway_bias_mps2 != 0 || e.yaw_bias_radps2 != 0))
      v.problem("noise", "gives IMU noise or bias, but write_accelerations is false (no accelerations are written)");
  }
};

// The converted transit.
struct ShipData {
  MeasuredSeries measured;      // the rows of the CSV (accelerations empty when not written)
  std::vector<Load3> sim_ice;   // the simulated ice load on the ship, body axes, per row (the truth)
  IdentifyOptions identify;     // the identify config matching the simulated ship (the sidecar)
  bool wind = false;            // the case had wind (else the wind columns are zero, as the simulator's load)
  double mean_t0_s = 0, mean_t1_s = 0;  // the steady part of the simulation (summary.json's mean)
};

// Converts a simulated transit. `summary` is the simulation's summary.json (its `vessel` particulars and its
// `settings`, the resolved simulate options); if the results carry their provenance, its config must equal the
// summary's settings (a summary of another run is an error).
//  - u, v: the recorded body-axis vessel velocity less the current (turned into body axes by the recorded
//    quaternion): the velocity through the water, as the simulator's resistance sees it; r: the body yaw rate.
//  - thrust: the surge component of the propulsion load (0 in bollard pull, as in the simulation).
//  - wind: the relative wind of the case's wind (air velocity less the vessel's, in body axes, angle it comes from
//    atan2(-a_y, -a_x)); zero when the case has none (the simulator then applies no wind load at all).
//  - du, dv, dr: backward differences (x_k - x_{k-1}) / dt of the recorded u, v, r at the simulation step (the
//    simulator's symplectic Euler step: the velocity change of step k comes from the loads of step k), the first
//    row a forward difference; then the noise and bias.
ShipData make_ship_data(const Results& results, const nlohmann::json& summary, const ShipDataOptions& o);

// The measured-data CSV text of `d` (floesim-identify's columns; extra sim_ice_* columns when asked for).
std::string ship_data_csv(const ShipData& d, const ShipDataOptions& o);

// The stage: reads results.h5, summary.json (default: beside the results) and the config (empty = defaults), and
// writes out_csv and, beside it, out_csv with the extension .json (the identify config) atomically.
std::string run_shipdata(const std::filesystem::path& results_file, const std::filesystem::path& summary_file,
                         const std::filesystem::path& config_file, const std::filesystem::path& out_csv);

}  // namespace floesim::sim
