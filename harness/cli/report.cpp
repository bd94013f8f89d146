// growbench report: figures, tables and index.html from a results file alone.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "harness/record/files.hpp"
#include "harness/cli/command.hpp"
#include "harness/record/record.hpp"
#include "harness/report/report.hpp"

namespace growbench::cli {

namespace {

struct ReportArgs {
  std::string results, out, pareto_metric;
};

Outcome report(ReportArgs& a) {
  if (a.out.empty()) a.out = (std::filesystem::path(a.results).parent_path() / "report").string();
  // Read first as the typed record: a file that does not fit is refused here with its JSON path, before
  // Python starts.
  (void)read_results(a.results);
  const FolderLock lock = FolderLock::take(a.out, "report");
  std::vector<std::string> extra;
  if (!a.pareto_metric.empty()) extra = {"--pareto-metric", a.pareto_metric};
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
  return {cmd, [a] { return report(*a); }};
}

}  // namespace growbench::cli
