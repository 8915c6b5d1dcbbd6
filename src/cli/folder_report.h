// The report's options, which `pathex report` shares with the commands that write a report after
// their run (trace, bias and converge --report; the writing is output/folder_report.h).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "output/folder_report.h"

namespace pathex::cli {

// --hover-size.
void add_report_options(CLI::App* sub, ReportOptions* o);

}  // namespace pathex::cli
