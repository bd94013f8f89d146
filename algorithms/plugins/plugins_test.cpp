// The plugin boundary: one test per loader error, a plugin written in C grown like a built-in, a suite
// that records a misbehaving plugin and goes on, and spacecol built as a plugin growing the built-in's
// plant bit for bit on every standard scene.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stb_image.h>

#include "algorithms/plugins/loader.hpp"
#include "core/file_hash.hpp"
#include "core/memory.hpp"
#include "harness/record/files.hpp"
#include "harness/record/record.hpp"
#include "harness/run/trial.hpp"
#include "scenes/scene_library.hpp"
#include "scenes/scene_query.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

namespace fs = std::filesystem;

std::string fixture(const std::string& name) {
  return std::string(GROWBENCH_PLUGIN_DIR) + "/test/" + name + ".so";
}
const std::string kSpacecolPlugin = std::string(GROWBENCH_PLUGIN_DIR) + "/spacecol_plugin.so";

// A copy of a fixture under a fresh path: a clash test must not depend on what an earlier test loaded.
std::string copy_of(const std::string& name, const std::string& as) {
  const fs::path p = test::temp_dir("plugin_" + as) / (as + ".so");
  fs::copy_file(fixture(name), p, fs::copy_options::overwrite_existing);
  return p.string();
}

std::string load_error(const std::string& path) {
  return test::error_of([&] { load_plugin(path); });
}

TEST(PluginLoader, MissingFileIsNamed) {
  EXPECT_EQ(load_error("/nonexistent/walker.so"), "/nonexistent/walker.so: no such plugin file");
}

TEST(PluginLoader, AFileThatIsNotASharedLibrary) {
  const std::string p = test::write_text(test::temp_dir("plugin_text") / "notes.so", "not an ELF file\n");
  EXPECT_EQ(load_error(p).rfind(p + ": not a loadable shared library (", 0), 0u) << load_error(p);
}

TEST(PluginLoader, ALibraryWithoutTheEntryPoint) {
  const std::string p = copy_of("no_entry", "no_entry");
  EXPECT_EQ(load_error(p), p + ": no growbench_plugin_entry() entry point; is it a growbench plugin? (see "
                               "docs/plugins.md)");
}

TEST(PluginLoader, AnotherAbiVersionSaysBoth) {
  const std::string p = copy_of("abi_99", "abi_99");
  EXPECT_EQ(load_error(p),
            p + ": built for plugin ABI version 99, but this growbench speaks versions 1 to 3; rebuild it "
                "against this growbench's SDK");
}

TEST(PluginLoader, TheNameOfABuiltIn) {
  const std::string p = copy_of("builtin_name", "builtin_name");
  EXPECT_EQ(load_error(p), p + ": plugin algorithm 'spacecol' has the name of a built-in algorithm");
}

TEST(PluginLoader, TheNameOfAnotherPlugin) {
  const std::string a = copy_of("line", "line_a"), b = copy_of("line", "line_b");
  load_plugin(a);
  EXPECT_EQ(load_error(b), b + ": plugin algorithm 'line' has the name of the plugin loaded from " + a);
}

TEST(PluginLoader, AMalformedParameterTable) {
  const std::string p = copy_of("bad_table", "bad_table");
  EXPECT_EQ(load_error(p),
            p + ": malformed plugin table: parameter 1 ('step'): its default 5 is not a finite value in [0.001, 1]");
}

TEST(PluginLoader, TheSameFileLoadsOnce) {
  const std::string p = copy_of("no_entry", "absent");  // any name: the copy below replaces it
  fs::copy_file(fixture("line"), p, fs::copy_options::overwrite_existing);
  const AlgorithmEntry& one = load_plugin(p);
  const std::size_t loaded = plugin_algorithms().size();
  EXPECT_EQ(&load_plugin(p), &one);
  EXPECT_EQ(&load_plugin(fs::path(p).parent_path().string() + "/./absent.so"), &one);
  EXPECT_EQ(plugin_algorithms().size(), loaded);
}

TEST(PluginLoader, ErrorsExitTwoFromTheCommandLine) {
  for (const std::string& cmd : std::vector<std::string>{"list --plugin /nonexistent/walker.so",
                                                         "run -a line -s wall --plugin " + fixture("abi_99"),
                                                         "list --plugin " + fixture("bad_table")}) {
    const auto r = test::run_growbench(cmd);
    EXPECT_EQ(r.status, 2) << cmd << "\n" << r.out;
    EXPECT_NE(r.out.find("growbench: error: "), std::string::npos) << r.out;
  }
}

TEST(PluginLoader, ListShowsAPluginWithItsTableAndOrigin) {
  const auto r = test::run_growbench("list line --plugin " + fixture("line"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("line  [plugin]"), std::string::npos) << r.out;
  // The origin line wraps at the terminal's width, a path longer than a line cut after a folder.
  test::expect_lines_fit(r.out, "list line");
  EXPECT_NE(test::without_spaces(r.out).find(test::without_spaces("plugin " + fs::canonical(fixture("line")).string() +
                                                                  " (version 1, ABI 1, xxh3 ")),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("length"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("misbehave, for tests"), std::string::npos) << r.out;
}

TEST(PluginLoader, DirectoriesFromTheEnvironment) {
  const fs::path dir = test::temp_dir("plugin_env");
  fs::copy_file(fixture("line"), dir / "line.so");
  const auto r = test::run_growbench("list line");
  EXPECT_EQ(r.status, 2) << r.out;  // not loaded without it
  ::setenv("GROWBENCH_PLUGIN_PATH", dir.c_str(), 1);
  const auto found = test::run_growbench("list line");
  ::unsetenv("GROWBENCH_PLUGIN_PATH");
  EXPECT_EQ(found.status, 0) << found.out;
  EXPECT_NE(found.out.find("line  [plugin]"), std::string::npos) << found.out;
}

// One bad file in GROWBENCH_PLUGIN_PATH ended every command, even `run -a spacecol`: it is a warning naming it.
TEST(PluginLoader, ABadFileInTheEnvironmentsDirectoriesIsAWarning) {
  const fs::path dir = test::temp_dir("plugin_env_bad");
  fs::copy_file(fixture("abi_99"), dir / "abi_99.so");
  test::write_text(dir / "notes.so", "not an ELF file\n");
  fs::copy_file(fixture("line"), dir / "line.so");
  ::setenv("GROWBENCH_PLUGIN_PATH", (dir.string() + ":/nonexistent/plugins").c_str(), 1);
  const auto r = test::run_growbench("list line");
  const auto run = test::run_growbench("run -a spacecol -s wall --max-steps 2 -q -o " +
                                       test::temp_dir("plugin_env_bad_run").string());
  ::unsetenv("GROWBENCH_PLUGIN_PATH");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("line  [plugin]"), std::string::npos) << r.out;  // the good one still loads
  EXPECT_NE(r.out.find("growbench: warning: GROWBENCH_PLUGIN_PATH: skipped: " + (dir / "abi_99.so").string() +
                       ": built for plugin ABI version 99"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("skipped: " + (dir / "notes.so").string() + ": not a loadable shared library"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("skipped: '/nonexistent/plugins' is not a directory"), std::string::npos) << r.out;
  EXPECT_EQ(run.status, 0) << run.out;
}

TrialSpec line_spec(const std::string& scene) {
  TrialSpec spec;
  spec.algorithm = "line";
  spec.scene = scene;
  spec.plugins = {fixture("line")};
  spec.metrics = false;
  return spec;
}

// A plugin in C grows through the host's queries like a built-in, and its record says what ran.
TEST(CPlugin, GrowsAndItsRecordNamesThePlugin) {
  TrialSpec spec = line_spec("wall");
  spec.threads = 1;
  Plant plant;
  const TrialRecord one = run_trial_record(spec, {}, &plant);
  spec.threads = 2;
  const TrialRecord two = run_trial_record(spec);
  EXPECT_EQ(one.results.geometry_hash, two.results.geometry_hash);
  EXPECT_EQ(plant.validate(), "");
  const Scene scene = load_scene("wall");
  EXPECT_EQ(plant.nodes.size(), 20 * scene.seeds.size());    // `length` nodes per seed, nothing in the way
  EXPECT_EQ(plant.organs.size(), scene.seeds.size());        // a leaf at each tip
  EXPECT_EQ(one.results.algorithm_stats.at("steps"), 20.0);  // the 20th step grows nothing and ends growth
  ASSERT_TRUE(one.context.has_value());
  ASSERT_EQ(one.context->plugins.size(), 1u);
  const PluginOrigin& o = one.context->plugins[0];
  EXPECT_EQ(o.name, "line");
  EXPECT_EQ(o.path, fs::canonical(fixture("line")).string());
  EXPECT_TRUE(std::regex_match(o.hash, std::regex("[0-9a-f]{16}"))) << o.hash;
  EXPECT_EQ(o.abi_version, 1u);
  EXPECT_EQ(o.version, "1");
}

// A version-1 plugin still loads under a newer host, is given version 1's host table (the plugin checks
// it), and grows the plant it grew under the version-1 host: this hash is what that host recorded. The wall's
// stalks meet nothing, so their floats are the same in every build; where a stalk stops at a solid (the
// boulder) an inside test within rounding of the rock may go either way under other compiler flags (ASan's).
TEST(CPlugin, AVersionOnePluginGrowsTheSamePlantAsBefore) {
  for (const auto& [scene, hash] : std::vector<std::pair<std::string, std::string>>{{"wall", "f07bc76b318c4df5"}}) {
    TrialSpec spec = line_spec(scene);
    spec.metrics = true;
    const TrialRecord r = run_trial_record(spec);
    EXPECT_EQ(r.results.geometry_hash, hash) << scene;
    ASSERT_TRUE(r.context.has_value());
    EXPECT_EQ(r.context->plugins.at(0).abi_version, 1u);
  }
}

// Version 2 carries what only built-ins could give: organ shapes and tints, named per-node attributes (here
// computed with the host's parallel_for), into the plant, its PLY and its skeleton, the same for 1 and 2 threads.
TEST(CPlugin, VersionTwoCarriesOrganShapesTintsAndNodeAttributes) {
  TrialSpec spec = line_spec("wall");
  spec.algorithm = "line_v2";
  spec.plugins = {fixture("line_v2")};
  spec.threads = 1;
  Plant one, two;
  const TrialRecord r1 = run_trial_record(spec, {}, &one);
  spec.threads = 2;
  spec.out_dir = test::temp_dir("plugin_v2").string();
  const TrialRecord r2 = run_trial_record(spec, {}, &two);
  EXPECT_EQ(r1.results.geometry_hash, r2.results.geometry_hash);
  EXPECT_EQ(r1.context->plugins.at(0).abi_version, 2u);
  EXPECT_EQ(one.organ_shapes, std::vector<std::string>{"blossom"});
  ASSERT_GE(one.organs.size(), 2u);
  for (std::size_t k = 0; k < one.organs.size(); ++k) {
    EXPECT_EQ(one.organs[k].shape, k % 2 == 0 ? 0 : kKindShape) << k;
    EXPECT_EQ(one.organs[k].tint, glm::vec3(1.0f, 0.5f + 0.5f * static_cast<float>(k % 3), 0.25f)) << k;
  }
  ASSERT_EQ(one.node_attributes.size(), 2u);
  EXPECT_EQ(one.node_attributes[0].name, "height");
  EXPECT_EQ(one.node_attributes[1].name, "Cd");
  ASSERT_EQ(one.node_attributes[0].values.size(), one.nodes.size());
  ASSERT_EQ(one.node_attributes[1].values.size(), 3 * one.nodes.size());
  for (std::size_t i = 0; i < one.nodes.size(); ++i) {  // every chunk of the parallel loop ran
    EXPECT_EQ(one.node_attributes[0].values[i], one.nodes[i].position.y) << i;
    EXPECT_EQ(one.node_attributes[1].values[3 * i], 0.2f) << i;
  }
  for (const char* file : {"plant.ply", "skeleton.ply"}) {
    std::ifstream in(fs::path(spec.out_dir) / file, std::ios::binary);
    std::string header(2048, '\0');
    in.read(header.data(), static_cast<std::streamsize>(header.size()));
    EXPECT_NE(header.find("property float height\n"), std::string::npos) << file;
    EXPECT_NE(header.find("property uchar red\n"), std::string::npos) << file;
  }
}

// Version 3 reads the scene's texture coordinates and gives back node groups and a decal. The plugin probes the
// surface frame where the line down -Z through the middle of the uv-cube meets its front face (z = +1 in the
// file), whose corners the file maps to u in [0.375, 0.625] and v in [0.25, 0.5] with u along +X and v along +Y:
// its middle is (0.5, 0.375), and a quarter of u or v spans the face's side. The decal follows that mesh, is
// written as a PNG of the plugin's pixels, and the groups become the skeleton's group property and the OBJ's parts.
TEST(CPlugin, VersionThreeReadsTextureCoordinatesAndGivesGroupsAndADecal) {
  TrialSpec spec = line_spec("mesh:uv-cube");
  spec.algorithm = "line_v3";
  spec.plugins = {fixture("line_v3")};
  spec.out_dir = test::temp_dir("plugin_v3").string();
  Plant plant;
  const TrialRecord r = run_trial_record(spec, {}, &plant);
  EXPECT_EQ(r.context->plugins.at(0).abi_version, 3u);
  const Scene scene = load_scene("mesh:uv-cube");
  const auto& st = r.results.algorithm_stats;
  const auto cube = static_cast<std::size_t>(st.at("uv_mesh"));
  ASSERT_LT(cube, scene.meshes.size());
  EXPECT_EQ(st.at("uv_count"), static_cast<double>(scene.meshes[cube].uvs.size()));
  EXPECT_EQ(st.at("uv_count"), 14.0);  // the file's vt lines
  EXPECT_NEAR(st.at("probe_u"), 0.5, 1e-5);
  EXPECT_NEAR(st.at("probe_v"), 0.375, 1e-5);
  EXPECT_NEAR(st.at("probe_du_x"), 1.0, 1e-5);
  EXPECT_NEAR(st.at("probe_dv_y"), 1.0, 1e-5);
  EXPECT_NEAR(st.at("probe_normal_z"), 1.0, 1e-5);
  const Aabb b = scene.meshes[cube].bounds();
  EXPECT_NEAR(st.at("probe_du_length") * 0.25, b.max.x - b.min.x, 1e-4);
  EXPECT_NEAR(st.at("probe_dv_length") * 0.25, b.max.y - b.min.y, 1e-4);

  ASSERT_EQ(plant.decals.size(), 1u);
  EXPECT_EQ(plant.decals[0].mesh, static_cast<std::int32_t>(cube));
  EXPECT_EQ(plant.decals[0].image, "decal0.png");
  int w = 0, h = 0, n = 0;
  const std::string png = (fs::path(spec.out_dir) / "decal0.png").string();
  std::unique_ptr<unsigned char, void (*)(void*)> px(stbi_load(png.c_str(), &w, &h, &n, 4), stbi_image_free);
  ASSERT_TRUE(px) << png;
  ASSERT_EQ(w, 4);
  ASSERT_EQ(h, 2);
  for (int k = 0; k < 8; ++k) {  // red by column, green by row, as the plugin painted them
    EXPECT_EQ(px.get()[4 * k], 60 * (k % 4)) << k;
    EXPECT_EQ(px.get()[4 * k + 1], 120 * (k / 4)) << k;
    EXPECT_EQ(px.get()[4 * k + 2], 200) << k;
  }

  EXPECT_EQ(plant.group_prefix, "stalk");
  ASSERT_EQ(plant.node_groups.size(), plant.nodes.size());
  for (std::size_t i = 0; i < plant.nodes.size(); ++i)
    EXPECT_EQ(plant.node_groups[i], i == 0 ? -1 : static_cast<std::int32_t>(plant.nodes[i].shoot)) << i;
  std::ifstream in(fs::path(spec.out_dir) / "skeleton.ply", std::ios::binary);
  std::string header(2048, '\0');
  in.read(header.data(), static_cast<std::streamsize>(header.size()));
  EXPECT_NE(header.find("property int group\n"), std::string::npos);
  std::ifstream obj_in(fs::path(spec.out_dir) / "plant.obj");
  const std::string obj((std::istreambuf_iterator<char>(obj_in)), std::istreambuf_iterator<char>());
  for (std::size_t i = 0; i < load_scene("mesh:uv-cube").seeds.size(); ++i)  // a part per stalk, named for it
    EXPECT_NE(obj.find(fmt::format("g branches stalk{}\n", i)), std::string::npos) << i;
}

// Where no mesh has texture coordinates the host says so, and the plugin's planar decal is kept as given. A
// decal the scene cannot hold is the plugin's error, named as such.
TEST(CPlugin, VersionThreeWithoutTextureCoordinatesAndWithABadDecal) {
  TrialSpec spec = line_spec("wall");
  spec.algorithm = "line_v3";
  spec.plugins = {fixture("line_v3")};
  Plant plant;
  const TrialRecord r = run_trial_record(spec, {}, &plant);
  EXPECT_EQ(r.results.algorithm_stats.at("uv_mesh"), -1.0);
  EXPECT_EQ(r.results.algorithm_stats.at("uv_count"), 0.0);
  ASSERT_EQ(plant.decals.size(), 1u);
  EXPECT_EQ(plant.decals[0].mesh, kPlanarDecal);
  const Scene scene = load_scene("wall");
  EXPECT_EQ(plant.decals[0].origin, scene.bounds().min);

  spec.params = {"fault=bad_decal"};
  try {
    run_trial_record(spec);
    ADD_FAILURE() << "a decal on a mesh the scene lacks was taken";
  } catch (const PluginError& e) {
    EXPECT_NE(std::string(e.what()).find("plugin " + fs::canonical(fixture("line_v3")).string() +
                                         ") returned a malformed plant: decal 0 follows mesh 99, but the scene has"),
              std::string::npos)
        << e.what();
  }
}

TEST(CPlugin, ItsErrorsKeepTheirKindAndMessage) {
  TrialSpec spec = line_spec("wall");
  const std::string who = "algorithm 'line' (plugin " + fs::canonical(fixture("line")).string() + ")";
  spec.params = {"fault=input"};
  EXPECT_EQ(test::error_of([&] { run_trial_record(spec); }),
            who + " failed in start: fault=input: this scene will not do");
  spec.params = {"fault=fail"};
  try {
    run_trial_record(spec);
    ADD_FAILURE() << "fault=fail did not fail";
  } catch (const PluginError& e) {
    EXPECT_STREQ(e.what(), (who + " failed in step: fault=fail: gave up").c_str());
  } catch (const std::exception& e) {
    ADD_FAILURE() << "the plugin's own failure was not attributed to it: " << e.what();
  }
  spec.params = {"step=7"};  // validated by the host against the plugin's table, as for a built-in
  EXPECT_NE(test::error_of([&] { run_trial_record(spec); }).find("'step'"), std::string::npos);
}

// A plugin's own failure, or a plant the host refuses, exited 3 calling itself a bug in growbench: it exits 2,
// naming the plugin's file and what was wrong.
TEST(CPlugin, ItsFailuresAreItsOwnOnTheCommandLine) {
  const std::string path = fs::canonical(fixture("line")).string();
  for (const auto& [fault, says] :
       std::vector<std::pair<std::string, std::string>>{{"fail", "failed in step: fault=fail: gave up"},
                                                        {"bad_parent", "handed over an invalid plant: node 0"},
                                                        {"nan_node", "handed over an invalid plant: node "}}) {
    const fs::path out = test::temp_dir("plugin_fault_" + fault);
    const auto r = test::run_growbench(
        fmt::format("run -a line -s wall --plugin {} --set fault={} -o {} -q", path, fault, out.string()));
    EXPECT_EQ(r.status, 2) << fault << ": " << r.out;
    EXPECT_NE(r.out.find("growbench: error: algorithm 'line' (plugin " + path + ") " + says), std::string::npos)
        << fault << ": " << r.out;
    EXPECT_NE(r.out.find("This is the plugin's failure, not growbench's"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("This is a bug in growbench"), std::string::npos) << fault << ": " << r.out;
  }
}

// NaN and infinite inputs to rays, occluded and light_visible aborted the host in Embree: they answer no hit.
TEST(CPlugin, QueriesOnNonFiniteInputAnswerNoHit) {
  TrialSpec spec = line_spec("boulder");
  spec.params = {"fault=nan_query"};
  Plant plant;
  run_trial_record(spec, {}, &plant);  // the plugin fails the trial if any answer was a hit
  EXPECT_GT(plant.nodes.size(), 0u);
}

// --plugin took every following word as another plugin, so `list --plugin X.so line` looked for a file 'line'.
TEST(PluginCli, APluginOptionTakesOneFileAndLeavesThePositionals) {
  const std::string p = fixture("line");
  for (const std::string& command : {"list --plugin " + p + " line", "list --plugin=" + p + " line",
                                     "list --plugin " + p + " --plugin " + kSpacecolPlugin + " line"}) {
    const auto r = test::run_growbench(command);
    EXPECT_EQ(r.status, 0) << command << ": " << r.out;
    EXPECT_NE(r.out.find("line  [plugin]"), std::string::npos) << command << ": " << r.out;
  }
}

// A plugin whose entry() crashed or called exit(0) ended `list`, and `suite` exited 0 with no results: it is
// loaded first in a child, and the command exits 2 naming it.
TEST(PluginLoader, AnEntryPointThatEndsTheProcessIsAnErrorNotTheEnd) {
  for (const auto& [variant, how] :
       std::vector<std::pair<std::string, std::string>>{{"crash_entry", "ended the process with signal 11"},
                                                        {"exit_entry", "ended the process with exit status 0"}}) {
    const std::string p = fixture(variant);
    for (const std::string& command : {"list --plugin " + p, "run -a line -s wall --plugin " + p}) {
      const auto r = test::run_growbench(command);
      EXPECT_EQ(r.status, 2) << command << ": " << r.out;
      EXPECT_NE(r.out.find(p + ": loading it " + how), std::string::npos) << command << ": " << r.out;
    }
  }
}

// A plugin whose entry() closes its descriptors (so the host reads the end of the child's report) and then
// waits forever is ended at the probe's time limit, not waited for.
TEST(PluginLoader, AnEntryPointThatClosesItsDescriptorsAndHangsIsEnded) {
  const std::string p = fixture("hang_entry");
  const auto r = test::run_growbench("list --plugin " + p);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(p + ": loading it did not return within 30 s"), std::string::npos) << r.out;
}

// A plugin that crashes, hangs or runs out of memory in a suite is recorded as such, and the suite goes on.
TEST(CPlugin, ASuiteRecordsAMisbehavingPluginAndGoesOn) {
  const fs::path dir = test::temp_dir("plugin_suite");
  fs::copy_file(fixture("line"), dir / "line.so");
  // Without an address-space limit (AddressSanitizer), fault=oom would take the whole machine.
  const std::string faults = kAddressSpaceLimitWorks
                                 ? R"("crash", "hang", "oom", "fail", "exit3", "long_message", "flood", "none")"
                                 : R"("crash", "hang", "fail", "exit3", "long_message", "flood", "none")";
  test::write_text(dir / "suite.json", fmt::format(R"({{"schema_version": 1, "name": "plugin_faults", "repetitions": 1,
    "warmup": 0, "timeout_s": 5, "memory_limit_mb": 1024, "plugins": ["line.so"], "scenes": ["wall"],
    "algorithms": [{{"name": "line", "sweep": {{"fault": [{}]}}}}]}})",
                                                   faults));
  const auto r =
      test::run_growbench(fmt::format("suite {} -o {} -q", (dir / "suite.json").string(), (dir / "out").string()));
  ASSERT_EQ(r.status, 0) << r.out;
  const ResultsFile res = read_results((dir / "out" / "results.json").string());
  std::map<std::string, std::string> status;
  for (const auto& c : res.trials) status[c.sweep.at("fault").get<std::string>()] = c.status;
  EXPECT_EQ(status["crash"], "crashed");
  EXPECT_EQ(status["hang"], "timeout");
  if (kAddressSpaceLimitWorks) {
    EXPECT_EQ(status["oom"], "out_of_memory");
  }
  EXPECT_EQ(status["fail"], "plugin_error");
  // exit(3) is the trial's own code for out of memory, but the trial never reported it: not a verdict.
  EXPECT_EQ(status["exit3"], "crashed");
  EXPECT_EQ(status["long_message"], "plugin_error");
  EXPECT_EQ(status["none"], "ok");
  // 80 MiB of stderr: the log keeps 64 MiB and says what it dropped; the plant is unharmed.
  EXPECT_EQ(status["flood"], "ok");
  const fs::path flood_log = dir / "out" / "trials" / "line" / "wall" / "s1" / "fault=flood" / "log.txt";
  EXPECT_LE(fs::file_size(flood_log), (64u << 20) + 8192u);
  std::ifstream in(flood_log, std::ios::binary);
  in.seekg(64 << 20);
  const std::string tail{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_NE(tail.find("[growbench: the log passed 67108864 bytes; "), std::string::npos) << tail.substr(0, 200);
  for (const auto& c : res.trials) {
    const std::string message = c.message.value_or("");
    if (c.sweep.at("fault") == "exit3") {
      EXPECT_NE(message.find("exited with status 3 without reporting why"), std::string::npos) << message;
    }
    if (c.sweep.at("fault") == "long_message") {
      EXPECT_LT(message.size(), 5000u);
      EXPECT_NE(message.find("(cut: the message has "), std::string::npos) << message;
    }
  }
  ASSERT_EQ(res.context.plugins.size(), 1u);
  EXPECT_EQ(res.context.plugins[0].path, fs::canonical(dir / "line.so").string());
}

// A suite's time_limit_s, at the top level and per entry, drives host->cancelled(): a cooperative plugin (fault=hang
// waits for it) stops and keeps its partial plant, stopped by the time limit, where timeout_s would have killed it.
// A limit at or past timeout_s, which could never act, is refused.
TEST(CPlugin, ASuiteTimeLimitCancelsACooperativePluginAndKeepsItsPlant) {
  const fs::path dir = test::temp_dir("plugin_time_limit");
  fs::copy_file(fixture("line"), dir / "line.so");
  test::write_text(dir / "suite.json", R"({"schema_version": 1, "name": "limits", "repetitions": 1, "warmup": 0,
    "timeout_s": 20, "time_limit_s": 0.4, "plugins": ["line.so"], "scenes": ["wall"], "algorithms": [
      {"name": "line", "label": "global", "params": {"fault": "hang"}},
      {"name": "line", "label": "own", "time_limit_s": 0.2, "params": {"fault": "hang"}}]})");
  const auto r =
      test::run_growbench(fmt::format("suite {} -o {} -q", (dir / "suite.json").string(), (dir / "out").string()));
  ASSERT_EQ(r.status, 0) << r.out;
  const ResultsFile res = read_results((dir / "out" / "results.json").string());
  ASSERT_EQ(res.trials.size(), 2u);
  const Scene wall = load_scene("wall");
  for (const auto& c : res.trials) {
    EXPECT_EQ(c.status, "ok") << c.label;
    ASSERT_TRUE(c.results.plant.has_value()) << c.label;
    EXPECT_EQ(c.results.plant->stopped_by, "time_limit") << c.label;
    // The first step waited for the cancellation and then grew, a seed node and one more per seed, and no
    // step followed it; where start() itself outlasted the limit (a loaded or instrumented machine), no step ran.
    EXPECT_LE(c.results.plant->counts.nodes, 2 * wall.seeds.size()) << c.label;
    EXPECT_GE(c.results.plant->counts.nodes, wall.seeds.size()) << c.label;
    EXPECT_LE(c.results.plant->steps, 1) << c.label;
    ASSERT_TRUE(c.samples.at(0).phases.has_value()) << c.label;
    const double growth = (*c.samples.at(0).phases)[Phase::growth].value().wall_s;
    const double limit = c.label == "own" ? 0.2 : 0.4;
    EXPECT_GE(growth, limit) << c.label;
    EXPECT_LT(growth, 10.0) << c.label;
  }
  test::write_text(dir / "late.json", R"({"schema_version": 1, "name": "late", "timeout_s": 5, "plugins": ["line.so"],
    "scenes": ["wall"], "algorithms": [{"name": "line", "time_limit_s": 5}]})");
  const auto late = test::run_growbench(fmt::format("suite {} --plan", (dir / "late.json").string()));
  EXPECT_EQ(late.status, 2) << late.out;
  EXPECT_NE(late.out.find("/algorithms/0/time_limit_s: 5 s is not under the suite's timeout_s (5 s)"),
            std::string::npos)
      << late.out;
}

// ab.json named no plugin for side B: each side lists its plugins with path, hash, ABI and version, B's being
// --plugin-b's files (here a copy of the plugin with a byte appended: another build of the same name).
TEST(PluginAb, AbJsonNamesEachSidesPluginBuild) {
  const fs::path dir = test::temp_dir("plugin_ab");
  fs::copy_file(fixture("line"), dir / "line.so");
  fs::copy_file(fixture("line"), dir / "line_b.so");
  std::ofstream(dir / "line_b.so", std::ios::app | std::ios::binary) << '\n';
  test::write_text(dir / "suite.json", R"({"schema_version": 1, "name": "ab_plugins", "timeout_s": 60,
    "scenes": ["wall"], "algorithms": [{"name": "line", "params": {"length": 4}}]})");
  const std::string g = GROWBENCH_BINARY;
  const auto r = test::run_growbench(fmt::format(
      "ab {} {} {} --plugin {} --plugin-b {} --min-reps 3 --max-reps 3 --no-confirm -q -o {}", g, g,
      (dir / "suite.json").string(), (dir / "line.so").string(), (dir / "line_b.so").string(), (dir / "out").string()));
  ASSERT_NE(r.status, 2) << r.out;
  const nlohmann::json ab = read_json_file((dir / "out" / "ab.json").string());
  const nlohmann::json& a = ab.at("binaries").at("A").at("plugins");
  const nlohmann::json& b = ab.at("binaries").at("B").at("plugins");
  ASSERT_EQ(a.size(), 1u) << ab.dump();
  ASSERT_EQ(b.size(), 1u) << ab.dump();
  EXPECT_EQ(a[0].at("path"), fs::canonical(dir / "line.so").string());
  EXPECT_EQ(b[0].at("path"), fs::canonical(dir / "line_b.so").string());
  EXPECT_EQ(a[0].at("hash"), file_hash((dir / "line.so").string()));
  EXPECT_EQ(b[0].at("hash"), file_hash((dir / "line_b.so").string()));
  EXPECT_NE(a[0].at("hash"), b[0].at("hash"));
  EXPECT_EQ(b[0].at("name"), "line");
  EXPECT_EQ(b[0].at("abi_version"), 1);
  EXPECT_NE(r.out.find(fmt::format("B plugins: line {} (xxh3 {})", fs::canonical(dir / "line_b.so").string(),
                                   b[0].at("hash").get<std::string>())),
            std::string::npos)
      << r.out;
}

// plugin-test gives an outside author the conformance checks the built-ins pass: a working plugin passes them;
// a plant that differs from process to process fails determinism and the thread check, and an invalid plant
// fails validity, each named with what was seen, and the command exits 2.
TEST(PluginTest, RunsTheBuiltInsConformanceChecksOnAPlugin) {
  const std::string p = fixture("line");
  const auto ok = test::run_growbench("plugin-test " + p + " -s wall -s boulder -q");
  EXPECT_EQ(ok.status, 0) << ok.out;
  EXPECT_NE(ok.out.find("plugin-test line: passed on all 2 scenes"), std::string::npos) << ok.out;
  for (const char* check : {"valid plant", "grows", "one tree per seed", "no node inside a solid", "1 and 2 threads",
                            "deterministic", "stops at its time limit"})
    EXPECT_NE(ok.out.find(fmt::format("  ok   {:<24}", check)), std::string::npos) << check << "\n" << ok.out;

  const auto moved = test::run_growbench("plugin-test " + p + " -s wall -q --set fault=by_process");
  EXPECT_EQ(moved.status, 2) << moved.out;
  EXPECT_NE(moved.out.find("  FAIL 1 and 2 threads          geometry hash "), std::string::npos) << moved.out;
  EXPECT_NE(moved.out.find("  FAIL deterministic            geometry hash "), std::string::npos) << moved.out;
  EXPECT_NE(moved.out.find("plugin-test line: failed on 1 of 1 scenes: wall"), std::string::npos) << moved.out;

  const auto invalid = test::run_growbench("plugin-test " + p + " -s wall -q --set fault=bad_parent");
  EXPECT_EQ(invalid.status, 2) << invalid.out;
  EXPECT_NE(invalid.out.find("  FAIL valid plant              plugin_error: algorithm 'line' (plugin "),
            std::string::npos)
      << invalid.out;
}

// An algorithm written in Python (examples/python/spacecol.py, numpy) loads with --plugin file.py, grows through
// the host's batched queries the same plant on 1 and 2 threads, and hands over organ shapes, tints and
// attributes through the version-2 view.
TEST(PythonPlugin, TheNumpyExampleGrowsLikeAnyPlugin) {
  const std::string script = std::string(GROWBENCH_SOURCE_DIR) + "/examples/python/spacecol.py";
  TrialSpec spec;
  spec.algorithm = "spacecol_py";
  spec.scene = "boulder";
  spec.plugins = {script};
  spec.params = {"point_count=6000"};
  spec.threads = 1;
  Plant one;
  const TrialRecord r1 = run_trial_record(spec, {}, &one);
  spec.threads = 2;
  const TrialRecord r2 = run_trial_record(spec);
  EXPECT_EQ(r1.results.geometry_hash, r2.results.geometry_hash);
  EXPECT_GT(one.nodes.size(), 100u);
  EXPECT_EQ(one.validate(), "");
  EXPECT_EQ(r1.context->plugins.at(0).path, fs::canonical(script).string());
  EXPECT_EQ(r1.context->plugins.at(0).abi_version, GROWBENCH_PLUGIN_ABI_VERSION);
  EXPECT_EQ(one.organ_shapes, std::vector<std::string>{"blossom"});
  ASSERT_FALSE(one.organs.empty());
  EXPECT_EQ(one.organs[0].kind, OrganKind::Flower);
  ASSERT_EQ(one.node_attributes.size(), 2u);
  EXPECT_EQ(one.node_attributes[0].name, "Cd");
  EXPECT_EQ(one.node_attributes[1].name, "depth");
  const Scene boulder = load_scene("boulder");
  SceneQuery q(boulder);
  for (const auto& n : one.nodes) ASSERT_FALSE(q.inside(n.position));
}

// Python reaches version 3 too: the uv-cube's texture coordinates where the line down -Z through its middle
// meets the front face (as the C plugin's probe: u 0.5, v 0.375, u along +X), node groups and a decal.
TEST(PythonPlugin, ReadsTextureCoordinatesAndGivesGroupsAndADecal) {
  const fs::path dir = test::temp_dir("python_v3");
  const std::string script = test::write_text(dir / "uv.py", R"(import numpy as np
import growbench
class Uv:
    name = 'py_uv'
    def start(self, scene, host, params, seed):
        self.cube = next(m for m in range(len(scene.meshes)) if host.mesh_uvs(m) is not None)
        uvs, tris = host.mesh_uvs(self.cube)
        v = scene.meshes[self.cube].vertices
        lo, hi = v.min(axis=0), v.max(axis=0)
        q = np.array([[(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] + 1]])
        p, n, d, found, mesh, tri = host.closest_points(q, triangles=True)
        ok, uv, normal, du, dv = host.surface_frames(p, mesh, tri)
        self.figures = {'uv_count': len(uvs), 'triangles': len(tris), 'u': float(uv[0, 0]), 'v': float(uv[0, 1]),
                        'found': float(ok[0]), 'du_x': float(du[0, 0] / np.linalg.norm(du[0]))}
        self.seed = scene.seed_positions[0]
    def step(self):
        return False
    def plant(self):
        image = np.zeros((2, 3, 4), dtype=np.uint8)
        image[..., 0] = [[10, 20, 30], [40, 50, 60]]
        image[..., 3] = 255
        return {'positions': [self.seed, self.seed + [0, 0.1, 0]], 'parent': [-1, 0],
                'groups': [-1, 2], 'group_prefix': 'py',
                'decals': [{'mesh': self.cube, 'image': image}]}
    def stats(self):
        return self.figures
PLUGIN = Uv
)");
  TrialSpec spec;
  spec.algorithm = "py_uv";
  spec.scene = "mesh:uv-cube";
  spec.plugins = {script};
  spec.metrics = false;
  spec.out_dir = (dir / "out").string();
  fs::create_directories(spec.out_dir);
  Plant plant;
  const TrialRecord r = run_trial_record(spec, {}, &plant);
  const auto& st = r.results.algorithm_stats;
  EXPECT_EQ(st.at("uv_count"), 14.0);
  EXPECT_EQ(st.at("triangles"), 12.0);
  EXPECT_EQ(st.at("found"), 1.0);
  EXPECT_NEAR(st.at("u"), 0.5, 1e-5);
  EXPECT_NEAR(st.at("v"), 0.375, 1e-5);
  EXPECT_NEAR(st.at("du_x"), 1.0, 1e-5);
  EXPECT_EQ(plant.node_groups, (std::vector<std::int32_t>{-1, 2}));
  EXPECT_EQ(plant.group_prefix, "py");
  ASSERT_EQ(plant.decals.size(), 1u);
  int w = 0, h = 0, n = 0;
  const std::string png = (dir / "out" / "decal0.png").string();
  std::unique_ptr<unsigned char, void (*)(void*)> px(stbi_load(png.c_str(), &w, &h, &n, 4), stbi_image_free);
  ASSERT_TRUE(px) << png;
  EXPECT_EQ(w, 3);
  EXPECT_EQ(h, 2);
  EXPECT_EQ(px.get()[4 * 4], 50);  // row 1, column 1
}

// A script's own errors are named with the file: Python's exception and its line, with the trial's status
// following what was raised (growbench.InputError: invalid input; anything else: the plugin's error).
TEST(PythonPlugin, AScriptsErrorsNameTheFileAndLine) {
  const fs::path dir = test::temp_dir("python_errors");
  const std::string header = "import growbench\nclass A:\n    name = 'py_{}'\n";
  const std::string body =
      "    def start(self, scene, host, params, seed):\n        {}\n"
      "    def step(self):\n        {}\n"
      "    def plant(self):\n        return {{'positions': [[0, 0, 0]], 'parent': [-1]}}\nPLUGIN = A\n";
  struct Case {
    std::string name, start, step, command_error;
    int status;
  };
  const std::vector<Case> cases = {
      {"syntax", "pass", "return False +", "SyntaxError", 2},
      {"input", "raise growbench.InputError('this scene will not do')", "return False",
       "failed in start: InputError: this scene will not do", 2},
      {"fails", "pass", "raise RuntimeError('gave up')", "failed in step: RuntimeError: gave up", 2},
  };
  for (const auto& c : cases) {
    const std::string path =
        test::write_text(dir / (c.name + ".py"),
                         fmt::format(fmt::runtime(header), c.name) + fmt::format(fmt::runtime(body), c.start, c.step));
    const auto r = test::run_growbench(
        fmt::format("run --plugin {} -a py_{} -s wall -q -o {}", path, c.name, (dir / c.name).string()));
    EXPECT_EQ(r.status, c.status) << c.name << ": " << r.out;
    EXPECT_NE(r.out.find(c.command_error), std::string::npos) << c.name << ": " << r.out;
    EXPECT_NE(r.out.find(path), std::string::npos) << c.name << ": " << r.out;
    EXPECT_EQ(r.out.find("internal error"), std::string::npos) << c.name << ": " << r.out;
  }
  const std::string none = test::write_text(dir / "none.py", "x = 1\n");
  const auto r = test::run_growbench("list --plugin " + none);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(none + ": " + none + ": no PLUGIN; end the file with PLUGIN = YourAlgorithmClass"),
            std::string::npos)
      << r.out;
}

// bench/python/query_cost.py, the cost of a batched query from Python, runs and reports its figures (their size
// is the benchmark's, not a test's, to judge).
TEST(PythonPlugin, TheQueryCostBenchmarkReportsItsFigures) {
  TrialSpec spec;
  spec.algorithm = "query_cost";
  spec.scene = "boulder";
  spec.plugins = {std::string(GROWBENCH_SOURCE_DIR) + "/bench/python/query_cost.py"};
  spec.params = {"seconds=0.01"};
  const TrialRecord r = run_trial_record(spec);
  for (const char* bound : {"bounded", "unbounded"})
    for (const char* n : {"1", "1024"})
      for (const char* unit : {"us_per_call", "ns_per_point"}) {
        const std::string key = fmt::format("closest_points_{}_{}_{}", bound, n, unit);
        ASSERT_TRUE(r.results.algorithm_stats.count(key)) << key;
        EXPECT_GT(r.results.algorithm_stats.at(key), 0.0) << key;
      }
}

// A trial that failed for want of disk space was journaled as failed, and --resume on a disk with room never
// ran it again: the suite stops with 2 before journaling it, and the resumed run grows it.
TEST(CPlugin, ATrialStarvedOfDiskRunsAgainOnResumeWithTheSamePlugin) {
  const fs::path dir = test::temp_dir("plugin_disk");
  fs::copy_file(fixture("line"), dir / "line.so");
  test::write_text(dir / "suite.json", R"({"schema_version": 1, "name": "disk", "repetitions": 1, "warmup": 0,
    "plugins": ["line.so"], "scenes": ["wall"],
    "algorithms": [{"name": "line", "label": "first"}, {"name": "line", "label": "full", "params": {"fault": "disk_full"}}]})");
  const std::string run = fmt::format("suite {} -o {} -q", (dir / "suite.json").string(), (dir / "out").string());
  const auto full = test::run_growbench(run);
  EXPECT_EQ(full.status, 2) << full.out;
  EXPECT_NE(full.out.find("No space left on device (cell full/wall/s1); free space and continue with --resume"),
            std::string::npos)
      << full.out;
  ::setenv("TEST_PLUGIN_DISK_HAS_ROOM", "1", 1);
  // The plugin rebuilt in between (a byte more, still a loadable library) is refused, named.
  std::ofstream(dir / "line.so", std::ios::app | std::ios::binary) << '\0';
  const auto rebuilt = test::run_growbench(run + " --resume");
  EXPECT_EQ(rebuilt.status, 2) << rebuilt.out;
  EXPECT_NE(rebuilt.out.find("cannot resume, plugin 'line' has changed since its trials ran (xxh3 "), std::string::npos)
      << rebuilt.out;
  fs::copy_file(fixture("line"), dir / "line.so", fs::copy_options::overwrite_existing);
  const auto resumed = test::run_growbench(run + " --resume");
  ::unsetenv("TEST_PLUGIN_DISK_HAS_ROOM");
  ASSERT_EQ(resumed.status, 0) << resumed.out;
  const ResultsFile res = read_results((dir / "out" / "results.json").string());
  ASSERT_EQ(res.trials.size(), 2u);
  for (const auto& c : res.trials) EXPECT_EQ(c.status, "ok") << c.id;
}

// The boundary loses nothing: spacecol, compiled from its own source as a plugin and loaded under
// another name, grows the built-in's plant bit for bit, its every query crossing the C ABI.
class SpacecolAsPlugin : public ::testing::TestWithParam<std::string> {};

TEST_P(SpacecolAsPlugin, GrowsTheBuiltInsPlant) {
  TrialSpec spec;
  spec.scene = GetParam();
  spec.params = find_algorithm("spacecol").info().test_params;
  spec.metrics = false;
  spec.threads = 2;
  spec.algorithm = "spacecol";
  const TrialRecord builtin = run_trial_record(spec);
  spec.algorithm = "spacecol_plugin";
  spec.plugins = {kSpacecolPlugin};
  const TrialRecord plugin = run_trial_record(spec);
  EXPECT_EQ(plugin.results.geometry_hash, builtin.results.geometry_hash);
  EXPECT_EQ(plugin.results.counts.nodes, builtin.results.counts.nodes);
  EXPECT_EQ(plugin.results.steps, builtin.results.steps);
  EXPECT_EQ(plugin.results.algorithm_stats, builtin.results.algorithm_stats);
  EXPECT_GT(builtin.results.counts.nodes, 10u);
}

std::vector<std::string> scene_names() {
  std::vector<std::string> v;
  for (const auto& s : standard_scenes()) v.push_back(s.name);
  return v;
}

INSTANTIATE_TEST_SUITE_P(EveryStandardScene, SpacecolAsPlugin, ::testing::ValuesIn(scene_names()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace growbench
