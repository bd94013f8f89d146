// The 3D turtle: interprets a derived string into the shared Plant.
//
// Frame. H (heading), L (left), U (up) with H x L = U; the default start is H = +Y, L = -X, U = +Z, so
// a flat L-system draws in the XY plane seen from +Z. Every rotation is right-handed about one frame
// axis: '+' rotates about U (toward L: a left turn, as in The Algorithmic Beauty of Plants), '&' about
// L (pitch down), '\' about H (roll). The Houdini convention (the default) negates the turn, so its '+'
// turns right as Houdini's documentation says; pitch and roll are the same in both.
//
// Geometry. F and H draw (a node at the new position, parented to the last one; the first F after the
// start, an f or an h puts a root node where it begins); G moves and keeps drawing from the last vertex
// without recording one; f and h move without drawing. Node radius = width / 2. J, K, M place the organs
// their kinds and shapes name, by default a leaf, a flower and a bud (blade +Z along H, +Y along U), scaled by their
// first parameter (default: the current step length) and stamped with their third to fifth parameters. '%' skips to the
// end of the branch (the reference's "cut off remainder of branch", applied when drawing); with surface=avoid, so does
// a step that would end in a solid or cross one at its midpoint, and the step is not taken.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "algorithms/lsystem/derive.hpp"
#include "algorithms/lsystem/lstring.hpp"
#include "algorithms/plant.hpp"

namespace growbench {
class SceneQuery;
}

namespace growbench::lsys {

enum class Convention { Houdini, Abop };

// What the turtle draws with. The values come from the parameter table (make_setup in lsystem.cpp), the
// per-plant ones from the plant being drawn: no member has a default of its own.
// An 8-bit RGB image read by (u, v): pic() and Apply Color.
struct Image {
  int w = 0, h = 0;
  std::vector<std::uint8_t> rgb;  // row 0 at the top; a quarter of floats' memory, the same values on lookup
  // The pixel holding (u, v), v up the image; outside [0, 1]^2, the nearest edge pixel.
  [[nodiscard]] const std::uint8_t* at(double u, double v) const {
    const int x = std::clamp(static_cast<int>(std::floor(u * w)), 0, w - 1);
    const int y = std::clamp(static_cast<int>(std::floor((1.0 - v) * h)), 0, h - 1);
    return &rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 3];
  }
};

// Houdini's Leaf Params A, B, C: the built-in shape setting each of J/K/M's stamps a, b, c sets, when the
// module passes it ("" for none). J/K/M's shape (`base`, a built-in's name with its settings) then becomes
// "base:setting=value,...", a shape of its own in Plant::organ_shapes.
struct OrganStamps {
  std::array<std::string, 3> params;
  std::array<std::string, 3> base;  // for J, K and M
};

struct TurtleSettings {
  double step;             // default F length (m)
  double step_scale;       // " and _
  double angle;            // default turn (degrees)
  double angle_scale;      // ; and @
  double thickness;        // default width (m)
  double thickness_scale;  // ! and ?
  double gravity;          // T: susceptibility (gravity_units per unit |H x down|)
  double gravity_unit;     // radians per unit of T's amount
  double random_scale;     // lengths scaled by 1 + random_scale * uniform(-1, 1)
  glm::dvec2 uv_increment;
  Convention convention;
  double fraction;  // < 1: modules of the last generation are scaled by it (fractional generations); else 1
  bool continuous_length, continuous_angles, continuous_width;
  std::uint64_t seed, stream;
  glm::dvec3 origin;
  glm::dvec3 heading;
  const SceneQuery* wrap;  // when set: every move is mapped onto the nearest surface
  double wrap_offset;
  const SceneQuery* avoid;  // when set: a step into a solid cuts the rest of its branch, as '%' does
  std::uint32_t birth_step;
  std::array<OrganKind, 3> organ_kind;       // what J, K and M place
  std::array<std::uint16_t, 3> organ_shape;  // their shapes: Plant::organ_shapes indices, or kKindShape
  const Image* color_image;                  // Apply Color: each node's Cd from it at the turtle's (u, v)
  const OrganStamps* stamps;                 // Leaf Params A, B, C; null when none is set
  // Houdini's Point Attributes: each node also gets up (the turtle's up vector), lage (vertical_increment
  // per drawn segment along the path) and gen (the rewrite that made the module drawing it: `generation`, the
  // plant's rewrites so far, less the module's age).
  bool point_attributes;
  double vertical_increment;
  int generation;
};

struct TurtleResult {
  std::size_t nodes = 0, organs = 0, polygons = 0;
  std::size_t max_depth = 0;  // deepest branch nesting
};

// Appends the plant drawn by `s` to `plant` (several plants share one Plant). When `states` is not
// null it receives the turtle state at every module (before the module acts), for rules that read it.
TurtleResult interpret(const LString& s, const TurtleSettings& settings, const std::vector<std::string>& strings,
                       Plant& plant, std::vector<TurtleVars>* states);

}  // namespace growbench::lsys
