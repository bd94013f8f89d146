// The vine texture's drawing, normal map and encoders on a synthetic vine like a grown one: branching
// random walks drawn walk by walk (as the growth draws them, parent before child), widths tapering from
// about 3 to 0.5 pixels at 4096, and a leaf every few strokes. The target: the 4096 texture with
// its leaves drawn in under a second on two threads.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "algorithms/vines/texture.hpp"
#include "core/random.hpp"

namespace growbench::vines {
namespace {

struct SyntheticVine {
  std::vector<Stroke> strokes;
  std::vector<LeafStamp> leaves;
};

// Walkers step a fixed length with a wiggling heading, turn back at the borders, and branch now and
// then into a thinner child that waits its turn; a walker stops when it has tapered to the thinnest
// width, and a new root starts when none is left.
SyntheticVine synthetic_vine(std::size_t stroke_count, std::size_t leaf_count) {
  constexpr float kPixel = 1.0f / 4096.0f;
  constexpr float kStep = 2.5f * kPixel, kThickest = 3.0f * kPixel, kThinnest = 0.5f * kPixel;
  constexpr double kBranching = 0.02, kWiggle = 0.3;
  struct Walker {
    glm::vec2 at;
    double heading;
    float width, taper;  // width now, and lost per step
  };
  Rng rng(7, 0);
  SyntheticVine v;
  v.strokes.reserve(stroke_count);
  std::deque<Walker> waiting;
  const std::size_t leaf_every = leaf_count > 0 ? std::max<std::size_t>(1, stroke_count / leaf_count) : 0;
  while (v.strokes.size() < stroke_count) {
    if (waiting.empty())
      waiting.push_back({{static_cast<float>(rng.uniform(0.05, 0.95)), static_cast<float>(rng.uniform(0.02, 0.3))},
                         std::numbers::pi / 2 + rng.uniform(-0.5, 0.5),
                         kThickest,
                         static_cast<float>(rng.uniform(0.5, 1.0)) * (kThickest - kThinnest) / 1500.0f});
    Walker w = waiting.front();
    waiting.pop_front();
    while (w.width > kThinnest && v.strokes.size() < stroke_count) {
      w.heading += rng.uniform(-kWiggle, kWiggle);
      glm::vec2 next = w.at + kStep * glm::vec2(std::cos(w.heading), std::sin(w.heading));
      if (next.x < 0.01f || next.x > 0.99f || next.y < 0.01f || next.y > 0.99f) {
        w.heading += std::numbers::pi;
        next = w.at;
      }
      const float width = std::max(kThinnest, w.width - w.taper);
      v.strokes.push_back({w.at, next, w.width, width});
      if (leaf_every > 0 && v.strokes.size() % leaf_every == 0 && v.leaves.size() < leaf_count)
        v.leaves.push_back({next, static_cast<float>(rng.uniform(-1.2, 1.2)),
                            static_cast<float>(rng.uniform(16.0, 36.0)) * kPixel,
                            static_cast<float>(rng.uniform(0.8, 1.2))});
      if (rng.uniform() < kBranching)
        waiting.push_back({next, w.heading + (rng.uniform() < 0.5 ? -1.0 : 1.0) * rng.uniform(0.4, 1.0),
                           std::max(kThinnest, 0.7f * width), w.taper});
      w.at = next;
      w.width = width;
    }
  }
  return v;
}

const SyntheticVine& vine() {
  static const SyntheticVine v = synthetic_vine(200000, 30000);
  return v;
}

// kWarm: each benchmark runs once untimed first, so that the timed runs reuse heap pages (bench_main.cpp
// keeps glibc from returning them) rather than timing the page faults of a fresh 64 MB image.
//
// Arguments: texture size, threads, leaves (0: strokes only).
void BM_VinesTextureDraw(benchmark::State& state) {
  DrawOptions options;
  options.size = static_cast<int>(state.range(0));
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(1)));
  const SyntheticVine& v = vine();
  const std::vector<LeafStamp> none;
  const std::vector<LeafStamp>& leaves = state.range(2) != 0 ? v.leaves : none;
  benchmark::DoNotOptimize(draw_texture(v.strokes, leaves, options));  // warm-up: see kWarm
  for (auto _ : state) benchmark::DoNotOptimize(draw_texture(v.strokes, leaves, options));
  state.counters["strokes"] = static_cast<double>(v.strokes.size());
  state.counters["leaves"] = static_cast<double>(leaves.size());
}
BENCHMARK(BM_VinesTextureDraw)
    ->ArgNames({"size", "threads", "leaves"})
    ->Args({1024, 1, 1})
    ->Args({1024, 2, 1})
    ->Args({4096, 1, 0})
    ->Args({4096, 2, 0})
    ->Args({4096, 1, 1})
    ->Args({4096, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

const Image& texture_4096() {
  static const Image image = [] {
    DrawOptions options;
    options.size = 4096;
    return draw_texture(vine().strokes, vine().leaves, options);
  }();
  return image;
}

// Argument: threads.
void BM_VinesTextureNormalMap(benchmark::State& state) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
  const Image& texture = texture_4096();
  benchmark::DoNotOptimize(normal_map(texture));  // warm-up: see kWarm
  for (auto _ : state) benchmark::DoNotOptimize(normal_map(texture));
}
BENCHMARK(BM_VinesTextureNormalMap)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

std::string bench_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("growbench_bench_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

// Argument: threads.
void BM_VinesTexturePng(benchmark::State& state) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
  const Image& texture = texture_4096();
  const std::string path = bench_path("texture.png");
  std::uint64_t bytes = write_png(path, texture);  // warm-up: see kWarm
  for (auto _ : state) bytes = write_png(path, texture);
  std::filesystem::remove(path);
  state.counters["MB"] = static_cast<double>(bytes) / 1e6;
}
BENCHMARK(BM_VinesTexturePng)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

void BM_VinesTextureSvg(benchmark::State& state) {
  DrawOptions options;
  options.size = 4096;
  const std::string path = bench_path("skeleton.svg");
  std::uint64_t bytes = 0;
  for (auto _ : state) bytes = write_svg(path, vine().strokes, vine().leaves, options);
  std::filesystem::remove(path);
  state.counters["MB"] = static_cast<double>(bytes) / 1e6;
}
BENCHMARK(BM_VinesTextureSvg)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true);

}  // namespace
}  // namespace growbench::vines
