#include "imaging/raster.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"

namespace floesim::imaging {

std::vector<cv::Point> to_fixed_point(const Polygon& outline_m, const PixelGrid& g) {
  std::vector<cv::Point> pts;
  pts.reserve(outline_m.size());
  const double f = double(1 << kRasterShift);
  for (const Vec2& v : outline_m) {
    const cv::Point2d c = g.metres_to_corner(v);
    // Corner coordinates -> OpenCV's pixel-centre coordinates: shift by half a pixel.
    pts.emplace_back(static_cast<int>(std::lround((c.x - 0.5) * f)), static_cast<int>(std::lround((c.y - 0.5) * f)));
  }
  return pts;
}

void fill_polygon(cv::Mat& img, const Polygon& outline_m, const PixelGrid& g, int value) {
  CV_Assert(img.type() == CV_8UC1 || img.type() == CV_32SC1);
  const size_t n = outline_m.size();
  if (n < 3) return;
  std::vector<cv::Point2d> v(n);
  double y0 = HUGE_VAL, y1 = -HUGE_VAL;
  for (size_t i = 0; i < n; ++i) {
    v[i] = g.metres_to_corner(outline_m[i]);
    y0 = std::min(y0, v[i].y);
    y1 = std::max(y1, v[i].y);
  }
  const int r0 = std::max(0, static_cast<int>(std::ceil(y0 - 0.5)));
  const int r1 = std::min(img.rows - 1, static_cast<int>(std::ceil(y1 - 0.5)) - 1);
  std::vector<double> xs;
  for (int r = r0; r <= r1; ++r) {
    const double yc = r + 0.5;
    xs.clear();
    for (size_t i = 0; i < n; ++i) {
      const cv::Point2d& a = v[i];
      const cv::Point2d& b = v[(i + 1) % n];
      // Half-open in y, so a vertex exactly on the scanline is counted once.
      if ((a.y <= yc && yc < b.y) || (b.y <= yc && yc < a.y))
        xs.push_back(a.x + (yc - a.y) * (b.x - a.x) / (b.y - a.y));
    }
    std::sort(xs.begin(), xs.end());
    for (size_t k = 0; k + 1 < xs.size(); k += 2) {
      // Pixels whose centre c + 0.5 lies in [xs[k], xs[k+1]).
      const int c0 = std::max(0, static_cast<int>(std::ceil(xs[k] - 0.5)));
      const int c1 = std::min(img.cols - 1, static_cast<int>(std::ceil(xs[k + 1] - 0.5)) - 1);
      if (img.type() == CV_8UC1) {
        uint8_t* p = img.ptr<uint8_t>(r);
        for (int c = c0; c <= c1; ++c) p[c] = static_cast<uint8_t>(value);
      } else {
        int* p = img.ptr<int>(r);
        for (int c = c0; c <= c1; ++c) p[c] = value;
      }
    }
  }
}

cv::Mat rasterise_floes(const FloeField& field, const PixelGrid& g) {
  cv::Mat labels(g.height, g.width, CV_32S, cv::Scalar(0));
  for (const Floe& f : field.floes) fill_polygon(labels, f.outline, g, f.id);
  return labels;
}

void write_labels_png(const std::filesystem::path& tmp, const cv::Mat& labels32, const std::string& final_name) {
  double lo = 0, hi = 0;
  cv::minMaxLoc(labels32, &lo, &hi);
  FLOESIM_REQUIRE(lo >= 0 && hi <= 65535, final_name, ": ", static_cast<long>(hi),
                  " floes do not fit a 16-bit label image (max 65535); raise brash_cutoff_m2 / min_floe_area_m2 or "
                  "digitise the image in tiles");
  cv::Mat u16;
  labels32.convertTo(u16, CV_16U);
  // Encoded in memory, then written with every write checked: imwrite does not report a full disk.
  std::vector<uchar> png;
  bool ok = false;
  try {
    ok = cv::imencode(".png", u16, png);
  } catch (const cv::Exception& e) {
    throw Error(final_name + ": cannot encode the label image: " + e.what());
  }
  FLOESIM_REQUIRE(ok, final_name, ": cannot encode the label image as PNG");
  write_file_checked(tmp, std::string(png.begin(), png.end()), final_name);
}

}  // namespace floesim::imaging
