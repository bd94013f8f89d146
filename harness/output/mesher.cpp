#include "harness/output/mesher.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>

#include "core/errors.hpp"
#include "scenes/scene_library.hpp"

namespace growbench {

std::vector<std::vector<std::int32_t>> plant_chains(const Plant& plant) {
  const std::size_t n = plant.nodes.size();
  std::vector<std::int32_t> main_child(n, kNoParent);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t p = plant.nodes[i].parent;
    if (p == kNoParent) continue;
    auto& mc = main_child[static_cast<std::size_t>(p)];
    const bool same_shoot = plant.nodes[i].shoot == plant.nodes[static_cast<std::size_t>(p)].shoot;
    if (mc == kNoParent) {
      mc = static_cast<std::int32_t>(i);
    } else if (same_shoot &&
               plant.nodes[static_cast<std::size_t>(mc)].shoot != plant.nodes[static_cast<std::size_t>(p)].shoot) {
      mc = static_cast<std::int32_t>(i);
    }
  }
  std::vector<std::vector<std::int32_t>> chains;
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t p = plant.nodes[i].parent;
    const bool starts = p == kNoParent || main_child[static_cast<std::size_t>(p)] != static_cast<std::int32_t>(i);
    if (!starts) continue;
    std::vector<std::int32_t> chain;
    if (p != kNoParent) chain.push_back(p);
    for (auto c = static_cast<std::int32_t>(i); c != kNoParent; c = main_child[static_cast<std::size_t>(c)])
      chain.push_back(c);
    if (chain.size() >= 2) chains.push_back(std::move(chain));
  }
  return chains;
}

namespace {

glm::vec3 any_perpendicular(const glm::vec3& t) {
  const glm::vec3 h = std::abs(t.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  return glm::normalize(glm::cross(t, h));
}

// What tubes carry from the plant's optional per-node data; all null for most plants, whose tubes are
// then made exactly as before that data existed.
struct TubeExtras {
  const std::vector<TubeShape>* tubes = nullptr;      // F(l, w, s, d)
  const std::vector<std::int32_t>* groups = nullptr;  // g
  const NodeAttribute* cd = nullptr;                  // a("Cd", ...): vertex colours
  std::vector<const NodeAttribute*> attributes;       // the other a(): OutputMesh::attributes from `first_attribute`
  std::size_t first_attribute = 0;
  TubeStyle style;
  std::vector<float> v;  // each node's texture v, when style.uvs
  [[nodiscard]] bool vertex_data() const { return cd != nullptr || !attributes.empty(); }
};

// Whose per-node values a ring carries: node a's mixed with node b's by t (a ring inside a segment cut
// into sections lies between its two nodes). b is the node whose segment ends at the ring.
struct RingSource {
  std::int32_t a, b;
  float t;
};

float attribute_value(const NodeAttribute& x, const RingSource& s, int component) {
  if (component >= x.components) return 0.0f;  // the reference's zero defaults
  const auto c = static_cast<std::size_t>(x.components);
  const float va = x.values[static_cast<std::size_t>(s.a) * c + static_cast<std::size_t>(component)];
  const float vb = x.values[static_cast<std::size_t>(s.b) * c + static_cast<std::size_t>(component)];
  return s.t == 0.0f ? vb : va + (vb - va) * s.t;
}

// `count` vertices' colours and attributes from the ring's source nodes.
void add_vertex_data(OutputMesh& m, const TubeExtras& x, const RingSource& s, std::size_t count) {
  if (x.cd) {
    const glm::vec3 c(attribute_value(*x.cd, s, 0), attribute_value(*x.cd, s, 1), attribute_value(*x.cd, s, 2));
    m.colors.insert(m.colors.end(), count, c);
  }
  for (std::size_t k = 0; k < x.attributes.size(); ++k) {
    VertexAttribute& out = m.attributes[x.first_attribute + k];
    for (std::size_t v = 0; v < count; ++v)
      for (int c = 0; c < out.components; ++c) out.values.push_back(attribute_value(*x.attributes[k], s, c));
  }
}

std::int32_t group_of(const TubeExtras& x, std::int32_t node) {
  const std::int32_t g = (*x.groups)[static_cast<std::size_t>(node)];
  return g < 0 ? -1 : g;
}

// Rings start..end of a tube with `sides` vertices each, the frame carried along from `normal`
// (parallel transport in projection form: the previous normal made perpendicular to the tangent), then
// the quads between them. One loop with its values in locals, as this is most of a big plant's meshing.
// With texture v per ring (`tex_v`), each ring has a seam vertex more, at u = 1 over the first.
void add_strip(OutputMesh& m, const std::vector<glm::vec3>& pts, const std::vector<float>& rad, std::size_t start,
               std::size_t end, int sides, glm::vec3& normal, const std::vector<float>* tex_v) {
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  const std::size_t n = pts.size();
  const float fsides = static_cast<float>(sides);
  const int ring = sides + (tex_v ? 1 : 0);
  glm::vec3 carried = normal;
  for (std::size_t j = start; j <= end; ++j) {
    const glm::vec3 a = pts[j == 0 ? 0 : j - 1], b = pts[j + 1 < n ? j + 1 : j];
    const glm::vec3 t = glm::normalize(b - a);
    glm::vec3 nrm = j == 0 ? any_perpendicular(t) : carried - glm::dot(carried, t) * t;
    if (glm::length(nrm) < 1e-6f) nrm = any_perpendicular(t);
    carried = glm::normalize(nrm);
    const glm::vec3 binormal = glm::cross(t, carried);
    for (int s = 0; s < ring; ++s) {
      const int around = s % sides;  // the seam vertex repeats the first's position
      const float ang = 2.0f * std::numbers::pi_v<float> * static_cast<float>(around) / fsides;
      const glm::vec3 d = std::cos(ang) * carried + std::sin(ang) * binormal;
      m.positions.push_back(pts[j] + rad[j] * d);
      m.normals.push_back(d);
      if (tex_v) m.uvs.emplace_back(static_cast<float>(s) / fsides, (*tex_v)[j]);
    }
  }
  normal = carried;
  const auto S = static_cast<std::uint32_t>(sides), R = static_cast<std::uint32_t>(ring);
  const auto segments = static_cast<std::uint32_t>(end - start);
  for (std::uint32_t j = 0; j < segments; ++j) {
    for (std::uint32_t s = 0; s < S; ++s) {
      const std::uint32_t a = base + j * R + s, b = base + j * R + (s + 1) % R;
      const std::uint32_t c = a + R, d = b + R;
      m.triangles.emplace_back(a, b, d);
      m.triangles.emplace_back(a, d, c);
    }
  }
}

// The rings of a tube along a chain: points and radii; and, only when needed, the divisions of each
// segment (ring j to j + 1), each ring's source of per-node values and its texture v.
struct TubePath {
  std::vector<glm::vec3> pts;
  std::vector<float> rad;
  std::vector<std::uint16_t> divisions;  // when the plant has node tubes
  std::vector<RingSource> src;           // when `sources`
  std::vector<std::uint32_t> steps;      // each ring's birth step: its segment's end node's
  std::vector<float> v;                  // when the style has UVs
  bool sources = false;
};

// Whether the tube drops the segment from a to b: too short to have a direction.
bool zero_length(const glm::vec3& a, const glm::vec3& b) {
  return glm::length(b - a) < 1e-7f;
}

// The chain's nodes that start a segment of non-zero length (the first always), as indices into `chain`.
std::vector<std::size_t> kept_nodes(const Plant& plant, const std::vector<std::int32_t>& chain) {
  std::vector<std::size_t> kept;
  glm::vec3 last(0.0f);
  for (std::size_t j = 0; j < chain.size(); ++j) {
    const glm::vec3 p = plant.nodes[static_cast<std::size_t>(chain[j])].position;
    if (!kept.empty() && zero_length(last, p)) continue;
    kept.push_back(j);
    last = p;
  }
  return kept;
}

// The tangents of TubeStyle's cardinal spline at the kept nodes. A side branch's first tangent leans
// toward the heading its parent arrived with, by branch_blend.
std::vector<glm::vec3> chain_tangents(const Plant& plant, const std::vector<std::int32_t>& chain,
                                      const std::vector<std::size_t>& kept, const TubeStyle& style) {
  const std::size_t n = kept.size();
  auto at = [&](std::size_t i) { return plant.nodes[static_cast<std::size_t>(chain[kept[i]])].position; };
  const float k = 1.0f - style.tension;
  std::vector<glm::vec3> t(n, glm::vec3(0.0f));
  if (n < 2) return t;
  t[0] = k * (at(1) - at(0));
  t[n - 1] = k * (at(n - 1) - at(n - 2));
  for (std::size_t i = 1; i + 1 < n; ++i) t[i] = 0.5f * k * (at(i + 1) - at(i - 1));
  const PlantNode& first = plant.nodes[static_cast<std::size_t>(chain[0])];
  if (first.parent != kNoParent && style.branch_blend > 0.0f) {  // a chain starts at a root or a branch point
    const glm::vec3 in = first.position - plant.nodes[static_cast<std::size_t>(first.parent)].position;
    if (glm::length(in) > 0.0f)
      t[0] = glm::mix(t[0], glm::normalize(in) * glm::length(at(1) - at(0)), style.branch_blend);
  }
  return t;
}

// The point a fraction f along the segment from node p0 to p1: on the straight segment, or on the
// Hermite curve with tangents m0 and m1 when the style curves tubes.
glm::vec3 section_point(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& m0, const glm::vec3& m1, float f,
                        bool curved) {
  if (!curved) return p0 + (p1 - p0) * f;
  const float f2 = f * f, f3 = f2 * f;
  return (2 * f3 - 3 * f2 + 1) * p0 + (f3 - 2 * f2 + f) * m0 + (-2 * f3 + 3 * f2) * p1 + (f3 - f2) * m1;
}

// Points and radii along the chain; most plants need nothing else, in vectors that do not escape.
void plain_tube_path(TubePath& t, const Plant& plant, const std::vector<std::int32_t>& chain, const MesherOptions& o) {
  std::vector<glm::vec3> pts;
  std::vector<float> rad;
  std::vector<std::uint32_t> steps;
  for (std::size_t j = 0; j < chain.size(); ++j) {
    const auto& node = plant.nodes[static_cast<std::size_t>(chain[j])];
    const glm::vec3 p = node.position;
    if (!pts.empty() && zero_length(pts.back(), p)) continue;
    float r = node.radius;
    // A chain's first ring is its first segment's: it appears with that segment's end.
    std::uint32_t step = node.birth_step;
    if (j == 0 && chain.size() > 1) {
      const auto& next = plant.nodes[static_cast<std::size_t>(chain[1])];
      if (next.shoot != node.shoot) r = std::min(r, next.radius);
      step = next.birth_step;
    }
    pts.push_back(p);
    rad.push_back(std::max(r, o.min_radius > 0.0f ? o.min_radius : 1e-4f));
    steps.push_back(step);
  }
  t.pts = std::move(pts);
  t.rad = std::move(rad);
  t.steps = std::move(steps);
}

// Points and radii along the chain, with the rings inside each segment's sections (on the style's
// curve); a side branch starts at its parent's node with its own radius.
void tube_path(TubePath& t, const Plant& plant, const std::vector<std::int32_t>& chain, const MesherOptions& o,
               const TubeExtras& x, int sides) {
  if (!x.tubes && !t.sources && !x.style.uvs) return plain_tube_path(t, plant, chain, o);
  const bool curved = x.tubes && x.style.curved();
  const std::vector<glm::vec3> tangents =
      curved ? chain_tangents(plant, chain, kept_nodes(plant, chain), x.style) : std::vector<glm::vec3>();
  std::size_t i = 0;  // the kept node's index (kept_nodes)
  for (std::size_t j = 0; j < chain.size(); ++j) {
    const auto id = chain[j];
    const auto& node = plant.nodes[static_cast<std::size_t>(id)];
    const glm::vec3 p = node.position;
    if (!t.pts.empty() && zero_length(t.pts.back(), p)) continue;
    // A lateral branch (its first node's shoot differs from the parent's) starts with its own radius,
    // and its own values: those of its first segment's end.
    float r = node.radius;
    std::int32_t own = id;
    std::uint32_t step = node.birth_step;
    if (j == 0 && chain.size() > 1) {
      const auto& next = plant.nodes[static_cast<std::size_t>(chain[1])];
      if (next.shoot != node.shoot) {
        r = std::min(r, next.radius);
        own = chain[1];
      }
      step = next.birth_step;
    }
    r = std::max(r, o.min_radius > 0.0f ? o.min_radius : 1e-4f);
    const float tex_v = x.style.uvs ? x.v[static_cast<std::size_t>(id)] : 0.0f;
    if (x.tubes && i > 0) {
      const TubeShape shape = (*x.tubes)[static_cast<std::size_t>(id)];
      const auto d = static_cast<std::uint16_t>(shape.divisions != 0 ? shape.divisions : sides);
      const glm::vec3 p0 = t.pts.back();
      const float r0 = t.rad.back(), v0 = x.style.uvs ? t.v.back() : 0.0f;
      const std::int32_t from = t.sources ? t.src.back().b : id;
      const glm::vec3 m0 = curved ? tangents[i - 1] : glm::vec3(0.0f), m1 = curved ? tangents[i] : glm::vec3(0.0f);
      for (int k = 1; k < shape.sections; ++k) {  // the section boundaries inside the segment
        const float f = static_cast<float>(k) / static_cast<float>(shape.sections);
        t.pts.push_back(section_point(p0, p, m0, m1, f, curved));
        t.rad.push_back(r0 + (r - r0) * f);
        t.divisions.push_back(d);
        t.steps.push_back(node.birth_step);
        if (t.sources) t.src.push_back({from, id, f});
        if (x.style.uvs) t.v.push_back(v0 + (tex_v - v0) * f);
      }
      t.divisions.push_back(d);
    }
    t.pts.push_back(p);
    t.rad.push_back(r);
    t.steps.push_back(step);
    if (t.sources) t.src.push_back({own, own, 0.0f});
    if (x.style.uvs) t.v.push_back(tex_v);
    ++i;
  }
}

// A tube along one chain. Each segment's cross sections and divisions come from the node it ends at
// (Plant::node_tubes; else one section of o.sides). A run of segments with the same divisions is one
// strip of rings; where the divisions change, the next strip starts with a ring of its own at the same
// joint (the two rings' polygons differ, so the tube is open there). Caps close the chain's two ends.
// `triangle_groups`, when given, receives the group of each triangle: that of the segment's end node.
void add_tube(OutputMesh& m, const Plant& plant, const std::vector<std::int32_t>& chain, const MesherOptions& o,
              const TubeExtras& x, std::vector<std::int32_t>* triangle_groups) {
  const int sides = std::clamp(o.sides, 3, 64);
  const bool vertex_data = x.vertex_data();
  TubePath path;
  path.sources = vertex_data || triangle_groups != nullptr;
  tube_path(path, plant, chain, o, x, sides);
  const std::vector<glm::vec3>& pts = path.pts;
  const std::vector<float>& rad = path.rad;
  const std::vector<std::uint16_t>& divisions = path.divisions;
  const std::vector<RingSource>& src = path.src;
  if (pts.size() < 2) return;
  auto segment_divisions = [&](std::size_t j) { return divisions.empty() ? sides : int{divisions[j]}; };
  // Strips of equal divisions: [strip_start, j] rings, emitted as rings then quads.
  glm::vec3 normal(0.0f);
  std::uint32_t first_ring = 0, last_ring = 0;  // the vertex of the chain's first and last ring
  int first_sides = sides, last_sides = sides;
  for (std::size_t start = 0; start + 1 < pts.size();) {
    const int d = segment_divisions(start);
    std::size_t end = divisions.empty() ? pts.size() - 1 : start + 1;
    while (end + 1 < pts.size() && segment_divisions(end) == d) ++end;
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    add_strip(m, pts, rad, start, end, d, normal, x.style.uvs ? &path.v : nullptr);
    const auto S = static_cast<std::uint32_t>(d), R = S + (x.style.uvs ? 1 : 0);
    for (std::size_t j = start; j <= end; ++j) m.birth_steps.insert(m.birth_steps.end(), R, path.steps[j]);
    if (vertex_data)
      for (std::size_t j = start; j <= end; ++j) add_vertex_data(m, x, src[j], R);
    if (triangle_groups)
      for (std::size_t j = start; j < end; ++j)
        triangle_groups->insert(triangle_groups->end(), 2 * S, group_of(x, src[j + 1].b));
    if (start == 0) {
      first_ring = base;
      first_sides = d;
    }
    last_ring = base + static_cast<std::uint32_t>(end - start) * R;
    last_sides = d;
    start = end;
  }
  if (o.caps) {
    for (const bool start : {true, false}) {
      const std::size_t j = start ? 0 : pts.size() - 1;
      const glm::vec3 t = glm::normalize(pts[start ? 1 : j] - pts[start ? 0 : j - 1]);
      const auto centre = static_cast<std::uint32_t>(m.positions.size());
      m.positions.push_back(pts[j]);
      m.normals.push_back(start ? -t : t);
      m.birth_steps.push_back(path.steps[j]);
      if (vertex_data) add_vertex_data(m, x, src[j], 1);
      if (x.style.uvs) m.uvs.emplace_back(0.5f, path.v[j]);
      const std::uint32_t ring = start ? first_ring : last_ring;
      const auto S = static_cast<std::uint32_t>(start ? first_sides : last_sides);
      for (std::uint32_t s = 0; s < S; ++s) {
        const std::uint32_t a = ring + s, b = ring + (s + 1) % S;
        if (start)
          m.triangles.emplace_back(centre, b, a);
        else
          m.triangles.emplace_back(centre, a, b);
      }
      if (triangle_groups) triangle_groups->insert(triangle_groups->end(), S, group_of(x, src[start ? 1 : j].b));
    }
  }
}

// Branch geometry skeleton: every node a vertex (normal +Y: lines have none), every segment a line.
void add_skeleton_lines(OutputMesh& m, const Plant& plant, const TubeExtras& x,
                        std::vector<std::int32_t>* line_groups) {
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  for (std::size_t i = 0; i < plant.nodes.size(); ++i) {
    m.positions.push_back(plant.nodes[i].position);
    m.normals.emplace_back(0.0f, 1.0f, 0.0f);
    m.birth_steps.push_back(plant.nodes[i].birth_step);
    const auto id = static_cast<std::int32_t>(i);
    if (x.vertex_data()) add_vertex_data(m, x, {id, id, 0.0f}, 1);
  }
  for (std::size_t i = 0; i < plant.nodes.size(); ++i) {
    const std::int32_t p = plant.nodes[i].parent;
    if (p == kNoParent) continue;
    m.lines.emplace_back(base + static_cast<std::uint32_t>(p), base + static_cast<std::uint32_t>(i));
    if (line_groups) line_groups->push_back(group_of(x, static_cast<std::int32_t>(i)));
  }
}

// Reorders items[first, end) by their groups (stable, -1 first) and returns each group with its count.
template <class T>
std::vector<std::pair<std::int32_t, std::uint32_t>> sort_by_group(std::vector<T>& items, std::size_t first,
                                                                  const std::vector<std::int32_t>& groups) {
  std::map<std::int32_t, std::uint32_t> counts;
  for (const std::int32_t g : groups) ++counts[g];
  std::map<std::int32_t, std::size_t> next;
  std::size_t offset = first;
  for (const auto& [g, n] : counts) {
    next[g] = offset;
    offset += n;
  }
  std::vector<T> sorted(groups.size());
  for (std::size_t k = 0; k < groups.size(); ++k) sorted[next[groups[k]]++ - first] = items[first + k];
  std::copy(sorted.begin(), sorted.end(), items.begin() + static_cast<std::ptrdiff_t>(first));
  return {counts.begin(), counts.end()};
}

// The branches: tubes (or lines, for branch geometry skeleton) with the plant's per-node colours and
// attributes, as one "branches" part, or one per plant group (ungrouped first) when the plant has groups.
void add_branches(OutputMesh& m, const Plant& plant, const MesherOptions& o) {
  TubeExtras x;
  if (!plant.node_tubes.empty()) x.tubes = &plant.node_tubes;
  if (!plant.node_groups.empty()) x.groups = &plant.node_groups;
  x.first_attribute = m.attributes.size();
  for (const auto& a : plant.node_attributes) {
    if (a.name == "Cd") {
      x.cd = &a;
      continue;
    }
    x.attributes.push_back(&a);
    m.attributes.push_back({a.name, a.components, {}});
    m.attributes.back().values.resize(m.positions.size() * static_cast<std::size_t>(a.components), 0.0f);
  }
  if (x.cd) pad_colors(m);
  x.style = plant.tube_style;
  if (x.style.uvs && plant.branch_geometry == BranchGeometry::Tube) {
    m.uvs.resize(m.positions.size(), glm::vec2(0.0f));
    x.v.resize(plant.nodes.size());  // parents precede children
    for (std::size_t i = 0; i < plant.nodes.size(); ++i) {
      const std::int32_t p = plant.nodes[i].parent;
      x.v[i] = p == kNoParent ? 0.0f : x.v[static_cast<std::size_t>(p)] + x.style.v_increment;
    }
  } else {
    x.style.uvs = false;
  }
  std::vector<std::int32_t> groups;  // per triangle or line, when the plant has groups
  const auto first_triangle = m.triangles.size(), first_line = m.lines.size();
  if (plant.branch_geometry == BranchGeometry::Skeleton) {
    add_skeleton_lines(m, plant, x, x.groups ? &groups : nullptr);
  } else {
    for (const auto& chain : plant_chains(plant)) add_tube(m, plant, chain, o, x, x.groups ? &groups : nullptr);
  }
  const auto triangles = static_cast<std::uint32_t>(m.triangles.size() - first_triangle);
  const auto lines = static_cast<std::uint32_t>(m.lines.size() - first_line);
  if (triangles + lines == 0) return;
  MeshGroup part("branches", "bark", static_cast<std::uint32_t>(first_triangle), triangles);
  part.first_line = static_cast<std::uint32_t>(first_line);
  part.line_count = lines;
  if (!x.groups) {
    m.groups.push_back(part);
    return;
  }
  const bool skeleton = plant.branch_geometry == BranchGeometry::Skeleton;
  const auto counts =
      skeleton ? sort_by_group(m.lines, first_line, groups) : sort_by_group(m.triangles, first_triangle, groups);
  std::uint32_t offset = skeleton ? part.first_line : part.first_triangle;
  for (const auto& [g, n] : counts) {
    MeshGroup piece("branches", "bark", skeleton ? 0 : offset, skeleton ? 0 : n);
    if (skeleton) {
      piece.first_line = offset;
      piece.line_count = n;
    }
    if (g >= 0) piece.plant_group = plant.group_name(g);
    m.groups.push_back(piece);
    offset += n;
  }
}

constexpr float kUncoloured = std::numeric_limits<float>::quiet_NaN();

// Completes the per-vertex data (OutputMesh::colors, attributes): a vertex left without a colour gets
// its group's material colour, a vertex without an attribute's value gets zeros.
void complete_vertex_data(OutputMesh& m) {
  if (!m.colors.empty()) {
    m.colors.resize(m.positions.size(), glm::vec3(kUncoloured));
    for (const auto& g : m.groups) {
      const glm::vec3 c = material_color(g.material);
      for (std::uint32_t t = g.first_triangle; t < g.first_triangle + g.triangle_count; ++t)
        for (int k = 0; k < 3; ++k)
          if (std::isnan(m.colors[m.triangles[t][k]].x)) m.colors[m.triangles[t][k]] = c;
      for (std::uint32_t l = g.first_line; l < g.first_line + g.line_count; ++l)
        for (int k = 0; k < 2; ++k)
          if (std::isnan(m.colors[m.lines[l][k]].x)) m.colors[m.lines[l][k]] = c;
    }
    for (auto& c : m.colors)
      if (std::isnan(c.x)) c = material_color("");  // in no part
  }
  for (auto& a : m.attributes) a.values.resize(m.positions.size() * static_cast<std::size_t>(a.components), 0.0f);
  if (!m.uvs.empty()) m.uvs.resize(m.positions.size(), glm::vec2(0.0f));
}

void add_organ(OutputMesh& m, const Organ& organ, const OrganShape& shape, const glm::vec3* color, std::uint32_t step) {
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  m.birth_steps.resize(base + shape.mesh.vertices.size(), step);
  const glm::mat3 r = glm::mat3_cast(organ.orientation);
  for (std::size_t k = 0; k < shape.mesh.vertices.size(); ++k) {
    // organ_point's arithmetic in its order (the same floats), with the rotation made once per organ.
    m.positions.push_back(organ.position + r * (shape.mesh.vertices[k] * organ.size));
    m.normals.push_back(r * shape.normals[k]);
  }
  if (color) m.colors.resize(m.positions.size(), *color);
  for (const auto& t : shape.mesh.triangles) m.triangles.push_back(t + glm::uvec3(base));
}

}  // namespace

std::uint32_t last_birth_step(const Plant& plant) {
  std::uint32_t last = 0;
  for (const auto& n : plant.nodes) last = std::max(last, n.birth_step);
  return last;
}

std::uint32_t organ_birth_step(const Plant& plant, const Organ& organ, std::uint32_t last_step) {
  const auto n = static_cast<std::size_t>(organ.node);
  return organ.node >= 0 && n < plant.nodes.size() ? plant.nodes[n].birth_step : last_step;
}

MesherOptions with_leaf_mesh(MesherOptions o) {
  if (!o.leaf_obj.empty() && !o.leaf) o.leaf = std::make_shared<const OrganShape>(load_organ_obj(o.leaf_obj));
  return o;
}

OrganShapes organ_shapes(const Plant& plant, const MesherOptions& o) {
  return OrganShapes(plant, o.leaf.get());
}

glm::vec3 material_srgb(std::string_view material) {
  if (material == "bark") return {0.40f, 0.27f, 0.17f};
  if (material == "flower") return organ_kind_srgb(OrganKind::Flower);
  return organ_kind_srgb(OrganKind::Leaf);
}

OutputMesh mesh_plant(const Plant& plant, const MesherOptions& o) {
  OutputMesh m;
  const OrganShapes shapes = organ_shapes(plant, o);
  // Vertex colours only when some organ has a colour of its own; then every vertex has one, its organ's
  // or its group's material colour.
  const bool colored = shapes.any_color(plant);
  const std::uint32_t last_step = last_birth_step(plant);
  auto organ_mesh = [&](const Organ& organ) {
    const std::uint32_t step = organ_birth_step(plant, organ, last_step);
    if (!colored) return add_organ(m, organ, shapes.of(organ), nullptr, step);
    pad_colors(m);
    const glm::vec3 c = shapes.linear_color(organ);
    add_organ(m, organ, shapes.of(organ), &c, step);
  };
  auto group = [&](const char* name, const char* material, auto&& body) {
    const auto first = static_cast<std::uint32_t>(m.triangles.size());
    body();
    const auto count = static_cast<std::uint32_t>(m.triangles.size()) - first;
    if (count > 0) m.groups.push_back({name, material, first, count});
  };
  add_branches(m, plant, o);
  group("leaves", "leaf", [&] {
    for (const auto& organ : plant.organs)
      if (organ.kind == OrganKind::Leaf || organ.kind == OrganKind::YoungLeaf) organ_mesh(organ);
  });
  group("flowers", "flower", [&] {
    for (const auto& organ : plant.organs)
      if (organ.kind == OrganKind::Flower || organ.kind == OrganKind::Bud) organ_mesh(organ);
  });
  group("polygons", "leaf", [&] {
    for (const auto& poly : plant.polygons) {
      if (poly.vertices.size() < 3) continue;
      const auto base = static_cast<std::uint32_t>(m.positions.size());
      glm::vec3 n(0.0f);  // Newell normal
      for (std::size_t i = 0; i < poly.vertices.size(); ++i) {
        const glm::vec3 a = poly.vertices[i], b = poly.vertices[(i + 1) % poly.vertices.size()];
        n += glm::vec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
      }
      n = glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0, 1, 0);
      for (const auto& v : poly.vertices) {  // polygons stand for no node: they appear with the plant
        m.positions.push_back(v);
        m.normals.push_back(n);
        m.birth_steps.push_back(last_step);
      }
      for (std::uint32_t i = 1; i + 1 < poly.vertices.size(); ++i)
        m.triangles.emplace_back(base, base + i, base + i + 1);
    }
  });
  complete_vertex_data(m);
  return m;
}

const std::vector<MaterialColor>& material_colors() {
  static const std::vector<MaterialColor> kMaterials = [] {
    std::vector<MaterialColor> v;
    for (const char* name : {"bark", "leaf", "flower"}) {
      const glm::vec3 c = srgb_to_linear(material_srgb(name));
      v.push_back({name, c.r, c.g, c.b});
    }
    return v;
  }();
  return kMaterials;
}

glm::vec3 material_color(const std::string& material) {
  for (const auto& c : material_colors())
    if (material == c.material) return {static_cast<float>(c.r), static_cast<float>(c.g), static_cast<float>(c.b)};
  return glm::vec3(0.5f);
}

void pad_colors(OutputMesh& m) {
  if (m.colors.size() < m.positions.size()) m.colors.resize(m.positions.size(), glm::vec3(kUncoloured));
}

}  // namespace growbench
