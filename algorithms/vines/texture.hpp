// Drawing a vine into its texture, as the seed's renderer does on the GPU: the vine's segments as
// anti-aliased strokes whose width follows the thickness, leaves stamped from a sprite, all with cairo.
// Also the normal map from the vines' height field and the skeleton as SVG for print figures.
//
// Coordinates are UV with v up, as in the mesh: (0, 0) is the image's bottom-left corner and its top row
// is v = 1, so a mask and the texture line up pixel for pixel.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace growbench::vines {

// One piece of a vine segment inside one UV chart, from the parent's end (a) to the child's (b). A
// segment that crosses a seam is drawn as one piece per chart.
struct Stroke {
  glm::vec2 a{0.0f}, b{0.0f};
  float width_a = 0.0f, width_b = 0.0f;  // the full width at each end, in UV units (1: the texture's width)
};

// A leaf stamped from the sprite.
struct LeafStamp {
  glm::vec2 at{0.0f};       // where the stem meets the vine (UV)
  float angle = 0.0f;       // radians; 0 hangs the blade toward -V, positive turns it counter-clockwise (v up)
  float length = 0.0f;      // the sprite's height once stamped (stem to tip), UV units
  float brightness = 1.0f;  // multiplies the sprite's colour (the seed varies it in [0.8, 1.2])
};

enum class Style { Lines, Dots };  // dots: a disc at every segment's child end (the seed's "corruption")

struct DrawOptions {
  int size = 1024;  // the texture is size x size pixels
  Style style = Style::Lines;
  glm::vec3 vine_colour{0.2f, 0.33f, 0.1f};   // sRGB in [0, 1]
  glm::vec3 leaf_colour{0.3f, 0.55f, 0.18f};  // the built-in sprite's
  // A user's leaf sprite (PNG, transparent around the leaf), drawn like the built-in one: unrotated it
  // hangs down with its stem at the top centre. "" uses the built-in sprite.
  std::string leaf_texture;
  float stem_offset = 0.0f;  // the stem's attachment below the sprite's top edge, as a fraction of its height
};

// An image, 8 bits per channel, straight (not premultiplied) alpha, row 0 at the top.
struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4
};

// Draws the strokes in order (later ones on top), then the leaves in order. Transparent where nothing is
// drawn. The image is cut into fixed tiles drawn in parallel, so its pixels are the same for any thread
// count. Throws InputError naming the file when options.leaf_texture cannot be read as a PNG.
Image draw_texture(const std::vector<Stroke>& strokes, const std::vector<LeafStamp>& leaves,
                   const DrawOptions& options);

// A tangent-space normal map (OpenGL convention: green is +V) of the height field the texture's alpha
// makes, smoothed over about a stroke's width; flat (128, 128, 255) where nothing is drawn.
Image normal_map(const Image& texture, float strength = 1.0f);

// Writes an image as PNG; returns the bytes written. Throws std::runtime_error naming the file.
std::uint64_t write_png(const std::string& path, const Image& image);

// The strokes (and leaves as outlines) as an SVG of `size` x `size` points. Returns the bytes written.
std::uint64_t write_svg(const std::string& path, const std::vector<Stroke>& strokes,
                        const std::vector<LeafStamp>& leaves, const DrawOptions& options);

}  // namespace growbench::vines
