// What the harness derives from a record struct's field list (harness/record/fields.hpp): visiting its
// fields, reading and writing JSON, checking a value against its declaration, merging and projecting
// structs by key, and the JSON Schema of a type. record.cpp instantiates these for every record; the
// command line and the suite reader use them to check a trial spec's settings against their declared ranges.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "harness/record/fields.hpp"

namespace growbench {

// ---------------------------------------------------------------- visiting

// Field I of T as a type, so that what its declaration says is known at compile time.
template <class T, std::size_t I>
struct FieldAt {
  static constexpr auto value = std::get<I>(fields_of<T>());
};

// f(FieldAt<T, I>{}) for each field of T, in declaration order. The visitor reads the declaration with
// `constexpr auto f = decltype(at)::value;` and may branch on it with if constexpr.
template <class T, class F>
constexpr void for_each_field(F&& f) {
  constexpr std::size_t n = std::tuple_size_v<decltype(fields_of<T>())>;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f(FieldAt<T, I>{}), ...);
  }
  (std::make_index_sequence<n>{});
}

// The declaration a for_each_field visitor was given.
#define GROWBENCH_FIELD(at) (std::remove_cvref_t<decltype(at)>::value)

template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};
template <class T>
struct is_vector : std::false_type {};
template <class T>
struct is_vector<std::vector<T>> : std::true_type {};
template <class T>
struct is_string_map : std::false_type {};
template <class T>
struct is_string_map<std::map<std::string, T>> : std::true_type {};
template <class T>
struct is_std_array : std::false_type {};
template <class T, std::size_t N>
struct is_std_array<std::array<T, N>> : std::true_type {};
template <class T>
struct is_phase_map : std::false_type {};
template <class T>
struct is_phase_map<PhaseMap<T>> : std::true_type {};

template <class T>
concept NamedEnum = std::is_enum_v<T> && requires(T e) {
  enum_names(e);
};

template <class T>
struct unoptional {
  using type = T;
};
template <class T>
struct unoptional<std::optional<T>> {
  using type = T;
};

// ---------------------------------------------------------------- checking a value against its field

// The range as a message gives it: integers without exponents, "none" for an unbounded end.
template <class V>
std::string range_text(double lo, double hi) {
  auto bound = [](double b) -> std::string {
    if (std::isinf(b)) return b < 0 ? "-inf" : "inf";
    if constexpr (std::is_integral_v<V>) {
      if (b >= 18446744073709551615.0) return "18446744073709551615";
      return fmt::format("{}", static_cast<long long>(b));
    }
    return fmt::format("{:g}", b);
  };
  return fmt::format("[{}, {}]", bound(lo), bound(hi));
}

// What a field's declaration says its values may be, whatever the field's type.
struct ValueRule {
  double lo = -kNoBound, hi = kNoBound;
  bool zero_or = false;
  std::span<const std::string_view> names{};
  [[nodiscard]] bool bounded() const { return lo != -kNoBound || hi != kNoBound; }
  template <class F>
  static ValueRule of(const F& f) {
    return {f.lo, f.hi, f.has(kZeroOr), f.names};
  }
};

// "" when `v` fits the rule, else what was expected ("expected an integer in [3, 64], got 2").
template <class V>
std::string check_value(const ValueRule& r, const V& v) {
  if constexpr (std::is_arithmetic_v<V> && !std::is_same_v<V, bool>) {
    if (!r.bounded()) return "";
    // long double holds every 64-bit integer exactly.
    const auto d = static_cast<long double>(v);
    if ((r.zero_or && v == V{}) || (d >= r.lo && d <= r.hi)) return "";
    return fmt::format("expected {}{} in {}, got {}", r.zero_or ? "0 or " : "",
                       std::is_integral_v<V> ? "an integer" : "a number", range_text<V>(r.lo, r.hi),
                       nlohmann::json(v).dump());
  } else if constexpr (std::is_same_v<V, std::string>) {
    if (r.names.empty()) return "";
    for (const auto n : r.names)
      if (n == v) return "";
    return fmt::format("expected one of {}, got {}", fmt::join(r.names, ", "), nlohmann::json(v).dump());
  } else {
    return "";
  }
}

// ---------------------------------------------------------------- projecting by key

// A member of `to` takes the member of `from` under the same key, types checked at compile time: a value
// into its optional, an optional (when present) into an optional. Inline structs are looked into.
template <class To, class From>
void assign_projected(To& to, const From& from) {
  if constexpr (std::is_assignable_v<To&, const From&>) {
    to = from;
  } else if constexpr (is_optional<From>::value && std::is_assignable_v<To&, const typename From::value_type&>) {
    if (from) to = *from;
  } else {
    static_assert(sizeof(To) == 0, "a projection's two fields of one key have types that do not convert");
  }
}

// Copies the field of `from` under the key of To's field `ToAt` (searching its inline structs) into `out`.
template <class ToAt, class From, class M>
void project_key(const From& from, M& out) {
  for_each_field<From>([&](auto at) {
    constexpr auto f = GROWBENCH_FIELD(at);
    using FM = typename decltype(f)::Member;
    if constexpr (f.has(kInline)) {
      if constexpr (is_optional<FM>::value) {
        if (const auto& inner = from.*f.member) project_key<ToAt>(*inner, out);
      } else {
        project_key<ToAt>(from.*f.member, out);
      }
    } else if constexpr (f.key == ToAt::value.key) {
      assign_projected(out, from.*f.member);
    }
  });
}

// `to` with every field that `from` has under the same key.
template <class To, class From>
void project(const From& from, To& to) {
  for_each_field<To>([&](auto at) { project_key<decltype(at)>(from, to.*GROWBENCH_FIELD(at).member); });
}

// Every present optional field of `from` into `to` (same type); inline structs field by field.
template <class T>
void take_present_fields(T& to, const T& from) {
  for_each_field<T>([&](auto at) {
    constexpr auto f = GROWBENCH_FIELD(at);
    using M = typename decltype(f)::Member;
    if constexpr (is_optional<M>::value) {
      if (from.*f.member) to.*f.member = from.*f.member;
    } else if constexpr (f.has(kInline)) {
      take_present_fields(to.*f.member, from.*f.member);
    }
  });
}

// ---------------------------------------------------------------- one field by key

// Calls g(field) with the field of T declared under `key`; false when there is none.
template <class T, class G>
bool with_field(std::string_view key, G&& g) {
  bool found = false;
  for_each_field<T>([&](auto at) {
    constexpr auto f = GROWBENCH_FIELD(at);
    if (!found && f.key == key) {
      g(f);
      found = true;
    }
  });
  return found;
}

}  // namespace growbench
