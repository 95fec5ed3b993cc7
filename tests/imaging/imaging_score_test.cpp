// Scoring (imaging/score.h) on hand-made label/mask pairs whose every number is worked out by hand below, the
// file-level entry points (floesim-score's run_score, digitise --truth-mask), and the close-range settings on one
// labelled passerotti image.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "imaging/digitise.h"
#include "imaging/score.h"
#include "imaging/shapes.h"
#include "pipeline/options.h"
#include "test_util.h"

namespace floesim::imaging {
namespace {

// 100 x 100 px at 0.1 m/px (1 m^2 = 100 px); no data in columns 90-99 of rows 0-29 (300 px).
constexpr double kS = 0.1;

cv::Mat rect_fill(cv::Mat m, int r0, int r1, int c0, int c1, int value) {
  m(cv::Range(r0, r1 + 1), cv::Range(c0, c1 + 1)).setTo(value);
  return m;
}

struct Case {
  cv::Mat mask, pred, valid;
};

Case known_case() {
  Case k;
  k.valid = cv::Mat(100, 100, CV_8U, cv::Scalar(255));
  k.valid(cv::Range(0, 30), cv::Range(90, 100)).setTo(0);
  k.mask = cv::Mat(100, 100, CV_8U, cv::Scalar(0));
  rect_fill(k.mask, 10, 29, 10, 19, 255);  // A 200 px, 2 m^2
  rect_fill(k.mask, 10, 29, 21, 30, 255);  // B 200 px, 2 m^2 (one column of water from A)
  rect_fill(k.mask, 50, 79, 50, 79, 255);  // C 900 px, 9 m^2
  rect_fill(k.mask, 60, 64, 10, 14, 255);  // D 25 px, 0.25 m^2: under 1 m^2, out of the matching
  rect_fill(k.mask, 80, 89, 0, 9, 255);    // E touches the image border: dropped
  rect_fill(k.mask, 5, 14, 80, 89, 255);   // F touches the no-data area dilated by 1 px (column 89): dropped
  rect_fill(k.mask, 16, 25, 78, 87, 255);  // G two columns clear of the no-data area: kept
  k.pred = cv::Mat(100, 100, CV_16U, cv::Scalar(0));
  rect_fill(k.pred, 10, 29, 10, 30, 1);  // A, the gap and B merged: 420 px, IoU 200/420 with each, no match
  rect_fill(k.pred, 50, 79, 53, 82, 2);  // C shifted 3 px: IoU 810/990
  rect_fill(k.pred, 10, 19, 60, 69, 3);  // 1 m^2 on open water
  rect_fill(k.pred, 80, 89, 0, 9, 4);    // = E, dropped
  rect_fill(k.pred, 5, 14, 80, 89, 5);   // = F, dropped
  rect_fill(k.pred, 16, 25, 78, 87, 6);  // = G, IoU 1
  rect_fill(k.pred, 60, 64, 10, 14, 7);  // = D, small
  return k;
}

TEST(Score, HandMadePairWithEveryProtocolStep) {
  const Case k = known_case();
  const ScoreResult r = score_against_mask(k.pred, k.mask, kS, k.valid, ScoreOptions::labelled_mask());
  EXPECT_EQ(r.truth, 4);      // A, B, C, G
  EXPECT_EQ(r.predicted, 4);  // 1, 2, 3, 6
  EXPECT_EQ(r.matched, 2);    // (2, C) and (6, G)
  EXPECT_EQ(r.truth_dropped_edge, 2);
  EXPECT_EQ(r.predicted_dropped_edge, 2);
  EXPECT_EQ(r.truth_small, 1);
  EXPECT_EQ(r.predicted_small, 1);
  EXPECT_DOUBLE_EQ(r.precision, 0.5);
  EXPECT_DOUBLE_EQ(r.recall, 0.5);
  EXPECT_DOUBLE_EQ(r.f1, 0.5);
  EXPECT_DOUBLE_EQ(r.mean_iou, (1.0 + 810.0 / 990.0) / 2);
  // Kept ice (all sizes): truth A+B+C+D+G = 1425 px, predicted 420+900+100+100+25 = 1545 px, both 400+810+100+25
  // = 1335 px; valid area 10000 - 300 = 9700 px.
  EXPECT_DOUBLE_EQ(r.pixel_iou, 1335.0 / (1425.0 + 1545.0 - 1335.0));
  EXPECT_DOUBLE_EQ(r.concentration_truth, 1425.0 / 9700.0);
  EXPECT_DOUBLE_EQ(r.concentration_predicted, 1545.0 / 9700.0);
  EXPECT_DOUBLE_EQ(r.concentration_error, 1545.0 / 9700.0 - 1425.0 / 9700.0);
  // Areas in the matching: predicted {4.2, 9, 1, 1}, truth {2, 2, 9, 1} m^2: the empirical CDFs differ most at
  // 1 m^2 (2/4 against 1/4) and at 2 m^2 (2/4 against 3/4).
  EXPECT_DOUBLE_EQ(r.ks_log_area, 0.25);
  ASSERT_EQ(r.matches.size(), 2u);
  EXPECT_EQ(r.matches[0], std::make_pair(6, 4));  // best IoU first; G is the 4th component in raster order (F, A, B, G)
}

TEST(Score, ProtocolSwitches) {
  const Case k = known_case();
  // Keeping edge floes: E and F match their predictions exactly, so 4 of 6 on each side.
  ScoreOptions keep = ScoreOptions::labelled_mask();
  keep.drop_edge_floes = false;
  const ScoreResult r = score_against_mask(k.pred, k.mask, kS, k.valid, keep);
  EXPECT_EQ(r.truth, 6);
  EXPECT_EQ(r.matched, 4);
  EXPECT_DOUBLE_EQ(r.f1, 4.0 / 6.0);
  // No area threshold: D and prediction 7 match too.
  ScoreOptions all = keep;
  all.min_area_m2 = 0;
  EXPECT_EQ(score_against_mask(k.pred, k.mask, kS, k.valid, all).matched, 5);
  // A stricter IoU: the shifted C (0.818) no longer matches.
  ScoreOptions strict = ScoreOptions::labelled_mask();
  strict.min_iou = 0.9;
  EXPECT_EQ(score_against_mask(k.pred, k.mask, kS, k.valid, strict).matched, 1);
}

TEST(Score, MaskFloesAreEightConnectedComponents) {
  cv::Mat mask(20, 20, CV_8U, cv::Scalar(0));
  rect_fill(mask, 2, 5, 2, 5, 255);
  rect_fill(mask, 6, 9, 6, 9, 255);    // touches the first only at a corner: the same floe
  rect_fill(mask, 2, 5, 12, 15, 255);  // separate
  cv::Mat comp = mask_components(mask);
  double hi = 0;
  cv::minMaxLoc(comp, nullptr, &hi);
  EXPECT_EQ(hi, 2);
  EXPECT_EQ(comp.at<int>(3, 3), comp.at<int>(7, 7));
  // As a prediction, the same two floes as two labels score perfectly against the mask.
  cv::Mat pred(20, 20, CV_32S, cv::Scalar(0));
  pred.setTo(1, comp == 1);
  pred.setTo(2, comp == 2);
  ScoreOptions o;  // plain: no edge or area rule
  const ScoreResult r = score_against_mask(pred, mask, 1.0, cv::Mat(), o);
  EXPECT_DOUBLE_EQ(r.f1, 1.0);
  EXPECT_DOUBLE_EQ(r.pixel_iou, 1.0);
  EXPECT_DOUBLE_EQ(r.ks_log_area, 0.0);
  // Split along the diagonal contact: two predictions for one truth floe, each with IoU 16/32 = 0.5 exactly,
  // which is a match (>= 0.5) for one of them only.
  cv::Mat split = pred.clone();
  split(cv::Range(6, 10), cv::Range(6, 10)).setTo(3);
  const ScoreResult s = score_against_mask(split, mask, 1.0, cv::Mat(), o);
  EXPECT_EQ(s.predicted, 3);
  EXPECT_EQ(s.matched, 2);
}

TEST(Score, KolmogorovSmirnovDistance) {
  EXPECT_DOUBLE_EQ(ks_distance({1, 2, 3}, {3, 2, 1}), 0.0);
  EXPECT_DOUBLE_EQ(ks_distance({1, 2}, {3, 4}), 1.0);
  EXPECT_DOUBLE_EQ(ks_distance({1, 2, 3}, {2, 3, 4}), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(ks_distance({1, 1, 1, 5}, {1, 5}), 0.25);  // ties jump together
  EXPECT_DOUBLE_EQ(ks_distance({}, {}), 0.0);
  EXPECT_DOUBLE_EQ(ks_distance({1.0}, {}), 1.0);
}

TEST(Score, EmptySides) {
  const cv::Mat none(30, 30, CV_32S, cv::Scalar(0));
  cv::Mat one = none.clone();
  rect_fill(one, 10, 19, 10, 19, 1);
  const ScoreResult both_empty = score_labels(none, none, 1.0);
  EXPECT_DOUBLE_EQ(both_empty.f1, 1.0);
  EXPECT_DOUBLE_EQ(both_empty.pixel_iou, 1.0);
  EXPECT_DOUBLE_EQ(both_empty.ks_log_area, 0.0);
  const ScoreResult missed = score_labels(none, one, 1.0);
  EXPECT_DOUBLE_EQ(missed.f1, 0.0);
  EXPECT_DOUBLE_EQ(missed.recall, 0.0);
  EXPECT_DOUBLE_EQ(missed.ks_log_area, 1.0);
  EXPECT_DOUBLE_EQ(missed.concentration_error, -100.0 / 900.0);
  const ScoreResult invented = score_labels(one, none, 1.0);
  EXPECT_DOUBLE_EQ(invented.precision, 0.0);
  EXPECT_DOUBLE_EQ(invented.f1, 0.0);
}

TEST(Score, RunScoreReadsFilesAndWritesJson) {
  test::ScratchDir d;
  const Case k = known_case();
  cv::Mat photo(100, 100, CV_8U, cv::Scalar(60));
  photo.setTo(0, k.valid == 0);
  ASSERT_TRUE(cv::imwrite((d.path / "labels.png").string(), k.pred));
  ASSERT_TRUE(cv::imwrite((d.path / "mask.png").string(), k.mask));
  ASSERT_TRUE(cv::imwrite((d.path / "photo.png").string(), photo));
  ScoreRequest req;
  req.labels = d.path / "labels.png";
  req.truth = d.path / "mask.png";
  req.photo = d.path / "photo.png";
  req.metres_per_pixel = kS;
  req.out = d.path / "out" / "score.json";
  const ScoreResult r = run_score(req);
  EXPECT_DOUBLE_EQ(r.f1, 0.5);
  const Json j = load_json_file(req.out);
  EXPECT_DOUBLE_EQ(j["f1"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["ks_log_area"].get<double>(), 0.25);
  EXPECT_EQ(j["protocol"]["min_area_m2"].get<double>(), 1.0);
  EXPECT_EQ(j["provenance"]["program"], "floesim-score");
  // An 8-bit prediction is a mask too: the truth against itself is perfect.
  req.labels = d.path / "mask.png";
  req.out.clear();
  EXPECT_DOUBLE_EQ(run_score(req).f1, 1.0);
  // A truth on another grid is refused with the sizes.
  cv::Mat small(50, 50, CV_8U, cv::Scalar(0));
  ASSERT_TRUE(cv::imwrite((d.path / "small.png").string(), small));
  req.truth = d.path / "small.png";
  try {
    run_score(req);
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("50 x 50"), std::string::npos) << e.what();
  }
  req.truth = d.path / "missing.png";
  EXPECT_THROW(run_score(req), Error);
}

TEST(Score, DigitiseWritesScoreAgainstAMask) {
  // Three bright floes on dark water, one of them on the border; the mask is the floes themselves.
  test::ScratchDir d;
  cv::Mat img(120, 160, CV_8U, cv::Scalar(40)), mask(120, 160, CV_8U, cv::Scalar(0));
  for (const cv::Rect& r : {cv::Rect(20, 20, 40, 30), cv::Rect(90, 60, 40, 40), cv::Rect(0, 90, 20, 20)}) {
    img(r).setTo(210);
    mask(r).setTo(255);
  }
  ASSERT_TRUE(cv::imwrite((d.path / "img.png").string(), img));
  ASSERT_TRUE(cv::imwrite((d.path / "mask.png").string(), mask));
  DigitiseRequest req;
  req.image = d.path / "img.png";
  req.metres_per_pixel = 0.1;
  req.out_dir = d.path / "out";
  req.config = {{"min_floe_area_m2", 1.0}, {"brash_cutoff_m2", 1.0}, {"simplify_tolerance_m", 0.05}};
  req.truth_mask = d.path / "mask.png";
  const DigitiseResult res = run_digitise(req);
  ASSERT_TRUE(res.score.has_value());
  EXPECT_EQ(res.score->truth, 2);  // the border floe is dropped
  EXPECT_EQ(res.score->matched, 2);
  EXPECT_GT(res.score->mean_iou, 0.9);
  const Json j = load_json_file(d.path / "out" / "score.json");
  EXPECT_EQ(j["matched"].get<int>(), 2);
  EXPECT_TRUE(j["protocol"]["drop_edge_floes"].get<bool>());
  // Both truths at once are refused before anything is written.
  req.truth = d.path / "t.geojson";
  req.out_dir = d.path / "out2";
  EXPECT_THROW(run_digitise(req), Error);
  EXPECT_TRUE(test::list_dir(d.path / "out2").empty());
}

TEST(Score, CloseRangeSettingsOnOneLabelledImage) {
  // The settings file of the benchmark on the quickest labelled image (sparse floes, 0.05 m/px). The benchmark
  // (imaging/bench/digitise_bench) runs all 12; this guards the file and the method against regressions:
  // measured F1 0.96, |concentration error| 0.05, KS 0.13.
  const auto image = test::shared_data("passerotti/images/2022-07-24_111713_ortho.png");
  const auto mask = test::shared_data("passerotti/masks/2022-07-24_111713_mask.png");
  test::ScratchDir d;
  DigitiseRequest req;
  req.image = image;
  req.metres_per_pixel = 0.05;
  req.out_dir = d.path;
  req.config_file = std::filesystem::path(FLOESIM_SOURCE_DIR) / "imaging/settings/close_range.json";
  req.config = load_json_file(req.config_file);
  req.truth_mask = mask;
  const DigitiseResult res = run_digitise(req);
  ASSERT_TRUE(res.score.has_value());
  EXPECT_GE(res.score->f1, 0.9);
  EXPECT_LT(std::abs(res.score->concentration_error), 0.08);
  EXPECT_LT(res.score->ks_log_area, 0.25);
  EXPECT_EQ(res.polygons.overlaps_remaining, 0);
  // The written outlines read back (simple, CCW: the strict reader checks) and no two of them overlap or touch.
  const FloeField floes = read_floes(d.path / "floes.geojson");
  ASSERT_GT(floes.floes.size(), 100u);
  std::vector<BBox> boxes;
  for (const Floe& f : floes.floes) {
    EXPECT_GT(signed_area(f.outline), 0);
    boxes.push_back(bounding_box(f.outline));
  }
  int overlapping = 0;
  for (size_t i = 0; i < boxes.size(); ++i)
    for (size_t j = i + 1; j < boxes.size(); ++j)
      if (boxes[i].overlaps(boxes[j]) && polygons_within(floes.floes[i].outline, floes.floes[j].outline, 0))
        ++overlapping;
  EXPECT_EQ(overlapping, 0);
}

}  // namespace
}  // namespace floesim::imaging
