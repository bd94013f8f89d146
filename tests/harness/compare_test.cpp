// The deterministic regression gate: what `growbench compare` flags, and what it lets pass.
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/memory.hpp"
#include "harness/gate/compare.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {
using json = nlohmann::json;

json cell(const std::string& id, int threads = 1) {
  return {{"id", id},
          {"status", "ok"},
          {"threads", threads},
          {"geometry_hash", "0123456789abcdef"},
          {"counts", {{"nodes", 100}, {"leaves", 10}}},
          {"metrics", {{"coverage", 0.25}, {"attached_fraction", 0.5}}},
          {"verdict", {{"status", "valid"}}},
          {"output_bytes", {{"obj", 1000}, {"glb", 400}}},
          {"alloc", {{"growth", {{"count", 50}, {"bytes", 4096}}}}},
          {"instructions", {{"growth", 10000000}, {"query_build", 5000000}}},
          {"samples", json::array({{{"repetition", 0}, {"child_wall_s", 0.5}}})}};
}

json results(std::vector<json> cells) {
  return {{"kind", "growbench-results"}, {"mode", "instructions"}, {"trials", cells}};
}

TEST(Compare, IdenticalResultsPass) {
  const json a = results({cell("a/wall/s1"), cell("b/wall/s1")});
  const auto r = compare_results(a, a);
  EXPECT_FALSE(r.fails());
  EXPECT_TRUE(r.changes.empty());
  EXPECT_EQ(r.cells_compared, 2u);
  EXPECT_NE(r.table().find("OK"), std::string::npos);
}

TEST(Compare, AnyBehaviourChangeFails) {
  const json a = results({cell("a/wall/s1")});
  for (const auto& [path, value] : std::vector<std::pair<std::string, json>>{{"/geometry_hash", "fedcba9876543210"},
                                                                             {"/counts/nodes", 101},
                                                                             {"/metrics/coverage", 0.2500001},
                                                                             {"/status", "timeout"},
                                                                             {"/verdict/status", "degenerate"}}) {
    json b = a;
    b["trials"][0][json::json_pointer(path)] = value;
    const auto r = compare_results(a, b);
    EXPECT_TRUE(r.fails()) << path;
    ASSERT_EQ(r.changes.size(), 1u) << path;
    EXPECT_EQ(r.changes[0].why, "behaviour") << path;
    EXPECT_NE(r.table().find("REGRESSION"), std::string::npos);
  }
}

// compare said nothing when a plugin was another build: it names the plugin, both files and both hashes, and
// says a plugin loaded on one side only. A note, not a failure: the cells say whether the plants changed.
TEST(Compare, SaysWhenAPluginIsAnotherBuild) {
  auto with_plugins = [](json plugins) {
    json r = results({cell("walker/wall/s1")});
    r["context"] = {{"plugins", std::move(plugins)}};
    return r;
  };
  auto origin = [](const std::string& name, const std::string& path, const std::string& hash) {
    return json{{"name", name}, {"path", path}, {"hash", hash}, {"abi_version", 1}, {"version", "1.0"}};
  };
  const json a = with_plugins(
      {origin("walker", "/a/walker.so", "00000000000000aa"), origin("dla", "/a/dla.so", "00000000000000dd")});
  const json b = with_plugins(
      {origin("walker", "/b/walker.so", "00000000000000bb"), origin("line", "/b/line.so", "00000000000000cc")});
  const auto r = compare_results(a, b);
  EXPECT_FALSE(r.fails());
  EXPECT_EQ(r.plugin_notes,
            (std::vector<std::string>{
                "plugin walker: another build: base /a/walker.so (version 1.0, ABI 1, xxh3 "
                "00000000000000aa), new /b/walker.so (version 1.0, ABI 1, xxh3 00000000000000bb)",
                "plugin dla: loaded in the base (/a/dla.so, xxh3 00000000000000dd), not in the new results",
                "plugin line: loaded in the new results (/b/line.so, xxh3 00000000000000cc), not in the base"}));
  EXPECT_NE(r.table().find("plugin walker: another build"), std::string::npos) << r.table();
  // A baseline keeps the plugins, so the note survives `baseline update`.
  EXPECT_EQ(compare_results(baseline_of(a), b).plugin_notes.size(), 3u);
  EXPECT_TRUE(compare_results(a, a).plugin_notes.empty());
}

TEST(Compare, TimingsAreJudgedAndReportedButNeverFail) {
  // Ten repetitions each: growth 10 ms +-1% against 11 ms +-1% (slower), and an unchanged cell.
  auto timed = [](const std::string& id, double centre) {
    json c = cell(id);
    c["samples"] = json::array();
    for (int r = 0; r < 10; ++r) {
      const double t = centre * (1.0 + 0.01 * ((r * 7) % 10 - 4.5) / 4.5);
      c["samples"].push_back(
          {{"repetition", r}, {"status", "ok"}, {"phases", {{"growth", {{"wall_s", t}, {"cpu_s", t}}}}}});
    }
    return c;
  };
  const json a = results({timed("a/wall/s1", 0.010), timed("b/wall/s1", 0.020)});
  const json b = results({timed("a/wall/s1", 0.011), timed("b/wall/s1", 0.020)});
  const auto r = compare_results(a, b);
  EXPECT_FALSE(r.fails()) << "an unconfirmed timing flag must not fail the gate";
  ASSERT_EQ(r.timings.size(), 4u);
  EXPECT_EQ(r.timings[0].cell, "a/wall/s1");
  EXPECT_EQ(r.timings[0].metric, "growth.wall_s");
  EXPECT_EQ(r.timings[0].verdict.verdict, "slower");
  EXPECT_NEAR(r.timings[0].verdict.interval.ratio, 1.1, 1e-9);
  EXPECT_LT(r.timings[0].verdict.test.p, 1e-4);
  EXPECT_EQ(r.timings[2].verdict.verdict, "no change");
  EXPECT_NE(r.table().find("timings: 2 no change, 2 slower"), std::string::npos) << r.table();
  // Baselines have no repetitions: nothing to judge.
  EXPECT_TRUE(compare_results(results({cell("a/wall/s1")}), results({cell("a/wall/s1")})).timings.empty());
}

TEST(Compare, InstructionsFailOnlyPastTheThreshold) {
  const json a = results({cell("a/wall/s1")});
  auto with_growth = [&](std::int64_t ir) {
    json b = a;
    b["trials"][0]["instructions"]["growth"] = ir;
    return compare_results(a, b);
  };
  auto r = with_growth(10190000);  // +1.9%: shown, passes
  EXPECT_FALSE(r.fails());
  ASSERT_EQ(r.changes.size(), 1u);
  EXPECT_NEAR(r.changes[0].ratio, 1.019, 1e-12);
  EXPECT_EQ(r.changes[0].quantity, "instructions.growth");
  r = with_growth(10210000);  // +2.1% (210,000 instructions): fails
  EXPECT_TRUE(r.fails());
  EXPECT_NE(r.changes[0].why.find("+2.10%"), std::string::npos) << r.changes[0].why;
  r = with_growth(9000000);  // faster: passes
  EXPECT_FALSE(r.fails());
  json b = a;
  b["trials"][0]["instructions"]["growth"] = 10210000;
  EXPECT_FALSE(compare_results(a, b, {0.05}).fails());  // a looser threshold
  // A tiny phase: +10% of 50,000 instructions is under the absolute floor.
  json c = a;
  c["trials"][0]["instructions"]["scene_load"] = 50000;
  json d = c;
  d["trials"][0]["instructions"]["scene_load"] = 55000;
  r = compare_results(c, d);
  EXPECT_FALSE(r.fails());
  EXPECT_NE(r.changes[0].why.find("below the floor"), std::string::npos);
}

TEST(Compare, AllocationsAndBytesGateOnlyWhenDeterministic) {
  json a = results({cell("a/wall/s1", 1), cell("b/wall/s1", 2)});
  json b = a;
  b["trials"][0]["alloc"]["growth"]["count"] = 50 + 33;
  b["trials"][1]["alloc"]["growth"]["count"] = 50 + 33;
  auto r = compare_results(a, b);
  ASSERT_EQ(r.changes.size(), 2u);
  EXPECT_TRUE(r.changes[0].fails);   // one thread: deterministic, gated
  EXPECT_FALSE(r.changes[1].fails);  // two threads: shown, not gated
  // Counts and bytes within their slack (paths of another depth and length by checkout) pass.
  b["trials"][0]["alloc"]["growth"]["count"] = 50 + 32;
  r = compare_results(a, b);
  EXPECT_FALSE(r.fails());
  EXPECT_EQ(r.changes[0].why, "allocations within 32 (paths differ by checkout)");
  b = a;
  b["trials"][0]["alloc"]["growth"]["bytes"] = 4096 + 90;
  r = compare_results(a, b);
  EXPECT_FALSE(r.fails());
  b["trials"][0]["alloc"]["growth"]["bytes"] = 4096 + 5000;
  EXPECT_TRUE(compare_results(a, b).fails());
  b = a;
  b["trials"][1]["output_bytes"]["glb"] = 401;
  r = compare_results(a, b);
  EXPECT_TRUE(r.fails());
  EXPECT_EQ(r.changes[0].why, "output bytes");
}

TEST(Compare, MissingCellsFailNewCellsAreListed) {
  const json a = results({cell("a/wall/s1"), cell("b/wall/s1")});
  const json b = results({cell("a/wall/s1"), cell("c/wall/s1")});
  const auto r = compare_results(a, b);
  EXPECT_TRUE(r.fails());
  EXPECT_EQ(r.missing_cells, std::vector<std::string>{"b/wall/s1"});
  EXPECT_EQ(r.new_cells, std::vector<std::string>{"c/wall/s1"});
}

TEST(Compare, BaselineKeepsWhatTheGateComparesAndDropsTimings) {
  const json a = results({cell("a/wall/s1")});
  const json base = baseline_of(a);
  EXPECT_EQ(base["kind"], "growbench-baseline");
  EXPECT_EQ(base["mode"], "instructions");
  EXPECT_FALSE(base["trials"][0].contains("samples"));
  EXPECT_EQ(base["trials"][0]["instructions"], a["trials"][0]["instructions"]);
  EXPECT_TRUE(compare_results(base, a).changes.empty());
}

// The gate end to end, under the real callgrind: an unchanged rerun passes; a planted slowdown of about
// 5% in one algorithm's growth phase (the test-only fault slow:N, which leaves the plant alone) fails.
TEST(RegressionGate, CatchesAPlantedFivePercentSlowdownAndNotAnUnchangedRerun) {
  // Valgrind cannot run a binary built with AddressSanitizer (both claim the address space).
  if (kAddressSanitizer) GTEST_SKIP() << "callgrind cannot run an AddressSanitizer build";
  const auto dir = test::temp_dir("gate");
  auto suite = [&](const std::string& name, const std::string& fault) {
    nlohmann::json entry = {{"name", "spacecol"}, {"label", "spacecol"}, {"params", {{"point_count", 400}}}};
    if (!fault.empty()) entry["fault"] = fault;
    const nlohmann::json s = {
        {"schema_version", 1}, {"name", name}, {"seeds", {1}}, {"scenes", {"wall"}}, {"algorithms", {entry}}};
    return test::write_text(dir / (name + ".json"), s.dump());
  };
  auto run = [&](const std::string& name, const std::string& fault) {
    const auto r =
        test::run_growbench("suite -q --instructions " + suite(name, fault) + " --out " + (dir / name).string());
    EXPECT_EQ(r.status, 0) << r.out;
    return (dir / name / "results.json").string();
  };
  // Equal-length output names: paths are allocated, and allocations must match exactly.
  const std::string base = run("run1", "");
  std::ifstream in(base);
  const auto results = nlohmann::json::parse(in);
  const auto& cell = results["trials"][0];
  ASSERT_EQ(cell["status"], "ok");
  EXPECT_EQ(cell["threads"], 1);
  for (const char* phase : {"scene_load", "growth", "meshing", "export", "metrics"})
    EXPECT_GT(cell["instructions"].value(phase, 0ull), 0ull) << phase;
  EXPECT_FALSE(cell["instructions"].contains("query_build"));  // left uninstrumented (see trial.cpp)

  const auto same = test::run_growbench("compare " + base + " " + run("run2", ""));
  EXPECT_EQ(same.status, 0) << same.out;
  EXPECT_NE(same.out.find("0 changed quantities"), std::string::npos) << same.out;

  // About 8 instructions per iteration of the planted loop (measured): 5% of the growth phase.
  const auto growth = cell["instructions"]["growth"].get<std::uint64_t>();
  const std::string slow = run("run3", "slow:" + std::to_string(growth / 20 / 8));
  const auto caught = test::run_growbench("compare " + base + " " + slow);
  EXPECT_EQ(caught.status, 1) << caught.out;
  EXPECT_NE(caught.out.find("instructions.growth"), std::string::npos) << caught.out;
  EXPECT_NE(caught.out.find("REGRESSION"), std::string::npos) << caught.out;
  std::ifstream sin(slow);
  const auto slowed = nlohmann::json::parse(sin)["trials"][0];
  const double ratio = slowed["instructions"]["growth"].get<double>() / static_cast<double>(growth);
  EXPECT_GT(ratio, 1.03);
  EXPECT_LT(ratio, 1.08);
  EXPECT_EQ(slowed["geometry_hash"], cell["geometry_hash"]);  // the plant is the same: only the cost changed
}

// Callgrind trials run side by side (--jobs) count what they count one at a time, and are kept in the same
// order: the results and the journal do not say how many ran at once.
TEST(RegressionGate, TrialsSideBySideCountTheSameAsOneAtATime) {
  if (kAddressSanitizer) GTEST_SKIP() << "callgrind cannot run an AddressSanitizer build";
  const auto dir = test::temp_dir("gate_jobs");
  const nlohmann::json s = {{"schema_version", 1},
                            {"name", "jobs"},
                            {"seeds", {1, 2}},
                            {"scenes", {"wall", "envelope"}},
                            {"algorithms", {{{"name", "spacecol"}, {"params", {{"point_count", 200}}}}}}};
  const std::string file = test::write_text(dir / "jobs.json", s.dump());
  auto run = [&](const std::string& out, int jobs) {
    const auto r = test::run_growbench(
        fmt::format("suite -q --instructions --jobs {} {} --out {}", jobs, file, (dir / out).string()));
    EXPECT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find(fmt::format("{} at a time", jobs)), std::string::npos) << r.out;
    std::ifstream in(dir / out / "results.json");
    const auto results = nlohmann::json::parse(in);
    std::vector<std::string> journal;  // cell ids, in the order they were appended
    std::ifstream jin(dir / out / "journal.jsonl");
    for (std::string line; std::getline(jin, line);) journal.push_back(nlohmann::json::parse(line)["id"]);
    return std::pair{results, journal};
  };
  // Equal-length output names: paths enter the export phase's counts.
  const auto [one, one_journal] = run("w1", 1);
  const auto [three, three_journal] = run("w3", 3);
  ASSERT_EQ(one["trials"].size(), 4u);
  EXPECT_EQ(one_journal, three_journal);
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& a = one["trials"][i];
    const auto& b = three["trials"][i];
    EXPECT_EQ(a["id"], b["id"]);
    ASSERT_EQ(a["status"], "ok") << a["id"];
    EXPECT_EQ(a["instructions"], b["instructions"]) << a["id"];
    EXPECT_EQ(a["geometry_hash"], b["geometry_hash"]) << a["id"];
  }
  // Timed trials are not run side by side.
  const auto timed = test::run_growbench(fmt::format("suite -q --jobs 2 {} --out {}", file, (dir / "t").string()));
  EXPECT_EQ(timed.status, 2) << timed.out;
  EXPECT_NE(timed.out.find("--jobs runs callgrind trials side by side and needs --instructions"), std::string::npos)
      << timed.out;
}

}  // namespace
}  // namespace growbench
