#include "core/json_util.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <type_traits>
#include <sstream>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/params.hpp"
#include "core/utf8.hpp"

namespace growbench {

std::string read_text_file(const std::string& path) {
  std::error_code ec;
  // A directory opens as a stream on Linux and fails only on the first read, with the library's words.
  if (std::filesystem::is_directory(path, ec)) throw InputError(fmt::format("{}: is a directory, not a file", path));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open", path));
  // One allocation of the file's size, not a stream's doublings: meshes run to many megabytes.
  std::string text;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > 0) {
    text.resize(size);
    in.read(text.data(), static_cast<std::streamsize>(size));
    text.resize(static_cast<std::size_t>(in.gcount()));
  } else {  // not a regular file (a pipe): as the stream gives it
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  if (in.bad()) throw InputError(fmt::format("{}: cannot read", path));
  return text;
}

std::string file_problem(const std::string& path, bool allow_stream) {
  namespace fs = std::filesystem;
  if (path.empty()) return "no file named (an empty path)";
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) return "no such file";
  if (ec) return ec.message();
  if (fs::is_directory(st)) return "is a directory, not a file";
  if (!allow_stream && !fs::is_regular_file(st)) return "not a regular file";
  return "";
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

namespace {

// nlohmann's DOM builder, told to keep where the first error is and to refuse what nlohmann accepts
// silently. A syntax error and a number out of range (1e400, which comes as an out_of_range exception)
// keep their byte position; a key given twice in one object (nlohmann keeps the last) and nesting deeper
// than kMaxJsonDepth keep their JSON path, as SAX events carry no position. The methods hide the base's:
// sax_parse calls them on this type.
class CheckingDomParser : public nlohmann::detail::json_sax_dom_parser<nlohmann::json> {
  using Base = nlohmann::detail::json_sax_dom_parser<nlohmann::json>;

 public:
  explicit CheckingDomParser(nlohmann::json& root) : Base(root, false) {}

  bool null() { return value() && Base::null(); }
  bool boolean(bool v) { return value() && Base::boolean(v); }
  bool number_integer(nlohmann::json::number_integer_t v) { return value() && Base::number_integer(v); }
  bool number_unsigned(nlohmann::json::number_unsigned_t v) { return value() && Base::number_unsigned(v); }
  bool number_float(nlohmann::json::number_float_t v, const std::string& s) {
    return value() && Base::number_float(v, s);
  }
  bool string(std::string& v) { return value() && Base::string(v); }
  bool binary(nlohmann::json::binary_t& v) { return value() && Base::binary(v); }
  bool start_object(std::size_t n) { return value() && open(true) && Base::start_object(n); }
  bool start_array(std::size_t n) { return value() && open(false) && Base::start_array(n); }
  bool end_object() {
    frames_.pop_back();
    return Base::end_object();
  }
  bool end_array() {
    frames_.pop_back();
    return Base::end_array();
  }
  bool key(std::string& k) {
    Frame& f = frames_.back();
    f.segment = k;
    if (!f.keys.insert(k).second) {
      problem_ = fmt::format("at {}: the key '{}' is given twice in one object", path(), k);
      return false;
    }
    return Base::key(k);
  }
  template <class Exception>
  bool parse_error(std::size_t position, const std::string& last_token, const Exception& ex) {
    error_at_ = position;
    // A number out of range is reported after its last character: point at its first.
    if (std::is_same_v<Exception, nlohmann::json::out_of_range> && position >= last_token.size())
      error_at_ = position + 1 - last_token.size();
    error_ = ex.what();
    if (const auto p = error_.find("parse error"); p != std::string::npos)
      error_ = error_.substr(p);
    else if (const auto q = error_.find("] "); error_.rfind("[json.exception.", 0) == 0 && q != std::string::npos)
      error_ = error_.substr(q + 2);  // "number overflow parsing '1e400'"
    if (std::is_same_v<Exception, nlohmann::json::out_of_range>)
      error_ += "; expected a number within a double's range";
    return false;
  }

  [[nodiscard]] std::size_t error_at() const { return error_at_; }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] const std::string& problem() const { return problem_; }

 private:
  struct Frame {
    bool object;
    std::size_t count = 0;  // array: values so far
    std::string segment;    // the key or index of the value being read
    std::set<std::string> keys;
  };
  // A value begins: in an array, it takes the next index.
  bool value() {
    if (!frames_.empty() && !frames_.back().object) frames_.back().segment = std::to_string(frames_.back().count++);
    return true;
  }
  bool open(bool object) {
    if (frames_.size() >= kMaxJsonDepth) {
      problem_ = fmt::format("at {}: arrays and objects nested deeper than {} levels", path(), kMaxJsonDepth);
      return false;
    }
    frames_.push_back({object, 0, {}, {}});
    return true;
  }
  [[nodiscard]] std::string path() const {
    std::string p;
    for (const auto& f : frames_) p += "/" + f.segment;
    return p.empty() ? "/" : p;
  }

  std::vector<Frame> frames_;
  std::size_t error_at_ = 0;
  std::string error_, problem_;
};

}  // namespace

nlohmann::json parse_json_file_text(const std::string& file, const std::string& text) {
  nlohmann::json j;
  CheckingDomParser sax(j);
  if (nlohmann::json::sax_parse(text, &sax)) return j;
  if (!sax.problem().empty()) throw InputError(fmt::format("{}: invalid JSON: {}", file, sax.problem()));
  const auto [line, col] = line_column(text, sax.error_at());
  throw InputError(fmt::format("{}:{}:{}: invalid JSON: {}", file, line, col, sax.error()));
}

std::string json_excerpt(const nlohmann::json& j) {
  return utf8_excerpt(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), kJsonExcerptBytes);
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
