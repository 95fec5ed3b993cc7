#include "render/strip_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "pipeline/error.h"
#include "pipeline/signal.h"
#include "pipeline/units.h"
#include "render/plot.h"

namespace floesim::render {

namespace {

// A round tick step (1, 2, 2.5 or 5 x 10^k) giving about `ticks` intervals over `range`.
double nice_step(double range, int ticks) {
  const double raw = range / ticks;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

double scale_px(const cv::Mat& img) { return img.rows / 720.0; }

const cv::Scalar kLabel(235, 235, 235), kGrid(95, 95, 95);

}  // namespace

int strip_chart_top(const RenderOptions& o, int height_px) {
  return height_px - static_cast<int>(std::lround(o.strip_height * height_px));
}

cv::Rect strip_chart_plot_area(const RenderOptions& o, int width_px, int height_px) {
  const double s = height_px / 720.0;
  const int top = strip_chart_top(o, height_px);
  const int left = int(std::lround(78 * s)), right = int(std::lround(22 * s));
  const int above = int(std::lround(34 * s)), below = int(std::lround(28 * s));
  return {left, top + above, width_px - left - right, height_px - top - above - below};
}

LoadStripChart::LoadStripChart(const Results& r, const RenderOptions& o, const std::string& source) : o_(o) {
  // 1. The signal and its average, as the plot stage computes them.
  const std::vector<double>& t = r.get("time_s");
  const std::vector<double> load = surge_ice_resistance_kN(r, source);
  FLOESIM_REQUIRE(t.size() >= 2, source, ": the strip chart needs at least 2 steps of series, the results hold ",
                  t.size(), " (set the render option strip_chart to false)");
  const double dt = uniform_step(t, (source + ": series time_s").c_str());
  std::vector<double> average;
  if (o.strip_average_window_s.is_string()) {
    FilteredLoad f = auto_filtered_surge_ice_resistance_kN(r, source);
    scale_.window_s = f.window_s;
    const bool both = f.text.rfind("rigid part", 0) == 0;
    scale_.average_label = both ? "moving average 20 s rigid + 0.5 s compliant"
                                : "moving average " + fmt("%g s", scale_.window_s);
    average = std::move(f.kN);
  } else {
    scale_.window_s = o.strip_average_window_s.get<double>();
    scale_.average_label = "moving average " + fmt("%g s", scale_.window_s);
    average = moving_average_centred(load, window_samples(scale_.window_s, dt));
  }

  // 2. Time: the series and the frames (the first frame may be at t = 0, before the first step ends).
  scale_.t_first = std::min(t.front(), r.frames() ? r.frame_time_s.front() : t.front());
  if (scale_.t_first > 0 && scale_.t_first < 0.05 * t.back()) scale_.t_first = 0;  // the axis from 0, as the plot
  scale_.t_last = std::max(t.back(), r.frames() ? r.frame_time_s.back() : t.back());
  const double run = std::max(scale_.t_last - scale_.t_first, 1e-9);
  scale_.span_s = o.strip_span_s > 0 ? std::min(o.strip_span_s, run) : run;

  // 3. Load axis: the top fits the average (3 x its peak at most, as the plot does) so that the rare single-step
  // spikes of rigid contacts are clipped instead of flattening everything else; brief negative loads are shown down
  // to a fifth of the top.
  const double raw_max = *std::max_element(load.begin(), load.end());
  const double raw_min = *std::min_element(load.begin(), load.end());
  const double avg_max = *std::max_element(average.begin(), average.end());
  const double avg_min = *std::min_element(average.begin(), average.end());
  double hi = o.strip_max_kN.is_number() ? o.strip_max_kN.get<double>()
                                         : 1.05 * std::max(std::min(raw_max, 3.0 * avg_max), avg_max);
  if (!(hi > 0)) hi = 1.0;  // no load at all (open water): an axis of 0..1 kN
  const double lo = std::min({0.0, avg_min, std::max(raw_min, -0.2 * hi)});
  // The unit that suits the axis (pipeline/units.h, as the plot and the report choose theirs).
  const ForceUnit unit = force_unit_for(1000.0 * hi);
  scale_.per_kN = 1000.0 / unit.newtons;
  scale_.unit = unit.name;
  scale_.y_hi = hi * scale_.per_kN;
  scale_.y_lo = lo * scale_.per_kN;

  // 4. Bins of one pixel column of the plot: the lowest and highest sample of each, in time order (the plot's
  // decimation), and the average at the bin's last sample.
  const cv::Rect area = strip_chart_plot_area(o, o.width_px, o.height_px);
  FLOESIM_REQUIRE(area.width > 8 && area.height > 8, "render options: the strip chart's plot area is ", area.width,
                  " x ", area.height, " px; raise strip_height or the frame size");
  const double bin = scale_.span_s / area.width;
  for (size_t i = 0; i < t.size();) {
    const double b = std::floor((t[i] - scale_.t_first) / bin);
    size_t j = i, imin = i, imax = i;
    while (j < t.size() && std::floor((t[j] - scale_.t_first) / bin) == b) {
      if (load[j] < load[imin]) imin = j;
      if (load[j] > load[imax]) imax = j;
      ++j;
    }
    const size_t a = std::min(imin, imax), c = std::max(imin, imax);
    raw_.push_back({t[a], load[a]});
    if (c != a) raw_.push_back({t[c], load[c]});
    average_.push_back({t[j - 1], average[j - 1]});
    i = j;
  }
  build_layer();
}

double LoadStripChart::window_start(double t_s) const {
  if (whole_run()) return scale_.t_first;
  return std::clamp(t_s - 0.8 * scale_.span_s, scale_.t_first, scale_.t_last - scale_.span_s);
}

// The chart is drawn in layers: what does not move (the load axis, the frame, the title; over the whole run also the
// time axis and the curves) once into a cached layer that each frame copies over the darkened band, the rest per
// frame. A frame of the whole run then costs the darkening, one masked copy and the cursor.
void LoadStripChart::draw_load_axis(cv::Mat& img) const {
  const double s = scale_px(img);
  const int font = cv::FONT_HERSHEY_SIMPLEX, thick = std::max(1, int(std::lround(1.2 * s)));
  const cv::Rect a = strip_chart_plot_area(o_, img.cols, img.rows);
  const double ys = nice_step(scale_.y_hi - scale_.y_lo, 4);
  for (double v = std::ceil(scale_.y_lo / ys) * ys; v <= scale_.y_hi + 1e-9 * ys; v += ys) {
    const int y = int(std::lround(a.y + a.height - (v - scale_.y_lo) / (scale_.y_hi - scale_.y_lo) * a.height));
    cv::line(img, {a.x, y}, {a.x + a.width, y}, kGrid, 1);
    const std::string l = fmt("%g", std::abs(v) < 1e-9 * ys ? 0.0 : v);
    int base = 0;
    const cv::Size sz = cv::getTextSize(l, font, 0.45 * s, thick, &base);
    cv::putText(img, l, {a.x - sz.width - int(8 * s), y + sz.height / 2}, font, 0.45 * s, kLabel, thick, cv::LINE_AA);
  }
  cv::rectangle(img, a, kGrid, 1);
  // Title and legend above the plot.
  const int yt = strip_chart_top(o_, img.rows) + int(22 * s);
  int x = a.x;
  const auto say = [&](const std::string& l, const cv::Scalar& c) {
    int base = 0;
    cv::putText(img, l, {x, yt}, font, 0.5 * s, c, thick, cv::LINE_AA);
    x += cv::getTextSize(l, font, 0.5 * s, thick, &base).width + int(18 * s);
  };
  say("surge ice load (" + scale_.unit + ")", kLabel);
  say("each step", kStripRawBgr);
  say(scale_.average_label, kStripAverageBgr);
}

void LoadStripChart::draw_time_axis_and_curves(cv::Mat& img, double t0) const {
  const double s = scale_px(img), span = scale_.span_s;
  const int font = cv::FONT_HERSHEY_SIMPLEX, thick = std::max(1, int(std::lround(1.2 * s)));
  const cv::Rect a = strip_chart_plot_area(o_, img.cols, img.rows);
  const auto px_x = [&](double t) { return a.x + (t - t0) / span * a.width; };
  const auto px_y = [&](double kN) {
    const double v = kN * scale_.per_kN;
    const double y = a.y + a.height - (v - scale_.y_lo) / (scale_.y_hi - scale_.y_lo) * a.height;
    return std::clamp(y, double(a.y), double(a.y + a.height));  // spikes beyond the axis are cut at its edge
  };
  const double xs = nice_step(span, 8);
  for (double tt = std::ceil(t0 / xs) * xs; tt <= t0 + span + 1e-9 * xs; tt += xs) {
    const int x = int(std::lround(px_x(tt)));
    cv::line(img, {x, a.y + a.height}, {x, a.y + a.height + int(5 * s)}, kLabel, 1);
    const bool last = tt + xs > t0 + span + 1e-9 * xs;  // the unit goes on the last label
    const std::string l = fmt("%g", std::abs(tt) < 1e-9 * xs ? 0.0 : tt) + (last ? " s" : "");
    int base = 0;
    const cv::Size sz = cv::getTextSize(l, font, 0.45 * s, thick, &base);
    cv::putText(img, l, {std::min(x - sz.width / 2, img.cols - sz.width - 2), a.y + a.height + int(22 * s)}, font,
                0.45 * s, kLabel, thick, cv::LINE_AA);
  }
  // The series inside the window (one bin before and after, so the lines reach the edges).
  const auto points = [&](const std::vector<std::pair<double, double>>& v, std::vector<cv::Point>& out) {
    out.clear();
    auto lo = std::lower_bound(v.begin(), v.end(), std::make_pair(t0, -1e300));
    auto hi = std::upper_bound(v.begin(), v.end(), std::make_pair(t0 + span, 1e300));
    if (lo != v.begin()) --lo;
    if (hi != v.end()) ++hi;
    for (auto it = lo; it != hi; ++it)
      out.emplace_back(int(std::lround(std::clamp(px_x(it->first), double(a.x), double(a.x + a.width)))),
                       int(std::lround(px_y(it->second))));
  };
  std::vector<cv::Point> p;
  points(raw_, p);
  if (!p.empty()) cv::polylines(img, p, false, kStripRawBgr, 1, cv::LINE_8);
  points(average_, p);
  if (!p.empty()) cv::polylines(img, p, false, kStripAverageBgr, std::max(2, int(std::lround(2 * s))), cv::LINE_AA);
}

bool LoadStripChart::whole_run() const { return scale_.span_s >= scale_.t_last - scale_.t_first; }

void LoadStripChart::build_layer() {
  cv::Mat full(o_.height_px, o_.width_px, CV_8UC3, cv::Scalar::all(0));
  draw_load_axis(full);
  if (whole_run()) draw_time_axis_and_curves(full, scale_.t_first);
  const int top = strip_chart_top(o_, o_.height_px);
  layer_ = full(cv::Rect(0, top, o_.width_px, o_.height_px - top)).clone();
  cv::Mat grey;
  cv::cvtColor(layer_, grey, cv::COLOR_BGR2GRAY);
  layer_mask_ = grey > 0;
}

void LoadStripChart::draw(cv::Mat& img, double t_s) const {
  FLOESIM_REQUIRE(img.cols == o_.width_px && img.rows == o_.height_px && img.type() == CV_8UC3,
                  "internal: strip chart for ", o_.width_px, " x ", o_.height_px, " drawn into ", img.cols, " x ",
                  img.rows);
  // Band: the scene darkened (a translucent panel), then the cached layer, then what moves.
  const int top = strip_chart_top(o_, img.rows);
  cv::Mat band = img(cv::Rect(0, top, img.cols, img.rows - top));
  band *= 0.3;
  layer_.copyTo(band, layer_mask_);
  const double t0 = window_start(t_s);
  if (!whole_run()) draw_time_axis_and_curves(img, t0);
  // Cursor at the frame's time.
  const cv::Rect a = strip_chart_plot_area(o_, img.cols, img.rows);
  const int xc = int(std::lround(a.x + (t_s - t0) / scale_.span_s * a.width));
  cv::line(img, {xc, a.y}, {xc, a.y + a.height}, kStripCursorBgr, std::max(1, int(std::lround(2 * scale_px(img)))),
           cv::LINE_8);
}

}  // namespace floesim::render
