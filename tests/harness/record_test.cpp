// The typed record (harness/record/record.hpp): what is written reads back the same, and what does not fit is an
// error that names the file and the JSON path.
#include <filesystem>
#include <fstream>
#include <iterator>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "harness/record/files.hpp"
#include "harness/record/record.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {
using json = nlohmann::json;

ResultsFile small_results() {
  ResultsFile r;
  r.suite = {"t", "t.json", "a test"};
  r.suite_hash = "0123456789abcdef";
  r.repetitions = 1;
  r.context.cpu_model = "Test CPU";
  r.context.commit_time = 1700000000;
  SuiteCell c;
  c.id = "a/wall/s1";
  c.label = c.algorithm = "a";
  c.scene = c.scene_spec = "wall";
  c.spec.algorithm = "a";
  c.spec.scene = "wall";
  c.spec.seed_at = {{0.5, 1.0, -2.0}};
  c.status = "ok";
  SuiteSample s;
  s.status = "ok";
  s.phases.emplace();
  s.phases->growth = PhaseMeasures{0.25, 0.5, 1u << 20, true, 10, 4096, {}, {}, {}, {}, {}, {}};
  s.launch_s = 0.001;
  c.samples.push_back(s);
  c.results.geometry_hash = "fedcba9876543210";
  c.results.counts = Counts{10, 9, 2, 2, 0, 100, 50};
  c.results.metrics = json{{"coverage", 0.5}, {"bbox_min", {0.0, 1.0, 2.0}}};
  c.results.alloc = AllocByPhase{{"growth", {10, 4096}}};
  r.trials.push_back(c);
  return r;
}

json results_json() {
  return to_json(small_results());
}

std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string error_of(const json& j) {
  try {
    (void)from_json<ResultsFile>(j, "results.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Record, WhatIsWrittenReadsBackTheSame) {
  const json j = results_json();
  EXPECT_EQ(to_json(from_json<ResultsFile>(j, "results.json")), j);
  // Absent optional fields stay absent; the nullable commit time is written as null.
  EXPECT_FALSE(j["trials"][0].contains("message"));
  EXPECT_FALSE(j["trials"][0]["samples"][0].contains("teardown_s"));
  EXPECT_EQ(j["trials"][0]["samples"][0]["phases"].size(), 1u);
  ResultsFile r;
  EXPECT_TRUE(to_json(r)["context"]["commit_time"].is_null());
  // The committed baseline, field for field.
  const std::string path = std::string(GROWBENCH_SOURCE_DIR) + "/reports/baselines/quick.json";
  std::ifstream in(path);
  EXPECT_EQ(to_json(read_baseline(path)), json::parse(in));
}

TEST(Record, ErrorsNameTheFileAndThePath) {
  json j = results_json();
  j["trials"][0]["samples"][0]["phases"]["growth"]["wall_s"] = "fast";
  EXPECT_EQ(error_of(j), "results.json: at trials[0].samples[0].phases.growth.wall_s: expected a number, got \"fast\"");
  j = results_json();
  j["trials"][0]["samples"][0]["phases"]["growth"]["wal_s"] = 0.1;
  EXPECT_EQ(
      error_of(j),
      "results.json: at trials[0].samples[0].phases.growth.wal_s: unknown field 'wal_s' (did you mean 'wall_s'?)");
  j = results_json();
  j["trials"][0]["counts"]["nodes"] = -1;
  EXPECT_EQ(error_of(j), "results.json: at trials[0].counts.nodes: expected a non-negative integer, got -1");
  j["trials"][0]["counts"]["nodes"] = 1.5;
  EXPECT_EQ(error_of(j), "results.json: at trials[0].counts.nodes: expected a non-negative integer, got 1.5");
  j = results_json();
  j.erase("kind");
  EXPECT_EQ(error_of(j), "results.json: at the top level: expected the field 'kind'");
  j = results_json();
  j["trials"][0]["spec"]["seed_at"][0] = {1.0, 2.0};
  EXPECT_EQ(error_of(j), "results.json: at trials[0].spec.seed_at[0]: expected an array of 3, got 2 items");
}

TEST(Record, PartialFilesReadWithDefaults) {
  // Hand-written files (tests, other tools) may leave fields out; a whole number written as a float is an integer.
  const json j = {
      {"kind", "growbench-results"},
      {"trials", {{{"id", "a"}, {"samples", {{{"phases", {{"growth", {{"wall_s", 1}, {"peak_rss_bytes", 1e6}}}}}}}}}}}};
  const ResultsFile r = from_json<ResultsFile>(j, "partial.json");
  ASSERT_EQ(r.trials.size(), 1u);
  const PhaseMeasures* g = r.trials[0].samples[0].phases->find("growth");
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->wall_s, 1.0);
  EXPECT_EQ(g->peak_rss_bytes, 1000000u);
  EXPECT_EQ(r.trials[0].samples[0].phases->find("meshing"), nullptr);
  EXPECT_EQ(r.schema_version, kSchemaVersion);
  EXPECT_EQ(r.mode, "timing");
}

TEST(Record, AlgorithmFilesRoundTripAndAreLeftOutWhenNone) {
  const auto dir = test::temp_dir("record_algorithm_files");
  TrialRecord rec;
  rec.output_bytes.obj = 100;
  rec.output_bytes.algorithm_files = {{"texture.png", 5000000000u}, {"skeleton.svg", 7}};
  const json j = to_json(rec);
  EXPECT_EQ(j["output_bytes"]["algorithm_files"], json({{"skeleton.svg", 7}, {"texture.png", 5000000000u}}));
  // Read back from a record file, as `growbench render` and the suite read them.
  const TrialRecord back = read_trial_record(test::write_text(dir / "record.json", j.dump()));
  EXPECT_EQ(back.output_bytes.algorithm_files, rec.output_bytes.algorithm_files);
  EXPECT_EQ(back.output_bytes.obj, 100u);
  // A suite cell carries them in its results.
  ResultsFile r = small_results();
  r.trials[0].results.output_bytes = rec.output_bytes;
  const json rj = to_json(r);
  EXPECT_EQ(rj["trials"][0]["output_bytes"]["algorithm_files"]["texture.png"], 5000000000u);
  EXPECT_EQ(to_json(from_json<ResultsFile>(rj, "results.json")), rj);
  // An algorithm that writes no files of its own leaves the key out, as records before it did.
  rec.output_bytes.algorithm_files.clear();
  EXPECT_FALSE(to_json(rec)["output_bytes"].contains("algorithm_files"));
  // A size that is not a byte count is an error at its path.
  json bad = j;
  bad["output_bytes"]["algorithm_files"]["texture.png"] = "5 GB";
  try {
    (void)from_json<TrialRecord>(bad, "record.json");
    FAIL() << "a size as a string was read";
  } catch (const InputError& e) {
    EXPECT_EQ(
        std::string(e.what()),
        "record.json: at output_bytes.algorithm_files.texture.png: expected a non-negative integer, got \"5 GB\"");
  }
}

TEST(Record, PhasesInTheOrderTheJsonHoldsThem) {
  Phases p;
  p.scene_load = PhaseMeasures{};
  p.exporting = PhaseMeasures{};
  p.growth = PhaseMeasures{};
  std::vector<std::string> names;
  p.each([&](std::string_view n, const PhaseMeasures&) { names.emplace_back(n); });
  EXPECT_EQ(names, (std::vector<std::string>{"export", "growth", "scene_load"}));
  EXPECT_EQ(to_json(p).begin().key(), "export");
}

TEST(Record, InputFilesThatCannotBeReadNameTheFileAndWhy) {
  const auto dir = test::temp_dir("record_input");
  const std::string d = dir.string();
  std::filesystem::create_directories(dir / "adir");
  test::write_text(dir / "overflow.json", R"({"kind": "growbench-results", "trials": [{"id": "a", "seed": 1e400}]})");
  test::write_text(dir / "kind5.json", R"({"kind": 5, "trials": []})");
  test::write_text(dir / "newer.json", R"({"kind": "growbench-results", "schema_version": 2, "new_field": 1})");
  auto error = [](const std::string& path) { return test::error_of([&] { (void)read_results(path); }); };
  EXPECT_EQ(error(d + "/adir"), d + "/adir: is a directory, expected a file");
  EXPECT_EQ(error("/dev/zero"), "/dev/zero: is a device, expected a file");
  EXPECT_EQ(error(d + "/missing.json"), d + "/missing.json: cannot open: No such file or directory");
  EXPECT_EQ(error(d + "/overflow.json"), d + "/overflow.json:1:62: invalid JSON: number overflow parsing '1e400'; "
                                             "expected a number within a double's range");
  EXPECT_EQ(error(d + "/kind5.json"),
            d + "/kind5.json: not a growbench results file (kind 5, expected 'growbench-results')");
  // The version is checked before the fields: a newer file's new field is not called a mistake.
  EXPECT_EQ(error(d + "/newer.json"),
            d + "/newer.json: schema_version 2 is newer than this growbench reads (1); use a newer growbench");
}

TEST(Record, InvalidUtf8IsWrittenReplacedInsteadOfThrowing) {
  // A trial's message quoting half of a two-byte character (an L-system error quoting one byte of 'é').
  SuiteSample sample;
  sample.status = "invalid_input";
  sample.message = "unknown symbol '\xc3'";
  const JournalEntry e{"a/wall/s1", sample, {}};
  const json j = to_json(e);
  EXPECT_THROW((void)j.dump(), json::type_error);  // nlohmann's default: type_error.316, the lost journal line
  const std::string line = json_text(j, -1);
  EXPECT_NE(line.find("unknown symbol '\xef\xbf\xbd'"), std::string::npos) << line;  // U+FFFD
  EXPECT_EQ(line.back(), '\n');
  const auto dir = test::temp_dir("record_utf8");
  const auto entries = read_journal(test::write_text(dir / "journal.jsonl", line + line));
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[1].sample.message, "unknown symbol '\xef\xbf\xbd'");
}

// A kill can cut the journal's last line at any byte. Resuming sets a torn line aside (PATH.torn) and cuts
// it off, keeps a line that lacks only its newline, and the next append starts on a fresh line: every whole
// entry reads back, and only the torn one's trial runs again.
TEST(Record, AJournalCutAtEveryByteOfItsLastLineReadsBackEveryWholeEntry) {
  const auto dir = test::temp_dir("record_torn");
  const std::string path = (dir / "journal.jsonl").string();
  const ResultsFile r = small_results();
  std::vector<JournalEntry> e;
  for (int k = 0; k < 4; ++k)
    e.push_back({fmt::format("a/wall/s{}", k), r.trials[0].samples[0], k == 2 ? r.trials[0].results : CellResults{}});
  std::vector<std::string> lines;
  for (const auto& x : e) lines.push_back(json_text(to_json(x), -1));
  const std::string last = lines[2].substr(0, lines[2].size() - 1);  // without its newline
  for (std::size_t cut = 0; cut <= last.size(); ++cut) {
    std::filesystem::remove(path + ".torn");
    test::write_text(path, lines[0] + lines[1] + last.substr(0, cut));
    const std::string torn = repair_journal(path);
    append_to_file(path, lines[3]);  // the resumed run's first entry
    const bool whole = cut == last.size();
    const bool cut_short = cut > 0 && !whole;
    EXPECT_EQ(torn, cut_short ? last.substr(0, cut) : "") << cut;
    EXPECT_EQ(file_text(path), lines[0] + lines[1] + (whole ? lines[2] : "") + lines[3]) << cut;
    EXPECT_EQ(std::filesystem::exists(path + ".torn"), cut_short) << cut;
    if (cut_short) {
      EXPECT_EQ(file_text(path + ".torn"), last.substr(0, cut) + "\n") << cut;
    }
    std::vector<std::string> ids;
    for (const auto& x : read_journal(path)) ids.push_back(x.id);
    std::vector<std::string> expected = {"a/wall/s0", "a/wall/s1"};
    if (whole) expected.emplace_back("a/wall/s2");
    expected.emplace_back("a/wall/s3");
    EXPECT_EQ(ids, expected) << cut;
  }
}

TEST(Record, FilesAreCheckedForKindAndVersion) {
  const auto dir = test::temp_dir("record_files");
  json j = results_json();
  j["schema_version"] = kSchemaVersion + 1;
  const std::string newer = test::write_text(dir / "newer.json", j.dump());
  try {
    (void)read_results(newer);
    FAIL() << "a newer schema_version was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is newer than this growbench reads"), std::string::npos) << e.what();
  }
  const std::string baseline = test::write_text(dir / "b.json", R"({"kind": "growbench-baseline", "trials": []})");
  EXPECT_THROW((void)read_results(baseline), InputError);
  EXPECT_EQ(read_baseline(baseline).trials.size(), 0u);
  // A journal whose last line a kill cut short: the line is skipped, its trial runs again.
  const JournalEntry e{"a/wall/s1", small_results().trials[0].samples[0], CellResults{}};
  const std::string line = to_json(e).dump();
  const std::string journal = test::write_text(dir / "journal.jsonl", line + "\n" + line.substr(0, 20));
  const auto entries = read_journal(journal);
  ASSERT_EQ(entries.size(), 1u);
  EXPECT_EQ(to_json(entries[0]), to_json(e));
}

}  // namespace
}  // namespace growbench
