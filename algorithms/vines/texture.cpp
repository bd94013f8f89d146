// The vine's texture, drawn with cairo in fixed tiles.
//
// Every stroke is the convex hull of its two end discs, one closed polygon, and all of a tile's strokes
// are filled as one path under the nonzero rule. The strokes share one opaque colour, so filling their
// union is what drawing them one after another shows, except that a joint is not anti-aliased twice
// (overlapping fringes would add up to a darker bead at every joint).
//
// Tiles make the pixels independent of the thread count: a tile is drawn from the strokes and leaves
// its bounds touch, in their input order, on its own surface, and the tile grid does not depend on the
// thread count. Cairo turns device coordinates into fixed point after translating by the tile's
// integer origin, which is exact, so a shape that crosses a tile border gets the same coverage on both
// sides as on one large surface.
//
// Leaves are stamped from a premultiplied sprite kept as a mip chain (bilinear sampling never shrinks
// by more than half) with one copy per quantised brightness, built before the tiles are drawn. The
// tiles only read those pixels, each through cairo surfaces of its own: cairo does not promise that
// one surface may be a source in several threads at once.
#include "algorithms/vines/texture.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string_view>

#include <cairo-svg.h>
#include <cairo.h>
#include <fmt/format.h>
#include <png.h>
#include <zlib.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/errors.hpp"

namespace growbench::vines {
namespace {

constexpr int kTile = 256;              // pixels on a side; fixed, so the image is the same for any thread count
constexpr double kArcTolerance = 0.1;   // a disc's polygon strays half this from the circle, in pixels
constexpr int kBrightnessSteps = 64;    // brightness is quantised to 1/kBrightnessSteps
constexpr double kMaxBrightness = 4.0;  // brighter is clamped, which bounds the sprite copies
constexpr int kSpriteWidth = 128;       // the built-in leaf's sprite
constexpr int kSpriteHeight = 256;
constexpr int kMaxSpriteHeight = 1024;  // a user's sprite is shrunk to this first
constexpr int kMinMipHeight = 4;        // the mip chain stops at this height
constexpr int kMaxSize = 1 << 15;       // keeps pixel counts within int, and PNG chunks small
constexpr double kLeafMargin = 2.0;     // pixels around a leaf's box for bilinear sampling

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};
using SurfacePtr = std::unique_ptr<cairo_surface_t, SurfaceDeleter>;
using ContextPtr = std::unique_ptr<cairo_t, ContextDeleter>;

void check(cairo_status_t status, const char* what) {
  if (status != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(fmt::format("vines texture: {}: {}", what, cairo_status_to_string(status)));
}

ContextPtr make_context(cairo_surface_t* s) {
  ContextPtr cr(cairo_create(s));
  check(cairo_status(cr.get()), "cairo_create");
  return cr;
}

// ---------- sprites ----------

// One level of a sprite: cairo's ARGB32 (premultiplied, native-endian words), rows packed.
struct SpriteLevel {
  int width = 0, height = 0;
  std::vector<std::uint32_t> pixels;

  // A cairo surface over these pixels, for one thread's use.
  SurfacePtr surface() const {
    SurfacePtr s(
        cairo_image_surface_create_for_data(reinterpret_cast<unsigned char*>(const_cast<std::uint32_t*>(pixels.data())),
                                            CAIRO_FORMAT_ARGB32, width, height, width * 4));
    check(cairo_surface_status(s.get()), "sprite surface");
    return s;
  }
};

// Level 0 is the full-size sprite; each next level is half as large, down to kMinMipHeight.
using Sprite = std::vector<SpriteLevel>;

SpriteLevel level_from_surface(cairo_surface_t* s) {
  cairo_surface_flush(s);
  SpriteLevel l;
  l.width = cairo_image_surface_get_width(s);
  l.height = cairo_image_surface_get_height(s);
  const int stride = cairo_image_surface_get_stride(s);
  const unsigned char* data = cairo_image_surface_get_data(s);
  l.pixels.resize(static_cast<std::size_t>(l.width) * static_cast<std::size_t>(l.height));
  for (int y = 0; y < l.height; ++y)
    std::copy_n(reinterpret_cast<const std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride), l.width,
                l.pixels.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(l.width));
  return l;
}

Sprite mip_chain(SpriteLevel base) {
  Sprite chain;
  chain.push_back(std::move(base));
  while (chain.back().height > kMinMipHeight) {
    const SpriteLevel& from = chain.back();
    const int w = std::max(1, (from.width + 1) / 2), h = std::max(1, (from.height + 1) / 2);
    SurfacePtr to(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h));
    check(cairo_surface_status(to.get()), "sprite level");
    {
      const ContextPtr cr = make_context(to.get());
      cairo_scale(cr.get(), static_cast<double>(w) / from.width, static_cast<double>(h) / from.height);
      const SurfacePtr src = from.surface();
      cairo_set_source_surface(cr.get(), src.get(), 0, 0);
      // GOOD shrinks with a box filter; PAD keeps a sprite's content that touches its edge from fading.
      cairo_pattern_set_filter(cairo_get_source(cr.get()), CAIRO_FILTER_GOOD);
      cairo_pattern_set_extend(cairo_get_source(cr.get()), CAIRO_EXTEND_PAD);
      cairo_set_operator(cr.get(), CAIRO_OPERATOR_SOURCE);
      cairo_paint(cr.get());
      check(cairo_status(cr.get()), "sprite level");
    }
    chain.push_back(level_from_surface(to.get()));
  }
  return chain;
}

glm::dvec3 clamp_colour(const glm::vec3& c, double scale = 1.0) {
  return glm::clamp(glm::dvec3(c) * scale, glm::dvec3(0.0), glm::dvec3(1.0));
}

void set_colour(cairo_t* cr, const glm::dvec3& c, double alpha = 1.0) {
  cairo_set_source_rgba(cr, c.r, c.g, c.b, alpha);
}

// The built-in leaf's blade, in units of the sprite's height, with the stem's top at the origin and the
// blade hanging toward +y: a pointed ellipse-like outline from the blade's base to its tip.
constexpr double kBladeBase = 0.12, kBladeTip = 0.985, kStemWidth = 0.03;
void append_blade(cairo_t* cr) {
  cairo_move_to(cr, 0.0, kBladeBase);
  cairo_curve_to(cr, 0.26, kBladeBase + 0.06, 0.22, 0.62, 0.0, kBladeTip);
  cairo_curve_to(cr, -0.22, 0.62, -0.26, kBladeBase + 0.06, 0.0, kBladeBase);
  cairo_close_path(cr);
}

SpriteLevel builtin_leaf(const glm::vec3& colour) {
  SurfacePtr s(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, kSpriteWidth, kSpriteHeight));
  check(cairo_surface_status(s.get()), "leaf sprite");
  {
    const ContextPtr owner = make_context(s.get());
    cairo_t* cr = owner.get();
    const glm::dvec3 fill = clamp_colour(colour), dark = clamp_colour(colour, 0.72), light = clamp_colour(colour, 1.25);
    cairo_translate(cr, kSpriteWidth / 2.0, 0.0);
    cairo_scale(cr, kSpriteHeight, kSpriteHeight);
    // Stem, from the top edge into the blade.
    cairo_rectangle(cr, -kStemWidth / 2, 0.0, kStemWidth, kBladeBase + 0.04);
    set_colour(cr, dark);
    cairo_fill(cr);
    // Blade, then everything else clipped to it so the silhouette stays the blade's.
    append_blade(cr);
    set_colour(cr, fill);
    cairo_fill_preserve(cr);
    cairo_clip_preserve(cr);
    cairo_set_line_width(cr, 0.045);  // half of it inside the clip: the darker edge
    set_colour(cr, dark);
    cairo_stroke(cr);
    // Side veins, thin and faint, leaning toward the tip.
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    cairo_set_line_width(cr, 0.009);
    set_colour(cr, light, 0.55);
    for (int i = 0; i < 5; ++i) {
      const double y = kBladeBase + 0.1 + 0.14 * i, reach = 0.2 - 0.025 * i;
      for (const double side : {-1.0, 1.0}) {
        cairo_move_to(cr, 0.0, y);
        cairo_curve_to(cr, side * reach * 0.4, y + 0.03, side * reach * 0.8, y + 0.08, side * reach, y + 0.14);
      }
    }
    cairo_stroke(cr);
    // Midrib: a thin wedge from the base to near the tip.
    cairo_move_to(cr, -0.011, kBladeBase);
    cairo_line_to(cr, 0.011, kBladeBase);
    cairo_line_to(cr, 0.0, kBladeTip - 0.06);
    cairo_close_path(cr);
    set_colour(cr, light, 0.9);
    cairo_fill(cr);
    check(cairo_status(cr), "leaf sprite");
  }
  return level_from_surface(s.get());
}

SpriteLevel read_sprite(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw InputError(fmt::format("leaf_texture={}: no such file; expected a PNG", path));
  SurfacePtr png(cairo_image_surface_create_from_png(path.c_str()));
  const cairo_status_t status = cairo_surface_status(png.get());
  if (status != CAIRO_STATUS_SUCCESS)
    throw InputError(fmt::format("leaf_texture={}: not a readable image ({}); expected a PNG", path,
                                 cairo_status_to_string(status)));
  const int w = cairo_image_surface_get_width(png.get()), h = cairo_image_surface_get_height(png.get());
  if (w <= 0 || h <= 0) throw InputError(fmt::format("leaf_texture={}: the image is empty; expected a PNG", path));
  // Whatever cairo decoded (RGB24 or A8 too) as ARGB32, and no taller than kMaxSpriteHeight: every
  // leaf keeps copies of the sprite, and none is drawn that large.
  const double scale = std::min(1.0, static_cast<double>(kMaxSpriteHeight) / h);
  const int sw = std::max(1, static_cast<int>(std::lround(w * scale))), sh = std::min(h, kMaxSpriteHeight);
  SurfacePtr argb(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, sw, sh));
  check(cairo_surface_status(argb.get()), "leaf sprite");
  {
    const ContextPtr cr = make_context(argb.get());
    cairo_scale(cr.get(), static_cast<double>(sw) / w, static_cast<double>(sh) / h);
    cairo_set_source_surface(cr.get(), png.get(), 0, 0);
    cairo_pattern_set_filter(cairo_get_source(cr.get()), CAIRO_FILTER_GOOD);
    cairo_pattern_set_extend(cairo_get_source(cr.get()), CAIRO_EXTEND_PAD);
    cairo_set_operator(cr.get(), CAIRO_OPERATOR_SOURCE);
    cairo_paint(cr.get());
    check(cairo_status(cr.get()), "leaf sprite");
  }
  return level_from_surface(argb.get());
}

// A sprite level with its colour times step / kBrightnessSteps, clamped (premultiplied: at most alpha).
SpriteLevel brightened(const SpriteLevel& level, int step) {
  SpriteLevel out = level;
  if (step == kBrightnessSteps) return out;
  const auto k = static_cast<std::uint32_t>(step);
  for (std::uint32_t& p : out.pixels) {
    const std::uint32_t a = p >> 24;
    auto scale = [&](int shift) {
      const std::uint32_t c = (p >> shift) & 0xffu;
      return std::min(a, (c * k + kBrightnessSteps / 2) / kBrightnessSteps) << shift;
    };
    p = (a << 24) | scale(16) | scale(8) | scale(0);
  }
  return out;
}

int brightness_step(float brightness) {
  return static_cast<int>(
      std::lround(std::clamp(static_cast<double>(brightness), 0.0, kMaxBrightness) * kBrightnessSteps));
}

// ---------- geometry in pixels ----------

glm::dvec2 to_pixels(const glm::vec2& uv, double size) {
  return {static_cast<double>(uv.x) * size, (1.0 - static_cast<double>(uv.y)) * size};
}

bool finite(const glm::vec2& v) {
  return std::isfinite(v.x) && std::isfinite(v.y);
}

bool drawable(const Stroke& s) {
  return finite(s.a) && finite(s.b) && std::isfinite(s.width_a) && std::isfinite(s.width_b);
}

bool drawable(const LeafStamp& l) {
  return finite(l.at) && std::isfinite(l.angle) && std::isfinite(l.length) && l.length > 0.0f &&
         std::isfinite(l.brightness);
}

struct Box {
  double x0, y0, x1, y1;
};

// The polygon's step for a disc of radius r, so that it strays at most kArcTolerance / 2 from the circle.
double arc_step(double r) {
  if (r <= kArcTolerance * 2) return std::numbers::pi / 3;
  return std::max(2.0 * std::acos(1.0 - kArcTolerance / r), 2.0 * std::numbers::pi / 256);
}

// An arc of radius r around c from the unit direction `from`, turning by `span` (>= 0) in the direction
// of increasing angle, as line segments; the first point is moved or lined to. The inner vertices lie a
// little outside the circle, so that the segments stray as far inside it as their ends do outside; the
// ends stay on it, where a capsule's straight sides touch.
void append_arc(cairo_t* cr, glm::dvec2 c, double r, glm::dvec2 from, double span, bool move) {
  const int n = std::max(1, static_cast<int>(std::ceil(span / arc_step(r))));
  const double step = span / n, cs = std::cos(step), sn = std::sin(step);
  const double outer = 2.0 * r / (1.0 + std::cos(0.5 * step));
  glm::dvec2 d = from;
  if (move)
    cairo_move_to(cr, c.x + r * d.x, c.y + r * d.y);
  else
    cairo_line_to(cr, c.x + r * d.x, c.y + r * d.y);
  for (int i = 1; i <= n; ++i) {
    d = {d.x * cs - d.y * sn, d.x * sn + d.y * cs};
    const double ri = i < n ? outer : r;
    cairo_line_to(cr, c.x + ri * d.x, c.y + ri * d.y);
  }
}

void append_disc(cairo_t* cr, glm::dvec2 c, double r) {
  append_arc(cr, c, r, {1.0, 0.0}, 2.0 * std::numbers::pi, true);
  cairo_close_path(cr);
}

// The convex hull of the discs (a, ra) and (b, rb), turning the same way as append_disc, so that under
// the nonzero rule overlapping pieces make their union.
void append_capsule(cairo_t* cr, glm::dvec2 a, double ra, glm::dvec2 b, double rb) {
  const glm::dvec2 ab = b - a;
  const double d = glm::length(ab);
  if (d <= std::abs(ra - rb)) {  // one disc holds the other
    if (ra >= rb)
      append_disc(cr, a, ra);
    else
      append_disc(cr, b, rb);
    return;
  }
  // The outer tangents touch both discs at the directions u cos(t) +- n sin(t), cos(t) = (ra - rb) / d.
  const glm::dvec2 u = ab / d, n{-u.y, u.x};
  const double c = (ra - rb) / d, s = std::sqrt(std::max(0.0, 1.0 - c * c)), t = std::acos(std::clamp(c, -1.0, 1.0));
  const glm::dvec2 minus = u * c - n * s, plus = u * c + n * s;
  append_arc(cr, b, rb, minus, 2.0 * t, true);                           // b's side, through u
  append_arc(cr, a, ra, plus, 2.0 * std::numbers::pi - 2.0 * t, false);  // a's side, through -u
  cairo_close_path(cr);
}

// ---------- tiles ----------

// Items binned by tile, in input order within each tile (compressed rows).
struct Bins {
  std::vector<std::uint32_t> start;  // tiles + 1
  std::vector<std::uint32_t> items;
};

struct TileSpan {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  // inclusive tile indices; empty when x1 < x0
};

TileSpan tiles_of(const Box& b, int size, int tiles) {
  if (!(b.x1 >= 0.0 && b.y1 >= 0.0 && b.x0 < size && b.y0 < size)) return {};
  auto tile = [&](double p) { return static_cast<int>(std::clamp(std::floor(p / kTile), 0.0, tiles - 1.0)); };
  return {tile(b.x0), tile(b.y0), tile(b.x1), tile(b.y1)};
}

Bins bin(const std::vector<TileSpan>& spans, int tiles) {
  Bins bins;
  bins.start.assign(static_cast<std::size_t>(tiles) * static_cast<std::size_t>(tiles) + 1, 0);
  for (const TileSpan& s : spans)
    for (int ty = s.y0; ty <= s.y1; ++ty)
      for (int tx = s.x0; tx <= s.x1; ++tx) ++bins.start[static_cast<std::size_t>(ty * tiles + tx) + 1];
  for (std::size_t i = 1; i < bins.start.size(); ++i) bins.start[i] += bins.start[i - 1];
  bins.items.resize(bins.start.back());
  std::vector<std::uint32_t> fill(bins.start.begin(), bins.start.end() - 1);
  for (std::size_t i = 0; i < spans.size(); ++i) {
    const TileSpan& s = spans[i];
    for (int ty = s.y0; ty <= s.y1; ++ty)
      for (int tx = s.x0; tx <= s.x1; ++tx)
        bins.items[fill[static_cast<std::size_t>(ty * tiles + tx)]++] = static_cast<std::uint32_t>(i);
  }
  return bins;
}

// A stroke (or dot) in pixels; r == 0 at both ends means nothing to draw.
struct PixelStroke {
  glm::dvec2 a, b;
  double ra, rb;
};

// A leaf ready to stamp: which sprite copy (brightness and level), and the transform from its pixels.
struct PixelLeaf {
  std::uint32_t copy = 0;
  cairo_matrix_t matrix{};
};

void unpremultiply_into(const std::uint32_t* tile, int w, int h, Image& image, int ox, int oy) {
  for (int y = 0; y < h; ++y) {
    const std::uint32_t* row = tile + static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    std::uint8_t* out =
        image.rgba.data() +
        (static_cast<std::size_t>(oy + y) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(ox)) * 4;
    for (int x = 0; x < w; ++x, out += 4) {
      const std::uint32_t p = row[x], a = p >> 24;
      if (a == 0) continue;  // the image starts transparent
      const std::uint32_t r = (p >> 16) & 0xffu, g = (p >> 8) & 0xffu, b = p & 0xffu;
      if (a == 255) {
        out[0] = static_cast<std::uint8_t>(r), out[1] = static_cast<std::uint8_t>(g);
        out[2] = static_cast<std::uint8_t>(b);
      } else {  // cairo's own rounding, so that premultiplying again gives the same pixel
        out[0] = static_cast<std::uint8_t>((r * 255 + a / 2) / a);
        out[1] = static_cast<std::uint8_t>((g * 255 + a / 2) / a);
        out[2] = static_cast<std::uint8_t>((b * 255 + a / 2) / a);
      }
      out[3] = static_cast<std::uint8_t>(a);
    }
  }
}

}  // namespace

Image draw_texture(const std::vector<Stroke>& strokes, const std::vector<LeafStamp>& leaves,
                   const DrawOptions& options) {
  const int size = options.size;
  if (size < 1 || size > kMaxSize)
    throw InputError(fmt::format("size={}: expected a texture size from 1 to {} pixels", size, kMaxSize));
  const double n = size;
  const int tiles = (size + kTile - 1) / kTile;

  // The sprite, read or drawn first so that a bad file fails before any drawing.
  const Sprite sprite =
      mip_chain(options.leaf_texture.empty() ? builtin_leaf(options.leaf_colour) : read_sprite(options.leaf_texture));

  // Strokes in pixels, and the tiles each touches (a pixel of margin for anti-aliasing).
  std::vector<PixelStroke> px(strokes.size());
  std::vector<TileSpan> spans(strokes.size());
  const bool dots = options.style == Style::Dots;
  for (std::size_t i = 0; i < strokes.size(); ++i) {
    const Stroke& s = strokes[i];
    if (!drawable(s)) continue;
    PixelStroke& p = px[i];
    p.b = to_pixels(s.b, n);
    p.rb = std::max(0.0, 0.5 * s.width_b * n);
    if (dots) {
      p.a = p.b, p.ra = 0.0;
    } else {
      p.a = to_pixels(s.a, n);
      p.ra = std::max(0.0, 0.5 * s.width_a * n);
    }
    if (p.ra <= 0.0 && p.rb <= 0.0) continue;
    const double r = std::max(p.ra, p.rb) + 1.0;
    spans[i] = tiles_of({std::min(p.a.x, p.b.x) - r, std::min(p.a.y, p.b.y) - r, std::max(p.a.x, p.b.x) + r,
                         std::max(p.a.y, p.b.y) + r},
                        size, tiles);
  }
  const Bins stroke_bins = bin(spans, tiles);

  // Leaves: their transforms and tiles, then the sprite copies they use (a brightness and a level).
  std::vector<int> steps;
  for (const LeafStamp& l : leaves)
    if (drawable(l)) steps.push_back(brightness_step(l.brightness));
  std::sort(steps.begin(), steps.end());
  steps.erase(std::unique(steps.begin(), steps.end()), steps.end());
  std::vector<PixelLeaf> stamps(leaves.size());
  std::vector<char> used(steps.size() * sprite.size(), 0);
  spans.assign(leaves.size(), TileSpan{});
  const double base_w = sprite[0].width, base_h = sprite[0].height;
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const LeafStamp& l = leaves[i];
    if (!drawable(l)) continue;
    PixelLeaf& p = stamps[i];
    const double height = static_cast<double>(l.length) * n;
    // The smallest level at least as tall as the stamp, so bilinear sampling shrinks by half at most.
    std::size_t level = 0;
    while (level + 1 < sprite.size() && sprite[level + 1].height >= height) ++level;
    const auto step = std::lower_bound(steps.begin(), steps.end(), brightness_step(l.brightness)) - steps.begin();
    p.copy = static_cast<std::uint32_t>(static_cast<std::size_t>(step) * sprite.size() + level);
    used[p.copy] = 1;
    const SpriteLevel& sl = sprite[level];
    // Level pixels -> image pixels: to the stem, scale, turn, then to `at`. A positive angle turns
    // counter-clockwise with v up, which is clockwise in cairo's y-down terms, hence -angle.
    const glm::dvec2 at = to_pixels(l.at, n);
    cairo_matrix_init_translate(&p.matrix, at.x, at.y);
    cairo_matrix_rotate(&p.matrix, -static_cast<double>(l.angle));
    cairo_matrix_scale(&p.matrix, height * base_w / base_h / sl.width, height / sl.height);
    cairo_matrix_translate(&p.matrix, -sl.width / 2.0, -static_cast<double>(options.stem_offset) * sl.height);
    Box box{at.x, at.y, at.x, at.y};
    for (const auto& [cx, cy] : std::array<std::pair<double, double>, 4>{
             {{0.0, 0.0}, {1.0 * sl.width, 0.0}, {0.0, 1.0 * sl.height}, {1.0 * sl.width, 1.0 * sl.height}}}) {
      double x = cx, y = cy;
      cairo_matrix_transform_point(&p.matrix, &x, &y);
      box = {std::min(box.x0, x), std::min(box.y0, y), std::max(box.x1, x), std::max(box.y1, y)};
    }
    spans[i] =
        tiles_of({box.x0 - kLeafMargin, box.y0 - kLeafMargin, box.x1 + kLeafMargin, box.y1 + kLeafMargin}, size, tiles);
  }
  std::vector<SpriteLevel> copies(used.size());
  tbb::parallel_for(std::size_t{0}, used.size(), [&](std::size_t c) {
    if (used[c] != 0) copies[c] = brightened(sprite[c % sprite.size()], steps[c / sprite.size()]);
  });
  const Bins leaf_bins = bin(spans, tiles);

  Image image;
  image.width = image.height = size;
  image.rgba.assign(static_cast<std::size_t>(size) * static_cast<std::size_t>(size) * 4, 0);
  const glm::dvec3 vine = clamp_colour(options.vine_colour);

  // One tile buffer per thread, cleared for each tile: fresh pages cost more than clearing.
  tbb::enumerable_thread_specific<std::vector<std::uint32_t>> buffers;
  tbb::parallel_for(tbb::blocked_range<int>(0, tiles * tiles, 1), [&](const tbb::blocked_range<int>& range) {
    std::vector<std::uint32_t>& buffer = buffers.local();
    for (int t = range.begin(); t != range.end(); ++t) {
      const auto ti = static_cast<std::size_t>(t);
      const std::uint32_t s0 = stroke_bins.start[ti], s1 = stroke_bins.start[ti + 1];
      const std::uint32_t l0 = leaf_bins.start[ti], l1 = leaf_bins.start[ti + 1];
      if (s0 == s1 && l0 == l1) continue;
      const int ox = (t % tiles) * kTile, oy = (t / tiles) * kTile;
      const int tw = std::min(kTile, size - ox), th = std::min(kTile, size - oy);
      buffer.assign(static_cast<std::size_t>(tw) * static_cast<std::size_t>(th), 0);
      SurfacePtr surface(cairo_image_surface_create_for_data(reinterpret_cast<unsigned char*>(buffer.data()),
                                                             CAIRO_FORMAT_ARGB32, tw, th, tw * 4));
      check(cairo_surface_status(surface.get()), "tile surface");
      {
        const ContextPtr owner = make_context(surface.get());
        cairo_t* cr = owner.get();
        cairo_translate(cr, -ox, -oy);
        if (s0 != s1) {
          for (std::uint32_t k = s0; k < s1; ++k) {
            const PixelStroke& p = px[stroke_bins.items[k]];
            append_capsule(cr, p.a, p.ra, p.b, p.rb);
          }
          set_colour(cr, vine);
          cairo_fill(cr);
        }
        // Leaf surfaces made on first use in this tile (see the file comment).
        std::vector<SurfacePtr> sources(l0 != l1 ? copies.size() : 0);
        for (std::uint32_t k = l0; k < l1; ++k) {
          const PixelLeaf& p = stamps[leaf_bins.items[k]];
          SurfacePtr& src = sources[p.copy];
          if (!src) src = copies[p.copy].surface();
          cairo_save(cr);
          cairo_transform(cr, &p.matrix);
          cairo_set_source_surface(cr, src.get(), 0, 0);
          cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_BILINEAR);
          cairo_paint(cr);
          cairo_restore(cr);
        }
        check(cairo_status(cr), "drawing a tile");
      }
      cairo_surface_flush(surface.get());
      unpremultiply_into(buffer.data(), tw, th, image, ox, oy);
    }
  });
  return image;
}

// ---------- normal map ----------

Image normal_map(const Image& texture, float strength) {
  const int w = texture.width, h = texture.height;
  if (w < 0 || h < 0 || texture.rgba.size() != static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4)
    throw std::invalid_argument("normal_map: the image's pixels do not match its size");
  if (!std::isfinite(strength)) throw std::invalid_argument("normal_map: the strength is not a finite number");
  Image out;
  out.width = w, out.height = h;
  out.rgba.resize(texture.rgba.size());
  if (w == 0 || h == 0) return out;
  const auto uw = static_cast<std::size_t>(w);

  // A Gaussian whose width follows the image's size, since the strokes' widths in pixels do too.
  const double sigma = std::max(0.75, std::max(w, h) / 2048.0);
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  std::vector<float> kernel(static_cast<std::size_t>(2 * radius + 1));
  double sum = 0.0;
  for (int i = -radius; i <= radius; ++i) sum += std::exp(-0.5 * i * i / (sigma * sigma));
  for (int i = -radius; i <= radius; ++i)
    kernel[static_cast<std::size_t>(i + radius)] = static_cast<float>(std::exp(-0.5 * i * i / (sigma * sigma)) / sum);

  // Bands of rows, each blurred from the rows it needs with its own scratch buffers (no image-sized
  // temporaries, whose fresh pages would cost more than the arithmetic). A band repeats the horizontal
  // pass over its neighbours' edge rows; every value is summed in the same order wherever it is
  // computed, so the bands and the thread count do not change the result.
  struct Scratch {
    std::vector<float> padded, across, height;
  };
  tbb::enumerable_thread_specific<Scratch> scratch;
  constexpr int kBand = 64;
  const int bands = (h + kBand - 1) / kBand;
  const auto r = static_cast<std::size_t>(radius), taps = kernel.size();
  // Rows padded to whole blocks of kBlock floats: a loop of a fixed count over restrict pointers is one
  // the compiler vectorises at -O2.
  constexpr std::size_t kBlock = 16;
  const std::size_t stride = (uw + kBlock - 1) / kBlock * kBlock;
  auto add_scaled = [stride](float* __restrict to, const float* __restrict from, float k) {
    for (std::size_t xb = 0; xb < stride; xb += kBlock)
      for (std::size_t j = 0; j < kBlock; ++j) to[xb + j] += k * from[xb + j];
  };
  tbb::parallel_for(0, bands, [&](int band) {
    Scratch& sc = scratch.local();
    const int y0 = band * kBand, y1 = std::min(h, y0 + kBand);
    const int hy0 = std::max(0, y0 - 1), hy1 = std::min(h, y1 + 1);              // rows of `height`
    const int ay0 = std::max(0, hy0 - radius), ay1 = std::min(h, hy1 + radius);  // rows of `across`
    sc.padded.assign(stride + 2 * r, 0.0f);
    sc.across.assign(stride * static_cast<std::size_t>(ay1 - ay0), 0.0f);
    sc.height.assign(stride * static_cast<std::size_t>(hy1 - hy0), 0.0f);
    // Along rows, the edge pixels repeated beyond the image.
    for (int y = ay0; y < ay1; ++y) {
      const std::uint8_t* in = texture.rgba.data() + static_cast<std::size_t>(y) * uw * 4;
      bool empty = true;
      for (std::size_t x = 0; x < uw; ++x) {
        sc.padded[x + r] = in[4 * x + 3] * (1.0f / 255.0f);
        empty = empty && in[4 * x + 3] == 0;
      }
      if (empty) continue;
      std::fill_n(sc.padded.begin(), r, sc.padded[r]);
      std::fill_n(sc.padded.begin() + static_cast<std::ptrdiff_t>(uw + r), r, sc.padded[uw + r - 1]);
      float* row = sc.across.data() + static_cast<std::size_t>(y - ay0) * stride;
      for (std::size_t i = 0; i < taps; ++i) add_scaled(row, sc.padded.data() + i, kernel[i]);
    }
    // Along columns, the edge rows repeated.
    for (int y = hy0; y < hy1; ++y) {
      float* row = sc.height.data() + static_cast<std::size_t>(y - hy0) * stride;
      for (int i = -radius; i <= radius; ++i)
        add_scaled(row, sc.across.data() + static_cast<std::size_t>(std::clamp(y + i, 0, h - 1) - ay0) * stride,
                   kernel[static_cast<std::size_t>(i + radius)]);
    }
    // Central differences; image y grows down while v grows up, hence the y term's sign.
    for (int y = y0; y < y1; ++y) {
      const float* row = sc.height.data() + static_cast<std::size_t>(y - hy0) * stride;
      const float* up = sc.height.data() + static_cast<std::size_t>(std::max(y - 1, 0) - hy0) * stride;
      const float* down = sc.height.data() + static_cast<std::size_t>(std::min(y + 1, h - 1) - hy0) * stride;
      std::uint8_t* o = out.rgba.data() + static_cast<std::size_t>(y) * uw * 4;
      for (int x = 0; x < w; ++x, o += 4) {
        const float dx = 0.5f * (row[std::min(x + 1, w - 1)] - row[std::max(x - 1, 0)]);
        const float dy = 0.5f * (down[x] - up[x]);
        if (dx == 0.0f && dy == 0.0f) {
          o[0] = 128, o[1] = 128, o[2] = 255, o[3] = 255;
          continue;
        }
        const glm::vec3 n = glm::normalize(glm::vec3(-strength * dx, strength * dy, 1.0f));
        auto encode = [](float c) { return static_cast<std::uint8_t>(std::clamp(c * 127.5f + 128.0f, 0.0f, 255.0f)); };
        o[0] = encode(n.x), o[1] = encode(n.y), o[2] = encode(n.z), o[3] = 255;
      }
    }
  });
  return out;
}

// ---------- PNG ----------
//
// libpng at zlib's fastest level with the Up filter and run-length matching: a vine texture is mostly
// empty rows and flat colour, which that combination turns into long runs, and the default settings
// (adaptive filters, level 6) spend seconds on a large texture for a file a third smaller.
namespace {

struct PngWrite {
  std::FILE* file = nullptr;
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngWrite() {
    if (png) png_destroy_write_struct(&png, info ? &info : nullptr);
    if (file) std::fclose(file);
  }
};

[[noreturn]] void png_failed(png_structp png, png_const_charp message) {
  *static_cast<std::string*>(png_get_error_ptr(png)) = message;
  png_longjmp(png, 1);
}

}  // namespace

std::uint64_t write_png(const std::string& path, const Image& image) {
  const int w = image.width, h = image.height;
  if (w <= 0 || h <= 0 || image.rgba.size() != static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4)
    throw std::runtime_error(fmt::format("write_png {}: the image is empty or its pixels do not match its size", path));
  std::string why;
  std::vector<png_const_bytep> rows(static_cast<std::size_t>(h));
  for (int y = 0; y < h; ++y)
    rows[static_cast<std::size_t>(y)] = image.rgba.data() + static_cast<std::size_t>(y) * w * 4;
  {
    PngWrite pw;
    pw.file = std::fopen(path.c_str(), "wb");
    if (!pw.file) throw std::runtime_error(fmt::format("write_png {}: cannot open: {}", path, std::strerror(errno)));
    pw.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &why, png_failed, nullptr);
    pw.info = pw.png ? png_create_info_struct(pw.png) : nullptr;
    if (!pw.info) throw std::runtime_error(fmt::format("write_png {}: libpng could not start", path));
    // libpng reports errors by longjmp: only trivially destructible locals live between here and the end.
    if (setjmp(png_jmpbuf(pw.png)) == 0) {
      png_init_io(pw.png, pw.file);
      png_set_IHDR(pw.png, pw.info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), 8, PNG_COLOR_TYPE_RGBA,
                   PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
      png_set_filter(pw.png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
      png_set_compression_level(pw.png, 1);
      png_set_compression_strategy(pw.png, Z_RLE);
      png_write_info(pw.png, pw.info);
      png_write_image(pw.png, const_cast<png_bytepp>(rows.data()));
      png_write_end(pw.png, nullptr);
      if (std::fflush(pw.file) != 0) why = std::strerror(errno);
    } else if (why.empty()) {
      why = "libpng failed";
    }
    if (std::fclose(pw.file) != 0 && why.empty()) why = std::strerror(errno);
    pw.file = nullptr;
  }
  if (!why.empty()) throw std::runtime_error(fmt::format("write_png {}: cannot write: {}", path, why));
  return std::filesystem::file_size(path);
}

// ---------- SVG ----------
//
// For print: strokes become polylines stroked with round caps and joins, one path per width class, a
// new subpath wherever a stroke does not start where the previous one of its class ended. Widths are
// classed on a log scale (a taper becomes steps too small to see), which is also what keeps the file
// small: one element per class, not per stroke. The strokes share one opaque colour, so their order
// does not show. Leaves are the built-in leaf's outline (for a user sprite too), grouped the same way
// by brightness class, so a leaf may land under an earlier one of a darker class. Coordinates are
// rounded to a sixteenth of a point, which cairo's SVG backend prints in a few digits.
namespace {

constexpr double kSvgWidthClasses = 16;       // per doubling of the width
constexpr double kSvgBrightnessClasses = 16;  // per unit of brightness
constexpr double kSvgGrid = 16;               // coordinates per point

cairo_status_t append_to_string(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

// Cairo names an SVG's group after a count of the surfaces the process has made ("surface179"), which
// would make the same drawing differ from run to run; the name becomes a fixed one.
std::string fixed_surface_names(const std::string& svg) {
  std::string out;
  out.reserve(svg.size());
  constexpr std::string_view kName = "\"surface";
  std::size_t at = 0;
  for (std::size_t hit; (hit = svg.find(kName, at)) != std::string::npos;) {
    std::size_t end = hit + kName.size();
    while (end < svg.size() && std::isdigit(static_cast<unsigned char>(svg[end]))) ++end;
    out.append(svg, at, hit - at);
    out += end > hit + kName.size() ? "\"vines" : std::string(kName);
    at = end;
  }
  out.append(svg, at, std::string::npos);
  return out;
}

glm::dvec2 on_grid(const glm::vec2& uv, double size) {
  const glm::dvec2 p = to_pixels(uv, size);
  return glm::round(p * kSvgGrid) / kSvgGrid;
}

// Indices of the items with a class, sorted by class and then by index.
std::vector<std::pair<long, std::uint32_t>> by_class(std::size_t n, const auto& class_of) {
  std::vector<std::pair<long, std::uint32_t>> order;
  for (std::size_t i = 0; i < n; ++i)
    if (const std::optional<long> c = class_of(i)) order.emplace_back(*c, static_cast<std::uint32_t>(i));
  std::sort(order.begin(), order.end());
  return order;
}

}  // namespace

std::uint64_t write_svg(const std::string& path, const std::vector<Stroke>& strokes,
                        const std::vector<LeafStamp>& leaves, const DrawOptions& options) {
  const int size = options.size;
  if (size < 1 || size > kMaxSize)
    throw InputError(fmt::format("size={}: expected a texture size from 1 to {} pixels", size, kMaxSize));
  const double n = size;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!file) throw std::runtime_error(fmt::format("write_svg {}: cannot open: {}", path, std::strerror(errno)));
  std::string svg;
  {
    SurfacePtr surface(cairo_svg_surface_create_for_stream(&append_to_string, &svg, n, n));
    check(cairo_surface_status(surface.get()), "SVG surface");
    cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PT);
    const ContextPtr owner = make_context(surface.get());
    cairo_t* cr = owner.get();
    set_colour(cr, clamp_colour(options.vine_colour));
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);

    if (options.style == Style::Dots) {
      for (const Stroke& s : strokes) {
        if (!drawable(s) || !(s.width_b > 0.0f)) continue;
        const glm::dvec2 b = on_grid(s.b, n);
        cairo_new_sub_path(cr);
        cairo_arc(cr, b.x, b.y, 0.5 * s.width_b * n, 0.0, 2.0 * std::numbers::pi);
      }
      cairo_fill(cr);
    } else {
      const auto order = by_class(strokes.size(), [&](std::size_t i) -> std::optional<long> {
        const Stroke& s = strokes[i];
        const double w = 0.5 * (static_cast<double>(s.width_a) + s.width_b) * n;
        if (!drawable(s) || !(w > 0.0)) return std::nullopt;
        return std::lround(std::log2(w) * kSvgWidthClasses);
      });
      for (std::size_t k = 0; k < order.size();) {
        const long c = order[k].first;
        const Stroke* last = nullptr;
        for (; k < order.size() && order[k].first == c; ++k) {
          const Stroke& s = strokes[order[k].second];
          if (last == nullptr || last->b != s.a) {
            const glm::dvec2 a = on_grid(s.a, n);
            cairo_move_to(cr, a.x, a.y);
          }
          const glm::dvec2 b = on_grid(s.b, n);
          cairo_line_to(cr, b.x, b.y);
          last = &s;
        }
        cairo_set_line_width(cr, std::exp2(static_cast<double>(c) / kSvgWidthClasses));
        cairo_stroke(cr);
      }
    }

    const auto order = by_class(leaves.size(), [&](std::size_t i) -> std::optional<long> {
      const LeafStamp& l = leaves[i];
      if (!drawable(l)) return std::nullopt;
      return std::lround(std::clamp(static_cast<double>(l.brightness), 0.0, kMaxBrightness) * kSvgBrightnessClasses);
    });
    cairo_set_line_width(cr, n / 4096.0);  // the leaves' edges: about a pixel of a large texture
    for (std::size_t k = 0; k < order.size();) {
      const long c = order[k].first;
      for (; k < order.size() && order[k].first == c; ++k) {
        const LeafStamp& l = leaves[order[k].second];
        const glm::dvec2 at = on_grid(l.at, n);
        cairo_save(cr);
        cairo_translate(cr, at.x, at.y);
        cairo_rotate(cr, -static_cast<double>(l.angle));
        cairo_scale(cr, static_cast<double>(l.length) * n, static_cast<double>(l.length) * n);
        cairo_translate(cr, 0.0, -static_cast<double>(options.stem_offset));
        cairo_rectangle(cr, -kStemWidth / 2, 0.0, kStemWidth, kBladeBase + 0.04);
        append_blade(cr);
        cairo_restore(cr);  // the path stays, in device space
      }
      const double brightness = static_cast<double>(c) / kSvgBrightnessClasses;
      set_colour(cr, clamp_colour(options.leaf_colour, brightness));
      cairo_fill_preserve(cr);
      set_colour(cr, clamp_colour(options.leaf_colour, 0.72 * brightness));
      cairo_stroke(cr);
    }
    check(cairo_status(cr), "drawing the SVG");
    cairo_surface_finish(surface.get());
    if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS)
      throw std::runtime_error(fmt::format("write_svg {}: cannot write: {}", path,
                                           cairo_status_to_string(cairo_surface_status(surface.get()))));
  }
  svg = fixed_surface_names(svg);
  const bool written = std::fwrite(svg.data(), 1, svg.size(), file.get()) == svg.size();
  if (std::fclose(file.release()) != 0 || !written)
    throw std::runtime_error(fmt::format("write_svg {}: cannot write: {}", path, std::strerror(errno)));
  return svg.size();
}

}  // namespace growbench::vines
