// Helpers for reading user JSON (scene and suite files) with errors that name the file and the JSON path.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace growbench {

// The whole file as text; InputError "PATH: cannot open" when it cannot be read (or is a directory).
std::string read_text_file(const std::string& path);

// Why `path` cannot be read as a regular file ("no such file", "is a directory", "File name too long"),
// or "" when it can be; `allow_stream` also accepts a pipe or device (/dev/stdin). Never throws: a user's
// path may be anything (a name longer than the system allows), and checking it must not crash.
std::string file_problem(const std::string& path, bool allow_stream = false);

// 1-based line and column of a byte offset (as nlohmann's parse_error::byte reports it).
std::pair<std::size_t, std::size_t> line_column(const std::string& text, std::size_t byte);

// No input file is nested this deep; a bound keeps recursive readers and dump() off the end of the stack.
constexpr std::size_t kMaxJsonDepth = 256;

// Parses `text`; a syntax error or a number out of range (1e400) becomes InputError
// "FILE:LINE:COL: invalid JSON: ...", a key given twice in one object or nesting deeper than
// kMaxJsonDepth InputError "FILE: invalid JSON: at PATH: ...".
nlohmann::json parse_json_file_text(const std::string& file, const std::string& text);

// A value as a message quotes it: its JSON text, cut to kJsonExcerptBytes at a character boundary.
constexpr std::size_t kJsonExcerptBytes = 80;
std::string json_excerpt(const nlohmann::json& j);

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
