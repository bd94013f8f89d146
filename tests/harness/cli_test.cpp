// The growbench binary as a user meets it: exit codes, error messages, files written.
#include <sys/wait.h>

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "harness/report/columns.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

test::CommandResult growbench(const std::string& args) {
  return test::run_growbench(args);
}

TEST(Cli, HelpAndLists) {
  auto r = growbench("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("run"), std::string::npos);
  r = growbench("run --help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("--seed-at"), std::string::npos);
  r = growbench("list");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("influence"), std::string::npos);
  r = growbench("scenes");
  EXPECT_EQ(r.status, 0);
  for (const char* s : {"wall", "facade", "column", "corner", "pergola", "boulder", "trunk", "envelope", "mesh:PATH"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
  EXPECT_NE(test::one_paragraph(r.out).find("(cow, spot, stanford-bunny, suzanne, teapot, uv-cube)"), std::string::npos)
      << r.out;
  r = growbench("run -a ivy -s mesh:bunny -o " + test::temp_dir("cli_badmesh").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("unknown mesh 'bunny' (did you mean 'stanford-bunny'?)"), std::string::npos) << r.out;
}

// record.json holds the whole trial spec: the trial can be run again from the record alone, and grows the
// same plant.
TEST(Cli, TheRecordHoldsTheWholeSpecAndReproducesThePlant) {
  const auto dir = test::temp_dir("cli_spec");
  const std::string out = (dir / "run").string();
  auto r = growbench(
      "run -q -a spacecol -s wall --set point_count=300 --sides 8 --glb plain --time-limit 100 "
      "--seed 7 --seed-at 0.5,0.2,0 --budget-nodes 400 --voxel-size 0.05 --band-voxels 6 -o " +
      out);
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in(dir / "run" / "record.json");
  const nlohmann::json rec = nlohmann::json::parse(in);
  const nlohmann::json& spec = rec["spec"];
  EXPECT_EQ(spec["sides"], 8);
  EXPECT_EQ(spec["glb"], "plain");
  EXPECT_EQ(spec["time_limit_s"], 100.0);
  EXPECT_EQ(spec["seed"], 7);
  EXPECT_EQ(spec["seed_at"], nlohmann::json::parse("[[0.5, 0.2, 0.0]]"));  // as given
  EXPECT_EQ(spec["budget_nodes"], 400);
  EXPECT_EQ(spec["voxel_size"], 0.05);
  EXPECT_EQ(spec["band_voxels"], 6.0);
  EXPECT_EQ(spec["params"], nlohmann::json::parse(R"(["point_count=300"])"));
  EXPECT_EQ(spec["out_dir"], out);
  nlohmann::json again = spec;
  again["out_dir"] = (dir / "again").string();
  const std::string spec_file = test::write_text(dir / "spec.json", again.dump());
  r = growbench("trial " + spec_file);
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in2(dir / "again" / "record.json");
  const nlohmann::json rec2 = nlohmann::json::parse(in2);
  EXPECT_EQ(rec2["geometry_hash"], rec["geometry_hash"]);
  EXPECT_EQ(rec2["counts"], rec["counts"]);
  EXPECT_EQ(rec2["output_bytes"]["glb"], rec["output_bytes"]["glb"]);
}

// list and scenes read in a 100-column terminal: every line, the parameter docs wrapped.
TEST(Cli, ListAndScenesFitAHundredColumns) {
  for (const char* cmd : {"list", "list organs", "scenes"}) {
    const auto r = growbench(cmd);
    ASSERT_EQ(r.status, 0) << cmd;
    test::expect_lines_fit(r.out, cmd);
  }
}

TEST(Cli, ListOneAlgorithmAsTextOrMarkdown) {
  auto r = growbench("list spacecol");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out.rfind("spacecol\n", 0), 0u) << r.out;
  EXPECT_EQ(r.out.find("lsystem"), std::string::npos) << r.out;
  r = growbench("list --markdown ivy");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out.rfind("| name | type | default | allowed | unit | doc |\n|---|---|---|---|---|---|\n", 0), 0u)
      << r.out;
  EXPECT_NE(r.out.find("| `preset` | choice | `luft` | `luft`, `blender` |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("- `blender`: `units=absolute`"), std::string::npos) << r.out;
  // A pipe in a doc would end its cell.
  r = growbench("list --markdown spacecol");
  EXPECT_NE(r.out.find("(\\|sum\\| < split * count)"), std::string::npos) << r.out;
  r = growbench("list --markdown spacel");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("did you mean 'spacecol'"), std::string::npos) << r.out;
}

TEST(Cli, LsystemPrintsTheDerivedStringAndGrowsExamplesFromFiles) {
  auto r = growbench("lsystem koch-island --generations 1 --print");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("F-F+F+FF-F-F+F-F-F+F+FF-F-F+F-F-F+F+FF-F-F+F-F-F+F+FF-F-F+F\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("F  32"), std::string::npos) << r.out;
  r = growbench("lsystem --examples");
  EXPECT_NE(r.out.find("topiary"), std::string::npos) << r.out;
  r = growbench("lsystem bush --set anlge=3");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("did you mean 'angle'"), std::string::npos) << r.out;
  r = growbench("lsystem busj");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("did you mean 'bush'"), std::string::npos) << r.out;
  // a grammar file by path, grown on a scene through `run`
  const auto dir = test::temp_dir("cli-lsys");
  const std::string file = test::write_text(dir / "mine.lsys", "premise: A\ngenerations: 4\nA = F[+A][-A]\n");
  r = growbench("run -a lsystem -s wall --set grammar=" + file + " -q -o " + (dir / "out").string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("4 steps (finished)"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "plant.ply"));
}

// Houdini's Write Rule Parameters to File: --write-rules writes the rules a grammar rewrote with, one per
// line, and rules_file reads them back to the same string.
TEST(Cli, LsystemWritesItsRulesToAFileThatRulesFileReadsBack) {
  const auto dir = test::temp_dir("cli-lsys-rules");
  const std::string rules = (dir / "bush.rules").string();
  auto r = growbench("lsystem bush --generations 3 --print --write-rules " + rules);
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in(rules);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_EQ(text,
            "# the rules of bush, written by growbench lsystem --write-rules\n"
            "A = [&FA[fK]]/////[&FA[fJ]]///////[&FA[fJ]]\nF = S/////\nS = F\n");
  EXPECT_NE(r.out.find("wrote 3 rules to " + rules), std::string::npos) << r.out;
  // The derived string, up to the counts' line, is the same from the file.
  auto string_of = [](const std::string& out) { return out.substr(0, out.find(" parameters, ")); };
  auto back = growbench("lsystem bush --generations 3 --print --set rules_file=" + rules);
  ASSERT_EQ(back.status, 0) << back.out;
  EXPECT_EQ(string_of(back.out), string_of(r.out));
  // a file it cannot write is a clear error
  r = growbench("lsystem bush --generations 1 --write-rules " + (dir / "no" / "such" / "x.rules").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find((dir / "no" / "such").string()), std::string::npos) << r.out;
}

TEST(Cli, BadInputExitsTwoWithAClearMessage) {
  auto r = growbench("run -a spacecl -s wall -o /tmp/x");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("unknown algorithm 'spacecl' (did you mean 'spacecol'?)"), std::string::npos) << r.out;
  r = growbench("run -a spacecol -s wal -o /tmp/x");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("did you mean 'wall'"), std::string::npos) << r.out;
  r = growbench("run -a spacecol -s wall --set stpe=0.1 -o /tmp/x");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("did you mean 'step'"), std::string::npos) << r.out;
  r = growbench("run -a spacecol -s wall --seed-at 1,2 -o /tmp/x");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("x,y,z"), std::string::npos) << r.out;
  r = growbench("run -a spacecol");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--scene"), std::string::npos) << r.out;
}

TEST(Cli, RunWritesMeshesSkeletonAndRecord) {
  const auto dir = test::temp_dir("cli_run");
  const auto r =
      growbench("run -q -a spacecol -s column --set surface=cling --set point_count=3000 --seed 3 --threads 2 -o " +
                dir.string());
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* f : {"plant.obj", "plant.mtl", "plant.ply", "skeleton.obj", "skeleton.ply", "record.json"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  std::ifstream in(dir / "record.json");
  const auto rec = nlohmann::json::parse(in);
  EXPECT_EQ(rec["schema_version"], 1);
  EXPECT_EQ(rec["status"], "ok");
  EXPECT_EQ(rec["seed"], 3);
  EXPECT_EQ(rec["params"]["surface"], "cling");
  EXPECT_EQ(rec["output_bytes"]["ply"].get<std::uintmax_t>(), std::filesystem::file_size(dir / "plant.ply"));
  EXPECT_EQ(rec["output_bytes"]["skeleton_ply"].get<std::uintmax_t>(),
            std::filesystem::file_size(dir / "skeleton.ply"));
  for (const char* ph : {"scene_load", "query_build", "growth", "meshing", "export"}) {
    EXPECT_TRUE(rec["phases"].contains(ph)) << ph;
    EXPECT_GE(rec["phases"][ph]["wall_s"].get<double>(), 0.0);
  }
  EXPECT_FALSE(rec["phases"].contains("outputs")) << "spacecol writes no files of its own";
  EXPECT_GT(rec["counts"]["nodes"].get<int>(), 50);
  EXPECT_EQ(rec["geometry_hash"].get<std::string>().size(), 16u);
}

// The vines' own files (texture, normal map, SVG) are drawn and written in their own phase, `outputs`,
// apart from the mesh exports, so drawing time can be plotted against resolution.
TEST(Cli, AnAlgorithmsOwnFilesAreTimedInTheOutputsPhase) {
  const auto dir = test::temp_dir("cli_outputs");
  const auto r = growbench("run -q -a vines -s wall --set resolution=48 --threads 1 -o " + dir.string());
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in(dir / "record.json");
  const auto rec = nlohmann::json::parse(in);
  ASSERT_TRUE(rec["phases"].contains("outputs"));
  EXPECT_GT(rec["phases"]["outputs"]["wall_s"].get<double>(), 0.0);
  EXPECT_TRUE(rec["phases"].contains("export"));
  EXPECT_EQ(rec["output_bytes"]["algorithm_files"]["texture.png"].get<std::uintmax_t>(),
            std::filesystem::file_size(dir / "texture.png"));
}

TEST(Cli, CustomLeafObjForHadrich) {
  // The same climbing plant with the default leaf and with a three-triangle leaf from an OBJ: the plant
  // is the same; each leaf adds one triangle to the mesh. A bad leaf file is invalid input (exit 2).
  const auto dir = test::temp_dir("cli_leaf");
  const std::string leaf = test::write_text(dir / "leaf.obj",
                                            "v 0 0 0\nv 0.3 0 0.5\nv 0 0 1\nv -0.3 0 0.5\nv 0 0.1 0.5\n"
                                            "f 1 2 3\nf 1 3 4\nf 1 5 3\n");
  const std::string common = "run -q -a hadrich -s wall --set max_particles=400 --max-steps 300 --threads 1 -o ";
  auto r = growbench(common + (dir / "plain").string());
  ASSERT_EQ(r.status, 0) << r.out;
  r = growbench(common + (dir / "custom").string() + " --leaf-obj " + leaf);
  ASSERT_EQ(r.status, 0) << r.out;
  auto record = [&](const char* sub) {
    std::ifstream in(dir / sub / "record.json");
    return nlohmann::json::parse(in);
  };
  const auto plain = record("plain"), custom = record("custom");
  EXPECT_EQ(plain["geometry_hash"], custom["geometry_hash"]);
  const int organs = custom["counts"]["organs"].get<int>();  // leaves and flowers share the shape
  ASSERT_GT(custom["counts"]["leaves"].get<int>(), 0);
  EXPECT_EQ(custom["counts"]["mesh_triangles"].get<int>() - plain["counts"]["mesh_triangles"].get<int>(), organs);
  EXPECT_EQ(custom["leaf_obj"], leaf);
  r = growbench(common + (dir / "bad").string() + " --leaf-obj " + (dir / "missing.obj").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("missing.obj: no such file"), std::string::npos) << r.out;
}

TEST(Cli, SeedAtSnapsToTheSurface) {
  const auto dir = test::temp_dir("cli_seedat");
  const auto r =
      growbench("run -q -a spacecol -s mesh:suzanne --seed-at 0,5,0 --set surface=cling --set point_count=2000 -o " +
                dir.string());
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in(dir / "skeleton.obj");
  std::string line;
  while (std::getline(in, line) && line.rfind("v ", 0) != 0) {
  }
  std::istringstream ls(line.substr(2));
  float x, y, z;
  ls >> x >> y >> z;
  EXPECT_LT(y, 2.0f);  // snapped down from y = 5 onto the (2 m tall) mesh
}

}  // namespace
}  // namespace growbench
