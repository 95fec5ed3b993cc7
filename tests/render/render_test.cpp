#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "pipeline/error.h"
#include "pipeline/provenance.h"
#include "pipeline/results_io.h"
#include "render/scene.h"
#include "render/video.h"
#include "synthetic_results.h"
#include "tests/test_util.h"

using namespace floesim;
using namespace floesim::render;
using namespace floesim::render::testing;
namespace fs = std::filesystem;
using floesim::tests::read_text;

namespace {

RenderOptions small_top_view() {
  RenderOptions o;
  o.width_px = 320;
  o.height_px = 180;
  o.view = "top";
  o.top_width_m = 200;  // 1.6 px/m
  o.overlay = false;    // pixel checks below must not hit the text panel
  o.strip_chart = false;  // nor the load strip chart at the bottom (tests/render/video_views_test.cpp)
  return o;
}

fs::path write_json(const fs::path& p, const nlohmann::json& j) {
  std::ofstream(p) << j.dump(2);
  return p;
}

// Mean BGR over a 5 x 5 patch (robust to the encoder's chroma subsampling and edges).
cv::Vec3d patch(const cv::Mat& img, cv::Point2d c) {
  const cv::Rect r(int(std::lround(c.x)) - 2, int(std::lround(c.y)) - 2, 5, 5);
  const cv::Scalar m = cv::mean(img(r & cv::Rect(0, 0, img.cols, img.rows)));
  return {m[0], m[1], m[2]};
}
bool bright(const cv::Vec3d& c) { return c[0] > 170 && c[1] > 170 && c[2] > 170; }
bool dark(const cv::Vec3d& c) { return c[0] < 90 && c[1] < 90 && c[2] < 90; }

}  // namespace

TEST(Render, TopViewShowsFloesWhereTheyAreAndWaterElsewhere) {
  const Results r = make_results(default_synthetic());
  const RenderOptions o = small_top_view();
  SceneRenderer scene(r, o, "synthetic");
  cv::Mat img;
  scene.render(0, img);
  ASSERT_EQ(img.cols, 320);
  ASSERT_EQ(img.rows, 180);
  ASSERT_EQ(img.type(), CV_8UC3);
  const auto px = [&](double x, double y) { return top_view_pixel(r, o, 0, x, y); };
  EXPECT_TRUE(bright(patch(img, px(60, 0)))) << "floe 1 centre: " << patch(img, px(60, 0));
  EXPECT_TRUE(bright(patch(img, px(60, 40)))) << "floe 2 centre: " << patch(img, px(60, 40));
  EXPECT_TRUE(dark(patch(img, px(30, -40)))) << "open water: " << patch(img, px(30, -40));
  EXPECT_TRUE(dark(patch(img, px(80, 20)))) << "water between floes: " << patch(img, px(80, 20));
  // The U-shaped floe (non-convex, at 100, -45): ice in its arms, water in its notch (a triangle fan would fill it).
  EXPECT_TRUE(bright(patch(img, px(100 - 10, -45)))) << "left arm: " << patch(img, px(90, -45));
  EXPECT_TRUE(bright(patch(img, px(100, -45 - 10)))) << "base: " << patch(img, px(100, -55));
  EXPECT_TRUE(dark(patch(img, px(100, -45 + 7)))) << "notch: " << patch(img, px(100, -38));
  // The hull (deck, grey) at the centre: neither water nor ice.
  const cv::Vec3d deck = patch(img, px(0, 0));
  EXPECT_FALSE(dark(deck)) << deck;
  EXPECT_FALSE(bright(deck)) << deck;
  EXPECT_EQ(scene.last_stats().floes_drawn + scene.last_stats().floes_culled, 5u);
  EXPECT_EQ(scene.last_stats().floes_culled, 1u) << "the floe at x = 150 m lies outside the 200 m wide view";
}

TEST(Render, PiecesOfBrokenFloesShowTheTintOfTheirFractureAndTheBrokenFloeIsGone) {
  const Results r = make_results(fractured_synthetic());
  const RenderOptions o = small_top_view();
  SceneRenderer scene(r, o, "synthetic");
  cv::Mat before, after;
  scene.render(1, before);  // t = 1 s: floe 1 whole
  scene.render(3, after);   // t = 3 s: split at t = 2 s into pieces 2 (centre 60, -8) and 3 (60, 8)
  const cv::Vec3d was = patch(before, top_view_pixel(r, o, 1, 60, -8));
  const cv::Vec3d piece = patch(after, top_view_pixel(r, o, 3, 60, -8));
  // BGR. Before: the near-white input floe, red and blue alike. After: amber, red well above blue.
  EXPECT_TRUE(bright(was)) << was;
  EXPECT_LT(std::abs(was[2] - was[0]), 20.0) << "an input floe is not tinted: " << was;
  EXPECT_GT(piece[2], piece[0] + 60) << "a splitting piece is amber: " << piece;
  EXPECT_GT(piece[2], 170.0) << piece;
  const cv::Vec3d north = patch(after, top_view_pixel(r, o, 3, 60, 8));
  EXPECT_GT(north[2], north[0] + 60) << "piece 3: " << north;
  // The crack between the pieces: floe 1 is no longer drawn, water shows.
  EXPECT_TRUE(bright(patch(before, top_view_pixel(r, o, 1, 60, 0))));
  EXPECT_TRUE(dark(patch(after, top_view_pixel(r, o, 3, 60, 0)))) << patch(after, top_view_pixel(r, o, 3, 60, 0));

  // Bending (piece 4 of piece 3, generation 2, from t = 6 s) and radial (piece 6 of floe 5, from t = 9 s): blue.
  cv::Mat img;
  scene.render(7, img);
  const cv::Vec3d wedge = patch(img, top_view_pixel(r, o, 7, 60, 8));
  EXPECT_GT(wedge[0], wedge[2] + 30) << "a bending piece is light blue: " << wedge;
  scene.render(10, img);
  const cv::Vec3d radial = patch(img, top_view_pixel(r, o, 10, -40, -50));
  EXPECT_GT(radial[0], radial[2] + 30) << "a radial piece is light blue: " << radial;
  EXPECT_EQ(scene.last_stats().floes_drawn + scene.last_stats().floes_culled, 3u) << "pieces 2, 4 and 6 at t = 10 s";
}

TEST(Render, PieceColoursFollowTheModeAndDarkenPerGenerationUpToALimit) {
  const RenderOptions o;
  float input[3], top[3], bend[3], radial[3], split1[3], split2[3], split4[3], split9[3], amber[3];
  floe_top_colour(o, kFractureNone, 0, input);
  parse_hex_colour(o.floe_top_colour, top);
  parse_hex_colour(o.splitting_piece_colour, amber);
  floe_top_colour(o, kFractureBending, 1, bend);
  floe_top_colour(o, kFractureRadial, 1, radial);
  floe_top_colour(o, kFractureSplitting, 1, split1);
  floe_top_colour(o, kFractureSplitting, 2, split2);
  floe_top_colour(o, kFractureSplitting, 4, split4);
  floe_top_colour(o, kFractureSplitting, 9, split9);
  for (int i = 0; i < 3; ++i) {
    EXPECT_FLOAT_EQ(input[i], top[i]) << "input floes keep floe_top_colour";
    EXPECT_FLOAT_EQ(bend[i], radial[i]) << "bending and radial pieces share a colour";
    EXPECT_FLOAT_EQ(split1[i], amber[i]);
    EXPECT_LT(split2[i], split1[i]) << "a piece of a piece is darker than its parent";
    EXPECT_FLOAT_EQ(split9[i], split4[i]) << "darkening stops at generation 4";
    EXPECT_GT(split4[i], 0.4f * split1[i]) << "never near the water's colour";
  }
  EXPECT_GT(bend[2], bend[0]) << "bending pieces are bluish";
  EXPECT_GT(split1[0], split1[2]) << "splitting pieces are amber";
}

TEST(Render, ChaseViewShowsSkyWaterIceAndTheRedHull) {
  const Results r = make_results(default_synthetic());
  RenderOptions o;
  o.width_px = 320;
  o.height_px = 180;
  o.supersample = 1;
  SceneRenderer scene(r, o, "synthetic");
  cv::Mat img;
  scene.render(3, img);
  cv::Scalar mean, sd;
  cv::meanStdDev(img, mean, sd);
  EXPECT_GT(sd[0] + sd[1] + sd[2], 40.0) << "frame is uniform (black?)";
  size_t red = 0, ice = 0, water = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b c = img.at<cv::Vec3b>(y, x);  // BGR
      if (c[2] > c[1] + 50 && c[2] > c[0] + 50) ++red;
      if (c[0] > 200 && c[1] > 200 && c[2] > 200) ++ice;
      if (c[0] < 80 && c[1] < 80 && c[2] < 80) ++water;
    }
  EXPECT_GT(red, 30u) << "the hull is not visible";
  EXPECT_GT(ice, 100u) << "no floe is visible";
  EXPECT_GT(water, 1000u) << "no water is visible";
}

TEST(Render, VideoHasOneFramePerResultsFrameAndShowsTheScene) {
  const fs::path dir = fresh_dir("video");
  const Results r = make_results(default_synthetic());
  write_results(dir / "results.h5", r);
  RenderOptions o = small_top_view();
  const auto cfg = write_json(dir / "render.json", options_to_json(o));
  const RenderStats st = render_video(dir / "results.h5", cfg, dir / "out" / "transit.mp4");
  EXPECT_EQ(st.frames, 12u);

  cv::VideoCapture cap((dir / "out" / "transit.mp4").string(), cv::CAP_FFMPEG);
  ASSERT_TRUE(cap.isOpened());
  EXPECT_EQ(cap.get(cv::CAP_PROP_FRAME_WIDTH), 320);
  EXPECT_EQ(cap.get(cv::CAP_PROP_FRAME_HEIGHT), 180);
  EXPECT_EQ(cap.get(cv::CAP_PROP_FRAME_COUNT), 12);
  std::vector<cv::Mat> frames;
  for (cv::Mat f; cap.read(f);) frames.push_back(f.clone());
  ASSERT_EQ(frames.size(), r.frames()) << "one video frame per results frame";

  // Floe 1 (x = 60 m) is under its expected pixel in the first and the last frame although the camera moved
  // with the vessel (22 m in 11 s); water is where no floe is.
  for (size_t k : {size_t(0), frames.size() - 1}) {
    EXPECT_TRUE(bright(patch(frames[k], top_view_pixel(r, o, k, 60, 0)))) << "frame " << k;
    EXPECT_TRUE(dark(patch(frames[k], top_view_pixel(r, o, k, 30, -40)))) << "frame " << k;
  }
  // The vessel moved, so the picture did.
  cv::Mat diff;
  cv::absdiff(frames.front(), frames.back(), diff);
  EXPECT_GT(cv::mean(diff)[0] + cv::mean(diff)[1] + cv::mean(diff)[2], 5.0);
  cv::absdiff(frames[0], frames[1], diff);
  EXPECT_GT(cv::norm(diff, cv::NORM_L1), 0.0) << "consecutive frames are identical although the vessel moves";

  const auto side = nlohmann::json::parse(read_text(dir / "out" / "transit.json"));
  EXPECT_EQ(side["frames"], 12);
  EXPECT_TRUE(side["warnings"].empty());
  EXPECT_EQ(side["provenance"]["program"], "floesim-render");
  EXPECT_EQ(listing(dir / "out"), (std::vector<std::string>{"transit.json", "transit.mp4"}));
  fs::remove_all(dir);
}

TEST(Render, MaxFramesLimitsTheVideoAndStillFrameWritesAnImage) {
  const fs::path dir = fresh_dir("maxframes");
  write_results(dir / "results.h5", make_results(default_synthetic()));
  const auto cfg = write_json(dir / "render.json", {{"width_px", 160}, {"height_px", 90}, {"max_frames", 5}});
  EXPECT_EQ(render_video(dir / "results.h5", cfg, dir / "v.mp4").frames, 5u);
  cv::VideoCapture cap((dir / "v.mp4").string(), cv::CAP_FFMPEG);
  int n = 0;
  for (cv::Mat f; cap.read(f);) ++n;
  EXPECT_EQ(n, 5);
  // The sidecar warns that the video stops short (the report lists it with the stages' warnings); a whole run's
  // video (the test above) has none.
  const auto side = nlohmann::json::parse(read_text(dir / "v.json"));
  ASSERT_EQ(side["warnings"].size(), 1u) << side.dump();
  const std::string w = side["warnings"][0];
  EXPECT_EQ(w.rfind("the video shows the first 5 of the run's 12 frames (render.max_frames)", 0), 0u) << w;

  render_still(dir / "results.h5", cfg, 7, dir / "still.png");
  const cv::Mat still = cv::imread((dir / "still.png").string());
  ASSERT_FALSE(still.empty());
  EXPECT_EQ(still.size(), cv::Size(160, 90));
  EXPECT_THROW(render_still(dir / "results.h5", cfg, 12, dir / "bad.png"), Error);
  EXPECT_FALSE(fs::exists(dir / "bad.png"));
  fs::remove_all(dir);
}

TEST(Render, SameInputsGiveByteIdenticalVideos) {
  const fs::path dir = fresh_dir("determinism");
  write_results(dir / "results.h5", make_results(default_synthetic()));
  const auto cfg = write_json(dir / "render.json", {{"width_px", 320}, {"height_px", 180}});
  render_video(dir / "results.h5", cfg, dir / "a" / "v.mp4");
  render_video(dir / "results.h5", cfg, dir / "b" / "v.mp4");
  EXPECT_EQ(sha256_file(dir / "a" / "v.mp4"), sha256_file(dir / "b" / "v.mp4"));
  EXPECT_EQ(sha256_file(dir / "a" / "v.json"), sha256_file(dir / "b" / "v.json"));
  fs::remove_all(dir);
}

TEST(Render, BadInputNamesTheFileOrKeyAndLeavesNothing) {
  const fs::path dir = fresh_dir("bad");
  write_results(dir / "results.h5", make_results(default_synthetic()));
  std::ofstream(dir / "not_hdf5.h5") << "this is not an HDF5 file\n";
  const auto good = write_json(dir / "good.json", {{"width_px", 160}, {"height_px", 90}});
  const fs::path out = dir / "out";  // must not even be created by a failed run
  auto expect_error = [&](const fs::path& results, const fs::path& cfg, const fs::path& video,
                          const std::vector<std::string>& needles) {
    try {
      render_video(results, cfg, video);
      ADD_FAILURE() << "no error; expected one mentioning " << needles.front();
    } catch (const Error& e) {
      for (const auto& n : needles) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(out)) << "a failed run left output behind";
  };
  expect_error(dir / "missing.h5", good, out / "v.mp4", {"missing.h5"});
  expect_error(dir / "not_hdf5.h5", good, out / "v.mp4", {"not_hdf5.h5", "HDF5"});
  expect_error(dir / "results.h5", write_json(dir / "typo.json", {{"widht_px", 640}}), out / "v.mp4",
               {"typo.json", "widht_px"});
  expect_error(dir / "results.h5", write_json(dir / "fps.json", {{"fps", 0}}), out / "v.mp4", {"fps.json", "fps"});
  expect_error(dir / "results.h5", write_json(dir / "odd.json", {{"width_px", 321}}), out / "v.mp4",
               {"width_px", "even"});
  expect_error(dir / "results.h5", good, out / "v.avi", {"v.avi", ".mp4"});
  expect_error(dir / "results.h5", dir / "no_config.json", out / "v.mp4", {"no_config.json"});
  fs::remove_all(dir);
}

TEST(Render, InconsistentResultsAreRefusedWithTheBodyNamed) {
  Results r = make_results(default_synthetic());
  r.state_body_id[3] = 99;  // a floe with no geometry
  try {
    SceneRenderer scene(r, small_top_view(), "runs/x/results.h5");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("99"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("runs/x/results.h5"), std::string::npos) << e.what();
  }
}

TEST(Render, FacesSharedByTwoHullPartsAreFoundAndOuterFacesKept) {
  // Two unit cubes side by side, x in [-1, 0] and [0, 1]; each closes its face at x = 0, triangulated along
  // different diagonals (as convex parts written independently are).
  std::vector<double> v;
  std::vector<int32_t> t;
  auto cube = [&](double x0, bool other_diagonal) {
    const int32_t b = static_cast<int32_t>(v.size() / 3);
    for (int i = 0; i < 8; ++i) v.insert(v.end(), {x0 + (i & 1), double((i >> 1) & 1), double((i >> 2) & 1)});
    // Corner index = x + 2y + 4z. Faces as two triangles each; the x = x0 + 0/1 faces may use either diagonal.
    const int32_t faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (int f = 0; f < 6; ++f) {
      const auto& q = faces[f];
      if (other_diagonal && f < 2)
        t.insert(t.end(), {b + q[0], b + q[1], b + q[3], b + q[1], b + q[2], b + q[3]});
      else
        t.insert(t.end(), {b + q[0], b + q[1], b + q[2], b + q[0], b + q[2], b + q[3]});
    }
  };
  cube(-1, false);
  cube(0, true);
  const std::vector<bool> internal = hull_internal_faces(v, t);
  ASSERT_EQ(internal.size(), 24u);
  // Internal: cube A's x = +max face (face 1, triangles 2, 3) and cube B's x = min face (face 0, triangles 12, 13).
  for (size_t k = 0; k < 24; ++k) {
    const bool expected = k == 2 || k == 3 || k == 12 || k == 13;
    EXPECT_EQ(internal[k], expected) << "triangle " << k;
  }
}
