// Scoring a segmentation (a label image) against a reference: the synthetic truth polygons, or a hand-labelled
// floe mask (the passerotti protocol of issue #3).
//
// The protocol, in order (ScoreOptions; score_labels does the work, the other entry points only build the truth
// label image):
//   1. Truth floes: the ids of a truth label image; a binary mask's floes are its 8-connected components
//      (mask_components). Predicted floes: the ids of the label image (0 = no floe).
//   2. Edge floes (drop_edge_floes): a floe with a pixel on the image border or in the no-data area dilated by
//      1 px (pure-black pixels of the photograph and their 8 neighbours) is dropped from its side, predicted and
//      truth alike: the labellers dropped the floes the camera footprint cuts, so neither side is judged there.
//      Dropped floes count as water everywhere below.
//   3. Small floes: floes under min_area_m2 (pixel area) are left out of the matching and of the size
//      distributions, on both sides; they still count as ice in the pixel measures.
//   4. Matching: one-to-one, greedy by decreasing IoU (ties: lower predicted id, then lower truth id), a match
//      needs IoU >= min_iou. precision = matched / predicted, recall = matched / truth, F1 their harmonic mean,
//      mean IoU over the matches.
//   5. Pixel measures inside the valid area (non-black pixels): pixel IoU of ice (any kept floe) against water,
//      concentration = ice pixels / valid pixels on each side, concentration error = predicted - truth.
//   6. Size distributions: the two-sample Kolmogorov-Smirnov distance sup |F_pred - F_truth| between the
//      empirical distributions of log(area) of the floes that enter the matching (the logarithm is monotone, so
//      this is also the KS distance of the areas themselves).
// Degenerate cases: nothing to find and nothing found scores precision = recall = F1 = 1, pixel IoU 1 and KS 0;
// floes on exactly one side give F1 0 and KS 1.
#pragma once
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <vector>

#include "pipeline/floes_io.h"

namespace floesim::imaging {

struct ScoreOptions {
  double min_iou = 0.5;          // a matched pair needs at least this IoU (0.5 makes greedy matching unique)
  double min_area_m2 = 0.0;      // floes below this area are left out of the matching and the size distributions
  bool drop_edge_floes = false;  // drop floes touching the image border or the (1-px dilated) no-data area

  // The protocol of issue #3 for hand-labelled masks: IoU >= 0.5, floes >= 1 m^2, edge floes dropped.
  static ScoreOptions labelled_mask() { return {0.5, 1.0, true}; }
  nlohmann::json to_json() const;
};

struct ScoreResult {
  int predicted = 0, truth = 0, matched = 0;  // floes entering the matching on each side, matched pairs
  int predicted_dropped_edge = 0, truth_dropped_edge = 0;
  int predicted_small = 0, truth_small = 0;  // kept floes below min_area_m2 (pixel measures only)
  double precision = 0, recall = 0, f1 = 0;
  double mean_iou = 0;   // over the matched pairs
  double pixel_iou = 0;  // ice (kept floes) against water inside the valid area
  double concentration_predicted = 0, concentration_truth = 0;
  double concentration_error = 0;  // predicted - truth (fractions of the valid area)
  double ks_log_area = 0;          // two-sample KS distance of the log-area distributions
  ScoreOptions options;
  std::vector<std::pair<int, int>> matches;  // (predicted id, truth id) of each match, best IoU first
  nlohmann::json to_json() const;           // the numbers and the protocol (not the match list)
};

// The 8-connected components of the non-zero pixels of `mask` (8- or 16-bit, single channel) as a CV_32S label
// image (0 = background, ids 1..n in raster order of their first pixel).
cv::Mat mask_components(const cv::Mat& mask);

// The two-sample Kolmogorov-Smirnov statistic sup_x |F_a(x) - F_b(x)|; 0 if both are empty, 1 if one is.
double ks_distance(std::vector<double> a, std::vector<double> b);

// The protocol above on two label images of the same size (CV_32S or CV_16U; 0 = no floe). `valid` (CV_8U,
// non-zero = data) is the camera footprint: the pixel measures are taken inside it and its complement (dilated
// by 1 px) is the no-data area edge floes touch; empty = every pixel is data.
ScoreResult score_labels(const cv::Mat& predicted, const cv::Mat& truth, double metres_per_pixel,
                         const cv::Mat& valid = cv::Mat(), const ScoreOptions& o = ScoreOptions());

// Against a hand-labelled binary mask (its floes are its 8-connected components); `photo_valid` is the photo's
// non-black pixels. Errors (floesim::Error) name `mask_name` when the sizes differ.
ScoreResult score_against_mask(const cv::Mat& predicted, const cv::Mat& mask, double metres_per_pixel,
                               const cv::Mat& photo_valid, const ScoreOptions& o = ScoreOptions::labelled_mask(),
                               const std::string& mask_name = "truth mask");

// Against known floe polygons (the synthetic truth), rasterised on the label image's grid by the pixel-centre
// rule (raster.h). Default options: every floe counts (the synthetic truth is exact and already clipped).
ScoreResult score_against_truth(const cv::Mat& labels, const FloeField& truth, double metres_per_pixel,
                                const cv::Mat& valid = cv::Mat(), const ScoreOptions& o = ScoreOptions());

// Reads a label image for scoring (CV_32S): an 8-bit (or 1-bit) image is a floe mask and becomes its 8-connected
// components, a 16-bit image is a label image taken as it is (digitise's labels.png, floesim-synth's
// truth_labels.png). Errors name the file and `what` ("truth image").
cv::Mat load_label_image(const std::filesystem::path& file, const std::string& what);

}  // namespace floesim::imaging

namespace floesim::imaging {

// floesim-score: scores any label image (digitise's labels.png, or another segmenter's) against a truth image.
struct ScoreRequest {
  std::filesystem::path labels;  // predicted: 16-bit labels (0 = no floe) or an 8-bit mask (load_label_image)
  std::filesystem::path truth;   // 8-bit mask (8-connected components) or 16-bit truth labels
  std::filesystem::path photo;   // the photograph: its black pixels are the no-data area (empty: all data)
  double metres_per_pixel = 0;
  std::filesystem::path out;  // score.json to write (atomically); empty: nothing written
  ScoreOptions options = ScoreOptions::labelled_mask();
};
ScoreResult run_score(const ScoreRequest& req);

}  // namespace floesim::imaging
