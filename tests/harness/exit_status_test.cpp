// The exit-status contract (README, "Exit status"), command by command, through the binary as a user meets
// it: 0 success, 1 a regression found by compare or ab and nothing else, 2 bad input or usage, 3 an
// internal error with a request for a bug report.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "harness/record/files.hpp"
#include "harness/record/record.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

test::CommandResult growbench(const std::string& args) {
  return test::run_growbench(args);
}

// Any command line (a shell command), its status and output, as run_growbench gives them.
test::CommandResult run_command(const std::string& command) {
  const auto log = test::temp_dir("exit_cmd") / "log.txt";
  const int rc = std::system((command + " > " + log.string() + " 2>&1").c_str());
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, ss.str()};
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The subcommands `growbench --help` lists, from its Subcommands section.
std::vector<std::string> listed_commands() {
  const std::string help = growbench("--help").out;
  std::istringstream in(help.substr(help.find("Subcommands:")));
  std::vector<std::string> out;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string name;
    if (line.rfind("  ", 0) == 0 && words >> name) out.push_back(name);
  }
  return out;
}

// A results file of one ok cell whose plant has `hash`: what compare, merge, baseline, history and summary
// read.
std::string write_results(const fs::path& path, const std::string& hash) {
  ResultsFile r;
  r.suite = {"t", "t.json", ""};
  r.suite_hash = "0123456789abcdef";
  r.repetitions = 1;
  r.context.growbench_commit = "0123456789ab";
  r.context.cpu_model = "Test CPU";
  SuiteCell c;
  c.id = "spacecol/wall/s1";
  c.label = c.algorithm = "spacecol";
  c.scene = c.scene_spec = "wall";
  c.status = "ok";
  SuiteSample s;
  s.status = "ok";
  s.phases.emplace();
  (*s.phases)[Phase::growth] = PhaseMeasures{0.25, 0.5, 1u << 20, true, 10, 4096, {}, {}, {}, {}, {}, {}};
  c.samples.push_back(s);
  TrialResults& plant = c.results.plant.emplace();
  plant.geometry_hash = hash;
  plant.counts = Counts{10, 9, 2, 2, 0, 100, 50};
  r.trials.push_back(c);
  return test::write_text(path, json_text(to_json(r), 1));
}

TEST(ExitStatus, HelpIsZeroAndEveryCommandLineErrorIsTwo) {
  // Every command --help lists is covered here: a new command must be added to this list (and to the
  // cases below) to pass.
  const std::vector<std::string> commands = listed_commands();
  EXPECT_EQ(commands, (std::vector<std::string>{"list", "scenes", "run", "suite", "history", "render", "ab", "compare",
                                                "merge", "baseline", "report", "lsystem", "summary", "plugin-test"}));
  std::vector<std::string> all = commands;
  for (const char* nested : {"history add", "history plot", "baseline update"}) all.emplace_back(nested);
  for (const auto& c : all) {
    auto r = growbench(c + " --help");
    EXPECT_EQ(r.status, 0) << c << ": " << r.out;
    r = growbench(c + " --no-such-option");
    EXPECT_EQ(r.status, 2) << c << ": " << r.out;
    EXPECT_FALSE(has(r.out, "internal error")) << c << ": " << r.out;
  }
  EXPECT_FALSE(has(growbench("ab --help").out, "{false}"));  // CLI11's rendering of a negated flag
  const auto version = growbench("--version");
  EXPECT_EQ(version.status, 0);
  EXPECT_TRUE(has(version.out, "(commit ")) << version.out;
  auto r = growbench("");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, "A subcommand is required")) << r.out;
  r = growbench("frobnicate");
  EXPECT_EQ(r.status, 2) << r.out;
  r = growbench("run -a spacecol -s wall --threads abc");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, "--threads")) << r.out;
}

TEST(ExitStatus, BadInputIsTwoForEveryCommandWithItsSourceNamed) {
  const auto dir = test::temp_dir("exit_bad");
  const std::string bad = test::write_text(dir / "malformed.json", "{\n");
  const std::string d = dir.string();
  fs::create_directories(dir / "empty");
  const struct {
    std::string args, expect;
  } cases[] = {
      {"list spacel", "did you mean 'spacecol'"},
      {"scenes extra", "extra"},
      {"run -a spacecol -s wall --voxel-size nan",
       "--voxel-size: expected 0 or a finite number in [1e-06, 1e+06], got 'nan'"},
      {"suite " + d + "/missing.json", d + "/missing.json: no such file (expected a suite file)"},
      {"history add " + bad, bad + ":2:1: invalid JSON"},
      {"history plot --dir " + d + "/empty", d + "/empty: no history files"},
      {"render " + d + "/missing", "neither a suite results directory"},
      {"ab /bin/true /bin/true " + d + "/missing.json", d + "/missing.json: no such file (expected a suite file)"},
      {"compare " + bad + " " + bad, bad + ":2:1: invalid JSON"},
      {"merge " + bad + " --out " + d + "/m.json", bad + ":2:1: invalid JSON"},
      {"baseline update " + bad + " --baseline " + d + "/b.json", bad + ":2:1: invalid JSON"},
      {"report " + bad, bad + ":2:1: invalid JSON"},
      {"lsystem busj", "did you mean 'bush'"},
      {"summary " + bad, bad + ":2:1: invalid JSON"},
      {"plugin-test " + d + "/missing.so", d + "/missing.so: no such plugin file"},
  };
  for (const auto& c : cases) {
    const auto r = growbench(c.args);
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.out;
    EXPECT_TRUE(has(r.out, c.expect)) << c.args << ": " << r.out;
    EXPECT_FALSE(has(r.out, "internal error")) << c.args << ": " << r.out;
  }
}

// Inputs that were accepted with exit 0 (or aborted the process) although they cannot work: each is now
// refused with 2 and says what was expected.
TEST(ExitStatus, InputsThatCannotWorkAreTwoNotZeroOrAnAbort) {
  const auto dir = test::temp_dir("exit_wrong");
  const std::string d = dir.string();
  const json ok = json::parse(std::ifstream(write_results(dir / "ok.json", "0123456789abcdef")));
  auto variant = [&](const std::string& name, const std::function<void(json&)>& change) {
    json j = ok;
    change(j);
    return test::write_text(dir / name, j.dump());
  };
  const std::string no_samples = variant("no_samples.json", [](json& j) { j["trials"][0]["samples"] = json::array(); });
  const std::string no_shard = variant("no_shard.json", [](json& j) { j.erase("shard"); });
  const std::string big = variant("big.json", [](json& j) {
    j["shard"] = {{"index", 0}, {"count", 2}};
    j["trials"].push_back(j["trials"][0]);
    j["trials"][1]["id"] = "spacecol/wall/s2";
  });
  const std::string empty = variant("empty.json", [](json& j) {
    j["shard"] = {{"index", 1}, {"count", 2}};
    j["trials"] = json::array();
  });
  const std::string twice0 = variant("twice0.json", [](json& j) { j["shard"] = {{"index", 0}, {"count", 2}}; });
  const std::string twice1 = variant("twice1.json", [](json& j) { j["shard"] = {{"index", 1}, {"count", 2}}; });
  // A shard is a results file: merge checks what every reader of one checks.
  const std::string shard_no_samples = variant("shard_no_samples.json", [](json& j) {
    j["shard"] = {{"index", 0}, {"count", 1}};
    j["trials"][0]["samples"] = json::array();
  });
  const std::string shard_escape = variant("shard_escape.json", [](json& j) {
    j["shard"] = {{"index", 0}, {"count", 1}};
    j["trials"][0]["id"] = "../../victim/s1";
  });
  const std::string clash = test::write_text(dir / "clash.lsys", "premise: A(1,2)\nA(x,x) = F(x) A(x,x)\n");
  const std::string flat = test::write_text(dir / "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  const std::string fault =
      test::write_text(dir / "fault.json",
                       R"({"schema_version": 1, "name": "f", "algorithms": [{"name": "spacecol", "fault": "explode"}],
          "scenes": ["wall"], "seeds": [1]})");
  auto suite_with = [&](const std::string& name, const std::string& entry) {
    return test::write_text(dir / name, R"({"schema_version": 1, "name": "n", "algorithms": [)" + entry +
                                            R"(], "scenes": ["wall"], "seeds": [1]})");
  };
  const std::string long_label =
      suite_with("long.json", R"({"name": "spacecol", "label": ")" + std::string(300, 'x') + R"("})");
  const std::string broken_label = suite_with("broken.json", R"({"name": "spacecol", "label": "a\nb"})");
  const std::string scene_name = test::write_text(dir / "named.json", R"({"schema_version": 1, "base": "wall",
      "name": "x\n#fopen F \"/tmp/pwned\" write"})");
  const std::string fifo = d + "/plugin.so";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);  // dlopen waited on it forever
  const struct {
    std::string args, expect;
  } cases[] = {
      // Names become folders, files and captions: a 300-byte label passed and failed only at the first
      // trial, after files were made; a line break in a name ended the comment it was written into.
      {"suite " + long_label + " -o " + d + "/long", "at /algorithms/0/label: expected a name of at most 100 bytes"},
      {"suite " + broken_label + " -o " + d + "/broken", "at /algorithms/0/label: expected a name without control"},
      {"run -a spacecol -s " + scene_name + " -o " + d + "/named", "at /name: expected a name without control"},
      // Every choice option suggests the nearest choice, as --algorithm and --scene do.
      {"run -a spacecol -s wall --render papr -o " + d + "/r",
       "--render 'papr': expected preview or paper (did you mean 'paper'?)"},
      {"render " + d + " --camera scen", "--camera 'scen': expected auto or scene (did you mean 'scene'?)"},
      {"render " + d + " --backdrop studi", "--backdrop 'studi': expected scene or studio (did you mean 'studio'?)"},
      {"list --plugin " + fifo, fifo + ": not a regular file (a FIFO, a device or a socket)"},
      {"run -a lsystem -s wall --set 'premise=F(2e18)J' --set generations=0 -o " + d + "/far",
       "node 1 lies at (-1, 2e+18, 0.13), not within 1e+09 m of the origin"},
      {"run -a lsystem -s wall --set grammar=" + clash + " -o " + d + "/clash", "the parameter name 'x' appears twice"},
      {"run -a ivy -s mesh:" + flat + " -o " + d + "/flat", flat + ": every face has zero area"},
      {"suite " + fault + " -o " + d + "/fault", "at /algorithms/0/fault: unknown fault 'explode'"},
      {"run -a spacecol -s wall -o ''", "--out: expected an output folder, got an empty name"},
      // Sizes that ran for minutes: refused where they enter.
      {"run -a spacecol -s wall --set point_count=50000000 --max-steps 2 -o " + d + "/big", "point_count"},
      {"run -a ivy -s wall --set branches_per_step=1000000 --max-steps 20 -o " + d + "/big", "branches_per_step"},
      {"compare " + no_samples + " " + d + "/ok.json",
       "at /trials/0/samples: cell 'spacecol/wall/s1' is ok but has no"},
      {"summary " + no_samples, "is ok but has no samples"},
      {"merge " + no_shard + " -o " + d + "/m.json", "no_shard.json: no 'shard' key, so which shard"},
      {"merge " + big + " " + empty + " -o " + d + "/m.json",
       "shard 0/2 has 2 cells, but a suite of 2 cells in 2 shards gives it 1"},
      {"merge " + twice0 + " " + twice1 + " -o " + d + "/m.json",
       "cell 'spacecol/wall/s1' is in the merged results twice"},
      {"merge " + shard_no_samples + " -o " + d + "/m.json", "at /trials/0/samples: cell 'spacecol/wall/s1' is ok"},
      {"merge " + shard_escape + " -o " + d + "/m.json", "at /trials/0/id: cell id \"../../victim/s1\""},
  };
  for (const auto& c : cases) {
    const auto r = growbench(c.args);
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.out;
    EXPECT_TRUE(has(r.out, "growbench: error: ")) << c.args << ": " << r.out;
    EXPECT_TRUE(has(r.out, c.expect)) << c.args << ": " << r.out;
  }
  EXPECT_FALSE(fs::exists(dir / "m.json"));
  EXPECT_FALSE(fs::exists(dir / "long"));  // refused before any file was made
}

// Two writers on one folder interleaved their files: duplicated (id, repetition) pairs, a good trial
// recorded as invalid_input, a render rewriting results.json with every cell pending. A second writer is
// now refused with 2, naming the one at work, and the folder is free again when it ends.
TEST(ExitStatus, ASecondWriterOnAFolderIsTwoUntilTheFirstEnds) {
  const auto dir = test::temp_dir("exit_lock");
  const std::string out = (dir / "out").string();
  const std::string suite = test::write_text(
      dir / "tiny.json",
      R"({"schema_version": 1, "name": "tiny", "algorithms": [{"name": "spacecol", "params": {"point_count": 300}}],
          "scenes": ["wall"], "seeds": [1], "repetitions": 1})");
  const std::string results = write_results(dir / "results.json", "0123456789abcdef");
  {
    const FolderLock held = FolderLock::take(out, "suite");
    const FolderLock again = FolderLock::take(out, "render");  // this process holds it already: no refusal
    fs::copy_file(results, out + "/results.json");
    const std::string holder =
        fmt::format("{}: another growbench is writing in this folder (pid {}: growbench suite)", out, ::getpid());
    for (const std::string& args :
         {"suite " + suite + " -o " + out, "suite " + suite + " --resume -o " + out, "render " + out,
          "run -a spacecol -s wall --set point_count=300 -o " + out, "report " + results + " -o " + out}) {
      const auto r = growbench(args);
      EXPECT_EQ(r.status, 2) << args << ": " << r.out;
      EXPECT_TRUE(has(r.out, holder)) << args << ": " << r.out;
    }
    EXPECT_EQ(read_input_file(out + "/results.json"), read_input_file(results));  // untouched
  }
  fs::remove(out + "/results.json");
  const auto r = growbench("suite " + suite + " -o " + out + " --quiet");
  EXPECT_EQ(r.status, 0) << r.out;
}

TEST(ExitStatus, SuccessIsZeroAndOnlyARegressionIsOne) {
  const auto dir = test::temp_dir("exit_ok");
  const std::string d = dir.string();
  const std::string base = write_results(dir / "base.json", "0123456789abcdef");
  const std::string changed = write_results(dir / "changed.json", "fedcba9876543210");
  for (const std::string& args : std::vector<std::string>{
           "list", "scenes", "lsystem koch-island -g 1", "summary " + base, "compare " + base + " " + base,
           "merge " + base + " --out " + d + "/merged.json", "baseline update " + base + " --baseline " + d + "/b.json",
           "compare " + d + "/b.json " + base, "history add " + base + " --dir " + d + "/history"}) {
    const auto r = growbench(args);
    EXPECT_EQ(r.status, 0) << args << ": " << r.out;
  }
  const auto r = growbench("compare " + base + " " + changed);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(has(r.out, "geometry_hash")) << r.out;
  EXPECT_TRUE(has(r.out, "REGRESSION")) << r.out;
}

TEST(ExitStatus, AnInternalErrorIsThreeAndAsksForABugReport) {
  const auto dir = test::temp_dir("exit_internal");
  auto r = growbench("run -q -a spacecol -s wall --max-steps 1 --fault throw -o " + (dir / "run").string());
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_TRUE(has(r.out,
                  "growbench: internal error: injected internal error\n"
                  "This is a bug in growbench: please report it"))
      << r.out;
  // The report script failing on a valid file is a bug too, never a regression's 1.
  const std::string script = test::write_text(dir / "broken.py", "raise RuntimeError('broken script')\n");
  const std::string results = write_results(dir / "results.json", "0123456789abcdef");
  ::setenv("GROWBENCH_REPORT_SCRIPT", script.c_str(), 1);
  r = growbench("report " + results + " -o " + (dir / "report").string());
  ::unsetenv("GROWBENCH_REPORT_SCRIPT");
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_TRUE(has(r.out, "internal error: reports/report.py ended with status 1")) << r.out;
}

TEST(ExitStatus, CompareOnAFileItCannotReadIsTwoNeverARegression) {
  const auto dir = test::temp_dir("exit_compare");
  const std::string d = dir.string();
  const std::string ok = write_results(dir / "ok.json", "0123456789abcdef");
  test::write_text(dir / "kind5.json", R"({"kind": 5, "trials": []})");
  test::write_text(dir / "overflow.json", R"({"kind": "growbench-results", "trials": [{"id": "a", "seed": 1e400}]})");
  test::write_text(dir / "idnum.json", R"({"kind": "growbench-results", "trials": [{"id": 5}]})");
  fs::create_directories(dir / "adir");
  const struct {
    std::string file, expect;
  } cases[] = {
      {d + "/missing.json", d + "/missing.json: cannot open: No such file or directory"},
      {d + "/kind5.json",
       d + "/kind5.json: not a growbench results or baseline file (kind 5, expected 'growbench-results' or "
           "'growbench-baseline')"},
      {d + "/overflow.json", d + "/overflow.json:1:62: invalid JSON: number overflow parsing '1e400'; expected a "
                                 "number within a double's range"},
      {d + "/idnum.json", d + "/idnum.json: at trials[0].id: expected a string, got number"},
      {d + "/adir", d + "/adir: is a directory, expected a file"},
  };
  for (const auto& c : cases)
    for (const std::string& args : {"compare " + c.file + " " + ok, "compare " + ok + " " + c.file}) {
      const auto r = growbench(args);
      EXPECT_EQ(r.status, 2) << args << ": " << r.out;
      EXPECT_TRUE(has(r.out, "growbench: error: " + c.expect)) << args << ": " << r.out;
    }
  for (const char* t : {"nan", "-1", "inf"}) {
    const auto r = growbench(std::string("compare --threshold ") + t + " " + ok + " " + ok);
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_TRUE(has(r.out, std::string("--threshold: expected a finite number in [0, 1e+06], got '") + t + "'"))
        << r.out;
  }
}

TEST(ExitStatus, AnOutputThatCannotBeWrittenIsTwoNeverASuccess) {
  const auto dir = test::temp_dir("exit_output");
  const std::string d = dir.string();
  const std::string results = write_results(dir / "results.json", "0123456789abcdef");
  fs::create_directories(dir / "adir");
  auto r = growbench("merge " + results + " --out /dev/full");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, "growbench: error: /dev/full: cannot write: No space left on device")) << r.out;
  EXPECT_FALSE(has(r.out, "merged")) << r.out;
  // Written to, not replaced: the device is still a device.
  struct stat st {};
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  r = growbench("merge " + results + " --out " + d + "/adir");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, "growbench: error: " + d + "/adir: is a directory, expected a file to write")) << r.out;
  EXPECT_FALSE(has(r.out, "merged")) << r.out;
  EXPECT_TRUE(fs::is_empty(dir / "adir"));
  r = growbench("merge " + results + " --out " + d + "/results.json/x.json");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, d + "/results.json: cannot create the directory")) << r.out;
  r = growbench("baseline update " + results + " --baseline " + d + "/adir");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, d + "/adir: is a directory")) << r.out;
  r = growbench("run -q -a spacecol -s wall --max-steps 1 -o /dev/full");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, "growbench: error: /dev/full: cannot create the directory: Not a directory")) << r.out;
}

TEST(ExitStatus, NumericOptionsOutOfRangeAreRefusedNotReplaced) {
  const auto dir = test::temp_dir("exit_values");
  const std::string results = write_results(dir / "results.json", "0123456789abcdef");
  const struct {
    std::string args, expect;
  } cases[] = {
      {"run -a spacecol -s wall --voxel-size nan",
       "--voxel-size: expected 0 or a finite number in [1e-06, 1e+06], got 'nan'"},
      {"run -a spacecol -s wall --voxel-size -1",
       "--voxel-size: expected 0 or a finite number in [1e-06, 1e+06], got '-1'"},
      {"run -a spacecol -s wall --voxel-size 1e-9",
       "--voxel-size: expected 0 or a finite number in [1e-06, 1e+06], got '1e-9'"},
      {"run -a spacecol -s wall --sides 2", "--sides: expected an integer in [3, 64], got '2'"},
      {"run -a spacecol -s wall --budget-nodes -1",
       "--budget-nodes: expected an integer in [0, 1000000000000], got '-1'"},
      {"run -a spacecol -s wall --time-limit -5", "--time-limit: expected a finite number in [0, 1e+09], got '-5'"},
      {"run -a spacecol -s wall --time-limit nan", "--time-limit: expected a finite number in [0, 1e+09], got 'nan'"},
      {"run -a spacecol -s wall --threads -1", "--threads: expected an integer in [0, 1024], got '-1'"},
      {"run -a spacecol -s wall --seed -1", "--seed: expected an integer in [0, 18446744073709551615], got '-1'"},
      {"run -a spacecol -s wall --max-steps -1", "--max-steps: expected an integer in [0, 2147483647], got '-1'"},
      {"lsystem bush --limit -1", "--limit: expected an integer in [0, 18446744073709551615], got '-1'"},
      {"render " + dir.string() + " --width -5", "--width: expected an integer in [0, 16384], got '-5'"},
      {"ab /bin/true /bin/true s.json --effect nan", "--effect: expected a finite number in (1, 100], got 'nan'"},
      {"compare " + results + " " + results + " --floor -1",
       "--floor: expected a finite number in [0, 1e+18], got '-1'"},
  };
  for (const auto& c : cases) {
    const auto r = growbench(c.args);
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.out;
    EXPECT_TRUE(has(r.out, c.expect)) << c.args << ": " << r.out;
  }
}

TEST(ExitStatus, ReportOnBadInputIsTwoWithoutATraceback) {
  const auto dir = test::temp_dir("exit_report");
  const std::string d = dir.string();
  test::write_text(dir / "malformed.json", "{\n");
  test::write_text(dir / "kind5.json", R"({"kind": 5, "trials": []})");
  test::write_text(dir / "idnum.json", R"({"kind": "growbench-results", "trials": [{"id": 5}]})");
  test::write_text(dir / "utf8.json", "{\"kind\": \"growbench-results\", \"trials\": [], \"x\": \"\xff\"}");
  fs::create_directories(dir / "adir");
  for (const char* f : {"malformed.json", "kind5.json", "idnum.json", "utf8.json", "adir"}) {
    const auto r = growbench("report " + d + "/" + f + " -o " + d + "/out");
    EXPECT_EQ(r.status, 2) << f << ": " << r.out;
    EXPECT_TRUE(has(r.out, "growbench: error: " + d + "/" + f)) << f << ": " << r.out;
    EXPECT_FALSE(has(r.out, "Traceback")) << f << ": " << r.out;
  }
  // The scripts themselves, as a user may run them: bad input is 2 with a message, not a traceback's 1.
  const std::string py = std::string("/usr/bin/python3 ") + GROWBENCH_SOURCE_DIR + "/reports/";
  const auto r = run_command(py + "report.py " + d + "/utf8.json --out " + d + "/out");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, "report: error: " + d + "/utf8.json: not valid JSON: byte")) << r.out;
  const auto h = run_command(py + "history.py " + d + "/adir --out " + d + "/hist");
  EXPECT_EQ(h.status, 2) << h.out;
  EXPECT_TRUE(has(h.out, "history: error: " + d + "/adir: no history files")) << h.out;
}

}  // namespace
}  // namespace growbench
