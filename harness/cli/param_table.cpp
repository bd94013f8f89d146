#include "harness/cli/param_table.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

namespace growbench::cli {

void print_param_table(const std::vector<ParamSpec>& specs) {
  std::size_t w = 4;
  for (const auto& s : specs) w = std::max(w, s.name.size());
  for (const auto& s : specs) {
    std::string range;
    if (s.type == ParamType::Choice)
      range = fmt::format("{{{}}}", fmt::join(s.choices, "|"));
    else if (std::isfinite(s.min) || std::isfinite(s.max))
      range = fmt::format("[{:g}, {:g}]", s.min, s.max);
    fmt::print("    {:<{}}  {:<6}  default {:<10} {:<18} {:<3}  {}\n", s.name, w, to_string(s.type),
               format_value(s.default_value).empty() ? "\"\"" : format_value(s.default_value), range, s.unit, s.doc);
  }
}

}  // namespace growbench::cli
