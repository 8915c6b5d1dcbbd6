// A render folder (of pathex trace, bias or converge) read into report.html (output/report_html.h)
// with the checker's verdict for each class: what `pathex report` does, and what trace, bias and
// converge do after their run for --report.
#pragma once

#include <string>

#include "core/error.h"
#include "core/limits.h"
#include "output/report_html.h"

namespace pathex {

// Writes dir/report.html from the folder's files (and what `known` holds of them already); returns
// its path. Errors name the file.
Result<std::string> write_folder_report(const std::string& dir, const ReportOptions& options, const Limits& limits,
                                        const KnownRender* known = nullptr);

}  // namespace pathex
