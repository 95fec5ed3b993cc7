// Label regions -> floe outlines in metres.
//
// Each region's boundary is traced along its pixel edges and the vertices are put at the edge midpoints
// (marching squares at the 0.5 level of the region's mask): for a 4-connected, hole-free region this is one
// simple ring whose area is the pixel count minus half a pixel, so the outline agrees with the label image.
// Douglas-Peucker then simplifies it at the requested tolerance; a result that is degenerate or not simple falls
// back to half, a quarter of the tolerance and finally to the traced ring. Outlines of neighbouring regions that
// overlap or touch after simplification fall back the same way (0.3 px, then the traced ring, which cannot
// overlap its neighbour's because regions are never 8-adjacent).
#pragma once
#include <opencv2/core.hpp>
#include <vector>

#include "imaging/raster.h"

namespace floesim::imaging {

// Boundary of the region of non-zero pixels containing the first non-zero pixel (raster order) of `mask`
// (CV_8U), through the midpoints of its boundary edges, in corner coordinates of `mask`. The region must be
// 4-connected; diagonal contacts are treated as separate (the saddle is cut on the region's side).
std::vector<cv::Point2d> trace_region_boundary(const cv::Mat& mask);

struct PolygonizeReport {
  int simplify_fallbacks = 0;  // outlines simplified at a smaller tolerance because the result was not simple
  int overlap_fallbacks = 0;   // outlines re-simplified finer because they overlapped a neighbour
  int overlaps_remaining = 0;  // must be 0 (checked by the tests)
};

// One CCW outline in metres per label 1..n of `labels` (CV_32S). Regions must be 4-connected, hole-free and
// never 8-adjacent to each other (segment_floes guarantees it).
std::vector<Polygon> polygonize_labels(const cv::Mat& labels, int n, const PixelGrid& g, double tolerance_m,
                                       PolygonizeReport* report = nullptr);

}  // namespace floesim::imaging
