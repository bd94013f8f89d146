// What an algorithm's registration needs, apart from the registry: a plugin built from a built-in's
// source (algorithms/plugins/builtin_plugin.cpp) links this file but not the registry.
#include "algorithms/algorithm.hpp"

namespace growbench {

std::vector<std::string> split_type_list(std::string_view list, std::size_t count) {
  auto trim = [](std::string_view t) {
    while (!t.empty() && t.front() == ' ') t.remove_prefix(1);
    while (!t.empty() && t.back() == ' ') t.remove_suffix(1);
    return std::string(t);
  };
  std::vector<std::string> names;
  int depth = 0;
  std::size_t start = 0;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const char c = list[i];
    if (c == '<' || c == '(') ++depth;
    if (c == '>' || c == ')') --depth;
    if (c == ',' && depth == 0) {
      names.push_back(trim(list.substr(start, i - start)));
      start = i + 1;
    }
  }
  names.push_back(trim(list.substr(start)));
  if (names.size() != count) names.assign(count, trim(list));
  return names;
}

}  // namespace growbench
