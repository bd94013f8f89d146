#include "harness/record/files.hpp"

#include <cctype>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>

#include "core/json_util.hpp"

namespace growbench {

AtomicFile::AtomicFile(std::string path)
    : path_(std::move(path)), tmp_(path_ + ".tmp"), f_(std::fopen(tmp_.c_str(), "wb"), &std::fclose) {
  if (!f_) throw std::runtime_error(fmt::format("{}: cannot open for writing", tmp_));
}

void AtomicFile::bytes(const void* p, std::size_t n) {
  if (used_ + n > buf_.size()) flush();
  if (n > buf_.size()) return write(p, n);
  std::memcpy(buf_.data() + used_, p, n);
  used_ += n;
}

std::uint64_t AtomicFile::finish() {
  flush();
  if (std::fclose(f_.release()) != 0) throw std::runtime_error(fmt::format("{}: write failed", tmp_));
  rename_into_place(tmp_, path_);
  return total_;
}

void AtomicFile::flush() {
  write(buf_.data(), used_);
  used_ = 0;
}

void AtomicFile::write(const void* p, std::size_t n) {
  if (n > 0 && std::fwrite(p, 1, n, f_.get()) != n) throw std::runtime_error(fmt::format("{}: write failed", tmp_));
  total_ += n;
}

std::uint64_t write_file_atomic(const std::string& path, const char* data, std::size_t size) {
  AtomicFile f(path);
  f.bytes(data, size);  // larger than the buffer: written straight through
  return f.finish();
}

void rename_into_place(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error(fmt::format("{}: cannot rename into place: {}", path, ec.message()));
}

std::string safe_name(std::string s) {
  for (auto& c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' || c == '=' || c == ','))
      c = '_';
  return s;
}

nlohmann::json read_json_file(const std::string& path) {
  return parse_json_file_text(path, read_text_file(path));
}

}  // namespace growbench
