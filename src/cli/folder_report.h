// What `pathex report` shares with the commands that write a report after their run (trace, bias
// and converge --report): reading a folder into report.html (output/report_html.h) with the checker's
// verdicts, and the report's options.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "cli/common.h"
#include "core/error.h"
#include "core/limits.h"
#include "output/report_html.h"

namespace pathex::cli {

// Writes dir/report.html from the folder's files (and what `known` holds of them already); returns
// its path. Errors name the file.
Result<std::string> write_folder_report(const std::string& dir, const ReportOptions& options, const Limits& limits,
                                        const KnownRender* known = nullptr);

// --hover-size.
void add_report_options(CLI::App* sub, ReportOptions* o);

}  // namespace pathex::cli
