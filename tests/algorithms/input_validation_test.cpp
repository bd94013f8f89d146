// Bad input to the algorithms' own readers: L-system grammars and expressions, organ OBJs, vine mask PNGs
// and plugin parameter tables. Each error names its source (file:line:column, key or row) and what was
// expected; none crashes or is read as something else.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include "algorithms/algorithm.hpp"
#include "algorithms/lsystem/grammar.hpp"
#include "algorithms/lsystem/lsystem.hpp"
#include "algorithms/organ_shapes.hpp"
#include "algorithms/plugins/loader.hpp"
#include "algorithms/vines/mask.hpp"
#include "core/errors.hpp"
#include "grow_util.hpp"
#include "scenes/scene_library.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

using test::error_of;

lsys::Grammar grammar(const std::string& premise, const std::string& rules) {
  return lsys::parse_grammar({"parameter 'premise'", premise, 1}, {{"g.lsys", rules, 1}}, {}, "");
}

std::string derive(const std::string& premise, const std::string& rules, int generations) {
  Params p = default_params(find_algorithm("lsystem"));
  p.set("premise", premise);
  p.set("rules", rules);
  p.set("generations", std::to_string(generations));
  return derive_lsystem(p, 1, nullptr, nullptr, 0).text;
}

// ---------- grammars ----------

TEST(GrammarInput, AByteOrderMarkIsSkipped) {
  const auto dir = test::temp_dir("grammar_bom");
  const std::string f = test::write_text(dir / "bom.lsys", "\xEF\xBB\xBFpremise: F\ngenerations: 2\nF = FF\n");
  const lsys::GrammarFile g = lsys::read_grammar_file(f, {"premise", "generations"});
  ASSERT_EQ(g.settings.size(), 2u);  // the BOM hid the premise: "no premise"
  EXPECT_EQ(g.settings[0].key, "premise");
  EXPECT_EQ(g.settings[0].column, 10u);
  const std::string bad = test::write_text(dir / "bad.lsys", "\xEF\xBB\xBFpremsie: F\n");
  EXPECT_EQ(error_of([&] { (void)lsys::read_grammar_file(bad, {"premise"}); }),
            bad + ":1:1: unknown setting 'premsie' (did you mean 'premise'?); expected one of premise");
}

TEST(GrammarInput, ANumberOutOfRangeIsQuoted) {
  // Was "malformed number ''".
  EXPECT_EQ(error_of([&] { (void)grammar("A(1e400)", ""); }),
            "parameter 'premise':1:3: in the parameter expression: number '1e400' is out of range; expected a "
            "magnitude from 2.22507e-308 to 1.79769e+308, or 0");
  // A module's parameter is a float: a constant beyond it would become inf.
  EXPECT_EQ(error_of([&] { (void)grammar("A", "A = B(1e39)"); }),
            "g.lsys:1:7: the parameter expression 1e+39 is out of range; a module's parameter is a 32-bit float, at "
            "most 3.40282e+38");
}

TEST(GrammarInput, ANonAsciiSymbolIsQuotedWhole) {
  // Was "found '\xC3'": half of the character, which a journal could not store.
  EXPECT_EQ(error_of([&] { (void)grammar("F", "F = F\xC3\xA9G"); }),
            "g.lsys:1:6: expected a symbol, found '\xC3\xA9' (symbols are printable ASCII characters other than ( ) , "
            ": = < >)");
  EXPECT_EQ(error_of([&] { (void)grammar("F", "F = F\xC3"); }),
            "g.lsys:1:6: expected a symbol, found '\\xc3' (symbols are printable ASCII characters other than ( ) , : = "
            "< >)");
  EXPECT_EQ(error_of([&] { (void)grammar("F", "F(x) = F(x\xE2\x82\xAC)"); }),
            "g.lsys:1:11: in the parameter expression: unexpected '\xE2\x82\xAC' after the expression");
  EXPECT_EQ(error_of([&] {
              (void)lsys::parse_grammar({"p", "F", 1}, {}, {}, "[\xC3\xA9");
            }),
            "context_ignore: '\xC3\xA9' is not a symbol (symbols are printable ASCII characters other than ( ) , : = < "
            ">)");
}

TEST(GrammarInput, APremiseFromAFileNamesTheFileLineAndColumn) {
  const auto dir = test::temp_dir("grammar_premise");
  const std::string f = test::write_text(dir / "p.lsys", "# a tree\npremise:   F(1,\nF = FF\n");
  const lsys::GrammarFile g = lsys::read_grammar_file(f, {"premise"});
  EXPECT_EQ(error_of([&] { (void)lsys::parse_grammar(g.setting_text(g.settings[0]), {g.rules}, {}, ""); }),
            f + ":2:13: expected ')' to close the parameter list");
}

TEST(GrammarInput, ExpressionNestingIsBounded) {
  const std::string deep = std::string(300, '(') + "1" + std::string(300, ')');
  EXPECT_EQ(
      error_of([&] { (void)grammar("F(" + deep + ")", ""); }),
      "parameter 'premise':1:203: in the parameter expression: expression nested more than 200 deep (parentheses, "
      "unary operators, powers and calls)");
  const std::string ok = std::string(150, '(') + "1" + std::string(150, ')');
  EXPECT_EQ(error_of([&] { (void)grammar("F(" + ok + ")", ""); }), "(no error)");
}

TEST(GrammarInput, AConstantThatIsNotFiniteIsRefusedWhereItIsWritten) {
  EXPECT_EQ(error_of([&] { (void)grammar("A(1/0)", ""); }),
            "parameter 'premise':1:3: in the parameter expression: the expression is always inf, from a division by "
            "zero");
  EXPECT_EQ(error_of([&] { (void)grammar("A", "A : sqrt(0-1) = B"); }),
            "g.lsys:1:5: in the condition: the expression is always nan, from the square root of a negative number");
}

// Division by zero or overflow during derivation ended later in "invalid plant: node 1 has a non-finite
// position", naming no rule.
TEST(GrammarInput, ADivisionByZeroDuringDerivationNamesTheRule) {
  EXPECT_EQ(error_of([&] { (void)derive("A(1)", "A(x) = F(1/x)A(x-1)", 3); }),
            "parameter 'rules':1:10: in rule 'A(x) = F(1/x)A(x-1)': the parameter expression '1/x' gave inf, from a "
            "division by zero");
  EXPECT_EQ(error_of([&] { (void)derive("A(0.01)", "A(x) = F(x)A(x*1e10)", 6); }),
            "parameter 'rules':1:14: in rule 'A(x) = F(x)A(x*1e10)': the parameter expression 'x*1e10' gave 1e+48, "
            "beyond the largest module parameter, 3.40282e+38 (a 32-bit float)");
  EXPECT_EQ(error_of([&] { (void)derive("A(2)", "A(x) : 1/(x-1) > 0 = A(x-1)", 3); }), "(no error)");
  EXPECT_EQ(error_of([&] { (void)derive("A(1)", "A(x) : x/(x-x) = B", 1); }),
            "parameter 'rules':1:8: in rule 'A(x) : x/(x-x) = B': the condition 'x/(x-x)' gave inf, from a division "
            "by zero");
}

// Steps that are each within float range can still carry the turtle beyond it; that ended in "invalid
// plant: node 2 has a non-finite position", naming no module.
TEST(GrammarInput, AStepThatLeavesFloatRangeNamesItsModule) {
  const Scene scene = load_scene("envelope");
  const SceneQuery query(scene);
  EXPECT_EQ(error_of([&] {
              (void)test::grow("lsystem", scene, query, {"premise=F(3e38)F(3e38)", "rules=", "surface=free"});
            }),
            "L-system: module 1 ('F', step 3e+38) moved the turtle to (0, 6e+38, 0), beyond the range of a 32-bit "
            "float; expected steps that keep the plant within +-3.40282e+38");
}

TEST(GrammarInput, VariablesMustBeFinite) {
  EXPECT_EQ(error_of([&] { (void)lsys::parse_variables("parameter 'variables'", "k=inf"); }),
            "parameter 'variables': variable 'k': expected a finite number, found 'inf'");
  EXPECT_EQ(error_of([&] { (void)lsys::parse_variables("parameter 'variables'", "k=1e400"); }),
            "parameter 'variables': variable 'k': the number '1e400' is out of range");
}

// ---------- organ OBJs ----------

TEST(OrganInput, AnOrganObjWithANanVertexIsRefusedWithItsLine) {
  const auto dir = test::temp_dir("organ_obj");
  // Was read as 0: an organ with a vertex at the stem.
  const std::string f = test::write_text(dir / "leaf.obj", "v 0 0 0\nv 0.2 0 0.5\nv nan 0 1\nf 1 2 3\n");
  EXPECT_EQ(error_of([&] { (void)load_organ_obj(f); }), f + ":3: vertex (v x y z): 'nan' is not a finite number");
  const std::string g =
      test::write_text(dir / "big.obj", "v 0 0 0\nv 0.2 0 0.5\nv 0 0 1\nf 1 2 99999999999999999999\n");
  EXPECT_EQ(error_of([&] { (void)load_organ_obj(g); }),
            g + ":4: face: vertex index 99999999999999999999 is out of range; 3 vertices are defined before this line "
                "(expected 1 to 3 or -1 to -3)");
}

// ---------- vine masks ----------

std::string write_bytes(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
  return p.string();
}

// The bytes of a 2 x 1 RGBA PNG, red then green, as stb_image_write makes it: to be cut and changed.
std::string tiny_png(const std::filesystem::path& dir) {
  const unsigned char px[8] = {255, 0, 0, 255, 0, 255, 0, 255};
  const auto p = dir / "tiny.png";
  EXPECT_NE(stbi_write_png(p.string().c_str(), 2, 1, 4, px, 8), 0);
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(MaskInput, TruncatedCorruptAndOversizedPngsNameTheFile) {
  const auto dir = test::temp_dir("mask_png");
  const std::string png = tiny_png(dir);
  const vines::Mask ok = vines::Mask::read(write_bytes(dir / "ok.png", png), "mask");
  ASSERT_EQ(ok.width(), 2);
  EXPECT_EQ(ok.zone_pixels(), 1u);

  const std::string cut = write_bytes(dir / "cut.png", png.substr(0, 45));  // in the image data
  EXPECT_EQ(error_of([&] { (void)vines::Mask::read(cut, "mask"); }),
            "mask=" + cut +
                ": cannot decode the image: the file ends before its image data does: truncated? "
                "(stb_image: outofdata)");
  std::string corrupt = png;
  corrupt[41] = '\xff';  // the image data's zlib header
  corrupt[42] = '\xff';
  const std::string bad = write_bytes(dir / "bad.png", corrupt);
  const std::string e = error_of([&] { (void)vines::Mask::read(bad, "mask"); });
  EXPECT_EQ(e.rfind("mask=" + bad + ": cannot decode the image: its compressed image data is corrupt (stb_image: ", 0),
            0u)
      << e;
  std::string huge = png;
  huge.replace(16, 8, std::string("\x00\x01\x86\xa0\x00\x01\x86\xa0", 8));  // 100000 x 100000
  const std::string big = write_bytes(dir / "big.png", huge);
  // stb_image said only "unknown image type".
  EXPECT_EQ(error_of([&] { (void)vines::Mask::read(big, "mask"); }),
            "mask=" + big + ": the image is 100000 x 100000 pixels; expected 1 to 16384 on each side");
  std::string empty = png;
  empty.replace(16, 4, std::string("\x00\x00\x00\x00", 4));
  const std::string zero = write_bytes(dir / "zero.png", empty);
  EXPECT_EQ(error_of([&] { (void)vines::Mask::read(zero, "mask"); }),
            "mask=" + zero + ": the image is 0 x 1 pixels; expected 1 to 16384 on each side");
  const std::string gif = write_bytes(dir / "m.png", "GIF89a\x01\x00\x01\x00");
  EXPECT_EQ(error_of([&] { (void)vines::Mask::read(gif, "mask"); }),
            "mask=" + gif + ": not a readable image: it is not a PNG (its first bytes are not the PNG signature)");
}

// A pic() image is read whole: a small file of vast pixels (a 27 KB PNG of 15000 x 15000) took gigabytes.
// It is capped as a mask is, from its header; an image within the cap is looked up as before.
TEST(PicImageInput, AnImageTooLargeIsRefusedFromItsHeaderAndASmallOneIsRead) {
  const auto dir = test::temp_dir("pic_png");
  const std::string png = tiny_png(dir);  // red, green
  auto run = [&](const std::string& image) {
    Params p = default_params(find_algorithm("lsystem"));
    p.set("premise", "A");
    p.set("rules", "A = B(pic(0.25, 0.5, 1), pic(0.75, 0.5, 2), pic(0.75, 0.5, 1))");
    p.set("generations", "1");
    p.set("pic_image", image);
    return derive_lsystem(p, 1, nullptr, nullptr, 0).text;
  };
  EXPECT_EQ(run(write_bytes(dir / "ok.png", png)), "B(1,1,0)");
  std::string wide = png;
  wide.replace(16, 4, std::string("\x00\x00\x4e\x20", 4));  // 20000 x 1
  const std::string big = write_bytes(dir / "wide.png", wide);
  EXPECT_EQ(error_of([&] { (void)run(big); }),
            "pic_image '" + big + "': the image is 20000 x 1 pixels; expected at most 16384 on each side");
}

// ---------- plugin parameter tables ----------

growbench_instance* no_create(const growbench_host*) {
  return nullptr;
}
int32_t no_start(growbench_instance*, const growbench_scene*, const growbench_value*, uint64_t) {
  return 0;
}
int32_t no_step(growbench_instance*) {
  return 0;
}
int32_t no_plant(growbench_instance*, growbench_plant_view*) {
  return 0;
}
void no_destroy(growbench_instance*) {}

growbench_plugin table_of(const growbench_param* rows, std::uint32_t count) {
  growbench_plugin t{};
  t.abi_version = GROWBENCH_PLUGIN_ABI_VERSION;
  t.struct_size = sizeof(growbench_plugin);
  t.name = "p";
  t.params = rows;
  t.param_count = count;
  t.create = no_create;
  t.start = no_start;
  t.step = no_step;
  t.finish = no_step;
  t.plant = no_plant;
  t.destroy = no_destroy;
  return t;
}

growbench_param real_row(const char* name, double value, double min, double max) {
  growbench_param r{};
  r.name = name;
  r.type = GROWBENCH_PARAM_REAL;
  r.default_value.real = value;
  r.min = min;
  r.max = max;
  return r;
}

std::string table_error(const std::vector<growbench_param>& rows, const char* const* tests = nullptr,
                        std::uint32_t test_count = 0) {
  growbench_plugin t = table_of(rows.data(), static_cast<std::uint32_t>(rows.size()));
  t.test_params = tests;
  t.test_param_count = test_count;
  return error_of([&] { (void)read_plugin_table("p.so", t); });
}

TEST(PluginTableInput, RowsAreCheckedAndNamed) {
  const double nan = std::nan(""), inf = INFINITY;
  EXPECT_EQ(table_error({real_row("a", 0.5, 0, 1)}), "(no error)");
  EXPECT_EQ(table_error({real_row("a", nan, 0, 1)}),
            "p.so: malformed plugin table: parameter 0 ('a'): its default nan is not a finite value in [0, 1]");
  EXPECT_EQ(table_error({real_row("a", inf, -inf, inf)}),
            "p.so: malformed plugin table: parameter 0 ('a'): its default inf is not a finite value in [-inf, inf]");
  EXPECT_EQ(table_error({real_row("a", 0.5, 2, 1)}),
            "p.so: malformed plugin table: parameter 0 ('a'): its range [2, 1] is empty or not a number");
  EXPECT_EQ(table_error({real_row("a", 0.5, 0, 1), real_row("a", 0.5, 0, 1)}),
            "p.so: malformed plugin table: parameter 1 ('a') is declared twice");
  EXPECT_EQ(table_error({real_row(nullptr, 0.5, 0, 1)}),
            "p.so: malformed plugin table: parameter 0 (''): its name is NULL");
  EXPECT_EQ(table_error({real_row("caf\xC3\xA9", 0.5, 0, 1)}),
            "p.so: malformed plugin table: parameter 0 ('caf\xC3\xA9'): its name 'caf\xC3\xA9' has '\xC3\xA9'; "
            "expected a-z, 0-9 and _ only");
  growbench_param doc = real_row("a", 0.5, 0, 1);
  doc.doc = "half \xC3";
  EXPECT_EQ(table_error({doc}),
            "p.so: malformed plugin table: parameter 0 ('a'): its doc 'half \\xc3' is not valid UTF-8");
  static const char* const kChoices[] = {"x", nullptr};
  growbench_param choice{};
  choice.name = "mode";
  choice.type = GROWBENCH_PARAM_CHOICE;
  choice.choices = kChoices;
  choice.choice_count = 1;
  EXPECT_EQ(table_error({choice}),
            "p.so: malformed plugin table: parameter 0 ('mode'): its default is NULL; expected one of its choices");
  choice.choice_count = 2;
  choice.default_value.text = "x";
  EXPECT_EQ(table_error({choice}), "p.so: malformed plugin table: parameter 0 ('mode'): choice 1 is NULL");
  static const char* const kTests[] = {nullptr};
  EXPECT_EQ(table_error({real_row("a", 0.5, 0, 1)}, kTests, 1),
            "p.so: malformed plugin table: test_params[0] is NULL; expected key=value");
}

}  // namespace
}  // namespace growbench
