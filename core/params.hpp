// Typed, validated parameters. Algorithms and parameterised scenes declare a table of ParamSpec; user
// values arrive as strings (--set key=value) or JSON and are checked against it. An unknown key, a wrong
// type, a non-finite or out-of-range value is an InputError that names the key, the value and what is
// allowed (with a close match for typos). Nothing runs silently on a typo.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json_fwd.hpp>

namespace growbench {

enum class ParamType { Int, Real, Bool, String, Vec3, Choice };
std::string_view to_string(ParamType t);

using ParamValue = std::variant<std::int64_t, double, bool, std::string, glm::dvec3>;

struct ParamSpec {
  std::string name;
  ParamType type = ParamType::Real;
  ParamValue default_value;
  double min = -std::numeric_limits<double>::infinity();  // Int, Real, each Vec3 component
  double max = std::numeric_limits<double>::infinity();
  std::string unit;                  // "m", "deg", "" ...
  std::string doc;                   // one line
  std::vector<std::string> choices;  // Choice only

  [[nodiscard]] std::string allowed() const;  // "a real number in [0, 1] (m)" etc.
};

std::string format_value(const ParamValue& v);

// Builders for the rows of a parameter table, so that a row states only what it has: its type, name and
// default, then whichever of range, unit, doc it needs (a row without a range accepts any finite value):
//   param::real("gravity", 0.5).range(0, 1000).unit("m/s^2").doc("a_g, downwards")
//   param::choice("venation", "open", {"open", "closed"}).doc("...")
// A row converts to its ParamSpec where the table is built.
namespace param {

class Row {
 public:
  Row(std::string name, ParamType type, ParamValue default_value);
  Row&& range(double min, double max) &&;
  Row&& unit(std::string unit) &&;
  Row&& doc(std::string doc) &&;
  operator ParamSpec() &&;  // NOLINT(google-explicit-constructor): a table is a list of rows

 private:
  friend Row choice(std::string name, std::string default_value, std::vector<std::string> choices);
  ParamSpec spec_;
};

Row integer(std::string name, std::int64_t default_value);
Row real(std::string name, double default_value);
Row boolean(std::string name, bool default_value);
Row text(std::string name, std::string default_value = {});
Row vec3(std::string name, const glm::dvec3& default_value);
// The default must be one of the choices (std::logic_error otherwise: a mistake in the table).
Row choice(std::string name, std::string default_value, std::vector<std::string> choices);

}  // namespace param

// The closest candidate to `name` by edit distance, or "" when nothing is close.
std::string closest_match(std::string_view name, const std::vector<std::string>& candidates);
// InputError "WHAT 'GIVEN': expected a, b or c (did you mean 'b'?)" for a value outside a list of choices.
[[noreturn]] void throw_unknown_choice(std::string_view what, std::string_view given,
                                       const std::vector<std::string>& choices);

// Named defaults for a parameter table: when the table's Choice parameter `preset` takes the value
// `name`, the listed parameters default to these values instead of their spec defaults (a value the
// user set explicitly always wins, whichever order the assignments came in).
struct ParamPreset {
  std::string name;
  std::vector<std::pair<std::string, ParamValue>> values;
};

class Params {
 public:
  Params() = default;
  // `owner` names whose parameters these are in error messages, e.g. "algorithm 'spacecol'".
  Params(std::string owner, const std::vector<ParamSpec>& specs);
  // Installs presets (see ParamPreset) and applies the one the `preset` parameter names now.
  void set_presets(const std::vector<ParamPreset>& presets);

  void set(std::string_view key, std::string_view text);  // parse and validate
  void set_json(std::string_view key, const nlohmann::json& value);
  // "key=value" as given on the command line.
  void set_assignment(std::string_view assignment);

  [[nodiscard]] std::int64_t integer(std::string_view key) const;
  [[nodiscard]] double real(std::string_view key) const;
  [[nodiscard]] bool boolean(std::string_view key) const;
  [[nodiscard]] const std::string& text(std::string_view key) const;  // String and Choice
  [[nodiscard]] glm::dvec3 vec3(std::string_view key) const;
  [[nodiscard]] bool was_set(std::string_view key) const;  // given by the user (not defaulted)

  [[nodiscard]] const std::vector<ParamSpec>& specs() const { return specs_; }
  [[nodiscard]] const std::string& owner() const { return owner_; }
  // Every parameter with its effective value (what a trial record stores).
  [[nodiscard]] nlohmann::json to_json() const;

 private:
  [[nodiscard]] std::size_t index_of(std::string_view key) const;  // throws InputError if unknown
  [[nodiscard]] const ParamValue& value(std::string_view key, ParamType expected) const;
  void check_and_store(std::size_t i, ParamValue v, std::string_view shown);
  void apply_preset();

  std::string owner_;
  std::vector<ParamSpec> specs_;
  std::vector<ParamValue> values_;
  std::vector<bool> set_;
  std::vector<ParamPreset> presets_;
};

}  // namespace growbench
