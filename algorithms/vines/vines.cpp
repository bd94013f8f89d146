// Space-colonization vines in texture space (after Khaddaj and Tantawy's Unity tool): attractors are
// spread over a texture's UV space at a "vine resolution", root growers reach toward them, and the vine
// is drawn into a texture that the mesh wears. Masks, tags, wiggling attractors, kill limits and leaves
// as the seed describes them; beyond it, growth measured on the surface and walking across UV seams.
//
// Space. Lengths are in cells: 1 / resolution of the texture's side in UV. With metric=surface a cell is
// the mean surface length of a texel column (sqrt(surface area / UV area) / resolution), and every
// distance (influence, kill, step, wiggle) is measured between points on the surface in 3D, so a chart
// squeezed in UV grows the same vine as one laid out generously, and a grower near a seam sees
// attractors on the other side. With metric=uv every distance is measured in UV, as in the seed.
//
// Cost model. Growers sit in a hash grid whose cells are the influence radius plus the wiggle amplitude
// wide (the seed's sizing); attractors in another keyed by their resting place. An attractor is
// "active" once a grower it can serve has come within that reach of its resting place; only active
// attractors search for their nearest grower, every iteration, from wherever their wiggle has taken
// them, so the search is exact while they move. Each attractor is active for the few iterations the
// growth front takes to pass it, so a run costs about (attractors x front passage x growers per cell).
//
// Determinism. Parallel passes write per-item slots; pulls, kills and new growers are applied in a
// fixed order (the active list's, then grower index), ties between equidistant growers go to the lower
// index, and every random draw is counter-based on (seed, stream, item).
#include "algorithms/vines/vines.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <stb_image.h>
#include <tbb/parallel_for.h>

#include "algorithms/colonization.hpp"
#include "algorithms/vines/grid.hpp"
#include "algorithms/vines/mask.hpp"
#include "algorithms/vines/surface.hpp"
#include "core/json_util.hpp"
#include "core/random.hpp"

namespace growbench {
namespace {

// ---- parameter table (what `growbench list` prints) ----
const AlgorithmInfo kInfo = {
    .name = "vines",
    .summary =
        "space colonization in a texture's UV space (or a canvas): masks, tags, wiggle, kill limits, "
        "leaves; draws texture.png, worn by the mesh",
    .params =
        {
            param::choice("space", "auto", {"auto", "uv", "canvas"})
                .doc("uv: the texture space of the scene mesh's texture coordinates; canvas: a unit square laid on "
                     "the scene's main climbable face; auto: uv when a scene mesh has texture coordinates"),
            param::integer("resolution", 256)
                .range(8, 4096)
                .doc("vine resolution: attractors are spread over resolution x resolution candidate cells, and "
                     "lengths are in cells (1/resolution of the texture)"),
            param::real("density", 1.0 / 3.0).range(1e-4, 1).doc("chance that a candidate cell holds an attractor"),
            param::choice("nodes", "continuous", {"continuous", "grid"})
                .doc("grid: growers sit on cell centres and step to a neighbouring cell (pixelated vines)"),
            param::choice("metric", "surface", {"surface", "uv"})
                .doc("surface: lengths, radii and attractor density are measured on the surface; uv: in UV, as "
                     "the seed (UV distortion shows, vines stop at chart borders)"),
            param::choice("seams", "cross", {"cross", "stop"})
                .doc("metric=surface: a grower that reaches a UV chart border continues in the chart across the "
                     "mesh edge (cross) or stops there"),
            param::real("influence", 4)
                .range(0.5, 200)
                .unit("cells")
                .doc("influence radius of an attractor; left at its default, divided by sqrt(share) for tags, "
                     "where share = 1/tags + tag_mix (1 - 1/tags) is the part of the attractors a vine may take"),
            param::real("kill", 1.5)
                .range(0.05, 200)
                .unit("cells")
                .doc("kill radius: an attractor this close to "
                     "the grower it pulls dies"),
            param::real("step", 1).range(0.05, 50).unit("cells").doc("distance from a grower to its child"),
            param::integer("stall_iterations", 10)
                .range(1, 100000)
                .doc("growth stops when no attractor has been killed for this many iterations"),
            param::text("roots").doc("root growers: 'u,v[,tag];...' in the mesh's UV, or 'random' (root_count of "
                                     "them); empty: the mask's green "
                                     "dots, else the scene's seeds"),
            param::integer("root_count", 3).range(1, 10000).doc("number of random roots (roots=random)"),
            param::text("mask").doc("inclusion/exclusion map, a PNG: red marks the zone, green dots mark roots"),
            param::choice("mask_mode", "include", {"include", "exclude"})
                .doc("include: attractors only in the red zone; exclude: only outside it"),
            param::integer("tags", 1).range(1, 16).doc("number of tags; root k carries tag k mod tags"),
            param::real("tag_mix", 0)
                .range(0, 1)
                .doc("each attractor carries one random tag, and every other tag with this chance (1: shared by "
                     "all, vines border each other; 0: exclusive, vines overlap)"),
            param::real("wiggle", 0).range(0, 50).unit("cells").doc("radius of the circle attractors move on"),
            param::real("wiggle_period", 6).range(1, 1e6).doc("iterations per turn of an attractor's circle"),
            param::integer("kill_limit", 0)
                .range(0, 1000000)
                .doc("a grower stops after killing this many attractors (0: no limit)"),
            param::integer("kill_limit_offset", 3)
                .range(0, 1000000)
                .doc("a side branch's kill count starts this far below its parent's (a strand's next grower "
                     "carries its parent's count on)"),
            param::integer("kill_limit_jitter", 0)
                .range(0, 1000000)
                .doc("a side branch's starting count varies at random by up to this many"),
            param::real("tip_width", 0.4).range(0.01, 100).unit("cells").doc("vine width at the tips"),
            param::real("max_width", 3).range(0.01, 1000).unit("cells").doc("widest vine (the pipe model is capped)"),
            param::real("pipe_exponent", 2.5).range(1, 4).doc("pipe model exponent n: w^n = sum of children's w^n"),
            param::choice("leaves", "interval", {"none", "ends", "interval"})
                .doc("leaves at every leaf_interval-th grower in drawing order, at the vines' ends only, or none"),
            param::integer("leaf_interval", 3).range(1, 100000).doc("a leaf every this many growers (leaves=interval)"),
            param::real("leaf_size", 3).range(0, 1000).unit("cells").doc("leaf length, stem to tip"),
            param::real("leaf_gravity", 0.5)
                .range(0, 100)
                .doc("pull of a leaf's direction toward -V: the segment direction plus this times (0, -1)"),
            param::real("leaf_angle_jitter", 30)
                .range(0, 180)
                .unit("deg")
                .doc("a leaf's rotation varies at random within plus or minus this"),
            param::real("leaf_scale_min", 0.8).range(0.01, 100).doc("smallest random leaf scale"),
            param::real("leaf_scale_max", 1.2).range(0.01, 100).doc("largest random leaf scale"),
            param::real("leaf_brightness_min", 0.8).range(0, 4).doc("darkest random leaf brightness"),
            param::real("leaf_brightness_max", 1.2).range(0, 4).doc("brightest random leaf brightness"),
            param::real("leaf_stem_offset", 0)
                .range(0, 0.5)
                .doc("where the sprite's stem meets the vine, below its top edge, as a fraction of its height"),
            param::text("leaf_texture")
                .doc("leaf sprite PNG, hanging down with its stem at the top centre "
                     "(empty: the built-in leaf)"),
            param::integer("texture_size", 1024)
                .range(16, 8192)
                .unit("px")
                .doc("texture.png is this many pixels "
                     "square"),
            param::choice("style", "lines", {"lines", "dots"})
                .doc("lines: strokes between growers; dots: a disc at each grower (the seed's corruption style)"),
            param::vec3("vine_color", glm::dvec3(0.24, 0.33, 0.13)).range(0, 1).doc("vine colour, sRGB"),
            param::vec3("leaf_color", glm::dvec3(0.28, 0.56, 0.18)).range(0, 1).doc("built-in leaf colour, sRGB"),
        },
    .test_params = {"resolution=64"},
};

using vines::Leaves;
using vines::Location;
using vines::Metric;
using vines::Space;
using vines::Style;

constexpr std::int32_t kNone = -1;
constexpr std::uint64_t kStreamAttractor = 0xA77Aull, kStreamRoot = 0x2007ull, kStreamLeaf = 0x1EAFull,
                        kStreamKills = 0x4111ull;
constexpr float kStallFraction = 0.2f;  // a child this close (times the step) to a sibling repeats it

using colonization::safe_normalize;

// The unit square laid on a scene's main climbable face: the climbable meshes' extent as the camera
// sees it, in the plane facing the camera at their front, above any ground.
struct Canvas {
  glm::vec3 origin{0.0f}, u_axis{1, 0, 0}, v_axis{0, 1, 0}, forward{0, 0, -1};
  float depth = 1.0f;  // how far behind the plane the climbable meshes reach
};

Canvas canvas_of(const Scene& scene) {
  Canvas c;
  glm::vec3 f = scene.camera.look_at - scene.camera.position;
  f.y = 0.0f;
  c.forward = glm::length(f) > 1e-6f ? glm::normalize(f) : glm::vec3(0, 0, -1);
  const glm::vec3 up(0, 1, 0), right = glm::normalize(glm::cross(c.forward, up));
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  auto extend = [&](const glm::vec3& p) {
    const glm::vec3 q(glm::dot(p, right), p.y, glm::dot(p, c.forward));
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  };
  float ground = -std::numeric_limits<float>::max();
  for (const auto& m : scene.meshes) {
    if (!m.climbable) {
      ground = std::max(ground, m.bounds().max.y);
      continue;
    }
    for (const auto& p : m.vertices) extend(p);
  }
  // Nothing to climb: the canvas stands free, across the envelope (or the whole scene) facing the camera.
  if (lo.x > hi.x) {
    const Aabb b = scene.envelope ? scene.envelope->bounds() : scene.bounds();
    for (int k = 0; k < 8; ++k)
      extend({k & 1 ? b.max.x : b.min.x, k & 2 ? b.max.y : b.min.y, k & 4 ? b.max.z : b.min.z});
  }
  if (lo.x > hi.x) {  // an empty scene: the unit square at the origin
    lo = glm::vec3(0.0f);
    hi = glm::vec3(1.0f);
  }
  if (ground > lo.y && ground < hi.y) lo.y = ground;
  c.origin = right * lo.x + up * lo.y + c.forward * lo.z;
  c.u_axis = right * std::max(hi.x - lo.x, 1e-6f);
  c.v_axis = up * std::max(hi.y - lo.y, 1e-6f);
  c.depth = std::max(hi.z - lo.z, 1e-6f);
  return c;
}

// The signed angle (counter-clockwise, v up) that turns (0, -1) onto d.
float hang_angle(const glm::vec2& d) {
  return std::atan2(d.x, -d.y);
}

glm::vec2 rotate(const glm::vec2& d, float a) {
  const float c = std::cos(a), s = std::sin(a);
  return {c * d.x - s * d.y, s * d.x + c * d.y};
}

class Vines final : public GrowthAlgorithm {
 public:
  const AlgorithmInfo& describe() const override { return kInfo; }

  // The mask is decoded here, in the harness's scene_load phase, so growth times growing only; start()
  // decodes it itself when this was not called (tests that call start() directly).
  void load_inputs(const Params& p) override {
    loaded_mask_.reset();
    loaded_mask_path_ = p.text("mask");
    if (!loaded_mask_path_.empty()) loaded_mask_ = vines::Mask::read(loaded_mask_path_, "mask");
  }

  void start(const Scene& scene, const SceneQuery& query, const Params& p, std::uint64_t seed) override {
    scene_ = &scene;
    query_ = &query;
    seed_ = seed;
    cfg_ = vines::make_config(p);
    check_config();
    leaf_texture_ = p.text("leaf_texture");
    if (!leaf_texture_.empty()) check_png(leaf_texture_, "leaf_texture");
    std::optional<vines::Mask> mask;
    mask_path_ = p.text("mask");
    if (loaded_mask_ && loaded_mask_path_ == mask_path_)
      mask = std::move(loaded_mask_);
    else if (!mask_path_.empty())
      mask = vines::Mask::read(mask_path_, "mask");
    loaded_mask_.reset();
    make_surface();
    place_attractors(mask ? &*mask : nullptr);
    place_roots(p.text("roots"), mask ? &*mask : nullptr);
    params_.reset();  // the record keeps the parameters as given, unless the default influence was widened
    if (static_cast<double>(cfg_.influence) != p.real("influence")) {
      params_ = p;
      params_->set("influence", fmt::format("{}", cfg_.influence));
    }
    warnings_.clear();
    warn_of_fitted_uvs();
    warn_of_rootless_tags();
    iteration_ = 0;
    last_kill_ = 0;
    activate(0);
  }

  bool step() override {
    ++iteration_;
    claim();
    if (apply_claims() > 0) last_kill_ = iteration_;
    const std::size_t before = growers_.size();
    grow_children();
    activate(before);
    std::erase_if(active_, [this](std::uint32_t a) { return !alive_[a]; });
    plant_stale_ = true;
    if (alive_count_ == 0) return false;
    if (active_.empty() && growers_.size() == before) return false;  // nothing can happen any more
    return iteration_ - last_kill_ < cfg_.stall_iterations;
  }

  void finish() override {
    finished_ = true;
    plant_stale_ = true;
    build_plant();
  }

  std::optional<Params> effective_params() const override { return params_; }
  std::vector<std::string> warnings() const override { return warnings_; }

  const Plant& plant() const override {
    if (plant_stale_) build_plant();
    return plant_;
  }
  std::size_t node_count() const override { return growers_.size(); }
  std::size_t organ_count() const override { return finished_ ? plant().organs.size() : 0; }

  OwnVerdict own_verdict() const override {
    if (mesh_ != kNone || climbable_) return {};
    return {fmt::format("a canvas needs a climbable surface to lie on, and scene '{}' has none: the vines would be "
                        "drawn on a card standing free",
                        scene_->name),
            {}};
  }

  std::vector<std::pair<std::string, double>> stats() const override {
    std::size_t tips = 0, stopped = 0;
    for (std::size_t g = 0; g < growers_.size(); ++g) {
      tips += first_child_[g] == kNone ? 1 : 0;
      stopped += spent(g) ? 1 : 0;
    }
    return {{"attractors", static_cast<double>(alive_.size())},
            {"attractors_left", static_cast<double>(alive_count_)},
            {"iterations", static_cast<double>(iteration_)},
            {"tips", static_cast<double>(tips)},
            {"growers_stopped_by_kill_limit", static_cast<double>(stopped)},
            {"seam_crossings", static_cast<double>(seam_crossings_)},
            {"uv_charts", static_cast<double>(surface_->chart_count())},
            {"cell_m", static_cast<double>(cell_m_)}};
  }

  std::vector<OutputFile> write_outputs(const OutputRequest& r) const override;

 private:
  // ---------- setup ----------
  void check_config() const {
    auto fail = [](const std::string& what) { throw InputError("algorithm 'vines': " + what); };
    if (cfg_.kill >= cfg_.influence)
      fail(fmt::format("kill ({}) must be smaller than influence ({})", cfg_.kill, cfg_.influence));
    if (cfg_.step > cfg_.influence)
      fail(fmt::format("step ({}) must not exceed influence ({})", cfg_.step, cfg_.influence));
    if (cfg_.leaf_scale_min > cfg_.leaf_scale_max)
      fail(fmt::format("leaf_scale_min ({}) exceeds leaf_scale_max ({})", cfg_.leaf_scale_min, cfg_.leaf_scale_max));
    if (cfg_.leaf_brightness_min > cfg_.leaf_brightness_max)
      fail(fmt::format("leaf_brightness_min ({}) exceeds leaf_brightness_max ({})", cfg_.leaf_brightness_min,
                       cfg_.leaf_brightness_max));
    if (cfg_.tip_width > cfg_.max_width)
      fail(fmt::format("tip_width ({}) exceeds max_width ({})", cfg_.tip_width, cfg_.max_width));
  }

  static void check_png(const std::string& path, const char* key) {
    int w = 0, h = 0, n = 0;
    if (const std::string why = file_problem(path); !why.empty())
      throw InputError(fmt::format("{}={}: {} (expected a PNG)", key, path, why));
    if (stbi_info(path.c_str(), &w, &h, &n) == 0 || w <= 0 || h <= 0)
      throw InputError(
          fmt::format("{}={}: not a readable image ({}); expected a PNG", key, path, stbi_failure_reason()));
  }

  // The surface the vine grows on, and the length of a cell on it.
  void make_surface() {
    mesh_ = kNone;
    if (cfg_.space != Space::Canvas)
      for (std::size_t i = 0; i < scene_->meshes.size() && mesh_ == kNone; ++i)
        if (scene_->meshes[i].has_uvs()) mesh_ = static_cast<std::int32_t>(i);
    if (cfg_.space == Space::Uv && mesh_ == kNone)
      throw InputError(fmt::format(
          "algorithm 'vines': space=uv needs a scene mesh with texture coordinates (OBJ vt), and scene '{}' has "
          "none; use space=canvas, or a mesh with UVs",
          scene_->name));
    plant_.decals.clear();
    if (mesh_ != kNone) {
      surface_ = std::make_unique<vines::Surface>(scene_->meshes[static_cast<std::size_t>(mesh_)]);
      if (surface_->uv_fitted()) {  // the texture spans the fitted square of the mesh's coordinates
        const glm::vec2 o = surface_->uv_origin();
        const float side = surface_->uv_side();
        plant_.decals.push_back({"texture.png", mesh_, {o.x, o.y, 0.0f}, {side, 0.0f, 0.0f}, {0.0f, side, 0.0f}});
      } else {
        plant_.decals.push_back({"texture.png", mesh_, {}, {}, {}});
      }
    } else {
      canvas_ = canvas_of(*scene_);
      climbable_ = scene_->has_climbable();
      surface_ =
          std::make_unique<vines::Surface>(vines::Surface::canvas(canvas_.origin, canvas_.u_axis, canvas_.v_axis));
      plant_.decals.push_back({"texture.png", kPlanarDecal, canvas_.origin, canvas_.u_axis, canvas_.v_axis});
    }
    if (!(surface_->uv_area() > 0.0))
      throw InputError(
          fmt::format("algorithm 'vines': the texture coordinates of scene '{}' cover no area", scene_->name));
    cell_m_ = static_cast<float>(std::sqrt(surface_->mean_area_ratio()) / cfg_.resolution);
    reach_ = cfg_.influence + cfg_.wiggle;
    growers_grid_ = std::make_unique<vines::CellTable>(reach_);
  }

  // Where the space colonization measures a point, in cells: its UV position (metric=uv), its place in
  // the canvas's plane (a canvas is flat, so that is its 3D distance, in two coordinates), or its 3D
  // position on a mesh.
  glm::vec3 metric_position(const Location& l) const {
    if (cfg_.metric == Metric::Uv) return glm::vec3(surface_->uv(l) * static_cast<float>(cfg_.resolution), 0.0f);
    if (mesh_ == kNone)
      return glm::vec3(surface_->uv(l) * glm::vec2(glm::length(canvas_.u_axis), glm::length(canvas_.v_axis)) / cell_m_,
                       0.0f);
    return surface_->position(l) / cell_m_;
  }
  // Whether metric positions lie in the plane z = 0 (the grid then looks at one layer of cells).
  bool planar() const { return cfg_.metric == Metric::Uv || mesh_ == kNone; }
  // A direction in metric space as a direction on the surface in 3D.
  glm::vec3 surface_direction(const glm::vec3& d) const {
    if (mesh_ != kNone) return d;
    return d.x * glm::normalize(canvas_.u_axis) + d.y * glm::normalize(canvas_.v_axis);
  }

  // Where a surface point is in the scene: on the mesh, or for a canvas, where the plane's point projects
  // along the view onto the climbable meshes (nullopt where it meets none).
  struct Placed {
    glm::vec3 position{0.0f}, normal{0.0f, 0.0f, 1.0f};
    bool on_scene = true;
  };
  Placed place(const Location& l) const {
    const glm::vec3 p = surface_->position(l);
    if (mesh_ != kNone) return {p, surface_->normal(l.tri), true};
    const float margin = 0.01f * canvas_.depth + 1e-4f;
    const RayHit h = query_->ray(p - margin * canvas_.forward, canvas_.forward, canvas_.depth + 2.0f * margin);
    if (!h.hit || !scene_->meshes[h.mesh].climbable) return {p, -canvas_.forward, !climbable_};
    // Lifted back along the ray, which came through free space (the plane lies in front of every
    // climbable mesh): a lift along the surface normal could enter the ground where a rock meets it.
    return {h.point, -canvas_.forward, true};
  }

  // A node's position: off the surface by its radius, so its tube stays outside the solid; less where
  // that would enter another solid (the ground a mesh stands on), and on the surface at worst.
  glm::vec3 lifted(const Placed& at, float radius) const {
    // A canvas node is lifted back along the ray that found it, through free space: no test needed.
    if (mesh_ == kNone) return at.position + (radius + 1e-4f * cell_m_) * at.normal;
    for (const float k : {1.0f, 0.25f}) {
      const glm::vec3 p = at.position + k * (radius + 1e-4f * cell_m_) * at.normal;
      if (!query_->inside(p)) return p;
    }
    return at.position;
  }

  // Whether an attractor may rest at a UV point: on the surface (and, for a canvas, over a climbable
  // mesh), where the mask allows, outside exclusion zones.
  std::optional<Location> attractor_site(const glm::vec2& uv, double chance, const vines::Mask* mask) const {
    const auto l = surface_->locate(uv);
    if (!l) return std::nullopt;
    double weight = 1.0;
    if (cfg_.metric == Metric::Surface)  // as many attractors per surface area in a squeezed chart as elsewhere
      weight = surface_->area_ratio(l->tri) / surface_->mean_area_ratio();
    if (chance >= cfg_.density * weight) return std::nullopt;
    if (mask && mask->zone(surface_->mesh_uv(uv)) != cfg_.mask_include) return std::nullopt;
    const Placed at = place(*l);
    if (!at.on_scene || !colonization::zones_allow(*scene_, query_->host_queries(), at.position)) return std::nullopt;
    return l;
  }

  void place_attractors(const vines::Mask* mask);
  void place_roots(const std::string& roots, const vines::Mask* mask);

  // Says which layout the texture follows when the mesh's coordinates went beyond the unit square.
  void warn_of_fitted_uvs() {
    if (mesh_ == kNone || !surface_->uv_fitted()) return;
    const glm::vec2 o = surface_->uv_origin();
    const float side = surface_->uv_side();
    warnings_.push_back(fmt::format(
        "scene mesh '{}' has texture coordinates beyond the unit square; the vines grow on them fitted into it, and "
        "texture.png covers u in [{:.4g}, {:.4g}], v in [{:.4g}, {:.4g}] of the mesh's coordinates (one image over "
        "the whole layout, not a tile repeated)",
        scene_->meshes[static_cast<std::size_t>(mesh_)].name, o.x, o.x + side, o.y, o.y + side));
  }

  // A tag no root carries leaves the attractors only it may take out of reach: the vines stop short of
  // them, which looks like a stall. Said, with how many.
  void warn_of_rootless_tags() {
    std::uint32_t rooted = 0;
    for (const auto t : tag_) rooted |= 1u << t;
    std::vector<int> missing;
    for (int t = 0; t < cfg_.tags; ++t)
      if (!((rooted >> t) & 1u)) missing.push_back(t);
    if (missing.empty()) return;
    const auto unreachable = std::count_if(tags_.begin(), tags_.end(), [&](std::uint16_t a) { return !(a & rooted); });
    warnings_.push_back(fmt::format(
        "tags={} but {} root{} carry only {} of them: no root carries tag {}, so {} of the {} attractors (those "
        "only {} may take) are never reached; give each tag a root (roots='u,v,tag;...') or fewer tags",
        cfg_.tags, tag_.size(), tag_.size() == 1 ? "" : "s", cfg_.tags - static_cast<int>(missing.size()),
        fmt::join(missing, ", "), unreachable, tags_.size(), missing.size() == 1 ? "it" : "those tags"));
  }
  std::vector<std::pair<Location, int>> parse_roots(const std::string& text) const;
  Location snapped(const Location& l) const;

  // ---------- growth ----------
  // An attractor's place at the current iteration: its resting place, moved around its circle.
  glm::vec3 attractor_at(std::uint32_t a) const {
    if (cfg_.wiggle <= 0.0f) return center_[a];
    const float turn =
        phase_[a] + 2.0f * std::numbers::pi_v<float> * static_cast<float>(iteration_) / cfg_.wiggle_period;
    glm::vec3 t1(1, 0, 0), t2(0, 1, 0);
    if (!planar()) {
      const glm::vec3 n = surface_->normal(attractor_tri_[a]);
      t1 = safe_normalize(glm::cross(n, std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
      t2 = glm::cross(n, t1);
    }
    return center_[a] + cfg_.wiggle * (std::cos(turn) * t1 + std::sin(turn) * t2);
  }

  bool spent(std::size_t g) const { return cfg_.kill_limit > 0 && kills_[g] >= cfg_.kill_limit; }

  // Visits the grower-grid cells within reach of p (all 27 neighbours; the 9 of its plane in UV).
  template <class F>
  void visit_cells(const vines::CellTable& table, const glm::vec3& p, F&& f) const {
    const glm::ivec3 c = table.cell_of(p);
    const int dz = planar() ? 0 : 1;
    for (int z = -dz; z <= dz; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
          const std::int32_t v = table.find(vines::CellTable::key(c + glm::ivec3(x, y, z)));
          if (v != vines::CellTable::kEmpty) f(v);
        }
  }

  // The nearest grower to p that attractor a serves (one carrying a tag of a's that has not spent its
  // kills) within the influence radius; ties go to the lower index.
  std::pair<std::int32_t, float> nearest_grower(const glm::vec3& p, std::uint32_t a) const {
    std::int32_t best = kNone;
    float best_d2 = cfg_.influence * cfg_.influence;
    visit_cells(*growers_grid_, p, [&](std::int32_t head) {
      for (std::int32_t g = head; g != kNone; g = grid_next_[static_cast<std::size_t>(g)]) {
        const auto ug = static_cast<std::size_t>(g);
        if (!((tags_[a] >> tag_[ug]) & 1u) || spent(ug)) continue;
        const glm::vec3 d = mpos_[ug] - p;
        const float d2 = glm::dot(d, d);
        if (d2 < best_d2 || (d2 == best_d2 && best != kNone && g < best)) {
          best_d2 = d2;
          best = g;
        }
      }
    });
    return {best, best_d2};
  }

  // Each active attractor's nearest grower. A wiggling attractor searches from where it has moved to,
  // every iteration; a resting one keeps the nearest that activate() found, searching again only when
  // that grower has spent its kills. Parallel: iteration k writes slot k and attractor active_[k] only.
  void claim() {
    claim_.resize(active_.size());
    kills_now_.resize(active_.size());
    pull_from_.resize(active_.size());
    const float k2 = cfg_.kill * cfg_.kill;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, active_.size(), 1024), [&](const auto& range) {
      for (std::size_t k = range.begin(); k < range.end(); ++k) {
        const std::uint32_t a = active_[k];
        glm::vec3 p = center_[a];
        std::pair<std::int32_t, float> best{nearest_[a], nearest_d2_[a]};
        if (cfg_.wiggle > 0.0f) {
          p = attractor_at(a);
          best = nearest_grower(p, a);
        } else if (best.first != kNone && spent(static_cast<std::size_t>(best.first))) {
          best = nearest_grower(p, a);
          nearest_[a] = best.first;
          nearest_d2_[a] = best.second;
        }
        claim_[k] = best.first;
        kills_now_[k] = best.first != kNone && best.second < k2 ? 1 : 0;
        pull_from_[k] = p;
      }
    });
  }

  // Pulls and kills in the active list's order; returns the number of attractors killed.
  std::size_t apply_claims() {
    influenced_.clear();
    pulls_.clear();
    slot_.resize(growers_.size(), kNone);
    std::size_t killed = 0;
    for (std::size_t k = 0; k < active_.size(); ++k) {
      const std::int32_t g = claim_[k];
      if (g == kNone) continue;
      const auto ug = static_cast<std::size_t>(g);
      if (slot_[ug] == kNone) {
        slot_[ug] = static_cast<std::int32_t>(influenced_.size());
        influenced_.push_back(g);
        pulls_.emplace_back(0.0f);
      }
      pulls_[static_cast<std::size_t>(slot_[ug])] += safe_normalize(pull_from_[k] - mpos_[ug]);
      if (kills_now_[k]) {
        alive_[active_[k]] = 0;
        --alive_count_;
        ++kills_[ug];
        ++killed;
      }
    }
    for (const auto g : influenced_) slot_[static_cast<std::size_t>(g)] = kNone;
    return killed;
  }

  // A grower's next child: where the step from it ends, and the step's pieces in UV (walk.end etc.).
  struct Child {
    bool ok = false;
    vines::Walk walk;
  };
  void child_of(std::size_t g, const glm::vec3& pull, Child& c) const;
  bool repeats(std::size_t g, const glm::vec3& m) const;
  void reserve_growers(std::size_t n);
  void grow_children();
  std::int32_t add_grower(const Location& at, std::int32_t parent, int tag, const std::vector<vines::UvPiece>& pieces);
  void activate(std::size_t from);

  // ---------- the plant and its drawing ----------
  void build_plant() const;
  std::vector<float> widths_cells() const;
  std::vector<std::uint32_t> preorder() const;
  struct Leaf {
    std::uint32_t grower;
    vines::LeafStamp stamp;
    glm::vec2 direction;  // the blade's direction in UV
    float scale;
  };
  std::vector<Leaf> leaves() const;
  float uv_scale(std::uint32_t tri) const {  // UV length of a unit of surface length here, over the mean
    if (cfg_.metric == Metric::Uv) return 1.0f;
    const float r = surface_->area_ratio(tri);
    return r > 0.0f ? static_cast<float>(std::sqrt(surface_->mean_area_ratio() / r)) : 1.0f;
  }
  vines::DrawOptions draw_options() const;

  // ---------- state ----------
  const Scene* scene_ = nullptr;
  const SceneQuery* query_ = nullptr;
  std::uint64_t seed_ = 0;
  vines::Config cfg_{};
  std::string leaf_texture_, mask_path_;
  std::optional<Params> params_;  // as given, with the influence radius the default became
  std::vector<std::string> warnings_;
  std::optional<vines::Mask> loaded_mask_;  // decoded by load_inputs, taken by start
  std::string loaded_mask_path_;
  std::int32_t mesh_ = kNone;
  Canvas canvas_;
  bool climbable_ = true;  // the canvas projects onto climbable meshes; without any it stands free
  std::unique_ptr<vines::Surface> surface_;
  float cell_m_ = 1.0f, reach_ = 1.0f;
  int iteration_ = 0, last_kill_ = 0;
  std::size_t seam_crossings_ = 0;

  // Attractors (structure of arrays): resting place in metric cells, triangle, wiggle phase, tag bits.
  std::vector<glm::vec3> center_;
  std::vector<std::uint32_t> attractor_tri_;
  std::vector<float> phase_;
  std::vector<std::uint16_t> tags_;
  std::vector<std::uint8_t> alive_, active_flag_;
  std::vector<std::int32_t> nearest_;  // the nearest grower it serves, as of the last activate() (resting)
  std::vector<float> nearest_d2_;
  std::size_t alive_count_ = 0;
  std::vector<std::uint32_t> active_;
  // Attractors by the grid cell of their resting place: cell -> index into cell_start_, whose range of
  // cell_entries_ holds copies of what activate() reads, side by side in memory.
  struct CellEntry {
    glm::vec3 center;
    std::uint32_t id;
    std::uint16_t tags;
  };
  std::unique_ptr<vines::CellTable> attractor_cells_;
  std::vector<std::uint32_t> cell_start_;
  std::vector<CellEntry> cell_entries_;

  // Growers.
  std::vector<Location> growers_;
  std::vector<glm::vec3> mpos_;
  std::vector<std::int32_t> parent_, first_child_, next_sibling_, last_child_, kills_, grid_next_;
  std::vector<std::uint8_t> tag_;
  std::vector<std::uint32_t> birth_, shoot_, piece_end_;
  std::vector<std::uint16_t> order_;
  std::vector<vines::UvPiece> pieces_;
  std::uint32_t next_shoot_ = 0;
  std::unique_ptr<vines::CellTable> growers_grid_;

  // Per-iteration scratch, kept to reuse its memory.
  std::vector<std::int32_t> claim_, slot_, influenced_;
  std::vector<std::uint8_t> kills_now_;
  std::vector<glm::vec3> pull_from_, pulls_;
  std::vector<std::vector<std::pair<std::uint32_t, float>>> found_;
  std::vector<Child> children_;

  // The plant, assembled on demand (and cached) from the growers.
  bool finished_ = false;
  mutable bool plant_stale_ = true;
  mutable Plant plant_;
};

void Vines::place_attractors(const vines::Mask* mask) {
  const int res = cfg_.resolution;
  const float fres = static_cast<float>(res);
  struct Row {
    std::vector<Location> at;
    std::vector<float> phase;
    std::vector<std::uint16_t> tags;
  };
  std::vector<Row> rows(static_cast<std::size_t>(res));
  const std::uint16_t all = static_cast<std::uint16_t>((1u << cfg_.tags) - 1u);
  tbb::parallel_for(tbb::blocked_range<int>(0, res, 4), [&](const auto& r) {
    for (int j = r.begin(); j < r.end(); ++j) {
      Row& row = rows[static_cast<std::size_t>(j)];
      for (int i = 0; i < res; ++i) {
        Rng rng(seed_, kStreamAttractor, (static_cast<std::uint64_t>(j) * static_cast<std::uint64_t>(res) + i) * 8);
        const double chance = rng.uniform();
        const float ju = cfg_.grid_nodes ? 0.5f : static_cast<float>(rng.uniform());
        const float jv = cfg_.grid_nodes ? 0.5f : static_cast<float>(rng.uniform());
        const auto l =
            attractor_site({(static_cast<float>(i) + ju) / fres, (static_cast<float>(j) + jv) / fres}, chance, mask);
        if (!l) continue;
        const float phase = static_cast<float>(rng.uniform(0.0, 2.0 * std::numbers::pi));
        const int own = static_cast<int>(rng.uniform() * cfg_.tags);
        std::uint16_t tags = static_cast<std::uint16_t>(1u << std::min(own, cfg_.tags - 1));
        for (int t = 0; t < cfg_.tags; ++t)
          if (t != own && rng.uniform() < cfg_.tag_mix) tags |= static_cast<std::uint16_t>(1u << t);
        row.at.push_back(*l);
        row.phase.push_back(phase);
        row.tags.push_back(cfg_.tags == 1 ? all : tags);
      }
    }
  });
  for (const Row& row : rows) {
    for (std::size_t k = 0; k < row.at.size(); ++k) {
      center_.push_back(metric_position(row.at[k]));
      attractor_tri_.push_back(row.at[k].tri);
    }
    phase_.insert(phase_.end(), row.phase.begin(), row.phase.end());
    tags_.insert(tags_.end(), row.tags.begin(), row.tags.end());
  }
  if (center_.empty())
    throw InputError(fmt::format(
        "algorithm 'vines': no attractor could be placed on scene '{}'{} (every candidate cell fell outside the "
        "texture's charts, the climbable surfaces, the mask's allowed area or the include zones)",
        scene_->name,
        mask ? fmt::format(" with mask={} (mask_mode={})", mask_path_, cfg_.mask_include ? "include" : "exclude")
             : ""));
  alive_.assign(center_.size(), 1);
  active_flag_.assign(center_.size(), 0);
  nearest_.assign(center_.size(), kNone);
  nearest_d2_.assign(center_.size(), 0.0f);
  alive_count_ = center_.size();
  // Attractors by cell: count, then fill in attractor order.
  attractor_cells_ = std::make_unique<vines::CellTable>(reach_);
  std::vector<std::int32_t> cell_of(center_.size());
  std::vector<std::uint32_t> count;
  for (std::size_t a = 0; a < center_.size(); ++a) {
    std::int32_t& c = attractor_cells_->at(vines::CellTable::key(attractor_cells_->cell_of(center_[a])));
    if (c == vines::CellTable::kEmpty) {
      c = static_cast<std::int32_t>(count.size());
      count.push_back(0);
    }
    cell_of[a] = c;
    ++count[static_cast<std::size_t>(c)];
  }
  cell_start_.assign(count.size() + 1, 0);
  for (std::size_t c = 0; c < count.size(); ++c) cell_start_[c + 1] = cell_start_[c] + count[c];
  cell_entries_.resize(center_.size());
  std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t a = 0; a < center_.size(); ++a)
    cell_entries_[fill[static_cast<std::size_t>(cell_of[a])]++] = {center_[a], static_cast<std::uint32_t>(a), tags_[a]};
}

Location Vines::snapped(const Location& l) const {
  if (!cfg_.grid_nodes) return l;
  const float res = static_cast<float>(cfg_.resolution);
  const glm::vec2 c = (glm::floor(surface_->uv(l) * res) + 0.5f) / res;
  return surface_->locate(c).value_or(l);
}

std::vector<std::pair<Location, int>> Vines::parse_roots(const std::string& text) const {
  std::vector<std::pair<Location, int>> out;
  std::stringstream ss(text);
  std::string item;
  for (int index = 1; std::getline(ss, item, ';'); ++index) {
    if (item.find_first_not_of(" \t") == std::string::npos) continue;
    double v[3] = {0, 0, 0};
    int n = 0;
    std::stringstream is(item);
    std::string part;
    bool ok = true;
    while (ok && std::getline(is, part, ',')) {
      std::size_t used = 0;
      try {
        if (n < 3) v[n] = std::stod(part, &used);
      } catch (const std::exception&) {
        ok = false;
      }
      ok = ok && n < 3 && part.find_first_not_of(" \t", used) == std::string::npos && std::isfinite(v[n]);
      ++n;
    }
    // In the mesh's own texture coordinates, as a mask is painted: the texture's square of them.
    const glm::vec2 lo = surface_->mesh_uv(glm::vec2(0.0f)), hi = surface_->mesh_uv(glm::vec2(1.0f));
    const bool tag_ok = n != 3 || (v[2] >= 0 && v[2] < cfg_.tags && v[2] == std::floor(v[2]));
    if (!ok || n < 2 || !tag_ok || v[0] < lo.x || v[0] > hi.x || v[1] < lo.y || v[1] > hi.y)
      throw InputError(fmt::format(
          "algorithm 'vines': roots entry {} ('{}'): expected u,v or u,v,tag with u in [{:.4g}, {:.4g}], v in "
          "[{:.4g}, {:.4g}] and tag an integer in [0, {}], entries separated by ';'",
          index, item, lo.x, hi.x, lo.y, hi.y, cfg_.tags - 1));
    const auto l = surface_->locate(surface_->square_uv({static_cast<float>(v[0]), static_cast<float>(v[1])}));
    if (!l)
      throw InputError(fmt::format("algorithm 'vines': roots entry {} ({}, {}) lies outside the texture's charts",
                                   index, v[0], v[1]));
    out.emplace_back(*l, n == 3 ? static_cast<int>(v[2]) : static_cast<int>(out.size()) % cfg_.tags);
  }
  if (out.empty()) throw InputError("algorithm 'vines': roots names no root");
  return out;
}

void Vines::place_roots(const std::string& text, const vines::Mask* mask) {
  std::vector<std::pair<Location, int>> roots;
  auto tag_of = [&](std::size_t i) { return static_cast<int>(i % static_cast<std::size_t>(cfg_.tags)); };
  if (text == "random") {
    Rng rng(seed_, kStreamRoot);
    for (int tries = 0; roots.size() < static_cast<std::size_t>(cfg_.root_count) && tries < 100000; ++tries) {
      const glm::vec2 uv(static_cast<float>(rng.uniform()), static_cast<float>(rng.uniform()));
      const auto l = surface_->locate(uv);
      if (l && (!mask || mask->zone(surface_->mesh_uv(uv)) == cfg_.mask_include) && place(*l).on_scene)
        roots.emplace_back(*l, tag_of(roots.size()));
    }
  } else if (!text.empty()) {
    roots = parse_roots(text);
  } else if (mask && !mask->roots().empty()) {
    for (const glm::vec2& uv : mask->roots()) {
      const auto l = surface_->locate(surface_->square_uv(uv));
      if (!l)
        throw InputError(
            fmt::format("algorithm 'vines': mask={}: the green dot at UV ({:.4f}, {:.4f}) lies outside the "
                        "texture's charts",
                        mask_path_, uv.x, uv.y));
      roots.emplace_back(*l, tag_of(roots.size()));
    }
  } else {
    for (const Seed& s : scene_->seeds) {
      Location l;
      if (mesh_ != kNone) {
        l = surface_->closest(s.position);
      } else {  // a seed projects onto the canvas along the view
        const glm::vec3 d = s.position - canvas_.origin;
        const glm::vec2 uv(glm::dot(d, canvas_.u_axis) / glm::dot(canvas_.u_axis, canvas_.u_axis),
                           glm::dot(d, canvas_.v_axis) / glm::dot(canvas_.v_axis, canvas_.v_axis));
        l = surface_->locate(glm::clamp(uv, 0.0f, 1.0f)).value_or(Location{});
      }
      roots.emplace_back(l, tag_of(roots.size()));
    }
  }
  if (roots.empty())
    throw InputError(
        fmt::format("algorithm 'vines': no root grower could be placed on scene '{}' (give roots=u,v)", scene_->name));
  // Room for about one grower per attractor, so the arrays are not copied over and over as they grow.
  reserve_growers(roots.size() + alive_.size());
  for (const auto& [l, tag] : roots) add_grower(snapped(l), kNone, tag, {});
}

void Vines::reserve_growers(std::size_t n) {
  growers_.reserve(n);
  mpos_.reserve(n);
  for (auto* v : {&parent_, &first_child_, &next_sibling_, &last_child_, &kills_, &grid_next_}) v->reserve(n);
  tag_.reserve(n);
  for (auto* v : {&birth_, &shoot_, &piece_end_}) v->reserve(n);
  order_.reserve(n);
  pieces_.reserve(n);
}

std::int32_t Vines::add_grower(const Location& at, std::int32_t parent, int tag,
                               const std::vector<vines::UvPiece>& pieces) {
  const auto g = static_cast<std::int32_t>(growers_.size());
  growers_.push_back(at);
  mpos_.push_back(metric_position(at));
  parent_.push_back(parent);
  first_child_.push_back(kNone);
  next_sibling_.push_back(kNone);
  last_child_.push_back(kNone);
  tag_.push_back(static_cast<std::uint8_t>(tag));
  birth_.push_back(static_cast<std::uint32_t>(iteration_));
  int kills = 0;
  if (parent == kNone) {
    shoot_.push_back(next_shoot_++);
    order_.push_back(0);
  } else {
    const auto up = static_cast<std::size_t>(parent);
    const bool first = first_child_[up] == kNone;
    shoot_.push_back(first ? shoot_[up] : next_shoot_++);
    order_.push_back(static_cast<std::uint16_t>(first ? order_[up] : order_[up] + 1));
    (first ? first_child_[up] : next_sibling_[static_cast<std::size_t>(last_child_[up])]) = g;
    last_child_[up] = g;
    // The strand's next grower carries its count on, so a strand halts once it has killed kill_limit
    // attractors along its length; a side branch starts kill_limit_offset below its parent, so the growers
    // behind a halted tip branch into what it leaves (the README says why not above, as the caption reads).
    kills = first ? kills_[up] : kills_[up] - cfg_.kill_limit_offset;
    if (!first && cfg_.kill_limit_jitter > 0) {
      Rng rng(seed_, kStreamKills, static_cast<std::uint64_t>(g));
      const int span = 2 * cfg_.kill_limit_jitter + 1;
      kills += std::min(static_cast<int>(rng.uniform() * span), span - 1) - cfg_.kill_limit_jitter;
    }
  }
  kills_.push_back(std::max(0, kills));
  pieces_.insert(pieces_.end(), pieces.begin(), pieces.end());
  piece_end_.push_back(static_cast<std::uint32_t>(pieces_.size()));
  grid_next_.push_back(kNone);
  std::int32_t& head = growers_grid_->at(vines::CellTable::key(growers_grid_->cell_of(mpos_.back())));
  grid_next_.back() = head;
  head = g;
  return g;
}

// Whether a child at metric position m would only repeat what grower g already has: a child there, g
// itself, or g's parent (a grower chasing a wiggling attractor around a circle).
bool Vines::repeats(std::size_t g, const glm::vec3& m) const {
  const float lim2 = (kStallFraction * cfg_.step) * (kStallFraction * cfg_.step);
  auto near = [&](std::int32_t o) {
    return o != kNone &&
           glm::dot(mpos_[static_cast<std::size_t>(o)] - m, mpos_[static_cast<std::size_t>(o)] - m) < lim2;
  };
  if (near(static_cast<std::int32_t>(g)) || near(parent_[g])) return true;
  for (std::int32_t c = first_child_[g]; c != kNone; c = next_sibling_[static_cast<std::size_t>(c)])
    if (near(c)) return true;
  return false;
}

void Vines::child_of(std::size_t g, const glm::vec3& pull, Child& c) const {
  c.ok = false;
  const Location& from = growers_[g];
  auto in_uv = [&](const glm::vec2& a, const glm::vec2& b) {  // a straight step in UV, where it lands
    const auto l = surface_->locate(b);
    if (!l) return;  // off every chart: the seed's vines stop at chart borders
    c.ok = true;
    c.walk.end = *l;
    c.walk.seams = 0;
    c.walk.pieces.assign(1, {a, b});
  };
  const glm::vec2 a = surface_->uv(from);
  if (cfg_.grid_nodes) {  // a king's move to the neighbouring cell the pull points at most
    glm::vec2 d = cfg_.metric == Metric::Uv ? glm::vec2(pull) : surface_->to_uv(from.tri, surface_direction(pull));
    const float len = glm::length(d);
    if (!(len > 0.0f)) return;
    d /= len;
    const float res = static_cast<float>(cfg_.resolution), lean = 0.3827f;  // sin(22.5 deg)
    const glm::vec2 move(std::abs(d.x) > lean ? std::copysign(1.0f, d.x) : 0.0f,
                         std::abs(d.y) > lean ? std::copysign(1.0f, d.y) : 0.0f);
    in_uv(a, (glm::floor(a * res) + 0.5f + move) / res);
    return;
  }
  if (cfg_.metric == Metric::Uv) {
    const glm::vec2 d = glm::vec2(pull);
    if (glm::length(d) > 0.0f) in_uv(a, a + glm::normalize(d) * (cfg_.step / static_cast<float>(cfg_.resolution)));
    return;
  }
  surface_->walk(from, surface_direction(pull), cfg_.step * cell_m_, cfg_.cross_seams, c.walk);
  c.ok = c.walk.length >= 0.25f * cfg_.step * cell_m_;  // not when held at a border right away
}

void Vines::grow_children() {
  // Influenced growers in index order, each with its summed pull.
  std::vector<std::size_t> order(influenced_.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return influenced_[a] < influenced_[b]; });
  if (children_.size() < order.size()) children_.resize(order.size());  // never shrunk: its walks keep their memory
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 128), [&](const auto& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const std::size_t k = order[i];
      const glm::vec3 d = safe_normalize(pulls_[k]);
      children_[i].ok = false;
      if (glm::dot(d, d) > 0.0f) child_of(static_cast<std::size_t>(influenced_[k]), d, children_[i]);
    }
  });
  for (std::size_t i = 0; i < order.size(); ++i) {
    const Child& c = children_[i];
    const auto g = static_cast<std::size_t>(influenced_[order[i]]);
    if (!c.ok || repeats(g, metric_position(c.walk.end))) continue;
    seam_crossings_ += static_cast<std::size_t>(c.walk.seams);
    add_grower(c.walk.end, static_cast<std::int32_t>(g), tag_[g], c.walk.pieces);
  }
}

// Attractors within reach of the growers from `from` on become active: from now on they take part in
// every iteration. A resting attractor also learns here whether one of them is its nearest grower, so
// claim() need not search (growers are only ever added, and ties keep the older, lower-index grower).
void Vines::activate(std::size_t from) {
  const std::size_t n = growers_.size() - from;
  if (found_.size() < n) found_.resize(n);
  const float reach2 = reach_ * reach_;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 128), [&](const auto& r) {
    for (std::size_t k = r.begin(); k < r.end(); ++k) {
      const std::size_t g = from + k;
      auto& out = found_[k];
      out.clear();
      visit_cells(*attractor_cells_, mpos_[g], [&](std::int32_t cell) {
        const auto c = static_cast<std::size_t>(cell);
        for (std::uint32_t i = cell_start_[c]; i < cell_start_[c + 1]; ++i) {
          const CellEntry& e = cell_entries_[i];
          const glm::vec3 d = e.center - mpos_[g];
          const float d2 = glm::dot(d, d);
          if (d2 <= reach2 && ((e.tags >> tag_[g]) & 1u) && alive_[e.id]) out.emplace_back(e.id, d2);
        }
      });
    }
  });
  const float r2 = cfg_.influence * cfg_.influence;
  for (std::size_t k = 0; k < n; ++k) {
    const auto g = static_cast<std::int32_t>(from + k);
    const bool serves = !spent(from + k);
    for (const auto& [a, d2] : found_[k]) {
      if (!active_flag_[a]) {
        active_flag_[a] = 1;
        active_.push_back(a);
      }
      if (serves && d2 < r2 && (nearest_[a] == kNone || d2 < nearest_d2_[a])) {
        nearest_[a] = g;
        nearest_d2_[a] = d2;
      }
    }
  }
}

// ---------- the plant ----------

// Vine widths in cells: the plant's radii once it is finished; during growth (a frame's texture) the
// pipe model over the growers so far.
std::vector<float> Vines::widths_cells() const {
  std::vector<float> w(growers_.size());
  if (finished_) {
    const Plant& p = plant();
    for (std::size_t g = 0; g < w.size(); ++g) w[g] = 2.0f * p.nodes[g].radius / cell_m_;
    return w;
  }
  Plant skeleton;
  skeleton.nodes.resize(growers_.size());
  for (std::size_t g = 0; g < growers_.size(); ++g) skeleton.nodes[g].parent = parent_[g];
  assign_pipe_radii(skeleton, 0.5f * cfg_.tip_width, cfg_.pipe_exponent);
  for (std::size_t g = 0; g < w.size(); ++g) w[g] = std::min(2.0f * skeleton.nodes[g].radius, cfg_.max_width);
  return w;
}

// Growers in the seed's drawing order: depth first from each root, children in the order they grew.
std::vector<std::uint32_t> Vines::preorder() const {
  std::vector<std::uint32_t> out, stack;
  out.reserve(growers_.size());
  for (std::size_t r = 0; r < growers_.size(); ++r) {
    if (parent_[r] != kNone) continue;
    stack.push_back(static_cast<std::uint32_t>(r));
    while (!stack.empty()) {
      const std::uint32_t g = stack.back();
      stack.pop_back();
      out.push_back(g);
      const std::size_t mark = stack.size();
      for (std::int32_t c = first_child_[g]; c != kNone; c = next_sibling_[static_cast<std::size_t>(c)])
        stack.push_back(static_cast<std::uint32_t>(c));
      std::reverse(stack.begin() + static_cast<std::ptrdiff_t>(mark), stack.end());
    }
  }
  return out;
}

// The leaves, in drawing order: every leaf_interval-th grower, or the vines' ends. Each hangs along its
// segment's direction in UV, pulled toward -V by leaf_gravity, turned and scaled at random.
std::vector<Vines::Leaf> Vines::leaves() const {
  std::vector<Leaf> out;
  if (cfg_.leaves == Leaves::None || cfg_.leaf_size <= 0.0f) return out;
  const float deg = std::numbers::pi_v<float> / 180.0f, res = static_cast<float>(cfg_.resolution);
  int counter = 0;
  for (const std::uint32_t g : preorder()) {
    if (parent_[g] == kNone) continue;
    const bool pick = cfg_.leaves == Leaves::Ends ? first_child_[g] == kNone : ++counter % cfg_.leaf_interval == 0;
    if (!pick) continue;
    const vines::UvPiece& last = pieces_[piece_end_[g] - 1];
    glm::vec2 d = last.b - last.a;
    if (!(glm::length(d) > 0.0f)) continue;
    d = glm::normalize(glm::normalize(d) + cfg_.leaf_gravity * glm::vec2(0.0f, -1.0f) + glm::vec2(0.0f, -1e-6f));
    Rng rng(seed_, kStreamLeaf, g);
    const float turn = static_cast<float>(rng.uniform(-cfg_.leaf_angle_jitter, cfg_.leaf_angle_jitter)) * deg;
    const float scale = static_cast<float>(rng.uniform(cfg_.leaf_scale_min, cfg_.leaf_scale_max));
    const float bright = static_cast<float>(rng.uniform(cfg_.leaf_brightness_min, cfg_.leaf_brightness_max));
    d = rotate(d, turn);
    const float length = cfg_.leaf_size * scale / res * uv_scale(growers_[g].tri);
    out.push_back({g, {surface_->uv(growers_[g]), hang_angle(d), length, bright}, d, scale});
  }
  return out;
}

void Vines::build_plant() const {
  plant_stale_ = false;
  const std::size_t n = growers_.size(), from = finished_ ? 0 : plant_.nodes.size();
  plant_.nodes.resize(n);
  for (std::size_t g = from; g < n; ++g) {
    PlantNode& node = plant_.nodes[g];
    node.parent = parent_[g];
    node.order = order_[g];
    node.shoot = shoot_[g];
    node.birth_step = birth_[g];
    node.radius = 0.5f * cfg_.tip_width * cell_m_;
  }
  if (finished_) {  // the pipe model, capped
    assign_pipe_radii(plant_, 0.5f * cfg_.tip_width * cell_m_, cfg_.pipe_exponent);
    for (auto& node : plant_.nodes) node.radius = std::min(node.radius, 0.5f * cfg_.max_width * cell_m_);
  }
  // Nodes rest on the surface, lifted by their radius so their tubes stay outside the solid.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(from, n, 256), [&](const auto& r) {
    for (std::size_t g = r.begin(); g < r.end(); ++g)
      plant_.nodes[g].position = lifted(place(growers_[g]), plant_.nodes[g].radius);
  });
  // Per-node attributes: where each grower is in the texture, and its tag.
  plant_.node_attributes.assign(2, {});
  plant_.node_attributes[0] = {"uv", 2, std::vector<float>(2 * n)};
  plant_.node_attributes[1] = {"tag", 1, std::vector<float>(n)};
  for (std::size_t g = 0; g < n; ++g) {
    const glm::vec2 uv = surface_->uv(growers_[g]);
    plant_.node_attributes[0].values[2 * g] = uv.x;
    plant_.node_attributes[0].values[2 * g + 1] = uv.y;
    plant_.node_attributes[1].values[g] = tag_[g];
  }
  plant_.organs.clear();
  if (!finished_) return;
  // Leaves lie on the surface, their blades along their direction in the texture.
  for (const Leaf& leaf : leaves()) {
    const std::uint32_t g = leaf.grower;
    const glm::vec3 n3 = place(growers_[g]).normal;
    glm::vec3 blade = mesh_ != kNone ? surface_->uv_to_3d(growers_[g].tri, leaf.direction)
                                     : leaf.direction.x * canvas_.u_axis + leaf.direction.y * canvas_.v_axis;
    blade = safe_normalize(blade - glm::dot(blade, n3) * n3);
    if (glm::dot(blade, blade) == 0.0f) continue;
    Organ o;
    o.position = plant_.nodes[g].position;
    o.orientation = glm::quat_cast(glm::mat3(glm::cross(n3, blade), n3, blade));
    o.size = cfg_.leaf_size * leaf.scale * cell_m_;
    o.kind = OrganKind::Leaf;
    o.node = static_cast<std::int32_t>(g);
    plant_.organs.push_back(o);
  }
}

vines::DrawOptions Vines::draw_options() const {
  vines::DrawOptions o;
  o.size = cfg_.texture_size;
  o.style = cfg_.style;
  o.vine_colour = cfg_.vine_color;
  o.leaf_colour = cfg_.leaf_color;
  o.leaf_texture = leaf_texture_;
  o.stem_offset = cfg_.leaf_stem_offset;
  return o;
}

std::vector<OutputFile> Vines::write_outputs(const OutputRequest& r) const {
  // The vine in drawing order: each grower's pieces, widths from the pipe model.
  const std::vector<float> w = widths_cells();
  const float res = static_cast<float>(cfg_.resolution);
  std::vector<vines::Stroke> strokes;
  strokes.reserve(growers_.size());
  for (const std::uint32_t g : preorder()) {
    if (parent_[g] == kNone) continue;
    const auto p = static_cast<std::size_t>(parent_[g]);
    const float wa = w[p] / res * uv_scale(growers_[p].tri), wb = w[g] / res * uv_scale(growers_[g].tri);
    for (std::uint32_t k = g == 0 ? 0 : piece_end_[g - 1]; k < piece_end_[g]; ++k)
      strokes.push_back({pieces_[k].a, pieces_[k].b, wa, wb});
  }
  std::vector<vines::LeafStamp> stamps;
  for (const Leaf& l : leaves()) stamps.push_back(l.stamp);
  const vines::DrawOptions options = draw_options();
  const vines::Image texture = vines::draw_texture(strokes, stamps, options);
  const std::filesystem::path dir(r.dir);
  std::vector<OutputFile> out;
  auto png = [&](const std::string& name, const vines::Image& image) {
    out.push_back({r.prefix + name, vines::write_png((dir / (r.prefix + name)).string(), image)});
  };
  png("texture.png", texture);
  if (r.frame) return out;
  png("texture_normal.png", vines::normal_map(texture));
  // The skeleton alone: leaves would multiply a print figure's size for little it shows.
  const std::string svg = r.prefix + "skeleton.svg";
  out.push_back({svg, vines::write_svg((dir / svg).string(), strokes, {}, options)});
  return out;
}

}  // namespace

namespace vines {

// The influence radius: as given, or by default widened for exclusive tags, each of which sees only its
// share of the attractors, so that a vine reaches as many of its own as an untagged vine does (spacing
// grows as 1 / sqrt(density)). At the bare default, 4 exclusive tags stalled at resolution 128.
float influence_of(const Params& p) {
  const double given = p.real("influence");
  if (p.was_set("influence")) return static_cast<float>(given);
  const double tags = static_cast<double>(p.integer("tags")), mix = p.real("tag_mix");
  const double share = 1.0 / tags + mix * (1.0 - 1.0 / tags);
  return static_cast<float>(given / std::sqrt(share));
}

Config make_config(const Params& p) {
  const std::string& space = p.text("space");
  const std::string& leaves = p.text("leaves");
  // Designated initializers: a member left out is a warning (-Wmissing-field-initializers), an error in CI.
  return {
      .space = space == "uv"       ? Space::Uv
               : space == "canvas" ? Space::Canvas
                                   : Space::Auto,
      .resolution = static_cast<int>(p.integer("resolution")),
      .density = static_cast<float>(p.real("density")),
      .grid_nodes = p.text("nodes") == "grid",
      .metric = p.text("metric") == "uv" ? Metric::Uv : Metric::Surface,
      .cross_seams = p.text("seams") == "cross",
      .influence = influence_of(p),
      .kill = static_cast<float>(p.real("kill")),
      .step = static_cast<float>(p.real("step")),
      .stall_iterations = static_cast<int>(p.integer("stall_iterations")),
      .root_count = static_cast<int>(p.integer("root_count")),
      .mask_include = p.text("mask_mode") == "include",
      .tags = static_cast<int>(p.integer("tags")),
      .tag_mix = static_cast<float>(p.real("tag_mix")),
      .wiggle = static_cast<float>(p.real("wiggle")),
      .wiggle_period = static_cast<float>(p.real("wiggle_period")),
      .kill_limit = static_cast<int>(p.integer("kill_limit")),
      .kill_limit_offset = static_cast<int>(p.integer("kill_limit_offset")),
      .kill_limit_jitter = static_cast<int>(p.integer("kill_limit_jitter")),
      .tip_width = static_cast<float>(p.real("tip_width")),
      .max_width = static_cast<float>(p.real("max_width")),
      .pipe_exponent = static_cast<float>(p.real("pipe_exponent")),
      .leaves = leaves == "none"   ? Leaves::None
                : leaves == "ends" ? Leaves::Ends
                                   : Leaves::Interval,
      .leaf_interval = static_cast<int>(p.integer("leaf_interval")),
      .leaf_size = static_cast<float>(p.real("leaf_size")),
      .leaf_gravity = static_cast<float>(p.real("leaf_gravity")),
      .leaf_angle_jitter = static_cast<float>(p.real("leaf_angle_jitter")),
      .leaf_scale_min = static_cast<float>(p.real("leaf_scale_min")),
      .leaf_scale_max = static_cast<float>(p.real("leaf_scale_max")),
      .leaf_brightness_min = static_cast<float>(p.real("leaf_brightness_min")),
      .leaf_brightness_max = static_cast<float>(p.real("leaf_brightness_max")),
      .leaf_stem_offset = static_cast<float>(p.real("leaf_stem_offset")),
      .texture_size = static_cast<int>(p.integer("texture_size")),
      .style = p.text("style") == "dots" ? Style::Dots : Style::Lines,
      .vine_color = glm::vec3(p.vec3("vine_color")),
      .leaf_color = glm::vec3(p.vec3("leaf_color")),
  };
}

}  // namespace vines

GROWBENCH_REGISTER_ALGORITHM(vines, Vines, kInfo, vines::Config)

}  // namespace growbench
