// Reading the photograph digitise works on, with every refusal explained (file, what is wrong, the fix).
#pragma once
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace floesim::imaging {

// What an image file's header says, read without decoding its pixels.
struct ImageHeader {
  std::string format;  // "PNG", "JPEG" or "TIFF"
  long width = 0, height = 0;
};

// The format, recognised by the signatures OpenCV recognises, and the size, read as the decoder reads it (libtiff
// for TIFF). Throws floesim::Error naming the file for any other format and for a header without a size: an image
// digitise cannot size before decoding is not decoded, since a decoder allocates what the header claims.
ImageHeader read_image_header(const std::filesystem::path& file);

// Loads an 8-bit single-channel image. Refused, with floesim::Error: a missing, unreadable, truncated or
// undecodable file; a format other than PNG, JPEG and TIFF; more than max_pixels pixels (checked from the header,
// before decoding); any depth other than 8 bits (16-bit, float); a colour image. Digitise does not guess how to turn colour into ice brightness, so colour is refused with the conversion to use. A 3- or
// 4-channel file whose colour channels are identical (grey stored as RGB) and fully opaque is grey data: it is
// accepted and a note is added to `warnings`.
cv::Mat load_grayscale_image(const std::filesystem::path& file, double max_pixels,
                             std::vector<std::string>* warnings = nullptr);

}  // namespace floesim::imaging
