#include "harness/cli/param_table.hpp"

#include "harness/report/columns.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace growbench::cli {

namespace {

bool is_word(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0;
}
bool is_space(char c) {
  return std::isspace(static_cast<unsigned char>(c)) != 0;
}

}  // namespace

// Doc text as literal Markdown in a table cell. Only what could end the cell or start code, emphasis, a
// link or HTML is escaped, so the raw README stays readable: `|`, backticks and backslashes always; `*`
// and `_` unless spaces on both sides (or, for `_`, letters) keep them from emphasising; `]` before
// `(`, `[` or `:`; `<` before a letter, `/`, `!` or `?`.
std::string markdown_text(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const char prev = i > 0 ? text[i - 1] : ' ', next = i + 1 < text.size() ? text[i + 1] : ' ';
    bool escape = c == '|' || c == '`' || c == '\\';
    if (c == '*' || c == '_')
      escape = !(is_space(prev) && is_space(next)) && !(c == '_' && is_word(prev) && is_word(next));
    if (c == ']') escape = next == '(' || next == '[' || next == ':';
    if (c == '<') escape = std::isalpha(static_cast<unsigned char>(next)) || next == '/' || next == '!' || next == '?';
    if (escape) out += '\\';
    out += c == '\n' ? ' ' : c;
  }
  return out;
}

// One parameter a line: name, type, default, range and unit in columns, then the doc, wrapped within the
// terminal's width, in its own column when the others leave it room and on the lines below when a long
// default or range would squeeze it.
void print_param_table(const std::vector<ParamSpec>& specs) {
  constexpr std::size_t kMaxDefault = 12, kMaxRange = 20, kMaxDocColumn = 60, kDocBelow = 8;
  std::vector<std::string> defaults, ranges;
  std::size_t wn = 4, wd = 2, wr = 0;
  for (const auto& s : specs) {
    const std::string d = format_value(s.default_value);
    defaults.push_back(d.empty() ? "\"\"" : d);
    if (s.type == ParamType::Choice)
      ranges.push_back(fmt::format("{{{}}}", fmt::join(s.choices, "|")));
    else if (std::isfinite(s.min) || std::isfinite(s.max))
      ranges.push_back(fmt::format("[{:g}, {:g}]", s.min, s.max));
    else
      ranges.emplace_back();
    wn = std::max(wn, display_width(s.name));
    wd = std::max(wd, std::min(kMaxDefault, display_width(defaults.back())));
    wr = std::max(wr, std::min(kMaxRange, display_width(ranges.back())));
  }
  std::size_t doc_column = 4 + wn + 2 + 6 + 2 + 8 + wd + 2 + wr + 2 + 3 + 2;
  if (doc_column > kMaxDocColumn) doc_column = kDocBelow;
  const std::string indent(doc_column, ' ');
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const ParamSpec& s = specs[i];
    std::string head = fmt::format("    {:<{}}  {:<6}  default {:<{}}  {:<{}}  {:<3}", s.name, wn, to_string(s.type),
                                   defaults[i], wd, ranges[i], wr, s.unit);
    while (!head.empty() && head.back() == ' ') head.pop_back();
    if (display_width(head) > kTerminalColumns) {  // a long list of choices: on the lines below, wrapped
      std::string front = fmt::format("    {:<{}}  {:<6}  default {}", s.name, wn, to_string(s.type), defaults[i]);
      fmt::print("{}{}", display_width(front) > kTerminalColumns ? wrap_text(front, "", indent) : front + '\n',
                 wrap_text(fmt::format("{}  {}", ranges[i], s.unit), indent, indent));
      head.clear();
    }
    if (head.empty())
      fmt::print("{}", wrap_text(s.doc, indent, indent));
    else if (display_width(head) + 2 <= doc_column)
      fmt::print("{}", wrap_text(s.doc, fmt::format("{:<{}}", head, doc_column), indent));
    else
      fmt::print("{}\n{}", head, wrap_text(s.doc, indent, indent));
  }
}

std::string markdown_code(const std::string& text) {
  // A code span is fenced by a backtick run longer than any inside it; in a table cell a pipe needs a
  // backslash even there, and a newline would end the row.
  std::size_t longest = 0, run = 0;
  for (const char c : text) {
    run = c == '`' ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  std::string body;
  for (const char c : text) body += c == '|' ? std::string("\\|") : c == '\n' ? std::string(" ") : std::string(1, c);
  const std::string fence(longest + 1, '`');
  const bool pad = !body.empty() && (body.front() == '`' || body.back() == '`');
  return fence + (pad ? " " : "") + body + (pad ? " " : "") + fence;
}

std::string param_table_markdown(const std::vector<ParamSpec>& specs) {
  std::string out = "| name | type | default | allowed | unit | doc |\n|---|---|---|---|---|---|\n";
  for (const auto& s : specs) {
    std::string allowed;
    if (s.type == ParamType::Choice) {
      std::vector<std::string> choices;
      for (const auto& c : s.choices) choices.push_back(markdown_code(c));
      allowed = fmt::format("{}", fmt::join(choices, ", "));
    } else if (std::isfinite(s.min) || std::isfinite(s.max)) {
      allowed = fmt::format("[{:g}, {:g}]", s.min, s.max);
    }
    const std::string value = format_value(s.default_value);
    out += fmt::format("| {} | {} | {} | {} | {} | {} |\n", markdown_code(s.name), to_string(s.type),
                       markdown_code(value.empty() ? "\"\"" : value), allowed, markdown_text(s.unit),
                       markdown_text(s.doc));
  }
  return out;
}

}  // namespace growbench::cli
