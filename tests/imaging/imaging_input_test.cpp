// Bad input to digitise and synth: each case is a floesim::Error whose message names the file, key or value and
// the fix, and nothing is written to the output directory.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "imaging/digitise.h"
#include "imaging/image_io.h"
#include "imaging/synth.h"
#include "test_util.h"

namespace floesim::imaging {
namespace {

class DigitiseBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    cv::Mat img(120, 160, CV_8U);
    cv::randu(img, 30, 60);
    cv::rectangle(img, cv::Rect(20, 20, 50, 40), cv::Scalar(220), cv::FILLED);
    cv::rectangle(img, cv::Rect(90, 60, 40, 40), cv::Scalar(210), cv::FILLED);
    good_ = dir_.path / "good.png";
    ASSERT_TRUE(cv::imwrite(good_.string(), img));
    out_ = dir_.path / "out";
  }
  DigitiseRequest request(const std::filesystem::path& image) const {
    DigitiseRequest r;
    r.image = image;
    r.metres_per_pixel = 1.0;
    r.out_dir = out_;
    return r;
  }
  // Runs digitise, expects an Error whose message contains every `needle`, and checks that nothing was written.
  void expect_refused(const DigitiseRequest& req, std::vector<std::string> needles) {
    try {
      run_digitise(req);
      ADD_FAILURE() << "expected an error";
    } catch (const Error& e) {
      const std::string msg = e.what();
      for (const auto& n : needles)
        EXPECT_NE(msg.find(n), std::string::npos) << "message lacks \"" << n << "\": " << msg;
    }
    EXPECT_TRUE(test::list_dir(out_).empty()) << "files were left in the output directory";
  }
  // Writes a hand-built TIFF claiming 30000 x 30000 pixels and checks that its header reads as such.
  std::filesystem::path write_tiff_of_30000_squared(const std::string& name, const std::string& bytes) {
    const auto f = dir_.path / name;
    std::ofstream(f, std::ios::binary) << bytes;
    const ImageHeader head = read_image_header(f);
    EXPECT_EQ(head.format, "TIFF");
    EXPECT_EQ(head.width, 30000);
    EXPECT_EQ(head.height, 30000);
    return f;
  }
  test::ScratchDir dir_;
  std::filesystem::path good_, out_;
};

TEST_F(DigitiseBadInput, TheGoodImageWorks) {
  // The reference for the cases below: the same request on a good image succeeds.
  const DigitiseResult res = run_digitise(request(good_));
  EXPECT_EQ(res.floes.floes.size(), 2u);
  // floes, labels, overlay, stats, fsd.png, fsd.csv, and the rasters' world files and CRS (.pgw, .prj)
  EXPECT_EQ(test::list_dir(out_).size(), 10u);
}

TEST_F(DigitiseBadInput, MissingFile) {
  expect_refused(request(dir_.path / "nope.png"), {"nope.png", "does not exist"});
}

TEST_F(DigitiseBadInput, NotAnImage) {
  const auto f = dir_.path / "text.png";
  std::ofstream(f) << "this is not a PNG\n";
  expect_refused(request(f), {"text.png", "cannot decode", "not a PNG, JPEG or TIFF"});
}

TEST_F(DigitiseBadInput, EmptyFileSaysItIsEmpty) {
  const auto f = dir_.path / "empty.png";
  std::ofstream(f).close();
  expect_refused(request(f), {"empty.png", "is empty (0 bytes)"});
}

// A uniform grey image (issue #37: it ran on as one 40,000 m^2 floe with exit 0): one class, refused with the key
// that accepts it; with the key, the warning and one floe of the whole image.
TEST_F(DigitiseBadInput, AnImageWithNoWaterIsRefusedUnlessTheCaseAllowsIt) {
  const auto f = dir_.path / "grey.png";
  ASSERT_TRUE(cv::imwrite(f.string(), cv::Mat(200, 200, CV_8U, cv::Scalar(180))));
  expect_refused(request(f), {"grey.png", "no water found", "digitise.allow_one_class"});
  DigitiseRequest r = request(f);
  r.config = {{"allow_one_class", true}};
  const DigitiseResult res = run_digitise(r);
  ASSERT_EQ(res.floes.floes.size(), 1u);
  EXPECT_NEAR(signed_area(res.floes.floes[0].outline), 200.0 * 200.0, 0.02 * 200 * 200);
  ASSERT_FALSE(res.warnings.empty());
  EXPECT_NE(res.warnings.back().find("no water found"), std::string::npos);
}

TEST_F(DigitiseBadInput, AnImageWithNoIceIsRefusedUnlessTheCaseAllowsIt) {
  const auto f = dir_.path / "dark.png";
  ASSERT_TRUE(cv::imwrite(f.string(), cv::Mat(100, 100, CV_8U, cv::Scalar(40))));
  expect_refused(request(f), {"dark.png", "no ice found", "digitise.allow_one_class"});
}

TEST_F(DigitiseBadInput, TruncatedPng) {
  std::ifstream in(good_, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto f = dir_.path / "truncated.png";
  std::ofstream(f, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  expect_refused(request(f), {"truncated.png", "cannot decode"});
}

TEST_F(DigitiseBadInput, SixteenBitImage) {
  cv::Mat img16(50, 60, CV_16U, cv::Scalar(40000));
  const auto f = dir_.path / "deep.png";
  ASSERT_TRUE(cv::imwrite(f.string(), img16));
  expect_refused(request(f), {"deep.png", "16-bit", "8 bits"});
}

TEST_F(DigitiseBadInput, ColourImage) {
  cv::Mat bgr(50, 60, CV_8UC3, cv::Scalar(200, 150, 100));
  const auto f = dir_.path / "colour.png";
  ASSERT_TRUE(cv::imwrite(f.string(), bgr));
  expect_refused(request(f), {"colour.png", "colour", "grayscale"});
}

TEST_F(DigitiseBadInput, GreyStoredAsRgbIsAcceptedWithANote) {
  cv::Mat g = cv::imread(good_.string(), cv::IMREAD_GRAYSCALE), bgr;
  cv::Mat planes[] = {g, g, g};
  cv::merge(planes, 3, bgr);
  const auto f = dir_.path / "grey_rgb.png";
  ASSERT_TRUE(cv::imwrite(f.string(), bgr));
  const DigitiseResult res = run_digitise(request(f));
  EXPECT_EQ(res.floes.floes.size(), 2u);
  ASSERT_FALSE(res.warnings.empty());
  EXPECT_NE(res.warnings[0].find("read as grayscale"), std::string::npos);
}

TEST_F(DigitiseBadInput, AllNoData) {
  const auto f = dir_.path / "black.png";
  ASSERT_TRUE(cv::imwrite(f.string(), cv::Mat(40, 40, CV_8U, cv::Scalar(0))));
  expect_refused(request(f), {"black.png", "no data"});
}

TEST_F(DigitiseBadInput, MetresPerPixel) {
  for (double s : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    DigitiseRequest r = request(good_);
    r.metres_per_pixel = s;
    expect_refused(r, {"--metres-per-pixel", "> 0"});
  }
}

TEST_F(DigitiseBadInput, LargerThanMaxPixels) {
  // Refused from the PNG header, before the pixels are decoded.
  DigitiseRequest r = request(good_);
  r.config = {{"max_pixels", 10000}};
  expect_refused(r, {"good.png", "160 x 120", "max_pixels"});
  const ImageHeader head = read_image_header(good_);
  EXPECT_EQ(head.format, "PNG");
  EXPECT_EQ(head.width, 160);
  EXPECT_EQ(head.height, 120);
}

TEST_F(DigitiseBadInput, HugeImageRefusedFromItsHeaderWithDefaults) {
  // A PNG whose header announces 60000 x 60000 pixels (3.6 gigapixels, ~290 GB of working memory) and holds no
  // pixel data: refused from the header with the default max_pixels, before any decoding or allocation.
  const unsigned char header[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                                  0, 0, 0xEA, 0x60, 0, 0, 0xEA, 0x60, 8, 0, 0, 0, 0, 0, 0, 0, 0};
  const auto f = dir_.path / "huge.png";
  std::ofstream(f, std::ios::binary).write(reinterpret_cast<const char*>(header), sizeof header);
  expect_refused(request(f), {"huge.png", "60000 x 60000", "3600 megapixels", "max_pixels", "GB", "tiles"});
}

TEST_F(DigitiseBadInput, UnknownAndInvalidConfigKeys) {
  DigitiseRequest r = request(good_);
  r.config_file = dir_.path / "digitise.json";
  r.config = {{"brash_cutof_m2", 3.0}, {"min_floe_area_m2", -1.0}};
  expect_refused(
      r, {"digitise.json", "brash_cutof_m2", "not a known key", "brash_cutoff_m2", "min_floe_area_m2", "must be >= 0"});
  r.config = {{"simplify_tolerance_m", "half a metre"}};
  expect_refused(r, {"simplify_tolerance_m", "wrong type"});
}

TEST_F(DigitiseBadInput, WrongTruthFile) {
  DigitiseRequest r = request(good_);
  r.truth = dir_.path / "missing.geojson";
  expect_refused(r, {"missing.geojson"});
}

TEST(SynthBadInput, CrossFieldChecks) {
  try {
    read_options<SynthOptions>(Json{{"min_diameter_m", 50.0}, {"max_diameter_m", 20.0}, {"colour", 1}}, "synth.json");
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("synth.json"), std::string::npos) << msg;
    EXPECT_NE(msg.find("max_diameter_m must be >= min_diameter_m"), std::string::npos) << msg;
    EXPECT_NE(msg.find("colour is not a known key"), std::string::npos) << msg;
  }
}


TEST_F(DigitiseBadInput, HugeTiffRefusedFromItsHeader) {
  // A little-endian TIFF announcing 30000 x 30000 pixels with 16 bytes of data: OpenCV allocated 900 MB and decoded
  // for seconds before the size was checked (tests/fuzz/fuzz_image); now refused from its header.
  std::string t = std::string("II*\0", 4) + std::string("\x18\0\0\0", 4) + std::string(16, '\x80');
  auto entry = [&](uint16_t tag, uint16_t type, uint32_t value) {
    const unsigned char e[12] = {uint8_t(tag), uint8_t(tag >> 8), uint8_t(type), 0, 1, 0, 0, 0,
                                 uint8_t(value), uint8_t(value >> 8), uint8_t(value >> 16), uint8_t(value >> 24)};
    t.append(reinterpret_cast<const char*>(e), 12);
  };
  t += std::string("\x06\0", 2);
  entry(256, 4, 30000);
  entry(257, 4, 30000);
  entry(258, 3, 8);
  entry(262, 3, 1);
  entry(273, 4, 8);
  entry(279, 4, 16);
  t += std::string(4, '\0');
  const auto f = write_tiff_of_30000_squared("huge.tif", t);
  DigitiseRequest r = request(f);
  r.config = {{"max_pixels", 1e8}};
  expect_refused(r, {"huge.tif", "30000 x 30000", "900 megapixels", "max_pixels"});
}

std::string read_bytes(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST_F(DigitiseBadInput, TiffWithImageWidthTwiceIsSizedAsLibtiffReadsIt) {
  // tests/fuzz/crashes/fuzz_image/oom-09ee...: a TIFF announcing 30000 x 30000 whose directory holds ImageWidth a
  // second time with an unknown field type. The hand-written header reader took the second entry, found no size and
  // let OpenCV decode, which allocated 3.6 GB. libtiff ignores the bad entry; the header is now read by libtiff.
  const auto crasher = std::filesystem::path(FLOESIM_SOURCE_DIR) / "tests/fuzz/crashes/fuzz_image" /
                       "oom-09eefeba5999f92997400fee46305ddcd03aab12";
  const auto f = dir_.path / "twice.tif";
  std::filesystem::copy_file(crasher, f);
  const ImageHeader head = read_image_header(f);
  EXPECT_EQ(head.width, 30000);
  EXPECT_EQ(head.height, 30000);
  expect_refused(request(f), {"twice.tif", "TIFF header gives 30000 x 30000", "max_pixels"});
}

TEST_F(DigitiseBadInput, BigTiffRefusedFromItsHeader) {
  // BigTIFF (version 43, 8-byte offsets) was not sized before: a 30000 x 30000 claim went to the decoder.
  std::string t = std::string("II+\0\x08\0\0\0", 8);
  auto u64 = [&](uint64_t v) {
    for (int i = 0; i < 8; ++i) t += char((v >> (8 * i)) & 0xFF);
  };
  auto u16 = [&](uint16_t v) { t += char(v & 0xFF), t += char(v >> 8); };
  u64(16);  // first directory
  u64(6);   // entries
  auto entry = [&](uint16_t tag, uint16_t type, uint64_t value) { u16(tag), u16(type), u64(1), u64(value); };
  const uint64_t data = 16 + 8 + 6 * 20 + 8;
  entry(256, 4, 30000);
  entry(257, 4, 30000);
  entry(258, 3, 8);
  entry(262, 3, 1);
  entry(273, 16, data);
  entry(279, 16, 16);
  u64(0);
  t += std::string(16, '\x80');
  const auto f = write_tiff_of_30000_squared("big.tif", t);
  expect_refused(request(f), {"big.tif", "30000 x 30000", "max_pixels"});
}

TEST_F(DigitiseBadInput, JpegSizedPastPaddingAndStrayBytes) {
  // libjpeg skips stray bytes and 0xFF fill before a marker; the header reader must find the same frame header,
  // or a JPEG it gave up on would be decoded unsized. The size is checked against OpenCV's decoding of the file.
  cv::Mat img(37, 53, CV_8U);
  cv::randu(img, 0, 255);
  const auto plain = dir_.path / "plain.jpg";
  ASSERT_TRUE(cv::imwrite(plain.string(), img));
  std::string bytes = read_bytes(plain);
  // After SOI: a COM segment, three stray bytes, then fill bytes before the next marker.
  bytes.insert(2, std::string("\xFF\xFE\x00\x06" "abcd" "xyz" "\xFF\xFF\xFF", 14));
  const auto f = dir_.path / "padded.jpg";
  std::ofstream(f, std::ios::binary) << bytes;
  const cv::Mat decoded = cv::imread(f.string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(decoded.empty());
  const ImageHeader head = read_image_header(f);
  EXPECT_EQ(head.format, "JPEG");
  EXPECT_EQ(head.width, decoded.cols);
  EXPECT_EQ(head.height, decoded.rows);
  EXPECT_EQ(head.width, 53);
  EXPECT_EQ(head.height, 37);
}

TEST_F(DigitiseBadInput, FormatsThatCannotBeSizedFirstAreRefused) {
  // BMP (and PNM, WebP, ...) decode in OpenCV but were not sized before decoding, so a header claiming gigapixels
  // was decoded: refused by format, with the conversion to use.
  const auto f = dir_.path / "field.bmp";
  ASSERT_TRUE(cv::imwrite(f.string(), cv::imread(good_.string(), cv::IMREAD_GRAYSCALE)));
  expect_refused(request(f), {"field.bmp", "not a PNG, JPEG or TIFF", "PNG"});
}
}  // namespace
}  // namespace floesim::imaging
