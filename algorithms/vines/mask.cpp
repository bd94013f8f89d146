#include "algorithms/image_limits.hpp"
#include "algorithms/vines/mask.hpp"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <memory>

#include <fmt/format.h>
#include <stb_image.h>

#include "core/json_util.hpp"
#include "core/errors.hpp"

namespace growbench::vines {

namespace {

constexpr int kMaxSide = kMaxImageSide;

// stb_image's terse reason for a PNG it cannot decode, in words.
std::string decode_failure(const char* reason) {
  const std::string r = reason ? reason : "";
  if (r == "outofdata" || r == "no IEND" || r == "no IDAT" || r == "not enough pixels")
    return fmt::format("the file ends before its image data does: truncated? (stb_image: {})", r);
  if (r.starts_with("bad") || r == "zlib corrupt" || r == "read past buffer" || r == "output buffer limit" ||
      r == "too many codes")
    return fmt::format("its compressed image data is corrupt (stb_image: {})", r);
  return fmt::format("stb_image: {}", r.empty() ? "unknown failure" : r);
}

// Width and height as the PNG's header (IHDR, bytes 16 to 23, big-endian) gives them, when it has one.
bool header_size(const std::string& bytes, std::uint32_t& w, std::uint32_t& h) {
  if (bytes.size() < 24 || bytes.compare(12, 4, "IHDR") != 0) return false;
  auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
    return v;
  };
  w = be32(16);
  h = be32(20);
  return true;
}

}  // namespace

Mask Mask::read(const std::string& path, const std::string& key) {
  if (const std::string why = file_problem(path); !why.empty())
    throw InputError(fmt::format("{}={}: {} (expected a PNG inclusion/exclusion map)", key, path, why));
  std::string head(24, '\0');
  {
    std::ifstream in(path, std::ios::binary);
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
  }
  constexpr std::string_view kPngSignature = "\x89PNG\r\n\x1a\n";
  if (!head.starts_with(kPngSignature))
    throw InputError(fmt::format(
        "{}={}: not a readable image: it is not a PNG (its first bytes are not the PNG signature)", key, path));
  // Refuse absurd sizes before decoding, from the header itself: stb_image refuses them too, but says only
  // that it does not know the file's type.
  std::uint32_t hw = 0, hh = 0;
  if (header_size(head, hw, hh) && (hw == 0 || hh == 0 || hw > kMaxSide || hh > kMaxSide))
    throw InputError(
        fmt::format("{}={}: the image is {} x {} pixels; expected 1 to {} on each side", key, path, hw, hh, kMaxSide));
  int w = 0, h = 0, channels = 0;
  if (stbi_info(path.c_str(), &w, &h, &channels) == 0)
    throw InputError(fmt::format("{}={}: not a readable image: {}", key, path, decode_failure(stbi_failure_reason())));
  std::unique_ptr<stbi_uc, void (*)(void*)> px(stbi_load(path.c_str(), &w, &h, &channels, 4), &stbi_image_free);
  if (!px)
    throw InputError(
        fmt::format("{}={}: cannot decode the image: {}", key, path, decode_failure(stbi_failure_reason())));
  Mask m;
  m.width_ = w;
  m.height_ = h;
  const auto n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  m.red_.assign(n, 0);
  std::vector<std::uint8_t> green(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const int r = px.get()[4 * i], g = px.get()[4 * i + 1], b = px.get()[4 * i + 2], a = px.get()[4 * i + 3];
    if (a < 128) continue;
    if (r >= 128 && r >= 2 * g && r >= 2 * b) m.red_[i] = 1;
    if (g >= 128 && g >= 2 * r && g >= 2 * b) green[i] = 1;
  }
  m.zone_pixels_ = static_cast<std::size_t>(std::count(m.red_.begin(), m.red_.end(), 1));
  // Green dots: 8-connected groups, flood-filled in scan order.
  std::vector<std::size_t> stack;
  for (std::size_t start = 0; start < n; ++start) {
    if (green[start] != 1) continue;
    double sx = 0.0, sy = 0.0;
    std::size_t count = 0;
    green[start] = 2;
    stack.assign(1, start);
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      const int x = static_cast<int>(i % static_cast<std::size_t>(w)),
                y = static_cast<int>(i / static_cast<std::size_t>(w));
      sx += x;
      sy += y;
      ++count;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const std::size_t j =
              static_cast<std::size_t>(ny) * static_cast<std::size_t>(w) + static_cast<std::size_t>(nx);
          if (green[j] == 1) {
            green[j] = 2;
            stack.push_back(j);
          }
        }
    }
    const double cx = sx / static_cast<double>(count) + 0.5, cy = sy / static_cast<double>(count) + 0.5;
    m.roots_.emplace_back(static_cast<float>(cx / w), static_cast<float>(1.0 - cy / h));
  }
  return m;
}

bool Mask::zone(const glm::vec2& uv) const {
  const int x = std::clamp(static_cast<int>(std::floor(uv.x * static_cast<float>(width_))), 0, width_ - 1);
  const int y = std::clamp(static_cast<int>(std::floor((1.0f - uv.y) * static_cast<float>(height_))), 0, height_ - 1);
  return red_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)] != 0;
}

}  // namespace growbench::vines
