// pathex report: a render folder (of pathex trace, bias or converge) as one self-contained
// report.html (output/folder_report.h reads the folder with the checker's verdicts and writes it);
// the command's options and what it prints. trace, bias and converge write it for --report.
#include <iostream>

#include "cli/common.h"
#include "cli/folder_report.h"
#include "output/folder_report.h"

namespace pathex::cli {
namespace {

struct ReportArgs {
  std::string dir;
  ReportOptions options;
  Limits limits;
};

}  // namespace

void add_report_options(CLI::App* sub, ReportOptions* o) {
  sub->add_option("--hover-size", o->hover_max,
                  "report.html: the largest side, in cells, of the per-class data shown under the pointer (larger images are "
                  "box-downsampled)")
      ->capture_default_str()->check(CLI::Range(1, 4096));
}

Command add_report(CLI::App& app) {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* sub = app.add_subcommand("report", "Write DIR/report.html: a render folder as one self-contained web page");
  sub->footer("Example:\n  pathex trace --out out && pathex report out      # then open out/report.html\n"
              "Reads the folder pathex trace, bias or converge wrote (histogram.json, classes.exr, run.json, bias.json or\n"
              "missed.json, converge.json) and writes DIR/report.html: the render and one tile per class with share, error,\n"
              "luminance, the checker's verdict and strategies, the exact paths, and when present the missed light, the\n"
              "convergence plot, the --only narrowing and the connectors. Images are embedded; it needs no network.\n"
              "trace --report, bias --report and converge --report write it after their run.");
  sub->add_option("DIR", args->dir, "The output folder of pathex trace, bias or converge")->required();
  sub->add_option("--top", args->options.top_paths, "Exact paths to list")->capture_default_str()->check(CLI::Range(0, 100000));
  add_report_options(sub, &args->options);
  add_limit_options(sub, &args->limits);
  return {sub, [args] {
            Result<std::string> written = write_folder_report(args->dir, args->options, args->limits);
            if (!written) return report(written.error());
            std::cout << "wrote " << *written << "\n";
            return kExitOk;
          }};
}

}  // namespace pathex::cli
