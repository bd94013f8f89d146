#include "core/params.hpp"

#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "test_util.hpp"

namespace growbench {
namespace {

std::vector<ParamSpec> specs() {
  return {
      param::real("step", 0.02).range(1e-4, 1.0).unit("m").doc("step length"),
      param::integer("count", 10).range(1, 100).doc("a count"),
      param::boolean("flag", false).doc("a flag"),
      param::choice("mode", "open", {"open", "closed"}).doc("mode"),
      param::vec3("dir", glm::dvec3(0, 1, 0)).range(-10, 10).doc("direction"),
      param::text("file").doc("a path"),
  };
}

using test::error_of;

// A row states only what it has; the rest is the spec's own: no range, no unit, no doc.
TEST(Params, RowsStateOnlyWhatTheyHave) {
  const ParamSpec bare = param::real("x", 1.5);
  EXPECT_EQ(bare.name, "x");
  EXPECT_EQ(bare.type, ParamType::Real);
  EXPECT_EQ(std::get<double>(bare.default_value), 1.5);
  EXPECT_EQ(bare.min, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(bare.max, std::numeric_limits<double>::infinity());
  EXPECT_EQ(bare.unit, "");
  EXPECT_EQ(bare.doc, "");
  EXPECT_TRUE(bare.choices.empty());
  const ParamSpec full = param::integer("n", 3).range(1, 9).unit("m").doc("a count");
  EXPECT_EQ(full.type, ParamType::Int);
  EXPECT_EQ(std::get<std::int64_t>(full.default_value), 3);
  EXPECT_EQ(full.min, 1);
  EXPECT_EQ(full.max, 9);
  EXPECT_EQ(full.unit, "m");
  EXPECT_EQ(full.doc, "a count");
  const ParamSpec text = param::text("path");
  EXPECT_EQ(text.type, ParamType::String);
  EXPECT_EQ(std::get<std::string>(text.default_value), "");
  const ParamSpec mode = param::choice("mode", "b", {"a", "b"});
  EXPECT_EQ(mode.type, ParamType::Choice);
  EXPECT_EQ(std::get<std::string>(mode.default_value), "b");
  EXPECT_EQ(mode.choices, (std::vector<std::string>{"a", "b"}));
  // A default that is not a choice is a mistake in the table, caught where the table is built.
  EXPECT_THROW((void)param::choice("mode", "c", {"a", "b"}), std::logic_error);
}

TEST(Params, DefaultsAndParsing) {
  Params p("algorithm 'x'", specs());
  EXPECT_DOUBLE_EQ(p.real("step"), 0.02);
  EXPECT_FALSE(p.was_set("step"));
  p.set_assignment("step=0.5");
  p.set("count", "42");
  p.set("flag", "yes");
  p.set("mode", "closed");
  p.set("dir", "1,-2.5,3");
  p.set("file", "a=b.txt");
  EXPECT_DOUBLE_EQ(p.real("step"), 0.5);
  EXPECT_TRUE(p.was_set("step"));
  EXPECT_EQ(p.integer("count"), 42);
  EXPECT_TRUE(p.boolean("flag"));
  EXPECT_EQ(p.text("mode"), "closed");
  EXPECT_EQ(p.vec3("dir"), glm::dvec3(1, -2.5, 3));
  EXPECT_EQ(p.text("file"), "a=b.txt");
  p.set("count", "1e1");  // whole numbers in exponent form are accepted
  EXPECT_EQ(p.integer("count"), 10);
}

TEST(Params, UnknownKeySuggestsCloseMatch) {
  Params p("algorithm 'x'", specs());
  const std::string e = error_of([&] { p.set("stpe", "1"); });
  EXPECT_NE(e.find("unknown parameter 'stpe'"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'step'"), std::string::npos) << e;
  EXPECT_NE(e.find("algorithm 'x'"), std::string::npos) << e;
  const std::string far = error_of([&] { p.set("zzzzzzzz", "1"); });
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
}

TEST(Params, WrongTypeRangeAndNonFinite) {
  Params p("algorithm 'x'", specs());
  std::string e = error_of([&] { p.set("step", "abc"); });
  EXPECT_NE(e.find("'step'"), std::string::npos);
  EXPECT_NE(e.find("'abc'"), std::string::npos);
  EXPECT_NE(e.find("real number"), std::string::npos) << e;
  e = error_of([&] { p.set("step", "2"); });
  EXPECT_NE(e.find("out of range"), std::string::npos) << e;
  EXPECT_NE(e.find("[0.0001, 1]"), std::string::npos) << e;
  e = error_of([&] { p.set("step", "nan"); });
  EXPECT_NE(e.find("not finite"), std::string::npos) << e;
  e = error_of([&] { p.set("step", "inf"); });
  EXPECT_NE(e.find("not finite"), std::string::npos) << e;
  e = error_of([&] { p.set("count", "2.5"); });
  EXPECT_NE(e.find("integer"), std::string::npos) << e;
  e = error_of([&] { p.set("flag", "maybe"); });
  EXPECT_NE(e.find("boolean"), std::string::npos) << e;
  e = error_of([&] { p.set("mode", "clsoed"); });
  EXPECT_NE(e.find("did you mean 'closed'"), std::string::npos) << e;
  e = error_of([&] { p.set("dir", "1,2"); });
  EXPECT_NE(e.find("x,y,z"), std::string::npos) << e;
  e = error_of([&] { p.set_assignment("step"); });
  EXPECT_NE(e.find("key=value"), std::string::npos) << e;
  // A failed set leaves the previous value in place.
  EXPECT_DOUBLE_EQ(p.real("step"), 0.02);
}

TEST(Params, Json) {
  Params p("suite entry", specs());
  p.set_json("step", nlohmann::json(0.1));
  p.set_json("count", nlohmann::json(7));
  p.set_json("dir", nlohmann::json::array({0, 0, 1}));
  EXPECT_EQ(p.integer("count"), 7);
  EXPECT_EQ(p.vec3("dir"), glm::dvec3(0, 0, 1));
  EXPECT_NE(error_of([&] { p.set_json("count", nlohmann::json("7")); }).find("wrong type"), std::string::npos);
  const auto j = p.to_json();
  EXPECT_DOUBLE_EQ(j["step"].get<double>(), 0.1);
  EXPECT_EQ(j["mode"], "open");
}

// A JSON integer beyond int64 wrapped (18446744073709551615 read as -1), and a whole real beyond it was
// cast with undefined behaviour.
TEST(Params, JsonIntegersOutOfRangeAreRefused) {
  Params p("suite entry", {param::integer("count", 10)});
  EXPECT_EQ(error_of([&] { p.set_json("count", nlohmann::json::parse("18446744073709551615")); }),
            "parameter 'count' of suite entry: value 18446744073709551615 is out of range; expected an integer");
  EXPECT_EQ(error_of([&] { p.set_json("count", nlohmann::json(1e300)); }),
            "parameter 'count' of suite entry: value 1e+300 is out of range; expected an integer");
  p.set_json("count", nlohmann::json(1e6));
  EXPECT_EQ(p.integer("count"), 1000000);
  EXPECT_EQ(error_of([&] { p.set("count", "1e300"); }),
            "parameter 'count' of suite entry: cannot read '1e300'; expected an integer");
}

// A text value goes into records and journals, which are JSON: bytes that are not UTF-8 cannot.
TEST(Params, TextMustBeValidUtf8) {
  Params p("algorithm 'x'", specs());
  EXPECT_EQ(error_of([&] { p.set("file", "a\xC3.png"); }),
            "parameter 'file' of algorithm 'x': value 'a\\xc3.png' is not valid UTF-8 text; expected a string");
  p.set("file", "caf\xC3\xA9.png");
  EXPECT_EQ(p.text("file"), "caf\xC3\xA9.png");
}

}  // namespace
}  // namespace growbench
