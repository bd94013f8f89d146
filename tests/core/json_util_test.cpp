#include "core/json_util.hpp"

#include <string>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

using test::error_of;

std::string parse_error(const std::string& text) {
  return error_of([&] { (void)parse_json_file_text("f.json", text); });
}

TEST(JsonFile, ANumberOutOfRangeNamesItsLineAndColumn) {
  // nlohmann reports it as out_of_range.406, without a position: the message was the library's own.
  EXPECT_EQ(parse_error("{\n  \"a\": 1e400\n}"),
            "f.json:2:8: invalid JSON: number overflow parsing '1e400'; expected a number within a double's range");
  EXPECT_EQ(parse_error("{\n  \"a\": [,]\n}"),
            "f.json:2:9: invalid JSON: parse error at line 2, column 9: syntax error while parsing value - unexpected "
            "','; expected '[', '{', or a literal");
}

TEST(JsonFile, AKeyGivenTwiceIsRefusedByItsPath) {
  // nlohmann keeps the last of two equal keys and drops the first without a word.
  EXPECT_EQ(parse_error(R"({"meshes": [{"box": 1}, {"name": "a", "name": "b"}]})"),
            "f.json: invalid JSON: at /meshes/1/name: the key 'name' is given twice in one object");
  EXPECT_EQ(parse_error(R"({"a": 1, "b": {"c": [1, 2]}})"), "(no error)");
}

TEST(JsonFile, NestingIsBounded) {
  const std::string deep = std::string(kMaxJsonDepth + 1, '[') + std::string(kMaxJsonDepth + 1, ']');
  const std::string e = parse_error(deep);
  EXPECT_EQ(e.rfind("f.json: invalid JSON: at /0/0/0/", 0), 0u) << e;
  EXPECT_NE(e.find(": arrays and objects nested deeper than 256 levels"), std::string::npos) << e;
  const std::string ok = std::string(kMaxJsonDepth, '[') + std::string(kMaxJsonDepth, ']');
  EXPECT_EQ(parse_error(ok), "(no error)");
}

TEST(JsonFile, ADirectoryIsNotReadAsAFile) {
  const auto dir = test::temp_dir("json_dir");
  // An ifstream opens a directory; the first read threw "basic_filebuf::underflow ... Is a directory".
  EXPECT_EQ(error_of([&] { (void)read_text_file(dir.string()); }), dir.string() + ": is a directory, not a file");
}

TEST(JsonFile, AFileProblemIsSaidNotThrown) {
  const auto dir = test::temp_dir("file_problem");
  const std::string file = test::write_text(dir / "f.txt", "x");
  EXPECT_EQ(file_problem(file), "");
  EXPECT_EQ(file_problem((dir / "none").string()), "no such file");
  EXPECT_EQ(file_problem(dir.string()), "is a directory, not a file");
  EXPECT_EQ(file_problem("/dev/null"), "not a regular file");
  EXPECT_EQ(file_problem("/dev/null", true), "");
  EXPECT_EQ(file_problem(""), "no file named (an empty path)");
  // A name longer than NAME_MAX: std::filesystem::exists without an error code throws on it.
  EXPECT_EQ(file_problem((dir / std::string(300, 'a') / "x.obj").string()), "File name too long");
}

TEST(JsonFile, ExcerptsAreShortAndWhole) {
  const nlohmann::json long_text = std::string(200, 'x');
  const std::string e = json_excerpt(long_text);
  EXPECT_EQ(e, "\"" + std::string(kJsonExcerptBytes - 1, 'x') + "...");
}

}  // namespace
}  // namespace growbench
