// Synthetic helicopter image: a known floe field (power-law floe sizes, irregular polygons, no contacts) rendered
// like a nadir photograph (dark water, bright floes of varying shade, melt ponds, brash, an illumination gradient,
// camera blur and noise). The true polygons and labels are kept, so digitise can be scored against them.
#pragma once
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/floes_io.h"
#include "pipeline/options.h"

namespace floesim::imaging {

struct SynthOptions {
  // Camera: the SAMS paper's helicopter image (Oden, 2015) by default.
  int width_px = 1114;               // image width
  int height_px = 627;               // image height
  double metres_per_pixel = 1.1794;  // ground sampling distance
  // Floe field.
  double concentration = 0.6;     // target floe area / image area
  double alpha = 2.0;             // floe size distribution n(D) ~ D^-alpha (D = equivalent diameter)
  double min_diameter_m = 5.0;    // smallest floe (equivalent diameter)
  double max_diameter_m = 150.0;  // largest floe
  double thickness_m = 1.0;       // written to every floe (SAMS table: h = 1 m)
  double irregularity = 0.22;     // relative amplitude of the random radial perturbation of the outline
  double max_aspect_ratio = 2.0;  // floes are perturbed ellipses with aspect ratio uniform in [1, this]
  double convex_fraction = 0.5;   // fraction of floes replaced by their convex hull (angular, straight-edged)
  int min_vertices = 8;           // outline vertices per floe: uniform in [min_vertices, max_vertices]
  int max_vertices = 20;
  double min_gap_m = 1.5;        // floes never touch: smallest distance between two outlines
  int placement_attempts = 400;  // random positions tried per floe before it is given up (counted)
  // Image content.
  double brash_per_km2 = 1500;     // small bright fragments in the water between floes
  double brash_min_area_m2 = 0.5;  // brash fragment area range (keep below digitise's brash_cutoff_m2)
  double brash_max_area_m2 = 6.0;
  double brash_gap_m = 3.5;       // brash keeps this far from floes and other brash (it must stay brash)
  double pond_probability = 0.3;  // chance that a floe of D >= pond_min_diameter_m carries a melt pond
  double pond_min_diameter_m = 30.0;
  double water_grey = 45;               // mean grey level of open water
  double water_texture_grey = 5;        // amplitude of the smooth water texture
  double ice_grey = 212;                // mean grey level of a floe
  double ice_grey_sigma = 10;           // floe-to-floe shade variation
  double grey_floe_fraction = 0.12;     // fraction of darker (wet / thin) floes
  double grey_floe_grey = 165;          // their mean grey level
  double pond_grey = 110;               // melt pond grey level
  double illumination_gradient = 0.15;  // brightness varies by +-this fraction across the image (linear ramp)
  double blur_sigma_px = 0.8;           // camera blur (Gaussian sigma, pixels)
  double noise_sigma = 4.0;             // Gaussian sensor noise (grey levels)
  std::uint64_t seed = 1;               // std::mt19937_64 seed: same seed, same image and truth

  template <class V>
  void visit(V& v) {
    v.field("width_px", width_px, "px", "image width", int_in_range(16, 30000));
    v.field("height_px", height_px, "px", "image height", int_in_range(16, 30000));
    v.field("metres_per_pixel", metres_per_pixel, "m/px", "ground sampling distance", positive());
    v.field("concentration", concentration, "-", "target floe area / image area", in_range(0, 0.85));
    v.field("alpha", alpha, "-", "power-law exponent of the floe size distribution n(D) ~ D^-alpha", in_range(0.5, 5));
    v.field("min_diameter_m", min_diameter_m, "m", "smallest floe (equivalent diameter)", positive());
    v.field("max_diameter_m", max_diameter_m, "m", "largest floe (equivalent diameter)", positive());
    v.field("thickness_m", thickness_m, "m", "ice thickness written to every floe", positive());
    v.field("irregularity", irregularity, "-", "relative amplitude of the radial outline perturbation",
            in_range(0, 0.6));
    v.field("max_aspect_ratio", max_aspect_ratio, "-", "largest aspect ratio of the underlying ellipse",
            in_range(1, 5));
    v.field("convex_fraction", convex_fraction, "-", "fraction of floes made convex", in_range(0, 1));
    v.field("min_vertices", min_vertices, "-", "fewest outline vertices per floe", int_in_range(3, 200));
    v.field("max_vertices", max_vertices, "-", "most outline vertices per floe", int_in_range(3, 200));
    v.field("min_gap_m", min_gap_m, "m", "smallest distance between two floes", non_negative());
    v.field("placement_attempts", placement_attempts, "-", "random positions tried per floe", int_in_range(1, 100000));
    v.field("brash_per_km2", brash_per_km2, "1/km^2", "brash fragments per square kilometre of image", non_negative());
    v.field("brash_min_area_m2", brash_min_area_m2, "m^2", "smallest brash fragment", positive());
    v.field("brash_max_area_m2", brash_max_area_m2, "m^2", "largest brash fragment", positive());
    v.field("brash_gap_m", brash_gap_m, "m", "distance brash keeps from floes and other brash", non_negative());
    v.field("pond_probability", pond_probability, "-", "chance of a melt pond on a large floe", in_range(0, 1));
    v.field("pond_min_diameter_m", pond_min_diameter_m, "m", "smallest floe that may carry a pond", positive());
    v.field("water_grey", water_grey, "grey", "mean grey level of water", in_range(1, 254));
    v.field("water_texture_grey", water_texture_grey, "grey", "amplitude of the water texture", in_range(0, 100));
    v.field("ice_grey", ice_grey, "grey", "mean grey level of floes", in_range(1, 255));
    v.field("ice_grey_sigma", ice_grey_sigma, "grey", "floe-to-floe shade variation", in_range(0, 100));
    v.field("grey_floe_fraction", grey_floe_fraction, "-", "fraction of darker floes", in_range(0, 1));
    v.field("grey_floe_grey", grey_floe_grey, "grey", "mean grey level of the darker floes", in_range(1, 255));
    v.field("pond_grey", pond_grey, "grey", "grey level of melt ponds", in_range(1, 255));
    v.field("illumination_gradient", illumination_gradient, "-", "relative brightness ramp across the image",
            in_range(0, 0.5));
    v.field("blur_sigma_px", blur_sigma_px, "px", "camera blur (Gaussian sigma)", in_range(0, 10));
    v.field("noise_sigma", noise_sigma, "grey", "Gaussian sensor noise", in_range(0, 100));
    v.field("seed", seed, "-", "random seed (std::mt19937_64)");
    if (max_diameter_m < min_diameter_m) v.problem("max_diameter_m", "must be >= min_diameter_m");
    if (max_vertices < min_vertices) v.problem("max_vertices", "must be >= min_vertices");
    if (brash_max_area_m2 < brash_min_area_m2) v.problem("brash_max_area_m2", "must be >= brash_min_area_m2");
    if (ice_grey <= water_grey + 20) v.problem("ice_grey", "must be at least 20 grey levels above water_grey");
  }
};

struct SynthResult {
  cv::Mat image;         // CV_8UC1, values 1..255 (0 would mean "no data" to digitise)
  cv::Mat truth_labels;  // CV_32S, 0 = water, k = truth floe id k (pixel-centre rule, see raster.h)
  FloeField truth;       // outlines clipped to the image, CCW, metres; ids 1..N
  // Nominal (unclipped) equivalent diameters of all floes placed in the generation domain, which extends past
  // the image so the crop is homogeneous: the sample drawn from the size distribution minus the rejected floes.
  std::vector<double> placed_diameters_m;
  int rejected_floes = 0;  // floes for which no free position was found (placement_attempts exhausted)
  int hidden_floes = 0;    // placed but outside the image or cut to less than a min_diameter_m disc (not drawn)
  int brash_fragments = 0;
  int ponds = 0;
  double concentration = 0;  // truth floe area / image area
  std::vector<std::string> warnings;
};

SynthResult synthesize(const SynthOptions& o);

// Synthesizes and writes out_dir/image.png, out_dir/truth.geojson and out_dir/truth_labels.png (16-bit), each
// atomically; truth.geojson's provenance holds the resolved options and the hashes of the two images.
SynthResult run_synth(const SynthOptions& o, const std::filesystem::path& out_dir);

}  // namespace floesim::imaging
