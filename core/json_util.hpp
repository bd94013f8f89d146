// Helpers for reading user JSON (scene and suite files) with errors that name the file and the JSON path.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace growbench {

// The whole file as text; InputError "PATH: cannot open" when it cannot be read.
std::string read_text_file(const std::string& path);

// 1-based line and column of a byte offset (as nlohmann's parse_error::byte reports it).
std::pair<std::size_t, std::size_t> line_column(const std::string& text, std::size_t byte);

// Parses `text`; a syntax error becomes InputError "FILE:LINE:COL: invalid JSON: ...".
nlohmann::json parse_json_file_text(const std::string& file, const std::string& text);

class JsonPathReader {
 public:
  explicit JsonPathReader(std::string file) : file_(std::move(file)) {}
  // Throws InputError "FILE: at PATH: WHAT".
  [[noreturn]] void fail(const std::string& path, const std::string& what) const;
  // j must be an object whose keys are all in `keys` (an unknown key gets a close-match suggestion).
  void only_keys(const nlohmann::json& j, const std::string& path, const std::vector<std::string>& keys) const;
  [[nodiscard]] const std::string& file() const { return file_; }

 private:
  std::string file_;
};

}  // namespace growbench
