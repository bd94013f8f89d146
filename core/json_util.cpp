#include "core/json_util.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/params.hpp"

namespace growbench {

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::pair<std::size_t, std::size_t> line_column(const std::string& text, std::size_t byte) {
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return {line, col};
}

nlohmann::json parse_json_file_text(const std::string& file, const std::string& text) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    const auto [line, col] = line_column(text, e.byte);
    std::string msg = e.what();
    if (const auto p = msg.find("parse error"); p != std::string::npos) msg = msg.substr(p);
    throw InputError(fmt::format("{}:{}:{}: invalid JSON: {}", file, line, col, msg));
  }
}

void JsonPathReader::fail(const std::string& path, const std::string& what) const {
  throw InputError(fmt::format("{}: at {}: {}", file_, path.empty() ? "/" : path, what));
}

void JsonPathReader::only_keys(const nlohmann::json& j, const std::string& path,
                               const std::vector<std::string>& keys) const {
  if (!j.is_object()) fail(path, fmt::format("expected an object, got {}", j.type_name()));
  for (const auto& [k, v] : j.items()) {
    if (std::find(keys.begin(), keys.end(), k) != keys.end()) continue;
    const std::string near = closest_match(k, keys);
    fail(path + "/" + k,
         fmt::format("unknown key '{}'{}; expected one of {}", k,
                     near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near), fmt::join(keys, ", ")));
  }
}

}  // namespace growbench
