#include "core/params.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/json_util.hpp"
#include "core/utf8.hpp"

namespace growbench {

std::string_view to_string(ParamType t) {
  switch (t) {
    case ParamType::Int:
      return "int";
    case ParamType::Real:
      return "real";
    case ParamType::Bool:
      return "bool";
    case ParamType::String:
      return "string";
    case ParamType::Vec3:
      return "vec3";
    case ParamType::Choice:
      return "choice";
  }
  return "?";
}

namespace {
std::string fmt_num(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{:g}", v);
}
}  // namespace

std::string format_value(const ParamValue& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::int64_t>)
          return fmt::format("{}", x);
        else if constexpr (std::is_same_v<T, double>)
          return fmt_num(x);
        else if constexpr (std::is_same_v<T, bool>)
          return x ? "true" : "false";
        else if constexpr (std::is_same_v<T, std::string>)
          return x;
        else
          return fmt::format("{},{},{}", fmt_num(x.x), fmt_num(x.y), fmt_num(x.z));
      },
      v);
}

std::string ParamSpec::allowed() const {
  std::string range;
  if (std::isfinite(min) || std::isfinite(max)) range = fmt::format(" in [{}, {}]", fmt_num(min), fmt_num(max));
  const std::string u = unit.empty() ? "" : fmt::format(" ({})", unit);
  switch (type) {
    case ParamType::Int:
      return fmt::format("an integer{}{}", range, u);
    case ParamType::Real:
      return fmt::format("a finite real number{}{}", range, u);
    case ParamType::Bool:
      return "a boolean (true/false, 1/0, yes/no, on/off)";
    case ParamType::String:
      return "a string";
    case ParamType::Vec3:
      return fmt::format("three comma-separated numbers x,y,z each{}{}", range, u);
    case ParamType::Choice:
      return fmt::format("one of {}", fmt::join(choices, ", "));
  }
  return "?";
}

namespace param {

Row::Row(std::string name, ParamType type, ParamValue default_value) {
  spec_.name = std::move(name);
  spec_.type = type;
  spec_.default_value = std::move(default_value);
}
Row&& Row::range(double min, double max) && {
  spec_.min = min;
  spec_.max = max;
  return std::move(*this);
}
Row&& Row::unit(std::string unit) && {
  spec_.unit = std::move(unit);
  return std::move(*this);
}
Row&& Row::doc(std::string doc) && {
  spec_.doc = std::move(doc);
  return std::move(*this);
}
Row::operator ParamSpec() && {
  return std::move(spec_);
}

Row integer(std::string name, std::int64_t default_value) {
  return {std::move(name), ParamType::Int, default_value};
}
Row real(std::string name, double default_value) {
  return {std::move(name), ParamType::Real, default_value};
}
Row boolean(std::string name, bool default_value) {
  return {std::move(name), ParamType::Bool, default_value};
}
Row text(std::string name, std::string default_value) {
  return {std::move(name), ParamType::String, std::move(default_value)};
}
Row vec3(std::string name, const glm::dvec3& default_value) {
  return {std::move(name), ParamType::Vec3, default_value};
}
Row choice(std::string name, std::string default_value, std::vector<std::string> choices) {
  if (std::find(choices.begin(), choices.end(), default_value) == choices.end())
    throw std::logic_error(fmt::format("parameter '{}': default '{}' is not one of its choices", name, default_value));
  Row row(std::move(name), ParamType::Choice, std::move(default_value));
  row.spec_.choices = std::move(choices);
  return row;
}

}  // namespace param

void throw_unknown_choice(std::string_view what, std::string_view given, const std::vector<std::string>& choices) {
  std::string list;
  for (std::size_t i = 0; i < choices.size(); ++i)
    list += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i];
  const std::string near = closest_match(given, choices);
  throw InputError(fmt::format("{} '{}': expected {}{}", what, given, list,
                               near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near)));
}

std::string closest_match(std::string_view name, const std::vector<std::string>& candidates) {
  // Optimal string alignment distance: insertions, deletions, substitutions and adjacent transpositions
  // ("stpe" is one edit from "step").
  auto distance = [](std::string_view a, std::string_view b) {
    std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
        d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
        if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
          d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
    return d[a.size()][b.size()];
  };
  std::string best;
  std::size_t best_d = std::numeric_limits<std::size_t>::max();
  for (const auto& c : candidates) {
    const std::size_t d = distance(name, c);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  // Close means: at most a third of the longer name changed (and at least one edit allowed).
  const std::size_t limit = std::max<std::size_t>(1, std::max(name.size(), best.size()) / 3);
  return best_d <= limit ? best : std::string{};
}

Params::Params(std::string owner, const std::vector<ParamSpec>& specs)
    : owner_(std::move(owner)), specs_(specs), set_(specs.size(), false) {
  values_.reserve(specs_.size());
  for (const auto& s : specs_) values_.push_back(s.default_value);
}

std::size_t Params::index_of(std::string_view key) const {
  for (std::size_t i = 0; i < specs_.size(); ++i)
    if (specs_[i].name == key) return i;
  std::vector<std::string> names;
  for (const auto& s : specs_) names.push_back(s.name);
  const std::string near = closest_match(key, names);
  throw InputError(fmt::format("unknown parameter '{}' for {}{}; known parameters: {}", key, owner_,
                               near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near), fmt::join(names, ", ")));
}

void Params::check_and_store(std::size_t i, ParamValue v, std::string_view shown) {
  const ParamSpec& s = specs_[i];
  auto bad = [&](std::string_view why) {
    throw InputError(
        fmt::format("parameter '{}' of {}: value '{}' {}; expected {}", s.name, owner_, shown, why, s.allowed()));
  };
  auto check_range = [&](double x) {
    if (!std::isfinite(x)) bad("is not finite");
    if (x < s.min || x > s.max) bad("is out of range");
  };
  switch (s.type) {
    case ParamType::Int:
      check_range(static_cast<double>(std::get<std::int64_t>(v)));
      break;
    case ParamType::Real:
      check_range(std::get<double>(v));
      break;
    case ParamType::Vec3: {
      const auto& x = std::get<glm::dvec3>(v);
      check_range(x.x);
      check_range(x.y);
      check_range(x.z);
      break;
    }
    case ParamType::String:
      // Values are written to records and journals, which are JSON: text that is not UTF-8 cannot be.
      if (!is_valid_utf8(std::get<std::string>(v))) bad("is not valid UTF-8 text");
      break;
    case ParamType::Choice:
      if (std::find(s.choices.begin(), s.choices.end(), std::get<std::string>(v)) == s.choices.end()) {
        const std::string near = closest_match(std::get<std::string>(v), s.choices);
        bad(near.empty() ? "is not a valid choice" : fmt::format("is not a valid choice (did you mean '{}'?)", near));
      }
      break;
    default:
      break;
  }
  values_[i] = std::move(v);
  set_[i] = true;
  if (s.name == "preset") apply_preset();
}

void Params::set_presets(const std::vector<ParamPreset>& presets) {
  presets_ = presets;
  for (const auto& p : presets_)
    for (const auto& [key, v] : p.values) {
      const std::size_t i = index_of(key);  // a typo in a preset table is a programming error
      if (v.index() != specs_[i].default_value.index())
        throw std::logic_error(fmt::format("preset '{}' of {}: '{}' has the wrong type", p.name, owner_, key));
    }
  apply_preset();
}

void Params::apply_preset() {
  const auto it = std::find_if(specs_.begin(), specs_.end(), [](const ParamSpec& s) { return s.name == "preset"; });
  if (it == specs_.end() || presets_.empty()) return;
  const std::string& name = std::get<std::string>(values_[static_cast<std::size_t>(it - specs_.begin())]);
  const ParamPreset* preset = nullptr;
  for (const auto& p : presets_)
    if (p.name == name) preset = &p;
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    if (set_[i]) continue;
    values_[i] = specs_[i].default_value;
    if (preset)
      for (const auto& [key, v] : preset->values)
        if (key == specs_[i].name) values_[i] = v;
  }
}

namespace {
// The largest whole number an integer parameter takes from a real number's text or JSON (2^53: every
// integer up to it is exact in a double).
constexpr double kMaxExactInteger = 9007199254740992.0;

bool parse_double(std::string_view t, double& out) {
  while (!t.empty() && t.front() == ' ') t.remove_prefix(1);
  while (!t.empty() && t.back() == ' ') t.remove_suffix(1);
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), out);
  return r.ec == std::errc{} && r.ptr == t.data() + t.size();
}
}  // namespace

void Params::set(std::string_view key, std::string_view text) {
  const std::size_t i = index_of(key);
  const ParamSpec& s = specs_[i];
  auto bad = [&]() {
    throw InputError(fmt::format("parameter '{}' of {}: cannot read '{}'; expected {}", s.name, owner_,
                                 utf8_excerpt(text, kJsonExcerptBytes), s.allowed()));
  };
  switch (s.type) {
    case ParamType::Int: {
      std::int64_t v = 0;
      const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
      if (r.ec != std::errc{} || r.ptr != text.data() + text.size()) {
        double d = 0;  // accept "1e6" and "3.0" when they are whole numbers
        if (!parse_double(text, d) || d != std::floor(d) || std::abs(d) > kMaxExactInteger) bad();
        v = static_cast<std::int64_t>(d);
      }
      check_and_store(i, v, utf8_excerpt(text, kJsonExcerptBytes));
      break;
    }
    case ParamType::Real: {
      double v = 0;
      if (!parse_double(text, v)) bad();
      check_and_store(i, v, utf8_excerpt(text, kJsonExcerptBytes));
      break;
    }
    case ParamType::Bool: {
      std::string t(text);
      std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return std::tolower(c); });
      bool v = false;
      if (t == "true" || t == "1" || t == "yes" || t == "on")
        v = true;
      else if (t == "false" || t == "0" || t == "no" || t == "off")
        v = false;
      else
        bad();
      check_and_store(i, v, text);
      break;
    }
    case ParamType::String:
    case ParamType::Choice:
      check_and_store(i, std::string(text), utf8_excerpt(text, kJsonExcerptBytes));
      break;
    case ParamType::Vec3: {
      glm::dvec3 v{0.0};
      std::string_view rest = text;
      for (int c = 0; c < 3; ++c) {
        const auto comma = rest.find(',');
        if ((c < 2) != (comma != std::string_view::npos)) bad();
        if (!parse_double(rest.substr(0, comma), v[c])) bad();
        if (c < 2) rest.remove_prefix(comma + 1);
      }
      check_and_store(i, v, utf8_excerpt(text, kJsonExcerptBytes));
      break;
    }
  }
}

void Params::set_json(std::string_view key, const nlohmann::json& j) {
  const std::size_t i = index_of(key);
  const ParamSpec& s = specs_[i];
  const std::string shown = json_excerpt(j);
  auto bad = [&]() {
    throw InputError(fmt::format("parameter '{}' of {}: value {} has the wrong type; expected {}", s.name, owner_,
                                 shown, s.allowed()));
  };
  switch (s.type) {
    case ParamType::Int: {
      const bool too_big =
          j.is_number_unsigned() &&
          j.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
      const bool whole = j.is_number_float() && j.get<double>() == std::floor(j.get<double>());
      // A real number is taken when whole and exact in a double (as set() reads "1e6"); beyond, a cast is undefined.
      if (too_big || (whole && std::abs(j.get<double>()) > kMaxExactInteger))
        throw InputError(fmt::format("parameter '{}' of {}: value {} is out of range; expected {}", s.name, owner_,
                                     shown, s.allowed()));
      if (j.is_number_integer())
        check_and_store(i, j.get<std::int64_t>(), shown);
      else if (whole)
        check_and_store(i, static_cast<std::int64_t>(j.get<double>()), shown);
      else
        bad();
      break;
    }
    case ParamType::Real:
      if (!j.is_number()) bad();
      check_and_store(i, j.get<double>(), shown);
      break;
    case ParamType::Bool:
      if (!j.is_boolean()) bad();
      check_and_store(i, j.get<bool>(), shown);
      break;
    case ParamType::String:
    case ParamType::Choice:
      if (!j.is_string()) bad();
      check_and_store(i, j.get<std::string>(), shown);
      break;
    case ParamType::Vec3:
      if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number()) bad();
      check_and_store(i, glm::dvec3(j[0].get<double>(), j[1].get<double>(), j[2].get<double>()), shown);
      break;
  }
}

void Params::set_assignment(std::string_view a) {
  const auto eq = a.find('=');
  if (eq == std::string_view::npos || eq == 0)
    throw InputError(fmt::format("'{}' for {}: expected key=value", a, owner_));
  set(a.substr(0, eq), a.substr(eq + 1));
}

const ParamValue& Params::value(std::string_view key, ParamType expected) const {
  const std::size_t i = index_of(key);
  const ParamType t = specs_[i].type;
  const bool ok = t == expected || (expected == ParamType::String && t == ParamType::Choice);
  if (!ok)  // a programming error in an algorithm, not user input
    throw std::logic_error(
        fmt::format("parameter '{}' of {} is {}, read as {}", key, owner_, to_string(t), to_string(expected)));
  return values_[i];
}

std::int64_t Params::integer(std::string_view key) const {
  return std::get<std::int64_t>(value(key, ParamType::Int));
}
double Params::real(std::string_view key) const {
  return std::get<double>(value(key, ParamType::Real));
}
bool Params::boolean(std::string_view key) const {
  return std::get<bool>(value(key, ParamType::Bool));
}
const std::string& Params::text(std::string_view key) const {
  return std::get<std::string>(value(key, ParamType::String));
}
glm::dvec3 Params::vec3(std::string_view key) const {
  return std::get<glm::dvec3>(value(key, ParamType::Vec3));
}
bool Params::was_set(std::string_view key) const {
  return set_[index_of(key)];
}

nlohmann::json Params::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    std::visit(
        [&](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, glm::dvec3>)
            j[specs_[i].name] = {x.x, x.y, x.z};
          else
            j[specs_[i].name] = x;
        },
        values_[i]);
  }
  return j;
}

}  // namespace growbench
