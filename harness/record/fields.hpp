// The vocabulary a record struct declares its fields in, once: each field's JSON key, its member, and what
// the files say of it (required, nullable, written only when set, a numeric range, the names a string may
// take, a schema refinement, a line of documentation). From that one list the harness derives the JSON
// writer, the strict reader, merging, projections between structs, CSV columns and results.schema.json
// (harness/record/reflect.hpp), so a field is added in one place.
//
//   struct Counts {
//     std::uint64_t nodes = 0, segments = 0;
//     static constexpr std::string_view kSchemaName = "counts";
//     static constexpr auto fields() {
//       return std::tuple{field("nodes", &Counts::nodes), field("segments", &Counts::segments)};
//     }
//   };
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string_view>
#include <tuple>
#include <type_traits>

namespace growbench {

// What a field's declaration may say beyond its key and member.
enum FieldFlag : unsigned {
  kRequiredField = 1u << 0,  // a file that leaves it out is refused (else absence reads as the default)
  kNullable = 1u << 1,       // an empty optional is written as null (else left out)
  kOmitEmpty = 1u << 2,      // an empty string or container is left out
  kOmitDefault = 1u << 3,    // a value equal to the member's default is left out
  kInline = 1u << 4,         // a struct whose fields are written into the parent's object
  kWhenOk = 1u << 5,         // the schema requires it (an inline struct: its required fields) when status is "ok"
  kZeroOr = 1u << 6,         // a number that is 0 (automatic, none) or within [lo, hi]
  kConstDefault = 1u << 7,   // the schema admits only the member's default (kind, schema_version)
  kNoCsv = 1u << 8,          // not a column of results.csv (the spec, renders, open-ended objects)
};

inline constexpr double kNoBound = std::numeric_limits<double>::infinity();

template <class C, class M>
struct Field {
  using Class = C;
  using Member = M;
  std::string_view key;
  M C::*member;
  unsigned flags = 0;
  double lo = -kNoBound, hi = kNoBound;       // numbers: the range a reader accepts
  std::span<const std::string_view> names{};  // strings: the values a reader accepts (none: any)
  std::string_view schema{};                  // JSON merged into the field's generated schema
  std::string_view doc{};                     // the schema's description, and the option's help

  [[nodiscard]] constexpr bool has(unsigned f) const { return (flags & f) != 0; }
  [[nodiscard]] constexpr bool bounded() const { return lo != -kNoBound || hi != kNoBound; }
  [[nodiscard]] constexpr Field with(unsigned f) const {
    Field c = *this;
    c.flags |= f;
    return c;
  }
  [[nodiscard]] constexpr Field in(double l, double h) const {
    Field c = *this;
    c.lo = l;
    c.hi = h;
    return c;
  }
  [[nodiscard]] constexpr Field one_of(std::span<const std::string_view> n) const {
    Field c = *this;
    c.names = n;
    return c;
  }
  [[nodiscard]] constexpr Field refine(std::string_view json_text) const {
    Field c = *this;
    c.schema = json_text;
    return c;
  }
  [[nodiscard]] constexpr Field describe(std::string_view d) const {
    Field c = *this;
    c.doc = d;
    return c;
  }
};

template <class C, class M>
constexpr Field<C, M> field(std::string_view key, M C::*member) {
  return {key, member};
}

// Schema refinements used by several structs.
inline constexpr std::string_view kHashSchema = R"({"type": "string", "pattern": "^[0-9a-f]{16}$"})";

// A struct that declares its fields.
template <class T>
concept Record = requires {
  T::fields();
};

// The field list of a declared struct: its own fields(), or a record_fields overload beside the struct (for
// structs declared below the record layer, such as PluginOrigin).
template <class T>
constexpr auto fields_of() {
  if constexpr (requires { T::fields(); })
    return T::fields();
  else
    return record_fields(std::type_identity<T>{});
}

template <class T>
concept Declared = Record<T> || requires {
  record_fields(std::type_identity<T>{});
};

template <class T>
constexpr std::string_view schema_name_of() {
  if constexpr (requires { T::kSchemaName; })
    return T::kSchemaName;
  else
    return record_schema_name(std::type_identity<T>{});
}

// ---------------------------------------------------------------- phases

// The phases of a trial, in pipeline order: the order every list of them follows.
// `outputs` is the algorithm's own files (GrowthAlgorithm::write_outputs, e.g. the vines' textures drawn
// and written), apart from `export`, the plant's mesh and skeleton files every algorithm writes.
enum class Phase : std::uint8_t { scene_load, query_build, growth, organs, meshing, exporting, outputs, metrics };
inline constexpr std::size_t kPhaseCount = 8;
// Their JSON names ("export" is a C++ keyword, hence `exporting`).
inline constexpr std::array<std::string_view, kPhaseCount> kPhaseNames = {
    "scene_load", "query_build", "growth", "organs", "meshing", "export", "outputs", "metrics"};
inline constexpr std::array<Phase, kPhaseCount> kPhases = {Phase::scene_load, Phase::query_build, Phase::growth,
                                                           Phase::organs,     Phase::meshing,     Phase::exporting,
                                                           Phase::outputs,    Phase::metrics};

constexpr std::string_view phase_name(Phase p) {
  return kPhaseNames[static_cast<std::size_t>(p)];
}
constexpr std::optional<Phase> phase_named(std::string_view name) {
  for (std::size_t i = 0; i < kPhaseCount; ++i)
    if (kPhaseNames[i] == name) return static_cast<Phase>(i);
  return std::nullopt;
}

// One value per phase that ran, indexed by the phase: written as an object of the phases present.
template <class T>
struct PhaseMap {
  using value_type = T;
  std::array<std::optional<T>, kPhaseCount> at{};

  std::optional<T>& operator[](Phase p) { return at[static_cast<std::size_t>(p)]; }
  const std::optional<T>& operator[](Phase p) const { return at[static_cast<std::size_t>(p)]; }
  [[nodiscard]] T* find(Phase p) {
    return at[static_cast<std::size_t>(p)] ? &*at[static_cast<std::size_t>(p)] : nullptr;
  }
  [[nodiscard]] const T* find(Phase p) const {
    return at[static_cast<std::size_t>(p)] ? &*at[static_cast<std::size_t>(p)] : nullptr;
  }
  [[nodiscard]] bool empty() const {
    for (const auto& v : at)
      if (v) return false;
    return true;
  }
  // f(phase, value) for each phase present, in pipeline order.
  template <class F>
  void each(F&& f) const {
    for (const Phase p : kPhases)
      if (const T* v = find(p)) f(p, *v);
  }
  friend bool operator==(const PhaseMap&, const PhaseMap&) = default;
};

}  // namespace growbench
