#include "harness/report/columns.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "core/utf8.hpp"

namespace growbench {

std::size_t display_width(std::string_view text) {
  // fmt pads to a display width it estimates for UTF-8 (wide East Asian characters count two): the width is
  // what the padding left over.
  const std::size_t field = text.size() * 2 + 1;
  const std::string padded = fmt::format("{:<{}}", text, field);
  return field - (padded.size() - text.size());
}

namespace {

// Spaces, tabs, line breaks and other control characters all separate words: a note that holds a line
// break or a tab would otherwise carry it into the middle of a wrapped line.
bool is_gap(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u <= 0x20 || u == 0x7f;
}

// Where to cut `word` so that its first part takes at most `room` columns: after the last '/', '|' or ','
// that fits, so that a cut path still reads as its folders and a list as its items, else at the last whole
// character that fits (at least one).
std::size_t cut_point(std::string_view word, std::size_t room) {
  std::size_t cut = 0, used = 0, after_mark = 0;
  while (cut < word.size()) {
    const std::size_t n = std::max<std::size_t>(1, utf8_char_length(word, cut));
    const std::size_t w = display_width(word.substr(cut, n));
    if (cut > 0 && used + w > room) break;
    cut += n;
    used += w;
    if ((word[cut - 1] == '/' || word[cut - 1] == '|' || word[cut - 1] == ',') && cut < word.size()) after_mark = cut;
  }
  return cut < word.size() && after_mark > 0 ? after_mark : cut;
}

}  // namespace

std::string wrap_text(std::string_view text, std::string_view first, std::string_view rest, std::size_t width) {
  std::string out(first);
  std::size_t used = display_width(first);
  const std::size_t rest_w = display_width(rest), room = width > rest_w ? width - rest_w : 1;
  bool empty_line = true;
  auto new_line = [&] {
    out += '\n';
    out += rest;
    used = rest_w;
    empty_line = true;
  };
  auto put = [&](std::string_view piece) {
    if (!empty_line) {
      out += ' ';
      ++used;
    }
    out += piece;
    used += display_width(piece);
    empty_line = false;
  };
  for (std::size_t i = 0; i < text.size();) {
    while (i < text.size() && is_gap(text[i])) ++i;
    std::size_t end = i;
    while (end < text.size() && !is_gap(text[end])) ++end;
    std::string_view word = text.substr(i, end - i);
    i = end;
    if (word.empty()) break;
    const std::size_t w = display_width(word);
    if (used + (empty_line ? 0 : 1) + w > width) {
      // A word that fits a line goes to the next; a longer one (a path, a cell id) starts where it is, if
      // the line has room, and is cut so that no line passes the width.
      if (w <= room ? (!empty_line || used > rest_w) : used + 2 > width) new_line();
      while (!word.empty() && used + (empty_line ? 0 : 1) + display_width(word) > width) {
        const std::size_t taken = used + (empty_line ? 0 : 1);
        const std::size_t cut = cut_point(word, width > taken ? width - taken : 1);
        put(word.substr(0, cut));
        word.remove_prefix(cut);
        if (!word.empty()) new_line();
      }
    }
    if (!word.empty()) put(word);
  }
  return out + '\n';
}

std::string TextTable::render(std::size_t width) const {
  const std::size_t n = header.size();
  std::vector<std::size_t> w(n, 0);
  auto widen = [&](const std::vector<std::string>& row) {
    for (std::size_t k = 0; k < n && k < row.size(); ++k) w[k] = std::max(w[k], display_width(row[k]));
  };
  widen(header);
  for (const auto& r : rows) widen(r);
  std::size_t rest = 0;
  for (std::size_t k = 1; k < n; ++k) rest += 2 + w[k];
  // The name column is as wide as the widest name that fits beside the numbers.
  std::size_t name_w = display_width(header[0]);
  for (const auto& r : rows)
    if (const std::size_t nw = display_width(r[0]); nw + rest <= width) name_w = std::max(name_w, nw);
  auto line = [&](const std::vector<std::string>& row, bool name_too) {
    std::string s = fmt::format("{:<{}}", name_too ? row[0] : "", name_w);
    for (std::size_t k = 1; k < n; ++k) s += fmt::format("  {:>{}}", k < row.size() ? row[k] : "", w[k]);
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s + '\n';
  };
  std::string out = line(header, true);
  for (const auto& r : rows) {
    const bool fits = display_width(r[0]) <= name_w;
    if (!fits) out += wrap_text(r[0], "", "", width);
    out += line(r, fits);
  }
  return out;
}

}  // namespace growbench
