#include "imaging/image_io.h"

#include <array>
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <fstream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <tiffio.h>

#include "pipeline/error.h"

namespace floesim::imaging {

namespace {
uint32_t be16(const unsigned char* p) { return (uint32_t(p[0]) << 8) | p[1]; }
uint32_t be32(const unsigned char* p) { return (be16(p) << 16) | be16(p + 2); }

[[noreturn]] void undecodable(const std::string& f, const std::string& why) {
  throw Error(f + ": cannot decode the image: " + why + "; re-export it as an 8-bit grayscale PNG");
}

// PNG: the IHDR chunk, which must come first (libpng refuses a file where it does not).
ImageHeader png_header(const std::string& f, const unsigned char* h, std::streamsize got) {
  if (got < 24 || std::string(reinterpret_cast<const char*>(h + 12), 4) != "IHDR")
    undecodable(f, "the PNG has no IHDR chunk after its signature");
  return {"PNG", static_cast<long>(be32(h + 16)), static_cast<long>(be32(h + 20))};
}

// JPEG: the frame header (SOFn), found the way libjpeg's next_marker() does: bytes before a marker are skipped
// (libjpeg warns and goes on), so are 0xFF fill bytes and stand-alone markers. A scan (SOS) or the end (EOI) before
// any frame header is an error to libjpeg, so it is one here.
ImageHeader jpeg_header(const std::string& f, std::ifstream& in) {
  in.clear();
  in.seekg(2);  // after SOI
  auto byte = [&]() -> int {
    const int c = in.get();
    if (c == std::char_traits<char>::eof()) undecodable(f, "the JPEG ends before its frame header (SOF)");
    return c;
  };
  for (;;) {
    int c = byte();
    while (c != 0xFF) c = byte();
    while (c == 0xFF) c = byte();
    if (c == 0) continue;  // a stuffed 0xFF 0x00 is data, not a marker
    const int marker = c;
    if (marker == 0xDA || marker == 0xD9) undecodable(f, "the JPEG has no frame header (SOF) before its scan");
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // stand-alone: no length
    unsigned char len_bytes[2] = {static_cast<unsigned char>(byte()), static_cast<unsigned char>(byte())};
    const uint32_t len = be16(len_bytes);
    const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      unsigned char s[5];
      for (auto& b : s) b = static_cast<unsigned char>(byte());
      return {"JPEG", static_cast<long>(be16(s + 3)), static_cast<long>(be16(s + 1))};
    }
    if (len < 2) undecodable(f, "a JPEG marker segment has a length below 2");
    in.seekg(len - 2, std::ios::cur);
  }
}

// TIFF (classic and BigTIFF): the first directory as libtiff, which decodes it for OpenCV, reads it. A hand-written
// reader differed from libtiff on a directory holding ImageWidth twice (tests/fuzz/crashes/fuzz_image), so the
// decoder's own library answers. Its messages are caught per file instead of going to stderr.
int keep_tiff_message(TIFF*, void* user, const char* module, const char* fmt, va_list ap) {
  auto& first = *static_cast<std::string*>(user);
  if (first.empty()) {
    char buf[512];
    std::vsnprintf(buf, sizeof buf, fmt, ap);
    first = std::string(module ? module : "libtiff") + ": " + buf;
  }
  return 1;  // handled: the process-wide handler is not called
}
int drop_tiff_warning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

ImageHeader tiff_header(const std::string& f) {
  std::string error;
  std::unique_ptr<TIFFOpenOptions, void (*)(TIFFOpenOptions*)> opts(TIFFOpenOptionsAlloc(), TIFFOpenOptionsFree);
  TIFFOpenOptionsSetErrorHandlerExtR(opts.get(), keep_tiff_message, &error);
  TIFFOpenOptionsSetWarningHandlerExtR(opts.get(), drop_tiff_warning, nullptr);
  std::unique_ptr<TIFF, void (*)(TIFF*)> tif(TIFFOpenExt(f.c_str(), "r", opts.get()), TIFFClose);
  if (!tif) undecodable(f, error.empty() ? "libtiff cannot read its first directory" : error);
  uint32_t w = 0, l = 0;
  if (TIFFGetField(tif.get(), TIFFTAG_IMAGEWIDTH, &w) != 1 || TIFFGetField(tif.get(), TIFFTAG_IMAGELENGTH, &l) != 1)
    undecodable(f, "the TIFF's first directory has no ImageWidth or ImageLength");
  return {"TIFF", static_cast<long>(w), static_cast<long>(l)};
}
}  // namespace

ImageHeader read_image_header(const std::filesystem::path& file) {
  const std::string f = file.string();
  std::ifstream in(file, std::ios::binary);
  FLOESIM_REQUIRE(static_cast<bool>(in), f, ": cannot open the image (check its permissions)");
  std::array<unsigned char, 24> h{};
  in.read(reinterpret_cast<char*>(h.data()), h.size());
  const std::streamsize got = in.gcount();
  FLOESIM_REQUIRE(got > 0, f, ": the image file is empty (0 bytes): an interrupted copy or download? Give a PNG, JPEG "
                  "or TIFF image");
  // The signatures OpenCV's decoders recognise a file by (imgcodecs grfmt_png, grfmt_jpeg, grfmt_tiff).
  static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (got >= 8 && std::equal(png_sig, png_sig + 8, h.begin())) return png_header(f, h.data(), got);
  if (got >= 3 && h[0] == 0xFF && h[1] == 0xD8 && h[2] == 0xFF) return jpeg_header(f, in);
  const bool ii = h[0] == 'I' && h[1] == 'I' && (h[2] == 42 || h[2] == 43) && h[3] == 0;
  const bool mm = h[0] == 'M' && h[1] == 'M' && h[2] == 0 && (h[3] == 42 || h[3] == 43);
  if (got >= 4 && (ii || mm)) {
    in.close();
    return tiff_header(f);
  }
  undecodable(f, "it is not a PNG, JPEG or TIFF file (the formats digitise reads, each sized from its header "
                 "before the pixels are decoded)");
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
  const ImageHeader head = read_image_header(file);
  const double pixels = double(head.width) * double(head.height);
  FLOESIM_REQUIRE(pixels <= max_pixels, f, ": the ", head.format, " header gives ", head.width, " x ", head.height,
                  " = ", pixels / 1e6, " megapixels, more than max_pixels = ", max_pixels / 1e6,
                  " megapixels (digitise needs about 80 bytes per pixel: ", std::lround(pixels * 80 / 1e9 * 10) / 10.0,
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
  // The header was read as the decoder reads it; a decoder that disagreed would make the size check above void.
  FLOESIM_REQUIRE(img.cols == head.width && img.rows == head.height, f, ": decoded as ", img.cols, " x ", img.rows,
                  " pixels but its ", head.format, " header gives ", head.width, " x ", head.height,
                  "; re-export it as an 8-bit grayscale PNG");
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
