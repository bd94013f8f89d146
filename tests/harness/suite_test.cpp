// Suites through the growbench binary, as a user runs them (the suite forks its trials; running it
// inside this multi-threaded test process would fork a process with live TBB threads).
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <tuple>
#include <vector>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "algorithms/algorithm.hpp"
#include "core/memory.hpp"
#include "harness/record/record.hpp"
#include "harness/suite/suite.hpp"
#include "test_util.hpp"

extern char** environ;

namespace growbench {
namespace {

using nlohmann::json;

test::CommandResult growbench(const std::string& args) {
  return test::run_growbench(args);
}

json read_json(const std::filesystem::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

std::string suite_file(const std::filesystem::path& dir, const json& extra) {
  json s = {{"schema_version", 1}, {"name", "t"},  {"repetitions", 1},
            {"warmup", 0},         {"threads", 2}, {"scenes", {"column"}}};
  s.update(extra);
  return test::write_text(dir / "suite.json", s.dump(2));
}

const json kSmall = {{"point_count", 1500}, {"surface", "avoid"}};

TEST(Suite, ValidationNamesFileAndPathBeforeAnythingRuns) {
  const auto dir = test::temp_dir("suite_valid");
  struct Case {
    json algorithms;
    const char* expect;
  } cases[] = {
      {json::array({{{"name", "spacecl"}}}),
       "at /algorithms/0/name: unknown algorithm 'spacecl' (did you mean 'spacecol'?)"},
      {json::array({{{"name", "spacecol"}, {"params", {{"point_cont", 5}}}}}),
       "at /algorithms/0/params/point_cont: unknown parameter 'point_cont'"},
      {json::array({{{"name", "spacecol"}, {"sweep", {{"step", {0.01, -1}}}}}}), "at /algorithms/0/sweep/step/1:"},
      {json::array({{{"name", "spacecol"}, {"parms", json::object()}}}), "did you mean 'params'"},
  };
  for (const auto& c : cases) {
    const auto r =
        growbench("suite -q -o " + (dir / "out").string() + " " + suite_file(dir, {{"algorithms", c.algorithms}}));
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("suite.json"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "results.json"));
  }
  const auto r = growbench("suite -q " + suite_file(dir, {{"scenes", {"colum"}}, {"algorithms", {"spacecol"}}}));
  EXPECT_NE(r.out.find("at /scenes/0: unknown scene 'colum'"), std::string::npos) << r.out;
}

TEST(Suite, SweepsMakeOneCellPerPoint) {
  const auto dir = test::temp_dir("suite_sweep");
  const json algos =
      json::array({{{"name", "spacecol"},
                    {"label", "grid"},
                    {"params", kSmall},
                    {"sweep", {{"step", {0.02, 0.04}}, {"kill", {0.05, 0.08}}}}},
                   {{"name", "spacecol"},
                    {"label", "list"},
                    {"params", kSmall},
                    {"sweep", json::array({{{"step", 0.02}, {"kill", 0.05}}, {{"step", 0.04}, {"kill", 0.1}}})}}});
  const auto r = growbench("suite -q -o " + (dir / "out").string() + " " + suite_file(dir, {{"algorithms", algos}}));
  ASSERT_EQ(r.status, 0) << r.out;
  const json res = read_json(dir / "out" / "results.json");
  std::vector<std::string> ids;
  for (const auto& t : res["trials"]) ids.push_back(t["id"]);
  // The product gives 4 cells, the list 2; cells interleave the two entries.
  ASSERT_EQ(ids.size(), 6u);
  EXPECT_EQ(ids[0], "grid/column/s1/kill=0.05,step=0.02");  // parameters in key order
  EXPECT_EQ(ids[1], "list/column/s1/kill=0.05,step=0.02");
  EXPECT_EQ(res["trials"][1]["params"]["kill"], 0.05);
  EXPECT_EQ(res["trials"][3]["params"]["kill"], 0.1);
}

// "glb" chooses every cell's glTF layout, and is checked like every other key.
TEST(Suite, GlbChoosesTheLayoutOfEveryCell) {
  const auto dir = test::temp_dir("suite_glb");
  const json algos = json::array({{{"name", "spacecol"}, {"params", kSmall}}});
  for (const char* layout : {"plain", "compact"}) {
    const auto out = dir / layout;
    const auto r = growbench("suite -q -o " + out.string() + " " +
                             suite_file(dir, {{"algorithms", algos}, {"glb", layout}, {"seeds", {1, 2}}}));
    ASSERT_EQ(r.status, 0) << r.out;
    const json res = read_json(out / "results.json");
    ASSERT_EQ(res["trials"].size(), 2u);
    for (const auto& t : res["trials"]) {
      const auto& bytes = t["output_bytes"];
      if (std::string(layout) == "plain")
        EXPECT_EQ(bytes["glb"], bytes["glb_plain"]) << t["id"];
      else
        EXPECT_LT(bytes["glb"].get<double>(), 0.5 * bytes["glb_plain"].get<double>()) << t["id"];
    }
  }
  for (const json& bad : {json("gzip"), json(3)}) {
    const auto r = growbench("suite -q -o " + (dir / "bad").string() + " " +
                             suite_file(dir, {{"algorithms", algos}, {"glb", bad}}));
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_NE(r.out.find("at /glb: "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("expected one of plain, instanced, compact, got "), std::string::npos) << r.out;
  }
}

TEST(Suite, CrashHangMemoryHogAndInvalidInputAreRecordedWhileOthersSucceed) {
  const auto dir = test::temp_dir("suite_isolation");
  json algos = json::array({
      {{"name", "spacecol"}, {"label", "good"}, {"params", kSmall}},
      {{"name", "spacecol"}, {"label", "crash"}, {"params", kSmall}, {"fault", "crash"}},
      {{"name", "spacecol"}, {"label", "hang"}, {"params", kSmall}, {"fault", "hang"}},
      {{"name", "spacecol"}, {"label", "bad"}, {"params", {{"kill", 0.5}, {"influence", 0.3}}}},
      {{"name", "spacecol"}, {"label", "good2"}, {"params", kSmall}},
  });
  // Without an address-space limit (AddressSanitizer), the hog would take the whole machine.
  if (kAddressSpaceLimitWorks)
    algos.push_back({{"name", "spacecol"}, {"label", "hog"}, {"params", kSmall}, {"fault", "oom"}});
  const auto r = growbench("suite -q -o " + (dir / "out").string() + " " +
                           suite_file(dir, {{"algorithms", algos}, {"timeout_s", 8}, {"memory_limit_mb", 1024}}));
  ASSERT_EQ(r.status, 0) << r.out;
  const json res = read_json(dir / "out" / "results.json");
  std::map<std::string, json> by_label;
  for (const auto& t : res["trials"]) by_label[t["label"]] = t;
  EXPECT_EQ(by_label["good"]["status"], "ok");
  EXPECT_EQ(by_label["good2"]["status"], "ok");
  EXPECT_EQ(by_label["crash"]["status"], "crashed");
  EXPECT_NE(by_label["crash"]["message"].get<std::string>().find("signal 11"), std::string::npos);
  EXPECT_EQ(by_label["hang"]["status"], "timeout");
  if (kAddressSpaceLimitWorks) {
    EXPECT_EQ(by_label["hog"]["status"], "out_of_memory");
  }
  EXPECT_EQ(by_label["bad"]["status"], "invalid_input");
  EXPECT_NE(by_label["bad"]["message"].get<std::string>().find("kill (0.5) must be smaller than influence"),
            std::string::npos);
  EXPECT_NE(r.out.find("Warnings"), std::string::npos);  // the summary says so
}

// On one thread, as the gate counts them: with two, whether TBB's worker joins a phase's parallel work
// (and makes its per-thread allocations there) depends on the machine's load, not on the code.
TEST(Suite, AllocationCountsAndPlantsRepeatAcrossRuns) {
  const auto dir = test::temp_dir("suite_alloc");
  const auto r = growbench(
      "suite -q -o " + (dir / "out").string() + " " +
      suite_file(dir,
                 {{"repetitions", 3}, {"threads", 1}, {"algorithms", {{{"name", "spacecol"}, {"params", kSmall}}}}}));
  ASSERT_EQ(r.status, 0) << r.out;
  const json t = read_json(dir / "out" / "results.json")["trials"][0];
  ASSERT_EQ(t["samples"].size(), 3u);
  EXPECT_FALSE(t.value("nondeterministic", false));
  for (const char* ph : {"scene_load", "growth", "meshing", "metrics"}) {
    const auto& s = t["samples"];
    EXPECT_EQ(s[0]["phases"][ph]["alloc_count"], s[1]["phases"][ph]["alloc_count"]) << ph;
    EXPECT_EQ(s[0]["phases"][ph]["alloc_bytes"], s[2]["phases"][ph]["alloc_bytes"]) << ph;
    EXPECT_GT(s[0]["phases"][ph]["alloc_count"].get<long>(), 0) << ph;
  }
  const auto csv_lines = [&] {
    std::ifstream in(dir / "out" / "results.csv");
    int n = 0;
    for (std::string l; std::getline(in, l);) ++n;
    return n;
  }();
  EXPECT_EQ(csv_lines, 1 + 3);
}

TEST(Suite, ResumeAfterKillLosesNothing) {
  const auto dir = test::temp_dir("suite_resume");
  const json algos = json::array({{{"name", "spacecol"}, {"label", "a"}, {"params", kSmall}},
                                  {{"name", "spacecol"}, {"label", "b"}, {"params", kSmall}}});
  const std::string file = suite_file(dir, {{"repetitions", 4}, {"algorithms", algos}, {"scenes", {"column", "wall"}}});
  const std::string out = (dir / "out").string();
  std::vector<std::string> args = {GROWBENCH_BINARY, "suite", "-q", "-o", out, file};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, GROWBENCH_BINARY, nullptr, nullptr, argv.data(), environ), 0);
  // Kill -9 once a few repetitions are in the journal.
  auto journal = [&] {
    std::vector<json> lines;
    std::ifstream in(dir / "out" / "journal.jsonl");
    for (std::string l; std::getline(in, l);) {
      try {
        lines.push_back(json::parse(l));
      } catch (...) {
      }
    }
    return lines;
  };
  for (int i = 0; i < 600 && journal().size() < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  const std::vector<json> before = journal();
  ASSERT_GE(before.size(), 3u);
  ASSERT_LT(before.size(), 16u) << "the suite finished before it could be killed";
  read_json(dir / "out" / "results.json");  // whatever snapshot is there parses: written atomically
  const auto again = growbench("suite -q -o " + out + " " + file);
  EXPECT_EQ(again.status, 2) << "refuses to overwrite results without --resume: " << again.out;
  const auto r = growbench("suite -q --resume -o " + out + " " + file);
  ASSERT_EQ(r.status, 0) << r.out;
  const json after = read_json(dir / "out" / "results.json");
  int done_after = 0;
  for (const auto& t : after["trials"]) {
    done_after += static_cast<int>(t["samples"].size());
    EXPECT_EQ(t["status"], "ok");
  }
  EXPECT_EQ(done_after, 16);
  // Every repetition journaled before the kill is in the results, unchanged, and was not run again.
  for (const auto& e : before) {
    int found = 0;
    for (const auto& t : after["trials"])
      if (t["id"] == e["id"])
        for (const auto& smp : t["samples"])
          if (smp["repetition"] == e["sample"]["repetition"]) {
            ++found;
            EXPECT_EQ(smp, e["sample"]);
          }
    EXPECT_EQ(found, 1) << e["id"];
  }
}

// The journal's last line cut short by a kill: at its start, its middle, a byte before its end, and whole but
// for its newline. Resuming runs only that line's trial again (none when the line is whole), never glues its
// first append onto the fragment, and a second interruption right after loses nothing.
TEST(Suite, ResumeOverATornJournalLineRunsOnlyThatTrialAgain) {
  const auto dir = test::temp_dir("suite_torn");
  const json algos = json::array({{{"name", "spacecol"}, {"label", "a"}, {"params", kSmall}},
                                  {{"name", "spacecol"}, {"label", "b"}, {"params", kSmall}}});
  const std::string file = suite_file(dir, {{"algorithms", algos}});
  const auto out = dir / "out";
  ASSERT_EQ(growbench("suite -q -o " + out.string() + " " + file).status, 0);
  auto text = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  auto samples = [&] {
    std::map<std::string, json> by_id;
    const json results = read_json(out / "results.json");
    for (const auto& t : results["trials"]) {
      EXPECT_EQ(t["samples"].size(), 1u) << t["id"];
      by_id[t["id"]] = t["samples"][0];
    }
    return by_id;
  };
  const std::map<std::string, json> original = samples();
  const std::string journal = text(out / "journal.jsonl");
  const std::size_t first_end = journal.find('\n') + 1;
  const std::string last = journal.substr(first_end, journal.size() - first_end - 1);  // without its newline
  ASSERT_EQ(journal.back(), '\n');
  for (const std::size_t cut : {std::size_t{1}, last.size() / 2, last.size() - 1, last.size()}) {
    test::write_text(out / "journal.jsonl", journal.substr(0, first_end) + last.substr(0, cut));
    std::filesystem::remove(out / "results.json");  // killed before its first snapshot
    std::filesystem::remove(out / "journal.jsonl.torn");
    const auto r = growbench("suite -q --resume -o " + out.string() + " " + file);
    ASSERT_EQ(r.status, 0) << r.out;
    const bool whole = cut == last.size();
    EXPECT_EQ(r.out.find("set aside in journal.jsonl.torn") != std::string::npos, !whole) << cut << ": " << r.out;
    if (!whole) {
      EXPECT_EQ(text(out / "journal.jsonl.torn"), last.substr(0, cut) + "\n") << cut;
    }
    const std::map<std::string, json> resumed = samples();
    EXPECT_EQ(resumed.at("a/column/s1"), original.at("a/column/s1")) << cut << ": run again";
    EXPECT_EQ(resumed.at("b/column/s1") == original.at("b/column/s1"), whole) << cut;
    // Every line whole, each on its own: nothing glued onto the fragment.
    const std::string after = text(out / "journal.jsonl");
    ASSERT_EQ(after.back(), '\n');
    std::istringstream lines(after);
    int n = 0;
    for (std::string line; std::getline(lines, line); ++n) EXPECT_TRUE(json::accept(line)) << cut << ": " << line;
    EXPECT_EQ(n, 2) << cut;
    // Interrupted again before a snapshot: the journal alone has everything, so nothing runs again.
    std::filesystem::remove(out / "results.json");
    ASSERT_EQ(growbench("suite -q --resume -o " + out.string() + " " + file).status, 0);
    EXPECT_EQ(samples(), resumed) << cut;
  }
}

TEST(Suite, EveryGrammarIsReadBeforeTheFirstTrial) {
  const auto dir = test::temp_dir("suite_grammar");
  const std::string bad = test::write_text(dir / "bad.lsys", "premise: A\nA = F(\n");
  const std::string out = (dir / "out").string();
  const struct {
    std::string grammar, expect;
  } cases[] = {
      {bad,
       "suite.json: cell lsystem/column/s1 cannot start: " + bad + ":2:7: expected ')' before the end of the rule"},
      {(dir / "missing.lsys").string(), "suite.json: cell lsystem/column/s1 cannot start: grammar '" +
                                            (dir / "missing.lsys").string() + "': no such file, and not an example"},
  };
  for (const auto& c : cases) {
    const json algos = json::array(
        {{{"name", "spacecol"}, {"params", kSmall}}, {{"name", "lsystem"}, {"params", {{"grammar", c.grammar}}}}});
    const auto r = growbench("suite -q -o " + out + " " + suite_file(dir, {{"algorithms", algos}}));
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "results.json"));
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "journal.jsonl"));
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "checks"));
  }
}

TEST(Suite, ABillionCellsAreRefusedBeforeAnyIsMade) {
  const auto dir = test::temp_dir("suite_huge");
  json values = json::array();
  for (int i = 0; i < 1000; ++i) values.push_back(0.01 + 1e-5 * i);
  const json algos =
      json::array({{{"name", "spacecol"}, {"sweep", {{"step", values}, {"kill", values}, {"influence", values}}}}});
  const auto r = growbench("suite -q -o " + (dir / "out").string() + " " + suite_file(dir, {{"algorithms", algos}}));
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("suite.json: at /: the suite makes more than 100000 cells (scenes x seeds x the sweep points "
                       "of every algorithm entry); a suite may have at most 100000"),
            std::string::npos)
      << r.out;
}

// Memory running out is out_of_memory whichever library meets it (here Embree, creating its device under a
// small address-space limit), and an L-system whose arithmetic fails is invalid input: neither is a crash.
TEST(Suite, FailuresAreClassifiedByTheirCause) {
  const auto dir = test::temp_dir("suite_causes");
  const std::string div0 = test::write_text(dir / "div0.lsys", "premise: A(1)\nA(x) = F(1/(x-1))A(x)\n");
  const json algos = json::array({{{"name", "spacecol"}, {"label", "small"}, {"params", kSmall}},
                                  {{"name", "lsystem"}, {"label", "div0"}, {"params", {{"grammar", div0}}}}});
  auto r = growbench("suite -q -o " + (dir / "lsys").string() + " " + suite_file(dir, {{"algorithms", algos}}));
  ASSERT_EQ(r.status, 0) << r.out;
  std::map<std::string, json> by_label;
  const json results = read_json(dir / "lsys" / "results.json");
  for (const auto& t : results["trials"]) by_label[t["label"]] = t;
  EXPECT_EQ(by_label["small"]["status"], "ok");
  EXPECT_EQ(by_label["div0"]["status"], "invalid_input");
  EXPECT_EQ(by_label["div0"]["message"],
            div0 +
                ":2:10: in rule 'A(x) = F(1/(x-1))A(x)': the parameter expression '1/(x-1)' gave inf, from a "
                "division by zero");
  if (!kAddressSpaceLimitWorks) GTEST_SKIP() << "no address-space limit under AddressSanitizer";
  r = growbench(
      "suite -q -o " + (dir / "oom").string() + " " +
      suite_file(dir, {{"memory_limit_mb", 300}, {"algorithms", {{{"name", "spacecol"}, {"params", kSmall}}}}}));
  ASSERT_EQ(r.status, 0) << r.out;
  const json t = read_json(dir / "oom" / "results.json")["trials"][0];
  EXPECT_EQ(t["status"], "out_of_memory") << t;
  EXPECT_EQ(t["message"].get<std::string>().rfind("out of memory", 0), 0u) << t;
}

TEST(Suite, RepetitionsOverrideIsRecordedAndGuardsResume) {
  const auto dir = test::temp_dir("suite_reps");
  const json algos = json::array({{{"name", "spacecol"}, {"params", kSmall}}});
  const std::string file = suite_file(dir, {{"repetitions", 5}, {"algorithms", algos}});
  const std::string out = (dir / "out").string();
  auto r = growbench("suite -q --repetitions 2 -o " + out + " " + file);
  ASSERT_EQ(r.status, 0) << r.out;
  const json res = read_json(dir / "out" / "results.json");
  EXPECT_EQ(res["repetitions"], 2);
  ASSERT_EQ(res["trials"].size(), 1u);
  EXPECT_EQ(res["trials"][0]["samples"].size(), 2u);
  r = growbench("suite -q --resume -o " + out + " " + file);  // the file's 5 are not the run's 2
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("cannot resume, it ran 2 repetitions per cell and this run asks 5"), std::string::npos) << r.out;
  r = growbench("suite -q --repetitions 2 --resume -o " + out + " " + file);
  EXPECT_EQ(r.status, 0) << r.out;
  r = growbench("suite -q --repetitions 0 -o " + (dir / "o2").string() + " " + file);
  EXPECT_EQ(r.status, 2) << r.out;
}

TEST(Suite, QuickSuiteEndToEndAndSummary) {
  const auto dir = test::temp_dir("suite_quick");
  const std::string out = (dir / "out").string();
  const auto r = growbench("suite -q -o " + out + " " + std::string(GROWBENCH_SOURCE_DIR) + "/bench/suites/quick.json");
  ASSERT_EQ(r.status, 0) << r.out;
  const json res = read_json(dir / "out" / "results.json");
  EXPECT_EQ(res["schema_version"], 1);
  for (const char* k : {"growbench_commit", "dirty", "compiler", "cxx_flags", "build_type", "cpu_model",
                        "hardware_threads", "dependencies", "date", "suite_file_hash"})
    EXPECT_TRUE(res["context"].contains(k)) << k;
  EXPECT_EQ(res["context"]["parent_threads_at_fork"], 1) << "trials must be forked from a single-threaded process";
  ASSERT_GE(res["trials"].size(), 3u);
  for (const auto& t : res["trials"]) {
    for (const auto& s : t["samples"])
      for (const char* k :
           {"launch_s", "child_bookkeeping_s", "teardown_s", "parent_s", "harness_overhead_s", "outside_phases_s"}) {
        EXPECT_TRUE(s.contains(k)) << k;
        if (s.contains(k)) {
          EXPECT_GE(s[k].get<double>(), 0.0) << k;
        }
      }
    EXPECT_EQ(t["status"], "ok") << t["id"];
    for (const char* k : {"geometry_hash", "metrics", "output_bytes", "alloc", "curve", "scene_hash", "verdict"})
      EXPECT_TRUE(t.contains(k)) << k;
    // Every plant of the quick suite is a real one, or a scene its algorithm says it cannot grow on.
    EXPECT_NE(t["verdict"]["status"], "degenerate") << t["id"] << ": " << t["verdict"].dump();
    if (t["verdict"]["status"] == "not_applicable") {
      EXPECT_EQ(t["scene"], "envelope") << t["id"];
    }
    for (const char* f : {"obj", "ply", "glb", "skeleton_obj", "skeleton_ply"})
      EXPECT_GT(t["output_bytes"][f].get<long>(), 0) << f;
  }
  // The generated schema holds what the quick suite writes: results, journal and every trial's record.
  const auto v =
      test::run_command("/usr/bin/python3 " + std::string(GROWBENCH_SOURCE_DIR) + "/scripts/check-schema " + out +
                        "/results.json " + out + "/journal.jsonl " + out + "/trials/*/*/*/record.json");
  EXPECT_EQ(v.status, 0) << v.out;
  EXPECT_NE(v.out.find("all valid"), std::string::npos) << v.out;
  const auto s = growbench("summary " + out + "/results.json");
  EXPECT_EQ(s.status, 0);
  EXPECT_NE(s.out.find("== scene wall"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("growth time"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find(" range "), std::string::npos) << "two repetitions give a range, not an interval: " << s.out;
  EXPECT_EQ(growbench("summary /nonexistent.json").status, 2);
}

// The regression gate covers every algorithm: the quick suite has an entry for each registered one, and the
// committed baseline was made from this very suite file, with an ok cell of each.
TEST(Suite, TheQuickSuiteAndItsBaselineCoverEveryRegisteredAlgorithm) {
  const std::string root = GROWBENCH_SOURCE_DIR;
  const Suite quick = load_suite(root + "/bench/suites/quick.json");
  const Baseline base = read_baseline(root + "/reports/baselines/quick.json");
  EXPECT_EQ(base.suite_hash, quick.hash) << "reports/baselines/quick.json is not of bench/suites/quick.json: "
                                            "run make baseline PRESET=ci";
  std::set<std::string> in_suite, in_baseline;
  for (const auto& c : quick.configs) in_suite.insert(c.spec.algorithm);
  for (const auto& t : base.trials)
    if (t.status == "ok") in_baseline.insert(t.algorithm);
  for (const AlgorithmEntry& e : algorithm_registry()) {
    const std::string& name = e.info().name;
    EXPECT_TRUE(in_suite.count(name)) << name << " is registered but has no entry in bench/suites/quick.json";
    EXPECT_TRUE(in_baseline.count(name)) << name << " has no ok cell in reports/baselines/quick.json";
  }
}

// The README's figures about the standard suite (what `make demo` runs) are the suite file's.
TEST(Suite, TheReadmesFiguresAreTheStandardSuites) {
  const std::string root = GROWBENCH_SOURCE_DIR;
  const SuitePlan p = plan_of(load_suite(root + "/bench/suites/standard.json"));
  std::ifstream in(root + "/README.md");
  std::stringstream text;
  text << in.rdbuf();
  const std::string readme = test::one_paragraph(text.str());  // lines wrap anywhere: compare with single spaces
  for (const std::string& said :
       {fmt::format("({} cells: {} algorithm entries x {} scenes x {} seeds,", p.cells, p.entries, p.scenes, p.seeds),
        fmt::format("**one repetition** of each cell ({} trials, after one warm-up)", p.cells),
        fmt::format("{} repetitions, {} trials,", p.repetitions, p.cells * static_cast<std::size_t>(p.repetitions))})
    EXPECT_NE(readme.find(said), std::string::npos) << "README.md should say: " << said;
}

// A cell's results carry everything its first successful repetition measured: the organ pass's counts too,
// as the journal has them.
TEST(Suite, ACellCarriesItsOrganPassCounts) {
  const auto dir = test::temp_dir("suite_organs");
  const json algos = json::array({{{"name", "lsystem"},
                                   {"params", {{"grammar", "cherry-blossom"}, {"generations", 4}}},
                                   {"organs", {{"placement", "avoid"}}}}});
  const auto r = growbench("suite -q -o " + (dir / "out").string() + " " + suite_file(dir, {{"algorithms", algos}}));
  ASSERT_EQ(r.status, 0) << r.out;
  const json cell = read_json(dir / "out" / "results.json")["trials"][0];
  ASSERT_EQ(cell["status"], "ok") << cell.dump();
  ASSERT_TRUE(cell.contains("organs")) << cell.dump();
  std::ifstream in(dir / "out" / "journal.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  const json journal = json::parse(line)["cell"]["organs"];
  EXPECT_EQ(cell["organs"], journal);
  EXPECT_EQ(cell["organs"]["options"]["placement"], "avoid");
  EXPECT_GT(cell["organs"]["placed"].get<int>(), 0) << cell["organs"].dump();
  // Every repetition's plant is recorded with its sample, and the cell's is the first's.
  EXPECT_EQ(cell["samples"][0]["geometry_hash"], cell["geometry_hash"]);
}

// The settings a suite file gives reach every cell's spec, checked against the same ranges as the command
// line's options.
TEST(Suite, SettingsAreTheTrialSpecsWithItsRanges) {
  const auto dir = test::temp_dir("suite_settings");
  const json algos = json::array({{{"name", "spacecol"}, {"params", kSmall}, {"sides", 5}}});
  const auto r = growbench("suite -q -o " + (dir / "out").string() + " " +
                           suite_file(dir, {{"algorithms", algos},
                                            {"time_limit_s", 100},
                                            {"voxel_size", 0.05},
                                            {"sides", 8},
                                            {"budget_nodes", 400},
                                            {"seeds", {18446744073709551615ull}}}));
  ASSERT_EQ(r.status, 0) << r.out;
  const json cell = read_json(dir / "out" / "results.json")["trials"][0];
  EXPECT_EQ(cell["spec"]["time_limit_s"], 100.0);
  EXPECT_EQ(cell["spec"]["voxel_size"], 0.05);
  EXPECT_EQ(cell["spec"]["sides"], 5) << "the entry's own setting wins over the suite's";
  EXPECT_EQ(cell["spec"]["budget_nodes"], 400);
  EXPECT_EQ(cell["seed"], 18446744073709551615ull) << "a seed is a 64-bit integer, not a double";
  EXPECT_EQ(cell["stopped_by"], "budget_nodes");
  for (const auto& [key, value, expect] : std::vector<std::tuple<std::string, json, std::string>>{
           {"max_steps", -1, "at /max_steps: expected an integer in [0, 2147483647], got -1"},
           {"max_steps", 3000000000ull, "at /max_steps: expected an integer, 3000000000 is too large"},
           {"sides", 65, "at /sides: expected an integer in [3, 64], got 65"},
           {"voxel_size", 1e-9, "at /voxel_size: expected 0 or a number in [1e-06, 1e+06], got 1e-09"},
           {"threads", 2.5, "at /threads: expected an integer, got 2.5"}}) {
    const auto bad = growbench("suite -q -o " + (dir / "bad").string() + " " +
                               suite_file(dir, {{"algorithms", algos}, {key, value}}));
    EXPECT_EQ(bad.status, 2) << key << ": " << bad.out;
    EXPECT_NE(bad.out.find(expect), std::string::npos) << key << ": " << bad.out;
  }
}

TEST(Suite, ShardsMergeIntoTheUnshardedRun) {
  const auto dir = test::temp_dir("suite_merge");
  const nlohmann::json suite = {{"schema_version", 1},
                                {"name", "merge"},
                                {"repetitions", 1},
                                {"warmup", 0},
                                {"threads", 1},
                                {"seeds", {1, 2}},
                                {"scenes", {"wall", "column"}},
                                {"algorithms",
                                 {{{"name", "spacecol"}, {"params", {{"point_count", 300}}}},
                                  {{"name", "lsystem"}, {"params", {{"generations", 3}}}}}}};
  const std::string file = test::write_text(dir / "merge.json", suite.dump());
  // Equal-length output paths (allocations include them): "full", "sh_0", "sh_1", "sh_2".
  ASSERT_EQ(growbench("suite -q " + file + " --out " + (dir / "full").string()).status, 0);
  std::string inputs;
  for (int i = 0; i < 3; ++i) {
    const auto out = dir / ("sh_" + std::to_string(i));
    ASSERT_EQ(growbench(fmt::format("suite -q {} --shard {}/3 --out {}", file, i, out.string())).status, 0);
    inputs = (out / "results.json").string() + " " + inputs;  // given out of order on purpose
  }
  const auto merged = growbench("merge " + inputs + "--out " + (dir / "merged.json").string());
  ASSERT_EQ(merged.status, 0) << merged.out;
  std::ifstream fa(dir / "full" / "results.json"), fb(dir / "merged.json");
  const auto a = nlohmann::json::parse(fa), b = nlohmann::json::parse(fb);
  ASSERT_EQ(a["trials"].size(), 8u);
  ASSERT_EQ(b["trials"].size(), 8u);
  for (std::size_t k = 0; k < 8; ++k) {
    const auto& x = a["trials"][k];
    const auto& y = b["trials"][k];
    EXPECT_EQ(x["id"], y["id"]) << k;
    for (const char* f : {"geometry_hash", "counts", "metrics", "output_bytes", "alloc", "spec", "status"})
      EXPECT_EQ(x[f], y[f]) << k << " " << f;
  }
  EXPECT_EQ(b["shards"].size(), 3u);
  // Each scene's file once per run, under its content hash (the trials' scene_hash); the merged file names
  // the shards' files relative to itself.
  ASSERT_EQ(a["scenes"].size(), 2u);
  for (const auto& t : a["trials"]) EXPECT_TRUE(a["scenes"].contains(t["scene_hash"].get<std::string>())) << t["id"];
  for (const auto& [hash, file] : a["scenes"].items())
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "full" / file.get<std::string>())) << file;
  ASSERT_EQ(b["scenes"].size(), 2u);
  for (const auto& [hash, file] : b["scenes"].items()) {
    const std::string f = file.get<std::string>();
    EXPECT_EQ(f.rfind("sh_", 0), 0u) << f;
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / f)) << f;
    EXPECT_TRUE(a["scenes"].contains(hash)) << hash;
  }
  const auto cmp =
      growbench("compare " + (dir / "full" / "results.json").string() + " " + (dir / "merged.json").string());
  EXPECT_EQ(cmp.status, 0) << cmp.out;
  // A shard given twice, or one missing: clear errors.
  const std::string s0 = (dir / "sh_0" / "results.json").string(), s1 = (dir / "sh_1" / "results.json").string();
  auto r = growbench("merge " + s0 + " " + s0 + " " + s1 + " --out " + (dir / "x.json").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("given twice"), std::string::npos) << r.out;
  r = growbench("merge " + s0 + " " + s1 + " --out " + (dir / "x.json").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("shard 2/3 is missing"), std::string::npos) << r.out;
  // A shard from another machine type: its timings cannot stand beside the others' unless asked for.
  nlohmann::json other = nlohmann::json::parse(std::ifstream(s1));
  other["context"]["cpu_model"] = "Another CPU";
  const std::string s1x = test::write_text(dir / "sh_1x.json", other.dump());
  const std::string s2 = (dir / "sh_2" / "results.json").string();
  r = growbench("merge " + s0 + " " + s1x + " " + s2 + " --out " + (dir / "x.json").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("different machines or builds"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("cpu_model \"Another CPU\" in " + s1x), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.json"));
  r = growbench("merge --mixed-machines " + s0 + " " + s1x + " " + s2 + " --out " + (dir / "x.json").string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(nlohmann::json::parse(std::ifstream(dir / "x.json"))["context"]["mixed_machines"]);
  EXPECT_FALSE(b["context"].contains("mixed_machines"));
}

}  // namespace
}  // namespace growbench
