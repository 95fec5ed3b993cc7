// The video a client watches (issue #11, part 4): the load strip chart, the side and split views, floes in contact
// and the hull's shading, each checked against numbers worked out here from the synthetic scene (times, loads,
// positions, the sun), never against the renderer's own output.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <opencv2/core.hpp>

#include "pipeline/error.h"
#include "pipeline/results_io.h"
#include "render/scene.h"
#include "render/strip_chart.h"
#include "render/video.h"
#include "synthetic_results.h"
#include "tests/test_util.h"

using namespace floesim;
using namespace floesim::render;
using namespace floesim::render::testing;
namespace fs = std::filesystem;

namespace {

// The synthetic run: 400 steps of 0.05 s (t = 0.05 .. 20 s), frames at t = 0, 1, .., 11 s (synthetic_results.h).
constexpr double kRunEnd_s = 20.0;

RenderOptions small(const std::string& view) {
  RenderOptions o;
  o.width_px = 640;
  o.height_px = 360;
  o.supersample = 1;
  o.view = view;
  o.overlay = false;
  return o;
}

bool same(const cv::Vec3b& c, const cv::Scalar& s) { return c[0] == s[0] && c[1] == s[1] && c[2] == s[2]; }

// Columns of the plot area where the cursor's colour fills at least 90 % of the rows; their mean (-1 if none).
double cursor_column(const cv::Mat& img, const cv::Rect& a) {
  double sum = 0;
  int n = 0;
  for (int x = a.x; x <= a.x + a.width; ++x) {
    int hits = 0;
    for (int y = a.y; y <= a.y + a.height; ++y) hits += same(img.at<cv::Vec3b>(y, x), kStripCursorBgr);
    if (hits > 0.9 * a.height) sum += x, ++n;
  }
  return n ? sum / n : -1;
}

cv::Vec3d patch(const cv::Mat& img, cv::Point2d c) {
  const cv::Rect r(int(std::lround(c.x)) - 2, int(std::lround(c.y)) - 2, 5, 5);
  const cv::Scalar m = cv::mean(img(r & cv::Rect(0, 0, img.cols, img.rows)));
  return {m[0], m[1], m[2]};
}

// Hex colour to BGR 0..255.
cv::Vec3d bgr(const std::string& hex) {
  float rgb[3];
  parse_hex_colour(hex, rgb);
  return {255.0 * rgb[2], 255.0 * rgb[1], 255.0 * rgb[0]};
}

using floesim::tests::error_of;

}  // namespace

TEST(VideoStrip, CursorStandsAtTheFrameTimeOverTheWholeRunAndInASlidingWindow) {
  const Results r = make_results(default_synthetic());
  RenderOptions o = small("top");
  SceneRenderer whole(r, o, "synthetic");
  const cv::Rect a = strip_chart_plot_area(o, o.width_px, o.height_px);
  cv::Mat img;
  for (size_t k : {0u, 3u, 11u}) {
    whole.render(k, img);
    // The whole run is 0 .. 20 s across the plot area: frame k (t = k s) at k / 20 of its width.
    const double expected = a.x + double(k) / kRunEnd_s * a.width;
    EXPECT_NEAR(cursor_column(img, a), expected, 1.0) << "frame " << k;
  }
  // A 5 s window: from the start until the cursor reaches 80 % of it (t = 4 s), then moving with it.
  o.strip_span_s = 5;
  SceneRenderer sliding(r, o, "synthetic");
  sliding.render(2, img);
  EXPECT_NEAR(cursor_column(img, a), a.x + 2.0 / 5.0 * a.width, 1.0) << "t = 2 s in the window 0 .. 5 s";
  sliding.render(10, img);
  EXPECT_NEAR(cursor_column(img, a), a.x + 0.8 * a.width, 1.0) << "t = 10 s in the window 6 .. 11 s";
}

TEST(VideoStrip, PeakAndAverageAreDrawnAtTheRowsOfTheirLoads) {
  // A steady 500 kN of resistance with one step of 1300 kN at t = 10 s; axis 0 .. 1500 kN, a 1 s average.
  Results r = make_results(default_synthetic());
  std::vector<double>& load = r.series["ice_load"];
  for (size_t k = 0; k < load.size() / 6; ++k) load[6 * k] = k == 199 ? -1.3e6 : -5.0e5;  // step 199 ends at 10 s
  RenderOptions o = small("top");
  o.strip_max_kN = 1500.0;
  o.strip_average_window_s = 1.0;
  SceneRenderer scene(r, o, "synthetic");
  cv::Mat img;
  scene.render(3, img);  // cursor at 3 s, away from both checks
  const cv::Rect a = strip_chart_plot_area(o, o.width_px, o.height_px);
  const auto row_of = [&](double kN) { return a.y + a.height - kN / 1500.0 * a.height; };

  // The highest pixel of the load line: the 1300 kN step, at 10 / 20 of the width.
  int top_y = a.y + a.height + 1, top_x = -1;
  for (int y = a.y; y <= a.y + a.height && top_x < 0; ++y)
    for (int x = a.x; x <= a.x + a.width; ++x)
      if (same(img.at<cv::Vec3b>(y, x), kStripRawBgr)) {
        top_y = y, top_x = x;
        break;
      }
  EXPECT_NEAR(top_y, row_of(1300), 1.0);
  EXPECT_NEAR(top_x, a.x + 10.0 / kRunEnd_s * a.width, 1.5);

  // The average at t = 15 s (its 1 s window far from the spike): 500 kN.
  const int x15 = int(std::lround(a.x + 15.0 / kRunEnd_s * a.width));
  double sum = 0;
  int n = 0;
  for (int y = a.y; y <= a.y + a.height; ++y) {
    const cv::Vec3b c = img.at<cv::Vec3b>(y, x15);
    if (c[2] > 200 && c[1] > 100 && c[1] < 200 && c[0] < 80) sum += y, ++n;  // orange
  }
  ASSERT_GT(n, 0) << "no average line at t = 15 s";
  EXPECT_NEAR(sum / n, row_of(500), 1.0);
  EXPECT_EQ(LoadStripChart(r, o, "synthetic").scale().unit, "kN");
}

TEST(VideoStrip, ModelScaleLoadsAreShownInNewtons) {
  Results r = make_results(default_synthetic());
  std::vector<double>& load = r.series["ice_load"];
  for (size_t k = 0; k < load.size() / 6; ++k) load[6 * k] = -400.0;  // 400 N: a model-basin load
  const StripChartScale s = LoadStripChart(r, small("top"), "synthetic").scale();
  EXPECT_EQ(s.unit, "N");
  EXPECT_GT(s.y_hi, 400.0) << "the axis holds the load";
  EXPECT_LT(s.y_hi, 500.0) << "and fits it";
  EXPECT_EQ(s.y_lo, 0.0);
  EXPECT_EQ(s.window_s, 20.0) << "auto: no contact_model recorded means rigid, 20 s as floesim-plot";
}

TEST(VideoViews, AFloeInContactWithTheVesselShowsTheContactColourOnlyInThatFrame) {
  Synthetic syn = default_synthetic();
  syn.floes[0].contact_frames = {3};  // floe 1 (20 x 20 m at 60, 0)
  const Results r = make_results(syn);
  RenderOptions o = small("top");
  o.strip_chart = false;
  o.top_width_m = 300;
  SceneRenderer scene(r, o, "synthetic");
  cv::Mat img;
  const cv::Vec3d contact = bgr(o.contact_colour), input = bgr(o.floe_top_colour);
  scene.render(3, img);
  const cv::Vec3d in = patch(img, top_view_pixel(r, o, 3, 60, 0));
  scene.render(2, img);
  const cv::Vec3d out = patch(img, top_view_pixel(r, o, 2, 60, 0));
  // A top face, lit straight from above, keeps its colour times the per-floe shade (0.92 .. 1).
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(in[i], 0.92 * contact[i] - 2) << "frame 3, channel " << i << ": " << in;
    EXPECT_LE(in[i], contact[i] + 2) << "frame 3, channel " << i << ": " << in;
    EXPECT_GE(out[i], 0.92 * input[i] - 2) << "frame 2, channel " << i << ": " << out;
    EXPECT_LE(out[i], input[i] + 2) << "frame 2, channel " << i << ": " << out;
  }
  o.show_contact = false;
  SceneRenderer plain(r, o, "synthetic");
  plain.render(3, img);
  const cv::Vec3d off = patch(img, top_view_pixel(r, o, 3, 60, 0));
  EXPECT_GE(off[1], 0.92 * input[1] - 2) << "show_contact false: the floe keeps its own colour " << off;
  EXPECT_GE(off[2], 0.92 * input[2] - 2) << off;
}

TEST(VideoViews, LevelIceIsOneSheetNeverLitAsInContact) {
  // The same floe in contact in frame 3, flagged as a tile of level ice: it keeps the input colour at full shade
  // (the sheet's tiles share one shade), in contact or not.
  Synthetic syn = default_synthetic();
  syn.floes[0].contact_frames = {3};
  Results r = make_results(syn);
  r.floe_level_ice.assign(r.floe_id.size(), 0);
  r.floe_level_ice[0] = 1;
  ASSERT_EQ(r.floe_id[0], 1);
  RenderOptions o = small("top");
  o.strip_chart = false;
  o.top_width_m = 300;
  SceneRenderer scene(r, o, "synthetic");
  cv::Mat img;
  const cv::Vec3d input = bgr(o.floe_top_colour);
  for (size_t k : {2, 3}) {
    scene.render(k, img);
    const cv::Vec3d c = patch(img, top_view_pixel(r, o, k, 60, 0));
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(c[i], input[i], 2) << "frame " << k << ", channel " << i << ": " << c;
  }
}

TEST(VideoViews, SideViewShowsAFloeUnderTheHullBelowTheWaterlineAndTheSunlitHull) {
  // Frame 5: the vessel (box hull 50 x 12 x 8 m, centre at z = 0) at x = 10 m. A 10 x 10 m floe, 3 m thick, pushed
  // under it: centre 10 m ahead of the vessel's centre, 8 m down (z -9.5 .. -6.5 m, below the keel at -4 m).
  Synthetic syn = default_synthetic();
  SyntheticFloe under{7, square(5), 3.0, 20, 0};
  under.z = -8;
  syn.floes.push_back(under);
  const Results r = make_results(syn);
  RenderOptions o = small("side");
  o.strip_chart = false;
  const size_t k = 5;
  // Orthographic from starboard, bow to the right: x_px = W/2 + dx * W / side_width_m, y_px = waterline - z * same.
  const double ppm = o.width_px / o.side_width_m, waterline = o.side_waterline * o.height_px;
  const auto px = [&](double dx, double z) { return cv::Point2d(o.width_px / 2.0 + dx * ppm, waterline - z * ppm); };
  SceneRenderer scene(r, o, "synthetic");
  cv::Mat img;
  scene.render(k, img);
  const cv::Vec3d water = patch(img, px(-40, -8));  // beside the floe, under nothing: the water
  const cv::Vec3d floe = patch(img, px(10, -8));
  EXPECT_GT(floe[0] + floe[1] + floe[2], water[0] + water[1] + water[2] + 90) << "floe " << floe << " water " << water;
  // The floe's pixels in its column all lie below the waterline row, between the rows of its top and bottom.
  const int col = int(std::lround(px(10, 0).x));
  int first = -1, last = -1;
  for (int y = 0; y < img.rows; ++y) {
    const cv::Vec3b c = img.at<cv::Vec3b>(y, col);
    const bool lit = c[0] + c[1] + c[2] > water[0] + water[1] + water[2] + 90 && y > px(0, -4).y + 1;
    if (lit && first < 0) first = y;
    if (lit) last = y;
  }
  ASSERT_GE(first, 0);
  EXPECT_GT(first, waterline);
  EXPECT_NEAR(first, px(0, -6.5).y, 1.5);
  EXPECT_NEAR(last, px(0, -9.5).y, 1.5);

  // The hull's starboard side above water faces the camera and the sun (south-west, normal (0, -1, 0)): lit to
  // ambient 0.5 + diffuse (0.5 / sun_z) x (normal . sun) of its colour, sun = (-0.4191, -0.4989, 0.7585).
  const double light = 0.5 + 0.5 / 0.7585 * 0.4989;
  const cv::Vec3d hull = patch(img, px(0, 2)), expect = bgr(o.hull_colour) * light;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(hull[i], expect[i], 3.0) << "channel " << i << ": " << hull;
  // Under water the same side is seen through the water: darker, towards the water's colour.
  const cv::Vec3d below = patch(img, px(0, -2));
  EXPECT_LT(below[2], hull[2] - 30) << below;
}

TEST(VideoViews, SplitFramesShowBothViewsInTheirHalves) {
  const Results r = make_results(default_synthetic());
  const cv::Vec3d sky = bgr("#c5d0da"), deck = bgr("#9aa1a6");
  for (const std::string layout : {"side_by_side", "stacked"}) {
    RenderOptions o = small("split");
    o.strip_chart = false;
    o.split_layout = layout;  // chase first, top second
    SceneRenderer scene(r, o, "synthetic");
    cv::Mat img;
    scene.render(4, img);
    // The chase half has sky along its top; the top half has the vessel's deck (lit from straight above: its own
    // colour) at its centre, where the vessel is.
    const bool sbs = layout == "side_by_side";
    const cv::Point2d chase_sky = sbs ? cv::Point2d(160, 4) : cv::Point2d(320, 4);
    const cv::Point2d top_centre = sbs ? cv::Point2d(480, 180) : cv::Point2d(320, 270);
    const cv::Vec3d s = patch(img, chase_sky), d = patch(img, top_centre);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(s[i], sky[i], 8.0) << layout << " sky " << s;
      EXPECT_NEAR(d[i], deck[i], 8.0) << layout << " deck " << d;
    }
    // The top half shows the sky nowhere: it looks straight down.
    const cv::Rect top_half = sbs ? cv::Rect(320, 0, 320, 360) : cv::Rect(0, 180, 640, 180);
    int sky_px = 0;
    for (int y = top_half.y + 4; y < top_half.y + top_half.height; ++y)
      for (int x = top_half.x + 4; x < top_half.x + top_half.width; ++x) {
        const cv::Vec3b c = img.at<cv::Vec3b>(y, x);
        sky_px += std::abs(c[0] - sky[0]) < 3 && std::abs(c[1] - sky[1]) < 3 && std::abs(c[2] - sky[2]) < 3;
      }
    EXPECT_EQ(sky_px, 0) << layout;
  }
}

TEST(VideoViews, BadViewOptionsNameTheKey) {
  const fs::path dir = fresh_dir("bad_views");
  const auto cfg = [&](const nlohmann::json& j) {
    const fs::path p = dir / "render.json";
    std::ofstream(p) << j.dump();
    return p;
  };
  const std::vector<std::pair<nlohmann::json, std::string>> bad = {
      {{{"view", "sideways"}}, "view"},
      {{{"view", "split"}, {"split_views", {"chase", "bottom"}}}, "split_views"},
      {{{"split_views", {"chase"}}}, "split_views"},
      {{{"split_views", "chase"}}, "split_views"},
      {{{"split_layout", "diagonal"}}, "split_layout"},
      {{{"strip_max_kN", -1}}, "strip_max_kN"},
      {{{"strip_average_window_s", "long"}}, "strip_average_window_s"},
      {{{"strip_span_s", -5}}, "strip_span_s"},
      {{{"side_waterline", 1.5}}, "side_waterline"},
      {{{"contact_colour", "green"}}, "contact_colour"},
  };
  for (const auto& item : bad) {
    // Plain references, not a structured binding: C++17 lets no lambda capture a binding (clang refuses it).
    const nlohmann::json& j = item.first;
    const std::string& key = item.second;
    const std::string e = error_of([&] { read_render_options(cfg(j)); });
    EXPECT_NE(e.find(key), std::string::npos) << j.dump() << ": " << e;
    EXPECT_NE(e.find("render.json"), std::string::npos) << e;
  }
  EXPECT_EQ(read_render_options(cfg({{"view", "split"}, {"split_views", {"side", "top"}}})).split_views,
            (std::vector<std::string>{"side", "top"}));
  fs::remove_all(dir);
}
