#include "scenes/obj_check.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <vector>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/utf8.hpp"

namespace growbench {
namespace {

// What an OBJ line reads, one element at a time, with its line for messages.
class ObjLineChecker {
 public:
  ObjLineChecker(const std::string& path, std::size_t line) : path_(path), line_(line) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}:{}: {}", path_, line_, what));
  }

  // Each token a finite number, at least `min` of them; `what` names the line's kind for messages.
  void numbers(const std::vector<std::string_view>& tokens, std::size_t min, const char* what) const {
    if (tokens.size() - 1 < min)
      fail(fmt::format("{} has {} number{}; expected at least {}", what, tokens.size() - 1,
                       tokens.size() == 2 ? "" : "s", min));
    for (std::size_t k = 1; k < tokens.size(); ++k) {
      std::string_view t = tokens[k];
      if (!t.empty() && t.front() == '+') t.remove_prefix(1);
      double v = 0.0;
      const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
      if (ec == std::errc() && end == t.data() + t.size() && !t.empty() && std::isfinite(v)) continue;
      const std::string shown = utf8_excerpt(tokens[k], 40);
      if (ec == std::errc::result_out_of_range)
        fail(fmt::format("{}: '{}' is out of the range of a number", what, shown));
      if (ec != std::errc() || end != t.data() + t.size() || t.empty())
        fail(fmt::format("{}: '{}' is not a number", what, shown));
      fail(fmt::format("{}: '{}' is not a finite number", what, shown));
    }
  }

  // One index of a face corner: an integer, not 0, naming one of the `count` elements defined so far
  // (negative: counted back from the last).
  struct Element {
    const char* one;
    const char* many;
  };
  void index(std::string_view t, std::size_t count, Element e) const {
    const char* element = e.one;
    if (t.empty()) fail(fmt::format("face: expected a {} index, found nothing", element));
    std::int64_t i = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), i);
    const bool integer = ec == std::errc() && end == t.data() + t.size() && i != 0;
    const auto n = static_cast<std::int64_t>(count);
    if (integer && ((i > 0 && i <= n) || (i < 0 && -i <= n))) return;
    const std::string shown = utf8_excerpt(t, 40);
    if (ec != std::errc::result_out_of_range && (ec != std::errc() || end != t.data() + t.size()))
      fail(fmt::format("face: {} index '{}' is not an integer", element, shown));
    fail(fmt::format("face: {} index {} is out of range; {} {} {} defined before this line{}", element, shown, count,
                     count == 1 ? e.one : e.many, count == 1 ? "is" : "are",
                     count == 0 ? "" : fmt::format(" (expected 1 to {} or -1 to -{})", count, count)));
  }

  // A corner: v, v/t, v//n or v/t/n.
  void corner(std::string_view t, std::size_t nv, std::size_t nt, std::size_t nn) const {
    std::string_view parts[3];
    std::size_t count = 0;
    for (std::size_t start = 0;;) {
      const std::size_t slash = t.find('/', start);
      if (count == 3) fail(fmt::format("face: corner '{}' has more than three indices", utf8_excerpt(t, 40)));
      parts[count++] = t.substr(start, slash == std::string_view::npos ? std::string_view::npos : slash - start);
      if (slash == std::string_view::npos) break;
      start = slash + 1;
    }
    index(parts[0], nv, {"vertex", "vertices"});
    if (count >= 2 && !(count == 3 && parts[1].empty()))
      index(parts[1], nt, {"texture coordinate", "texture coordinates"});
    if (count == 3) index(parts[2], nn, {"normal", "normals"});
  }

 private:
  const std::string& path_;
  std::size_t line_;
};

// The line's words, up to a '#' that starts one (a comment) or a NUL (where tinyobjloader's C string ends).
void tokens_of(std::string_view line, std::vector<std::string_view>& out) {
  line = line.substr(0, line.find('\0'));
  out.clear();
  std::size_t k = 0;
  while (k < line.size()) {
    while (k < line.size() && (line[k] == ' ' || line[k] == '\t')) ++k;
    const std::size_t start = k;
    while (k < line.size() && line[k] != ' ' && line[k] != '\t') ++k;
    if (k == start) break;
    if (line[start] == '#') break;
    out.push_back(line.substr(start, k - start));
  }
}

}  // namespace

void check_obj_text(const std::string& path, std::string_view text) {
  std::size_t nv = 0, nt = 0, nn = 0, line = 0;
  std::vector<std::string_view> tokens;  // one line's, reused: a mesh has millions of lines
  for (std::size_t start = 0; start < text.size();) {
    // A line ends at "\n", "\r\n" or a lone "\r", as tinyobjloader's reader has it.
    const std::size_t end = std::min(text.find_first_of("\r\n", start), text.size());
    const std::string_view l = text.substr(start, end - start);
    start = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    ++line;
    tokens_of(l, tokens);
    if (tokens.empty()) continue;
    const ObjLineChecker check(path, line);
    if (tokens[0] == "v") {
      check.numbers(tokens, 3, "vertex (v x y z)");
      ++nv;
    } else if (tokens[0] == "vt") {
      check.numbers(tokens, 1, "texture coordinate (vt u v)");
      ++nt;
    } else if (tokens[0] == "vn") {
      check.numbers(tokens, 3, "normal (vn x y z)");
      ++nn;
    } else if (tokens[0] == "f") {
      if (tokens.size() < 4)
        check.fail(
            fmt::format("face has {} corner{}; expected at least 3", tokens.size() - 1, tokens.size() == 2 ? "" : "s"));
      for (std::size_t k = 1; k < tokens.size(); ++k) check.corner(tokens[k], nv, nt, nn);
    }
  }
}

}  // namespace growbench
