#include "harness/record/record.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/params.hpp"
#include "harness/record/files.hpp"
#include "harness/record/reflect.hpp"

namespace growbench {
using nlohmann::json;

namespace {

// ---------------------------------------------------------------- reading

// A JSON value and where it is: the file (for errors) and the path to it ("trials[3].samples[0]").
struct Node {
  const json& j;
  const std::string& source;
  std::string path;

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}: at {}: {}", source, path.empty() ? "the top level" : path, what));
  }
  [[nodiscard]] Node key(std::string_view k) const {
    return {j.at(std::string(k)), source, path.empty() ? std::string(k) : fmt::format("{}.{}", path, k)};
  }
  [[nodiscard]] Node index(std::size_t i) const { return {j[i], source, fmt::format("{}[{}]", path, i)}; }
  [[nodiscard]] std::string got() const {
    return fmt::format("got {}", j.is_string() ? j.dump() : std::string(j.type_name()));
  }
};

// The keys of an object that nobody named, each refused with a close match when there is one.
void refuse_unknown(const Node& n, const std::vector<std::string>& named) {
  for (const auto& [k, v] : n.j.items()) {
    if (std::find(named.begin(), named.end(), k) != named.end()) continue;
    const std::string near = closest_match(k, named);
    n.key(k).fail(
        fmt::format("unknown field '{}'{}", k, near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near)));
  }
}

template <class T>
void read(const Node& n, T& v, const ValueRule& rule);

template <class V>
void checked(const Node& n, const V& v, const ValueRule& rule) {
  if (const std::string bad = check_value(rule, v); !bad.empty()) n.fail(bad);
}

// Integers: JSON integers, and whole numbers written as floats (1e6 from Python), in range.
template <class T>
void read_integer(const Node& n, T& v) {
  const char* what = std::is_signed_v<T> ? "an integer" : "a non-negative integer";
  if (n.j.is_number_unsigned()) {
    const auto u = n.j.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<T>::max()))
      n.fail(fmt::format("expected {}, {} is too large", what, u));
    v = static_cast<T>(u);
  } else if (n.j.is_number_integer()) {
    const auto s = n.j.get<std::int64_t>();
    if ((std::is_unsigned_v<T> && s < 0) ||
        (std::is_signed_v<T> && (s < static_cast<std::int64_t>(std::numeric_limits<T>::min()) ||
                                 s > static_cast<std::int64_t>(std::numeric_limits<T>::max()))))
      n.fail(fmt::format("expected {}, got {}", what, s));
    v = static_cast<T>(s);
  } else if (n.j.is_number_float()) {
    const double d = n.j.get<double>();
    if (d != std::floor(d) || d < static_cast<double>(std::numeric_limits<T>::min()) ||
        d >= std::ldexp(1.0, std::numeric_limits<T>::digits))
      n.fail(fmt::format("expected {}, got {}", what, n.j.dump()));
    v = static_cast<T>(d);
  } else {
    n.fail(fmt::format("expected {}, {}", what, n.got()));
  }
}

// The flattened keys of T: its own, and those of its inline structs.
template <class T>
void keys_of(std::vector<std::string>& out) {
  for_each_field<T>([&](auto at) {
    constexpr auto f = GROWBENCH_FIELD(at);
    if constexpr (f.has(kInline))
      keys_of<typename unoptional<typename decltype(f)::Member>::type>(out);
    else
      out.emplace_back(f.key);
  });
}

// Reads the fields of T from the object at `n`, naming each key it reads in `named`.
template <class T>
void read_fields(const Node& n, T& v, std::vector<std::string>& named) {
  for_each_field<T>([&](auto at) {
    constexpr auto f = GROWBENCH_FIELD(at);
    using M = typename decltype(f)::Member;
    M& m = v.*f.member;
    if constexpr (f.has(kInline)) {
      if constexpr (is_optional<M>::value) {
        // Present when any of its keys is.
        std::vector<std::string> keys;
        keys_of<typename M::value_type>(keys);
        m.reset();
        if (std::any_of(keys.begin(), keys.end(), [&](const std::string& k) { return n.j.contains(k); }))
          read_fields(n, m.emplace(), named);
        else
          named.insert(named.end(), keys.begin(), keys.end());
      } else {
        read_fields(n, m, named);
      }
    } else {
      named.emplace_back(f.key);
      const auto it = n.j.find(std::string(f.key));
      if (it == n.j.end()) {
        if (f.has(kRequiredField)) n.fail(fmt::format("expected the field '{}'", f.key));
        if constexpr (is_optional<M>::value) m.reset();
        return;
      }
      if constexpr (is_optional<M>::value) {
        m.reset();
        if (it->is_null()) return;
        read(n.key(f.key), m.emplace(), ValueRule::of(f));
      } else {
        read(n.key(f.key), m, ValueRule::of(f));
      }
    }
  });
}

template <class T>
void read(const Node& n, T& v, const ValueRule& rule) {
  if constexpr (std::is_same_v<T, bool>) {
    if (!n.j.is_boolean()) n.fail("expected true or false, " + n.got());
    v = n.j.get<bool>();
  } else if constexpr (std::is_integral_v<T>) {
    read_integer(n, v);
    checked(n, v, rule);
  } else if constexpr (std::is_floating_point_v<T>) {
    if (!n.j.is_number()) n.fail("expected a number, " + n.got());
    v = n.j.get<T>();
    checked(n, v, rule);
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!n.j.is_string())
      n.fail(rule.names.empty() ? "expected a string, " + n.got()
                                : fmt::format("expected one of {}, {}", fmt::join(rule.names, ", "), n.got()));
    v = n.j.get<std::string>();
    checked(n, v, rule);
  } else if constexpr (NamedEnum<T>) {
    std::string name;
    read(n, name, ValueRule{.names = enum_names(T{})});
    const auto names = enum_names(T{});
    v = static_cast<T>(std::find(names.begin(), names.end(), name) - names.begin());
  } else if constexpr (std::is_same_v<T, json>) {
    // Open-ended parts (metrics and parameters by name, sweep values, versions): objects, kept as they are.
    if (!n.j.is_object()) n.fail("expected an object, " + n.got());
    v = n.j;
  } else if constexpr (is_vector<T>::value) {
    if (!n.j.is_array()) n.fail("expected an array, " + n.got());
    v.assign(n.j.size(), typename T::value_type{});
    for (std::size_t i = 0; i < v.size(); ++i) read(n.index(i), v[i], rule);
  } else if constexpr (is_string_map<T>::value) {
    if (!n.j.is_object()) n.fail("expected an object, " + n.got());
    v.clear();
    for (const auto& [k, x] : n.j.items()) read(n.key(k), v[k], rule);
  } else if constexpr (is_std_array<T>::value) {
    constexpr std::size_t N = std::tuple_size_v<T>;
    if (!n.j.is_array()) n.fail(fmt::format("expected an array of {}, {}", N, n.got()));
    if (n.j.size() != N) n.fail(fmt::format("expected an array of {}, got {} items", N, n.j.size()));
    for (std::size_t i = 0; i < N; ++i) read(n.index(i), v[i], rule);
  } else if constexpr (is_phase_map<T>::value) {
    if (!n.j.is_object()) n.fail("expected an object, " + n.got());
    v = T{};
    refuse_unknown(n, {kPhaseNames.begin(), kPhaseNames.end()});
    for (const Phase p : kPhases)
      if (n.j.contains(std::string(phase_name(p)))) read(n.key(phase_name(p)), v[p].emplace(), rule);
  } else {
    static_assert(Declared<T>, "a record field of a type the reader does not know");
    if (!n.j.is_object()) n.fail("expected an object, " + n.got());
    std::vector<std::string> named;
    read_fields(n, v, named);
    refuse_unknown(n, named);
  }
}

// ---------------------------------------------------------------- writing

// A default-constructed T, made once (and never destroyed: GCC 12 warns of a false uninitialized read in
// the destructor of a static TrialRecord).
template <class T>
const T& defaults_of() {
  static const T* defaults = new T{};
  return *defaults;
}

template <class T>
json value_json(const T& v);

template <class T>
void write_fields(json& j, const T& v) {
  for_each_field<T>([&](auto at) {
    constexpr auto f = GROWBENCH_FIELD(at);
    using M = typename decltype(f)::Member;
    const M& m = v.*f.member;
    if constexpr (f.has(kInline)) {
      if constexpr (is_optional<M>::value) {
        if (m) write_fields(j, *m);
      } else {
        write_fields(j, m);
      }
    } else if constexpr (is_optional<M>::value) {
      if (m)
        j[std::string(f.key)] = value_json(*m);
      else if (f.has(kNullable))
        j[std::string(f.key)] = nullptr;
      return;
    } else {
      if constexpr (f.has(kOmitEmpty))
        if (m.empty()) return;
      if constexpr (f.has(kOmitDefault))
        if (m == defaults_of<T>().*f.member) return;
      j[std::string(f.key)] = value_json(m);
    }
  });
}

template <class T>
json value_json(const T& v) {
  if constexpr (NamedEnum<T>) {
    return std::string(enum_names(v)[static_cast<std::size_t>(v)]);
  } else if constexpr (is_vector<T>::value || is_std_array<T>::value) {
    json a = json::array();
    for (const auto& x : v) a.push_back(value_json(x));
    return a;
  } else if constexpr (is_string_map<T>::value) {
    json o = json::object();
    for (const auto& [k, x] : v) o[k] = value_json(x);
    return o;
  } else if constexpr (is_phase_map<T>::value) {
    json o = json::object();
    v.each([&](Phase p, const auto& x) { o[std::string(phase_name(p))] = value_json(x); });
    return o;
  } else if constexpr (Declared<T>) {
    json o = json::object();
    write_fields(o, v);
    return o;
  } else {
    return json(v);
  }
}

// ---------------------------------------------------------------- the schema

constexpr std::string_view kSchemaId = "https://growbench.invalid/harness/record/results.schema.json";
constexpr std::string_view kSchemaDescription =
    "What `growbench suite` writes, generated from the field declarations in harness/record/record.hpp "
    "(`make schema`; a test fails while this file differs from what the binary declares). $defs also describe "
    "the trial record (record.json), the baseline (reports/baselines/*.json), a journal line and a history file. "
    "Every field the harness always writes is required; objects whose fields the harness defines admit no "
    "others, so a renamed or mistyped field fails. Open-ended parts (parameters, metrics, sweep values, library "
    "versions) are objects of any keys.";

// A rule's range or names on the innermost value of a schema (the items of an array, the values of a map).
void apply_rule(json& s, const ValueRule& rule) {
  if (s.contains("items")) return apply_rule(s["items"], rule);
  if (s.contains("additionalProperties") && s["additionalProperties"].is_object() &&
      !s["additionalProperties"].contains("$ref"))
    return apply_rule(s["additionalProperties"], rule);
  if (!rule.names.empty()) s["enum"] = json(std::vector<std::string>(rule.names.begin(), rule.names.end()));
  if (!rule.bounded()) return;
  json range = json::object();
  if (!std::isinf(rule.lo)) range["minimum"] = rule.lo;
  if (!std::isinf(rule.hi)) range["maximum"] = rule.hi;
  if (rule.zero_or) {
    s["anyOf"] = json::array({{{"const", 0}}, range});
  } else {
    s.erase("minimum");
    s.update(range);
  }
}

class SchemaBuilder {
 public:
  json defs = json::object();

  template <class T>
  json type_schema() {
    if constexpr (is_optional<T>::value) {
      return type_schema<typename T::value_type>();
    } else if constexpr (std::is_same_v<T, bool>) {
      return {{"type", "boolean"}};
    } else if constexpr (std::is_integral_v<T>) {
      return std::is_unsigned_v<T> ? json{{"type", "integer"}, {"minimum", 0}} : json{{"type", "integer"}};
    } else if constexpr (std::is_floating_point_v<T>) {
      return {{"type", "number"}};
    } else if constexpr (std::is_same_v<T, std::string>) {
      return {{"type", "string"}};
    } else if constexpr (NamedEnum<T>) {
      const auto names = enum_names(T{});
      return {{"enum", std::vector<std::string>(names.begin(), names.end())}};
    } else if constexpr (std::is_same_v<T, json>) {
      return {{"type", "object"}};
    } else if constexpr (is_vector<T>::value) {
      return {{"type", "array"}, {"items", type_schema<typename T::value_type>()}};
    } else if constexpr (is_std_array<T>::value) {
      constexpr std::size_t N = std::tuple_size_v<T>;
      return {{"type", "array"}, {"items", type_schema<typename T::value_type>()}, {"minItems", N}, {"maxItems", N}};
    } else if constexpr (is_string_map<T>::value) {
      return {{"type", "object"}, {"additionalProperties", type_schema<typename T::mapped_type>()}};
    } else if constexpr (is_phase_map<T>::value) {
      return {{"type", "object"},
              {"propertyNames", {{"enum", std::vector<std::string>(kPhaseNames.begin(), kPhaseNames.end())}}},
              {"additionalProperties", type_schema<typename T::value_type>()}};
    } else {
      static_assert(Declared<T>);
      define<T>();
      return {{"$ref", fmt::format("#/$defs/{}", schema_name_of<T>())}};
    }
  }

  template <class T>
  void define() {
    const std::string name(schema_name_of<T>());
    if (defs.contains(name)) return;
    defs[name] = json::object();  // a placeholder against recursion
    json props = json::object();
    std::vector<std::string> required, when_ok;
    add_properties<T>(props, required, when_ok, false);
    json def = {{"type", "object"}, {"additionalProperties", false}, {"properties", props}};
    if (!required.empty()) def["required"] = required;
    if (!when_ok.empty()) {
      def["if"] = {{"properties", {{"status", {{"const", "ok"}}}}}, {"required", {"status"}}};
      def["then"] = {{"required", when_ok}};
    }
    if constexpr (requires { T::kSchemaDoc; }) def["description"] = std::string(T::kSchemaDoc);
    defs[name] = std::move(def);
  }

 private:
  // T's properties into `props`; its always-written fields into `required` (into `when_ok` instead when
  // `ok_only`: an inline struct present only in ok cells).
  template <class T>
  void add_properties(json& props, std::vector<std::string>& required, std::vector<std::string>& when_ok,
                      bool ok_only) {
    for_each_field<T>([&](auto at) {
      constexpr auto f = GROWBENCH_FIELD(at);
      using M = typename decltype(f)::Member;
      if constexpr (f.has(kInline)) {
        add_properties<typename unoptional<M>::type>(props, required, when_ok, ok_only || f.has(kWhenOk));
        return;
      }
      const std::string key(f.key);
      if (props.contains(key))
        throw std::logic_error(fmt::format("{}: two fields write the key '{}'", schema_name_of<T>(), key));
      props[key] = field_schema<T>(at);
      const bool always = (!is_optional<M>::value || f.has(kNullable)) && !f.has(kOmitEmpty) && !f.has(kOmitDefault);
      if (always || f.has(kRequiredField))
        (ok_only ? when_ok : required).push_back(key);
      else if (f.has(kWhenOk))
        when_ok.push_back(key);
    });
  }

  template <class T, class At>
  json field_schema(At at) {
    constexpr auto f = GROWBENCH_FIELD(at);
    using M = typename decltype(f)::Member;
    json s = type_schema<M>();
    if (!s.contains("$ref")) apply_rule(s, ValueRule::of(f));
    if constexpr (f.has(kConstDefault)) s = {{"const", value_json(defaults_of<T>().*f.member)}};
    if (!f.schema.empty()) s.update(json::parse(f.schema));
    if (f.has(kNullable)) {
      json either = json::array();  // not built from an initializer list holding `s`, which it would replace
      either.push_back(std::move(s));
      either.push_back({{"type", "null"}});
      s = {{"anyOf", std::move(either)}};
    }
    if (!f.doc.empty()) s["description"] = std::string(f.doc);
    return s;
  }
};

// ---------------------------------------------------------------- results.csv

using CsvRow = std::vector<std::pair<std::string, std::string>>;

template <class T>
void csv_cells(const T& v, const std::string& prefix, CsvRow& out);

template <class T>
void csv_fields(const T& v, const std::string& prefix, CsvRow& out) {
  for_each_field<T>([&](auto at) {
    constexpr auto f = GROWBENCH_FIELD(at);
    using M = typename decltype(f)::Member;
    const M& m = v.*f.member;
    if constexpr (f.has(kNoCsv)) {
    } else if constexpr (f.has(kInline)) {
      if constexpr (is_optional<M>::value) {
        if (m) csv_fields(*m, prefix, out);
      } else {
        csv_fields(m, prefix, out);
      }
    } else {
      csv_cells(m, prefix + std::string(f.key), out);
    }
  });
}

// Text as a spreadsheet shows it rather than runs it: one starting with = + - @ (or a tab or CR) would be
// read as a formula, so it gets a leading apostrophe, which spreadsheets take as "text".
std::string csv_text(std::string s) {
  if (!s.empty() && std::string_view("=+-@\t\r").find(s.front()) != std::string_view::npos) s.insert(0, 1, '\'');
  return s;
}

// A value as the JSON has it, so that the CSV and results.json agree digit for digit.
std::string csv_scalar(const json& j) {
  return j.is_string() ? csv_text(j.get<std::string>()) : j.dump(-1, ' ', false, json::error_handler_t::replace);
}

// Each scalar reachable from `v` as a column named by its dotted path; arrays are not columns, but for a
// list of strings, joined.
template <class T>
void csv_cells(const T& v, const std::string& name, CsvRow& out) {
  if constexpr (is_optional<T>::value) {
    if (v) csv_cells(*v, name, out);
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    if (!v.empty()) out.emplace_back(name, csv_text(fmt::format("{}", fmt::join(v, "; "))));  // reasons, say
  } else if constexpr (is_vector<T>::value || is_std_array<T>::value) {
  } else if constexpr (is_string_map<T>::value) {
    for (const auto& [k, x] : v) csv_cells(x, name + "." + k, out);
  } else if constexpr (is_phase_map<T>::value) {
    v.each([&](Phase p, const auto& x) { csv_cells(x, name + "." + std::string(phase_name(p)), out); });
  } else if constexpr (std::is_same_v<T, json>) {
    if (v.is_object()) {
      for (const auto& [k, x] : v.items())
        if (x.is_primitive() && !x.is_null()) out.emplace_back(name + "." + k, csv_scalar(x));
    } else if (v.is_primitive() && !v.is_null()) {
      out.emplace_back(name, csv_scalar(v));
    }
  } else if constexpr (Declared<T>) {
    csv_fields(v, name + ".", out);
  } else {
    out.emplace_back(name, csv_scalar(value_json(v)));
  }
}

std::string csv_quoted(const std::string& c) {
  if (c.find_first_of(",\"\n\r") == std::string::npos) return c;
  std::string q = "\"";
  for (const char ch : c) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + "\"";
}

}  // namespace

// ---------------------------------------------------------------- entry points

template <Declared T>
json to_json(const T& v) {
  return value_json(v);
}

template <Declared T>
T from_json(const json& j, const std::string& source) {
  T v;
  read(Node{j, source, ""}, v, ValueRule{});
  return v;
}

#define GROWBENCH_RECORD_TYPE(T)      \
  template json to_json<T>(const T&); \
  template T from_json<T>(const json&, const std::string&);
GROWBENCH_RECORD_TYPE(PluginOrigin)
GROWBENCH_RECORD_TYPE(TrialSpec)
GROWBENCH_RECORD_TYPE(PhaseMeasures)
GROWBENCH_RECORD_TYPE(Counts)
GROWBENCH_RECORD_TYPE(OutputBytes)
GROWBENCH_RECORD_TYPE(Curve)
GROWBENCH_RECORD_TYPE(SceneInfo)
GROWBENCH_RECORD_TYPE(FramesInfo)
GROWBENCH_RECORD_TYPE(RunContext)
GROWBENCH_RECORD_TYPE(RenderRecord)
GROWBENCH_RECORD_TYPE(AnimationRecord)
GROWBENCH_RECORD_TYPE(Media)
GROWBENCH_RECORD_TYPE(OrganPassRecord)
GROWBENCH_RECORD_TYPE(Verdict)
GROWBENCH_RECORD_TYPE(TrialResults)
GROWBENCH_RECORD_TYPE(TrialRecord)
GROWBENCH_RECORD_TYPE(AllocCount)
GROWBENCH_RECORD_TYPE(SuiteSample)
GROWBENCH_RECORD_TYPE(CellResults)
GROWBENCH_RECORD_TYPE(MedianSummary)
GROWBENCH_RECORD_TYPE(CellSummary)
GROWBENCH_RECORD_TYPE(JournalEntry)
GROWBENCH_RECORD_TYPE(SuiteCell)
GROWBENCH_RECORD_TYPE(SuiteInfo)
GROWBENCH_RECORD_TYPE(ShardInfo)
GROWBENCH_RECORD_TYPE(ShardRecord)
GROWBENCH_RECORD_TYPE(RenderSummary)
GROWBENCH_RECORD_TYPE(PooledSummary)
GROWBENCH_RECORD_TYPE(ResultsSummary)
GROWBENCH_RECORD_TYPE(ResultsFile)
GROWBENCH_RECORD_TYPE(BaselineContext)
GROWBENCH_RECORD_TYPE(BaselineCell)
GROWBENCH_RECORD_TYPE(Baseline)
GROWBENCH_RECORD_TYPE(HistoryCell)
GROWBENCH_RECORD_TYPE(HistoryRun)
GROWBENCH_RECORD_TYPE(HistoryFile)
#undef GROWBENCH_RECORD_TYPE

template <class T>
json to_json(const PhaseMap<T>& v) {
  return value_json(v);
}
template json to_json(const Phases&);
template json to_json(const AllocByPhase&);
template json to_json(const InstructionCounts&);

void read_spec_field(TrialSpec& spec, std::string_view key, const json& j, const std::string& source,
                     const std::string& path) {
  const Node n{j, source, path};
  const bool known = with_field<TrialSpec>(key, [&](const auto& f) { read(n, spec.*f.member, ValueRule::of(f)); });
  if (!known) throw std::logic_error(fmt::format("read_spec_field: TrialSpec has no field '{}'", key));
}

namespace {

// The first value in `v` (itself, or an item of it) outside `rule`, said as check_value says it.
template <class V>
std::string first_misfit(const ValueRule& rule, const V& v) {
  if constexpr (is_vector<V>::value || is_std_array<V>::value) {
    for (const auto& x : v)
      if (std::string bad = first_misfit(rule, x); !bad.empty()) return bad;
    return "";
  } else {
    return check_value(rule, v);
  }
}

}  // namespace

void check_trial_spec(const TrialSpec& spec) {
  for_each_field<TrialSpec>([&](auto at) {
    constexpr auto f = GROWBENCH_FIELD(at);
    if (const std::string bad = first_misfit(ValueRule::of(f), spec.*f.member); !bad.empty())
      throw InputError(fmt::format("the trial spec: {}: {}", f.key, bad));
  });
}

json results_schema() {
  SchemaBuilder b;
  b.define<ResultsFile>();
  b.define<TrialRecord>();
  b.define<Baseline>();
  b.define<JournalEntry>();
  b.define<HistoryFile>();
  return {{"$schema", "https://json-schema.org/draft/2020-12/schema"},
          {"$id", kSchemaId},
          {"title", "growbench results.json"},
          {"description", kSchemaDescription},
          {"$ref", "#/$defs/results"},
          {"$defs", b.defs}};
}

std::string results_csv(const ResultsFile& results) {
  std::vector<CsvRow> rows;
  for (const auto& t : results.trials) {
    SuiteCell bare = t;  // a failed repetition's row: the cell without its results
    bare.samples.clear();
    bare.results = {};
    CsvRow cell_ok, cell_failed;
    csv_cells(bare, "", cell_failed);
    bare.results = t.results;
    csv_cells(bare, "", cell_ok);
    for (auto& [k, v] : cell_ok) k.erase(0, 1);  // the leading '.' of a top-level path
    for (auto& [k, v] : cell_failed) k.erase(0, 1);
    for (const auto& s : t.samples) {
      CsvRow row = s.status == "ok" ? cell_ok : cell_failed;
      csv_cells(s, "sample", row);
      rows.push_back(std::move(row));
    }
  }
  std::vector<std::string> columns;
  for (const auto& row : rows)
    for (const auto& [k, v] : row)
      if (std::find(columns.begin(), columns.end(), k) == columns.end()) columns.push_back(k);
  std::string out;
  auto line = [&](const std::vector<std::string>& cells) {
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (i > 0) out += ',';
      out += csv_quoted(cells[i]);
    }
    out += "\n";
  };
  line(columns);
  for (const auto& row : rows) {
    std::vector<std::string> cells(columns.size());
    for (const auto& [k, v] : row)
      cells[static_cast<std::size_t>(std::find(columns.begin(), columns.end(), k) - columns.begin())] = v;
    line(cells);
  }
  return out;
}

BaselineCell baseline_cell_of(const SuiteCell& cell) {
  BaselineCell b;
  project(cell, b);
  return b;
}

void take_present(CellResults& to, const CellResults& from) {
  take_present_fields(to, from);
}

// ---------------------------------------------------------------- the files

namespace {

// Before the typed read, so that a newer file's new fields are not taken for mistakes.
void check_version(const json& j, const std::string& path) {
  const json* v = j.is_object() && j.contains("schema_version") ? &j["schema_version"] : nullptr;
  if (v && v->is_number() && v->get<double>() > kSchemaVersion)
    throw InputError(fmt::format("{}: schema_version {} is newer than this growbench reads ({}); use a newer growbench",
                                 path, v->dump(), kSchemaVersion));
}

void check_kind(const json& j, std::string_view kind, const std::string& path, const char* what) {
  const json* k = j.is_object() && j.contains("kind") ? &j["kind"] : nullptr;
  if (!k || *k != kind)
    throw InputError(fmt::format("{}: not a {} (kind {}, expected '{}')", path, what,
                                 k ? k->dump(-1, ' ', false, json::error_handler_t::replace) : "absent", kind));
}

}  // namespace

TrialRecord read_trial_record(const std::string& path) {
  const json j = read_json_file(path);
  check_version(j, path);
  return from_json<TrialRecord>(j, path);
}

ResultsFile results_from_json(const json& j, const std::string& path) {
  check_kind(j, kResultsKind, path, "growbench results file");
  check_version(j, path);
  ResultsFile r = from_json<ResultsFile>(j, path);
  for (std::size_t i = 0; i < r.trials.size(); ++i) {
    const SuiteCell& c = r.trials[i];
    if (const std::string why = cell_id_problem(c.id); !why.empty())
      throw InputError(fmt::format("{}: at /trials/{}/id: {}", path, i, why));
    // An ok cell's figures are its samples': without them every comparison of it would be empty.
    if (c.status == "ok" && c.samples.empty())
      throw InputError(
          fmt::format("{}: at /trials/{}/samples: cell '{}' is ok but has no samples; expected one "
                      "per repetition",
                      path, i, c.id));
  }
  return r;
}

ResultsFile read_results(const std::string& path) {
  return results_from_json(read_json_file(path), path);
}

Baseline baseline_from_json(const json& j, const std::string& path) {
  check_kind(j, kBaselineKind, path, "growbench baseline");
  check_version(j, path);
  return from_json<Baseline>(j, path);
}

Baseline read_baseline(const std::string& path) {
  return baseline_from_json(read_json_file(path), path);
}

HistoryFile read_history_file(const std::string& path) {
  const json j = read_json_file(path);
  check_kind(j, kHistoryKind, path, "growbench history file");
  check_version(j, path);
  return from_json<HistoryFile>(j, path);
}

std::vector<JournalEntry> read_journal(const std::string& path) {
  std::vector<JournalEntry> out;
  std::ifstream in(path);
  std::size_t line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    json j;
    try {
      j = json::parse(line);
    } catch (const json::exception&) {
      continue;  // a line cut short by a kill: its trial runs again
    }
    out.push_back(from_json<JournalEntry>(j, fmt::format("{}:{}", path, line_no)));
    if (const std::string why = cell_id_problem(out.back().id); !why.empty())
      throw InputError(fmt::format("{}:{}: at /id: {}", path, line_no, why));
  }
  return out;
}

std::string repair_journal(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size == 0) return "";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open the journal: {}", path, std::strerror(errno)));
  // The last line: read back from the end in blocks until a newline.
  std::string tail;
  std::uintmax_t start = size;
  for (std::uintmax_t block = 4096; start > 0; block *= 2) {
    const std::uintmax_t from = start > block ? start - block : 0;
    std::string chunk(static_cast<std::size_t>(start - from), '\0');
    in.seekg(static_cast<std::streamoff>(from));
    if (!in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())))
      throw InputError(fmt::format("{}: cannot read the journal", path));
    tail.insert(0, chunk);
    start = from;
    if (const auto nl = tail.rfind('\n'); nl != std::string::npos) {
      if (nl + 1 == tail.size()) return "";  // ends with a newline: nothing torn
      start += nl + 1;
      tail.erase(0, nl + 1);
      break;
    }
  }
  in.close();
  bool whole = false;
  try {
    (void)from_json<JournalEntry>(json::parse(tail), path);
    whole = true;
  } catch (const std::exception&) {
  }
  if (whole) {
    append_to_file(path, "\n");
    return "";
  }
  append_to_file(path + ".torn", tail + "\n");  // first, so that the bytes are kept whatever happens next
  std::filesystem::resize_file(path, start, ec);
  if (ec) throw InputError(fmt::format("{}: cannot cut off its torn last line: {}", path, ec.message()));
  return tail;
}

std::string json_text(const json& j, int indent) {
  return j.dump(indent, ' ', false, json::error_handler_t::replace) + "\n";
}

}  // namespace growbench
