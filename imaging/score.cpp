#include "imaging/score.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <tuple>

#include "imaging/image_io.h"
#include "imaging/raster.h"
#include "pipeline/atomic_file.h"
#include "pipeline/provenance.h"
#include "pipeline/error.h"

namespace floesim::imaging {

nlohmann::json ScoreOptions::to_json() const {
  return {{"min_iou", min_iou},
          {"min_area_m2", min_area_m2},
          {"drop_edge_floes", drop_edge_floes},
          {"matching", "one-to-one, greedy by decreasing IoU, a match needs IoU >= min_iou"},
          {"edge_floes",
           drop_edge_floes ? "floes touching the image border or the no-data area (black pixels dilated by 1 px) "
                             "are dropped from both sides"
                           : "kept"},
          {"small_floes", "floes below min_area_m2 are left out of the matching and the size distributions"}};
}

nlohmann::json ScoreResult::to_json() const {
  return {{"predicted", predicted},
          {"truth", truth},
          {"matched", matched},
          {"predicted_dropped_edge", predicted_dropped_edge},
          {"truth_dropped_edge", truth_dropped_edge},
          {"predicted_small", predicted_small},
          {"truth_small", truth_small},
          {"precision", precision},
          {"recall", recall},
          {"f1", f1},
          {"mean_iou", mean_iou},
          {"pixel_iou", pixel_iou},
          {"concentration_predicted", concentration_predicted},
          {"concentration_truth", concentration_truth},
          {"concentration_error", concentration_error},
          {"ks_log_area", ks_log_area},
          {"protocol", options.to_json()}};
}

cv::Mat mask_components(const cv::Mat& mask) {
  FLOESIM_REQUIRE(mask.channels() == 1 && (mask.depth() == CV_8U || mask.depth() == CV_16U),
                  "mask_components: the mask must be an 8- or 16-bit single-channel image");
  cv::Mat labels;
  cv::connectedComponents(mask != 0, labels, 8, CV_32S);
  return labels;
}

double ks_distance(std::vector<double> a, std::vector<double> b) {
  if (a.empty() && b.empty()) return 0.0;
  if (a.empty() || b.empty()) return 1.0;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  // Walk both sorted samples; the supremum is attained just after a value (both CDFs jump there together when
  // the value occurs in both samples, so equal values are consumed on both sides before comparing).
  size_t i = 0, j = 0;
  double d = 0;
  while (i < a.size() && j < b.size()) {
    const double x = std::min(a[i], b[j]);
    while (i < a.size() && a[i] == x) ++i;
    while (j < b.size() && b[j] == x) ++j;
    d = std::max(d, std::abs(double(i) / a.size() - double(j) / b.size()));
  }
  return d;  // after one sample is exhausted the gap only shrinks towards 0
}

namespace {

struct Side {
  std::vector<long long> area;  // pixels per id (index = id)
  std::vector<char> edge;       // touches the border or the no-data area
  std::vector<char> keep;       // not dropped (pixel measures)
  std::vector<char> match;      // enters the matching (kept and large enough)
  int dropped_edge = 0, small = 0, n_match = 0;
};

Side classify(const cv::Mat& lab, const cv::Mat& forbidden, double px_area, const ScoreOptions& o) {
  double hi = 0;
  cv::minMaxLoc(lab, nullptr, &hi);
  const int n = static_cast<int>(hi);
  Side s;
  s.area.assign(n + 1, 0);
  s.edge.assign(n + 1, 0);
  for (int r = 0; r < lab.rows; ++r) {
    const int* p = lab.ptr<int>(r);
    const uint8_t* f = forbidden.ptr<uint8_t>(r);
    for (int c = 0; c < lab.cols; ++c) {
      const int l = p[c];
      if (l <= 0) continue;
      ++s.area[l];
      if (f[c]) s.edge[l] = 1;
    }
  }
  s.keep.assign(n + 1, 0);
  s.match.assign(n + 1, 0);
  for (int l = 1; l <= n; ++l) {
    if (s.area[l] == 0) continue;
    if (o.drop_edge_floes && s.edge[l]) {
      ++s.dropped_edge;
      continue;
    }
    s.keep[l] = 1;
    if (s.area[l] * px_area < o.min_area_m2) {
      ++s.small;
      continue;
    }
    s.match[l] = 1;
    ++s.n_match;
  }
  return s;
}

cv::Mat as_labels32(const cv::Mat& m, const char* what) {
  FLOESIM_REQUIRE(m.channels() == 1 && (m.depth() == CV_32S || m.depth() == CV_16U || m.depth() == CV_8U), what,
                  ": a label image must be single-channel 8-, 16- or 32-bit integers");
  cv::Mat out;
  m.convertTo(out, CV_32S);
  double lo = 0;
  cv::minMaxLoc(out, &lo, nullptr);
  FLOESIM_REQUIRE(lo >= 0, what, ": label values must be >= 0");
  return out;
}

}  // namespace

ScoreResult score_labels(const cv::Mat& pred_in, const cv::Mat& truth_in, double s, const cv::Mat& valid_in,
                         const ScoreOptions& o) {
  FLOESIM_REQUIRE(std::isfinite(s) && s > 0, "score: metres_per_pixel must be finite and > 0, got ", s);
  const cv::Mat pred = as_labels32(pred_in, "predicted labels"), truth = as_labels32(truth_in, "truth labels");
  FLOESIM_REQUIRE(pred.size() == truth.size(), "score: the predicted labels are ", pred.cols, " x ", pred.rows,
                  " px but the truth is ", truth.cols, " x ", truth.rows, " px; they must share the pixel grid");
  cv::Mat valid = valid_in.empty() ? cv::Mat(pred.size(), CV_8U, cv::Scalar(255)) : (valid_in != 0);
  FLOESIM_REQUIRE(valid.size() == pred.size(), "score: the valid mask is ", valid.cols, " x ", valid.rows,
                  " px but the labels are ", pred.cols, " x ", pred.rows, " px");

  // Border frame and no-data dilated by one pixel (8-neighbourhood).
  cv::Mat forbidden;
  cv::dilate(valid == 0, forbidden, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)), cv::Point(-1, -1), 1,
             cv::BORDER_CONSTANT, cv::Scalar(0));
  if (forbidden.rows > 0 && forbidden.cols > 0) {
    forbidden.row(0).setTo(255);
    forbidden.row(forbidden.rows - 1).setTo(255);
    forbidden.col(0).setTo(255);
    forbidden.col(forbidden.cols - 1).setTo(255);
  }
  const double px_area = s * s;
  const Side P = classify(pred, forbidden, px_area, o), T = classify(truth, forbidden, px_area, o);

  ScoreResult res;
  res.options = o;
  res.predicted = P.n_match;
  res.truth = T.n_match;
  res.predicted_dropped_edge = P.dropped_edge;
  res.truth_dropped_edge = T.dropped_edge;
  res.predicted_small = P.small;
  res.truth_small = T.small;

  std::map<std::pair<int, int>, long long> inter;
  long long n_valid = 0, n_p = 0, n_t = 0, n_both = 0;
  for (int r = 0; r < pred.rows; ++r) {
    const int* lp = pred.ptr<int>(r);
    const int* lt = truth.ptr<int>(r);
    const uint8_t* v = valid.ptr<uint8_t>(r);
    for (int c = 0; c < pred.cols; ++c) {
      const int p = lp[c], q = lt[c];
      const bool ip = p > 0 && P.keep[p], it = q > 0 && T.keep[q];
      if (v[c]) {
        ++n_valid;
        n_p += ip;
        n_t += it;
        n_both += ip && it;
      }
      if (ip && it && P.match[p] && T.match[q]) ++inter[{p, q}];
    }
  }
  std::vector<std::tuple<double, int, int>> pairs;  // (IoU, predicted, truth)
  for (const auto& [pq, n] : inter) {
    const double iou = double(n) / double(P.area[pq.first] + T.area[pq.second] - n);
    if (iou >= o.min_iou) pairs.emplace_back(iou, pq.first, pq.second);
  }
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
    if (std::get<0>(a) != std::get<0>(b)) return std::get<0>(a) > std::get<0>(b);
    return std::make_pair(std::get<1>(a), std::get<2>(a)) < std::make_pair(std::get<1>(b), std::get<2>(b));
  });
  std::vector<char> used_p(P.area.size(), 0), used_t(T.area.size(), 0);
  double iou_sum = 0;
  for (const auto& [iou, p, q] : pairs) {
    if (used_p[p] || used_t[q]) continue;
    used_p[p] = used_t[q] = 1;
    ++res.matched;
    res.matches.emplace_back(p, q);
    iou_sum += iou;
  }
  // Nothing to find and nothing found is perfect agreement, not a score of zero.
  res.precision = res.predicted ? double(res.matched) / res.predicted : (res.truth ? 0.0 : 1.0);
  res.recall = res.truth ? double(res.matched) / res.truth : (res.predicted ? 0.0 : 1.0);
  res.f1 = res.precision + res.recall > 0 ? 2 * res.precision * res.recall / (res.precision + res.recall) : 0.0;
  res.mean_iou = res.matched ? iou_sum / res.matched : 0.0;
  const long long n_union = n_p + n_t - n_both;
  res.pixel_iou = n_union ? double(n_both) / double(n_union) : 1.0;
  res.concentration_predicted = n_valid ? double(n_p) / n_valid : 0.0;
  res.concentration_truth = n_valid ? double(n_t) / n_valid : 0.0;
  res.concentration_error = res.concentration_predicted - res.concentration_truth;
  std::vector<double> la_p, la_t;
  for (size_t l = 1; l < P.area.size(); ++l)
    if (P.match[l]) la_p.push_back(std::log(P.area[l] * px_area));
  for (size_t l = 1; l < T.area.size(); ++l)
    if (T.match[l]) la_t.push_back(std::log(T.area[l] * px_area));
  res.ks_log_area = ks_distance(la_p, la_t);
  return res;
}

ScoreResult score_against_mask(const cv::Mat& predicted, const cv::Mat& mask, double s, const cv::Mat& photo_valid,
                               const ScoreOptions& o, const std::string& mask_name) {
  FLOESIM_REQUIRE(mask.size() == predicted.size(), mask_name, ": the mask is ", mask.cols, " x ", mask.rows,
                  " px but the image is ", predicted.cols, " x ", predicted.rows,
                  " px; a mask must be on the photograph's pixel grid");
  return score_labels(predicted, mask_components(mask), s, photo_valid, o);
}

ScoreResult score_against_truth(const cv::Mat& labels, const FloeField& truth, double s, const cv::Mat& valid,
                                const ScoreOptions& o) {
  const PixelGrid g{labels.cols, labels.rows, s};
  return score_labels(labels, rasterise_floes(truth, g), s, valid, o);
}

cv::Mat load_label_image(const std::filesystem::path& file, const std::string& what) {
  const std::string f = file.string();
  std::error_code ec;
  FLOESIM_REQUIRE(std::filesystem::is_regular_file(file, ec), f, ": the ", what, " does not exist (check the path)");
  cv::Mat img;
  try {
    img = cv::imread(f, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw Error(f + ": cannot decode the " + what + ": " + e.what());
  }
  FLOESIM_REQUIRE(!img.empty(), f, ": cannot decode the ", what, " (truncated, corrupt or not an image)");
  FLOESIM_REQUIRE(img.channels() == 1, f, ": the ", what, " must be single-channel (", img.channels(),
                  " channels found): non-zero = floe for an 8-bit mask, floe ids for a 16-bit label image");
  if (img.depth() == CV_8U) return mask_components(img);
  FLOESIM_REQUIRE(img.depth() == CV_16U, f, ": the ", what, " must be an 8-bit mask or a 16-bit label image");
  cv::Mat out;
  img.convertTo(out, CV_32S);
  return out;
}

ScoreResult run_score(const ScoreRequest& req) {
  FLOESIM_REQUIRE(std::isfinite(req.metres_per_pixel) && req.metres_per_pixel > 0,
                  "--metres-per-pixel must be a finite number > 0 (the ground size of one pixel in metres), got ",
                  req.metres_per_pixel);
  FLOESIM_REQUIRE(req.options.min_area_m2 >= 0 && std::isfinite(req.options.min_area_m2),
                  "--min-area-m2 must be >= 0, got ", req.options.min_area_m2);
  FLOESIM_REQUIRE(req.options.min_iou > 0 && req.options.min_iou <= 1, "--min-iou must be in (0, 1], got ",
                  req.options.min_iou);
  const cv::Mat labels = load_label_image(req.labels, "label image");
  const cv::Mat truth = load_label_image(req.truth, "truth image");
  FLOESIM_REQUIRE(truth.size() == labels.size(), req.truth.string(), ": the truth is ", truth.cols, " x ",
                  truth.rows, " px but the labels are ", labels.cols, " x ", labels.rows,
                  " px; both must be on the photograph's pixel grid");
  cv::Mat valid;
  if (!req.photo.empty()) {
    const cv::Mat photo = load_grayscale_image(req.photo, 1e12);
    FLOESIM_REQUIRE(photo.size() == labels.size(), req.photo.string(), ": the photograph is ", photo.cols, " x ",
                    photo.rows, " px but the labels are ", labels.cols, " x ", labels.rows, " px");
    valid = photo > 0;
  }
  ScoreResult res = score_labels(labels, truth, req.metres_per_pixel, valid, req.options);
  if (!req.out.empty()) {
    std::vector<NamedInput> inputs{{"labels", req.labels}, {"truth", req.truth}};
    if (!req.photo.empty()) inputs.push_back({"photo", req.photo});
    nlohmann::json j = res.to_json();
    j["provenance"] = make_provenance("floesim-score", inputs,
                                      {{"metres_per_pixel", req.metres_per_pixel}, {"protocol", req.options.to_json()}});
    if (req.out.has_parent_path()) ensure_directory(req.out.parent_path());
    write_text_atomic(req.out, j.dump(1) + "\n");
  }
  return res;
}

}  // namespace floesim::imaging
