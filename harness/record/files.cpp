#include "harness/record/files.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/json_util.hpp"
#include "core/utf8.hpp"

namespace growbench {

namespace {

// Whether `path` exists and is something other than a regular file; InputError for a directory.
bool is_special_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return false;  // absent (or unreachable: opening says why)
  if (S_ISDIR(st.st_mode)) throw InputError(fmt::format("{}: is a directory, expected a file to write", path));
  return !S_ISREG(st.st_mode);
}

}  // namespace

AtomicFile::AtomicFile(std::string path)
    : path_(std::move(path)), tmp_(is_special_file(path_) ? path_ : path_ + ".tmp"), f_(nullptr, &std::fclose) {
  if (tmp_ == path_) {
    f_.reset(std::fopen(tmp_.c_str(), "wb"));  // a device or pipe the user named: written in place
  } else {
    // A fresh file, never one found there: whatever lies at PATH.tmp (a stale one, or a symlink planted to
    // redirect the write) is removed, and the new one is created exclusively, not following a symlink.
    ::unlink(tmp_.c_str());
    const int fd = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0) {
      f_.reset(::fdopen(fd, "wb"));
      if (!f_) ::close(fd);
    }
  }
  if (!f_) throw InputError(fmt::format("{}: cannot open for writing: {}", path_, std::strerror(errno)));
}

AtomicFile::~AtomicFile() {
  if (!f_) return;  // finished, or failed after closing
  f_.reset();
  if (tmp_ != path_) std::remove(tmp_.c_str());
}

void AtomicFile::fail(const char* what) const {
  throw InputError(fmt::format("{}: cannot {}: {}", path_, what, std::strerror(errno)));
}

void AtomicFile::bytes(const void* p, std::size_t n) {
  if (used_ + n > buf_.size()) flush();
  if (n > buf_.size()) return write(p, n);
  std::memcpy(buf_.data() + used_, p, n);
  used_ += n;
}

std::uint64_t AtomicFile::finish() {
  flush();
  // stdio's own buffer is written out here: a device that takes nothing (/dev/full) fails now, not before.
  if (std::fflush(f_.get()) != 0) fail("write");
  const int closed = std::fclose(f_.release());
  if (closed != 0) {
    if (tmp_ != path_) std::remove(tmp_.c_str());
    fail("write");
  }
  if (tmp_ != path_) rename_into_place(tmp_, path_);
  return total_;
}

void AtomicFile::flush() {
  write(buf_.data(), used_);
  used_ = 0;
}

void AtomicFile::write(const void* p, std::size_t n) {
  if (n > 0 && std::fwrite(p, 1, n, f_.get()) != n) fail("write");
  total_ += n;
}

void make_directories(const std::string& path) {
  std::error_code ec;
  if (path.empty() || std::filesystem::is_directory(path, ec)) return;
  std::filesystem::create_directories(path, ec);
  if (ec) throw InputError(fmt::format("{}: cannot create the directory: {}", path, ec.message()));
}

namespace {
// The folders this process holds locks on (by canonical path), so that it never refuses itself.
std::mutex g_locks_mutex;
std::set<std::string>& held_locks() {
  static std::set<std::string> held;
  return held;
}
}  // namespace

FolderLock FolderLock::take(const std::string& dir, std::string_view command) {
  make_directories(dir);
  std::error_code ec;
  const std::string key = std::filesystem::weakly_canonical(dir, ec).string();
  FolderLock lock;
  {
    std::lock_guard guard(g_locks_mutex);
    if (held_locks().count(key) != 0) return lock;  // this process writes here already
  }
  const std::string path = (std::filesystem::path(dir) / ".growbench-lock").string();
  lock.fd_ = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (lock.fd_ < 0) throw InputError(fmt::format("{}: cannot create the lock file: {}", path, std::strerror(errno)));
  if (flock(lock.fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    char holder[200] = {};
    const ssize_t n = pread(lock.fd_, holder, sizeof holder - 1, 0);
    std::string who(holder, static_cast<std::size_t>(std::max<ssize_t>(n, 0)));
    while (!who.empty() && (who.back() == '\n' || who.back() == ' ')) who.pop_back();
    if (err != EWOULDBLOCK) throw InputError(fmt::format("{}: cannot lock: {}", path, std::strerror(err)));
    throw InputError(
        fmt::format("{}: another growbench is writing in this folder ({}); wait for it to end, or give "
                    "another output folder",
                    dir, who.empty() ? "unknown process" : escape_utf8(who, true)));
  }
  const std::string me = fmt::format("pid {}: growbench {}\n", getpid(), command);
  // Only a description for a refusal: the lock holds without it.
  [[maybe_unused]] const int cut = ftruncate(lock.fd_, 0);
  [[maybe_unused]] const ssize_t put = pwrite(lock.fd_, me.data(), me.size(), 0);
  lock.key_ = key;
  std::lock_guard guard(g_locks_mutex);
  held_locks().insert(key);
  return lock;
}

FolderLock::FolderLock(FolderLock&& o) noexcept : fd_(o.fd_), key_(std::move(o.key_)) {
  o.fd_ = -1;
  o.key_.clear();
}

FolderLock& FolderLock::operator=(FolderLock&& o) noexcept {
  if (this != &o) {
    FolderLock gone(std::move(*this));
    fd_ = o.fd_;
    key_ = std::move(o.key_);
    o.fd_ = -1;
    o.key_.clear();
  }
  return *this;
}

FolderLock::~FolderLock() {
  if (fd_ < 0) return;
  {
    std::lock_guard guard(g_locks_mutex);
    held_locks().erase(key_);
  }
  close(fd_);  // drops the flock once no forked child holds the descriptor too (it is close-on-exec)
}

void append_to_file(const std::string& path, std::string_view text) {
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "ab"), &std::fclose);
  auto fail = [&](const char* what) {
    throw InputError(fmt::format("{}: cannot {}: {}", path, what, std::strerror(errno)));
  };
  if (!f) fail("open for appending");
  if (std::fwrite(text.data(), 1, text.size(), f.get()) != text.size() || std::fflush(f.get()) != 0) fail("write");
  if (std::fclose(f.release()) != 0) fail("write");
}

std::uint64_t write_file_atomic(const std::string& path, const char* data, std::size_t size) {
  AtomicFile f(path);
  f.bytes(data, size);  // larger than the buffer: written straight through
  return f.finish();
}

void rename_into_place(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(fmt::format("{}: cannot rename into place: {}", path, ec.message()));
  }
}

std::string safe_name(std::string s) {
  for (auto& c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' || c == '=' || c == ','))
      c = '_';
  // Leading dots too: '..' would step out of the folder, and '.x' would be a hidden folder that globs skip.
  for (auto& c : s) {
    if (c != '.') break;
    c = '_';
  }
  return s;
}

std::string cell_id_problem(const std::string& id) {
  std::size_t start = 0;
  while (true) {
    const std::size_t end = std::min(id.find('/', start), id.size());
    const std::string part = id.substr(start, end - start);
    if (part.empty() || safe_name(part) != part)
      return fmt::format(
          "cell id \"{}\" is not a path of plain names inside the folder (expected LABEL/SCENE/sSEED, "
          "each of [A-Za-z0-9-_.=,], none empty or starting with '.')",
          escape_utf8(id, true));
    if (end == id.size()) return "";
    start = end + 1;
  }
}

std::string read_input_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (fs::is_directory(st)) throw InputError(fmt::format("{}: is a directory, expected a file", path));
  // A device never ends (/dev/zero) or gives nothing (/dev/null); a pipe (/dev/stdin) is read.
  if (fs::is_character_file(st) || fs::is_block_file(st))
    throw InputError(fmt::format("{}: is a device, expected a file", path));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open: {}", path, std::strerror(errno)));
  std::ostringstream text;
  try {
    text << in.rdbuf();
  } catch (const std::ios_base::failure& e) {  // libstdc++'s filebuf throws on a read error
    throw InputError(fmt::format("{}: cannot read: {}", path, e.code().message()));
  }
  if (in.bad()) throw InputError(fmt::format("{}: cannot read", path));
  return text.str();
}

nlohmann::json parse_input_json(const std::string& path, const std::string& text) {
  // Syntax and range errors come as InputErrors with file:line:column; anything else nlohmann might throw
  // still names the file.
  auto message = [](const nlohmann::json::exception& e) {
    const std::string msg = e.what();
    const auto p = msg.find("] ");
    return p == std::string::npos ? msg : msg.substr(p + 2);
  };
  try {
    return parse_json_file_text(path, text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: invalid JSON: {}", path, message(e)));
  }
}

nlohmann::json read_json_file(const std::string& path) {
  return parse_input_json(path, read_input_file(path));
}

}  // namespace growbench
