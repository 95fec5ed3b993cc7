// The load strip chart drawn into every video frame: a band at the bottom of the frame (the scene shows through it,
// darkened) with the surge ice resistance (-Fx, ice_load column 0, the signal floesim-plot draws), its centred
// moving average (pipeline/signal, the plot's window rule) and a cursor at the frame's time, over the whole run or a
// sliding window. The series is binned once to the plot's pixel columns (each column keeps its lowest and highest
// sample, in time order), so a frame costs a few thousand line points whatever the number of steps.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/results_io.h"
#include "render/render_options.h"

namespace floesim::render {

// Colours (BGR) of the chart's lines: the tests find them by these.
inline const cv::Scalar kStripRawBgr(235, 196, 150);     // light blue: the load of every step
inline const cv::Scalar kStripAverageBgr(0, 150, 255);   // orange: its moving average
inline const cv::Scalar kStripCursorBgr(255, 255, 255);  // white: the frame's time

// The axis the chart chose: loads are shown in kN, or in N when the axis top is below 1 kN (model scale).
struct StripChartScale {
  std::string unit = "kN";
  double per_kN = 1;            // display units per kN (1000 for N, 1 for kN, 0.001 for MN)
  double y_lo = 0, y_hi = 0;    // axis range, display units
  double window_s = 0;          // moving-average window used (the longest, with "auto" on a run of both laws)
  std::string average_label;    // the legend's name of the average, e.g. "moving average 0.5 s"
  double t_first = 0, t_last = 0;  // the run's time range (series and frames)
  double span_s = 0;            // time shown at once
};

// The band's first row, and the plot area inside it (the axes' rectangle), in a frame of width x height.
int strip_chart_top(const RenderOptions& o, int height_px);
cv::Rect strip_chart_plot_area(const RenderOptions& o, int width_px, int height_px);

class LoadStripChart {
 public:
  // Reads time_s and ice_load of `r` (errors name `source`: a series that is not finite or not uniformly sampled).
  LoadStripChart(const Results& r, const RenderOptions& o, const std::string& source);

  // Draws the band into `img` (8-bit BGR, o.width_px x o.height_px) for a frame at time t_s.
  void draw(cv::Mat& img, double t_s) const;

  const StripChartScale& scale() const { return scale_; }
  // The first time shown at frame time t_s: the run's start, or for a sliding window t_s - 0.8 span clamped to the
  // run (the cursor stays at 80 % of the width once the window moves).
  double window_start(double t_s) const;

 private:
  bool whole_run() const;
  void draw_load_axis(cv::Mat& img) const;                            // grid, labels, frame, title, legend
  void draw_time_axis_and_curves(cv::Mat& img, double t0) const;     // for the window from t0
  void build_layer();

  RenderOptions o_;
  StripChartScale scale_;
  std::vector<std::pair<double, double>> raw_, average_;  // binned (time s, load kN), in time order
  cv::Mat layer_, layer_mask_;  // what does not move, drawn once (band rows only) and where it drew
};

}  // namespace floesim::render
