// Files the harness writes and reads: every output is written atomically (PATH.tmp renamed into place), so an
// interrupted run leaves either the old file or the new one, never half of one; names built from user text
// are made safe for paths; and JSON files are read with errors that name the file, line and column.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace growbench {

// A file written atomically through a fixed 64 KiB buffer. A buffer the size of the file would be fresh
// memory, whose page faults on a virtual machine cost more than the writing. Nothing appears at PATH until
// finish(); a writer destroyed before finish() leaves PATH untouched (the .tmp file stays behind).
class AtomicFile {
 public:
  explicit AtomicFile(std::string path);
  void bytes(const void* p, std::size_t n);
  std::uint64_t finish();  // flushes, closes and renames into place; returns the bytes written

 private:
  void flush();
  void write(const void* p, std::size_t n);
  std::string path_, tmp_;
  std::unique_ptr<FILE, int (*)(FILE*)> f_;
  std::array<char, 1 << 16> buf_;  // only the bytes written into it are read
  std::size_t used_ = 0;
  std::uint64_t total_ = 0;
};

// Writes `data` to `path` atomically; returns the bytes written. std::runtime_error naming the path on failure.
std::uint64_t write_file_atomic(const std::string& path, const char* data, std::size_t size);
inline std::uint64_t write_file_atomic(const std::string& path, std::string_view text) {
  return write_file_atomic(path, text.data(), text.size());
}
// The last step of an atomic write made by other means (a library that writes its own stream): the finished
// `tmp` becomes `path`.
void rename_into_place(const std::string& tmp, const std::string& path);

// `s` with every character outside [A-Za-z0-9-_.=,] replaced by '_': a file or folder name for a label,
// scene or sweep value.
std::string safe_name(std::string s);

// Reads and parses a JSON file: InputError "PATH: cannot open" or "PATH:LINE:COL: invalid JSON: ...".
nlohmann::json read_json_file(const std::string& path);

}  // namespace growbench
