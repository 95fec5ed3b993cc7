// Digitise: scored against the synthetic truth (F1 with IoU >= 0.5 matching, concentration), artefacts consistent
// with each other (labels <-> polygons <-> stats), the pieces (boundary tracing, scoring) on known answers, and a
// sanity run on real photographs.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "imaging/digitise.h"
#include "imaging/polygons.h"
#include "imaging/raster.h"
#include "imaging/shapes.h"
#include "imaging/stats.h"
#include "imaging/synth.h"
#include "pipeline/provenance.h"
#include "test_util.h"
#include "pipeline/geometry2d.h"

namespace floesim::imaging {
namespace {


// ---- the pieces on known answers ----

TEST(Trace, RingThroughEdgeMidpointsHasPixelAreaMinusHalf) {
  // A 3x3 square, an L and a region with a diagonal contact (4-connected parts are separate regions).
  cv::Mat sq(7, 7, CV_8U, cv::Scalar(0));
  sq(cv::Rect(2, 2, 3, 3)) = 255;
  auto area = [](const std::vector<cv::Point2d>& r) {
    double a = 0;
    for (size_t i = 0; i < r.size(); ++i) a += r[i].x * r[(i + 1) % r.size()].y - r[(i + 1) % r.size()].x * r[i].y;
    return std::abs(a) / 2;
  };
  EXPECT_DOUBLE_EQ(area(trace_region_boundary(sq)), 9 - 0.5);
  cv::Mat l(8, 8, CV_8U, cv::Scalar(0));
  l(cv::Rect(1, 1, 2, 5)) = 255;
  l(cv::Rect(3, 4, 3, 2)) = 255;  // 16 pixels, one concave corner
  EXPECT_DOUBLE_EQ(area(trace_region_boundary(l)), 16 - 0.5);
  cv::Mat diag(6, 6, CV_8U, cv::Scalar(0));
  diag(cv::Rect(1, 1, 2, 2)) = 255;
  diag(cv::Rect(3, 3, 2, 2)) = 255;  // touches the first block only at a corner
  const auto ring = trace_region_boundary(diag);
  EXPECT_DOUBLE_EQ(area(ring), 4 - 0.5) << "the diagonal neighbour is a separate region";
  Polygon p;
  for (const auto& q : ring) p.emplace_back(q.x, q.y);
  EXPECT_LT(find_self_intersection(p).first, 0);
}

TEST(Score, PerfectAndDegradedPredictions) {
  SynthOptions o;
  const SynthResult syn = synthesize(o);
  const double s = o.metres_per_pixel;
  const ScoreResult perfect = score_against_truth(syn.truth_labels, syn.truth, s);
  EXPECT_EQ(perfect.matched, perfect.truth);
  EXPECT_DOUBLE_EQ(perfect.f1, 1.0);
  EXPECT_DOUBLE_EQ(perfect.mean_iou, 1.0);
  EXPECT_DOUBLE_EQ(perfect.concentration_error, 0.0);
  // Drop one floe: recall (N-1)/N, precision 1; the concentration falls by that floe's share.
  cv::Mat fewer = syn.truth_labels.clone();
  fewer.setTo(0, fewer == 1);
  const ScoreResult s1 = score_against_truth(fewer, syn.truth, s);
  EXPECT_EQ(s1.matched, perfect.truth - 1);
  EXPECT_DOUBLE_EQ(s1.precision, 1.0);
  EXPECT_LT(s1.concentration_error, 0);
  // Merge floes 2 and 3 into one prediction: at most one of them can match (one-to-one).
  cv::Mat merged = syn.truth_labels.clone();
  merged.setTo(2, merged == 3);
  const ScoreResult s2 = score_against_truth(merged, syn.truth, s);
  EXPECT_LE(s2.matched, perfect.truth - 1);
  EXPECT_EQ(s2.predicted, perfect.truth - 1);
  // Open water predicted as open water: perfect.
  const ScoreResult empty = score_against_truth(cv::Mat(50, 50, CV_32S, cv::Scalar(0)), FloeField{}, s);
  EXPECT_DOUBLE_EQ(empty.f1, 1.0);
}

TEST(PowerLaw, RecoversTheExponentOfAKnownSample) {
  // Inverse-CDF sample of p(D) ~ D^-2.3 on [2, 200]; deterministic quantiles, so the fit is near-exact.
  std::vector<double> d;
  const double a = 2.3, lo = 2, hi = 200, e = 1 - a;
  for (int i = 0; i < 20000; ++i) {
    const double u = (i + 0.5) / 20000;
    d.push_back(std::pow(std::pow(lo, e) + u * (std::pow(hi, e) - std::pow(lo, e)), 1 / e));
  }
  EXPECT_NEAR(fit_power_law(d, lo, hi).alpha, a, 1e-3);
  // Untruncated on the same sample: biased high, as it must be when the range is finite.
  EXPECT_GT(fit_power_law(d, lo).alpha, a + 0.01);
}

TEST(PowerLaw, ChoosesTheLowerBoundWhereTheImageStopsResolvingFloes) {
  // D ~ D^-2.5 on [5, 300], plus floes in [1, 5] at a tenth of the power law's density (an image that
  // under-resolves small floes): the KS criterion puts d_min near 5 m and the fit above it recovers alpha.
  std::vector<double> d;
  const double a = 2.5, e = 1 - a;
  auto sample = [&](double lo, double hi, int n) {
    for (int i = 0; i < n; ++i) {
      const double u = (i + 0.5) / n;
      d.push_back(std::pow(std::pow(lo, e) + u * (std::pow(hi, e) - std::pow(lo, e)), 1 / e));
    }
  };
  sample(5, 300, 3000);
  // The power law would put (1^e - 5^e) / (5^e - 300^e) * 3000 = 31,000 floes in [1, 5]; a tenth of that:
  sample(1, 5, 3100);
  std::sort(d.begin(), d.end());
  double ks = 0;
  const double dmin = choose_fit_min_diameter(d, 30, &ks);
  EXPECT_NEAR(dmin, 5.0, 0.5);
  EXPECT_LT(ks, 0.02);
  EXPECT_NEAR(fit_power_law(d, dmin, d.back()).alpha, a, 0.05);
  // From the smallest floe the exponent is far too low.
  EXPECT_LT(fit_power_law(d, d.front(), d.back()).alpha, 2.0);
}

TEST(PowerLaw, PlotIsDeterministicAndHandlesNoFloes) {
  const Json st = floe_statistics({1, 2, 3, 5, 8, 13, 21, 34, 55, 89}, 231, 1000, 5, 0.5);
  const cv::Mat a = plot_size_distribution(st, "test"), b = plot_size_distribution(st, "test");
  ASSERT_EQ(a.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  const cv::Mat none = plot_size_distribution(floe_statistics({}, 0, 1000, 5, 0), "empty");
  EXPECT_EQ(none.size(), a.size());
  EXPECT_EQ(size_distribution_csv(floe_statistics({}, 0, 1000, 5, 0)), "d_min_m,d_max_m,count,number_density_per_m3\n");
}

// ---- on the synthetic image ----

struct SyntheticRun {
  SynthResult syn;
  DigitiseResult res;
};

SyntheticRun run_on_synthetic(std::uint64_t seed, const std::filesystem::path& dir) {
  SynthOptions o;
  o.seed = seed;
  SyntheticRun run;
  run.syn = run_synth(o, dir / "synth");
  DigitiseRequest req;
  req.image = dir / "synth" / "image.png";
  req.metres_per_pixel = o.metres_per_pixel;
  req.out_dir = dir / "floes";
  req.truth = dir / "synth" / "truth.geojson";
  run.res = run_digitise(req);
  return run;
}

TEST(DigitiseSynthetic, MatchesTheTruthOnThreeSeeds) {
  // The target: F1 >= 0.95 with one-to-one IoU >= 0.5 matching, concentration error < 0.02.
  // (Measured: F1 0.996-0.999, concentration error < 0.002 on seeds 1-8.)
  for (std::uint64_t seed : {1, 2, 3}) {
    test::ScratchDir d;
    const SyntheticRun run = run_on_synthetic(seed, d.path);
    ASSERT_TRUE(run.res.score.has_value());
    const ScoreResult& sc = *run.res.score;
    EXPECT_GE(sc.f1, 0.95) << "seed " << seed << ": precision " << sc.precision << ", recall " << sc.recall;
    EXPECT_LT(std::abs(sc.concentration_error), 0.02) << "seed " << seed;
    EXPECT_GT(sc.mean_iou, 0.85) << "seed " << seed;
    EXPECT_TRUE(run.res.warnings.empty());
    // score.json holds the same numbers.
    const Json sj = load_json_file(d.path / "floes" / "score.json");
    EXPECT_DOUBLE_EQ(sj["f1"].get<double>(), sc.f1);
  }
}

TEST(DigitiseSynthetic, ArtefactsAgreeWithEachOther) {
  test::ScratchDir d;
  const SyntheticRun run = run_on_synthetic(1, d.path);
  const double s = 1.1794;
  const std::filesystem::path out = d.path / "floes";
  std::set<std::string> files;
  for (const auto& n : test::list_dir(out)) files.insert(n);
  EXPECT_EQ(files, (std::set<std::string>{"floes.geojson", "labels.png", "overlay.png", "stats.json", "fsd.png",
                                          "fsd.csv", "score.json", "labels.pgw", "labels.prj", "overlay.pgw",
                                          "overlay.prj"}));

  // floes.geojson reads back through the strict reader (simple, CCW, unique ids >= 1).
  const FloeField floes = read_floes(out / "floes.geojson");
  EXPECT_NEAR(floes.width_m, 1114 * s, 1e-9);
  EXPECT_NEAR(floes.height_m, 627 * s, 1e-9);
  EXPECT_EQ(floes.provenance["program"], "floesim-digitise");
  EXPECT_EQ(floes.provenance["inputs"][0]["sha256"], sha256_file(d.path / "synth" / "image.png"));

  // labels.png: 16-bit, the input's grid, one distinct value per feature.
  const cv::Mat labels16 = cv::imread((out / "labels.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(labels16.type(), CV_16UC1);
  ASSERT_EQ(labels16.size(), cv::Size(1114, 627));
  cv::Mat labels;
  labels16.convertTo(labels, CV_32S);
  std::map<int, long long> pixels;
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x)
      if (const int l = labels.at<int>(y, x)) ++pixels[l];
  ASSERT_EQ(pixels.size(), floes.floes.size());
  ASSERT_GT(floes.floes.size(), 500u);

  // Each feature's area agrees with its label's pixel area: the traced ring has the pixel area minus half a
  // pixel and Douglas-Peucker moves the outline by at most the tolerance, so |dA| <= 0.5 px + perimeter * tol;
  // for floes of 200 pixels and more that is within 3%.
  const double tol = DigitiseOptions{}.simplify_tolerance_m;
  for (const Floe& f : floes.floes) {
    ASSERT_TRUE(pixels.count(f.id)) << "feature " << f.id << " has no label pixels";
    const double a_pix = pixels[f.id] * s * s;
    double perimeter = 0;
    for (size_t i = 0; i < f.outline.size(); ++i)
      perimeter += (f.outline[(i + 1) % f.outline.size()] - f.outline[i]).norm();
    EXPECT_LE(std::abs(f.area_m2 - a_pix), 0.5 * s * s + perimeter * tol) << "feature " << f.id;
    if (pixels[f.id] >= 200) {
      EXPECT_NEAR(f.area_m2, a_pix, 0.03 * a_pix) << "feature " << f.id;
    }
  }
  // Outlines are non-overlapping and inside the image; rasterised again they give back the labels.
  std::vector<BBox> boxes;
  for (const Floe& f : floes.floes) boxes.push_back(bounding_box(f.outline));
  int overlaps = 0;
  for (size_t i = 0; i < boxes.size(); ++i) {
    EXPECT_GE(boxes[i].x0, 0);
    EXPECT_GE(boxes[i].y0, 0);
    EXPECT_LE(boxes[i].x1, floes.width_m + 1e-9);
    EXPECT_LE(boxes[i].y1, floes.height_m + 1e-9);
    for (size_t j = i + 1; j < boxes.size(); ++j)
      if (boxes[i].overlaps(boxes[j]) && polygons_within(floes.floes[i].outline, floes.floes[j].outline, 0)) ++overlaps;
  }
  EXPECT_EQ(overlaps, 0);
  const ScoreResult self = score_against_truth(labels, floes, s);
  EXPECT_EQ(self.matched, self.truth) << "every polygon matches its own label region";
  EXPECT_GT(self.mean_iou, 0.9);

  // stats.json: count, concentration, the size table and the power-law fit.
  const Json st = load_json_file(out / "stats.json");
  EXPECT_EQ(st["floe_count"].get<size_t>(), floes.floes.size());
  double label_area = 0;
  for (const auto& [l, n] : pixels) label_area += n * s * s;
  EXPECT_NEAR(st["ice_concentration"].get<double>(), label_area / (1114 * 627 * s * s), 1e-9);
  int binned = 0;
  for (const auto& b : st["size_distribution"]["bins"]) binned += b["count"].get<int>();
  EXPECT_EQ(binned, static_cast<int>(floes.floes.size()));
  EXPECT_TRUE(st["power_law"]["truncated_mle"]["alpha"].is_number());
  // The fitted exponent agrees with the same estimator on the truth polygons (both are clipped by the border and
  // cut at the smallest floe, so they are comparable; they are not the generator's alpha).
  std::vector<double> d_truth, d_pred;
  for (const Floe& f : run.syn.truth.floes) d_truth.push_back(std::sqrt(4 * f.area_m2 / kPi));
  for (const Floe& f : floes.floes) d_pred.push_back(std::sqrt(4 * f.area_m2 / kPi));
  const double dmin = 8.0, dmax = 150.0;  // above the smallest, partly lost floes
  const PowerLawFit ft = fit_power_law(d_truth, dmin, dmax), fp = fit_power_law(d_pred, dmin, dmax);
  EXPECT_NEAR(fp.alpha, ft.alpha, 3 * ft.alpha_stderr) << "truth " << ft.alpha << " +- " << ft.alpha_stderr;

  // fsd.csv: the same bins as stats.json; fsd.png a colour plot.
  std::ifstream csv(out / "fsd.csv");
  std::string line;
  int rows = -1;  // header
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, static_cast<int>(st["size_distribution"]["bins"].size()));
  EXPECT_EQ(cv::imread((out / "fsd.png").string(), cv::IMREAD_UNCHANGED).type(), CV_8UC3);

  // overlay.png: colour, the input's size.
  const cv::Mat overlay = cv::imread((out / "overlay.png").string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(overlay.type(), CV_8UC3);
  EXPECT_EQ(overlay.size(), cv::Size(1114, 627));
}

TEST(DigitiseSynthetic, ConvexPartsTileEachFloe) {
  SynthOptions so;
  const SynthResult syn = synthesize(so);
  test::ScratchDir d;
  cv::imwrite((d.path / "image.png").string(), syn.image);
  DigitiseRequest req;
  req.image = d.path / "image.png";
  req.metres_per_pixel = so.metres_per_pixel;
  req.out_dir = d.path / "out";
  req.config = {{"convex_parts", true}};
  const DigitiseResult res = run_digitise(req);
  const Json parts = load_json_file(d.path / "out" / "convex_parts.geojson");
  ASSERT_EQ(parts["features"].size(), res.floes.floes.size());
  int non_convex_floes = 0;
  for (size_t i = 0; i < res.floes.floes.size(); ++i) {
    const Floe& f = res.floes.floes[i];
    const Json& feat = parts["features"][i];
    ASSERT_EQ(feat["properties"]["id"].get<int>(), f.id);
    ASSERT_EQ(feat["geometry"]["type"], "MultiPolygon");
    double sum = 0;
    for (const Json& poly : feat["geometry"]["coordinates"]) {
      Polygon p;
      for (const Json& v : poly[0]) p.emplace_back(v[0].get<double>(), v[1].get<double>());
      ASSERT_EQ(p.front(), p.back()) << "GeoJSON rings are closed";
      p.pop_back();
      EXPECT_GT(signed_area(p), 0) << "floe " << f.id;
      EXPECT_TRUE(is_convex(p, 1e-9)) << "floe " << f.id;
      sum += signed_area(p);
    }
    EXPECT_NEAR(sum, f.area_m2, 1e-9 * f.area_m2) << "floe " << f.id;
    EXPECT_EQ(feat["properties"]["parts"].get<size_t>(), feat["geometry"]["coordinates"].size());
    non_convex_floes += feat["geometry"]["coordinates"].size() > 1;
  }
  EXPECT_GT(non_convex_floes, 10) << "the digitised outlines include non-convex floes";
  // Without the option the file is not written.
  req.config = Json::object();
  req.out_dir = d.path / "out2";
  run_digitise(req);
  EXPECT_FALSE(std::filesystem::exists(d.path / "out2" / "convex_parts.geojson"));
}

TEST(DigitiseSynthetic, SameInputSameBytes) {
  SynthOptions o;
  const SynthResult syn = synthesize(o);
  test::ScratchDir d;
  cv::imwrite((d.path / "image.png").string(), syn.image);
  for (const char* out : {"a", "b"}) {
    DigitiseRequest req;
    req.image = d.path / "image.png";
    req.metres_per_pixel = o.metres_per_pixel;
    req.out_dir = d.path / out;
    run_digitise(req);
  }
  for (const char* f : {"floes.geojson", "labels.png", "overlay.png", "stats.json", "fsd.png", "fsd.csv"})
    EXPECT_EQ(sha256_file(d.path / "a" / f), sha256_file(d.path / "b" / f)) << f;
}

TEST(DigitiseSynthetic, NoDataFrameIsNeverIce) {
  // Black out a wedge of the image (a camera footprint edge): no floe pixel there, valid area smaller.
  SynthOptions o;
  const SynthResult syn = synthesize(o);
  cv::Mat img = syn.image.clone();
  std::vector<std::vector<cv::Point>> wedge{{{0, 0}, {500, 0}, {0, 400}}};
  cv::fillPoly(img, wedge, cv::Scalar(0));
  const DigitiseResult res = digitise(img, o.metres_per_pixel, DigitiseOptions{});
  EXPECT_EQ(cv::countNonZero((img == 0) & (res.seg.labels > 0)), 0);
  EXPECT_EQ(res.seg.valid_pixels, static_cast<long long>(cv::countNonZero(img)));
  const double conc = res.stats["ice_concentration"].get<double>();
  const ScoreResult sc = score_against_truth(res.seg.labels, syn.truth, o.metres_per_pixel, img > 0);
  EXPECT_NEAR(conc, sc.concentration_predicted, 1e-9);
  EXPECT_LT(std::abs(sc.concentration_error), 0.03) << "concentration over the valid area only";
}

TEST(DigitiseSynthetic, OpenWaterAndAllIceGiveCorrectResultsWithAWarning) {
  cv::Mat water(200, 300, CV_8U), ice(200, 300, CV_8U);
  cv::randu(water, 35, 55);
  cv::randu(ice, 205, 225);
  // An image of one class is refused unless it is meant (imaging_input_test checks the refusal).
  DigitiseOptions one_class;
  one_class.allow_one_class = true;
  const DigitiseResult w = digitise(water, 1.0, one_class, "water.png");
  EXPECT_EQ(w.floes.floes.size(), 0u);
  EXPECT_EQ(w.stats["ice_concentration"].get<double>(), 0.0);
  ASSERT_EQ(w.warnings.size(), 1u);
  EXPECT_NE(w.warnings[0].find("no ice"), std::string::npos) << w.warnings[0];
  const DigitiseResult i = digitise(ice, 1.0, one_class, "ice.png");
  ASSERT_EQ(i.floes.floes.size(), 1u);
  EXPECT_NEAR(i.stats["ice_concentration"].get<double>(), 1.0, 1e-12);
  // The outline may deviate from the pixel area by the simplification tolerance along its perimeter.
  EXPECT_NEAR(i.floes.floes[0].area_m2, 300.0 * 200.0, 2 * (300 + 200) * DigitiseOptions{}.simplify_tolerance_m);
  ASSERT_EQ(i.warnings.size(), 1u);
  EXPECT_NE(i.warnings[0].find("no water"), std::string::npos) << i.warnings[0];
}

// ---- real photographs: no score target yet (a later issue), but no crash and a plausible result ----

TEST(DigitiseReal, PasserottiCloseRangeImage) {
  // 2410 x 1158 at 0.05 m/px (S.A. Agulhas II, 2022). The lengths of the default options are for a helicopter
  // at ~1 m/px; for floes of 1-5 m they are scaled down (this is what the options in metres are for).
  const auto image = test::shared_data("passerotti/images/2022-07-19_123132_ortho.png");
  test::ScratchDir d;
  DigitiseRequest req;
  req.image = image;
  req.metres_per_pixel = 0.05;
  req.out_dir = d.path;
  req.config = {{"illumination_scale_m", 6.0}, {"max_hole_area_m2", 4.0},     {"opening_radius_m", 0.1},
                {"brash_cutoff_m2", 0.05},     {"marker_dynamic_m", 0.1},     {"min_marker_separation_m", 0.15},
                {"min_floe_area_m2", 0.1},     {"simplify_tolerance_m", 0.03}};
  const DigitiseResult res = run_digitise(req);
  const double conc = res.stats["ice_concentration"].get<double>();
  EXPECT_GT(conc, 0.2);
  EXPECT_LT(conc, 0.9);
  EXPECT_GT(res.floes.floes.size(), 100u);
  // Outside the camera footprint (pure black) nothing is ice, and the valid area excludes it.
  const cv::Mat img = cv::imread(image.string(), cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(cv::countNonZero((img == 0) & (res.seg.labels > 0)), 0);
  EXPECT_LT(res.seg.valid_pixels, static_cast<long long>(img.total()) * 3 / 4);
  EXPECT_EQ(res.polygons.overlaps_remaining, 0);
}

TEST(DigitiseReal, HotraxHelicopterImage) {
  // 3008 x 2000, HOTRAX 2005; the scale is unknown, 0.2 m/px assumed. Default options.
  const auto image = test::shared_data("hotrax/ice10.png");
  test::ScratchDir d;
  DigitiseRequest req;
  req.image = image;
  req.metres_per_pixel = 0.2;
  req.out_dir = d.path;
  const DigitiseResult res = run_digitise(req);
  const double conc = res.stats["ice_concentration"].get<double>();
  EXPECT_GT(conc, 0.2);
  EXPECT_LT(conc, 0.9);
  EXPECT_GT(res.floes.floes.size(), 10u);
  EXPECT_EQ(res.polygons.overlaps_remaining, 0);
  // The largest floes of this photograph are hundreds of metres across at the assumed scale.
  EXPECT_GT(res.stats["max_area_m2"].get<double>(), 5000.0);
}

}  // namespace
}  // namespace floesim::imaging
