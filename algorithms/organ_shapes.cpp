#include "algorithms/organ_shapes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>

#include "core/errors.hpp"
#include "scenes/scene_library.hpp"

namespace growbench {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// A built-in's settings, given after its name: "blossom:petals=6,cup=20".
struct ShapeSettings {
  std::map<std::string, double> values;
  std::string text, source;

  double take(const std::string& key, double fallback, double lo, double hi) {
    const auto it = values.find(key);
    if (it == values.end()) return fallback;
    const double v = it->second;
    values.erase(it);
    if (!(v >= lo && v <= hi))
      throw InputError(fmt::format("{}: '{}': {} must be in [{}, {}], got {}", source, text, key, lo, hi, v));
    return v;
  }
  void done() const {
    if (!values.empty())
      throw InputError(
          fmt::format("{}: '{}': unknown setting '{}' for this shape", source, text, values.begin()->first));
  }
};

ShapeSettings parse_settings(std::string_view text, std::string_view source, std::string& name) {
  ShapeSettings s;
  s.text = std::string(text);
  s.source = std::string(source);
  const auto colon = text.find(':');
  name = std::string(text.substr(0, colon));
  if (colon == std::string_view::npos) return s;
  std::string_view rest = text.substr(colon + 1);
  while (!rest.empty()) {
    const auto comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    const auto eq = item.find('=');
    double v = 0.0;
    std::string value = eq == std::string_view::npos ? "" : std::string(item.substr(eq + 1));
    char* end = nullptr;
    if (!value.empty()) v = std::strtod(value.c_str(), &end);
    if (eq == std::string_view::npos || value.empty() || *end != '\0' || !std::isfinite(v))
      throw InputError(fmt::format(
          "{}: '{}': expected settings as key=number separated by commas after the shape's name", source, text));
    s.values[std::string(item.substr(0, eq))] = v;
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
  }
  return s;
}

void finish_shape(OrganShape& s) {
  s.normals.assign(s.mesh.vertices.size(), glm::vec3(0.0f));
  for (const auto& t : s.mesh.triangles) {
    const glm::vec3 a = s.mesh.vertices[t.x], b = s.mesh.vertices[t.y], c = s.mesh.vertices[t.z];
    const glm::vec3 n = glm::cross(b - a, c - a);
    for (int k = 0; k < 3; ++k) s.normals[t[k]] += n;
  }
  for (auto& n : s.normals) n = glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0, 1, 0);
  s.box_min = glm::vec3(std::numeric_limits<float>::max());
  s.box_max = glm::vec3(std::numeric_limits<float>::lowest());
  for (const auto& v : s.mesh.vertices) {
    s.box_min = glm::min(s.box_min, v);
    s.box_max = glm::max(s.box_max, v);
  }
}

// The leaf every algorithm has drawn so far: a diamond in the XZ plane, widest at 0.4 of its length.
OrganShape leaf(ShapeSettings& st) {
  const auto w = static_cast<float>(st.take("width", 0.25, 0.01, 2.0));
  const auto at = static_cast<float>(st.take("widest", 0.4, 0.05, 0.95));
  OrganShape s;
  s.mesh.vertices = {{0, 0, 0}, {w, 0, at}, {0, 0, 1}, {-w, 0, at}};
  s.mesh.triangles = {{0, 2, 1}, {0, 3, 2}};
  return s;
}

// A five-petalled flower facing +Z, 1 across: each petal a fan from the receptacle, widest at two
// thirds of its length with a notch at the tip (a cherry's), tilted forward by `cup` degrees.
OrganShape blossom(ShapeSettings& st, double cup_default, double length_default) {
  const int petals = static_cast<int>(st.take("petals", 5, 3, 12));
  const auto cup = glm::radians(static_cast<float>(st.take("cup", cup_default, 0, 85)));
  const auto length = static_cast<float>(st.take("length", length_default, 0.1, 1.0));
  const auto notch = static_cast<float>(st.take("notch", 0.08, 0.0, 0.5));
  OrganShape s;
  s.has_color = true;
  // The petal's outline as (distance from the centre, offset across), base to tip and back.
  const float r0 = 0.05f, half = 0.5f * length;
  const float across = std::min(0.32f * half, 0.9f * std::sin(kPi / static_cast<float>(petals)) * 0.66f * half);
  const std::vector<glm::vec2> outline = {{r0, 0.0f},
                                          {0.35f * half, 0.75f * across},
                                          {0.66f * half, across},
                                          {0.92f * half, 0.6f * across},
                                          {half, 0.22f * across},
                                          {(1.0f - notch) * half, 0.0f},
                                          {half, -0.22f * across},
                                          {0.92f * half, -0.6f * across},
                                          {0.66f * half, -across},
                                          {0.35f * half, -0.75f * across}};
  const float lift = std::sin(cup), spread = std::cos(cup);
  for (int p = 0; p < petals; ++p) {
    const float a = 2.0f * kPi * static_cast<float>(p) / static_cast<float>(petals);
    const glm::vec3 radial(std::cos(a), std::sin(a), 0.0f), side(-std::sin(a), std::cos(a), 0.0f);
    const auto base = static_cast<std::uint32_t>(s.mesh.vertices.size());
    for (const auto& q : outline)
      s.mesh.vertices.push_back(q.x * spread * radial + q.y * side + glm::vec3(0, 0, 0.04f + q.x * lift));
    for (std::uint32_t k = 1; k + 1 < outline.size(); ++k) s.mesh.triangles.emplace_back(base, base + k, base + k + 1);
    s.mesh.triangles.emplace_back(base, base + static_cast<std::uint32_t>(outline.size()) - 1, base + 1);
  }
  // The receptacle: a small cone from the stem to the petals' bases, closing the centre.
  const auto tip = static_cast<std::uint32_t>(s.mesh.vertices.size());
  s.mesh.vertices.emplace_back(0.0f, 0.0f, 0.0f);
  for (int p = 0; p < petals; ++p) {
    const auto a = static_cast<std::uint32_t>(p) * static_cast<std::uint32_t>(outline.size());
    const auto b = static_cast<std::uint32_t>((p + 1) % petals) * static_cast<std::uint32_t>(outline.size());
    s.mesh.triangles.emplace_back(tip, b, a);
  }
  return s;
}

// A closed bud: a lathe of a teardrop along +Z, 1 long.
OrganShape bud(ShapeSettings& st) {
  const auto width = static_cast<float>(st.take("width", 0.32, 0.05, 1.0));
  const int sides = static_cast<int>(st.take("sides", 8, 3, 32));
  const std::vector<glm::vec2> profile = {{0.18f, 0.06f}, {0.45f, 0.2f}, {0.62f, 0.26f}, {0.8f, 0.2f}, {0.93f, 0.1f}};
  OrganShape s;
  s.has_color = true;
  s.mesh.vertices.emplace_back(0.0f, 0.0f, 0.0f);
  for (const auto& q : profile)
    for (int k = 0; k < sides; ++k) {
      const float a = 2.0f * kPi * static_cast<float>(k) / static_cast<float>(sides);
      const float r = q.y * width / 0.52f;
      s.mesh.vertices.emplace_back(r * std::cos(a), r * std::sin(a), q.x);
    }
  s.mesh.vertices.emplace_back(0.0f, 0.0f, 1.0f);
  const auto S = static_cast<std::uint32_t>(sides);
  const auto last = static_cast<std::uint32_t>(s.mesh.vertices.size()) - 1;
  for (std::uint32_t k = 0; k < S; ++k) s.mesh.triangles.emplace_back(0, 1 + (k + 1) % S, 1 + k);
  for (std::uint32_t ring = 0; ring + 1 < profile.size(); ++ring)
    for (std::uint32_t k = 0; k < S; ++k) {
      const std::uint32_t a = 1 + ring * S + k, b = 1 + ring * S + (k + 1) % S;
      s.mesh.triangles.emplace_back(a, b, b + S);
      s.mesh.triangles.emplace_back(a, b + S, a + S);
    }
  const std::uint32_t top = 1 + static_cast<std::uint32_t>(profile.size() - 1) * S;
  for (std::uint32_t k = 0; k < S; ++k) s.mesh.triangles.emplace_back(top + k, top + (k + 1) % S, last);
  return s;
}

}  // namespace

const std::vector<std::string>& builtin_organ_shape_names() {
  static const std::vector<std::string> names = {"leaf", "blossom", "half_bloom", "bud"};
  return names;
}

const std::vector<std::string>& builtin_organ_shape_docs() {
  static const std::vector<std::string> docs = {
      "a diamond blade in the XZ plane (width=0.25, widest=0.4)",
      "an open five-petalled flower facing along the stem, 1 across (petals=5, cup=12, length=1, notch=0.08)",
      "the blossom half open: petals cupped forward (petals=5, cup=55, length=0.75, notch=0.08)",
      "a closed teardrop bud (width=0.32, sides=8)",
  };
  return docs;
}

OrganShape builtin_organ_shape(std::string_view text, std::string_view source) {
  std::string name;
  ShapeSettings st = parse_settings(text, source, name);
  OrganShape s;
  if (name == "leaf") {
    s = leaf(st);
  } else if (name == "blossom") {
    s = blossom(st, 12.0, 1.0);
    s.srgb = {0.97f, 0.78f, 0.84f};
  } else if (name == "half_bloom") {
    s = blossom(st, 55.0, 0.75);
    s.srgb = {0.95f, 0.62f, 0.74f};
  } else if (name == "bud") {
    s = bud(st);
    s.srgb = {0.85f, 0.36f, 0.50f};
  } else {
    throw InputError(fmt::format("{}: unknown organ shape '{}'; expected one of {}, or the path of an OBJ file", source,
                                 name, fmt::join(builtin_organ_shape_names(), ", ")));
  }
  st.done();
  s.name = std::string(text);
  s.mesh.name = s.name;
  finish_shape(s);
  return s;
}

OrganShape load_organ_obj(const std::string& path) {
  OrganShape s;
  s.mesh = load_obj(path);  // InputError without faces
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  for (const auto& v : s.mesh.vertices) lo = std::min(lo, v.z), hi = std::max(hi, v.z);
  if (!(hi - lo > 1e-6f))
    throw InputError(fmt::format("{}: the organ has no length along z; expected it along +Z from the stem", path));
  for (auto& v : s.mesh.vertices) v = glm::vec3(v.x, v.y, v.z - lo) / (hi - lo);
  s.mesh.uvs.clear();
  s.mesh.uv_triangles.clear();
  s.name = path;
  s.mesh.name = "organ_obj";
  finish_shape(s);
  return s;
}

bool names_a_file(const std::string& name) {
  return name.find('/') != std::string::npos || name.ends_with(".obj") || name.ends_with(".OBJ");
}

OrganShape organ_shape_named(const std::string& name, std::string_view source) {
  return names_a_file(name) ? load_organ_obj(name) : builtin_organ_shape(name, source);
}

glm::vec3 organ_point(const Organ& organ, const glm::vec3& local) {
  return organ.position + glm::mat3_cast(organ.orientation) * (local * organ.size);
}

glm::vec3 organ_kind_srgb(OrganKind kind) {
  switch (kind) {
    case OrganKind::Leaf:
      return {0.24f, 0.52f, 0.16f};
    case OrganKind::YoungLeaf:
      return {0.52f, 0.72f, 0.24f};
    case OrganKind::Flower:
      return {0.95f, 0.80f, 0.88f};
    case OrganKind::Bud:
      return {0.85f, 0.36f, 0.50f};
  }
  return glm::vec3(1.0f);
}

glm::vec3 srgb_to_linear(const glm::vec3& c) {
  auto f = [](float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); };
  return {f(c.x), f(c.y), f(c.z)};
}

namespace {

// Built-ins by their text, made once per process: a plant's meshing, metrics and render each ask for
// the same few, and a leafy plant should not pay for a blossom it does not have.
std::shared_ptr<const OrganShape> shared_builtin(const std::string& text) {
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const OrganShape>> made;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& s = made[text];
  if (!s) s = std::make_shared<const OrganShape>(builtin_organ_shape(text));
  return s;
}

}  // namespace

OrganShapes::OrganShapes(const Plant& plant, const OrganShape* custom_leaf) {
  static const char* const kDefault[4] = {"leaf", "leaf", "blossom", "bud"};
  std::array<bool, 4> present{};
  for (const auto& o : plant.organs)
    if (o.shape == kKindShape) present[static_cast<std::size_t>(o.kind)] = true;
  if (custom_leaf) shapes_.push_back(std::make_shared<const OrganShape>(*custom_leaf));
  for (std::size_t k = 0; k < 4; ++k) {
    if (custom_leaf || !present[k]) continue;  // kind_[k] stays 0: never asked for
    const auto it = std::find_if(shapes_.begin(), shapes_.end(), [&](const auto& s) { return s->name == kDefault[k]; });
    kind_[k] = static_cast<std::size_t>(it - shapes_.begin());
    if (it == shapes_.end()) shapes_.push_back(shared_builtin(kDefault[k]));
  }
  for (const auto& name : plant.organ_shapes) {
    const auto it = std::find_if(shapes_.begin(), shapes_.end(), [&](const auto& s) { return s->name == name; });
    named_.push_back(static_cast<std::size_t>(it - shapes_.begin()));
    if (it != shapes_.end()) continue;
    shapes_.push_back(names_a_file(name) ? std::make_shared<const OrganShape>(load_organ_obj(name))
                                         : shared_builtin(name));
  }
}

std::size_t OrganShapes::index_of(const Organ& o) const {
  return o.shape == kKindShape ? kind_[static_cast<std::size_t>(o.kind)] : named_[o.shape];
}

const OrganShape& OrganShapes::of(const Organ& o) const {
  return *shapes_[index_of(o)];
}

glm::vec3 OrganShapes::linear_color(const Organ& o) const {
  const OrganShape& s = of(o);
  return srgb_to_linear(s.has_color ? s.srgb : organ_kind_srgb(o.kind)) * o.tint;
}

bool OrganShapes::any_color(const Plant& plant) const {
  return std::any_of(plant.organs.begin(), plant.organs.end(), [&](const Organ& o) {
    const OrganShape& s = of(o);
    return o.tint != glm::vec3(1.0f) || (s.has_color && s.srgb != organ_kind_srgb(o.kind));
  });
}

}  // namespace growbench
