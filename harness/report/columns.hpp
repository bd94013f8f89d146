// Text for a terminal: a line is at most kTerminalColumns wide, counted as a terminal shows it (a CJK
// character takes two columns), so that tables and notes read in a 100-column window and in a CI log.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace growbench {

inline constexpr std::size_t kTerminalColumns = 100;

// The columns `text` takes on a terminal, as fmt's padding counts them (so that padded text lines up).
std::size_t display_width(std::string_view text);

// `text` broken at spaces (and tabs, line breaks and other control characters) into lines of at most
// `width` columns, the first starting with `first`, the others with `rest`. A word longer than a line is
// cut: after a '/', '|' or ',' where it can be, so that a path reads as its folders and a list as its
// items. Each line ends with '\n'.
std::string wrap_text(std::string_view text, std::string_view first, std::string_view rest,
                      std::size_t width = kTerminalColumns);

// A table: the first column left-aligned, the others right-aligned, each as wide as its widest entry.
// When a row would pass `width`, its first entry takes a line of its own and the numbers follow on the
// next, under their headers, so that a long name never pushes the columns out of line.
struct TextTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::string render(std::size_t width = kTerminalColumns) const;
};

}  // namespace growbench
