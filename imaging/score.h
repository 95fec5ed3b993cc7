// Scoring a segmentation against a known floe field (the synthetic truth, or hand-labelled floes).
#pragma once
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "pipeline/floes_io.h"

namespace floesim::imaging {

struct ScoreResult {
  int predicted = 0, truth = 0, matched = 0;
  double precision = 0, recall = 0, f1 = 0;
  double mean_iou = 0;  // over the matched pairs
  double concentration_predicted = 0, concentration_truth = 0;
  double concentration_error = 0;  // predicted - truth (fractions of the valid area)
  nlohmann::json to_json() const;
};

// The truth polygons are rasterised on the label image's grid (pixel-centre rule, raster.h). Predicted regions
// and truth floes are matched one-to-one, greedily by decreasing IoU (ties: lower ids first); a pair matches when
// IoU >= min_iou (0.5 makes the matching unique anyway). Concentrations are pixel fractions of the valid area
// (`valid`: CV_8U, non-zero = data; empty = the whole image). labels: CV_32S or CV_16U. With no truth floe and
// no predicted region, precision, recall and F1 are 1 (nothing to find, nothing found).
ScoreResult score_against_truth(const cv::Mat& labels, const FloeField& truth, double metres_per_pixel,
                                const cv::Mat& valid = cv::Mat(), double min_iou = 0.5);

}  // namespace floesim::imaging
