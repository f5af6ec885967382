#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"

// An RGB image in memory, and PNG files through libpng.

namespace vrflow::viewer {

/// 8-bit RGB pixels, rows from the top, three bytes per pixel.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  /// The pixel at column x, row y (from the top); both must be inside the image.
  std::array<std::uint8_t, 3> at(int x, int y) const;
};

/// Writes `image` as an 8-bit RGB PNG (to `path`.tmp, then renamed).
Status writePng(const std::string& path, const Image& image);
/// Reads a PNG (any colour type libpng can turn into 8-bit RGB).
Result<Image> readPng(const std::string& path);

}  // namespace vrflow::viewer
