#include "harness/report/report.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>

#include "core/json_util.hpp"
#include "core/data_path.hpp"
#include "core/errors.hpp"
#include "harness/run/process.hpp"

namespace growbench {
namespace fs = std::filesystem;

std::string report_script() {
  if (const char* s = std::getenv("GROWBENCH_REPORT_SCRIPT"); s && *s) return s;
  return data_path("reports/report.py");
}

std::string report_python() {
  if (const char* s = std::getenv("GROWBENCH_PYTHON"); s && *s) return s;
  // Debian's python3-matplotlib and python3-numpy serve /usr/bin/python3; another python3 first on
  // PATH may not see them.
  if (access("/usr/bin/python3", X_OK) == 0) return "/usr/bin/python3";
  return "python3";
}

namespace {

int run_python(const std::string& script, const std::vector<std::string>& script_args) {
  std::vector<std::string> args = {report_python(), script};
  args.insert(args.end(), script_args.begin(), script_args.end());
  if (args[0].find('/') == std::string::npos) args[0] = find_program(args[0]);
  if (args[0].empty()) throw InputError("no python3 found (install Debian's python3: scripts/install-deps)");
  const ChildResult r = run_program(args, "", {0.0, 0}, "");
  if (r.exit_code == 127) throw InputError(fmt::format("cannot run {} (install Debian's python3)", args[0]));
  return r.signal != 0 ? 128 + r.signal : r.exit_code;
}

}  // namespace

int run_report(const std::string& results, const std::string& out_dir, const std::vector<std::string>& extra) {
  const std::string script = report_script();
  if (!fs::exists(script))
    throw InputError(
        fmt::format("report script {} not found (set GROWBENCH_REPORT_SCRIPT to reports/report.py)", script));
  if (const std::string why = file_problem(results); !why.empty())
    throw InputError(fmt::format("{}: {} (expected a results file)", results, why));
  std::vector<std::string> args = {results, "--out", out_dir};
  args.insert(args.end(), extra.begin(), extra.end());
  return run_python(script, args);
}

int run_reports_script(const std::string& name, const std::vector<std::string>& args) {
  const std::string script = (fs::path(report_script()).parent_path() / name).string();
  if (!fs::exists(script))
    throw InputError(fmt::format("script {} not found (it lives beside reports/report.py)", script));
  return run_python(script, args);
}

}  // namespace growbench
