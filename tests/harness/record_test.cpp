// The typed record (harness/record/record.hpp): what is written reads back the same, and what does not fit is an
// error that names the file and the JSON path.
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <iterator>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/json_util.hpp"
#include "harness/record/files.hpp"
#include "harness/record/record.hpp"
#include "harness/report/columns.hpp"
#include "harness/report/summary.hpp"
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
  (*s.phases)[Phase::growth] = PhaseMeasures{0.25, 0.5, 1u << 20, true, 10, 4096, {}, {}, {}, {}, {}, {}};
  s.launch_s = 0.001;
  s.geometry_hash = "fedcba9876543210";
  c.samples.push_back(s);
  TrialResults& plant = c.results.plant.emplace();
  plant.geometry_hash = "fedcba9876543210";
  plant.counts = Counts{10, 9, 2, 2, 0, 100, 50};
  plant.metrics = json{{"coverage", 0.5}, {"bbox_min", {0.0, 1.0, 2.0}}};
  plant.stopped_by = "finished";
  c.results.scene_hash = "00112233445566ff";
  c.results.alloc.emplace()[Phase::growth] = AllocCount{10, 4096};
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
  const PhaseMeasures* g = r.trials[0].samples[0].phases->find(Phase::growth);
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->wall_s, 1.0);
  EXPECT_EQ(g->peak_rss_bytes, 1000000u);
  EXPECT_EQ(r.trials[0].samples[0].phases->find(Phase::meshing), nullptr);
  EXPECT_EQ(r.schema_version, kSchemaVersion);
  EXPECT_EQ(r.mode, "timing");
}

TEST(Record, AlgorithmFilesRoundTripAndAreLeftOutWhenNone) {
  const auto dir = test::temp_dir("record_algorithm_files");
  TrialRecord rec;
  rec.results.output_bytes.obj = 100;
  rec.results.output_bytes.algorithm_files = {{"texture.png", 5000000000u}, {"skeleton.svg", 7}};
  const json j = to_json(rec);
  EXPECT_EQ(j["output_bytes"]["algorithm_files"], json({{"skeleton.svg", 7}, {"texture.png", 5000000000u}}));
  // Read back from a record file, as `growbench render` and the suite read them.
  const TrialRecord back = read_trial_record(test::write_text(dir / "record.json", j.dump()));
  EXPECT_EQ(back.results.output_bytes.algorithm_files, rec.results.output_bytes.algorithm_files);
  EXPECT_EQ(back.results.output_bytes.obj, 100u);
  // A suite cell carries them in its results.
  ResultsFile r = small_results();
  r.trials[0].results.plant->output_bytes = rec.results.output_bytes;
  const json rj = to_json(r);
  EXPECT_EQ(rj["trials"][0]["output_bytes"]["algorithm_files"]["texture.png"], 5000000000u);
  EXPECT_EQ(to_json(from_json<ResultsFile>(rj, "results.json")), rj);
  // An algorithm that writes no files of its own leaves the key out, as records before it did.
  rec.results.output_bytes.algorithm_files.clear();
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

TEST(Record, PhasesInPipelineOrder) {
  Phases p;
  p[Phase::metrics] = PhaseMeasures{};
  p[Phase::exporting] = PhaseMeasures{};
  p[Phase::scene_load] = PhaseMeasures{};
  std::vector<std::string> names;
  p.each([&](Phase phase, const PhaseMeasures&) { names.emplace_back(phase_name(phase)); });
  EXPECT_EQ(names, (std::vector<std::string>{"scene_load", "export", "metrics"}));
  const json j = to_json(p);
  EXPECT_EQ(j.size(), 3u);
  EXPECT_TRUE(j.contains("export"));
  for (std::size_t i = 0; i < kPhaseCount; ++i) EXPECT_EQ(phase_named(kPhaseNames[i]), kPhases[i]);
  EXPECT_EQ(phase_named("exporting"), std::nullopt);
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

// results.schema.json is generated from the declarations: the committed file is what this binary declares.
TEST(Record, SchemaFileIsGenerated) {
  const std::string path = std::string(GROWBENCH_SOURCE_DIR) + "/harness/record/results.schema.json";
  std::ifstream in(path);
  ASSERT_TRUE(in) << path;
  const json committed = json::parse(in);
  EXPECT_TRUE(committed == results_schema())
      << path << " differs from the record declarations: run `make schema` and commit it";
  // The writer and the schema agree field for field: every key a full record writes is a property.
  const json defs = results_schema()["$defs"];
  ResultsFile r = small_results();
  r.trials[0].results.plant->organs =
      OrganPassRecord{json{{"placement", "avoid"}}, 3, 1, 2, {{"leaf", {2, 1, 0}}, {"flower", {1, 0, 2}}}};
  const json cell = to_json(r)["trials"][0];
  for (const auto& [k, v] : cell.items()) EXPECT_TRUE(defs["cell"]["properties"].contains(k)) << k;
  // What only ok cells carry is required of them, and of no other.
  const json then = defs["cell"]["then"]["required"];
  for (const char* k : {"geometry_hash", "counts", "output_bytes", "curve", "scene_hash", "alloc"})
    EXPECT_NE(std::find(then.begin(), then.end(), k), then.end()) << k;
  const json always = defs["cell"]["required"];
  EXPECT_EQ(std::find(always.begin(), always.end(), "geometry_hash"), always.end());
  EXPECT_EQ(defs["results"]["properties"]["schema_version"]["const"], kSchemaVersion);
  EXPECT_EQ(defs["spec"]["properties"]["sides"]["maximum"], 64);
}

// A projection copies each field of the same key, looking into inline structs: a baseline cell is its cell's
// gated fields, whatever field is added to either.
TEST(Record, ABaselineCellIsItsCellsFieldsOfTheSameKeys) {
  const ResultsFile r = small_results();
  const SuiteCell& c = r.trials[0];
  const BaselineCell b = baseline_cell_of(c);
  EXPECT_EQ(b.id, c.id);
  EXPECT_EQ(b.status, "ok");
  EXPECT_EQ(b.geometry_hash, c.results.plant->geometry_hash);
  EXPECT_EQ(b.counts, c.results.plant->counts);
  EXPECT_EQ(b.metrics, c.results.plant->metrics);
  EXPECT_EQ(b.threads, c.results.plant->threads);
  EXPECT_EQ(b.alloc, c.results.alloc);
  EXPECT_FALSE(b.instructions);
  // A cell without results (pending, failed) projects none.
  SuiteCell pending = c;
  pending.results = {};
  pending.status = "pending";
  const BaselineCell p = baseline_cell_of(pending);
  EXPECT_FALSE(p.geometry_hash);
  EXPECT_FALSE(p.counts);
  EXPECT_FALSE(p.alloc);
}

// Merging takes every present field of a cell's results, the organ pass's included (a field the copy once
// left out).
TEST(Record, TakingACellsResultsTakesEveryField) {
  CellResults from = small_results().trials[0].results;
  from.plant->organs = OrganPassRecord{json{{"placement", "avoid"}}, 231, 4, 5, {{"leaf", {231, 4, 5}}}};
  from.instructions.emplace()[Phase::growth] = 12345;
  CellResults to;
  take_present(to, from);
  EXPECT_EQ(to_json(to), to_json(from));
  EXPECT_EQ(to.plant->organs->placed, 231u);
}

// results.csv: a row per repetition, a column per field named by its JSON path; a failed repetition's row
// has no plant results.
TEST(Record, CsvColumnsAreJsonPaths) {
  ResultsFile r = small_results();
  SuiteSample failed;
  failed.repetition = 1;
  failed.status = "crashed";
  failed.message = "signal 11, \"SIGSEGV\"";
  r.trials[0].samples.push_back(failed);
  const std::string csv = results_csv(r);
  std::vector<std::string> lines;
  std::istringstream in(csv);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 3u) << csv;
  std::vector<std::string> head;
  std::istringstream hs(lines[0]);
  for (std::string c; std::getline(hs, c, ',');) head.push_back(c);
  auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(head.begin(), head.end(), name) - head.begin());
  };
  for (const char* k : {"id", "counts.nodes", "metrics.coverage", "alloc.growth.count", "sample.phases.growth.wall_s",
                        "sample.repetition", "sample.status", "geometry_hash", "scene_hash"})
    EXPECT_LT(column(k), head.size()) << k << " in " << lines[0];
  EXPECT_EQ(column("metrics.bbox_min"), head.size()) << "arrays are not columns";
  EXPECT_EQ(column("spec.algorithm"), head.size()) << "the spec is not a column";
  EXPECT_NE(lines[1].find(",10,"), std::string::npos) << lines[1];  // the ok row's node count
  EXPECT_EQ(lines[2].find("fedcba9876543210,"), lines[2].find("fedcba9876543210,"));
  EXPECT_EQ(lines[2].find("fedcba9876543210"), std::string::npos) << "a failed row shows no plant: " << lines[2];
  EXPECT_NE(lines[2].find("\"signal 11, \"\"SIGSEGV\"\"\""), std::string::npos) << lines[2];
}

// A label or message that a spreadsheet would run as a formula is written as text; numbers stay numbers.
TEST(Record, CsvTextThatLooksLikeAFormulaIsWrittenAsText) {
  ResultsFile r = small_results();
  r.trials[0].label = "=HYPERLINK(\"http://x\")";
  r.trials[0].scene = "@SUM(A1)";
  r.trials[0].results.plant->metrics = json{{"coverage", -0.5}, {"note", "-2+3"}};
  const std::string csv = results_csv(r);
  EXPECT_NE(csv.find(",\"'=HYPERLINK(\"\"http://x\"\")\","), std::string::npos) << csv;
  EXPECT_NE(csv.find(",'@SUM(A1),"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",'-2+3"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",-0.5"), std::string::npos) << csv;
  EXPECT_EQ(csv.find(",="), std::string::npos) << csv;
  EXPECT_EQ(csv.find(",@"), std::string::npos) << csv;
}

// Every cell id a results file or journal gives names a folder inside it: render and report write there.
TEST(Record, ACellIdThatLeavesItsFolderIsRefused) {
  EXPECT_EQ(cell_id_problem("a/wall/s1"), "");
  EXPECT_EQ(cell_id_problem("spacecol/wall/s2/point_count=10,radius=0.5"), "");
  for (const char* id :
       {"../../s1", "a/../s1", "/etc/s1", "a//s1", "a/./s1", "a/wall/", "", "a/w all/s1", "a/wall\n#x/s1"})
    EXPECT_NE(cell_id_problem(id), "") << id;
  EXPECT_EQ(safe_name(".."), "__");
  EXPECT_EQ(safe_name("."), "_");
  EXPECT_EQ(safe_name(""), "");
  EXPECT_EQ(safe_name("../x"), "___x");
  EXPECT_EQ(safe_name(".hidden.v2"), "_hidden.v2");
  const auto dir = test::temp_dir("cell_ids");
  nlohmann::json j = to_json(small_results());
  j["trials"][0]["id"] = "../../victim/s1";
  const std::string path = test::write_text(dir / "results.json", j.dump());
  EXPECT_EQ(test::error_of([&] { read_results(path); }),
            path +
                ": at /trials/0/id: cell id \"../../victim/s1\" is not a path of plain names inside the folder "
                "(expected LABEL/SCENE/sSEED, each of [A-Za-z0-9-_.=,], none empty or starting with '.')");
}

// A symlink planted where a file's temporary copy goes does not redirect the write: the link is replaced,
// and its target is left alone.
TEST(Record, AWriteDoesNotFollowALinkPlantedAtItsTemporaryName) {
  const auto dir = test::temp_dir("planted_tmp");
  const std::string victim = test::write_text(dir / "victim.txt", "untouched");
  std::filesystem::create_symlink(victim, dir / "results.json.tmp");
  write_file_atomic((dir / "results.json").string(), "{}", 2);
  EXPECT_EQ(read_text_file(victim), "untouched");
  EXPECT_EQ(read_text_file((dir / "results.json").string()), "{}");
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(dir / "results.json.tmp")));
}

// A spec made in code is held to the declared ranges, as the command line and suite files are.
TEST(Record, ASpecOutsideItsDeclaredRangesIsRefused) {
  TrialSpec s;
  s.algorithm = "spacecol";
  s.scene = "wall";
  EXPECT_NO_THROW(check_trial_spec(s));
  s.sides = 2;
  EXPECT_EQ(test::error_of([&] { check_trial_spec(s); }),
            "the trial spec: sides: expected an integer in [3, 64], got 2");
  s.sides = 6;
  s.voxel_size = 1e-9;
  EXPECT_EQ(test::error_of([&] { check_trial_spec(s); }),
            "the trial spec: voxel_size: expected 0 or a number in [1e-06, 1e+06], got 1e-09");
  s.voxel_size = 0.0;
  s.seed_at = {{0.0, 2e9, 0.0}};
  EXPECT_EQ(test::error_of([&] { check_trial_spec(s); }),
            "the trial spec: seed_at: expected a number in [-1e+09, 1e+09], got 2000000000.0");
  // Read from a file, a value out of range names its path.
  json j = to_json(TrialSpec{});
  j["threads"] = 5000;
  EXPECT_EQ(test::error_of([&] { (void)from_json<TrialSpec>(j, "spec.json"); }),
            "spec.json: at threads: expected an integer in [0, 1024], got 5000");
}

// Terminal text: CJK characters count two columns, paragraphs break at spaces within the width.
TEST(Columns, WrapAndTableKeepToTheirWidth) {
  EXPECT_EQ(display_width("abc"), 3u);
  EXPECT_EQ(display_width("\xe6\xa4\x8d\xe7\x89\xa9"), 4u);  // two CJK characters
  EXPECT_EQ(wrap_text("aa bb cc dd", "> ", "  ", 8), "> aa bb\n  cc dd\n");
  EXPECT_EQ(wrap_text("averyveryverylongword x", "", "", 8), "averyver\nyverylon\ngword x\n");  // cut at the width
  // A path is cut after a folder; line breaks, tabs and other control characters separate words.
  EXPECT_EQ(wrap_text("see /tmp/abc/defgh/x.so now", "", "", 12), "see /tmp/\nabc/defgh/\nx.so now\n");
  EXPECT_EQ(wrap_text("{none|crash|hang|oom}", "", "  ", 12), "{none|crash|\n  hang|oom}\n");
  EXPECT_EQ(wrap_text("a\nb\tc\x1b\x7f d\r\n", "", "", 80), "a b c d\n");
  EXPECT_EQ(wrap_text("", "> ", "  ", 8), "> \n");
  // A first part wider than the rest sends a word that fits the other lines to the next line.
  EXPECT_EQ(wrap_text("abcdef", "long head: ", "  ", 10), "long head: \n  abcdef\n");
  TextTable t{{"cell", "n", "time"}, {{"a/s1", "10", "1 ms"}, {"a-very-long-label-that-does-not-fit/s1", "2", "3 ms"}}};
  EXPECT_EQ(t.render(20),
            "cell   n  time\n"
            "a/s1  10  1 ms\n"
            "a-very-long-label-th\n"
            "at-does-not-fit/s1\n"
            "       2  3 ms\n");
}

// `growbench summary` fits a 100-column terminal, whatever the names and numbers.
TEST(Columns, TheSummaryFitsAHundredColumns) {
  ResultsFile r = small_results();
  r.suite.name = std::string(90, 's') + " with a long name";
  SuiteCell wide = r.trials[0];
  wide.scene = std::string(120, 'w');
  wide.label = std::string(70, 'x') + "\xe6\xa4\x8d\xe7\x89\xa9";
  wide.id = "x/wall/s1/k=1";
  wide.status = "invalid_input";
  wide.message = std::string(300, 'm');
  r.trials.push_back(wide);
  const std::string text = summarize_results(r);
  test::expect_lines_fit(text, "summary");
  EXPECT_GT(std::count(text.begin(), text.end(), '\n'), 10);
  // A name that fits a line is never cut: its row's name has a line of its own.
  EXPECT_NE(text.find("\n" + wide.label + "/s1/k=1\n"), std::string::npos) << text;
  EXPECT_NE(text.find("== scene " + std::string(91, 'w') + "\n   " + std::string(29, 'w') + "\ncell"),
            std::string::npos)
      << text;
}

}  // namespace
}  // namespace growbench
