// Files the harness writes and reads: every output is written atomically (PATH.tmp renamed into place), so an
// interrupted run leaves either the old file or the new one, never half of one; names built from user text
// are made safe for paths; and JSON files are read with errors that name the file, line and column.
//
// Where output goes is the user's choice, so a path that cannot be written (a directory, a missing folder,
// a full disk, /dev/full) is an InputError naming it and why: never a success that wrote nothing.
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
// finish(); a writer destroyed before finish() leaves PATH untouched and removes its .tmp file. A PATH that
// exists and is not a regular file (a device such as /dev/null, a pipe) is written directly, as there is
// nothing to replace; a directory is refused. Every write, the flush and the close are checked: a failure
// is an InputError "PATH: cannot write: REASON".
class AtomicFile {
 public:
  explicit AtomicFile(std::string path);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();
  void bytes(const void* p, std::size_t n);
  std::uint64_t finish();  // flushes, closes and renames into place; returns the bytes written

 private:
  void flush();
  void write(const void* p, std::size_t n);
  [[noreturn]] void fail(const char* what) const;
  std::string path_, tmp_;  // tmp_ == path_ when written directly
  std::unique_ptr<FILE, int (*)(FILE*)> f_;
  std::array<char, 1 << 16> buf_;  // only the bytes written into it are read
  std::size_t used_ = 0;
  std::uint64_t total_ = 0;
};

// Creates the directory `path` and its parents (nothing when it exists); InputError "PATH: cannot create
// the directory: REASON" when it cannot (a file in the way, no permission).
void make_directories(const std::string& path);

// One writer per output folder: while a FolderLock on a folder lives, no other growbench process can take
// one there (two suites on one --out, a suite and its --resume, or a render during a suite interleaved
// their writes). The lock is an flock on DIR/.growbench-lock, which the kernel drops when the holder's
// processes end, however they end; the file names the holder (pid and command) for the refusal. A
// process that already holds a folder's lock takes it again as a no-op (run then renders its folder).
class FolderLock {
 public:
  FolderLock() = default;
  // Creates `dir` if needed and locks it for `command`; InputError "DIR: another growbench is writing here
  // (...)" when another process holds it.
  static FolderLock take(const std::string& dir, std::string_view command);
  FolderLock(FolderLock&& o) noexcept;
  FolderLock& operator=(FolderLock&& o) noexcept;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock();

 private:
  int fd_ = -1;
  std::string key_;  // the folder's canonical path, while this object holds it
};

// Appends `text` to `path` (created if absent), flushed and closed; InputError "PATH: cannot write: REASON".
void append_to_file(const std::string& path, std::string_view text);

// Writes `data` to `path` atomically; returns the bytes written. InputError naming the path on failure.
std::uint64_t write_file_atomic(const std::string& path, const char* data, std::size_t size);
inline std::uint64_t write_file_atomic(const std::string& path, std::string_view text) {
  return write_file_atomic(path, text.data(), text.size());
}
// The last step of an atomic write made by other means (a library that writes its own stream): the finished
// `tmp` becomes `path`.
void rename_into_place(const std::string& tmp, const std::string& path);

// `s` with every character outside [A-Za-z0-9-_.=,] replaced by '_': a file or folder name for a label,
// scene or sweep value. Leading dots become underscores too, so that ".." names a folder inside its parent,
// never the parent itself, and no name makes a hidden folder.
std::string safe_name(std::string s);

// Why `id` cannot name a cell's folder under trials/, or "" if it can: a cell id is safe_name parts
// joined by '/' (LABEL/SCENE/sSEED[/SWEEP]), none empty or starting with a dot, so that no results file, journal
// or baseline can point a writer outside its folder.
std::string cell_id_problem(const std::string& id);

// The whole of an input file: InputError "PATH: cannot open: REASON", "PATH: is a directory, expected a
// file" (or a device), or "PATH: cannot read: REASON". A pipe is read to its end.
std::string read_input_file(const std::string& path);
// Parses the JSON text of `path`: InputError "PATH:LINE:COL: invalid JSON: ..." for a syntax error, and
// "PATH: invalid JSON: number overflow parsing '1e400' (...)" for a number beyond a double's range.
nlohmann::json parse_input_json(const std::string& path, const std::string& text);
// Both: reads and parses a JSON file.
nlohmann::json read_json_file(const std::string& path);

}  // namespace growbench
