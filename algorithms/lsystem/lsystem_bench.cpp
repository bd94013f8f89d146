// L-system rates against the targets: context-free rewriting of plain symbols (>= 100 M
// symbols/s per core), parametric rewriting with expressions (>= 10 M/s), turtle interpretation
// (>= 20 M/s), and memory per plain symbol (<= 8 bytes). Each benchmark times one generation (or one
// interpretation) of about 5-25 million symbols; the generations before it are derived outside the
// timed region. Rates count output symbols.
#include <string>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "algorithms/lsystem/derive.hpp"
#include "algorithms/lsystem/grammar.hpp"
#include "algorithms/lsystem/turtle.hpp"

namespace growbench::lsys {
namespace {

struct NoHost final : ExprHost {
  double in(double, double, double) const override { return 0.0; }
  double pic(double, double, double) const override { return 0.0; }
  double rand(double) const override { return 0.0; }
  double chan(double) const override { return 0.0; }
};

Grammar grammar(const std::string& premise, const std::string& rules) {
  return parse_grammar({"bench premise", premise, 1}, {{"bench rules", rules, 1}}, {}, "");
}

DeriveSettings settings(const NoHost& host) {
  return {.host = &host,
          .seed = 1,
          .stream = 0,
          .probability = ProbabilityMode::Sequential,
          .units = ProbabilityUnits::Auto,
          .brackets_transparent = false,
          .siblings = false,
          .left_in_branch = false,
          .max_symbols = 200'000'000,
          .max_params = 400'000'000,
          .env = {}};
}

// Derives `generations - 1` generations, then times the last one.
void time_last_generation(benchmark::State& state, const std::string& premise, const std::string& rules,
                          int generations) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
  static const NoHost host;
  const Grammar g = grammar(premise, rules);
  Deriver d(g, settings(host));
  LString a, b;
  d.premise(a);
  for (int k = 1; k < generations; ++k) {
    d.rewrite(a, b, k, {});
    std::swap(a, b);
  }
  std::size_t out = 0;
  for (auto _ : state) {
    d.rewrite(a, b, generations, {});
    out = b.size();
    benchmark::DoNotOptimize(b.symbols.data());
  }
  state.counters["symbols"] = static_cast<double>(out);
  state.counters["symbols_per_s"] =
      benchmark::Counter(static_cast<double>(out), benchmark::Counter::kIsIterationInvariantRate);
  // input and output strings together, per output symbol (what one generation holds in memory)
  state.counters["bytes_per_symbol"] = static_cast<double>(a.bytes() + b.bytes()) / static_cast<double>(out);
}

void BM_LsysPlainRewrite(benchmark::State& state) {  // F -> F[+F]F[-F]F, generation 10: 24.4 M symbols
  time_last_generation(state, "F", "F = F[+F]F[-F]F", 10);
}
BENCHMARK(BM_LsysPlainRewrite)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

void BM_LsysParametricRewrite(benchmark::State& state) {  // conditions and expressions, ~12.6 M symbols
  time_last_generation(state, "A(1,0)",
                       "A(l,k): k < 100 & l > 0 = F(l, l*0.1)[+(k*2+10)A(l*0.7, k+1)]A(l*0.9, k+1)\n"
                       "A(l,k) = F(l)",
                       21);
}
BENCHMARK(BM_LsysParametricRewrite)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

// The peer workloads (bench/peers/cases.json), each derived whole from its premise, as `make
// peers` times them against npm lindenmayer. Arg: threads. Rates count the last generation's modules.
void derive_whole(benchmark::State& state, const std::string& premise, const std::string& rules, int generations) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
  static const NoHost host;
  const Grammar g = grammar(premise, rules);
  Deriver d(g, settings(host));
  LString a, b;
  for (auto _ : state) {
    d.premise(a);
    for (int k = 1; k <= generations; ++k) {
      d.rewrite(a, b, k, {});
      std::swap(a, b);
    }
    benchmark::DoNotOptimize(a.symbols.data());
  }
  state.counters["modules"] = static_cast<double>(a.size());
  state.counters["modules_per_s"] =
      benchmark::Counter(static_cast<double>(a.size()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_LsysPeerBracketedPlant(benchmark::State& state) {  // n=9: 4.88 M modules
  derive_whole(state, "F", "F = F[+F]F[-F]F", 9);
}
void BM_LsysPeerMonopodialTree(benchmark::State& state) {  // ABOP fig. 2.6, n=18: 1.84 M modules
  derive_whole(state, "A(1,10)",
               "A(l,w) = !(w)F(l)[&(45)B(l*0.6,w*0.707)]/(137.5)A(l*0.9,w*0.707)\n"
               "B(l,w) = !(w)F(l)[-(45)$C(l*0.6,w*0.707)]C(l*0.9,w*0.707)\n"
               "C(l,w) = !(w)F(l)[+(45)$B(l*0.6,w*0.707)]B(l*0.9,w*0.707)",
               18);
}
void BM_LsysPeerContextSignal(benchmark::State& state) {  // b + 350,000 a, 8 steps
  derive_whole(state, "b" + std::string(350000, 'a'), "b < a = b\nb = a", 8);
}
BENCHMARK(BM_LsysPeerBracketedPlant)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LsysPeerMonopodialTree)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LsysPeerContextSignal)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The plain plant at generation 9: 4.9 M symbols, 2 M nodes. Arg 0: a fresh Plant per interpretation
// (cold: the node array's pages are touched for the first time); arg 1: the Plant is cleared and
// reused, as the algorithm does when it redraws after every generation.
void BM_LsysTurtle(benchmark::State& state) {
  static const NoHost host;
  const Grammar g = grammar("F", "F = F[+F]F[-F]F");
  Deriver d(g, settings(host));
  LString a, b;
  d.premise(a);
  for (int k = 1; k <= 9; ++k) {
    d.rewrite(a, b, k, {});
    std::swap(a, b);
  }
  const TurtleSettings ts = {.step = 0.1,
                             .step_scale = 0.9,
                             .angle = 25.7,
                             .angle_scale = 0.9,
                             .thickness = 0.01,
                             .thickness_scale = 0.9,
                             .gravity = 0.2,
                             .gravity_unit = 1.0,
                             .random_scale = 0.0,
                             .uv_increment = {0.1, 0.1},
                             .convention = Convention::Houdini,
                             .fraction = 1.0,
                             .continuous_length = true,
                             .continuous_angles = true,
                             .continuous_width = true,
                             .seed = 0,
                             .stream = 0,
                             .origin = glm::dvec3(0.0),
                             .heading = glm::dvec3(0.0, 1.0, 0.0),
                             .wrap = nullptr,
                             .wrap_offset = 0.0,
                             .avoid = nullptr,
                             .birth_step = 0,
                             .organ_kind = {OrganKind::Leaf, OrganKind::Flower, OrganKind::Bud},
                             .organ_shape = {kKindShape, kKindShape, kKindShape},
                             .color_image = nullptr,
                             .stamps = nullptr,
                             .point_attributes = false,
                             .vertical_increment = 1.0,
                             .generation = 0};
  std::size_t nodes = 0;
  Plant reused;
  for (auto _ : state) {
    Plant fresh;
    Plant& plant = state.range(0) ? reused : fresh;
    plant.clear();
    nodes = interpret(a, ts, g.strings, plant, nullptr).nodes;
    benchmark::DoNotOptimize(plant.nodes.data());
  }
  state.counters["symbols"] = static_cast<double>(a.size());
  state.counters["nodes"] = static_cast<double>(nodes);
  state.counters["symbols_per_s"] =
      benchmark::Counter(static_cast<double>(a.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_LsysTurtle)
    ->ArgName("reuse")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(3)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace growbench::lsys
