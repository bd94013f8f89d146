#include "core/data_path.hpp"

#include <filesystem>
#include <system_error>

namespace growbench {
namespace fs = std::filesystem;

namespace {

fs::path self_exe() {
  std::error_code ec;
  return fs::read_symlink("/proc/self/exe", ec);
}

}  // namespace

std::string data_path(std::string_view relative) {
  std::error_code ec;
  const fs::path source = fs::path(GROWBENCH_SOURCE_DIR) / relative;
  if (fs::exists(source, ec)) return source.string();
  const fs::path installed = self_exe().parent_path().parent_path() / "share" / "growbench" / relative;
  if (fs::exists(installed, ec)) return installed.string();
  return source.string();  // for the error message: where it was looked for first
}

std::string module_path(std::string_view name) {
  if (running_from_build_tree()) return (fs::path(GROWBENCH_BINARY_DIR) / "plugins" / name).string();
  return (self_exe().parent_path().parent_path() / "lib" / "growbench" / name).string();
}

bool running_from_build_tree() {
  const std::string exe = self_exe().string(), build = GROWBENCH_BINARY_DIR;
  return !build.empty() && exe.compare(0, build.size(), build) == 0;
}

}  // namespace growbench
