// Reading the photograph digitise works on, with every refusal explained (file, what is wrong, the fix).
#pragma once
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace floesim::imaging {

// Image size from the file header without decoding the pixels (PNG, JPEG and TIFF); false for other formats.
bool read_image_size(const std::filesystem::path& file, int& width, int& height);

// Loads an 8-bit single-channel image. Refused, with floesim::Error: a missing, unreadable, truncated or
// undecodable file; more than max_pixels pixels (checked from the header before decoding for PNG, JPEG and TIFF,
// after decoding for other formats); any depth other than 8 bits (16-bit, float); a colour image. Digitise does not
// guess how to turn colour into ice brightness, so colour is refused with the conversion to use. A 3- or
// 4-channel file whose colour channels are identical (grey stored as RGB) and fully opaque is grey data: it is
// accepted and a note is added to `warnings`.
cv::Mat load_grayscale_image(const std::filesystem::path& file, double max_pixels,
                             std::vector<std::string>* warnings = nullptr);

}  // namespace floesim::imaging
