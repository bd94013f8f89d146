// Runions space colonization: open venation (Runions et al. 2005, trees 2007) and closed venation
// (relative neighbourhood, 2005), in a volume, on surfaces, or held on them (the Hyphae variant).
//
// Cost model. Attraction points sit in a few nanoflann kd-trees, one per tier of distance to their
// nearest node, rebuilt only when stale points crowd one (compact_active). Each point keeps its
// nearest node within the influence radius; nodes are only ever added, so after a step only the
// points within the influence radius of the *new* nodes can change their nearest node or die. One
// radius query per new node and tier (in parallel) does all the updating; there is never a rebuild plus
// re-query of every point per step. Points that have a node in range form the `active` list, the only
// points a step looks at.
//
// Determinism. Parallel work writes to per-item slots; everything that depends on order (merging
// query results, accumulating directions, appending nodes) runs in a fixed order (node index, then
// query-result index), and ties between equidistant nodes go to the lower node index. The plant is
// bit-identical for any thread count.
#include "algorithms/spacecol/spacecol.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>

#include <fmt/format.h>
#include <glm/gtc/noise.hpp>
#include <tbb/parallel_for.h>

#include "algorithms/colonization.hpp"
#include "core/kdtree.hpp"
#include "core/random.hpp"

namespace growbench {
namespace {

// ---- parameter table (what `growbench list` prints) ----
const AlgorithmInfo kInfo = {
    .name = "spacecol",
    .summary =
        "Runions space colonization: attraction points pull nodes; open or closed venation; free, avoid or cling",
    .params =
        {
            param::choice("venation", "open", {"open", "closed"})
                .doc("open: each point pulls its nearest node; closed: every node in its relative neighbourhood"),
            param::choice("points", "auto", {"auto", "envelope", "surface", "file"})
                .doc("attraction points: in the scene envelope, on the surfaces (area-weighted), or from points_file; "
                     "auto = surface when surface=cling or the scene has no envelope, else envelope"),
            param::text("points_file")
                .doc("text file of attraction points, one 'x y z' (or x,y,z) per line, # comments (points=file)"),
            param::integer("point_count", 20000).range(1, 1e7).doc("number of attraction points sampled"),
            param::real("center_density", 0.0)
                .range(0, 16)
                .doc("envelope points grow denser toward its centre, density ~ exp(-k s^2), s the distance from "
                     "the centre in half-sizes of the envelope (0: uniform). The Hyphae notes' fix for roots around "
                     "a volume whose veins stop at the first points they reach"),
            param::real("surface_offset", 0.01)
                .range(0, 10)
                .unit("m")
                .doc("surface-sampled points are lifted this far along the surface normal"),
            param::real("influence", 0.25)
                .range(1e-4, 1e3)
                .unit("m")
                .doc("influence radius d_i: points farther from every node are ignored"),
            param::real("kill", 0.05)
                .range(1e-5, 1e3)
                .unit("m")
                .doc("kill distance d_k: a point this close to a node is removed"),
            param::real("step", 0.02).range(1e-5, 1e2).unit("m").doc("step length D between a node and its child"),
            param::vec3("tropism", glm::dvec3(0.0))
                .range(-10, 10)
                .doc("added to each normalised growth direction (e.g. 0,0.2,0 bends growth upward)"),
            param::real("noise", 0.0)
                .range(0, 10)
                .doc("noise vector times this is added to each growth direction (see noise_field)"),
            param::choice("noise_field", "position", {"position", "random"})
                .doc("position: a coherent simplex-noise field of the node's position, so neighbouring branches "
                     "bend alike (the Hyphae notes' noise(CLPOS)); random: a fresh random unit vector per node "
                     "and step"),
            param::real("noise_scale", 0.25)
                .range(1e-4, 1e3)
                .unit("m")
                .doc("feature size of the position noise field: it turns over about this distance"),
            param::choice("surface", "free", {"free", "avoid", "cling"})
                .doc("free: ignore solids; avoid: push nodes out of solids; cling: hold nodes at cling_distance from "
                     "the "
                     "nearest surface (the Hyphae collision vector)"),
            param::real("cling_distance", 0.01)
                .range(0, 10)
                .unit("m")
                .doc("distance kept from the surface (cling), minimum clearance (avoid)"),
            param::real("split", 0.1)
                .range(0, 1)
                .doc("when the pulls on a node nearly cancel (|sum| < split * count), grow two children toward the two "
                     "most opposed points instead of stalling (0: such a node stalls)"),
            param::boolean("seek", true)
                .doc("while no attraction point is within reach, roots grow along their seed direction"),
            param::real("tip_radius", 0.002).range(1e-6, 10).unit("m").doc("radius of branch tips (pipe model)"),
            param::real("pipe_exponent", 2.5).range(1, 4).doc("pipe model exponent n: r^n = sum of children's r^n"),
            param::choice("leaves", "tips", {"none", "tips", "interval", "both"})
                .doc("where leaves go: none, at branch tips, every leaf_interval nodes, or both"),
            param::integer("leaf_interval", 6)
                .range(1, 1000)
                .doc("a leaf every k nodes along a branch (leaves=interval/both)"),
            param::real("leaf_size", 0.05).range(0, 10).unit("m").doc("leaf blade length"),
        },
    .test_params = {"surface=avoid", "point_count=4000"},
};

using Cloud = Vec3Cloud;
using PointTree = Vec3Tree;
using NodeTree = Vec3DynamicTree;

// Collects (index, squared distance) within a radius, skipping entries a filter rejects.
template <class Keep>
struct CollectWithin {
  using DistanceType = float;
  using IndexType = std::uint32_t;
  float radius2;
  std::vector<std::pair<std::uint32_t, float>>* out;
  Keep keep;
  void init() {}
  [[nodiscard]] std::size_t size() const { return out->size(); }
  [[nodiscard]] bool full() const { return true; }
  bool addPoint(float d2, std::uint32_t i) {
    if (d2 < radius2 && keep(i, d2)) out->emplace_back(i, d2);
    return true;
  }
  [[nodiscard]] float worstDist() const { return radius2; }
};
template <class Keep>
CollectWithin<Keep> collect_within(float r2, std::vector<std::pair<std::uint32_t, float>>& out, Keep keep) {
  out.clear();
  return CollectWithin<Keep>{r2, &out, keep};
}

using colonization::safe_normalize;

using spacecol::Leaves;
using spacecol::NoiseField;
using spacecol::Points;
using spacecol::Surface;
constexpr std::int32_t kNone = -1;
constexpr float kStallFraction = 0.05f;  // a child closer than this * step to a sibling means a stalled node
// Point tiers (associate()): each tier's upper bound is this times the one below it. Thinner tiers
// cost more queries per node (one tree descent each), thicker ones more points per query that the
// filter then rejects (their nearest node is already nearer than the new one).
constexpr float kTierRatio = 1.5f;
constexpr std::size_t kMaxTiers = 16;
constexpr std::size_t kRebuildSlack = 1024;  // stale points a tier may hold beyond half before a rebuild
// Points per kd-tree leaf. Larger than nanoflann's usual 10-16: a radius query here covers many
// leaves, and scanning a leaf's points costs less than descending to more, smaller leaves.
constexpr std::size_t kLeafSize = 32;

// The pulls of the attraction points on one node, accumulated in a fixed order.
struct Pull {
  glm::vec3 sum{0.0f};
  glm::vec3 first{0.0f};     // the first pull seen
  glm::vec3 opposite{0.0f};  // the pull most opposed to `first` (filled only for nearly cancelling nodes)
  float min_dot = 2.0f;
  std::uint32_t count = 0;
};

class SpaceColonization final : public PortableGrowthAlgorithm {
 public:
  const AlgorithmInfo& describe() const override { return kInfo; }

  // The points file is read here, in the harness's scene_load phase; start_with() reads it itself when
  // this was not called (the plugin build, tests that call start() directly).
  void load_inputs(const Params& p) override {
    if (p.text("points") != "file") return;
    loaded_path_ = p.text("points_file");
    loaded_pts_ = read_points_file(loaded_path_);
    loaded_ = true;
  }

  void start_with(const Scene& scene, const HostQueries& query, const Params& p, std::uint64_t seed) override {
    scene_ = &scene;
    query_ = &query;
    seed_ = seed;
    not_applicable_.clear();
    cfg_ = spacecol::make_config(p);
    if (cfg_.kill >= cfg_.influence)
      throw InputError(fmt::format("algorithm 'spacecol': kill ({}) must be smaller than influence ({})", cfg_.kill,
                                   cfg_.influence));
    if (cfg_.step >= cfg_.influence)
      throw InputError(fmt::format("algorithm 'spacecol': step ({}) must be smaller than influence ({})", cfg_.step,
                                   cfg_.influence));
    if (cfg_.surface != Surface::Free && !query.has_sdf())
      throw InputError("algorithm 'spacecol': surface=avoid/cling needs the scene's distance field");

    Rng offsets(seed, 0x40000001ull, 0);  // each seed reads its own part of the noise field
    for (glm::vec3& o : noise_offset_)
      o = glm::vec3(offsets.uniform(0.0, 256.0), offsets.uniform(0.0, 256.0), offsets.uniform(0.0, 256.0));
    sample_points(p.text("points_file"));
    closest_.assign(pts_.size(), kNone);
    closest_d2_.assign(pts_.size(), 0.0f);
    alive_.assign(pts_.size(), 1);
    where_.assign(pts_.size(), 0);
    make_tiers();
    build_trees();
    alive_count_ = pts_.size();
    if (cfg_.closed)
      node_tree_ = std::make_unique<NodeTree>(3, node_cloud_, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    step_ = 0;
    add_due_roots();
  }

  bool step() override {
    ++step_;
    std::vector<std::int32_t> new_nodes;
    if (cfg_.closed)
      grow_closed(new_nodes);
    else
      grow_open(new_nodes);
    if (new_nodes.empty() && cfg_.seek && !ever_influenced_) seek(new_nodes);
    if (!new_nodes.empty()) associate(new_nodes);
    const bool roots_pending = add_due_roots();
    compact_active();
    if (alive_count_ == 0 && !roots_pending) return false;
    return !new_nodes.empty() || roots_pending || step_ < max_start_step_;
  }

  void finish() override {
    assign_pipe_radii(plant_, cfg_.tip_radius, cfg_.pipe_exponent);
    place_leaves();
  }

  const Plant& plant() const override { return plant_; }

  OwnVerdict own_verdict() const override {
    OwnVerdict v{not_applicable_, {}};
    if (!pts_.empty() && alive_count_ == pts_.size())
      v.degenerate.push_back(fmt::format("attraction: none of the {} attraction points was reached", pts_.size()));
    return v;
  }

  std::vector<std::pair<std::string, double>> stats() const override {
    return {{"attraction_points", static_cast<double>(pts_.size())},
            {"attraction_points_left", static_cast<double>(alive_count_)},
            {"stalled_nodes", static_cast<double>(stalled_count_)},
            {"tree_rebuilds", static_cast<double>(tree_builds_)}};
  }

 private:
  // ---------- attraction points ----------
  bool accept_point(const glm::vec3& q) const {
    return colonization::zones_allow(*scene_, *query_, q) && !query_->inside(q);  // never inside a solid
  }

  // Fills pts_ with `count` accepted candidates, generated in parallel in index order.
  template <class Gen>
  void sample_accepted(std::size_t count, Gen gen, const char* what) {
    const std::size_t max_tries = 50 * count + 1000;
    std::size_t next = 0;
    while (pts_.size() < count && next < max_tries) {
      const std::size_t batch =
          std::min<std::size_t>(max_tries - next, std::max<std::size_t>(4096, 2 * (count - pts_.size())));
      std::vector<glm::vec3> cand(batch);
      std::vector<std::uint8_t> ok(batch);
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, batch, 1024), [&](const auto& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
          cand[i] = gen(next + i);
          ok[i] = accept_point(cand[i]) ? 1 : 0;
        }
      });
      for (std::size_t i = 0; i < batch && pts_.size() < count; ++i)
        if (ok[i]) pts_.push_back(cand[i]);
      next += batch;
    }
    // A point is never kept inside a solid; when most of the region is solid, the few points left would
    // grow a plant that answers none of what was asked (a lone stalk toward the last point).
    if (2 * pts_.size() < count)
      throw InputError(fmt::format(
          "algorithm 'spacecol': only {} of {} attraction points could be placed {} of scene '{}' in {} tries: the "
          "other candidates fell inside solids or outside the include zones; keep the region clear of solid meshes, "
          "or ask for fewer points",
          pts_.size(), count, what, scene_->name, next));
  }

  // Rejection sampling for center_density: keeps q with probability exp(-k s^2), s its distance from the
  // envelope's centre in half-sizes (an ellipsoid's radii, else half the bounding box).
  [[nodiscard]] bool near_center(const Shape& env, const glm::vec3& q, double u) const {
    const Aabb b = env.bounds();
    const glm::vec3 c = env.kind == Shape::Kind::Sphere ? env.center : 0.5f * (b.min + b.max);
    const glm::vec3 half = env.kind == Shape::Kind::Sphere ? env.radii : 0.5f * b.size();
    const glm::vec3 s = (q - c) / glm::max(half, glm::vec3(1e-20f));
    return u < std::exp(-static_cast<double>(cfg_.center_density) * glm::dot(s, s));
  }

  void sample_points(const std::string& points_file) {
    Points mode = cfg_.points;
    if (mode == Points::Auto)
      mode = (cfg_.surface == Surface::Cling || !scene_->envelope) ? Points::Surface : Points::Envelope;
    const std::size_t count = cfg_.point_count;
    pts_.clear();
    pts_.reserve(count);
    if (mode == Points::Envelope) {
      if (!scene_->envelope)
        throw InputError(
            fmt::format("algorithm 'spacecol': points=envelope but scene '{}' has no envelope", scene_->name));
      const Shape& env = *scene_->envelope;
      const Aabb b = env.bounds();
      sample_accepted(
          count,
          [&](std::size_t i) {
            // With center_density a candidate may take many tries, so it draws from a stream of its own
            // (overlapping slots gave neighbouring candidates the same point); the uniform case keeps the
            // stream it always had, so its plants are unchanged.
            Rng rng = cfg_.center_density > 0.0f ? Rng(seed_, (0xE2ull << 40) | i, 0) : Rng(seed_, 0xE1u, 4 * i);
            for (int tries = 0; tries < (cfg_.center_density > 0.0f ? 1024 : 64); ++tries) {
              glm::vec3 q;
              if (env.kind == Shape::Kind::Sphere)
                q = env.center + rng.in_unit_ball() * env.radii;
              else
                q = b.min + glm::vec3(rng.uniform(), rng.uniform(), rng.uniform()) * b.size();
              if (env.kind == Shape::Kind::Mesh && !query_->inside_shape(kEnvelopeShape, q)) continue;
              if (cfg_.center_density > 0.0f && !near_center(env, q, rng.uniform())) continue;
              return q;
            }
            return glm::vec3(std::numeric_limits<float>::quiet_NaN());
          },
          "in the envelope");
      pts_.erase(std::remove_if(pts_.begin(), pts_.end(), [](const glm::vec3& v) { return std::isnan(v.x); }),
                 pts_.end());
    } else if (mode == Points::Surface) {
      // With no climbable mesh, the samples would lie on the ground: a carpet, not what surface points mean.
      if (!scene_->has_climbable())
        not_applicable_ =
            fmt::format("points on the surfaces: scene '{}' has no climbable surface, only ground", scene_->name);
      const float off = cfg_.surface_offset;
      sample_accepted(
          count,
          [&](std::size_t i) {
            const SurfaceSample s = query_->sample_surface(seed_, i);
            return s.position + off * s.normal;
          },
          "on the surfaces");
    } else if (loaded_ && loaded_path_ == points_file) {
      pts_ = std::move(loaded_pts_);
      loaded_ = false;
    } else {
      pts_ = read_points_file(points_file);
    }
    morton_order();
  }

  // Orders the points along a Morton (Z-order) curve, ties by their original index: point ids become
  // spatially coherent, so kd-tree leaves and the per-point arrays are read with good locality
  // (faster radius queries on large point sets). Deterministic, like everything here.
  void morton_order() {
    Aabb b;
    for (const auto& v : pts_) b.extend(v);
    const glm::vec3 ext = glm::max(b.size(), glm::vec3(1e-20f));
    auto spread = [](std::uint64_t x) {  // 21 bits -> every third bit
      x &= 0x1FFFFF;
      x = (x | x << 32) & 0x1F00000000FFFFull;
      x = (x | x << 16) & 0x1F0000FF0000FFull;
      x = (x | x << 8) & 0x100F00F00F00F00Full;
      x = (x | x << 4) & 0x10C30C30C30C30C3ull;
      x = (x | x << 2) & 0x1249249249249249ull;
      return x;
    };
    std::vector<std::pair<std::uint64_t, std::uint32_t>> key(pts_.size());
    tbb::parallel_for(std::size_t{0}, pts_.size(), [&](std::size_t i) {
      const glm::vec3 u = (pts_[i] - b.min) / ext * 2097151.0f;
      key[i] = {spread(static_cast<std::uint64_t>(u.x)) | spread(static_cast<std::uint64_t>(u.y)) << 1 |
                    spread(static_cast<std::uint64_t>(u.z)) << 2,
                static_cast<std::uint32_t>(i)};
    });
    std::sort(key.begin(), key.end());
    std::vector<glm::vec3> sorted(pts_.size());
    for (std::size_t i = 0; i < key.size(); ++i) sorted[i] = pts_[key[i].second];
    pts_.swap(sorted);
  }

  static std::vector<glm::vec3> read_points_file(const std::string& path) {
    if (path.empty()) throw InputError("algorithm 'spacecol': points=file needs points_file=PATH");
    std::ifstream in(path);
    if (!in) throw InputError(fmt::format("{}: cannot open attraction point file", path));
    std::vector<glm::vec3> pts;
    std::string line;
    for (int ln = 1; std::getline(in, line); ++ln) {
      std::replace(line.begin(), line.end(), ',', ' ');
      const auto hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      std::istringstream ls(line);
      glm::vec3 v;
      std::string extra;
      if (!(ls >> v.x >> v.y >> v.z) || (ls >> extra) || !std::isfinite(v.x) || !std::isfinite(v.y) ||
          !std::isfinite(v.z))
        throw InputError(fmt::format("{}:{}: expected three finite numbers 'x y z'", path, ln));
      pts.push_back(v);
    }
    if (pts.empty()) throw InputError(fmt::format("{}: no attraction points in the file", path));
    return pts;
  }

  // ---------- nodes ----------
  std::int32_t add_node(const glm::vec3& pos, std::int32_t parent) {
    PlantNode n;
    n.position = pos;
    n.parent = parent;
    n.birth_step = static_cast<std::uint32_t>(step_);
    if (parent == kNone) {
      n.shoot = next_shoot_++;
    } else {
      const auto& par = plant_.nodes[static_cast<std::size_t>(parent)];
      if (first_child_[static_cast<std::size_t>(parent)] == kNone) {
        n.shoot = par.shoot;  // the first child continues the axis
        n.order = par.order;
      } else {
        n.shoot = next_shoot_++;
        n.order = static_cast<std::uint16_t>(par.order + 1);
      }
    }
    const auto idx = static_cast<std::int32_t>(plant_.nodes.size());
    plant_.nodes.push_back(n);
    node_pos_.push_back(pos);
    first_child_.push_back(kNone);
    next_sibling_.push_back(kNone);
    stalled_.push_back(0);
    if (parent != kNone) {
      auto& fc = first_child_[static_cast<std::size_t>(parent)];
      if (fc == kNone) {
        fc = idx;
      } else {
        std::int32_t c = fc;
        while (next_sibling_[static_cast<std::size_t>(c)] != kNone) c = next_sibling_[static_cast<std::size_t>(c)];
        next_sibling_[static_cast<std::size_t>(c)] = idx;
      }
    }
    return idx;
  }

  // Adds roots whose start step has come; returns whether any seed is still waiting.
  bool add_due_roots() {
    bool pending = false;
    std::vector<std::int32_t> added;
    for (std::size_t i = 0; i < scene_->seeds.size(); ++i) {
      const Seed& s = scene_->seeds[i];
      max_start_step_ = std::max(max_start_step_, s.start_step);
      if (root_added_.size() < scene_->seeds.size()) root_added_.resize(scene_->seeds.size(), 0);
      if (root_added_[i]) continue;
      if (s.start_step <= step_) {
        root_added_[i] = 1;
        const std::int32_t r = add_node(s.position, kNone);
        seek_tips_.push_back({r, glm::normalize(s.direction)});
        added.push_back(r);
      } else {
        pending = true;
      }
    }
    if (!added.empty()) associate(added);
    return pending;
  }

  // Where a node grown from `from` along `dir` lands, after the surface mode has its say.
  glm::vec3 place(const glm::vec3& from, const glm::vec3& dir) const {
    glm::vec3 c = from + cfg_.step * dir;
    if (cfg_.surface == Surface::Free) return c;
    // A few fixed-point iterations: the SDF gradient is that of a trilinear field, so one push lands close.
    for (int it = 0; it < 3; ++it) {
      const float d = query_->signed_distance(c);
      if (cfg_.surface == Surface::Avoid && d >= cfg_.cling_distance) break;
      if (std::abs(d - cfg_.cling_distance) < 1e-3f * cfg_.step) break;
      c += (cfg_.cling_distance - d) * query_->gradient(c);
    }
    return c;
  }

  // A node is stalled when its new child would land on the node itself (held back by a solid), on an
  // existing child (the same pull again) or back on its own parent (oscillating between two points).
  bool is_stalled_child(std::int32_t parent, const glm::vec3& pos) const {
    const float lim2 = (kStallFraction * cfg_.step) * (kStallFraction * cfg_.step);
    const glm::vec3 self = node_pos_[static_cast<std::size_t>(parent)] - pos;
    if (glm::dot(self, self) < lim2) return true;  // pushed back onto itself (growing into a solid)
    if (const std::int32_t gp = plant_.nodes[static_cast<std::size_t>(parent)].parent; gp != kNone) {
      const glm::vec3 d = node_pos_[static_cast<std::size_t>(gp)] - pos;
      if (glm::dot(d, d) < 0.25f * cfg_.step * cfg_.step) return true;
    }
    for (std::int32_t c = first_child_[static_cast<std::size_t>(parent)]; c != kNone;
         c = next_sibling_[static_cast<std::size_t>(c)]) {
      const glm::vec3 d = node_pos_[static_cast<std::size_t>(c)] - pos;
      if (glm::dot(d, d) < lim2) return true;
    }
    return false;
  }

  bool cancelling(const Pull& p) const {
    return cfg_.split > 0.0f && glm::length(p.sum) < cfg_.split * static_cast<float>(p.count);
  }

  glm::vec3 steer(glm::vec3 dir, std::size_t v, std::uint64_t salt) const {
    dir = safe_normalize(dir + cfg_.tropism, dir);
    if (cfg_.noise > 0.0f) {
      glm::vec3 n;
      if (cfg_.noise_field == NoiseField::Position) {
        const glm::vec3 q = node_pos_[v] / cfg_.noise_scale;
        n = glm::vec3(glm::simplex(q + noise_offset_[0]), glm::simplex(q + noise_offset_[1]),
                      glm::simplex(q + noise_offset_[2]));
      } else {
        Rng rng(seed_, 0x40000000ull + v, static_cast<std::uint64_t>(step_) * 4 + salt);
        n = rng.unit_vector();
      }
      dir = safe_normalize(dir + cfg_.noise * n, dir);
    }
    return dir;
  }

  // Grows children for every influenced node (sorted by index): one along the mean pull, or two toward
  // the most opposed pulls when they nearly cancel (the node would otherwise stall or oscillate).
  void grow_children(const std::vector<std::int32_t>& influenced, const std::vector<Pull>& pull,
                     std::vector<std::int32_t>& new_nodes) {
    const glm::vec3 none(std::numeric_limits<float>::quiet_NaN());
    std::vector<std::pair<glm::vec3, glm::vec3>> target(influenced.size(), {none, none});
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, influenced.size(), 64), [&](const auto& r) {
      for (std::size_t k = r.begin(); k < r.end(); ++k) {
        const auto v = static_cast<std::size_t>(influenced[k]);
        const Pull& p = pull[k];
        // A node the field's push leaves inside a solid (one thinner than its voxels) does not grow.
        auto outside = [&](const glm::vec3& c) {
          return cfg_.surface != Surface::Free && query_->inside(c) ? none : c;
        };
        if (cancelling(p) && p.min_dot < 0.0f) {
          target[k] = {outside(place(node_pos_[v], steer(p.first, v, 1))),
                       outside(place(node_pos_[v], steer(p.opposite, v, 2)))};
          continue;
        }
        const glm::vec3 dir = safe_normalize(p.sum, glm::vec3(0.0f));
        if (glm::dot(dir, dir) == 0.0f) continue;  // pulls cancel exactly and splitting is off: the node waits
        target[k].first = outside(place(node_pos_[v], steer(dir, v, 0)));
      }
    });
    for (std::size_t k = 0; k < influenced.size(); ++k) {
      const std::int32_t v = influenced[k];
      bool grew = false;
      for (const glm::vec3& t : {target[k].first, target[k].second}) {
        if (std::isnan(t.x) || is_stalled_child(v, t)) continue;
        new_nodes.push_back(add_node(t, v));
        grew = true;
      }
      if (!grew) {
        if (!stalled_[static_cast<std::size_t>(v)]) ++stalled_count_;
        stalled_[static_cast<std::size_t>(v)] = 1;
      }
    }
  }

  // Accumulates the pull of point s on node v (in the caller's fixed order).
  void add_pull(std::vector<std::int32_t>& influenced, std::vector<Pull>& pull, std::size_t v, std::uint32_t s) {
    if (slot_[v] == kNone) {
      slot_[v] = static_cast<std::int32_t>(influenced.size());
      influenced.push_back(static_cast<std::int32_t>(v));
      pull.emplace_back();
    }
    Pull& p = pull[static_cast<std::size_t>(slot_[v])];
    const glm::vec3 d = safe_normalize(pts_[s] - node_pos_[v], glm::vec3(0.0f));
    if (p.count == 0) p.first = d;
    p.sum += d;
    ++p.count;
  }

  // For nearly cancelling nodes, finds the pull most opposed to the first one (second pass, same order).
  template <class ForEachPair>
  void find_opposites(const std::vector<std::int32_t>& influenced, std::vector<Pull>& pull, ForEachPair each) {
    bool any = false;
    for (const auto& p : pull) any = any || cancelling(p);
    if (!any) return;
    for (std::size_t k = 0; k < influenced.size(); ++k)
      slot_[static_cast<std::size_t>(influenced[k])] = static_cast<std::int32_t>(k);
    each([&](std::size_t v, std::uint32_t s) {
      if (slot_[v] == kNone) return;
      Pull& p = pull[static_cast<std::size_t>(slot_[v])];
      if (!cancelling(p)) return;
      const glm::vec3 d = safe_normalize(pts_[s] - node_pos_[v], glm::vec3(0.0f));
      const float dot = glm::dot(d, p.first);
      if (dot < p.min_dot) {
        p.min_dot = dot;
        p.opposite = d;
      }
    });
    for (const auto v : influenced) slot_[static_cast<std::size_t>(v)] = kNone;
  }

  void grow_open(std::vector<std::int32_t>& new_nodes) {
    // Pull of each active point on its nearest node, accumulated in active-list order (deterministic).
    auto each = [&](auto&& f) {
      for (const std::uint32_t s : active_) {
        const auto v = static_cast<std::size_t>(closest_[s]);
        if (!stalled_[v]) f(v, s);
      }
    };
    grow_from_pulls(each, new_nodes);
  }

  void grow_closed(std::vector<std::int32_t>& new_nodes) {
    // For each active point, its relative neighbourhood among the nodes within the influence radius.
    const float r2 = cfg_.influence * cfg_.influence, k2 = cfg_.kill * cfg_.kill;
    std::vector<std::vector<std::uint32_t>> rn(active_.size());
    std::vector<std::uint8_t> dies(active_.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, active_.size(), 64), [&](const auto& r) {
      std::vector<std::pair<std::uint32_t, float>> near;
      for (std::size_t a = r.begin(); a < r.end(); ++a) {
        const glm::vec3& s = pts_[active_[a]];
        auto rs = collect_within(r2, near, [](std::uint32_t, float) { return true; });
        node_tree_->findNeighbors(rs, &s.x, nanoflann::SearchParams());
        std::sort(near.begin(), near.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
        bool all_within_kill = !near.empty();
        for (const auto& [v, dv2] : near) {
          bool in_rn = true;
          for (const auto& [u, du2] : near) {
            if (u == v || du2 >= dv2) continue;
            const glm::vec3 uv = node_pos_[u] - node_pos_[v];
            if (glm::dot(uv, uv) < dv2) {
              in_rn = false;
              break;
            }
          }
          if (in_rn) {
            rn[a].push_back(v);
            if (dv2 >= k2) all_within_kill = false;
          }
        }
        dies[a] = all_within_kill ? 1 : 0;
      }
    });
    for (std::size_t a = 0; a < active_.size(); ++a)
      if (dies[a]) kill_point(active_[a]);
    auto each = [&](auto&& f) {
      for (std::size_t a = 0; a < active_.size(); ++a) {
        if (dies[a]) continue;
        for (const std::uint32_t v : rn[a])
          if (!stalled_[v]) f(std::size_t{v}, active_[a]);
      }
    };
    grow_from_pulls(each, new_nodes);
  }

  // Accumulates the pulls that `each` enumerates as (node, point) pairs in a fixed order, then grows the
  // influenced nodes' children (shared by open and closed venation).
  template <class ForEachPair>
  void grow_from_pulls(ForEachPair each, std::vector<std::int32_t>& new_nodes) {
    std::vector<std::int32_t> influenced;
    std::vector<Pull> pull;
    slot_.resize(plant_.nodes.size(), kNone);
    each([&](std::size_t v, std::uint32_t s) { add_pull(influenced, pull, v, s); });
    for (const auto v : influenced) slot_[static_cast<std::size_t>(v)] = kNone;
    find_opposites(influenced, pull, each);
    if (!influenced.empty()) ever_influenced_ = true;
    sort_by_node(influenced, pull);
    grow_children(influenced, pull, new_nodes);
  }

  static void sort_by_node(std::vector<std::int32_t>& nodes, std::vector<Pull>& pull) {
    std::vector<std::size_t> order(nodes.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return nodes[a] < nodes[b]; });
    std::vector<std::int32_t> n2(nodes.size());
    std::vector<Pull> p2(nodes.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      n2[i] = nodes[order[i]];
      p2[i] = pull[order[i]];
    }
    nodes.swap(n2);
    pull.swap(p2);
  }

  // Roots that nothing reaches yet grow straight along their seed direction (the trunk of a tree
  // below its crown).
  void seek(std::vector<std::int32_t>& new_nodes) {
    const Aabb b = scene_->bounds();
    const int limit = static_cast<int>(std::ceil(2.0f * glm::length(b.size()) / cfg_.step)) + 1;
    if (seek_steps_++ > limit) return;
    for (auto& [tip, dir] : seek_tips_) {
      const std::int32_t n = add_node(place(node_pos_[static_cast<std::size_t>(tip)], dir), tip);
      tip = n;
      new_nodes.push_back(n);
    }
  }

  void kill_point(std::uint32_t s) {
    if (alive_[s]) {
      alive_[s] = 0;
      --alive_count_;
      make_stale(s);
    }
  }

  // Marks a point its tier's tree need not hold any more (dead, or nearer than the tier's range).
  void make_stale(std::uint32_t s) {
    if (where_[s] & kStale) return;
    ++tiers_[where_[s]]->stale;
    where_[s] |= kStale;
  }

  // The tiers' bounds: the first at tau, small enough that searches of the nearest points are cheap,
  // large enough that most covered points fall below it (every live point is at least the kill
  // distance from its nearest node); then a geometric series up to the influence radius.
  void make_tiers() {
    const float tau = std::min(cfg_.influence, std::max(2.0f * cfg_.kill, cfg_.kill + 2.0f * cfg_.step));
    tiers_.clear();
    float lo = 0.0f;
    for (float hi = tau; hi < cfg_.influence && tiers_.size() + 2 < kMaxTiers; hi *= kTierRatio) {
      tiers_.push_back(std::make_unique<Tier>(lo, hi));
      lo = hi;
    }
    tiers_.push_back(std::make_unique<Tier>(lo, cfg_.influence));  // also every point with no node in range
  }

  // Updates nearest nodes, activations and kills for points near the given (new) nodes.
  void associate(const std::vector<std::int32_t>& nodes) {
    if (cfg_.closed)
      node_tree_->addPoints(static_cast<std::uint32_t>(node_pos_.size() - nodes.size()),
                            static_cast<std::uint32_t>(node_pos_.size() - 1));
    const float k2 = cfg_.kill * cfg_.kill;
    std::vector<std::vector<std::pair<std::uint32_t, float>>> found(nodes.size());
    // Only points the new node is nearer to than their current nearest can change (every live point is
    // farther than the kill distance from its nearest node, so this also keeps every point to kill).
    // A tier's points are searched only within its upper bound: their nearest node can only get
    // nearer. The parallel part only reads; all writes happen in the merge below, in point-index order
    // per node, so the result does not depend on the trees.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nodes.size(), 16), [&](const auto& r) {
      std::vector<std::pair<std::uint32_t, float>> part;
      for (std::size_t k = r.begin(); k < r.end(); ++k) {
        const glm::vec3& q = node_pos_[static_cast<std::size_t>(nodes[k])];
        auto& out = found[k];
        out.clear();
        for (const auto& tier : tiers_) {
          const auto& ids = tier->ids;
          auto rs = collect_within(tier->hi * tier->hi, part, [&](std::uint32_t j, float d2) {
            const std::uint32_t i = ids[j];
            return alive_[i] != 0 && (closest_[i] == kNone || d2 < closest_d2_[i]);
          });
          tier->tree->findNeighbors(rs, &q.x, nanoflann::SearchParams(32, 0.0f, false));
          for (const auto& [j, d2] : part) out.emplace_back(ids[j], d2);
        }
        std::sort(out.begin(), out.end());
      }
    });
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const std::int32_t v = nodes[k];
      for (const auto& [s, d2] : found[k]) {
        if (!alive_[s]) continue;
        if (!cfg_.closed && d2 < k2) {
          kill_point(s);
          continue;
        }
        if (closest_[s] == kNone) {
          closest_[s] = v;
          closest_d2_[s] = d2;
          active_.push_back(s);
        } else if (d2 < closest_d2_[s]) {  // ties keep the older (lower-index) node
          closest_[s] = v;
          closest_d2_[s] = d2;
        } else {
          continue;
        }
        // Below its tier now, but still searched in that tier's tree.
        if (const float lo = tiers_[where_[s] & ~kStale]->lo; d2 < lo * lo) make_stale(s);
      }
    }
  }

  void compact_active() {
    active_.erase(std::remove_if(active_.begin(), active_.end(), [this](std::uint32_t s) { return !alive_[s]; }),
                  active_.end());
    // Stale points (dead, or below their tier) cost time in every radius query: rebuild the trees when
    // they make up half of any tier (amortised O(n log n) over the whole run).
    if (alive_count_ == 0) return;
    for (const auto& t : tiers_)
      if (2 * t->stale > t->ids.size() + kRebuildSlack) return build_trees();
  }

  void build_trees() {
    for (auto& t : tiers_) {
      t->ids.clear();
      t->pts.clear();
      t->stale = 0;
    }
    for (std::uint32_t i = 0; i < pts_.size(); ++i) {
      if (!alive_[i]) continue;
      std::uint8_t k = 0;
      if (closest_[i] == kNone)
        k = static_cast<std::uint8_t>(tiers_.size() - 1);
      else
        while (std::size_t{k} + 1 < tiers_.size() && closest_d2_[i] >= tiers_[k]->hi * tiers_[k]->hi) ++k;
      where_[i] = k;
      tiers_[k]->ids.push_back(i);
      tiers_[k]->pts.push_back(pts_[i]);
    }
    ++tree_builds_;
    tbb::parallel_for(std::size_t{0}, tiers_.size(), [&](std::size_t k) {
      tiers_[k]->tree =
          std::make_unique<PointTree>(3, tiers_[k]->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));
    });
  }

  // ---------- leaves ----------
  void place_leaves() {
    if (cfg_.leaves == Leaves::None || cfg_.leaf_size <= 0.0f) return;
    const bool tips = cfg_.leaves == Leaves::Tips || cfg_.leaves == Leaves::Both;
    const bool interval = cfg_.leaves == Leaves::Interval || cfg_.leaves == Leaves::Both;
    std::vector<int> depth(plant_.nodes.size(), 0);
    for (std::size_t i = 0; i < plant_.nodes.size(); ++i) {
      const auto& n = plant_.nodes[i];
      if (n.parent != kNone) depth[i] = depth[static_cast<std::size_t>(n.parent)] + 1;
      const bool tip = first_child_[i] == kNone && n.parent != kNone;
      if (!((tips && tip) || (interval && n.parent != kNone && depth[i] % cfg_.leaf_interval == 0))) continue;
      const glm::vec3 axis =
          safe_normalize(n.position - plant_.nodes[static_cast<std::size_t>(n.parent)].position, glm::vec3(0, 1, 0));
      Rng rng(seed_, 0x1EAFull, i);
      // Upper side faces away from the nearest surface when clinging, otherwise up (toward the sky).
      glm::vec3 up = cfg_.surface == Surface::Free ? glm::vec3(0, 1, 0) : query_->gradient(n.position);
      // Blade: along the branch, tilted away from the axis by a random angle around it.
      glm::vec3 side = safe_normalize(glm::cross(axis, up),
                                      safe_normalize(glm::cross(axis, glm::vec3(1, 0, 0)), glm::vec3(0, 0, 1)));
      if (rng.uniform() < 0.5) side = -side;
      glm::vec3 blade = safe_normalize(axis + 0.8f * side, axis);
      glm::vec3 normal = safe_normalize(up - glm::dot(up, blade) * blade, safe_normalize(glm::cross(blade, side), up));
      const glm::vec3 x = glm::cross(normal, blade);
      Organ leaf;
      leaf.position = n.position;
      leaf.orientation = glm::quat_cast(glm::mat3(x, normal, blade));
      leaf.size = cfg_.leaf_size * static_cast<float>(rng.uniform(0.8, 1.2));
      leaf.kind = tip ? OrganKind::YoungLeaf : OrganKind::Leaf;
      leaf.node = static_cast<std::int32_t>(i);
      plant_.organs.push_back(leaf);
    }
  }

  // ---------- state ----------
  const Scene* scene_ = nullptr;
  const HostQueries* query_ = nullptr;
  std::uint64_t seed_ = 0;
  std::array<glm::vec3, 3> noise_offset_{};  // where each component of the position noise is read
  spacecol::Config cfg_{};                   // set by start()
  bool ever_influenced_ = false;

  std::vector<glm::vec3> pts_;
  std::string not_applicable_;  // why this scene is not one it can grow on (OwnVerdict)
  // The points file as load_inputs() read it, until start_with() takes it.
  bool loaded_ = false;
  std::string loaded_path_;
  std::vector<glm::vec3> loaded_pts_;
  // Live points split at the last rebuild by the distance to their nearest node into tiers [lo, hi),
  // each in its own kd-tree searched within hi; the last tier also holds the points no node reaches.
  // The ids map tree indices back to point indices.
  struct Tier {
    Tier(float l, float h) : lo(l), hi(h) {}
    float lo, hi;
    std::vector<glm::vec3> pts;
    std::vector<std::uint32_t> ids;
    Cloud cloud{&pts};  // nanoflann keeps a reference to the adaptor: a Tier never moves
    std::unique_ptr<PointTree> tree;
    std::size_t stale = 0;
  };
  std::vector<std::unique_ptr<Tier>> tiers_;
  std::vector<std::uint8_t> where_;  // the point's tier, | kStale once the tree need not hold it
  static constexpr std::uint8_t kStale = 0x80;
  std::size_t tree_builds_ = 0;
  std::vector<std::int32_t> closest_;
  std::vector<float> closest_d2_;
  std::vector<std::uint8_t> alive_;
  std::size_t alive_count_ = 0;
  std::vector<std::uint32_t> active_;

  Plant plant_;
  std::vector<glm::vec3> node_pos_;
  Cloud node_cloud_{&node_pos_};
  std::unique_ptr<NodeTree> node_tree_;
  std::vector<std::int32_t> first_child_, next_sibling_, slot_;
  std::vector<std::uint8_t> stalled_;
  std::size_t stalled_count_ = 0;
  std::vector<std::uint8_t> root_added_;
  std::vector<std::pair<std::int32_t, glm::vec3>> seek_tips_;
  int step_ = 0, seek_steps_ = 0, max_start_step_ = 0;
  std::uint32_t next_shoot_ = 0;
};

}  // namespace

namespace spacecol {

Config make_config(const Params& p) {
  const std::string& points = p.text("points");
  const std::string& surface = p.text("surface");
  const std::string& leaves = p.text("leaves");
  // Designated initializers: a member left out is a warning (-Wmissing-field-initializers), an error in CI.
  return {
      .closed = p.text("venation") == "closed",
      .points = points == "envelope"  ? Points::Envelope
                : points == "surface" ? Points::Surface
                : points == "file"    ? Points::File
                                      : Points::Auto,
      .point_count = static_cast<std::size_t>(p.integer("point_count")),
      .center_density = static_cast<float>(p.real("center_density")),
      .surface_offset = static_cast<float>(p.real("surface_offset")),
      .influence = static_cast<float>(p.real("influence")),
      .kill = static_cast<float>(p.real("kill")),
      .step = static_cast<float>(p.real("step")),
      .tropism = glm::vec3(p.vec3("tropism")),
      .noise = static_cast<float>(p.real("noise")),
      .noise_field = p.text("noise_field") == "random" ? NoiseField::Random : NoiseField::Position,
      .noise_scale = static_cast<float>(p.real("noise_scale")),
      .surface = surface == "cling"   ? Surface::Cling
                 : surface == "avoid" ? Surface::Avoid
                                      : Surface::Free,
      .cling_distance = static_cast<float>(p.real("cling_distance")),
      .split = static_cast<float>(p.real("split")),
      .seek = p.boolean("seek"),
      .tip_radius = static_cast<float>(p.real("tip_radius")),
      .pipe_exponent = static_cast<float>(p.real("pipe_exponent")),
      .leaves = leaves == "none"       ? Leaves::None
                : leaves == "tips"     ? Leaves::Tips
                : leaves == "interval" ? Leaves::Interval
                                       : Leaves::Both,
      .leaf_interval = static_cast<int>(p.integer("leaf_interval")),
      .leaf_size = static_cast<float>(p.real("leaf_size")),
  };
}

}  // namespace spacecol

GROWBENCH_REGISTER_ALGORITHM(spacecol, SpaceColonization, kInfo, spacecol::Config)

}  // namespace growbench
