// An inclusion/exclusion map as the seed draws it: a PNG whose red pixels mark the zone and whose green
// dots mark where root growers start. Pixel (x, y), row 0 at the top, covers the UV square
// [x / width, (x + 1) / width] x [1 - (y + 1) / height, 1 - y / height]: the mask's top row is v = 1,
// like the texture's.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace growbench::vines {

class Mask {
 public:
  // Reads PATH; `key` names the parameter in errors. InputError for a file that is missing, not a PNG,
  // truncated or corrupt, or 0 or more than 16384 pixels on a side. Red: R at least 128 and at least twice G and B;
  // green: the same with G; a pixel with alpha below 128 is neither.
  static Mask read(const std::string& path, const std::string& key);

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  // Whether the pixel holding uv is red (uv outside the unit square takes the nearest edge pixel).
  [[nodiscard]] bool zone(const glm::vec2& uv) const;
  // One root per 8-connected group of green pixels, at its centroid (UV), in the order the groups are
  // first met scanning rows from the top.
  [[nodiscard]] const std::vector<glm::vec2>& roots() const { return roots_; }
  [[nodiscard]] std::size_t zone_pixels() const { return zone_pixels_; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<std::uint8_t> red_;
  std::vector<glm::vec2> roots_;
  std::size_t zone_pixels_ = 0;
};

}  // namespace growbench::vines
