// The plot stage: surge ice load against time, its centred moving average and the steady-state mean (like Fig. 5
// of the SAMS paper), drawn by gnuplot to PNG and SVG, with the numbers in a CSV and a JSON sidecar. Fracture
// events at the vessel are marked along the bottom of the plot (one marker style for splitting, one for bending
// and radial), and every fracture event is listed in fracture_events.csv.
// floesim-plot is a thin main over plot_surge_load().
#pragma once
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/options.h"
#include "pipeline/load_series.h"
#include "pipeline/results_io.h"
#include "pipeline/signal.h"
#include "pipeline/units.h"
#include "render/render_options.h"  // auto_or_number

namespace floesim::render {

struct PlotOptions {
  Json moving_average_window_s = "auto";  // s; "auto": 20 s if the run used only rigid contacts, else 0.5 s
  Json steady_start_s = "auto";           // s; "auto": the results attribute steady_start_s, 0 if absent
  Json y_max_kN = "auto";                 // kN; "auto": fit the average and clip rare raw spikes (noted on the plot)
  int width_px = 1400;                    // PNG size (the SVG has the same proportions)
  int height_px = 650;
  std::string title = "Surge ice load";   // "" for none

  template <class V>
  void visit(V& v) {
    v.field("moving_average_window_s", moving_average_window_s, "s",
            "centred moving-average window, or \"auto\" (PHYSICS.md 5): the rigid part of the load over 20 s plus "
            "the compliant part over 0.5 s, each filtered and then summed",
            auto_or_number(true));
    v.field("steady_start_s", steady_start_s, "s",
            "start of the steady part averaged for the mean, or \"auto\": results attribute steady_start_s (else 0)",
            auto_or_number(false));
    v.field("y_max_kN", y_max_kN, "kN", "top of the load axis, or \"auto\"", auto_or_number(true));
    v.field("width_px", width_px, "px", "PNG width", int_in_range(320, 8000));
    v.field("height_px", height_px, "px", "PNG height", int_in_range(200, 8000));
    v.field("title", title, "-", "plot title (empty for none)");
  }
};

PlotOptions read_plot_options(const std::filesystem::path& config);

struct SurgeLoadSummary {
  std::string contact_model;       // from the results attributes ("rigid" if absent)
  double time_step_s = 0;          // sample step of the series
  double window_s = 0;             // moving-average window used (the longest, with "auto" on a mixed run)
  std::string filter;              // what the moving average is, for labels
  size_t window_samples = 0;       // N = round(window_s / time_step_s)
  double steady_start_s = 0;
  size_t steady_samples = 0;
  double mean_kN = 0;              // mean ice resistance (-Fx) over t >= steady_start_s, unfiltered
  MeanInterval interval;           // its batch-means 95 % interval (kN; pipeline/signal.h), as summary.json's
  bool moving_average_complete = true;  // false: the run is shorter than the window (all windows cut)
  double moving_average_std_kN = 0;  // of the moving average over the steady part, full windows only (NaN if none)
  double moving_average_max_kN = 0;
  double raw_max_kN = 0;           // over the whole run
  ForceUnit display_unit{"kN", 1e3};  // the unit the plot and the printed summary use (force_unit_for the loads)
  size_t fracture_events = 0;                // all of /fracture (in fracture_events.csv)
  size_t vessel_splitting_events = 0;        // at the vessel, marked on the plot
  size_t vessel_bending_radial_events = 0;   // at the vessel, marked on the plot
};

// Writes DIR/surge_ice_load.{png,svg,csv}, DIR/fracture_events.csv and DIR/plot.json; each appears only when
// complete.
SurgeLoadSummary plot_surge_load(const Results& r, const PlotOptions& o, const std::filesystem::path& out_dir,
                                 const nlohmann::json& provenance, const std::string& source);
SurgeLoadSummary plot_surge_load(const std::filesystem::path& results, const std::filesystem::path& config,
                                 const std::filesystem::path& out_dir);

// Each structure's ice load (results /structures: the vessel's hull body when it is a structure, and those beside
// it): the horizontal load along its heading at its station, raw and through the 0.5 s centred moving average of the
// compliant contacts (PHYSICS.md 5), and the vertical load through the same, against time. Writes
// DIR/structure_NAME_load.{png,svg}, each only when complete; returns the stems written.
std::vector<std::string> plot_structure_loads(const Results& r, const PlotOptions& o,
                                              const std::filesystem::path& out_dir);
std::vector<std::string> plot_structure_loads(const std::filesystem::path& results,
                                              const std::filesystem::path& config,
                                              const std::filesystem::path& out_dir);

// The identified ice load of floesim-identify (its folder: identified.csv and identified.json) against time at its
// output rate: the identified resistance and, when the measured data carried a known load (a simulated ship's), that
// load averaged over the same intervals; each with its mean over the identification's mean window. The comparison
// a reader checks by eye: same filter, same window. Writes DIR/identified_load.{png,svg}, each only when complete.
struct IdentifiedPlotSummary {
  size_t samples = 0;            // output-rate rows plotted
  bool known = false;            // the known load was plotted too
  double mean_identified_kN = 0;  // identified.json mean_surge_ice_resistance_n / 1000
  double mean_known_kN = NAN;     // identified.json known_load.mean_surge_ice_resistance_n / 1000
};
IdentifiedPlotSummary plot_identified_load(const std::filesystem::path& identify_dir, const PlotOptions& o,
                                           const std::filesystem::path& out_dir);

}  // namespace floesim::render
