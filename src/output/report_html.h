// report.html: a render folder as one self-contained web page (issue 41). The page is a view of the
// folder's linear data (histogram.json, classes.exr, bias.json or missed.json, converge.json, run.json,
// render.shard's header), never a second copy of it:
//
//   - the render, tone-mapped like the PNG previews (io/image_io.h: the 99th percentile of the
//     total's luminance maps to 1, sRGB), with that exposure stated;
//   - a tile per class: its image, share ± standard error, absolute luminance, the checker's
//     verdict for the renderer, its top strategies;
//   - the most important exact paths with share, luminance and strategies;
//   - when the folder has them: the missed light (missed.png over the render, the by-class and
//     by-path tables with the checker's reasons), converge's plot and table, the --only narrowing
//     and the strategies the checker narrowed, the connectors' statistics;
//   - the scene, renderer, spp, seed, time, non-finite count and the command that reproduces it.
//
// Images are PNGs (the folder's previews when present, else encoded from the EXR) embedded as
// base64 data URLs; every table is HTML, so the page reads without JavaScript. A few lines of plain
// JavaScript show, under the pointer on any tile, that pixel's luminance per class, from per-class
// luminances embedded as base64 float32 arrays, box-downsampled so that neither side exceeds
// ReportOptions::hover_max cells. Once the script has read them it sets data-hover="ready" on
// <body> (what the browser test waits for).
//
// Machine-readable values sit in data-* attributes as the shortest decimal text that reads back the
// same double (JsonReader::fmt), so a test compares them with histogram.json exactly.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "stats/histogram.h"
#include "core/error.h"
#include "core/limits.h"
#include "output/shard.h"

namespace pathex {

inline constexpr const char* kReportName = "report.html";

struct ReportOptions {
  int hover_max = 128;  // the hover data's largest side in cells (--hover-size); 1 to 4096
  int top_paths = 20;   // exact paths listed (--top)
  std::size_t max_file_bytes = Limits{}.max_file_bytes;  // per input file (--max-file-size)
};

// What the folder holds, read and checked. Everything but `folder` is optional: a bias folder has
// no run.json, a converge folder no histogram.json.
struct ReportData {
  std::string folder;  // as the user named it
  std::string kind;    // "trace", "bias" or "converge": which command wrote the folder

  std::optional<HistogramReport> histogram;  // histogram.json (converge: reference.json)
  std::string histogram_file;                // its name in the folder
  struct Connector {
    std::string strategy, connector;
    std::uint64_t attempts = 0, successes = 0;
    std::map<std::string, std::uint64_t> failures;  // histogram.json's "failures", in its order by name
  };
  std::vector<Connector> connectors;
  std::vector<std::pair<std::string, std::string>> only;  // histogram.json "only": {name, expr}

  // run.json (trace)
  std::optional<double> time_s, cpu_s;
  std::optional<int> threads;
  struct Pruned {
    std::string strategy, profile, runs, reason;  // runs "": not run
  };
  std::vector<Pruned> pruned;

  std::optional<RenderIdentity> identity;  // render.shard's header (trace)
  std::string command;  // the command line that reproduces the render; "" when unknown
  // The checker's verdict for the renderer per class name (the caller's: the CLI asks the checker;
  // a bias folder's come from bias.json), and whose verdicts they are.
  std::map<std::string, std::string> verdicts;
  std::string verdict_renderer;

  // Images: the PNG of each layer ("total", the classes, "missed"), by name.
  std::map<std::string, std::string> png;
  std::optional<double> exposure;  // the previews' exposure (from the EXR's total)
  int width = 0, height = 0;       // the render's pixels
  // Hover data: per layer, luminance on a grid of hover_width x hover_height cells, row-major.
  int hover_width = 0, hover_height = 0, hover_factor = 1;
  std::vector<std::pair<std::string, std::vector<float>>> hover;

  // bias.json (pathex bias) or missed.json (pathex trace --missed)
  struct MissedClass {
    std::string name, verdict;
    double missed = 0, share_of_class = 0, share_of_image = 0;
    std::string witness, reason;  // the shortest path of the class the renderer cannot sample
  };
  struct MissedPath {
    std::string path;
    double share = 0, luminance = 0;
    std::string reason;
  };
  struct Missed {
    std::string file, renderer, reference;
    double luminance = 0, share = 0, share_stderr = 0;
    bool exact = false;
    std::vector<MissedClass> classes;
    std::vector<MissedPath> paths;
  };
  std::optional<Missed> missed;

  // converge.json and converge.png (pathex converge)
  struct Rung {
    std::string budget;
    double cpu_s = 0, estimate = 0;
    std::optional<double> std_error, error;
  };
  struct ConvergeRow {
    std::string renderer, class_name;
    std::vector<Rung> rungs;
    std::optional<double> slope, efficiency;
    std::string warning;
  };
  struct Converge {
    std::vector<ConvergeRow> rows;
    std::vector<std::string> best;
    std::string png;
  };
  std::optional<Converge> converge;
};

// What a command that has just written a render folder already holds in memory (pathex trace
// --report): the folder's histogram.json and render.shard are then not read again (parsing the
// default render's 1.2 MB histogram.json took longer than the rest of the report together).
struct KnownRender {
  std::string folder;  // the folder's name for the page, when `dir` is where its files are staged
  const HistogramReport* histogram = nullptr;
  std::vector<ReportData::Connector> connectors;
  std::vector<std::pair<std::string, std::string>> only;
  const RenderIdentity* identity = nullptr;
  std::uint64_t spp = 0;  // requested
};
// histogram.json's "connectors" entries from the render's statistics (the same keys).
std::vector<ReportData::Connector> report_connectors(const std::vector<ConnectorStats>& stats);

// Reads `dir`: histogram.json (required unless the folder holds converge.json), run.json,
// render.shard's header (the command), bias.json or missed.json, converge.json and converge.png,
// classes.exr (and missed.exr) and the PNG previews. Errors (kBadFile) name the file, and a JSON
// file's pointer, line and column: not a folder, no histogram.json, a file that does not parse.
Result<ReportData> load_report_folder(const std::string& dir, const ReportOptions& options, const KnownRender* known = nullptr);

// The page.
std::string report_html(const ReportData& data, const ReportOptions& options);

// Writes dir/report.html whole or not at all (io/atomic_file.h) and, when the folder is an output
// set (io/output_set.h), lists it in the set's manifest first, so that the next run into the folder
// replaces it like the set's other files.
Result<bool> write_report(const std::string& dir, const std::string& html);

// Standard base64 (RFC 4648, with padding) of `bytes`.
std::string base64(std::string_view bytes);

}  // namespace pathex
