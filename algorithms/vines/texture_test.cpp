// The vine texture's drawing: where strokes and leaves land and how they look, the tiles (same pixels
// for any thread count, no seams), the normal map's directions, and the PNG and SVG writers.
#include <gtest/gtest.h>
#include <stb_image.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/vines/texture.hpp"
#include "core/errors.hpp"
#include "core/random.hpp"

namespace growbench::vines {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

std::filesystem::path temp_dir(const std::string& name) {
  const auto d =
      std::filesystem::temp_directory_path() / ("growbench_texture_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const std::uint8_t* pixel(const Image& im, int x, int y) {
  return im.rgba.data() +
         (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) + static_cast<std::size_t>(x)) * 4;
}
int alpha(const Image& im, int x, int y) {
  return pixel(im, x, y)[3];
}

// The UV of the point (x, y) in pixels (y down the image).
glm::vec2 uv_of(double x, double y, int size) {
  return {static_cast<float>(x / size), static_cast<float>(1.0 - y / size)};
}

// Coverage in pixels along a column or a row (alpha summed over 255).
double column_coverage(const Image& im, int x) {
  double sum = 0.0;
  for (int y = 0; y < im.height; ++y) sum += alpha(im, x, y);
  return sum / 255.0;
}
double row_coverage(const Image& im, int y) {
  double sum = 0.0;
  for (int x = 0; x < im.width; ++x) sum += alpha(im, x, y);
  return sum / 255.0;
}

// The alpha-weighted centroid of the image, in pixels.
glm::dvec2 centroid(const Image& im) {
  glm::dvec2 sum(0.0);
  double total = 0.0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const double a = alpha(im, x, y);
      sum += a * glm::dvec2(x + 0.5, y + 0.5);
      total += a;
    }
  return total > 0.0 ? sum / total : glm::dvec2(-1.0);
}

DrawOptions options_of(int size) {
  DrawOptions o;
  o.size = size;
  return o;
}

int channel(float c) {
  return static_cast<int>(std::lround(c * 255.0f));
}

TEST(VinesTexture, StrokeCoversItsMidpointInTheVineColourAndNothingAWidthAway) {
  // A horizontal stroke 4 pixels wide along the centres of row 32.
  const int size = 64;
  const std::vector<Stroke> strokes = {{uv_of(16, 32.5, size), uv_of(48, 32.5, size), 4.0f / size, 4.0f / size}};
  const DrawOptions o = options_of(size);
  const Image im = draw_texture(strokes, {}, o);
  ASSERT_EQ(im.width, size);
  ASSERT_EQ(im.height, size);
  ASSERT_EQ(im.rgba.size(), static_cast<std::size_t>(size * size * 4));
  for (const int y : {31, 32, 33}) {
    const std::uint8_t* p = pixel(im, 32, y);
    EXPECT_EQ(p[3], 255) << "row " << y;
    EXPECT_NEAR(p[0], channel(o.vine_colour.r), 1);
    EXPECT_NEAR(p[1], channel(o.vine_colour.g), 1);
    EXPECT_NEAR(p[2], channel(o.vine_colour.b), 1);
  }
  // Rows 30 and 34 are half covered; one width (4 pixels) from the centre is clear.
  EXPECT_GT(alpha(im, 32, 30), 64);
  EXPECT_LT(alpha(im, 32, 30), 192);
  EXPECT_EQ(alpha(im, 32, 28), 0);
  EXPECT_EQ(alpha(im, 32, 36), 0);
  // Round ends: half a width beyond each end, on the axis, is partly covered; a width beyond is clear.
  EXPECT_GT(alpha(im, 14, 32), 0);
  EXPECT_EQ(alpha(im, 11, 32), 0);
  EXPECT_EQ(alpha(im, 52, 32), 0);
  // A partly covered pixel keeps the vine colour (straight alpha, not darkened).
  EXPECT_NEAR(pixel(im, 32, 30)[0], channel(o.vine_colour.r), 2);
  EXPECT_NEAR(pixel(im, 32, 30)[1], channel(o.vine_colour.g), 2);
  EXPECT_NEAR(pixel(im, 32, 30)[2], channel(o.vine_colour.b), 2);
}

TEST(VinesTexture, VUpIsTheTopOfTheImage) {
  const int size = 64;
  // From u = 0.1 to 0.3 at v = 0.9: the top rows, the left side.
  const std::vector<Stroke> strokes = {{{0.1f, 0.9f}, {0.3f, 0.9f}, 2.0f / size, 2.0f / size}};
  const Image im = draw_texture(strokes, {}, options_of(size));
  const glm::dvec2 c = centroid(im);
  EXPECT_NEAR(c.x, 0.2 * size, 0.5);
  EXPECT_NEAR(c.y, 0.1 * size, 0.5);
  for (int y = size / 4; y < size; ++y) EXPECT_EQ(row_coverage(im, y), 0.0) << "row " << y;
}

TEST(VinesTexture, WidthTapersFromTheParentsEndToTheChilds) {
  const int size = 128;
  // 2 pixels wide at x = 20, 16 at x = 108.
  const std::vector<Stroke> strokes = {{uv_of(20, 64, size), uv_of(108, 64, size), 2.0f / size, 16.0f / size}};
  const Image im = draw_texture(strokes, {}, options_of(size));
  auto width_at = [](double x) { return 2.0 + 14.0 * (x + 0.5 - 20.0) / 88.0; };
  for (const int x : {24, 40, 64, 88, 104}) EXPECT_NEAR(column_coverage(im, x), width_at(x), 0.5) << "column " << x;
}

TEST(VinesTexture, DotsStyleDrawsADiscOfTheChildsWidthAtItsEnd) {
  const int size = 64;
  // A wide parent end that the lines style would draw, and a child end 10 pixels across.
  const std::vector<Stroke> strokes = {{uv_of(12, 32, size), uv_of(44, 32, size), 20.0f / size, 10.0f / size}};
  DrawOptions o = options_of(size);
  o.style = Style::Dots;
  const Image im = draw_texture(strokes, {}, o);
  EXPECT_EQ(alpha(im, 44, 32), 255);
  EXPECT_EQ(alpha(im, 12, 32), 0);
  EXPECT_EQ(alpha(im, 28, 32), 0);
  EXPECT_NEAR(row_coverage(im, 32), 10.0, 0.5);  // the diameter through the centre
  EXPECT_NEAR(column_coverage(im, 44), 10.0, 0.5);
  const glm::dvec2 c = centroid(im);
  EXPECT_NEAR(c.x, 44.0, 0.1);
  EXPECT_NEAR(c.y, 32.0, 0.1);
  o.style = Style::Lines;
  EXPECT_GT(alpha(draw_texture(strokes, {}, o), 12, 32), 0);  // the same strokes as lines do reach a
}

TEST(VinesTexture, LeafHangsDownAtAngleZeroAndPointsToPlusUAtHalfPi) {
  const int size = 128;
  const glm::vec2 at = uv_of(64, 64, size);
  const DrawOptions o = options_of(size);
  const Image down = draw_texture({}, {{at, 0.0f, 0.4f, 1.0f}}, o);
  const glm::dvec2 d = centroid(down);
  EXPECT_NEAR(d.x, 64.0, 1.0);
  EXPECT_GT(d.y, 64.0 + 0.15 * 0.4 * size);
  for (int y = 0; y < 63; ++y) EXPECT_EQ(row_coverage(down, y), 0.0) << "row " << y << " is above the stem";
  // Stem to tip is the length: the lowest covered row is about 0.4 * size below the stem.
  int lowest = 0;
  for (int y = 0; y < size; ++y)
    if (row_coverage(down, y) > 0.0) lowest = y;
  EXPECT_NEAR(lowest, 64 + 0.4 * size, 2.0);

  const Image right = draw_texture({}, {{at, kPi / 2, 0.4f, 1.0f}}, o);
  const glm::dvec2 r = centroid(right);
  EXPECT_GT(r.x, 64.0 + 0.15 * 0.4 * size);
  EXPECT_NEAR(r.y, 64.0, 1.0);
  for (int x = 0; x < 63; ++x) EXPECT_EQ(column_coverage(right, x), 0.0) << "column " << x << " is behind the stem";
  // The built-in leaf is green, as the options colour it.
  const std::uint8_t* p = pixel(down, static_cast<int>(d.x), static_cast<int>(d.y));
  EXPECT_EQ(p[3], 255);
  EXPECT_GT(p[1], p[0]);
  EXPECT_GT(p[1], p[2]);
}

// A user sprite half as wide as tall, its top half red and its bottom half blue.
std::string two_colour_sprite(const std::filesystem::path& dir, int height) {
  Image sprite;
  sprite.width = height / 2, sprite.height = height;
  sprite.rgba.resize(static_cast<std::size_t>(sprite.width * height) * 4);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < sprite.width; ++x) {
      std::uint8_t* p = sprite.rgba.data() + (static_cast<std::size_t>(y * sprite.width + x)) * 4;
      p[0] = y < height / 2 ? 255 : 0, p[1] = 0, p[2] = y < height / 2 ? 0 : 255, p[3] = 255;
    }
  const std::string path = (dir / ("sprite" + std::to_string(height) + ".png")).string();
  write_png(path, sprite);
  return path;
}

TEST(VinesTexture, UserSpriteHangsFromItsStemUnmirroredAndHonoursTheStemOffset) {
  const auto dir = temp_dir("sprite");
  const int size = 64;
  DrawOptions o = options_of(size);
  // A small sprite, and one taller than any stamp needs (shrunk when read).
  for (const int height : {32, 1100}) {
    SCOPED_TRACE("a sprite " + std::to_string(height) + " pixels tall");
    o.leaf_texture = two_colour_sprite(dir, height);
    o.stem_offset = 0.0f;
    // Angle 0, stem at (32, 16), 32 pixels long: red from row 16 to 32, blue below.
    const Image down = draw_texture({}, {{uv_of(32, 16, size), 0.0f, 0.5f, 1.0f}}, o);
    EXPECT_EQ(alpha(down, 32, 12), 0);
    EXPECT_GT(pixel(down, 32, 20)[0], 200);
    EXPECT_GT(pixel(down, 32, 42)[2], 200);
    EXPECT_EQ(alpha(down, 32, 52), 0);
    // Half pi: the blade points to +U, red next to the stem.
    const Image right = draw_texture({}, {{uv_of(16, 32, size), kPi / 2, 0.5f, 1.0f}}, o);
    EXPECT_GT(pixel(right, 20, 32)[0], 200);
    EXPECT_GT(pixel(right, 42, 32)[2], 200);
    EXPECT_EQ(alpha(right, 12, 32), 0);
    // The stem at half the height: `at` is the sprite's centre, red above it and blue below.
    o.stem_offset = 0.5f;
    const Image centred = draw_texture({}, {{uv_of(32, 32, size), 0.0f, 0.5f, 1.0f}}, o);
    EXPECT_GT(pixel(centred, 32, 24)[0], 200);
    EXPECT_GT(pixel(centred, 32, 40)[2], 200);
    EXPECT_NEAR(centroid(centred).y, 32.0, 0.5);
  }
  std::filesystem::remove_all(dir);
}

TEST(VinesTexture, BrightnessDarkensBelowOneAndBrightensAboveClampingAt255) {
  const int size = 128;
  DrawOptions o = options_of(size);
  o.leaf_colour = {0.95f, 0.5f, 0.2f};
  const glm::vec2 at = uv_of(64, 16, size);
  auto blade = [&](float brightness) {
    const Image im = draw_texture({}, {{at, 0.0f, 0.75f, brightness}}, o);
    // Halfway down the blade, a little off the midrib.
    const std::uint8_t* p = pixel(im, 70, 16 + 48);
    EXPECT_EQ(p[3], 255);
    return glm::ivec3(p[0], p[1], p[2]);
  };
  const glm::ivec3 dark = blade(0.8f), plain = blade(1.0f), bright = blade(1.2f);
  EXPECT_LT(dark.g, plain.g);
  EXPECT_LT(plain.g, bright.g);
  EXPECT_NEAR(dark.g, 0.8 * plain.g, 2.5);
  EXPECT_NEAR(bright.g, 1.2 * plain.g, 2.5);
  EXPECT_LT(dark.r, plain.r);
  EXPECT_EQ(bright.r, 255) << "0.95 times 1.2 clamps rather than wrapping";
  EXPECT_GE(bright.r, plain.r);
}

TEST(VinesTexture, UnreadableLeafTextureThrowsInputErrorNamingKeyAndPath) {
  const auto dir = temp_dir("bad_sprite");
  auto message = [](const std::string& path) -> std::string {
    DrawOptions o = options_of(32);
    o.leaf_texture = path;
    try {
      draw_texture({}, {{{0.5f, 0.5f}, 0.0f, 0.2f, 1.0f}}, o);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  };
  const std::string missing = (dir / "missing.png").string();
  const std::string m1 = message(missing);
  EXPECT_NE(m1.find("leaf_texture=" + missing), std::string::npos) << m1;
  EXPECT_NE(m1.find("PNG"), std::string::npos) << m1;
  const std::string text = (dir / "leaf.png").string();
  std::ofstream(text) << "not an image\n";
  const std::string m2 = message(text);
  EXPECT_NE(m2.find("leaf_texture=" + text), std::string::npos) << m2;
  EXPECT_NE(m2.find("PNG"), std::string::npos) << m2;
  std::filesystem::remove_all(dir);
}

TEST(VinesTexture, SizeOutsideTheRangeThrowsInputError) {
  DrawOptions o = options_of(0);
  try {
    draw_texture({}, {}, o);
    FAIL() << "size 0 was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("size=0"), std::string::npos) << e.what();
  }
}

// A tangle of tapering random walks with leaves, across many tiles.
void random_vine(std::vector<Stroke>& strokes, std::vector<LeafStamp>& leaves, std::size_t count) {
  Rng rng(3, 1);
  glm::vec2 at(0.5f);
  double heading = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    heading += rng.uniform(-0.6, 0.6);
    glm::vec2 next = at + 0.004f * glm::vec2(std::cos(heading), std::sin(heading));
    if (next.x < 0.02f || next.x > 0.98f || next.y < 0.02f || next.y > 0.98f) next = {0.5f, 0.5f};
    const float w = static_cast<float>(rng.uniform(0.0005, 0.004));
    strokes.push_back({at, next, w, 0.8f * w});
    if (i % 9 == 0)
      leaves.push_back({next, static_cast<float>(rng.uniform(-3.0, 3.0)), static_cast<float>(rng.uniform(0.01, 0.04)),
                        static_cast<float>(rng.uniform(0.8, 1.2))});
    at = next;
  }
}

TEST(VinesTexture, SameBytesForOneAndTwoThreads) {
  std::vector<Stroke> strokes;
  std::vector<LeafStamp> leaves;
  random_vine(strokes, leaves, 20000);
  const DrawOptions o = options_of(1024);
  Image one, two;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
    one = draw_texture(strokes, leaves, o);
  }
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
    two = draw_texture(strokes, leaves, o);
  }
  ASSERT_GT(std::count_if(one.rgba.begin(), one.rgba.end(), [](std::uint8_t v) { return v != 0; }), 100000);
  EXPECT_TRUE(one.rgba == two.rgba);
  // The normal map and the PNG bytes too.
  const auto dir = temp_dir("threads");
  std::string png_one, png_two;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
    one = normal_map(two);
    write_png((dir / "one.png").string(), two);
    png_one = read_file((dir / "one.png").string());
  }
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
    EXPECT_TRUE(normal_map(two).rgba == one.rgba);
    write_png((dir / "two.png").string(), two);
    png_two = read_file((dir / "two.png").string());
  }
  EXPECT_FALSE(png_one.empty());
  EXPECT_TRUE(png_one == png_two);
  std::filesystem::remove_all(dir);
}

TEST(VinesTexture, StrokesAndLeavesCrossTileBordersWithoutSeams) {
  // Tiles are 256 pixels; these cross x = 256 and y = 256 at fractional positions and widths.
  const int size = 512;
  const std::vector<Stroke> strokes = {
      {uv_of(200.3, 100.3, size), uv_of(320.7, 100.3, size), 5.3f / size, 5.3f / size},  // across x = 256
      {uv_of(100.6, 200.2, size), uv_of(100.6, 310.9, size), 3.7f / size, 3.7f / size},  // across y = 256
      {uv_of(180.0, 180.0, size), uv_of(340.0, 340.0, size), 4.1f / size, 4.1f / size},  // through the corner
      {uv_of(200.0, 50.5, size), uv_of(253.3, 50.5, size), 6.8f / size, 6.8f / size},    // its cap ends at 256.7
  };
  const Image im = draw_texture(strokes, {}, options_of(size));
  for (int y = 90; y < 111; ++y)
    for (int x = 250; x < 262; ++x) EXPECT_NEAR(alpha(im, x, y), alpha(im, 240, y), 1) << x << ", " << y;
  for (int x = 90; x < 111; ++x)
    for (int y = 250; y < 262; ++y) EXPECT_NEAR(alpha(im, x, y), alpha(im, x, 240), 1) << x << ", " << y;
  EXPECT_NEAR(alpha(im, 256, 50), 0.7 * 255, 20) << "a cap reaching 0.7 pixels into the next tile";
  EXPECT_EQ(alpha(im, 257, 50), 0);
  // The diagonal: the same coverage in each column and each row around the corner.
  auto diagonal_column = [&](int x) {
    double sum = 0.0;
    for (int y = 200; y < 320; ++y) sum += alpha(im, x, y);
    return sum / 255.0;
  };
  auto diagonal_row = [&](int y) {
    double sum = 0.0;
    for (int x = 200; x < 320; ++x) sum += alpha(im, x, y);
    return sum / 255.0;
  };
  for (int i = 250; i < 262; ++i) {
    EXPECT_NEAR(diagonal_column(i), 4.1 * std::numbers::sqrt2, 0.05) << "column " << i;
    EXPECT_NEAR(diagonal_row(i), 4.1 * std::numbers::sqrt2, 0.05) << "row " << i;
  }
  // A leaf across x = 256: no step in coverage there beyond its neighbours' steps.
  const Image leaf = draw_texture({}, {{uv_of(230.0, 200.0, size), kPi / 2, 0.12f, 1.0f}}, options_of(size));
  const double step = std::abs(column_coverage(leaf, 256) - column_coverage(leaf, 255));
  const double around = std::abs(column_coverage(leaf, 255) - column_coverage(leaf, 254)) +
                        std::abs(column_coverage(leaf, 257) - column_coverage(leaf, 256));
  EXPECT_LE(step, around + 0.05);
  for (int y = 180; y < 220; ++y) EXPECT_NEAR(alpha(leaf, 256, y), (alpha(leaf, 255, y) + alpha(leaf, 257, y)) / 2, 24);
  // A leaf whose tip reaches a few pixels into the next tile.
  const Image tip = draw_texture({}, {{uv_of(200.0, 400.0, size), kPi / 2, 61.0f / size, 1.0f}}, options_of(size));
  EXPECT_GT(column_coverage(tip, 257), 0.2);
}

TEST(VinesTexture, NormalMapIsFlatWhereEmpty) {
  const int size = 128;
  const Image empty = draw_texture({}, {}, options_of(size));
  const Image flat = normal_map(empty);
  ASSERT_EQ(flat.width, size);
  ASSERT_EQ(flat.rgba.size(), empty.rgba.size());
  for (std::size_t i = 0; i < flat.rgba.size(); i += 4) {
    ASSERT_EQ(flat.rgba[i], 128);
    ASSERT_EQ(flat.rgba[i + 1], 128);
    ASSERT_EQ(flat.rgba[i + 2], 255);
    ASSERT_EQ(flat.rgba[i + 3], 255);
  }
  const std::vector<Stroke> strokes = {{uv_of(16, 16, size), uv_of(40, 16, size), 4.0f / size, 4.0f / size}};
  const Image n = normal_map(draw_texture(strokes, {}, options_of(size)));
  for (const auto& [x, y] : {std::pair{100, 100}, {0, 127}, {127, 0}, {28, 40}}) {
    const std::uint8_t* p = pixel(n, x, y);
    EXPECT_EQ(p[0], 128);
    EXPECT_EQ(p[1], 128);
    EXPECT_EQ(p[2], 255);
  }
}

TEST(VinesTexture, NormalMapTiltsAwayFromAHorizontalStrokeOnEachSide) {
  const int size = 256;
  // Centred on row 128, from x = 37 to x = 219 with its caps.
  const std::vector<Stroke> strokes = {{uv_of(40, 128.5, size), uv_of(216, 128.5, size), 6.0f / size, 6.0f / size}};
  const Image texture = draw_texture(strokes, {}, options_of(size));
  const Image n = normal_map(texture);
  // Above the stroke (smaller y, larger v) the surface faces +V: green above 128; below, under 128.
  const std::uint8_t* above = pixel(n, 128, 124);
  const std::uint8_t* below = pixel(n, 128, 132);
  EXPECT_GT(above[1], 150);
  EXPECT_LT(below[1], 106);
  EXPECT_NEAR(above[0], 128, 2);
  EXPECT_NEAR(below[0], 128, 2);
  // On the ridge's top, flat again.
  EXPECT_NEAR(pixel(n, 128, 128)[1], 128, 3);
  // Its left end faces -U (red under 128), its right end +U.
  EXPECT_LT(pixel(n, 37, 128)[0], 106);
  EXPECT_GT(pixel(n, 218, 128)[0], 150);
  EXPECT_NEAR(pixel(n, 37, 128)[1], 128, 2);
  // More strength, more tilt.
  EXPECT_GT(normal_map(texture, 3.0f).rgba[(124 * size + 128) * 4 + 1], above[1]);
}

std::uint32_t big_endian(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v = v << 8 | static_cast<std::uint8_t>(s[at + i]);
  return v;
}

// What decoders may skip: every chunk's CRC-32 and the zlib stream's Adler-32 (stb checks neither).
void expect_valid_checksums(const std::string& png, const Image& image) {
  ASSERT_GT(png.size(), 8u);
  std::string zlib;
  std::size_t at = 8;
  while (at + 12 <= png.size()) {
    const std::uint32_t n = big_endian(png, at);
    ASSERT_LE(at + 12 + n, png.size());
    std::uint32_t crc = 0xffffffffu;
    for (std::size_t i = at + 4; i < at + 8 + n; ++i) {
      crc ^= static_cast<std::uint8_t>(png[i]);
      for (int k = 0; k < 8; ++k) crc = (crc & 1u) != 0 ? 0xedb88320u ^ (crc >> 1) : crc >> 1;
    }
    EXPECT_EQ(~crc, big_endian(png, at + 8 + n)) << "chunk " << png.substr(at + 4, 4) << " at " << at;
    if (png.compare(at + 4, 4, "IDAT") == 0) zlib += png.substr(at + 8, n);
    at += 12 + n;
  }
  EXPECT_EQ(at, png.size());
  ASSERT_GT(zlib.size(), 6u);
  int length = 0;
  const std::unique_ptr<char, void (*)(void*)> raw(
      stbi_zlib_decode_malloc(zlib.data(), static_cast<int>(zlib.size()), &length), &stbi_image_free);
  ASSERT_TRUE(raw);
  ASSERT_EQ(static_cast<std::size_t>(length),
            static_cast<std::size_t>(image.height) * (static_cast<std::size_t>(image.width) * 4 + 1));
  std::uint32_t a = 1, b = 0;
  for (int i = 0; i < length; ++i) {
    a = (a + static_cast<std::uint8_t>(raw.get()[i])) % 65521;
    b = (b + a) % 65521;
  }
  EXPECT_EQ(b << 16 | a, big_endian(zlib, zlib.size() - 4));
}

void expect_png_round_trip(const Image& image, const std::string& path) {
  const std::uint64_t bytes = write_png(path, image);
  EXPECT_EQ(bytes, std::filesystem::file_size(path));
  expect_valid_checksums(read_file(path), image);
  int w = 0, h = 0, channels = 0;
  const std::unique_ptr<stbi_uc, void (*)(void*)> px(stbi_load(path.c_str(), &w, &h, &channels, 4), &stbi_image_free);
  ASSERT_TRUE(px) << stbi_failure_reason();
  ASSERT_EQ(w, image.width);
  ASSERT_EQ(h, image.height);
  EXPECT_EQ(channels, 4);
  EXPECT_TRUE(std::equal(image.rgba.begin(), image.rgba.end(), px.get())) << path;
}

TEST(VinesTexture, WritePngRoundTripsExactly) {
  const auto dir = temp_dir("png");
  std::vector<Stroke> strokes;
  std::vector<LeafStamp> leaves;
  random_vine(strokes, leaves, 3000);
  const Image texture = draw_texture(strokes, leaves, options_of(512));
  expect_png_round_trip(texture, (dir / "texture.png").string());
  expect_png_round_trip(normal_map(texture), (dir / "normal.png").string());
  // Straight alpha as given, even under a faint alpha; runs, repeats and noise; rows in several bands.
  Image noise;
  noise.width = 1023, noise.height = 600;
  noise.rgba.resize(static_cast<std::size_t>(noise.width * noise.height) * 4);
  Rng rng(5, 2);
  for (std::size_t i = 0; i < noise.rgba.size(); ++i)
    noise.rgba[i] = (i / 4000) % 3 == 0   ? 0
                    : (i / 4000) % 3 == 1 ? static_cast<std::uint8_t>(i / 4 % 7)
                                          : static_cast<std::uint8_t>(rng.next_u64());
  expect_png_round_trip(noise, (dir / "noise.png").string());
  // Wider than deflate's window reaches back to the row above.
  Image wide;
  wide.width = 9000, wide.height = 3;
  wide.rgba.assign(static_cast<std::size_t>(wide.width * wide.height) * 4, 7);
  for (std::size_t i = 0; i < wide.rgba.size(); i += 97) wide.rgba[i] = static_cast<std::uint8_t>(i);
  expect_png_round_trip(wide, (dir / "wide.png").string());
  // Deterministic: the same bytes again.
  const std::string first = read_file((dir / "texture.png").string());
  write_png((dir / "texture.png").string(), texture);
  EXPECT_EQ(read_file((dir / "texture.png").string()), first);
  std::filesystem::remove_all(dir);
}

TEST(VinesTexture, WritersNameThePathWhenTheyCannotWrite) {
  const Image image = draw_texture({}, {}, options_of(64));
  // A folder that does not exist, and a device that is always full.
  for (const std::string dir : {"/nonexistent-growbench-dir", "/dev/full"}) {
    const std::string png = dir == "/dev/full" ? dir : dir + "/texture.png";
    const std::string svg = dir == "/dev/full" ? dir : dir + "/skeleton.svg";
    try {
      write_png(png, image);
      ADD_FAILURE() << "write_png " << png << ": no error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(png), std::string::npos) << e.what();
    }
    try {
      write_svg(svg, {{{0.1f, 0.1f}, {0.9f, 0.9f}, 0.01f, 0.01f}}, {}, options_of(64));
      ADD_FAILURE() << "write_svg " << svg << ": no error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(svg), std::string::npos) << e.what();
    }
  }
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(VinesTexture, SvgStrokesAChainOfEqualWidthsAsOnePath) {
  const auto dir = temp_dir("svg");
  const std::string path = (dir / "skeleton.svg").string();
  // A thousand pieces of one width in a chain, then two leaves of one brightness.
  std::vector<Stroke> strokes;
  for (int i = 0; i < 1000; ++i) {
    const float t0 = static_cast<float>(i) / 1000.0f, t1 = static_cast<float>(i + 1) / 1000.0f;
    strokes.push_back({{0.1f + 0.8f * t0, 0.5f + 0.2f * std::sin(6.0f * t0)},
                       {0.1f + 0.8f * t1, 0.5f + 0.2f * std::sin(6.0f * t1)},
                       0.003f,
                       0.003f});
  }
  const std::uint64_t bytes = write_svg(path, strokes, {}, options_of(1024));
  EXPECT_EQ(bytes, std::filesystem::file_size(path));
  std::string svg = read_file(path);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("width=\"1024pt\""), std::string::npos);
  EXPECT_EQ(count(svg, "<path"), 1u);
  EXPECT_EQ(count(svg, " M "), 0u) << "one subpath, no jump";
  EXPECT_GT(count(svg, "L "), 500u);  // cairo merges the pieces that come out collinear
  EXPECT_LT(bytes, 40u * 1000u);
  EXPECT_NE(svg.find("stroke-linecap:round"), std::string::npos);

  write_svg(path, strokes, {{{0.3f, 0.5f}, 0.0f, 0.05f, 1.0f}, {{0.6f, 0.5f}, 1.0f, 0.05f, 1.0f}}, options_of(1024));
  svg = read_file(path);
  EXPECT_EQ(count(svg, "<path"), 2u) << "the vine, and the leaves filled and outlined";
  EXPECT_NE(svg.find("fill:rgb("), std::string::npos);

  DrawOptions dots = options_of(1024);
  dots.style = Style::Dots;
  write_svg(path, strokes, {}, dots);
  svg = read_file(path);
  EXPECT_EQ(count(svg, "<path"), 1u);
  EXPECT_EQ(count(svg, "M "), 1000u) << "a disc per stroke";
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace growbench::vines
