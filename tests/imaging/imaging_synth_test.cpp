// The synthetic helicopter image: reproducible, the requested concentration and size distribution, and a truth
// that digitise can be scored against (simple CCW non-overlapping polygons inside the image, labels that match).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "imaging/raster.h"
#include "imaging/shapes.h"
#include "imaging/stats.h"
#include "imaging/synth.h"
#include "pipeline/provenance.h"
#include "test_util.h"
#include "pipeline/geometry2d.h"

namespace floesim::imaging {
namespace {


TEST(Synth, SameSeedSameBytesOtherSeedOtherImage) {
  test::ScratchDir a, b;
  SynthOptions o;
  run_synth(o, a.path / "x");
  run_synth(o, b.path / "x");
  for (const char* f : {"image.png", "truth.geojson", "truth_labels.png"})
    EXPECT_EQ(sha256_file(a.path / "x" / f), sha256_file(b.path / "x" / f)) << f << " differs between two runs";
  SynthOptions o2;
  o2.seed = 2;
  const SynthResult r1 = synthesize(o), r2 = synthesize(o2);
  EXPECT_GT(cv::countNonZero(r1.image != r2.image), r1.image.total() / 2) << "another seed, another image";
}

TEST(Synth, ConcentrationNearTarget) {
  // The target is an expectation: one 150 m floe is ~2% of the 1314 m x 740 m image, so a seed's concentration
  // fluctuates by about +-0.01 (measured over 6 seeds: 0.576..0.604 for 0.6). 0.03 is three of those.
  for (double target : {0.3, 0.6}) {
    for (std::uint64_t seed : {1, 2, 3}) {
      SynthOptions o;
      o.concentration = target;
      o.seed = seed;
      const SynthResult r = synthesize(o);
      EXPECT_NEAR(r.concentration, target, 0.03) << "target " << target << ", seed " << seed;
      EXPECT_EQ(r.rejected_floes, 0) << "every floe should find room at this concentration";
      // The label image carries the same ice area as the polygons (pixel-centre rule: unbiased).
      const double label_conc = cv::countNonZero(r.truth_labels) / double(r.truth_labels.total());
      EXPECT_NEAR(label_conc, r.concentration, 0.002);
    }
  }
}

TEST(Synth, SizeDistributionExponent) {
  // Maximum likelihood of the truncated power law on the known range [min_diameter_m, max_diameter_m] applied to
  // the sampled (unclipped) diameters: unbiased, standard error ~0.03 for the ~1400 floes of the default field.
  // Four standard errors (and at least 0.08) leave room for the few floes placement could reject.
  for (double alpha : {2.0, 2.5}) {
    SynthOptions o;
    o.alpha = alpha;
    const SynthResult r = synthesize(o);
    const PowerLawFit f = fit_power_law(r.placed_diameters_m, o.min_diameter_m, o.max_diameter_m);
    ASSERT_GT(f.n, 500);
    EXPECT_NEAR(f.alpha, alpha, std::max(0.08, 4 * f.alpha_stderr)) << "n = " << f.n << ", stderr " << f.alpha_stderr;
    // The untruncated estimator is biased high for a range of only 30x (the reason for the truncated one).
    const PowerLawFit u = fit_power_law(r.placed_diameters_m, o.min_diameter_m);
    EXPECT_GT(u.alpha, f.alpha);
  }
}

TEST(Synth, TruthPolygonsAreValid) {
  SynthOptions o;
  const SynthResult r = synthesize(o);
  const double W = o.width_px * o.metres_per_pixel, H = o.height_px * o.metres_per_pixel;
  ASSERT_GT(r.truth.floes.size(), 500u);
  EXPECT_DOUBLE_EQ(r.truth.width_m, W);
  EXPECT_DOUBLE_EQ(r.truth.height_m, H);
  std::vector<BBox> boxes;
  for (size_t i = 0; i < r.truth.floes.size(); ++i) {
    const Floe& f = r.truth.floes[i];
    EXPECT_EQ(f.id, static_cast<int>(i) + 1);
    ASSERT_GE(f.outline.size(), 3u);
    EXPECT_GT(signed_area(f.outline), 0) << "floe " << f.id << " is not counter-clockwise";
    EXPECT_NEAR(f.area_m2, signed_area(f.outline), 1e-9 * f.area_m2);
    EXPECT_LT(find_self_intersection(f.outline).first, 0) << "floe " << f.id << " intersects itself";
    EXPECT_GE(f.area_m2, kPi / 4 * o.min_diameter_m * o.min_diameter_m * (1 - 1e-9)) << "floe " << f.id;
    EXPECT_EQ(f.thickness_m, o.thickness_m);
    for (const Vec2& v : f.outline) {
      EXPECT_GE(v.x(), -1e-9);
      EXPECT_LE(v.x(), W + 1e-9);
      EXPECT_GE(v.y(), -1e-9);
      EXPECT_LE(v.y(), H + 1e-9);
    }
    boxes.push_back(bounding_box(f.outline));
  }
  // Floes never touch: every pair keeps min_gap_m (clipping only removes area, so it holds for the truth too).
  int close_pairs = 0;
  for (size_t i = 0; i < boxes.size(); ++i)
    for (size_t j = i + 1; j < boxes.size(); ++j)
      if (boxes[i].overlaps(boxes[j], o.min_gap_m) &&
          polygons_within(r.truth.floes[i].outline, r.truth.floes[j].outline, o.min_gap_m * (1 - 1e-6)))
        ++close_pairs;
  EXPECT_EQ(close_pairs, 0);
}

TEST(Synth, ImageLooksLikeAPhotoOfTheTruth) {
  SynthOptions o;
  const SynthResult r = synthesize(o);
  ASSERT_EQ(r.image.type(), CV_8UC1);
  ASSERT_EQ(r.image.cols, 1114);
  ASSERT_EQ(r.image.rows, 627);
  EXPECT_EQ(cv::countNonZero(r.image == 0), 0) << "0 means no data to digitise";
  // Ice is much brighter than water; brash and ponds exist.
  const cv::Mat ice = r.truth_labels > 0;
  const double ice_mean = cv::mean(r.image, ice)[0], water_mean = cv::mean(r.image, ~ice)[0];
  EXPECT_GT(ice_mean, 170);
  EXPECT_LT(water_mean, 70);
  EXPECT_GT(r.brash_fragments, 100);
  EXPECT_GT(r.ponds, 5);
}

TEST(Synth, WrittenArtefactsReadBack) {
  test::ScratchDir d;
  SynthOptions o;
  const SynthResult r = run_synth(o, d.path);
  const FloeField back = read_floes(d.path / "truth.geojson");  // strict reader: simple, CCW, unique ids
  ASSERT_EQ(back.floes.size(), r.truth.floes.size());
  EXPECT_NEAR(back.width_m, r.truth.width_m, 1e-9);
  EXPECT_EQ(back.provenance["program"], "floesim-synth");
  EXPECT_EQ(back.provenance["config"]["seed"], o.seed);
  EXPECT_EQ(back.provenance["outputs"]["image.png"], sha256_file(d.path / "image.png"));
  const cv::Mat labels = cv::imread((d.path / "truth_labels.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(labels.type(), CV_16UC1);
  cv::Mat l32;
  labels.convertTo(l32, CV_32S);
  EXPECT_EQ(cv::countNonZero(l32 != r.truth_labels), 0);
  const cv::Mat img = cv::imread((d.path / "image.png").string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(cv::countNonZero(img != r.image), 0);
  // Every truth floe covers pixels of its own id (none is lost to rasterisation).
  std::vector<int> count(r.truth.floes.size() + 1, 0);
  for (int y = 0; y < l32.rows; ++y)
    for (int x = 0; x < l32.cols; ++x) ++count[l32.at<int>(y, x)];
  for (size_t k = 1; k < count.size(); ++k) EXPECT_GT(count[k], 0) << "truth floe " << k << " has no pixel";
}

}  // namespace
}  // namespace floesim::imaging
