// The typed record (harness/record/record.hpp): what is written reads back the same, and what does not fit is an
// error that names the file and the JSON path.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
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
