// Digitise's image processing: from an 8-bit grayscale photograph to a label image of floes.
//
//   1. no data: pure black (0) pixels are outside the camera footprint - never ice, not part of the valid area.
//      Optional pre-smoothing (smoothing_m, normalised inside the footprint) against noise and surface texture.
//   2. ice/water: Otsu on the valid pixels gives a first split; an image whose classes differ by less than
//      min_contrast is one class (all ice or no ice). Otherwise the local water and ice brightness normalise the
//      image (0 = water, 1 = ice), and ice is where the normalised brightness exceeds threshold_fraction. The
//      local levels are either "two_class" (masked Gaussian averages of the two classes at illumination_scale_m,
//      twice, refining the split: smooth illumination, one kind of ice) or "local_otsu" (Otsu's class means in
//      blocks of local_block_m, weighted by how clearly a block holds both classes and smoothed over the
//      neighbouring blocks: also a darker far field, grey floes, a field of dense floes).
//      Cracks (crack_width_m > 0): dark lines narrower than crack_width_m (black top-hat) deeper than
//      crack_depth of the local contrast are cut from the ice, so touching floes part along them.
//   3. cleanup: enclosed water up to max_hole_area_m2 is filled (melt ponds), a morphological opening of
//      opening_radius_m removes thin bridges and specks, connected pieces below brash_cutoff_m2 are dropped.
//   4. splitting of touching floes, with two cues. Intensity: the core of each floe (smoothed normalised
//      brightness above core_fraction of its ice piece's bright level; core_fraction 0: the whole ice piece)
//      loses the dark line between floes even where blur bridged the gap. Shape: seeds are the h-maxima of the
//      core's distance map with h = marker_dynamic_m (a bump must rise that much to be a floe of its own);
//      seeds closer than min_marker_separation_m within one piece merge; a piece without core is seeded at its
//      deepest pixel. Marker-based watershed (hierarchical queue) floods the ice from the seeds over the relief
//      "core distance inside the core, brightness below it", so boundaries follow necks and the darkest pixels
//      between cores. Then pieces rejoin (relabelled, without flooding again): two pieces whose shared boundary
//      is not a neck (its highest core distance reaches neck_ratio of the smaller piece's inscribed radius) are
//      one floe with a dent; a piece below min_floe_area_m2 joins the neighbour it shares the longest boundary
//      with. Outline refinement (edge_fraction > 0): within edge_band_m of its outline a floe keeps only pixels
//      brighter than edge_fraction of its own median brightness, which puts each floe's edge at its own half
//      level (the threshold sits low so that dark floes are kept).
//   5. regions: holes of each region filled (a region enclosed by another joins it), each region reduced to its
//      largest 4-connected part, regions never 8-adjacent, lone regions below min_floe_area_m2 dropped,
//      numbered 1..N in raster order of their first pixel.
#pragma once
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "imaging/digitise_options.h"

namespace floesim::imaging {

struct Segmentation {
  cv::Mat labels;  // CV_32S: 0 = no floe, k = floe k (see step 5 for the guarantees)
  int floes = 0;
  cv::Mat valid;  // CV_8U, 255 where the pixel is data (non-zero)
  cv::Mat norm;   // CV_32F normalised brightness (0 = local water level, 1 = local ice level); empty if one class
  long long valid_pixels = 0;
  std::string classes;                  // "mixed", "no_ice" or "all_ice"
  double otsu_threshold = 0;            // first global split (grey level)
  double water_grey = 0, ice_grey = 0;  // mean grey levels of the two classes (first split)
  int seeds = 0;                        // watershed seeds after merging close ones
  int merged_pieces = 0;                // split pieces below min_floe_area_m2 merged into a neighbour
  std::vector<std::string> warnings;
};

// `name` is used in messages (the image file). Throws floesim::Error if the image holds no valid pixel.
Segmentation segment_floes(const cv::Mat& gray, double metres_per_pixel, const DigitiseOptions& o,
                           const std::string& name);

// Morphological reconstruction by dilation of `marker` under `mask` (both CV_32F, marker <= mask), restricted to
// the non-zero pixels of `domain` (8-connectivity; Vincent's hybrid raster/queue algorithm). In place.
void reconstruct_by_dilation(cv::Mat& marker, const cv::Mat& mask, const cv::Mat& domain);

// Marker-controlled watershed of `relief` (CV_32F, e.g. a distance map) inside `domain`: floods from the
// markers (CV_32S, > 0) in order of decreasing relief (quantised to 1/16 unit; FIFO within a level); returns
// CV_32S labels with -1 on the one-pixel boundaries, 0 outside the domain. Two different labels are never
// 8-adjacent.
cv::Mat watershed_distance(const cv::Mat& markers, const cv::Mat& relief, const cv::Mat& domain);

}  // namespace floesim::imaging
