#include "algorithms/vines/surface.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "scenes/geometry.hpp"

namespace growbench::vines {
namespace {

constexpr std::int32_t kNone = -1;

glm::vec3 bary_of(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::vec3 e1 = b - a, e2 = c - a, d = p - a;
  const float g11 = glm::dot(e1, e1), g12 = glm::dot(e1, e2), g22 = glm::dot(e2, e2);
  const float det = g11 * g22 - g12 * g12;
  if (!(det > 0.0f)) return {1.0f, 0.0f, 0.0f};
  const float r1 = glm::dot(e1, d), r2 = glm::dot(e2, d);
  const float v = (g22 * r1 - g12 * r2) / det, w = (g11 * r2 - g12 * r1) / det;
  return {1.0f - v - w, v, w};
}

// Barycentric coordinates of uv in the UV triangle (a, b, c); nullopt for a triangle of no UV area.
std::optional<glm::vec3> uv_bary(const glm::vec2& p, const glm::vec2& a, const glm::vec2& b, const glm::vec2& c) {
  const glm::vec2 e1 = b - a, e2 = c - a, d = p - a;
  const float det = e1.x * e2.y - e1.y * e2.x;
  if (!(std::abs(det) > 0.0f)) return std::nullopt;
  const float v = (d.x * e2.y - d.y * e2.x) / det, w = (e1.x * d.y - e1.y * d.x) / det;
  return glm::vec3(1.0f - v - w, v, w);
}

struct UnionFind {
  std::vector<std::uint32_t> up;
  explicit UnionFind(std::size_t n) : up(n) { std::iota(up.begin(), up.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (up[x] != x) x = up[x] = up[up[x]];
    return x;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) up[std::max(a, b)] = std::min(a, b);  // the lower index is the root: deterministic
  }
};

// Joins consecutive pieces that meet and run on in the same direction in UV (an edge inside a region
// mapped by one affine map, such as a canvas), and drops pieces of no length.
void join_straight(std::vector<UvPiece>& pieces) {
  std::size_t w = 0;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const UvPiece& p = pieces[i];
    if (w > 0) {
      UvPiece& q = pieces[w - 1];
      const glm::vec2 d1 = q.b - q.a, d2 = p.b - p.a;
      const float cross = d1.x * d2.y - d1.y * d2.x, scale = glm::length(d1) * glm::length(d2);
      if (q.b == p.a && (glm::dot(d2, d2) == 0.0f || (std::abs(cross) <= 1e-6f * scale && glm::dot(d1, d2) >= 0.0f))) {
        q.b = p.b;
        continue;
      }
    }
    pieces[w++] = p;
  }
  pieces.resize(w);
}

}  // namespace

Surface::Surface(const TriangleMesh& mesh) {
  // Weld equal positions, so that seams which duplicate vertices do not cut the surface apart.
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> by_hash;
  std::vector<std::uint32_t> weld(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const glm::vec3& v = mesh.vertices[i];
    std::uint32_t bits[3];
    std::memcpy(bits, &v, sizeof bits);
    const std::uint64_t h = (std::uint64_t{bits[0]} * 0x9E3779B97F4A7C15ull) ^ (std::uint64_t{bits[1]} << 21) ^
                            (std::uint64_t{bits[2]} * 0xC2B2AE3D27D4EB4Full);
    auto& same = by_hash[h];
    std::uint32_t id = static_cast<std::uint32_t>(pos_.size());
    for (const std::uint32_t j : same)
      if (pos_[j] == v) id = j;
    if (id == pos_.size()) {
      pos_.push_back(v);
      same.push_back(id);
    }
    weld[i] = id;
  }
  corners_.reserve(mesh.triangles.size());
  uv_.reserve(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::uvec3& tri = mesh.triangles[t];
    corners_.emplace_back(weld[tri.x], weld[tri.y], weld[tri.z]);
    const glm::uvec3& ut = mesh.uv_triangles[t];
    uv_.push_back({mesh.uvs[ut.x], mesh.uvs[ut.y], mesh.uvs[ut.z]});
  }
  fit_uvs();
  build();
}

void Surface::fit_uvs() {
  glm::vec2 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
  for (const auto& t : uv_)
    for (const glm::vec2& c : t) {
      lo = glm::min(lo, c);
      hi = glm::max(hi, c);
    }
  if (uv_.empty() || (lo.x >= 0.0f && lo.y >= 0.0f && hi.x <= 1.0f && hi.y <= 1.0f)) return;
  // The unit square as a decal on the mesh spans [origin, origin + side]^2 of its coordinates.
  uv_origin_ = lo;
  uv_side_ = std::max({hi.x - lo.x, hi.y - lo.y, std::numeric_limits<float>::min()});
  for (auto& t : uv_)
    for (glm::vec2& c : t) c = glm::min((c - uv_origin_) / uv_side_, glm::vec2(1.0f));
}

Surface Surface::canvas(const glm::vec3& origin, const glm::vec3& u_axis, const glm::vec3& v_axis) {
  Surface s;
  s.pos_ = {origin, origin + u_axis, origin + u_axis + v_axis, origin + v_axis};
  s.corners_ = {{0, 1, 2}, {0, 2, 3}};
  s.uv_ = {{glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1)}, {glm::vec2(0, 0), glm::vec2(1, 1), glm::vec2(0, 1)}};
  s.build();
  return s;
}

void Surface::build() {
  const std::size_t n = corners_.size();
  normal_.resize(n);
  ratio_.resize(n);
  for (std::size_t t = 0; t < n; ++t) {
    const glm::vec3 &a = pos_[corners_[t].x], &b = pos_[corners_[t].y], &c = pos_[corners_[t].z];
    const glm::vec3 cr = glm::cross(b - a, c - a);
    const double area = 0.5 * glm::length(cr);
    normal_[t] = area > 0.0 ? glm::normalize(cr) : glm::vec3(0.0f);
    const glm::vec2 e1 = uv_[t][1] - uv_[t][0], e2 = uv_[t][2] - uv_[t][0];
    const double uv_area = 0.5 * std::abs(static_cast<double>(e1.x) * e2.y - static_cast<double>(e1.y) * e2.x);
    ratio_[t] = uv_area > 0.0 && area > 0.0 ? static_cast<float>(area / uv_area) : 0.0f;
    if (ratio_[t] > 0.0f) {
      surface_area_ += area;
      uv_area_ += uv_area;
    }
  }
  mean_ratio_ = uv_area_ > 0.0 ? surface_area_ / uv_area_ : 1.0;
  build_adjacency();
  build_uv_grid();
}

void Surface::build_adjacency() {
  const std::size_t n = corners_.size();
  next_tri_.assign(n, {kNone, kNone, kNone});
  next_edge_.assign(n, {-1, -1, -1});
  // Edge (lower position id, higher) -> its (triangle, edge) uses; an edge with exactly two is interior.
  std::unordered_map<std::uint64_t, std::vector<std::pair<std::uint32_t, std::int8_t>>> edges;
  edges.reserve(3 * n);
  for (std::uint32_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = corners_[t][k], b = corners_[t][(k + 1) % 3];
      edges[(std::uint64_t{std::min(a, b)} << 32) | std::max(a, b)].emplace_back(t, static_cast<std::int8_t>(k));
    }
  for (const auto& [key, uses] : edges) {
    if (uses.size() != 2) continue;  // a boundary, or a non-manifold edge: walks stop there
    const auto [t0, k0] = uses[0];
    const auto [t1, k1] = uses[1];
    next_tri_[t0][k0] = static_cast<std::int32_t>(t1);
    next_edge_[t0][k0] = k1;
    next_tri_[t1][k1] = static_cast<std::int32_t>(t0);
    next_edge_[t1][k1] = k0;
  }
  UnionFind charts(n);
  for (std::uint32_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k)
      if (next_tri_[t][k] != kNone && !is_seam(t, k)) charts.join(t, static_cast<std::uint32_t>(next_tri_[t][k]));
  chart_.resize(n);
  std::unordered_map<std::uint32_t, std::uint32_t> number;
  for (std::uint32_t t = 0; t < n; ++t) {
    const auto [it, fresh] = number.emplace(charts.find(t), static_cast<std::uint32_t>(number.size()));
    chart_[t] = it->second;
  }
  charts_ = number.size();
}

bool Surface::is_seam(std::uint32_t t, int k) const {
  const std::int32_t o = next_tri_[t][k];
  if (o == kNone) return false;
  const int ok = next_edge_[t][k];
  const auto u = static_cast<std::size_t>(o);
  // The neighbour's edge runs the other way on a consistently wound mesh; match corners by position.
  const std::uint32_t a = corners_[t][k];
  const int oa = corners_[u][ok] == a ? ok : (ok + 1) % 3, ob = oa == ok ? (ok + 1) % 3 : ok;
  return uv_[t][k] != uv_[u][oa] || uv_[t][(k + 1) % 3] != uv_[u][ob];
}

void Surface::build_uv_grid() {
  glm::vec2 lo(0.0f), hi(1.0f);
  for (std::size_t t = 0; t < uv_.size(); ++t)
    if (ratio_[t] > 0.0f)
      for (const auto& c : uv_[t]) {
        lo = glm::min(lo, c);
        hi = glm::max(hi, c);
      }
  grid_n_ = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(uv_.size()))), 1, 1024);
  grid_min_ = lo;
  grid_cell_ = glm::max((hi - lo) / static_cast<float>(grid_n_), glm::vec2(1e-12f));
  const auto cells = static_cast<std::size_t>(grid_n_) * static_cast<std::size_t>(grid_n_);
  std::vector<std::uint32_t> count(cells + 1, 0);
  auto range = [&](std::size_t t, auto&& visit) {
    glm::vec2 a = uv_[t][0], b = uv_[t][0];
    for (const auto& c : uv_[t]) {
      a = glm::min(a, c);
      b = glm::max(b, c);
    }
    const glm::ivec2 i0 = glm::clamp(glm::ivec2(glm::floor((a - grid_min_) / grid_cell_)), 0, grid_n_ - 1);
    const glm::ivec2 i1 = glm::clamp(glm::ivec2(glm::floor((b - grid_min_) / grid_cell_)), 0, grid_n_ - 1);
    for (int y = i0.y; y <= i1.y; ++y)
      for (int x = i0.x; x <= i1.x; ++x) visit(static_cast<std::size_t>(y) * grid_n_ + static_cast<std::size_t>(x));
  };
  for (std::size_t t = 0; t < uv_.size(); ++t)
    if (ratio_[t] > 0.0f) range(t, [&](std::size_t c) { ++count[c + 1]; });
  std::partial_sum(count.begin(), count.end(), count.begin());
  grid_start_ = count;
  grid_tris_.resize(count.back());
  for (std::size_t t = 0; t < uv_.size(); ++t)
    if (ratio_[t] > 0.0f) range(t, [&](std::size_t c) { grid_tris_[count[c]++] = static_cast<std::uint32_t>(t); });
}

glm::vec3 Surface::position(const Location& l) const {
  const glm::uvec3& c = corners_[l.tri];
  return l.bary.x * pos_[c.x] + l.bary.y * pos_[c.y] + l.bary.z * pos_[c.z];
}

glm::vec2 Surface::uv(const Location& l) const {
  const auto& u = uv_[l.tri];
  return l.bary.x * u[0] + l.bary.y * u[1] + l.bary.z * u[2];
}

glm::vec3 Surface::uv_to_3d(std::uint32_t t, const glm::vec2& d) const {
  // Solve d = a (uv1 - uv0) + b (uv2 - uv0), then map with the 3D edges.
  const glm::vec2 e1 = uv_[t][1] - uv_[t][0], e2 = uv_[t][2] - uv_[t][0];
  const float det = e1.x * e2.y - e1.y * e2.x;
  if (!(std::abs(det) > 0.0f)) return glm::vec3(0.0f);
  const float a = (d.x * e2.y - d.y * e2.x) / det, b = (e1.x * d.y - e1.y * d.x) / det;
  const glm::uvec3& c = corners_[t];
  return a * (pos_[c.y] - pos_[c.x]) + b * (pos_[c.z] - pos_[c.x]);
}

glm::vec2 Surface::to_uv(std::uint32_t t, const glm::vec3& d) const {
  const glm::uvec3& c = corners_[t];
  const glm::vec3 b = bary_of(pos_[c.x] + d, pos_[c.x], pos_[c.y], pos_[c.z]);
  return b.y * (uv_[t][1] - uv_[t][0]) + b.z * (uv_[t][2] - uv_[t][0]);
}

std::optional<Location> Surface::locate(const glm::vec2& uv) const {
  glm::ivec2 i = glm::ivec2(glm::floor((uv - grid_min_) / grid_cell_));
  // The grid's far edges belong to its last cells (uv = 1 lies on the unit square).
  if (i.x == grid_n_ && uv.x <= grid_min_.x + grid_cell_.x * static_cast<float>(grid_n_)) i.x = grid_n_ - 1;
  if (i.y == grid_n_ && uv.y <= grid_min_.y + grid_cell_.y * static_cast<float>(grid_n_)) i.y = grid_n_ - 1;
  if (i.x < 0 || i.y < 0 || i.x >= grid_n_ || i.y >= grid_n_) return std::nullopt;
  const std::size_t cell = static_cast<std::size_t>(i.y) * grid_n_ + static_cast<std::size_t>(i.x);
  // A little slack on the edges, so that a point on an edge shared by two triangles is found.
  constexpr float kSlack = -1e-6f;
  for (std::uint32_t k = grid_start_[cell]; k < grid_start_[cell + 1]; ++k) {
    const std::uint32_t t = grid_tris_[k];  // increasing: the lowest index wins where charts overlap
    const auto b = uv_bary(uv, uv_[t][0], uv_[t][1], uv_[t][2]);
    if (b && b->x >= kSlack && b->y >= kSlack && b->z >= kSlack) {
      const glm::vec3 c = glm::max(*b, glm::vec3(0.0f));
      return Location{t, c / (c.x + c.y + c.z)};
    }
  }
  return std::nullopt;
}

Location Surface::closest(const glm::vec3& p) const {
  Location best;
  float best_d2 = std::numeric_limits<float>::infinity();
  for (std::uint32_t t = 0; t < corners_.size(); ++t) {
    if (ratio_[t] <= 0.0f) continue;
    const glm::uvec3& c = corners_[t];
    const glm::vec3 q = geom::closest_point_on_triangle(p, pos_[c.x], pos_[c.y], pos_[c.z]);
    const float d2 = glm::dot(q - p, q - p);
    if (d2 < best_d2) {
      best_d2 = d2;
      best = {t, glm::max(bary_of(q, pos_[c.x], pos_[c.y], pos_[c.z]), glm::vec3(0.0f))};
      best.bary /= best.bary.x + best.bary.y + best.bary.z;
    }
  }
  return best;
}

Walk Surface::walk(const Location& from, const glm::vec3& d, float length, bool cross_seams) const {
  Walk w;
  walk(from, d, length, cross_seams, w);
  return w;
}

void Surface::walk(const Location& from, const glm::vec3& d_in, float length, bool cross_seams, Walk& w) const {
  w.length = 0.0f;
  w.stopped = false;
  w.seams = 0;
  w.pieces.clear();
  w.end = from;
  Location& at = w.end;
  UvPiece piece{uv(at), uv(at)};
  glm::vec3 d = d_in - glm::dot(d_in, normal_[at.tri]) * normal_[at.tri];
  float left = length;
  int no_progress = 0;
  for (int guard = 0; guard < 256 && left > 0.0f; ++guard) {
    const glm::uvec3& c = corners_[at.tri];
    const glm::vec3 p0 = pos_[c.x], e1 = pos_[c.y] - p0, e2 = pos_[c.z] - p0;
    const float g11 = glm::dot(e1, e1), g12 = glm::dot(e1, e2), g22 = glm::dot(e2, e2);
    const float det = g11 * g22 - g12 * g12, dl = glm::length(d);
    if (!(det > 0.0f) || !(dl > 0.0f)) {
      w.stopped = true;
      break;
    }
    d /= dl;
    // Barycentric rates per unit of surface length along d.
    const float r1 = glm::dot(e1, d), r2 = glm::dot(e2, d);
    const float a = (g22 * r1 - g12 * r2) / det, b = (g11 * r2 - g12 * r1) / det;
    const glm::vec3 rate(-a - b, a, b);
    float t_exit = left;
    int out = -1;
    for (int i = 0; i < 3; ++i)
      if (rate[i] < 0.0f) {
        const float ti = std::max(0.0f, at.bary[i]) / -rate[i];
        if (ti < t_exit) {
          t_exit = ti;
          out = i;
        }
      }
    at.bary += t_exit * rate;
    w.length += t_exit;
    left -= t_exit;
    if (out < 0) {  // ends inside this triangle
      at.bary = glm::max(at.bary, glm::vec3(0.0f));
      at.bary /= at.bary.x + at.bary.y + at.bary.z;
      break;
    }
    at.bary[out] = 0.0f;
    at.bary /= at.bary.x + at.bary.y + at.bary.z;
    no_progress = t_exit > 1e-7f * std::sqrt(std::max(g11, g22)) ? 0 : no_progress + 1;
    // Corner `out` reached zero: the walk leaves through the edge opposite it.
    const int edge = (out + 1) % 3;
    const std::int32_t next = next_tri_[at.tri][edge];
    const bool seam = next != kNone && is_seam(at.tri, edge);
    if (next == kNone || (seam && !cross_seams) || no_progress > 4 || ratio_[static_cast<std::size_t>(next)] <= 0.0f) {
      w.stopped = true;
      break;
    }
    const auto nt = static_cast<std::uint32_t>(next);
    const int ne = next_edge_[at.tri][edge];
    const std::uint32_t pa = c[edge], pb = c[(edge + 1) % 3];
    const float sa = at.bary[edge], sb = at.bary[(edge + 1) % 3];
    // Unfold d about the shared edge into the neighbour's plane: keep its part along the edge, turn the
    // part across it from "out of this triangle" to "into that one".
    const glm::vec3 ev = glm::normalize(pos_[pb] - pos_[pa]);
    const glm::vec3 opp_old = pos_[c[out]], opp_new = pos_[corners_[nt][(ne + 2) % 3]];
    glm::vec3 m0 = glm::cross(ev, normal_[at.tri]);
    if (glm::dot(m0, opp_old - pos_[pa]) > 0.0f) m0 = -m0;
    glm::vec3 m1 = glm::cross(ev, normal_[nt]);
    if (glm::dot(m1, opp_new - pos_[pa]) < 0.0f) m1 = -m1;
    d = glm::dot(d, ev) * ev + std::max(0.0f, glm::dot(d, m0)) * m1;
    // The walk is straight on the surface but bends in UV wherever the next triangle maps differently:
    // a piece ends at every edge (pieces that carry on in a straight line are joined again below).
    piece.b = uv(at);
    w.pieces.push_back(piece);
    w.seams += seam ? 1 : 0;
    Location in{nt, glm::vec3(0.0f)};
    for (int k = 0; k < 3; ++k) {
      if (corners_[nt][k] == pa) in.bary[k] = sa;
      if (corners_[nt][k] == pb) in.bary[k] = sb;
    }
    at = in;
    piece.a = uv(at);
  }
  piece.b = uv(at);
  w.pieces.push_back(piece);
  join_straight(w.pieces);
}

}  // namespace growbench::vines
