// Images into digitise: the header check and decoding of imaging/image_io.h load_grayscale_image (PNG, JPEG, TIFF,
// anything OpenCV reads), then, for a small accepted image, digitise itself. max_pixels is kept small so that each
// input stays fast; the header check must refuse a larger claimed size before decoding.
#include "fuzz_util.h"
#include "imaging/digitise.h"
#include "imaging/image_io.h"

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
