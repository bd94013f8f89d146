#include "harness/gate/conformance.hpp"

#include <unistd.h>

#include <algorithm>
#include <climits>
#include <exception>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "algorithms/algorithm.hpp"
#include "core/outcome.hpp"
#include "harness/run/process.hpp"
#include "harness/run/trial.hpp"
#include "scenes/scene.hpp"
#include "scenes/scene_query.hpp"

namespace growbench {
namespace {
using json = nlohmann::json;

// One trial's findings as its process reports them (one write of at most PIPE_BUF bytes).
struct Finding {
  std::string error;  // "STATUS: message" when the trial failed
  std::string hash, stopped_by;
  std::uint64_t nodes = 0, roots = 0, seeds = 0, inside = 0, first_inside = 0;
  double growth_s = 0.0;
};

// The body of one trial's process: grows the plant, looks at it, reports.
int grow_and_report(const TrialSpec& spec, bool look_inside, int fd) {
  json r;
  try {
    Plant plant;
    Scene scene;
    const TrialRecord rec = run_trial_record(spec, {}, &plant, &scene);
    r["hash"] = rec.results.geometry_hash;
    r["stopped_by"] = rec.results.stopped_by;
    r["nodes"] = plant.nodes.size();
    r["growth_s"] = rec.phases[Phase::growth] ? rec.phases[Phase::growth]->wall_s : 0.0;
    std::uint64_t roots = 0;
    for (const auto& n : plant.nodes) roots += n.parent == kNoParent ? 1 : 0;
    r["roots"] = roots;
    r["seeds"] = scene.seeds.size();
    if (look_inside) {  // the metrics' exact test, node by node
      const SceneQuery q(scene);
      std::uint64_t inside = 0, first = 0;
      for (std::size_t i = 0; i < plant.nodes.size(); ++i)
        if (q.inside(plant.nodes[i].position) && inside++ == 0) first = i;
      r["inside"] = inside;
      r["first_inside"] = first;
    }
  } catch (const std::exception& e) {
    std::string what = e.what();
    if (what.size() > 3000) what = what.substr(0, 3000) + "...";
    r = json{{"error", fmt::format("{}: {}", status_name(outcome_of(e)), what)}};
  }
  const std::string text = r.dump(-1, ' ', false, json::error_handler_t::replace);
  [[maybe_unused]] const auto n = write(fd, text.data(), std::min<std::size_t>(text.size(), PIPE_BUF));
  return 0;
}

Finding run_one(const TrialSpec& spec, bool look_inside, double timeout_s) {
  std::string report;
  const ChildResult cr = run_forked([&](int fd) { return grow_and_report(spec, look_inside, fd); },
                                    ChildLimits{timeout_s, 0}, "", [&](const std::string& s) { report = s; });
  Finding f;
  if (cr.timed_out) f.error = fmt::format("timeout: killed after {} s", timeout_s);
  if (cr.signal != 0) f.error = fmt::format("crashed: {}", signal_name(cr.signal));
  if (!f.error.empty()) return f;
  const json r = json::parse(report, nullptr, false);
  if (!r.is_object()) {
    f.error = fmt::format("crashed: the trial's process exited with status {} without reporting", cr.exit_code);
    return f;
  }
  f.error = r.value("error", "");
  f.hash = r.value("hash", "");
  f.stopped_by = r.value("stopped_by", "");
  f.nodes = r.value("nodes", std::uint64_t{0});
  f.roots = r.value("roots", std::uint64_t{0});
  f.seeds = r.value("seeds", std::uint64_t{0});
  f.inside = r.value("inside", std::uint64_t{0});
  f.first_inside = r.value("first_inside", std::uint64_t{0});
  f.growth_s = r.value("growth_s", 0.0);
  return f;
}

ConformanceCheck same_plant(const std::string& name, const Finding& a, const Finding& b) {
  if (!b.error.empty()) return {name, false, b.error};
  if (a.hash == b.hash) return {name, true, "same geometry hash"};
  return {name, false,
          fmt::format("geometry hash {} against {} ({} against {} nodes)", a.hash, b.hash, a.nodes, b.nodes)};
}

// What the first run shows of the plant itself.
void check_plant(const Finding& one, std::vector<ConformanceCheck>& checks) {
  checks.push_back(
      {"valid plant", one.error.empty(), one.error.empty() ? "finite, parents before children" : one.error});
  if (!one.error.empty()) return;
  checks.push_back({"grows", one.nodes > 1, fmt::format("{} nodes", one.nodes)});
  checks.push_back(
      {"one tree per seed", one.roots == one.seeds, fmt::format("{} roots for {} seeds", one.roots, one.seeds)});
  checks.push_back(
      {"no node inside a solid", one.inside == 0,
       one.inside == 0 ? "none" : fmt::format("{} nodes, the first node {}", one.inside, one.first_inside)});
}

ConformanceCheck cancellation(const Finding& c, const ConformanceOptions& o) {
  const std::string name = "stops at its time limit";
  if (!c.error.empty()) return {name, false, c.error};
  const double bound = o.cancel_after_s + o.cancel_grace_s;
  const std::string seen =
      fmt::format("growth {:.3f} s under a {:g} s limit, stopped by {}", c.growth_s, o.cancel_after_s, c.stopped_by);
  if (c.growth_s > bound)
    return {name, false, seen + fmt::format("; past {:g} s: a long step should return once host->cancelled()", bound)};
  if (c.stopped_by != "time_limit") return {name, true, seen + " (ended before the limit: not exercised)"};
  return {name, true, seen};
}

}  // namespace

bool SceneConformance::pass() const {
  return !checks.empty() && std::all_of(checks.begin(), checks.end(), [](const auto& c) { return c.pass; });
}

SceneConformance check_conformance(const std::string& algorithm, const std::string& scene,
                                   const ConformanceOptions& o) {
  TrialSpec spec;
  spec.algorithm = algorithm;
  spec.scene = scene;
  spec.params = find_algorithm(algorithm).info().test_params;
  spec.params.insert(spec.params.end(), o.params.begin(), o.params.end());
  spec.max_steps = o.max_steps;
  spec.metrics = false;
  SceneConformance out{scene, {}};
  spec.threads = 1;
  const Finding one = run_one(spec, true, o.timeout_s);
  check_plant(one, out.checks);
  if (!one.error.empty()) return out;
  spec.threads = 2;
  out.checks.push_back(same_plant("1 and 2 threads", one, run_one(spec, false, o.timeout_s)));
  spec.threads = 1;
  out.checks.push_back(same_plant("deterministic", one, run_one(spec, false, o.timeout_s)));
  // Without the test parameters, which keep plants small enough to end by themselves before any limit.
  spec.params = o.params;
  spec.threads = 2;
  spec.time_limit_s = o.cancel_after_s;
  out.checks.push_back(cancellation(run_one(spec, false, o.timeout_s), o));
  return out;
}

}  // namespace growbench
