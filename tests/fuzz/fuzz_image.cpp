// Images into digitise: the header check and decoding of imaging/image_io.h load_grayscale_image (PNG, JPEG, TIFF,
// anything OpenCV reads), then, for a small accepted image, digitise itself. max_pixels is kept small so that each
// input stays fast; the header check must refuse a larger claimed size before decoding.
#include "fuzz_util.h"
#include "imaging/digitise.h"
#include "imaging/image_io.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

// FLOESIM_FUZZ_WRITE_SEED=DIR writes small seeds in every format digitise is meant to read (written by OpenCV, so
// that they are the files a user's tools make): 8-bit grey PNG, JPEG, TIFF (LZW), grey stored as RGB, and a
// 16-bit PNG (refused). Then it exits.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* dir = std::getenv("FLOESIM_FUZZ_WRITE_SEED");
  if (!dir) return 0;
  cv::Mat g(24, 32, CV_8UC1);
  for (int y = 0; y < g.rows; ++y)
    for (int x = 0; x < g.cols; ++x) g.at<uint8_t>(y, x) = ((x / 8 + y / 8) % 2) ? 230 : 30;
  const std::string d = dir;
  cv::imwrite(d + "/grey.png", g);
  cv::imwrite(d + "/grey.jpg", g, {cv::IMWRITE_JPEG_QUALITY, 50});
  cv::imwrite(d + "/grey_progressive.jpg", g, {cv::IMWRITE_JPEG_PROGRESSIVE, 1});
  cv::imwrite(d + "/grey.tif", g);
  cv::Mat rgb;
  cv::cvtColor(g, rgb, cv::COLOR_GRAY2BGR);
  cv::imwrite(d + "/grey_as_rgb.png", rgb);
  cv::Mat g16;
  g.convertTo(g16, CV_16U, 256);
  cv::imwrite(d + "/grey16.png", g16);
  std::exit(0);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const auto file = floesim::fuzz::temp_file(".img");
  floesim::fuzz::write_input(file, data, size);
  floesim::fuzz::expect_ok_or_error([&] {
    std::vector<std::string> warnings;
    const cv::Mat img = floesim::imaging::load_grayscale_image(file, 256.0 * 256.0, &warnings);
    if (img.empty() || img.type() != CV_8UC1) std::abort();
    if (img.total() <= 64 * 64) {
      floesim::imaging::DigitiseOptions o;
      (void)floesim::imaging::digitise(img, 0.5, o, file.string());
    }
  });
  return 0;
}
