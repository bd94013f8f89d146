// `growbench report`: the figures, tables and HTML report come from reports/report.py (matplotlib),
// run with Debian's /usr/bin/python3. It reads only the results JSON.
#pragma once

#include <string>
#include <vector>

namespace growbench {

// The report script (GROWBENCH_REPORT_SCRIPT, else reports/report.py in the source tree this binary was
// built from) and the Python that runs it (GROWBENCH_PYTHON, else /usr/bin/python3, else python3).
std::string report_script();
std::string report_python();

// Runs the report script on RESULTS writing into OUT_DIR; returns its exit status. Throws InputError
// when the script or Python cannot be found.
int run_report(const std::string& results, const std::string& out_dir, const std::vector<std::string>& extra_args);

// Runs another script of reports/ (beside the report script) with `args`; the same Python, the same errors.
int run_reports_script(const std::string& name, const std::vector<std::string>& args);

}  // namespace growbench
