#include "algorithms/lsystem/turtle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <unordered_map>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>

#include "algorithms/organ_shapes.hpp"
#include "core/errors.hpp"
#include "core/random.hpp"
#include "scenes/scene_query.hpp"

namespace growbench::lsys {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Whether a position survives the cast to the plant's floats (finite, within float range).
bool fits_float(const glm::dvec3& p) {
  constexpr double kMax = std::numeric_limits<float>::max();
  return std::abs(p.x) <= kMax && std::abs(p.y) <= kMax && std::abs(p.z) <= kMax;
}

struct State {
  glm::dvec3 pos{0.0}, H{0.0, 1.0, 0.0}, L{-1.0, 0.0, 0.0}, U{0.0, 0.0, 1.0};
  double length = 0.0, width = 0.0, angle = 0.0, arc = 0.0, u = 0.0, v = 0.0;
  double lage = 0.0;  // Point Attributes' lage: vertical_increment per drawn segment along the path
  std::int32_t node = kNoParent;
  std::int32_t group = -1;
  std::uint32_t shoot = 0;
  std::uint32_t attrs = 0;  // index of the attribute snapshot in force
  std::uint16_t order = 0;
};

// Rotates (a, b) by theta in their plane: a' = a cos + b sin, b' = b cos - a sin.
inline void rotate_pair(glm::dvec3& a, glm::dvec3& b, double c, double s) {
  const glm::dvec3 a2 = a * c + b * s;
  b = b * c - a * s;
  a = a2;
}

glm::dvec3 rotate_about(const glm::dvec3& v, const glm::dvec3& axis, double c, double s) {
  return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.0 - c);
}

class Interpreter {
 public:
  Interpreter(const LString& str, const TurtleSettings& s, const std::vector<std::string>& strings, Plant& plant,
              std::vector<TurtleVars>* states)
      : str_(str), s_(s), strings_(strings), plant_(plant), states_(states) {}

  TurtleResult run() {
    State t;
    t.pos = s_.origin;
    t.H = glm::length(s_.heading) > 0 ? glm::normalize(s_.heading) : glm::dvec3(0, 1, 0);
    glm::dvec3 side = glm::cross(glm::dvec3(0, 0, 1), t.H);
    if (glm::length(side) < 1e-9) side = glm::cross(glm::dvec3(0, 1, 0), t.H);
    t.L = glm::normalize(side);
    t.U = glm::cross(t.H, t.L);
    t.length = s_.step;
    t.width = s_.thickness;
    t.angle = s_.angle;
    for (const auto& nd : plant_.nodes)
      shoot_counter_ = std::max(shoot_counter_, nd.shoot + 1);  // after earlier plants'
    t.shoot = next_shoot();
    if (s_.wrap) snap_start(t);
    const std::size_t first_node = plant_.nodes.size();
    first_node_ = first_node;
    const std::size_t first_organ = plant_.organs.size();
    const std::size_t first_poly = plant_.polygons.size();
    attr_snapshots_.assign(1, {});
    if (states_) states_->resize(str_.size());

    const std::uint16_t* sym = str_.symbols.data();
    const float* par = str_.params.data();
    const std::size_t n = str_.size();
    {  // one node per F or H (plus roots): reserve once instead of growing
      std::size_t draws = 0;
      for (std::size_t m = 0; m < n; ++m) {
        const char c = symbol_of(sym[m]);
        draws += (c == 'F') | (c == 'H');
      }
      plant_.nodes.reserve(plant_.nodes.size() + draws + 1);
    }
    std::size_t p = 0;
    const double turn_sign = s_.convention == Convention::Houdini ? -1.0 : 1.0;
    for (std::size_t m = 0; m < n; ++m) {
      const std::uint16_t w = sym[m];
      const char c = symbol_of(w);
      const int k = count_of(w);
      const float* a = par + p;
      p += static_cast<std::size_t>(k);
      if (states_) record(t, m);
      const bool fresh = is_new(w) && s_.fraction < 1.0;
      switch (c) {
        case 'F':
        case 'H':
        case 'G':
        case 'f':
        case 'h': {
          double len = k > 0 ? a[0] : t.length;
          if (c == 'H' || c == 'h') len *= 0.5;
          if (s_.random_scale != 0.0) {
            Rng rng(s_.seed, s_.stream * 0x100000001ull + 7, m);
            len *= std::max(0.0, 1.0 + s_.random_scale * rng.uniform(-1.0, 1.0));
          }
          if (fresh && s_.continuous_length) len *= s_.fraction;
          double width = k > 1 ? a[1] : t.width;
          if (fresh && s_.continuous_width) width *= s_.fraction;
          const bool draw = c == 'F' || c == 'H';
          if (s_.point_attributes) module_gen_ = s_.generation - (str_.ages.size() > m ? str_.ages[m] : 0);
          if (draw && t.node == kNoParent) t.node = add_node(t.pos, width, kNoParent, t, {});
          const glm::dvec3 before = t.pos;
          t.pos += t.H * len;
          if (!fits_float(t.pos))
            throw InputError(
                fmt::format("L-system: module {} ('{}', step {:g}) moved the turtle to ({:g}, {:g}, {:g}), "
                            "beyond the range of a 32-bit float; expected steps that keep the plant "
                            "within +-{:g}",
                            m, c, len, t.pos.x, t.pos.y, t.pos.z, std::numeric_limits<float>::max()));
          if (s_.wrap) snap(t);
          if (s_.avoid && enters_solid(before, t.pos)) {  // the branch ends before the solid
            t.pos = before;
            skip_branch(t, m, p);
            break;
          }
          if (c == 'F' || c == 'H' || c == 'G') t.arc += glm::length(t.pos - before);
          if (draw) {
            t.lage += s_.vertical_increment;
            t.node = add_node(t.pos, width, t.node, t, k > 2 ? tube_shape(a, k) : TubeShape{});
          } else if (c == 'f' || c == 'h')
            t.node = kNoParent;
          break;
        }
        case 'J':
        case 'K':
        case 'M': {
          Organ o;
          o.position = glm::vec3(t.pos);
          o.orientation = glm::quat_cast(glm::mat3(glm::vec3(t.L), glm::vec3(t.U), glm::vec3(t.H)));
          double size = k > 0 ? a[0] : t.length;
          if (fresh && s_.continuous_length) size *= s_.fraction;
          o.size = static_cast<float>(std::max(0.0, size));
          const std::size_t which = c == 'J' ? 0 : c == 'K' ? 1 : 2;
          o.kind = s_.organ_kind[which];
          o.shape = s_.organ_shape[which];
          o.node = t.node;
          for (int q = 2; q < k && q < 5; ++q) o.stamp[static_cast<std::size_t>(q - 2)] = a[q];
          if (k > 2 && s_.stamps) o.shape = stamped_shape(c, which, a, k);
          plant_.organs.push_back(o);
          break;
        }
        case 'T': {
          const double g = (k > 0 ? a[0] : s_.gravity) * s_.gravity_unit;
          const glm::dvec3 down(0.0, -1.0, 0.0);
          const glm::dvec3 axis = glm::cross(t.H, down);
          const double sin_between = glm::length(axis);
          if (sin_between > 1e-12 && g != 0.0) {
            const glm::dvec3 ax = axis / sin_between;
            // ABOP's bend, g |H x down|, toward -Y and never past it: at most the angle left to straight down
            // (for g < 0, up to straight up), so a large g hangs the heading rather than swinging it back up.
            const double to_down = std::atan2(sin_between, glm::dot(t.H, down));
            const double alpha = std::clamp(g * sin_between, to_down - std::numbers::pi, to_down);
            const double cs = std::cos(alpha), sn = std::sin(alpha);
            t.H = glm::normalize(rotate_about(t.H, ax, cs, sn));
            t.L = glm::normalize(rotate_about(t.L, ax, cs, sn));
            t.U = glm::cross(t.H, t.L);
          }
          break;
        }
        case '+':
        case '-':
        case '&':
        case '^':
        case '\\':
        case '/': {
          double ang = k > 0 ? a[0] : t.angle;
          if (fresh && s_.continuous_angles) ang *= s_.fraction;
          double cs, sn;
          sincos_deg(ang, cs, sn);
          switch (c) {
            case '+':
              rotate_pair(t.H, t.L, cs, turn_sign * sn);
              break;  // about U
            case '-':
              rotate_pair(t.H, t.L, cs, -turn_sign * sn);
              break;
            case '&':
              rotate_pair(t.H, t.U, cs, -sn);
              break;  // about L: pitch down
            case '^':
              rotate_pair(t.H, t.U, cs, sn);
              break;
            case '\\':
              rotate_pair(t.L, t.U, cs, sn);
              break;  // about H: roll
            default:
              rotate_pair(t.L, t.U, cs, -sn);
              break;  // '/'
          }
          break;
        }
        case '|':
          t.H = -t.H;
          t.L = -t.L;
          break;
        case '*':
          t.L = -t.L;
          t.U = -t.U;
          break;
        case '~':
          random_turn(t, k > 0 ? a[0] : 180.0, m);
          break;
        case '"':
          t.length *= k > 0 ? a[0] : s_.step_scale;
          break;
        case '_':
          t.length /= k > 0 ? a[0] : s_.step_scale;
          break;
        case '!':
          t.width *= k > 0 ? a[0] : s_.thickness_scale;
          break;
        case '?':
          t.width /= k > 0 ? a[0] : s_.thickness_scale;
          break;
        case ';':
          t.angle *= k > 0 ? a[0] : s_.angle_scale;
          break;
        case '@':
          t.angle /= k > 0 ? a[0] : s_.angle_scale;
          break;
        case '\'':
          t.u += k > 0 ? a[0] : s_.uv_increment.x;
          break;
        case '#':
          t.v += k > 0 ? a[0] : s_.uv_increment.y;
          break;
        case '%':  // skip to the end of this branch; its ']' then pops as usual
          skip_branch(t, m, p);
          break;
        case '$': {
          if (k >= 3) {
            const glm::dvec3 d = glm::dvec3(a[0], a[1], a[2]) - t.pos;
            if (glm::length(d) > 1e-12) {
              const glm::dvec3 h = glm::normalize(d);
              // keep the frame: the minimal rotation from the old heading
              const glm::dvec3 axis = glm::cross(t.H, h);
              const double sn = glm::length(axis), cs = glm::dot(t.H, h);
              if (sn > 1e-12) {
                const glm::dvec3 ax = axis / sn;
                t.L = rotate_about(t.L, ax, cs, sn);
              }
              t.H = h;
            }
          }
          const glm::dvec3 side = glm::cross(glm::dvec3(0.0, 1.0, 0.0), t.H);
          if (glm::length(side) > 1e-9) {
            t.L = glm::normalize(side);
          } else {
            t.L = glm::normalize(t.L - t.H * glm::dot(t.L, t.H));
          }
          t.U = glm::cross(t.H, t.L);
          break;
        }
        case '[':
          stack_.push_back(t);
          t.order = static_cast<std::uint16_t>(std::min<int>(t.order + 1, 65535));
          t.shoot = next_shoot();
          result_.max_depth = std::max(result_.max_depth, stack_.size());
          break;
        case ']':
          if (!stack_.empty()) {
            t = stack_.back();
            stack_.pop_back();
          }
          break;
        case '{':
          polys_.emplace_back();
          break;
        case '.':
          if (!polys_.empty()) polys_.back().vertices.push_back(glm::vec3(t.pos));
          break;
        case '}':
          if (!polys_.empty()) {
            if (polys_.back().vertices.size() >= 3) plant_.polygons.push_back(std::move(polys_.back()));
            polys_.pop_back();
          }
          break;
        case 'g':
          if (k > 0) {
            t.group = static_cast<std::int32_t>(std::lround(a[0]));
          } else {
            t.group = group_counter_++;
          }
          if (!groups_used_) node_groups_.assign(plant_.nodes.size() - first_node, -1);
          groups_used_ = true;
          break;
        case 'a':
          if (k >= 2 && a[0] >= 0 && static_cast<std::size_t>(a[0]) < strings_.size()) {
            const auto id = static_cast<std::size_t>(a[0]);
            auto snap = attr_snapshots_[t.attrs];
            if (snap.size() <= id) snap.resize(id + 1);
            snap[id] = {a[1], k > 2 ? a[2] : 0.0f, k > 3 ? a[3] : 0.0f, static_cast<float>(std::min(k - 1, 3))};
            attr_components_.resize(std::max(attr_components_.size(), id + 1), 0);
            attr_components_[id] = std::max(attr_components_[id], std::min(k - 1, 3));
            attr_snapshots_.push_back(std::move(snap));
            if (!attrs_used_) node_attrs_.assign(plant_.nodes.size() - first_node, 0);
            attrs_used_ = true;
            t.attrs = static_cast<std::uint32_t>(attr_snapshots_.size() - 1);
          }
          break;
        default:
          break;  // any other symbol does nothing to the turtle
      }
    }
    finish_attributes(first_node);
    result_.nodes = plant_.nodes.size() - first_node;
    result_.organs = plant_.organs.size() - first_organ;
    result_.polygons = plant_.polygons.size() - first_poly;
    return result_;
  }

 private:
  void sincos_deg(double deg, double& c, double& s) {
    if (deg != cached_angle_) {
      cached_angle_ = deg;
      cached_cos_ = std::cos(deg * kDeg);
      cached_sin_ = std::sin(deg * kDeg);
    }
    c = cached_cos_;
    s = cached_sin_;
  }
  std::uint32_t next_shoot() { return shoot_counter_++; }
  void record(const State& t, std::size_t m) {
    (*states_)[m] = {static_cast<float>(t.pos.x), static_cast<float>(t.pos.y),  static_cast<float>(t.pos.z),
                     static_cast<float>(t.arc),   static_cast<float>(t.length), static_cast<float>(t.width),
                     static_cast<float>(t.u),     static_cast<float>(t.v)};
  }
  // F(l, w, s, d)'s s cross sections and d divisions, rounded and clamped to what Plant::validate accepts
  // (a value below 1 leaves it to the mesher).
  static TubeShape tube_shape(const float* a, int k) {
    auto count = [](float v, int lo, int hi) -> std::uint16_t {
      if (!(v >= 0.5f)) return 0;
      return static_cast<std::uint16_t>(std::clamp(static_cast<int>(std::lround(std::min(v, 1e4f))), lo, hi));
    };
    TubeShape shape;
    shape.sections = count(a[2], 1, kMaxTubeSections);
    if (k > 3) shape.divisions = count(a[3], kMinTubeDivisions, kMaxTubeDivisions);
    return shape;
  }
  std::int32_t add_node(const glm::dvec3& pos, double width, std::int32_t parent, const State& t, TubeShape tube) {
    PlantNode nd;
    nd.position = glm::vec3(pos);
    nd.radius = static_cast<float>(std::max(0.0, width * 0.5));
    nd.parent = parent;
    nd.order = t.order;
    nd.shoot = t.shoot;
    nd.birth_step = s_.birth_step;
    plant_.nodes.push_back(nd);
    // per-node groups and attribute snapshots are kept only once a g or an a has appeared (every node
    // before that has no group and the empty snapshot)
    if (groups_used_) node_groups_.push_back(t.group);
    if (attrs_used_) node_attrs_.push_back(t.attrs);
    if (s_.color_image) {  // Apply Color: the image's sRGB pixel at the turtle's (u, v), as linear Cd
      const std::uint8_t* px = s_.color_image->at(t.u, t.v);
      const glm::vec3 c = srgb_to_linear(glm::vec3(px[0], px[1], px[2]) / 255.0f);
      node_colors_.insert(node_colors_.end(), {c.r, c.g, c.b});
    }
    if (s_.point_attributes) {
      const glm::vec3 up(t.U);
      node_points_.insert(node_points_.end(),
                          {up.x, up.y, up.z, static_cast<float>(t.lage), static_cast<float>(std::max(0, module_gen_))});
    }
    if (tube.sections != 0 || tube.divisions != 0) {
      if (!tubes_used_) node_tubes_.assign(plant_.nodes.size() - 1 - first_node_, TubeShape{});
      tubes_used_ = true;
    }
    if (tubes_used_) node_tubes_.push_back(tube);
    return static_cast<std::int32_t>(plant_.nodes.size() - 1);
  }
  void snap_start(State& t) { snap(t); }

  // The shape J/K/M (symbol c, index which) takes with its stamps a, b, c (args 2..4) set as the Leaf Params
  // name them: kept in Plant::organ_shapes, each distinct name checked once.
  std::uint16_t stamped_shape(char c, std::size_t which, const float* a, int k) {
    std::string settings;
    for (int q = 2; q < k && q < 5; ++q) {
      const std::string& setting = s_.stamps->params[static_cast<std::size_t>(q - 2)];
      if (setting.empty()) continue;
      settings += fmt::format("{}{}={}", settings.empty() ? "" : ",", setting, a[q]);
    }
    if (settings.empty()) return s_.organ_shape[which];
    const std::string& base = s_.stamps->base[which];
    if (names_a_file(base))
      throw InputError(
          fmt::format("{}'s stamps set '{}' of its shape, but its shape is the OBJ file '{}', which has no "
                      "settings; leaf_param_a/b/c apply to the built-in shapes",
                      c, settings, base));
    const std::string name = base + (base.find(':') == std::string::npos ? ":" : ",") + settings;
    if (const auto it = stamped_.find(name); it != stamped_.end()) return it->second;
    auto& shapes = plant_.organ_shapes;
    auto at = std::find(shapes.begin(), shapes.end(), name);
    if (at == shapes.end()) {
      (void)organ_shape_named(name, fmt::format("{}'s stamps (leaf_param_a/b/c)", c));
      if (shapes.size() >= kKindShape) throw InputError(fmt::format("{}'s stamps make too many shapes", c));
      at = shapes.insert(shapes.end(), name);
    }
    return stamped_.emplace(name, static_cast<std::uint16_t>(at - shapes.begin())).first->second;
  }

  // ~(a): a heading drawn uniformly from the cone of half-angle a about the current one (the whole sphere
  // from 180), reached by the smallest rotation of the frame, then a roll of up to a about it. The heading
  // moves at most a degrees, which three independent turns of up to a each would not keep.
  void random_turn(State& t, double limit_deg, std::size_t m) {
    Rng rng(s_.seed, s_.stream * 0x100000001ull + 11, m);
    const double lim = std::clamp(limit_deg, 0.0, 180.0) * std::numbers::pi / 180.0;
    const double cos_theta = 1.0 - rng.uniform() * (1.0 - std::cos(lim));  // uniform over the cap's area
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    const double phi = rng.uniform(0.0, 2.0 * std::numbers::pi);
    const glm::dvec3 h = cos_theta * t.H + sin_theta * (std::cos(phi) * t.L + std::sin(phi) * t.U);
    const glm::dvec3 axis = glm::cross(t.H, h);
    const double sn = glm::length(axis), cs = glm::dot(t.H, h);
    if (sn > 1e-12) {
      t.L = glm::normalize(rotate_about(t.L, axis / sn, cs, sn));
      t.H = glm::normalize(h);
      t.U = glm::cross(t.H, t.L);
    } else if (cs < 0.0) {  // exactly opposite: a half turn about U
      t.H = -t.H;
      t.L = -t.L;
    }
    double rc, rs;
    sincos_deg(limit_deg * rng.uniform(-1.0, 1.0), rc, rs);
    rotate_pair(t.L, t.U, rc, rs);
  }

  // Moves the module cursor (m, p) to the last module of the current branch, so that its ']' pops next;
  // the skipped modules see the turtle as it stands.
  void skip_branch(const State& t, std::size_t& m, std::size_t& p) {
    const std::uint16_t* sym = str_.symbols.data();
    const std::size_t n = str_.size();
    int depth = 0;
    while (m + 1 < n) {
      const std::uint16_t w2 = sym[m + 1];
      const char c2 = symbol_of(w2);
      if (c2 == ']' && depth == 0) break;
      if (c2 == '[') ++depth;
      if (c2 == ']') --depth;
      ++m;
      p += static_cast<std::size_t>(count_of(w2));
      if (states_) record(t, m);
    }
  }

  // Whether a step from `a` to `b` ends in a solid or passes through one at its midpoint (a thin wall).
  bool enters_solid(const glm::dvec3& a, const glm::dvec3& b) const {
    return s_.avoid->inside(glm::vec3(b)) || s_.avoid->inside(glm::vec3(0.5 * (a + b)));
  }
  // Maps the position onto the nearest climbable surface, offset along the direction away from it, and turns the
  // frame so the heading is tangent there (the minimal rotation, so the turtle keeps its roll). The
  // projection repeats (up to 6 times; a point inside a solid first leaves it along the SDF gradient) until the point
  // is wrap_offset from its nearest surface, which settles points in concave corners, where the offset from one face
  // can lie inside another.
  void snap(State& t) {
    glm::dvec3 dir(0.0);
    for (int iter = 0; iter < 6; ++iter) {
      if (s_.wrap->has_sdf() &&
          s_.wrap->inside(glm::vec3(t.pos))) {  // (e.g. near a face of another mesh): out along the gradient
        const float sd = std::min(0.0f, s_.wrap->signed_distance(glm::vec3(t.pos)));
        t.pos += glm::dvec3(s_.wrap->gradient(glm::vec3(t.pos))) * (static_cast<double>(-sd) + s_.wrap_offset);
        continue;
      }
      // The climbable surfaces only: a wrap follows what the plant climbs, never the ground slab.
      const ClosestHit hit =
          s_.wrap->closest_point(glm::vec3(t.pos), std::numeric_limits<float>::infinity(), /*climbable_only=*/true);
      if (!hit.found) break;
      const glm::dvec3 cp(hit.point), nrm(hit.normal);
      const glm::dvec3 v = t.pos - cp;
      const double dist = glm::length(v);
      const auto& solid = s_.wrap->mesh_solid();
      const bool inside = glm::dot(v, nrm) < 0.0 && hit.mesh < solid.size() && solid[hit.mesh];
      if (!inside && dist > 1e-9)
        dir = v / dist;
      else
        dir = nrm;
      if (!inside && std::fabs(dist - s_.wrap_offset) <= 1e-6 + 1e-4 * s_.wrap_offset) break;
      t.pos = cp + dir * s_.wrap_offset;
    }
    if (glm::length(dir) > 0.0) retangent(t, dir);
  }
  static void retangent(State& t, const glm::dvec3& nrm) {
    glm::dvec3 h = t.H - nrm * glm::dot(t.H, nrm);
    if (glm::length(h) < 1e-9) return;
    h = glm::normalize(h);
    const glm::dvec3 axis = glm::cross(t.H, h);
    const double sn = glm::length(axis), cs = glm::dot(t.H, h);
    if (sn > 1e-12) t.L = glm::normalize(rotate_about(t.L, axis / sn, cs, sn));
    t.H = h;
    t.L = glm::normalize(t.L - t.H * glm::dot(t.L, t.H));
    t.U = glm::cross(t.H, t.L);
  }
  void finish_attributes(std::size_t first_node) {
    const std::size_t count = plant_.nodes.size() - first_node;
    if (groups_used_) node_groups_.resize(count, -1);
    if (attrs_used_) node_attrs_.resize(count, 0);
    if (groups_used_ || !plant_.node_groups.empty()) {
      plant_.node_groups.resize(first_node, -1);
      plant_.node_groups.insert(plant_.node_groups.end(), node_groups_.begin(), node_groups_.end());
      plant_.node_groups.resize(plant_.nodes.size(), -1);  // a plant without g after one with it
    }
    if (tubes_used_) node_tubes_.resize(count);
    if (tubes_used_ || !plant_.node_tubes.empty()) {
      plant_.node_tubes.resize(first_node);
      plant_.node_tubes.insert(plant_.node_tubes.end(), node_tubes_.begin(), node_tubes_.end());
      plant_.node_tubes.resize(plant_.nodes.size());
    }
    for (std::size_t id = 0; id < attr_components_.size(); ++id) {
      const int comps = attr_components_[id];
      if (comps == 0) continue;
      const std::string& name = strings_[id];
      auto it = std::find_if(plant_.node_attributes.begin(), plant_.node_attributes.end(),
                             [&](const NodeAttribute& x) { return x.name == name; });
      if (it == plant_.node_attributes.end()) {
        plant_.node_attributes.push_back({name, comps, std::vector<float>(first_node * comps, 0.0f)});
        it = plant_.node_attributes.end() - 1;
      }
      NodeAttribute& attr = *it;
      for (std::size_t q = 0; q < count; ++q) {
        const auto& snap = attr_snapshots_[attrs_used_ ? node_attrs_[q] : 0];
        for (int cpt = 0; cpt < attr.components; ++cpt)
          attr.values.push_back(id < snap.size() && cpt < 3 ? snap[id][static_cast<std::size_t>(cpt)] : 0.0f);
      }
    }
    // An attribute the turtle gives each node of this plant, after the zeros of earlier plants' nodes.
    auto per_node = [&](const std::string& name, int comps) -> std::vector<float>& {
      auto it = std::find_if(plant_.node_attributes.begin(), plant_.node_attributes.end(),
                             [&](const NodeAttribute& x) { return x.name == name; });
      if (it == plant_.node_attributes.end()) {
        plant_.node_attributes.push_back({name, comps, std::vector<float>(first_node * comps, 0.0f)});
        it = plant_.node_attributes.end() - 1;
      }
      return it->values;
    };
    if (s_.color_image) {
      auto& cd = per_node("Cd", 3);
      cd.insert(cd.end(), node_colors_.begin(), node_colors_.end());
    }
    if (s_.point_attributes) {
      for (const auto& [name, comps] : {std::pair{"up", 3}, {"lage", 1}, {"gen", 1}}) per_node(name, comps);
      // All three exist now, so holding one cannot be invalidated by making another.
      auto &up = per_node("up", 3), &lage = per_node("lage", 1), &gen = per_node("gen", 1);
      for (std::size_t q = 0; q + 5 <= node_points_.size(); q += 5) {
        up.insert(up.end(), node_points_.begin() + static_cast<std::ptrdiff_t>(q),
                  node_points_.begin() + static_cast<std::ptrdiff_t>(q + 3));
        lage.push_back(node_points_[q + 3]);
        gen.push_back(node_points_[q + 4]);
      }
    }
    // attributes other plants made before this one: pad with zeros for this plant's nodes
    for (auto& attr : plant_.node_attributes)
      attr.values.resize(plant_.nodes.size() * static_cast<std::size_t>(attr.components), 0.0f);
  }

  const LString& str_;
  const TurtleSettings& s_;
  const std::vector<std::string>& strings_;
  Plant& plant_;
  std::vector<TurtleVars>* states_;
  std::vector<State> stack_;
  std::vector<PlantPolygon> polys_;
  std::vector<std::int32_t> node_groups_;
  std::vector<std::uint32_t> node_attrs_;
  std::vector<std::vector<std::array<float, 4>>> attr_snapshots_;
  std::vector<int> attr_components_;
  std::vector<TubeShape> node_tubes_;
  std::vector<float> node_colors_;                          // Apply Color: 3 per node of this plant
  std::vector<float> node_points_;                          // Point Attributes: up, lage, gen per node
  int module_gen_ = 0;                                      // gen of the module drawing now
  std::unordered_map<std::string, std::uint16_t> stamped_;  // stamped shape names -> Plant::organ_shapes
  std::int32_t group_counter_ = 0;
  bool groups_used_ = false, attrs_used_ = false, tubes_used_ = false;
  std::size_t first_node_ = 0;  // this plant's first node in plant_
  std::uint32_t shoot_counter_ = 0;
  double cached_angle_ = std::numeric_limits<double>::quiet_NaN(), cached_cos_ = 1.0, cached_sin_ = 0.0;
  TurtleResult result_;
};

}  // namespace

TurtleResult interpret(const LString& s, const TurtleSettings& settings, const std::vector<std::string>& strings,
                       Plant& plant, std::vector<TurtleVars>* states) {
  Interpreter it(s, settings, strings, plant, states);
  return it.run();
}

}  // namespace growbench::lsys
