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
  auto put = [&](std::string_view piece, std::size_t w) {
    if (!empty_line) {
      out += ' ';
      ++used;
    }
    out += piece;
    used += w;
    empty_line = false;
  };
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t start = text.find_first_not_of(' ', i);
    if (start == std::string_view::npos) break;
    const std::size_t end = std::min(text.find(' ', start), text.size());
    std::string_view word = text.substr(start, end - start);
    i = end;
    const std::size_t w = display_width(word);
    if (used + (empty_line ? 0 : 1) + w <= width) {
      put(word, w);
      continue;
    }
    if (w <= room) {
      new_line();
      put(word, w);
      continue;
    }
    // A word longer than any line (a path, a cell id) is cut at the width, a whole character at a time.
    if (!empty_line) new_line();
    while (!word.empty()) {
      std::size_t cut = 0, cut_w = 0;
      while (cut < word.size()) {
        const std::size_t n = std::max<std::size_t>(1, utf8_char_length(word, cut));
        const std::size_t cw = display_width(word.substr(cut, n));
        if (cut > 0 && used + cut_w + cw > width) break;
        cut += n;
        cut_w += cw;
      }
      put(word.substr(0, cut), cut_w);
      word.remove_prefix(cut);
      if (!word.empty()) new_line();
    }
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
