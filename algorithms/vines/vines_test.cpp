// The vines: the surface they walk on (UV lookup, walks across edges and seams), masks, tags, kill
// limits, wiggle, seams and UV distortion, the texture they draw, determinism and bad input.
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <stb_image.h>
#include <tbb/global_control.h>
#include <stb_image_write.h>

#include "algorithms/algorithm.hpp"
#include "algorithms/vines/mask.hpp"
#include "algorithms/vines/surface.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

namespace fs = std::filesystem;
using vines::Location;
using vines::Surface;

// ---------- helpers ----------

struct Grown {
  Plant plant;
  std::map<std::string, double> stats;
  fs::path dir;  // texture.png and the rest, when asked for
  std::vector<std::string> warnings = {};
  double influence = 0.0;  // the radius grown with (effective_params)
};

Grown grow_vines(const Scene& scene, const SceneQuery& query, const std::vector<std::string>& sets, int threads = 0,
                 const std::string& out = "") {
  std::unique_ptr<tbb::global_control> gc;
  if (threads > 0)
    gc = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               static_cast<std::size_t>(threads));
  const AlgorithmEntry& e = find_algorithm("vines");
  Params p = default_params(e);
  for (const auto& s : sets) p.set_assignment(s);
  auto algo = e.make();
  algo->start(scene, query, p, 1);
  for (int i = 0; i < 20000 && algo->step(); ++i) {
  }
  algo->finish();
  Grown g{algo->plant(), {}, {}, algo->warnings(), algo->effective_params().value_or(p).real("influence")};
  for (const auto& [k, v] : algo->stats()) g.stats[k] = v;
  if (!out.empty()) {
    g.dir = test::temp_dir(out);
    (void)algo->write_outputs({g.dir.string(), "", false});
  }
  return g;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

glm::vec2 uv_of(const Plant& p, std::size_t i) {
  return {p.node_attributes[0].values[2 * i], p.node_attributes[0].values[2 * i + 1]};
}
int tag_of(const Plant& p, std::size_t i) {
  return static_cast<int>(p.node_attributes[1].values[i]);
}

struct Rgba {
  int w = 0, h = 0;
  std::vector<unsigned char> px;
  [[nodiscard]] int alpha(int x, int y) const { return px[4 * (static_cast<std::size_t>(y) * w + x) + 3]; }
  // The pixel holding uv (v up: row 0 is v = 1).
  [[nodiscard]] int alpha_at(const glm::vec2& uv) const {
    const int x = std::clamp(static_cast<int>(uv.x * static_cast<float>(w)), 0, w - 1);
    const int y = std::clamp(static_cast<int>((1.0f - uv.y) * static_cast<float>(h)), 0, h - 1);
    return alpha(x, y);
  }
};

Rgba read_png(const fs::path& path) {
  Rgba r;
  int n = 0;
  unsigned char* d = stbi_load(path.string().c_str(), &r.w, &r.h, &n, 4);
  EXPECT_NE(d, nullptr) << path;
  if (d) r.px.assign(d, d + static_cast<std::size_t>(r.w) * r.h * 4);
  stbi_image_free(d);
  return r;
}

// A PNG of w x h pixels coloured by f(x, y) -> RGBA (row 0 at the top).
template <class F>
std::string write_mask(const fs::path& path, int w, int h, F f) {
  std::vector<unsigned char> px(static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::array<unsigned char, 4> c = f(x, y);
      std::copy(c.begin(), c.end(), px.begin() + 4 * (static_cast<std::ptrdiff_t>(y) * w + x));
    }
  EXPECT_NE(stbi_write_png(path.string().c_str(), w, h, 4, px.data(), w * 4), 0);
  return path.string();
}
constexpr std::array<unsigned char, 4> kRed{230, 20, 20, 255}, kGreen{20, 230, 20, 255}, kWhite{255, 255, 255, 255};

const Scene& wall() {
  static const Scene s = load_scene("wall");
  return s;
}
const SceneQuery& wall_query() {
  static const SceneQuery q(wall());
  return q;
}
const Scene& cube() {
  static const Scene s = load_scene("mesh:uv-cube");
  return s;
}
const SceneQuery& cube_query() {
  static const SceneQuery q(cube());
  return q;
}

// ---------- the surface ----------

// The cube as its OBJ has it (side 2, centred): the front is z = 1, the top y = 1.
Surface raw_cube() {
  return Surface(load_obj(mesh_path("uv-cube")));
}

TEST(VinesSurface, LocatesUvPointsOnTheCubesFaces) {
  const Surface s = raw_cube();
  EXPECT_EQ(s.chart_count(), 1u);
  const auto front = s.locate({0.5f, 0.375f});  // the middle of the strip's second square
  ASSERT_TRUE(front);
  const glm::vec3 p = s.position(*front);
  EXPECT_NEAR(p.x, 0.0f, 1e-5f);
  EXPECT_NEAR(p.y, 0.0f, 1e-5f);
  EXPECT_NEAR(p.z, 1.0f, 1e-5f);
  EXPECT_FALSE(s.locate({0.05f, 0.05f})) << "outside the cross";
  const auto corner = s.locate({0.625f, 1.0f});  // the layout's top-right corner lies on the last cells' edge
  ASSERT_TRUE(corner);
  EXPECT_NEAR(glm::length(s.position(*corner) - glm::vec3(1, -1, -1)), 0.0f, 1e-5f);
  // Every face is as large on the surface (4) as in UV (1/16): the ratio is 64 everywhere.
  EXPECT_NEAR(s.mean_area_ratio(), 64.0, 1e-6);
}

TEST(VinesSurface, WalksAcrossAnEdgeInsideTheChart) {
  const Surface s = raw_cube();
  const auto from = s.locate({0.5f, 0.375f});
  ASSERT_TRUE(from);
  const vines::Walk w = s.walk(*from, {0, 1, 0}, 1.5f, true);  // up the front, over the edge onto the top
  EXPECT_FALSE(w.stopped);
  EXPECT_NEAR(w.length, 1.5f, 1e-5f);
  EXPECT_NEAR(glm::length(s.position(w.end) - glm::vec3(0, 1, 0.5f)), 0.0f, 1e-4f);
  EXPECT_EQ(w.seams, 0);
  ASSERT_EQ(w.pieces.size(), 1u) << "front and top touch in UV: one piece";
  EXPECT_NEAR(glm::length(w.pieces[0].b - glm::vec2(0.5f, 0.5f + 0.0625f)), 0.0f, 1e-5f);
}

TEST(VinesSurface, WalksAcrossASeamOntoTheOtherChartOrStopsThere) {
  const Surface s = raw_cube();
  const auto top = s.locate({0.5f, 0.625f});  // the top's centre (0, 1, 0)
  ASSERT_TRUE(top);
  EXPECT_NEAR(glm::length(s.position(*top) - glm::vec3(0, 1, 0)), 0.0f, 1e-5f);
  // Toward -X the top meets the left face along a seam: the left face lies elsewhere in UV.
  const vines::Walk w = s.walk(*top, {-1, 0, 0}, 1.5f, true);
  EXPECT_FALSE(w.stopped);
  EXPECT_EQ(w.seams, 1);
  EXPECT_NEAR(glm::length(s.position(w.end) - glm::vec3(-1, 0.5f, 0)), 0.0f, 1e-4f) << "down the left face";
  ASSERT_EQ(w.pieces.size(), 2u);
  // The two pieces meet at one 3D point, (-1, 1, 0), seen from each chart.
  const auto a = s.locate(w.pieces[0].b), b = s.locate(w.pieces[1].a);
  ASSERT_TRUE(a && b);
  EXPECT_NEAR(glm::length(s.position(*a) - glm::vec3(-1, 1, 0)), 0.0f, 1e-4f);
  EXPECT_NEAR(glm::length(s.position(*b) - glm::vec3(-1, 1, 0)), 0.0f, 1e-4f);
  EXPECT_GT(glm::length(w.pieces[0].b - w.pieces[1].a), 0.1f) << "far apart in UV";
  const vines::Walk held = s.walk(*top, {-1, 0, 0}, 1.5f, false);
  EXPECT_TRUE(held.stopped);
  EXPECT_NEAR(held.length, 1.0f, 1e-5f);
  EXPECT_EQ(held.pieces.size(), 1u);
}

// ---------- masks ----------

TEST(VinesMask, ReadsRedZonesAndGreenDotsTopRowFirst) {
  const fs::path d = test::temp_dir("vines_mask");
  // Red top half, a 2x2 green dot at pixels (4..5, 12..13), white elsewhere.
  const std::string path = write_mask(d / "m.png", 16, 16, [](int x, int y) {
    if (x >= 4 && x <= 5 && y >= 12 && y <= 13) return kGreen;
    return y < 8 ? kRed : kWhite;
  });
  const vines::Mask m = vines::Mask::read(path, "mask");
  EXPECT_TRUE(m.zone({0.5f, 0.9f})) << "the image's top row is v = 1";
  EXPECT_FALSE(m.zone({0.5f, 0.1f}));
  EXPECT_EQ(m.zone_pixels(), 128u);
  ASSERT_EQ(m.roots().size(), 1u);
  EXPECT_FLOAT_EQ(m.roots()[0].x, 5.0f / 16.0f);
  EXPECT_FLOAT_EQ(m.roots()[0].y, 1.0f - 13.0f / 16.0f);
}

TEST(VinesMask, BadFilesAreInputErrorsNamingTheKey) {
  const fs::path d = test::temp_dir("vines_mask_bad");
  EXPECT_NE(test::error_of([&] { vines::Mask::read((d / "none.png").string(), "mask"); }).find("mask="),
            std::string::npos);
  const std::string text = test::write_text(d / "not.png", "hello");
  const std::string e = test::error_of([&] { vines::Mask::read(text, "mask"); });
  EXPECT_NE(e.find("not a readable image"), std::string::npos) << e;
}

// Distance in pixels from texture pixel (x, y) to the nearest red pixel of a mask scaled to the texture
// (a window of +-limit pixels is searched; limit + 1 when none is that near).
float distance_to_zone(const vines::Mask& m, int size, int x, int y, int limit, bool red) {
  float best = static_cast<float>(limit + 1);
  for (int dy = -limit; dy <= limit; ++dy)
    for (int dx = -limit; dx <= limit; ++dx) {
      const int qx = x + dx, qy = y + dy;
      if (qx < 0 || qy < 0 || qx >= size || qy >= size) continue;
      const glm::vec2 uv((qx + 0.5f) / size, 1.0f - (qy + 0.5f) / size);
      if (m.zone(uv) == red) best = std::min(best, std::sqrt(static_cast<float>(dx * dx + dy * dy)));
    }
  return best;
}

// Grows on the wall's canvas with a mask and checks every vine pixel against the zone: within the red
// zone (include) or outside it (exclude), to within the widest stroke.
void check_mask(const std::string& mode) {
  const fs::path d = test::temp_dir("vines_mask_" + mode);
  // A red ring (a letter-like shape, concave) with a green dot on it.
  const std::string path = write_mask(d / "m.png", 64, 64, [](int x, int y) {
    const float r = std::hypot(x + 0.5f - 32.0f, y + 0.5f - 32.0f);
    if (std::abs(x - 32) <= 1 && std::abs(y - 52) <= 1) return kGreen;
    return r > 14.0f && r < 24.0f ? kRed : kWhite;
  });
  const vines::Mask mask = vines::Mask::read(path, "mask");
  const int size = 256;
  const Grown g = grow_vines(wall(), wall_query(),
                             {"space=canvas", "resolution=64", "texture_size=256", "leaves=none", "max_width=1.5",
                              "mask=" + path, "mask_mode=" + mode},
                             0, "vines_mask_out_" + mode);
  ASSERT_GT(g.plant.nodes.size(), 100u);
  const Rgba t = read_png(g.dir / "texture.png");
  ASSERT_EQ(t.w, size);
  const int tolerance = static_cast<int>(std::ceil(1.5f * size / 64.0f));  // the widest stroke, in pixels
  std::size_t vine = 0, off = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      if (t.alpha(x, y) == 0) continue;
      ++vine;
      if (distance_to_zone(mask, size, x, y, tolerance, mode == "include") > static_cast<float>(tolerance)) ++off;
    }
  EXPECT_GT(vine, 1000u);
  EXPECT_EQ(off, 0u) << off << " of " << vine << " vine pixels lie beyond the stroke width from where the mask "
                     << (mode == "include" ? "includes" : "excludes");
  if (mode == "include") {  // the one root sits on the green dot
    std::size_t roots = 0;
    for (std::size_t i = 0; i < g.plant.nodes.size(); ++i) {
      if (g.plant.nodes[i].parent != kNoParent) continue;
      ++roots;
      EXPECT_NEAR(uv_of(g.plant, i).x, 32.5f / 64.0f, 1e-5f);
      EXPECT_NEAR(uv_of(g.plant, i).y, 1.0f - 52.5f / 64.0f, 1e-5f);
    }
    EXPECT_EQ(roots, 1u);
  }
}

// The harness calls load_inputs in its scene_load phase: the mask is decoded there, so growth does not
// time it. start() then uses the decoded mask: here its file is gone by then, and the vine is the one
// grown from the file.
TEST(Vines, TheMaskIsDecodedWithTheInputsNotInGrowth) {
  const fs::path d = test::temp_dir("vines_mask_inputs");
  const std::string path = write_mask(d / "m.png", 32, 32, [](int x, int) { return x < 16 ? kRed : kWhite; });
  const std::vector<std::string> sets = {"space=canvas", "resolution=48", "mask=" + path};
  const std::string hash = grow_vines(wall(), wall_query(), sets).plant.geometry_hash();
  const AlgorithmEntry& e = find_algorithm("vines");
  Params p = default_params(e);
  for (const auto& s : sets) p.set_assignment(s);
  auto algo = e.make();
  algo->load_inputs(p);
  fs::remove(path);
  algo->start(wall(), wall_query(), p, 1);
  for (int i = 0; i < 20000 && algo->step(); ++i) {
  }
  algo->finish();
  EXPECT_EQ(algo->plant().geometry_hash(), hash);
  // Without load_inputs, start() reads the file itself, and names it when it is missing.
  auto again = e.make();
  EXPECT_THROW(again->start(wall(), wall_query(), p, 1), InputError);
}

TEST(Vines, AnInclusionMaskKeepsTheVinesInsideItsRedZone) {
  check_mask("include");
}

TEST(Vines, AnExclusionMaskKeepsTheVinesOutOfItsRedZone) {
  check_mask("exclude");
}

// ---------- tags ----------

// The share of tag-0 growers with a tag-1 grower within `cells` cells in UV.
double overlap(const Plant& p, int resolution, float cells) {
  std::vector<glm::vec2> a, b;
  for (std::size_t i = 0; i < p.nodes.size(); ++i) (tag_of(p, i) == 0 ? a : b).push_back(uv_of(p, i));
  const float r = cells / static_cast<float>(resolution);
  std::size_t near = 0;
  for (const auto& x : a)
    for (const auto& y : b)
      if (glm::length(x - y) < r) {
        ++near;
        break;
      }
  return a.empty() ? 0.0 : static_cast<double>(near) / static_cast<double>(a.size());
}

TEST(Vines, TagsLetVinesOverlapOrBorderEachOther) {
  const std::vector<std::string> base = {"space=canvas", "resolution=64", "roots=0.3,0.5,0;0.7,0.5,1", "tags=2"};
  auto with = [&](const std::string& mix) {
    auto sets = base;
    sets.push_back("tag_mix=" + mix);
    return grow_vines(wall(), wall_query(), sets).plant;
  };
  const double exclusive = overlap(with("0"), 64, 1.5f), shared = overlap(with("1"), 64, 1.5f),
               mixed = overlap(with("0.5"), 64, 1.5f);
  // Exclusive attractors: each vine covers the whole canvas, through the other. Shared ones: the vines
  // compete and meet along a border.
  EXPECT_GT(exclusive, 0.5) << "exclusive attractors: overlap";
  EXPECT_LT(shared, 0.1) << "shared attractors: a border";
  EXPECT_GT(mixed, shared);
  EXPECT_LT(mixed, exclusive);
}

// Four exclusive tags give each vine a quarter of the attractors, twice as far apart: at the bare default
// influence (4 cells) the vines stalled at once (95 nodes, 5,384 of 5,424 attractors left). Left at its
// default, the radius is now 4 / sqrt(1/4); given, it is kept. A tag without a root is warned of.
TEST(Vines, ExclusiveTagsWidenTheDefaultInfluenceAndARootlessTagIsWarnedOf) {
  const std::vector<std::string> four = {"space=canvas", "resolution=128", "tags=4",
                                         "roots=0.05,0.05,0;0.95,0.05,1;0.05,0.95,2;0.95,0.95,3"};
  const Grown g = grow_vines(wall(), wall_query(), four);
  EXPECT_EQ(g.influence, 8.0);
  EXPECT_LT(g.stats.at("attractors_left"), 0.05 * g.stats.at("attractors"));
  EXPECT_TRUE(g.warnings.empty());
  auto given = four;
  given.push_back("influence=4");
  EXPECT_EQ(grow_vines(wall(), wall_query(), given).influence, 4.0);
  auto mixed = four;
  mixed.push_back("tag_mix=1");  // every vine may take every attractor: no widening
  EXPECT_EQ(grow_vines(wall(), wall_query(), mixed).influence, 4.0);
  const Grown rootless =
      grow_vines(wall(), wall_query(), {"space=canvas", "resolution=32", "tags=4", "roots=0.1,0.1,0;0.9,0.1,2"});
  ASSERT_EQ(rootless.warnings.size(), 1u);
  const double n = rootless.stats.at("attractors");
  const std::string& w = rootless.warnings[0];
  const std::string head = "tags=4 but 2 roots carry only 2 of them: no root carries tag 1, 3, so ";
  ASSERT_TRUE(w.starts_with(head)) << w;
  // Exclusive tags: about half of the attractors are tag 1's or 3's, and none of them is ever taken.
  const double unreachable = std::stod(w.substr(head.size()));
  EXPECT_GT(unreachable, 0.4 * n);
  EXPECT_LT(unreachable, 0.6 * n);
  EXPECT_GE(rootless.stats.at("attractors_left"), unreachable);
  EXPECT_NE(w.find(fmt::format("of the {} attractors (those only those tags may take)", n)), std::string::npos) << w;
}

// ---------- kill limits and wiggle ----------

std::size_t tips(const Plant& p) {
  std::vector<std::uint8_t> has_child(p.nodes.size(), 0);
  for (const auto& n : p.nodes)
    if (n.parent != kNoParent) has_child[static_cast<std::size_t>(n.parent)] = 1;
  std::size_t t = 0;
  for (std::size_t i = 0; i < p.nodes.size(); ++i) t += p.nodes[i].parent != kNoParent && !has_child[i] ? 1 : 0;
  return t;
}

// The mean turn, in radians, between a segment and its parent's (in UV).
double curl(const Plant& p) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < p.nodes.size(); ++i) {
    const std::int32_t a = p.nodes[i].parent;
    if (a == kNoParent || p.nodes[static_cast<std::size_t>(a)].parent == kNoParent) continue;
    const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(p.nodes[ua].parent);
    const glm::vec2 d1 = uv_of(p, ua) - uv_of(p, ub), d2 = uv_of(p, i) - uv_of(p, ua);
    if (glm::length(d1) == 0.0f || glm::length(d2) == 0.0f) continue;
    sum += std::acos(std::clamp(glm::dot(glm::normalize(d1), glm::normalize(d2)), -1.0f, 1.0f));
    ++n;
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

// At Figure 4's settings (resolution 164, limit 20, offset 3) the vine covers the canvas and branches more
// than without a limit. When every child added the offset, each strand halted after 20 / 3 steps: 31
// nodes, with 8,909 of 8,931 attractors left.
TEST(Vines, AKillLimitHaltsLongStrandsAndTheVineBranchesMore) {
  const std::vector<std::string> base = {"space=canvas", "resolution=164", "roots=0.05,0.05"};
  auto with = [&](const std::string& limit) {
    auto sets = base;
    sets.push_back("kill_limit=" + limit);
    return grow_vines(wall(), wall_query(), sets);
  };
  const Grown free = with("0"), limited = with("20");
  EXPECT_EQ(free.stats.at("growers_stopped_by_kill_limit"), 0.0);
  EXPECT_GT(limited.stats.at("growers_stopped_by_kill_limit"), 100.0);
  EXPECT_LT(limited.stats.at("attractors_left"), 0.1 * limited.stats.at("attractors"));
  EXPECT_GT(limited.plant.nodes.size(), free.plant.nodes.size() / 2);
  // Halted strands, and branches from the growers behind them: more tips per metre of vine.
  const double free_branching = static_cast<double>(tips(free.plant)) / free.plant.total_length();
  const double limited_branching = static_cast<double>(tips(limited.plant)) / limited.plant.total_length();
  EXPECT_GT(limited_branching, 1.3 * free_branching) << free_branching << " " << limited_branching;
}

TEST(Vines, WigglingAttractorsCurlTheVines) {
  const std::vector<std::string> base = {"space=canvas", "resolution=64"};
  auto with = [&](const std::string& wiggle) {
    auto sets = base;
    sets.push_back("wiggle=" + wiggle);
    return grow_vines(wall(), wall_query(), sets).plant;
  };
  const double still = curl(with("0")), wiggling = curl(with("2"));
  EXPECT_GT(wiggling, 1.5 * still) << "mean turn per segment: " << still << " still, " << wiggling << " wiggling";
}

// ---------- seams and distortion ----------

// The cube's faces (its OBJ's quads, two triangles each) and the pairs that meet along a UV seam.
int face_of(const Surface& s, const glm::vec2& uv) {
  const auto l = s.locate(uv);
  return l ? static_cast<int>(l->tri / 2) : -1;
}
const std::set<std::pair<int, int>> kCubeSeams = {  // faces: bottom 0, front 1, top 2, back 3, left 4, right 5
    {0, 3}, {0, 4}, {0, 5}, {2, 4}, {2, 5}, {3, 4}, {3, 5}};

TEST(Vines, OnACubeTheVinesRunOnAcrossEverySeamTheyReach) {
  const Surface s(cube().meshes[0]);
  const std::vector<std::string> sets = {"space=uv", "resolution=64"};
  const Grown g = grow_vines(cube(), cube_query(), sets);
  const double step_m = g.stats.at("cell_m");  // step = 1 cell
  std::set<std::pair<int, int>> crossed;
  std::size_t segments = 0;
  for (std::size_t i = 0; i < g.plant.nodes.size(); ++i) {
    const std::int32_t p = g.plant.nodes[i].parent;
    if (p == kNoParent) continue;
    ++segments;
    const glm::vec2 a = uv_of(g.plant, static_cast<std::size_t>(p)), b = uv_of(g.plant, i);
    const int fa = face_of(s, a), fb = face_of(s, b);
    if (fa != fb) crossed.insert({std::min(fa, fb), std::max(fa, fb)});
    // Continuous in 3D: each child one step from its parent along the surface (a chord over an edge is
    // at least cos 45 degrees of it), never a jump to the far side of the texture.
    const double chord = glm::length(s.position(*s.locate(b)) - s.position(*s.locate(a)));
    EXPECT_LE(chord, 1.001 * step_m) << "segment " << i;
    EXPECT_GE(chord, 0.7 * step_m) << "segment " << i;
  }
  EXPECT_GT(segments, 400u);
  for (const auto& seam : kCubeSeams)
    EXPECT_TRUE(crossed.count(seam)) << "no vine crossed the seam between faces " << seam.first << " and "
                                     << seam.second;
  EXPECT_GT(g.stats.at("seam_crossings"), 0.0);
  // The seed's behaviour: vines stop at the seams.
  const Grown held = grow_vines(cube(), cube_query(), {"space=uv", "resolution=64", "seams=stop"});
  EXPECT_EQ(held.stats.at("seam_crossings"), 0.0);
  for (std::size_t i = 0; i < held.plant.nodes.size(); ++i) {
    const std::int32_t p = held.plant.nodes[i].parent;
    if (p == kNoParent) continue;
    const int fa = face_of(s, uv_of(held.plant, static_cast<std::size_t>(p))), fb = face_of(s, uv_of(held.plant, i));
    EXPECT_FALSE(kCubeSeams.count({std::min(fa, fb), std::max(fa, fb)})) << "segment " << i << " crossed a seam";
  }
}

TEST(Vines, OnSpotTheTextureLinesUpAcrossTheSeams) {
  const Scene scene = load_scene("mesh:spot");
  const SceneQuery query(scene);
  const Surface s(scene.meshes[0]);
  ASSERT_GT(s.chart_count(), 1u) << "spot's texture has several charts";
  const Grown g = grow_vines(scene, query, {"space=uv", "resolution=128", "texture_size=1024", "leaves=none"}, 0,
                             "vines_spot_seams");
  const Rgba t = read_png(g.dir / "texture.png");
  std::size_t seam_segments = 0, samples = 0, bare = 0;
  for (std::size_t i = 0; i < g.plant.nodes.size(); ++i) {
    const std::int32_t p = g.plant.nodes[i].parent;
    if (p == kNoParent) continue;
    const auto la = s.locate(uv_of(g.plant, static_cast<std::size_t>(p))), lb = s.locate(uv_of(g.plant, i));
    ASSERT_TRUE(la && lb);
    if (s.chart(la->tri) == s.chart(lb->tri)) continue;
    ++seam_segments;
    // Along the segment on the surface, the texture as the mesh wears it shows the vine, on both sides.
    const glm::vec3 a = s.position(*la), b = s.position(*lb);
    for (int k = 0; k <= 8; ++k) {
      const Location at = s.closest(glm::mix(a, b, static_cast<float>(k) / 8.0f));
      ++samples;
      if (t.alpha_at(s.uv(at)) == 0) {
        ++bare;
        ADD_FAILURE() << "segment " << i << " sample " << k << " uv " << s.uv(at).x << "," << s.uv(at).y << " from uv "
                      << uv_of(g.plant, static_cast<std::size_t>(p)).x << ","
                      << uv_of(g.plant, static_cast<std::size_t>(p)).y << " to " << uv_of(g.plant, i).x << ","
                      << uv_of(g.plant, i).y << " dist3 " << glm::length(s.position(at) - glm::mix(a, b, k / 8.0f));
      }
    }
  }
  EXPECT_GT(seam_segments, 20u);
  EXPECT_EQ(bare, 0u) << bare << " of " << samples << " points along seam-crossing segments show no vine";
}

// Two unit squares side by side; the left one takes a quarter of the UV area the right one does.
Scene two_scales() {
  TriangleMesh m;
  m.name = "two-scales";
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {2, 1, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}};
  m.uvs = {{0, 0}, {0.25f, 0}, {0.25f, 0.25f}, {0, 0.25f}, {0.5f, 0}, {1, 0}, {1, 0.5f}, {0.5f, 0.5f}};
  m.uv_triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  Scene s = test::scene_with(m);
  s.seeds = {{{0.5f, 0.5f, 0.0f}, {0, 1, 0}, 0}, {{1.5f, 0.5f, 0.0f}, {0, 1, 0}, 0}};
  return s;
}

// Mean 3D segment length and node count per unit of area, on the left and right squares.
std::pair<std::array<double, 2>, std::array<double, 2>> per_side(const Plant& p) {
  std::array<double, 2> length{0, 0}, count{0, 0};
  std::array<double, 2> segs{0, 0};
  for (const auto& n : p.nodes) {
    const int side = n.position.x < 1.0f ? 0 : 1;
    count[side] += 1;
    if (n.parent == kNoParent) continue;
    length[side] += glm::length(n.position - p.nodes[static_cast<std::size_t>(n.parent)].position);
    segs[side] += 1;
  }
  return {{length[0] / segs[0], length[1] / segs[1]}, count};
}

TEST(Vines, MeasuredOnTheSurfaceAChartsUvScaleDoesNotChangeTheVine) {
  const Scene scene = two_scales();
  const SceneQuery query(scene);
  const std::vector<std::string> sets = {"space=uv", "resolution=128", "tip_width=0.05", "max_width=0.05"};
  auto surface_sets = sets;
  surface_sets.push_back("metric=surface");
  const auto [len, count] = per_side(grow_vines(scene, query, surface_sets).plant);
  EXPECT_NEAR(len[0] / len[1], 1.0, 0.05) << "steps as long on both squares";
  EXPECT_NEAR(count[0] / count[1], 1.0, 0.25) << "as many growers per area on both";
  auto uv_sets = sets;
  uv_sets.push_back("metric=uv");
  const auto [uv_len, uv_count] = per_side(grow_vines(scene, query, uv_sets).plant);
  EXPECT_NEAR(uv_len[0] / uv_len[1], 2.0, 0.1) << "measured in UV, the squeezed chart's steps are twice as long";
  EXPECT_LT(uv_count[0] / uv_count[1], 0.5);
}

// Texture coordinates beyond the unit square (a tiled or UDIM-like layout, here tripled and moved to
// u in [1, 4], v in [-2, 1]) are fitted into it: the vine grows as it does on the same layout inside the
// unit square, the decal spans the layout's square, and a warning says so.
TEST(Vines, ALayoutBeyondTheUnitSquareIsFittedIntoIt) {
  Scene moved = cube();
  for (glm::vec2& uv : moved.meshes[0].uvs) uv = 3.0f * uv + glm::vec2(1.0f, -2.0f);
  const SceneQuery query(moved);
  const std::vector<std::string> sets = {"space=uv", "resolution=64"};
  const Grown inside = grow_vines(cube(), cube_query(), sets);
  const Grown beyond = grow_vines(moved, query, sets);
  glm::vec2 lo(1e9f), hi(-1e9f);
  for (const glm::vec2& uv : cube().meshes[0].uvs) {
    lo = glm::min(lo, uv);
    hi = glm::max(hi, uv);
  }
  ASSERT_EQ(beyond.plant.decals.size(), 1u);
  const SurfaceDecal& d = beyond.plant.decals[0];
  EXPECT_NEAR(d.origin.x, 3.0f * lo.x + 1.0f, 1e-5f);
  EXPECT_NEAR(d.origin.y, 3.0f * lo.y - 2.0f, 1e-5f);
  EXPECT_NEAR(d.u_axis.x, 3.0f * std::max(hi.x - lo.x, hi.y - lo.y), 1e-5f);
  EXPECT_EQ(d.u_axis.x, d.v_axis.y);
  EXPECT_EQ(inside.plant.decals[0].u_axis, glm::vec3(0.0f)) << "inside the unit square the decal is as before";
  // The cube's own layout fills the unit square, so the fitted one is the same up to rounding.
  ASSERT_GT(inside.plant.nodes.size(), 400u);
  EXPECT_NEAR(static_cast<double>(beyond.plant.nodes.size()) / static_cast<double>(inside.plant.nodes.size()), 1.0,
              0.05);
  ASSERT_EQ(beyond.warnings.size(), 1u);
  EXPECT_NE(beyond.warnings[0].find("scene mesh '" + moved.meshes[0].name + "' has texture coordinates beyond"),
            std::string::npos)
      << beyond.warnings[0];
  EXPECT_TRUE(inside.warnings.empty());
}

// spot's layout reaches a little past the unit square, so it is fitted; its body mask, painted over the
// mesh's own unit square, still lines up: each root sits at one of the mask's green dots in the mesh's
// coordinates.
TEST(Vines, AMaskIsPaintedInTheMeshsOwnCoordinatesWhenTheLayoutIsFitted) {
  const Scene scene = load_scene("mesh:spot");
  const SceneQuery query(scene);
  const Surface s(scene.meshes[0]);
  ASSERT_TRUE(s.uv_fitted());
  const std::string mask = std::string(GROWBENCH_SOURCE_DIR) + "/algorithms/vines/examples/spot-body.png";
  const Grown g = grow_vines(scene, query, {"space=uv", "resolution=96", "mask=" + mask});
  ASSERT_GT(g.plant.nodes.size(), 100u);
  const vines::Mask m = vines::Mask::read(mask, "mask");
  ASSERT_FALSE(m.roots().empty());
  std::size_t roots = 0;
  for (std::size_t i = 0; i < g.plant.nodes.size(); ++i) {
    if (g.plant.nodes[i].parent != kNoParent) continue;
    const glm::vec2 at = s.mesh_uv(uv_of(g.plant, i));
    float nearest = 1e9f;
    for (const glm::vec2& dot : m.roots()) nearest = std::min(nearest, glm::distance(at, dot));
    EXPECT_LT(nearest, 1e-4f) << "root " << roots;
    ++roots;
  }
  EXPECT_EQ(roots, m.roots().size());
  // Every attractor the vine consumed lay in the red zone: each node is within a few cells of it.
  std::size_t outside = 0;
  for (std::size_t i = 0; i < g.plant.nodes.size(); ++i) outside += m.zone(s.mesh_uv(uv_of(g.plant, i))) ? 0 : 1;
  EXPECT_LT(outside, g.plant.nodes.size() / 20) << outside << " of " << g.plant.nodes.size() << " nodes off the body";
}

// ---------- determinism ----------

TEST(Vines, ThePlantAndTheTextureAreTheSameForOneAndTwoThreads) {
  const Scene scene = load_scene("mesh:spot");
  const SceneQuery query(scene);
  const std::vector<std::string> sets = {"resolution=96", "texture_size=512", "wiggle=1",     "tags=2",
                                         "tag_mix=0.5",   "kill_limit=150",   "roots=random", "kill_limit_jitter=2"};
  const Grown one = grow_vines(scene, query, sets, 1, "vines_det_1"),
              two = grow_vines(scene, query, sets, 2, "vines_det_2");
  EXPECT_GT(one.plant.nodes.size(), 500u);
  EXPECT_EQ(one.plant.geometry_hash(), two.plant.geometry_hash());
  EXPECT_EQ(one.plant.node_attributes[0].values, two.plant.node_attributes[0].values);
  const Rgba a = read_png(one.dir / "texture.png"), b = read_png(two.dir / "texture.png");
  EXPECT_TRUE(a.px == b.px) << "texture pixels differ between 1 and 2 threads";
  EXPECT_EQ(read_bytes(one.dir / "skeleton.svg"), read_bytes(two.dir / "skeleton.svg"));
}

// ---------- bad input ----------

TEST(Vines, BadInputIsAClearError) {
  auto error = [](const Scene& scene, const SceneQuery& query, const std::vector<std::string>& sets) {
    return test::error_of([&] { grow_vines(scene, query, sets); });
  };
  EXPECT_NE(error(wall(), wall_query(), {"space=uv"}).find("space=uv needs a scene mesh with texture coordinates"),
            std::string::npos);
  EXPECT_NE(error(wall(), wall_query(), {"roots=0.5"}).find("roots entry 1 ('0.5')"), std::string::npos);
  EXPECT_NE(error(wall(), wall_query(), {"roots=0.2,0.2;x,1"}).find("roots entry 2"), std::string::npos);
  EXPECT_NE(error(wall(), wall_query(), {"tags=2", "roots=0.2,0.2,2"}).find("tag an integer in [0, 1]"),
            std::string::npos);
  EXPECT_NE(error(cube(), cube_query(), {"roots=0.05,0.05"}).find("outside the texture's charts"), std::string::npos);
  EXPECT_NE(error(wall(), wall_query(), {"mask=/no/such.png"}).find("mask=/no/such.png: no such file"),
            std::string::npos);
  EXPECT_NE(error(wall(), wall_query(), {"leaf_texture=/no/such.png"}).find("leaf_texture=/no/such.png"),
            std::string::npos);
  EXPECT_NE(error(wall(), wall_query(), {"kill=5"}).find("kill (5) must be smaller than influence (4)"),
            std::string::npos);
  EXPECT_NE(error(wall(), wall_query(), {"leaf_scale_min=2"}).find("leaf_scale_min (2) exceeds"), std::string::npos);
  EXPECT_NE(error(wall(), wall_query(), {"mask=/tmp"}).find("mask=/tmp: is a directory, not a file (expected a PNG"),
            std::string::npos);
  // An inclusion map with no red: nowhere for an attractor.
  const fs::path d = test::temp_dir("vines_bad_mask");
  const std::string white = write_mask(d / "white.png", 8, 8, [](int, int) { return kWhite; });
  const std::string e = error(wall(), wall_query(), {"space=canvas", "mask=" + white});
  EXPECT_NE(e.find("no attractor could be placed on scene 'wall' with mask=" + white + " (mask_mode=include)"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace growbench
