// growbench report: figures, tables and index.html from a results file alone.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "harness/record/files.hpp"
#include "harness/cli/command.hpp"
#include "harness/record/record.hpp"
#include "harness/report/report.hpp"

namespace growbench::cli {

namespace {

struct ReportArgs {
  std::string results, out, pareto_metric;
  std::optional<double> viewer_autoload_mb;
  bool no_viewer = false;
};

Outcome report(ReportArgs& a) {
  if (a.out.empty()) a.out = (std::filesystem::path(a.results).parent_path() / "report").string();
  // Read first as the typed record: a file that does not fit is refused here with its JSON path, before
  // Python starts.
  (void)read_results(a.results);
  const FolderLock lock = FolderLock::take(a.out, "report");
  std::vector<std::string> extra;
  if (!a.pareto_metric.empty()) extra = {"--pareto-metric", a.pareto_metric};
  if (a.viewer_autoload_mb)
    extra.insert(extra.end(), {"--viewer-autoload-mb", fmt::format("{}", *a.viewer_autoload_mb)});
  if (a.no_viewer) extra.push_back("--no-viewer");
  return script_status(run_report(a.results, a.out, extra), "reports/report.py");
}

}  // namespace

Command add_report(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "report", "Figures (PNG, PDF), LaTeX and Markdown tables and index.html from a results file alone");
  auto a = std::make_shared<ReportArgs>();
  cmd->add_option("results", a->results, "results.json written by `growbench suite`")->required();
  cmd->add_option("-o,--out", a->out, "report directory (default: report/ beside the results file)")
      ->check(path_named("a report folder"));
  cmd->add_option("--pareto-metric", a->pareto_metric,
                  "the quality metric of the quality-against-cost figures (one per scene of a suite with sweeps; "
                  "default coverage): any metric of the results file, e.g. attached_fraction, leaf_light_exposure");
  cmd->add_option("--viewer-autoload-mb", a->viewer_autoload_mb,
                  "a trial page shows its 3D view at once when plant.glb is at most this many MB, else on a click "
                  "(default: reports/report.py's)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--no-viewer", a->no_viewer,
                "trial pages without a 3D view (each view puts its plant.glb into the report, as base64)");
  return {cmd, [a] { return report(*a); }};
}

}  // namespace growbench::cli
