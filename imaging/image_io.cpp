#include "imaging/image_io.h"

#include <array>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "pipeline/error.h"

namespace floesim::imaging {

namespace {
uint32_t be32(const unsigned char* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | p[3];
}
uint32_t be16(const unsigned char* p) { return (uint32_t(p[0]) << 8) | p[1]; }

// TIFF (classic, either byte order): ImageWidth (256) and ImageLength (257) of the first image file directory.
bool read_tiff_size(std::ifstream& in, const unsigned char* h, int& width, int& height) {
  const bool le = h[0] == 'I';
  auto u16 = [le](const unsigned char* p) { return le ? uint32_t(p[0]) | (uint32_t(p[1]) << 8) : be16(p); };
  auto u32 = [le](const unsigned char* p) {
    return le ? uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24) : be32(p);
  };
  if (u16(h + 2) != 42) return false;  // 43 is BigTIFF: sized after decoding
  in.clear();
  in.seekg(u32(h + 4));
  unsigned char n[2];
  if (!in.read(reinterpret_cast<char*>(n), 2)) return false;
  long w = -1, l = -1;
  for (uint32_t k = 0, count = u16(n); k < count && k < 4096; ++k) {
    unsigned char e[12];
    if (!in.read(reinterpret_cast<char*>(e), 12)) return false;
    const uint32_t tag = u16(e), type = u16(e + 2);
    const long value = type == 3 ? long(u16(e + 8)) : type == 4 ? long(u32(e + 8)) : -1;
    if (tag == 256) w = value;
    if (tag == 257) l = value;
  }
  if (w < 0 || l < 0) return false;
  width = static_cast<int>(std::min<long>(w, 0x7fffffff));
  height = static_cast<int>(std::min<long>(l, 0x7fffffff));
  return true;
}
}  // namespace

bool read_image_size(const std::filesystem::path& file, int& width, int& height) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  std::array<unsigned char, 24> h{};
  in.read(reinterpret_cast<char*>(h.data()), h.size());
  const auto got = in.gcount();
  static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (got >= 24 && std::equal(png_sig, png_sig + 8, h.begin())) {
    if (std::string(reinterpret_cast<const char*>(&h[12]), 4) != "IHDR") return false;
    width = static_cast<int>(std::min<uint32_t>(be32(&h[16]), 0x7fffffff));
    height = static_cast<int>(std::min<uint32_t>(be32(&h[20]), 0x7fffffff));
    return true;
  }
  if (got >= 8 && ((h[0] == 'I' && h[1] == 'I') || (h[0] == 'M' && h[1] == 'M')))
    return read_tiff_size(in, h.data(), width, height);
  if (got >= 2 && h[0] == 0xFF && h[1] == 0xD8) {
    // JPEG: walk the marker segments to the first start-of-frame (SOFn) segment.
    in.clear();
    in.seekg(2);
    for (int guard = 0; guard < 10000; ++guard) {
      unsigned char m[4];
      if (!in.read(reinterpret_cast<char*>(m), 4) || m[0] != 0xFF) return false;
      const unsigned marker = m[1], len = be16(m + 2);
      const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
      if (sof) {
        unsigned char s[5];
        if (!in.read(reinterpret_cast<char*>(s), 5)) return false;
        height = static_cast<int>(be16(s + 1));
        width = static_cast<int>(be16(s + 3));
        return true;
      }
      if (len < 2) return false;
      in.seekg(len - 2, std::ios::cur);
    }
  }
  return false;
}

cv::Mat load_grayscale_image(const std::filesystem::path& file, double max_pixels, std::vector<std::string>* warnings) {
  const std::string f = file.string();
  std::error_code ec;
  FLOESIM_REQUIRE(std::filesystem::exists(file, ec), f, ": the image does not exist (check the path)");
  FLOESIM_REQUIRE(std::filesystem::is_regular_file(file, ec), f, ": is not a file");
  {
    std::ifstream probe(file, std::ios::binary);
    FLOESIM_REQUIRE(static_cast<bool>(probe), f, ": cannot open the image (check its permissions)");
  }
  int w = 0, h = 0;
  if (read_image_size(file, w, h))
    FLOESIM_REQUIRE(double(w) * double(h) <= max_pixels, f, ": the image has ", w, " x ", h, " = ",
                    double(w) * double(h) / 1e6, " megapixels, more than max_pixels = ", max_pixels / 1e6,
                    " megapixels (digitise needs about 80 bytes per pixel: ",
                    std::lround(double(w) * double(h) * 80 / 1e9 * 10) / 10.0,
                    " GB for this image); digitise it in tiles or raise max_pixels in the config if memory allows");

  cv::Mat img;
  try {
    img = cv::imread(f, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw Error(f + ": cannot decode the image: " + e.what());
  }
  FLOESIM_REQUIRE(!img.empty(), f,
                  ": cannot decode the image (truncated, corrupt or not an image format OpenCV reads); "
                  "re-export it as an 8-bit grayscale PNG");
  FLOESIM_REQUIRE(double(img.rows) * double(img.cols) <= max_pixels, f, ": the image has ", img.cols, " x ", img.rows,
                  " pixels, more than max_pixels = ", max_pixels, "; digitise it in tiles");
  const int depth = img.depth();
  FLOESIM_REQUIRE(depth == CV_8U, f, ": is a ",
                  depth == CV_16U || depth == CV_16S ? "16-bit"
                  : depth == CV_32F                  ? "32-bit float"
                                                     : "non-8-bit",
                  " image; digitise reads 8-bit grayscale photographs. Convert it to 8 bits by scaling its range "
                  "to 0..255 (if it is a label image, you passed the wrong file)");
  if (img.channels() == 1) return img;

  const int ch = img.channels();
  FLOESIM_REQUIRE(ch == 3 || ch == 4, f, ": has ", ch, " channels; digitise reads 8-bit grayscale images");
  std::vector<cv::Mat> planes;
  cv::split(img, planes);
  const bool grey = cv::countNonZero(planes[0] != planes[1]) == 0 && cv::countNonZero(planes[0] != planes[2]) == 0;
  FLOESIM_REQUIRE(grey, f,
                  ": is a colour image; digitise reads 8-bit grayscale and does not guess how colour maps "
                  "to ice brightness. Convert it first, e.g. `convert in.png -colorspace Gray -depth 8 out.png` "
                  "(ImageMagick) or cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)");
  if (ch == 4)
    FLOESIM_REQUIRE(cv::countNonZero(planes[3] != 255) == 0, f,
                    ": has transparent pixels; mark pixels outside the camera footprint as pure black (0) in a "
                    "single-channel 8-bit image instead");
  if (warnings)
    warnings->push_back(f + ": stored as " + std::to_string(ch) +
                        " channels but all colour channels are equal: read as grayscale");
  return planes[0];
}

}  // namespace floesim::imaging
