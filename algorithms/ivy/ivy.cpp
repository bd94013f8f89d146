// Luft-style ivy. The growth rules are Luft's (README.md beside this file); what changes is the cost:
//
//  * Luft loops over every scene triangle for each node's adhesion and again for its collision test.
//    Here Embree queries find the same answers from a few triangles: in `luft` adhesion mode a point
//    query on an index of the triangles' adhesion prisms (see EmbreeGeometry), in `closest` mode
//    growing ball queries. For the collision: his first pass can only mirror at a triangle the
//    segment itself crosses, so when his rule finds no triangle crossed by the segment the loop ends
//    (most nodes). That is asked of an index of the triangles' boxes (swept a
//    few steps along the normal for the adhesion lookup, and padded past the inside test's
//    tolerance), traversed along the segment: every triangle the rule can call crossed has a box the
//    segment passes through, and the rule itself decides. Otherwise every position the loop can
//    produce stays within the segment's length of the start (mirroring across a plane the segment
//    crosses never moves the end farther from the start), so a ball query of that radius gathers a
//    complete candidate set, and his loop over it in index order gives exactly his result. Embree's own ray-triangle
//    hits could not promise that: its float test differs from Luft's rule along edges. (The Blender collision mode is a
//    ray, because Blender's is.)
//  * Luft's branching scans every node of every alive root each iteration (quadratic over a run).
//    The same distribution is drawn without the scan: a node can only branch where its weight
//    w = 1 - (cos(2 pi l / L) / 2 + 1/2) exceeds the threshold b, a contiguous window of the root
//    found by binary search on arc length; inside it, Bernoulli trials with p_i = 1 - b / w_i are
//    thinned from trials with the maximum p = 1 - b whose gaps are geometric. The first accepted
//    node is distributed exactly as the first success of Luft's node-by-node loop.
#include "algorithms/ivy/ivy.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/random.hpp"
#include "scenes/geometry.hpp"

namespace growbench {
namespace {

// ---- parameter table (what `growbench list` prints) ----
const AlgorithmInfo kInfo = {
    .name = "ivy",
    .summary =
        "Luft's ivy generator (and Blender IvyGen): roots creep along surfaces by primary, random, adhesion and "
        "gravity terms, mirror off what they hit, branch, and carry leaves facing away from the surface",
    .params =
        {
            param::choice("preset", "luft", {"luft", "blender"})
                .doc(
                    "luft: Luft's defaults, sizes relative to R (the scene's bounding-sphere radius); blender: Blender "
                    "IvyGen 0.1.5 (absolute metres, max_root_length 1, one ray collision without death, closest-point "
                    "adhesion, one smoothing pass, its leaves)"),
            param::choice("units", "relative", {"relative", "absolute"})
                .doc("relative: ivy_size, max_float_length, max_adhesion_distance and the length limits are multiples "
                     "of "
                     "R, leaf_size and branch_size multiples of R * ivy_size (Luft); absolute: all of them in metres "
                     "(Blender)"),
            param::real("ivy_size", 0.005).range(1e-6, 100).doc("length scale of one growth step"),
            param::real("primary_weight", 0.5).range(0, 100).doc("weight of the previous direction"),
            param::real("random_weight", 0.2)
                .range(0, 100)
                .doc("weight of a random direction (uniform in a cube, plus 0.2 up)"),
            param::real("adhesion_weight", 0.1)
                .range(0, 100)
                .doc("weight of the pull to the nearest surface (the three weights are normalised by their sum)"),
            param::real("gravity_weight", 1.0)
                .range(0, 100)
                .doc("gravity: ivy_size * this * (floating length / max_float_length)^0.7 downwards"),
            param::real("branching_probability", 0.95)
                .range(0, 1)
                .doc(
                    "a node starts a new root when rand * w > this (w peaks mid-root); Blender's panel shows 1 - this"),
            param::real("leaf_probability", 0.7)
                .range(0, 10)
                .doc("a leaf grows when rand * w > this (w grows toward the tip and on the ground); Blender's panel "
                     "shows 1 - this"),
            param::real("leaf_size", 1.5).range(0, 100).doc("leaf half-size (relative: times R * ivy_size)"),
            param::real("branch_size", 0.15).range(0, 100).doc("branch radius scale (relative: times R * ivy_size)"),
            param::real("max_float_length", 0.1)
                .range(1e-6, 1e4)
                .doc("a root dies once it has floated (not touched a surface) this far"),
            param::real("max_adhesion_distance", 0.1).range(1e-6, 1e4).doc("surfaces farther than this do not attract"),
            param::real("max_root_length", 3.0)
                .range(0, 1e6)
                .doc("stop when a root is this long (Blender's maxIvyLength; Luft's GUI has none, the user stops "
                     "growth: "
                     "roots that never leave a surface never die); 0: no limit"),
            param::real("max_total_length", 0.0)
                .range(0, 1e9)
                .doc("stop when all roots together are this long; 0: no limit"),
            param::choice("adhesion", "luft", {"luft", "closest"})
                .doc("luft: face interiors only, front sides only (Luft); closest: true closest point incl. edges and "
                     "vertices (Blender's BVH)"),
            param::choice("collision", "luft", {"luft", "blender"})
                .doc("luft: mirror across every entered face, repeat, the root dies after more than 5 passes; blender: "
                     "one ray, mirror across the first face if entering, never dies"),
            param::integer("max_depth", 3).range(0, 100).doc("roots this deep (ancestor count) can still branch"),
            param::integer("branches_per_step", 1).range(1, 1000).doc("new roots per iteration at most (Luft: 1)"),
            param::integer("max_roots", 10000)
                .range(1, 1000000)
                .doc("no new roots once this many have started: without it, many branches per iteration multiply "
                     "the roots every iteration until memory runs out"),
            param::integer("smoothing_passes", 5)
                .range(0, 100)
                .doc("passes of the 11-tap [1 2 4 7 9 10 9 7 4 2 1]/56 filter over each root's adhesion vectors"),
            param::choice("leaves", "luft", {"luft", "blender", "none"})
                .doc("luft: leaf_passes passes over each root's nodes, young and adult leaves; blender: leaf_passes "
                     "tries along each segment; none"),
            param::integer("leaf_passes", 10)
                .range(0, 1000)
                .doc("leaf passes per root (luft) or tries per segment (blender)"),
        },
    .presets =
        {
            {"luft", {}},
            {"blender",
             {{"units", std::string("absolute")},
              {"ivy_size", 0.02},
              {"max_float_length", 0.5},
              {"max_adhesion_distance", 1.0},
              {"max_root_length", 1.0},
              {"branching_probability", 0.95},
              {"leaf_probability", 0.65},
              {"leaf_size", 0.02},
              {"branch_size", 0.001},
              {"adhesion", std::string("closest")},
              {"collision", std::string("blender")},
              {"smoothing_passes", std::int64_t{1}},
              {"leaves", std::string("blender")}}},
        },
    .test_params = {"max_root_length=1"},
};

constexpr glm::vec3 kUp{0.0f, 1.0f, 0.0f};
constexpr std::uint64_t kGrowStream = 0x1f7a11ull << 32;
constexpr std::uint64_t kBranchStream = 0xb4a9c4ull << 32;
constexpr std::uint64_t kLeafStream = 0x1eaf00ull << 32;
constexpr float kTwoPi = 2.0f * std::numbers::pi_v<float>;
// Height of the short adhesion prisms, in growth steps (see EmbreeGeometry): the height that took the
// fewest instructions on the bunny, its neighbours within noise of it.
constexpr float kShortPrism = 3.0f;

// Uniform in [-0.5, 0.5]^3 (Luft's getRandomized, Blender's rand_val() - 0.5).
glm::vec3 cube(Rng& rng) {
  const auto x = static_cast<float>(rng.uniform() - 0.5);
  const auto y = static_cast<float>(rng.uniform() - 0.5);
  const auto z = static_cast<float>(rng.uniform() - 0.5);
  return {x, y, z};
}

// ---- Embree geometry ----
//
// Luft adhesion: a triangle attracts p only when p lies in its prism (the triangle swept along its
// normal for the adhesion distance) and the closest such triangle wins. A ball query would have to
// visit every triangle within the adhesion distance to learn that none counts, which is the common
// case above convex parts of a scanned mesh (between the prisms of a convex surface lie the regions
// closest to its edges and vertices, where no face counts): on the bunny such nodes visited many
// triangles each. So the prisms' bounding boxes get their own Embree BVH, and a point query returns the
// few whose box holds p; the exact rule then decides. Each box is padded beyond anything rounding or
// the inside test's tolerance can accept, so it is a superset and the answer is Luft's, bit for bit.
// A node near the surface is first looked up among prisms only kShortPrism steps tall: their boxes
// are small and overlap little, so the traversal is cheap, and a target found there no farther than
// that height is final (any triangle that could beat or tie it is that close too, so its short prism
// holds p). On the bunny most nodes end there; the rest ask the full index.
// A node whose segment crossed nothing got this lookup from the crossing test, whose traversal of the
// same index passed every box that holds the segment's end (crosses_any).
// Closest mode keeps growing balls around the previous target (the true closest point is found at
// once when the root clings, and there is no rule under which nothing near counts).
class EmbreeGeometry final : public ivy::Geometry {
 public:
  EmbreeGeometry(const SceneQuery& q, const ivy::TriangleTable& t, const ivy::Config& c)
      : query_(q), table_(t), cfg_(c) {
    // One index of every triangle's box swept kShortPrism steps along its normal serves both the
    // short-prism lookup and the crossing test (a triangle's box lies inside its swept box): a
    // separate index of the bare boxes made bunny nodes a little faster but cost a third Embree build
    // per trial, more than it saves on all but very large plants.
    const bool luft = cfg_.adhesion_mode == ivy::AdhesionMode::Luft;
    if (luft && kShortPrism * cfg_.step < cfg_.max_adhesion) short_height_ = kShortPrism * cfg_.step;
    if (cfg_.collision_mode == ivy::CollisionMode::Luft || short_height_ > 0.0f)
      near_ = prism_index(short_height_, true);
    if (luft) prisms_ = prism_index(cfg_.max_adhesion);
  }

  glm::vec3 adhesion(const glm::vec3& p, std::uint32_t& hint) const override {
    State st{this, {p, cfg_.max_adhesion, cfg_.adhesion_mode == ivy::AdhesionMode::Luft}};
    if (prisms_) {
      if (short_height_ > 0.0f) near_->visit_containing(p, &EmbreeGeometry::prism_visit, &st);
      return finish_luft(p, st, hint);
    }
    // A clinging root's next target is usually the same triangle: offered first, its distance bounds
    // the traversal from the start. The visit offers it again; ties resolve the same either way.
    if (hint != ivy::kNoTriangle) st.search.offer(table_.tris[hint], hint, geom::closest_point_on_triangle);
    auto reach = [&](float d) { return d * (1.0f + 1e-4f) + cfg_.margin; };
    // Growing balls (two steps, then eight): when the target is found inside one, every triangle that
    // could beat or tie it was inside it too, so the answer is final. Otherwise the full adhesion ball.
    for (const float steps : {2.0f, 8.0f}) {
      const float near = steps * cfg_.step;
      if (near >= cfg_.max_adhesion) break;
      query_.visit_near(p, reach(std::min(near, st.search.best)), &EmbreeGeometry::visit, &st);
      if (reach(st.search.best) <= reach(near)) {
        hint = st.search.best_id;
        return st.search.vector();
      }
    }
    query_.visit_near(p, reach(std::min(cfg_.max_adhesion, st.search.best)), &EmbreeGeometry::visit, &st);
    hint = st.search.best_id;
    return st.search.vector();
  }

  void gather(const glm::vec3& centre, float radius, ivy::Candidates& candidates) const override {
    Gather st{&table_, centre, radius * radius, &candidates};
    query_.visit_near(centre, radius, &EmbreeGeometry::gather_visit, &st);
  }

  bool crosses_any(const glm::vec3& o, const glm::vec3& q, ivy::Lookahead& at_q) const override {
    Segment st{o, q, {this, {q, cfg_.max_adhesion, true}}};
    near_->visit_segment(o, q - o, &EmbreeGeometry::cross_visit, &st);
    if (st.crossed || short_height_ <= 0.0f) return st.crossed;
    // Nothing crossed, so the traversal went the whole way, through every box that holds q: the
    // search at q saw all that the short lookup would offer (and some more, which the exact rule
    // judges anyway). Finish it as adhesion(q) would.
    at_q.vector = finish_luft(q, st.at_q, at_q.hint);
    at_q.valid = true;
    return false;
  }

  RayHit first_hit(const glm::vec3& o, const glm::vec3& d) const override { return query_.ray(o, d, 1.0f, 0.0f); }

 private:
  struct State {
    const EmbreeGeometry* self;
    ivy::AdhesionSearch search;
  };
  struct Segment {
    glm::vec3 o, q;
    State at_q;  // Luft's adhesion at q, over the boxes passed
    bool crossed = false;
  };
  // Luft's adhesion at p from a search that has seen the short-prism boxes holding p (or nothing, when
  // there is no short index): a target no farther than the short height is final; else the full
  // prisms decide.
  glm::vec3 finish_luft(const glm::vec3& p, State& st, std::uint32_t& hint) const {
    if (st.search.best_id == ivy::kNoTriangle || st.search.reject_beyond() > short_height_)
      prisms_->visit_containing(p, &EmbreeGeometry::prism_visit, &st);
    hint = st.search.best_id;
    return st.search.vector();
  }
  static bool cross_visit(void* user, std::uint32_t id) {
    auto& st = *static_cast<Segment*>(user);
    const EmbreeGeometry& self = *st.at_q.self;
    const ivy::Triangle& t = self.table_.tris[id];
    st.crossed = ivy::crosses(t, st.o, st.q);
    if (!st.crossed && self.short_height_ > 0.0f) st.at_q.search.offer(t, id, geom::closest_point_on_triangle);
    return st.crossed;
  }
  static void visit(void* user, std::uint32_t mesh, std::uint32_t tri, float* radius) {
    auto& st = *static_cast<State*>(user);
    const auto& table = st.self->table_;
    const std::uint32_t id = table.id(mesh, tri);
    if (st.search.offer(table.tris[id], id, geom::closest_point_on_triangle)) {
      // Keep every triangle that could still tie or win in reach.
      *radius = std::min(*radius, st.search.best * (1.0f + 1e-4f) + st.self->cfg_.margin);
    }
  }
  struct Gather {
    const ivy::TriangleTable* table;
    glm::vec3 centre;
    float radius2;
    ivy::Candidates* out;
  };
  static void gather_visit(void* user, std::uint32_t mesh, std::uint32_t tri, float*) {
    auto& st = *static_cast<Gather*>(user);
    const std::uint32_t id = st.table->id(mesh, tri);
    if (ivy::box_distance2(st.table->tris[id], st.centre) <= st.radius2) st.out->push(id);
  }
  static bool prism_visit(void* user, std::uint32_t id) {
    auto& st = *static_cast<State*>(user);
    st.search.offer(st.self->table_.tris[id], id, geom::closest_point_on_triangle);
    return false;
  }
  // The boxes of the triangles' adhesion prisms `height` tall (empty for triangles that never attract),
  // or with `all`, of every triangle with a normal, swept by `height`.
  std::unique_ptr<BoxIndex> prism_index(float height, bool all = false) const {
    std::vector<Aabb> prisms(table_.size());
    const float reach = height * (1.0f + 1e-4f) + cfg_.margin;
    for (std::size_t i = 0; i < table_.size(); ++i) {
      const ivy::Triangle& t = table_.tris[i];
      if ((!t.adhesive && !all) || t.n == glm::vec3(0.0f)) continue;
      const glm::vec3 sweep = t.n * reach;
      const glm::vec3 lo = t.lo(), hi = t.hi(), pad(cfg_.margin + 1e-4f * glm::length(hi - lo));
      prisms[i].min = glm::min(lo, lo + sweep) - pad;
      prisms[i].max = glm::max(hi, hi + sweep) + pad;
    }
    return query_.box_index(std::move(prisms));
  }
  const SceneQuery& query_;
  const ivy::TriangleTable& table_;
  ivy::Config cfg_;
  std::unique_ptr<BoxIndex> near_;    // every triangle's box swept short_height_ (0: not swept)
  std::unique_ptr<BoxIndex> prisms_;  // adhesion prisms, Luft adhesion only
  float short_height_ = 0.0f;
};

// ---- the algorithm as the harness sees it ----
class IvyAlgorithm final : public GrowthAlgorithm {
 public:
  const AlgorithmInfo& describe() const override { return kInfo; }
  void start(const Scene& scene, const SceneQuery& query, const Params& params, std::uint64_t seed) override {
    table_ = std::make_unique<ivy::TriangleTable>(scene);
    const ivy::Config cfg = ivy::make_config(params, scene);
    geometry_ = ivy::make_embree_geometry(query, *table_, cfg);
    grower_ = std::make_unique<ivy::Grower>(scene, *geometry_, *table_, cfg, seed);
    not_applicable_ =
        scene.has_climbable()
            ? ""
            : fmt::format("nothing to climb: scene '{}' has no climbable surface, only ground", scene.name);
  }
  OwnVerdict own_verdict() const override { return {not_applicable_, {}}; }
  bool step() override { return grower_->step(); }
  const Plant& plant() const override { return grower_ ? grower_->plant() : empty_; }
  void finish() override { grower_->finish(); }
  std::vector<std::pair<std::string, double>> stats() const override { return grower_->stats(); }

 private:
  std::unique_ptr<ivy::TriangleTable> table_;
  std::unique_ptr<ivy::Geometry> geometry_;
  std::unique_ptr<ivy::Grower> grower_;
  std::string not_applicable_;
  Plant empty_;
};

}  // namespace

GROWBENCH_REGISTER_ALGORITHM(ivy, IvyAlgorithm, kInfo, ivy::Config)

namespace ivy {

float bounding_sphere_radius(const Scene& scene) {
  bool any_climbable = false;
  for (const auto& m : scene.meshes) any_climbable = any_climbable || m.climbable;
  glm::dvec3 sum(0.0);
  std::size_t count = 0;
  auto each_vertex = [&](auto&& f) {
    for (const auto& m : scene.meshes) {
      if (any_climbable && !m.climbable) continue;
      for (const auto& t : m.triangles) {  // vertices used by a face (Luft's mesh has no loose ones)
        f(m.vertices[t.x]);
        f(m.vertices[t.y]);
        f(m.vertices[t.z]);
      }
    }
  };
  each_vertex([&](const glm::vec3& v) {
    sum += glm::dvec3(v);
    ++count;
  });
  if (count == 0) return 0.0f;
  const glm::vec3 centre(sum / static_cast<double>(count));
  float r = 0.0f;
  each_vertex([&](const glm::vec3& v) { r = std::max(r, glm::length(v - centre)); });
  return r;
}

Config make_config(const Params& p, const Scene& scene) {
  const float radius = bounding_sphere_radius(scene);
  if (!(radius > 0.0f))
    throw InputError(fmt::format("ivy: scene '{}' has no climbable surface to size R by", scene.name));
  const bool relative = p.text("units") == "relative";
  const float R = relative ? radius : 1.0f;
  const float step = static_cast<float>(p.real("ivy_size")) * R;
  const double sum = p.real("primary_weight") + p.real("random_weight") + p.real("adhesion_weight");
  if (!(sum > 0.0))
    throw InputError("ivy: primary_weight, random_weight and adhesion_weight are all 0; at least one must be > 0");
  const std::string& leaves = p.text("leaves");
  // Designated initializers: a member left out is a warning (-Wmissing-field-initializers), an error in CI.
  return {
      .radius = radius,
      .step = step,
      .primary = static_cast<float>(p.real("primary_weight") / sum),
      .random = static_cast<float>(p.real("random_weight") / sum),
      .adhesion = static_cast<float>(p.real("adhesion_weight") / sum),
      .gravity = static_cast<float>(p.real("gravity_weight")),
      .branching = static_cast<float>(p.real("branching_probability")),
      .leaf_probability = static_cast<float>(p.real("leaf_probability")),
      .leaf_size = static_cast<float>(p.real("leaf_size")) * (relative ? step : 1.0f),
      .branch_size = static_cast<float>(p.real("branch_size")) * (relative ? step : 1.0f),
      .max_float = static_cast<float>(p.real("max_float_length")) * R,
      .max_adhesion = static_cast<float>(p.real("max_adhesion_distance")) * R,
      .max_root_length = p.real("max_root_length") * R,
      .max_total_length = p.real("max_total_length") * R,
      .adhesion_mode = p.text("adhesion") == "luft" ? AdhesionMode::Luft : AdhesionMode::Closest,
      .collision_mode = p.text("collision") == "luft" ? CollisionMode::Luft : CollisionMode::Blender,
      .leaf_mode = leaves == "luft"      ? LeafMode::Luft
                   : leaves == "blender" ? LeafMode::Blender
                                         : LeafMode::None,
      .max_depth = static_cast<int>(p.integer("max_depth")),
      .branches_per_step = static_cast<int>(p.integer("branches_per_step")),
      .max_roots = static_cast<std::size_t>(p.integer("max_roots")),
      .smoothing_passes = static_cast<int>(p.integer("smoothing_passes")),
      .leaf_passes = static_cast<int>(p.integer("leaf_passes")),
      .margin = 1e-5f * radius,
  };
}

std::span<const std::uint32_t> Candidates::sorted_unique() {
  std::uint32_t* b = heap_.empty() ? local_.data() : heap_.data();
  std::uint32_t* e = b + n_;
  std::sort(b, e);
  e = std::unique(b, e);
  n_ = static_cast<std::size_t>(e - b);
  if (!heap_.empty()) heap_.resize(n_);
  return {b, n_};
}

std::unique_ptr<Geometry> make_embree_geometry(const SceneQuery& query, const TriangleTable& table,
                                               const Config& config) {
  return std::make_unique<EmbreeGeometry>(query, table, config);
}

Grower::Grower(const Scene& scene, const Geometry& geometry, const TriangleTable& table, const Config& config,
               std::uint64_t seed)
    : scene_(scene), geometry_(geometry), table_(table), cfg_(config), seed_(seed) {
  if (scene.seeds.empty()) throw InputError(fmt::format("ivy: scene '{}' has no seeds to grow from", scene.name));
  pending_seeds_ = scene.seeds.size();
  add_seed_roots();
}

void Grower::add_seed_roots() {
  for (const Seed& s : scene_.seeds) {
    if (s.start_step != iteration_) continue;
    Root r;
    r.id = static_cast<std::uint32_t>(roots_.size());
    const float len = glm::length(s.direction);
    r.dir = len > 0.0f ? s.direction / len : kUp;
    PlantNode n;
    n.position = s.position;
    n.radius = 1.3f * base_radius(0);
    n.shoot = r.id;
    n.birth_step = static_cast<std::uint32_t>(iteration_);
    r.nodes.push_back(static_cast<std::uint32_t>(plant_.nodes.size()));
    r.tip = s.position;
    plant_.nodes.push_back(n);
    adhesion_.emplace_back(0.0f);
    length_.push_back(0.0f);
    floating_.push_back(0.0f);
    alive_.push_back(r.id);
    roots_.push_back(std::move(r));
    --pending_seeds_;
  }
}

Grower::Grown Grower::grow_one(const Root& r) const {
  const glm::vec3 pos = r.tip;
  const float floating = r.tip_floating;
  Grown g{};
  g.hint = r.hint;
  g.floated_out = floating > cfg_.max_float;  // Luft: dies, but still grows this once

  Rng rng(seed_, kGrowStream ^ r.id, 3 * static_cast<std::uint64_t>(r.nodes.size() - 1));
  glm::vec3 random = cube(rng) + glm::vec3(0.0f, 0.2f, 0.0f);
  const float rl = glm::length(random);
  random = rl > 0.0f ? random / rl : kUp;

  const float fall = cfg_.gravity * std::pow(floating / cfg_.max_float, 0.7f);
  const glm::vec3 adhesion = r.ahead_valid ? r.ahead : geometry_.adhesion(pos, g.hint);

  glm::vec3 grow = cfg_.step * (r.dir * cfg_.primary + random * cfg_.random + adhesion * cfg_.adhesion);
  const glm::vec3 gravity = cfg_.step * fall * glm::vec3(0.0f, -1.0f, 0.0f);
  glm::vec3 next = pos + grow + gravity;

  bool ok = true;
  if (cfg_.collision_mode == CollisionMode::Luft) {
    // Pass one of Luft's loop mirrors only at a triangle the segment crosses. Only if one is crossed
    // does the loop need every triangle the mirrored ends can reach, all within the segment's length
    // of pos. (The slack covers rounding and the inside test's tolerance.)
    if (geometry_.crosses_any(pos, next, g.ahead)) {
      const float len = glm::length(next - pos);
      Candidates reach;
      geometry_.gather(pos, len * (1.0f + 1e-3f) + cfg_.margin, reach);
      const CollisionResult c = collide(table_, reach.sorted_unique(), pos, next);
      g.climbing = c.climbing;
      g.reflections = static_cast<std::uint32_t>(c.reflections);
      ok = c.alive;
    }
  } else {
    const RayHit h = geometry_.first_hit(pos, next - pos);
    if (h.hit && glm::dot(next - pos, h.normal) < 0.0f) {
      next -= 2.0f * h.normal * glm::dot(h.normal, next - h.point);
      g.climbing = true;
      g.reflections = 1;
    }
  }
  grow = next - pos - gravity;
  const float gl = glm::length(grow);
  const glm::vec3 dir = 0.5f * r.dir + 0.5f * (gl > 0.0f ? grow / gl : r.dir);
  const float dl = glm::length(dir);
  const float seg = glm::length(next - pos);
  g.pos = next;
  g.dir = dl > 0.0f ? dir / dl : r.dir;
  g.adhesion = adhesion;
  g.length = r.tip_length + seg;
  g.floating = g.climbing ? 0.0f : floating + seg;
  g.collision_death = !ok;
  return g;
}

std::ptrdiff_t Grower::pick_branch_node(const Root& r) const {
  Rng rng(seed_, kBranchStream ^ static_cast<std::uint64_t>(iteration_), static_cast<std::uint64_t>(r.id) << 20);
  return sample_branch_node(
      r.nodes.size(), [&](std::size_t k) { return length_at(r, k); }, cfg_.branching, rng);
}

bool Grower::limits_reached() const {
  return (cfg_.max_root_length > 0.0 && longest_root_ >= cfg_.max_root_length) ||
         (cfg_.max_total_length > 0.0 && total_length_ >= cfg_.max_total_length);
}

namespace {
// Resizes v to n, growing its capacity by half when it must grow: the per-node arrays then hold at
// most 1.5x their nodes (doubling, as push_back and resize do, leaves up to 2x just past a power of
// two; README, "Memory per node").
template <class T>
void grow_by_half(std::vector<T>& v, std::size_t n) {
  if (n > v.capacity()) v.reserve(std::max(n, v.capacity() + v.capacity() / 2));
  v.resize(n);
}
}  // namespace

bool Grower::step() {
  if (limits_reached()) return false;
  // Grow every alive root by one node, in parallel. Root alive_[i] appends node base + i, so each
  // root writes its own record and its own node slots; only the sums and the compaction of alive_
  // below are serial, in root order.
  const std::size_t count = alive_.size();
  const std::size_t base = plant_.nodes.size();
  grow_by_half(plant_.nodes, base + count);
  grow_by_half(adhesion_, base + count);
  grow_by_half(length_, base + count);
  grow_by_half(floating_, base + count);
  outcome_.resize(count);
  auto grow_range = [&](std::size_t a, std::size_t b) {
    for (std::size_t i = a; i < b; ++i) {
      Root& r = roots_[alive_[i]];
      const Grown g = grow_one(r);
      const std::size_t k = base + i;
      PlantNode& n = plant_.nodes[k];
      n.position = g.pos;
      n.parent = static_cast<std::int32_t>(r.nodes.back());
      n.radius = 1.3f * base_radius(r.depth);
      n.order = r.depth;
      n.shoot = r.id;
      n.birth_step = static_cast<std::uint32_t>(iteration_ + 1);
      adhesion_[k] = g.adhesion;
      length_[k] = g.length;
      floating_[k] = g.floating;
      outcome_[i] = {glm::length(g.pos - r.tip), g.length, g.reflections, g.climbing, g.floated_out, g.collision_death};
      r.nodes.push_back(static_cast<std::uint32_t>(k));
      r.dir = g.dir;
      r.tip = g.pos;
      r.tip_length = g.length;
      r.tip_floating = g.floating;
      r.hint = g.ahead.valid ? g.ahead.hint : g.hint;
      r.ahead = g.ahead.vector;
      r.ahead_valid = g.ahead.valid;
    }
  };
  // A node is cheap: grains of 8 roots keep the threads' shares of a step even, and each writes
  // contiguous runs of the node arrays (small dynamic chunks handed out one at a time interleaved the
  // threads' writes and were slower).
  if (count >= 16)
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 8),
                      [&](const tbb::blocked_range<std::size_t>& rg) { grow_range(rg.begin(), rg.end()); });
  else
    grow_range(0, count);

  std::size_t still = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const Outcome& o = outcome_[i];
    total_length_ += o.segment;
    longest_root_ = std::max(longest_root_, static_cast<double>(o.length));
    climbing_nodes_ += o.climbing ? 1 : 0;
    reflections_ += o.reflections;
    floated_out_ += o.floated_out ? 1 : 0;
    collision_deaths_ += o.collision_death ? 1 : 0;
    if (!o.floated_out && !o.collision_death) alive_[still++] = alive_[i];
  }
  alive_.resize(still);

  // Branching: alive roots in index order; the first `branches_per_step` that branch start new roots.
  int started = 0;
  const std::size_t alive_now = alive_.size();
  for (std::size_t i = 0; i < alive_now && started < cfg_.branches_per_step && roots_.size() < cfg_.max_roots; ++i) {
    const std::uint32_t ri = alive_[i];
    if (roots_[ri].depth > cfg_.max_depth) continue;
    const std::ptrdiff_t k = pick_branch_node(roots_[ri]);
    if (k < 0) continue;
    Root child;
    child.id = static_cast<std::uint32_t>(roots_.size());
    child.depth = static_cast<std::uint16_t>(roots_[ri].depth + 1);
    child.nodes.push_back(roots_[ri].nodes[static_cast<std::size_t>(k)]);
    child.first_floating = floating_at(roots_[ri], static_cast<std::size_t>(k));
    child.tip = plant_.nodes[child.nodes[0]].position;
    child.tip_floating = child.first_floating;
    child.dir = kUp;
    alive_.push_back(child.id);
    roots_.push_back(std::move(child));
    ++started;
  }
  ++iteration_;
  if (pending_seeds_ > 0) {
    add_seed_roots();
    std::sort(alive_.begin(), alive_.end());
  }
  return (!alive_.empty() || pending_seeds_ > 0) && !limits_reached();
}

void Grower::finish() {
  // Per root: smooth the adhesion vectors, assign radii, place leaves. Roots are independent; each
  // writes its own slot and the slots are concatenated in root order.
  std::vector<std::vector<Organ>> leaves(roots_.size());
  static constexpr float kGauss[11] = {1, 2, 4, 7, 9, 10, 9, 7, 4, 2, 1};
  auto per_root = [&](std::size_t ri) {
    const Root& r = roots_[ri];
    const std::size_t n = r.nodes.size();
    std::vector<glm::vec3> a(n);  // this root's (smoothed) adhesion vectors
    a[0] = glm::vec3(0.0f);       // the start node carries no adhesion (Luft's new-root node)
    for (std::size_t k = 1; k < n; ++k) a[k] = adhesion_[r.nodes[k]];
    std::vector<glm::vec3> tmp(n);
    for (int pass = 0; pass < cfg_.smoothing_passes; ++pass) {
      for (std::size_t k = 0; k < n; ++k) {
        glm::vec3 e(0.0f);
        for (int i = -5; i <= 5; ++i) {
          const auto j = static_cast<std::ptrdiff_t>(k) + i;
          const std::size_t c = j < 0 ? 0 : std::min(static_cast<std::size_t>(j), n - 1);
          e += a[c] * kGauss[i + 5];
        }
        tmp[k] = e / 56.0f;
      }
      a.swap(tmp);
    }
    const float L = length_at(r, n - 1);
    if (n < 2 || !(L > 0.0f)) return;
    const float base = base_radius(r.depth);
    // Radii: the start node of a branch root belongs to its parent root and keeps the parent's.
    for (std::size_t k = (r.depth == 0 ? 0 : 1); k < n; ++k)
      plant_.nodes[r.nodes[k]].radius = base * (1.3f - length_at(r, k) / L);
    if (cfg_.leaf_mode == LeafMode::None) return;

    auto make_leaf = [&](const glm::vec3& centre, const glm::vec3& adh, float dphi, float dtheta, float half,
                         std::uint32_t node, OrganKind kind) {
      const float align = glm::length(adh);
      const glm::vec3 an = align > 0.0f ? adh / align : glm::vec3(0.0f);
      // Toward the surface, horizontally; the leaf normal tilts from up away from it by half the
      // angle between the adhesion vector and straight down (Luft's theta), turned by phi.
      float phi = std::abs(an.x) + std::abs(an.z) > 1e-6f ? std::atan2(an.z, an.x) : 0.0f;
      float theta = align > 0.0f ? 0.5f * std::acos(std::clamp(-an.y, -1.0f, 1.0f)) : 0.0f;
      phi += dphi;
      theta += dtheta;
      const glm::vec3 toward(std::cos(phi), 0.0f, std::sin(phi));
      const glm::vec3 normal = std::cos(theta) * kUp - std::sin(theta) * toward;
      const glm::vec3 blade = glm::normalize(glm::cross(kUp, toward));
      const glm::vec3 across = glm::cross(normal, blade);
      Organ o;
      o.size = 2.0f * half;
      o.position = centre - 0.5f * o.size * blade;
      o.orientation = glm::quat_cast(glm::mat3(across, normal, blade));
      o.kind = kind;
      o.node = static_cast<std::int32_t>(node);
      leaves[ri].push_back(o);
    };
    auto leaf_weight = [&](std::size_t k) {
      const float x = length_at(r, k) / L;
      const float al = glm::length(a[k]);
      const float ground = al > 0.0f ? std::max(0.0f, -glm::dot(kUp, a[k] / al)) : 0.0f;
      return std::pow(x, 0.7f) + ground * std::pow(1.0f - x, 2.0f);
    };
    if (cfg_.leaf_mode == LeafMode::Luft) {
      for (int pass = 0; pass < cfg_.leaf_passes; ++pass)
        for (std::size_t k = 0; k < n; ++k) {
          Rng rng(seed_, kLeafStream ^ (static_cast<std::uint64_t>(r.id) << 8) ^ static_cast<std::uint64_t>(pass),
                  8 * k);
          const float w = leaf_weight(k);
          if (!(static_cast<float>(rng.uniform()) * w > cfg_.leaf_probability)) continue;
          const float align = glm::length(a[k]);
          const glm::vec3 centre = plant_.nodes[r.nodes[k]].position + cube(rng) * cfg_.leaf_size;
          const float size_w = 1.5f - (std::cos(w * kTwoPi) * 0.5f + 0.5f);
          const auto dphi = static_cast<float>(rng.uniform() - 0.5) * (1.3f - align);
          const auto dtheta = static_cast<float>(rng.uniform() - 0.5) * (1.1f - align);
          const bool young = static_cast<float>(rng.uniform()) * w > cfg_.leaf_probability;
          make_leaf(centre, a[k], dphi, dtheta, cfg_.leaf_size * size_w, r.nodes[k],
                    young ? OrganKind::YoungLeaf : OrganKind::Leaf);
        }
    } else {  // Blender: angles once per node, leaf_passes tries spread along the segment to the next node
      for (std::size_t k = 0; k + 1 < n; ++k) {
        Rng rng(seed_, kLeafStream ^ (static_cast<std::uint64_t>(r.id) << 8) ^ 0xFFull, 64 * k);
        const float w = leaf_weight(k);
        const float align = glm::length(a[k]);
        const float size_w = 1.5f - (std::cos(w * kTwoPi) * 0.5f + 0.5f);
        const auto dphi = static_cast<float>(rng.uniform() - 0.5) * (1.3f - align);
        const auto dtheta = static_cast<float>(rng.uniform() - 0.5) * (1.1f - align);
        const glm::vec3 p0 = plant_.nodes[r.nodes[k]].position, p1 = plant_.nodes[r.nodes[k + 1]].position;
        for (int j = 0; j < cfg_.leaf_passes; ++j) {
          if (!(static_cast<float>(rng.uniform()) * w > cfg_.leaf_probability)) continue;
          const float t = static_cast<float>(j) / static_cast<float>(cfg_.leaf_passes);
          const glm::vec3 centre = glm::mix(p0, p1, t) + cfg_.leaf_size * cube(rng);
          make_leaf(centre, a[k], dphi, dtheta, cfg_.leaf_size * size_w, r.nodes[k], OrganKind::Leaf);
        }
      }
    }
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, roots_.size(), 16),
                    [&](const tbb::blocked_range<std::size_t>& rg) {
                      for (std::size_t ri = rg.begin(); ri < rg.end(); ++ri) per_root(ri);
                    });
  plant_.organs.clear();
  for (auto& l : leaves) plant_.organs.insert(plant_.organs.end(), l.begin(), l.end());
}

double Grower::state_bytes_per_node() const {
  if (plant_.nodes.empty()) return 0.0;
  double bytes = static_cast<double>(
      plant_.nodes.capacity() * sizeof(PlantNode) + adhesion_.capacity() * sizeof(glm::vec3) +
      (length_.capacity() + floating_.capacity()) * sizeof(float) + roots_.capacity() * sizeof(Root));
  for (const auto& r : roots_) bytes += static_cast<double>(r.nodes.capacity() * sizeof(std::uint32_t));
  return bytes / static_cast<double>(plant_.nodes.size());
}

std::vector<std::pair<std::string, double>> Grower::stats() const {
  return {{"R_m", cfg_.radius},
          {"step_m", cfg_.step},
          {"iterations", iteration_},
          {"roots", static_cast<double>(roots_.size())},
          {"roots_alive", static_cast<double>(alive_.size())},
          {"climbing_nodes", static_cast<double>(climbing_nodes_)},
          {"reflections", static_cast<double>(reflections_)},
          {"deaths_floating", static_cast<double>(floated_out_)},
          {"deaths_collision", static_cast<double>(collision_deaths_)},
          {"longest_root_m", longest_root_},
          {"state_bytes_per_node", state_bytes_per_node()}};
}

}  // namespace ivy
}  // namespace growbench
