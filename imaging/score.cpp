#include "imaging/score.h"

#include <algorithm>
#include <map>
#include <tuple>

#include "imaging/raster.h"
#include "pipeline/error.h"

namespace floesim::imaging {

nlohmann::json ScoreResult::to_json() const {
  return {{"predicted", predicted},
          {"truth", truth},
          {"matched", matched},
          {"precision", precision},
          {"recall", recall},
          {"f1", f1},
          {"mean_iou", mean_iou},
          {"concentration_predicted", concentration_predicted},
          {"concentration_truth", concentration_truth},
          {"concentration_error", concentration_error},
          {"matching", "one-to-one, greedy by decreasing IoU, a match needs IoU >= 0.5"}};
}

ScoreResult score_against_truth(const cv::Mat& labels_in, const FloeField& truth, double s, const cv::Mat& valid,
                                double min_iou) {
  FLOESIM_REQUIRE(labels_in.type() == CV_32SC1 || labels_in.type() == CV_16UC1,
                  "score_against_truth: the label image must be 16-bit or 32-bit single channel");
  cv::Mat labels;
  labels_in.convertTo(labels, CV_32S);
  const PixelGrid g{labels.cols, labels.rows, s};
  const cv::Mat t = rasterise_floes(truth, g);
  FLOESIM_REQUIRE(valid.empty() || valid.size() == labels.size(), "score_against_truth: valid mask size mismatch");

  std::map<int, long long> area_p, area_t;
  std::map<std::pair<int, int>, long long> inter;
  long long n_valid = 0, n_p = 0, n_t = 0;
  for (int r = 0; r < labels.rows; ++r) {
    const int* lp = labels.ptr<int>(r);
    const int* lt = t.ptr<int>(r);
    for (int c = 0; c < labels.cols; ++c) {
      if (!valid.empty() && !valid.at<uint8_t>(r, c)) continue;
      ++n_valid;
      const int p = lp[c], q = lt[c];
      if (p > 0) ++area_p[p], ++n_p;
      if (q > 0) ++area_t[q], ++n_t;
      if (p > 0 && q > 0) ++inter[{p, q}];
    }
  }
  std::vector<std::tuple<double, int, int>> pairs;  // (IoU, predicted, truth)
  for (const auto& [pq, n] : inter) {
    const double iou = double(n) / double(area_p[pq.first] + area_t[pq.second] - n);
    if (iou >= min_iou) pairs.emplace_back(iou, pq.first, pq.second);
  }
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
    if (std::get<0>(a) != std::get<0>(b)) return std::get<0>(a) > std::get<0>(b);
    return std::make_pair(std::get<1>(a), std::get<2>(a)) < std::make_pair(std::get<1>(b), std::get<2>(b));
  });
  std::map<int, bool> used_p, used_t;
  ScoreResult res;
  double iou_sum = 0;
  for (const auto& [iou, p, q] : pairs) {
    if (used_p[p] || used_t[q]) continue;
    used_p[p] = used_t[q] = true;
    ++res.matched;
    iou_sum += iou;
  }
  res.predicted = static_cast<int>(area_p.size());
  res.truth = static_cast<int>(truth.floes.size());
  // Nothing to find and nothing found is perfect agreement, not a score of zero.
  res.precision = res.predicted ? double(res.matched) / res.predicted : (res.truth ? 0.0 : 1.0);
  res.recall = res.truth ? double(res.matched) / res.truth : (res.predicted ? 0.0 : 1.0);
  res.f1 = res.precision + res.recall > 0 ? 2 * res.precision * res.recall / (res.precision + res.recall) : 0.0;
  res.mean_iou = res.matched ? iou_sum / res.matched : 0.0;
  res.concentration_predicted = n_valid ? double(n_p) / n_valid : 0.0;
  res.concentration_truth = n_valid ? double(n_t) / n_valid : 0.0;
  res.concentration_error = res.concentration_predicted - res.concentration_truth;
  return res;
}

}  // namespace floesim::imaging
