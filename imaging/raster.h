// The one mapping between the image's pixel grid and the floe field's metres, used by synth, digitise and scoring.
// Pixel (col, row) covers x in [col*s, (col+1)*s] and y in [(H-row-1)*s, (H-row)*s]: its centre is
// x = (col+0.5)*s, y = (H-row-0.5)*s (x right, y up, origin at the image's bottom-left corner).
// "Corner coordinates" (X, Y) are continuous pixel coordinates with (0, 0) the top-left corner of pixel (0, 0).
#pragma once
#include <filesystem>
#include <opencv2/core.hpp>

#include "pipeline/floes_io.h"

namespace floesim::imaging {

struct PixelGrid {
  int width = 0, height = 0;      // pixels
  double metres_per_pixel = 1.0;  // s

  double width_m() const { return width * metres_per_pixel; }
  double height_m() const { return height * metres_per_pixel; }
  Vec2 corner_to_metres(double X, double Y) const { return {X * metres_per_pixel, (height - Y) * metres_per_pixel}; }
  // Inverse of corner_to_metres.
  cv::Point2d metres_to_corner(const Vec2& p) const {
    return {p.x() / metres_per_pixel, height - p.y() / metres_per_pixel};
  }
};

// Fixed-point vertices for cv::fillPoly / cv::polylines in OpenCV's convention (pixel centres at integers).
constexpr int kRasterShift = 8;
std::vector<cv::Point> to_fixed_point(const Polygon& outline_m, const PixelGrid& g);

// Sets every pixel of `img` (CV_8UC1 or CV_32SC1) whose centre lies inside `outline_m` (even-odd rule, exact
// scanline) to `value`. cv::fillPoly is not used for this: it also fills every pixel its edges touch, which
// biases areas outward by about half a pixel along the whole outline.
void fill_polygon(cv::Mat& img, const Polygon& outline_m, const PixelGrid& g, int value);

// Label image (CV_32S) of the floes: a pixel gets a floe's id when its centre lies inside the outline.
cv::Mat rasterise_floes(const FloeField& field, const PixelGrid& g);

// Writes a label image (CV_32S, values 0..65535) as a 16-bit PNG to an already open temporary path.
// Errors name `final_name` and say what to do when there are more than 65535 floes.
void write_labels_png(const std::filesystem::path& tmp, const cv::Mat& labels32, const std::string& final_name);

}  // namespace floesim::imaging
