// report.html (output/report_html.h, pathex report, trace/bias/converge --report): the page holds every
// class and the top paths of histogram.json with exactly its numbers, the hover data is the EXR's
// luminance box-downsampled, the in-memory report of trace --report is the bytes pathex report
// makes from the files, the file joins the output set, and bad folders get one located message.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "stats/histogram.h"
#include "io/image_io.h"
#include "output/report_html.h"
#include "support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using pathex::test::CliRun;
using pathex::test::read_file;
using pathex::test::run_pathex;
using pathex::test::run_pathex_args;
using pathex::test::scratch_dir;

// The value of attribute `name` in the tag where `anchor` (its first occurrence) ends.
std::string attr(const std::string& html, const std::string& anchor, const std::string& name) {
  const std::size_t found = html.find(anchor);
  if (found == std::string::npos) return "<no " + anchor + ">";
  const std::size_t at = found + anchor.size() - 1;
  const std::size_t open = html.rfind('<', at), close = html.find('>', at);
  const std::string tag = html.substr(open, close - open);
  const std::size_t p = tag.find(" " + name + "=\"");
  if (p == std::string::npos) return "<no " + name + ">";
  const std::size_t v = p + name.size() + 3;
  return tag.substr(v, tag.find('"', v) - v);
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + what.size())) ++n;
  return n;
}

// The default scene rendered with --report into a folder of this test process (once).
const fs::path& default_render() {
  static const fs::path dir = [] {
    const fs::path d = scratch_dir() / "default";
    const CliRun r = run_pathex_args({"trace", "--out", d.string(), "--quiet", "--report"});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("wrote " + d.string() + "/report.html in "), std::string::npos) << r.out;
    return d;
  }();
  return dir;
}

TEST(ReportBase64, Rfc4648Vectors) {
  EXPECT_EQ(pathex::base64(""), "");
  EXPECT_EQ(pathex::base64("f"), "Zg==");
  EXPECT_EQ(pathex::base64("fo"), "Zm8=");
  EXPECT_EQ(pathex::base64("foo"), "Zm9v");
  EXPECT_EQ(pathex::base64("foob"), "Zm9vYg==");
  EXPECT_EQ(pathex::base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(pathex::base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(pathex::base64(std::string("\xff\xfe\x00", 3)), "//4A");
}

TEST(ReportContent, EveryClassAndTopPathWithHistogramJsonsNumbers) {
  const fs::path dir = default_render();
  const std::string html = read_file(dir / "report.html");
  const auto doc = nlohmann::json::parse(read_file(dir / "histogram.json"));
  ASSERT_FALSE(html.empty());
  EXPECT_EQ(attr(html, "data-nonfinite=", "data-nonfinite"), doc["nonfinite_samples"].dump());
  EXPECT_EQ(attr(html, "data-spp=", "data-spp"), "16");
  EXPECT_EQ(attr(html, "<tr><th>image mean luminance</th><td", "data-luminance"), doc["total"]["luminance"].dump());
  EXPECT_EQ(attr(html, "<tr><th>image mean luminance</th><td", "data-stderr"), doc["total"]["stderr"].dump());
  ASSERT_EQ(doc["classes"].size(), 5u);
  EXPECT_EQ(count(html, "<div class=\"tile\""), doc["classes"].size());
  for (const auto& c : doc["classes"]) {
    const std::string anchor = "data-class=\"" + c["name"].get<std::string>() + "\"";
    EXPECT_EQ(attr(html, anchor, "data-share"), c["share"].dump()) << c["name"];
    EXPECT_EQ(attr(html, anchor, "data-luminance"), c["luminance"].dump()) << c["name"];
    EXPECT_EQ(attr(html, anchor, "data-stderr"), c["stderr"].dump()) << c["name"];
    // its image, with a text alternative, and the checker's verdict (bdpt reaches every class here)
    EXPECT_NE(html.find("data-layer=\"" + c["name"].get<std::string>() + "\""), std::string::npos) << c["name"];
    EXPECT_NE(html.find("alt=\"class " + c["name"].get<std::string>() + " ("), std::string::npos) << c["name"];
  }
  EXPECT_EQ(count(html, "<dt>verdict</dt><dd class=\"verdict-reachable\">reachable</dd>"), 5u);
  // the top 20 paths, in histogram.json's order, with its numbers
  std::size_t last = 0;
  for (std::size_t i = 0; i < 20; ++i) {
    const auto& p = doc["paths"][i];
    const std::string anchor = "<tr data-path=\"" + p["path"].get<std::string>() + "\"";
    const std::size_t at = html.find(anchor);
    ASSERT_NE(at, std::string::npos) << p["path"];
    EXPECT_GT(at, last) << p["path"];
    last = at;
    EXPECT_EQ(attr(html, anchor, "data-luminance"), p["luminance"].dump()) << p["path"];
    EXPECT_EQ(attr(html, anchor, "data-stderr"), p["stderr"].dump()) << p["path"];
  }
  EXPECT_EQ(count(html, "<tr data-path="), 20u);
  EXPECT_NE(html.find("<td colspan=\"6\">980 more paths listed in histogram.json and "), std::string::npos);
  // the render, its exposure and the command that reproduces it
  EXPECT_NE(html.find("alt=\"the rendered image, tone-mapped\""), std::string::npos);
  EXPECT_NE(html.find("tone-mapped: linear values × "), std::string::npos);
  EXPECT_NE(html.find("<pre class=\"cmd\" id=\"command\">pathex trace --renderer bdpt --spp 16 --seed 1 --max-bounces 16 "
                      "--sampler sobol --batches 32 --replicates 2 --resolution 64x64 --splits 1</pre>"),
            std::string::npos);
  // the strategies the checker narrowed (run.json's "pruned")
  EXPECT_NE(html.find("<td>bdpt</td><td class=\"mono\">(0.., DD, 0..)</td><td class=\"mono\">(0.., DD, 1..)</td>"), std::string::npos);
  // self-contained: nothing is fetched
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find(" src=\"data:image/png;base64,") != std::string::npos, true);
  EXPECT_EQ(count(html, " src=\""), count(html, " src=\"data:image/png;base64,"));
}

TEST(ReportContent, HoverDataIsTheExrLuminanceBoxDownsampled) {
  const fs::path dir = default_render();
  const fs::path copy = scratch_dir() / "hover";
  fs::copy(dir, copy);
  const CliRun r = run_pathex_args({"report", copy.string(), "--hover-size", "16"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "wrote " + copy.string() + "/report.html\n");
  const std::string html = read_file(copy / "report.html");
  const std::string open = "<script type=\"application/json\" id=\"hover-data\">";
  const std::size_t at = html.find(open);
  ASSERT_NE(at, std::string::npos);
  const auto meta = nlohmann::json::parse(html.substr(at + open.size(), html.find("</script>", at) - at - open.size()));
  EXPECT_EQ(meta["width"], 64);
  EXPECT_EQ(meta["factor"], 4);
  EXPECT_EQ(meta["grid"], nlohmann::json::array({16, 16}));
  pathex::Result<std::vector<pathex::ImageLayer>> layers = pathex::read_exr_layers((dir / "classes.exr").string());
  ASSERT_TRUE(layers.ok());
  ASSERT_EQ(meta["layers"].size(), layers->size());
  // the total first, then the classes in histogram.json's order
  const auto doc = nlohmann::json::parse(read_file(dir / "histogram.json"));
  std::vector<std::string> order = {"total"};
  for (const auto& c : doc["classes"]) order.push_back(c["name"]);
  for (std::size_t l = 0; l < order.size(); ++l) EXPECT_EQ(meta["layers"][l]["name"], order[l]);
  for (std::size_t l = 0; l < layers->size(); ++l) {
    std::size_t m = 0;
    while (m < meta["layers"].size() && meta["layers"][m]["name"] != (*layers)[l].name) ++m;
    ASSERT_LT(m, meta["layers"].size()) << (*layers)[l].name;
    // decode cell (2, 3): the mean luminance of pixels x 8..11, y 12..15
    const std::string b64 = meta["layers"][m]["data"];
    ASSERT_EQ(b64.size(), (16u * 16u * 4u + 2u) / 3u * 4u);
    std::string bytes;
    static const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (std::size_t i = 0; i + 4 <= b64.size(); i += 4) {
      unsigned v = 0;
      for (int k = 0; k < 4; ++k) v = v << 6 | static_cast<unsigned>(b64[i + k] == '=' ? 0 : alphabet.find(b64[i + k]));
      bytes += static_cast<char>(v >> 16);
      bytes += static_cast<char>(v >> 8 & 0xff);
      bytes += static_cast<char>(v & 0xff);
    }
    float cell = 0;
    std::memcpy(&cell, bytes.data() + (3 * 16 + 2) * 4, 4);
    double sum = 0;
    const pathex::RgbImage& im = (*layers)[l].image;
    for (int y = 12; y < 16; ++y)
      for (int x = 8; x < 12; ++x) sum += pathex::luminance({im.at(x, y, 0), im.at(x, y, 1), im.at(x, y, 2)});
    EXPECT_EQ(cell, static_cast<float>(sum / 16)) << (*layers)[l].name;
  }
}

TEST(ReportContent, TraceReportIsThePageReportMakesFromTheFiles) {
  // trace --report builds the page from what it holds in memory; pathex report reads the files.
  const fs::path dir = default_render();
  const std::string made = read_file(dir / "report.html");
  const CliRun r = run_pathex_args({"report", dir.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_file(dir / "report.html"), made);
}

TEST(ReportContent, TheCommandOnThePageReproducesTheRender) {
  const fs::path dir = default_render();
  const std::string html = read_file(dir / "report.html");
  const std::string open = "<pre class=\"cmd\" id=\"command\">pathex ";
  const std::size_t at = html.find(open);
  ASSERT_NE(at, std::string::npos);
  const std::string command = html.substr(at + open.size(), html.find("</pre>", at) - at - open.size());
  ASSERT_EQ(command.find('&'), std::string::npos) << command;  // no entity to undo here
  const fs::path again = scratch_dir() / "again";
  const CliRun r = run_pathex(command + " --quiet --out " + again.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_file(again / "histogram.json"), read_file(dir / "histogram.json"));
}

TEST(ReportContent, ReportJoinsTheOutputSetAndTheNextRunReplacesIt) {
  const fs::path dir = scratch_dir() / "set";
  CliRun r = run_pathex_args({"trace", "--out", dir.string(), "--quiet", "--resolution", "16x16", "--spp", "2"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_file(dir / ".pathex-manifest").find("report.html"), std::string::npos);
  r = run_pathex_args({"report", dir.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(read_file(dir / ".pathex-manifest").find("\nreport.html\n"), std::string::npos);
  // the folder is still pathex's: the next run replaces the set, report.html with it
  r = run_pathex_args({"trace", "--out", dir.string(), "--quiet", "--resolution", "16x16", "--spp", "2"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir / "report.html"));
}

TEST(ReportContent, OnlyAndNotRenderedClasses) {
  const fs::path dir = scratch_dir() / "only";
  const CliRun r = run_pathex_args({"trace", "--out", dir.string(), "--quiet", "--resolution", "16x16", "--spp", "2", "--only",
                                    "$caustic", "--report"});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string html = read_file(dir / "report.html");
  EXPECT_NE(html.find("<ul id=\"only\"><li>caustic <code>L..S+D.*..E</code></li></ul>"), std::string::npos);
  EXPECT_EQ(attr(html, "data-class=\"direct\"", "data-rendered"), "false");
  EXPECT_EQ(attr(html, "data-class=\"caustic\"", "data-rendered"), "true");
  EXPECT_NE(html.find("<tr><th>luminance of the requested paths"), std::string::npos);
  EXPECT_NE(html.find(" --only &apos;$caustic&apos; "), std::string::npos);
}

// Each class tile and the total carry histogram.json's stderr_stability, and a tile says its stderr is
// unstable exactly where trace's table does (stability ≥ 0.7, the stderr more than rounding): the
// caustic seen through the ball of lamp-glass.json, which a few fold events carry (flagged in 3
// renders of 4 at 256 spp), and the default scene's classes.
TEST(ReportContent, TilesSayWhereTheStderrIsUnstableAsTheTableDoes) {
  const fs::path dir = scratch_dir() / "unstable";
  const CliRun r = run_pathex_args({"trace", "samples/scenes/lamp-glass.json", "--renderer", "pt-nee+manifold", "--only", "LDDSSDSSDSE",
                                    "--spp", "256", "--seed", "1", "--threads", "1", "--out", dir.string(), "--report"});
  ASSERT_EQ(r.code, 0) << r.err;
  for (const fs::path& d : {dir, default_render()}) {
    const std::string html = read_file(d / "report.html");
    const nlohmann::json h = nlohmann::json::parse(read_file(d / "histogram.json"));
    for (const auto& c : h["classes"]) {
      if (c.contains("rendered")) continue;
      const std::string anchor = "data-class=\"" + c["name"].get<std::string>() + "\"";
      const std::size_t tile = html.find(anchor);
      ASSERT_NE(tile, std::string::npos) << anchor;
      const std::string body = html.substr(tile, html.find("</div>", tile) - tile);
      const bool says = body.find("<dd class=\"unstable\">unstable: a few pixel groups carry it") != std::string::npos;
      if (c["stderr_stability"].is_null()) {
        EXPECT_EQ(attr(html, anchor, "data-stderr-stability"), "<no data-stderr-stability>");
        EXPECT_FALSE(says) << anchor;
        continue;
      }
      EXPECT_EQ(std::stod(attr(html, anchor, "data-stderr-stability")), c["stderr_stability"].get<double>()) << anchor;
      const bool unstable = c["stderr_stability"].get<double>() >= 0.7 && c["stderr"].get<double>() > 1e-6 * c["luminance"].get<double>();
      EXPECT_EQ(says, unstable) << anchor;
      if (d == dir) {  // the table printed by the same run says the same of the class's line
        const std::size_t at = r.out.find("\n" + c["name"].get<std::string>() + ": ");
        ASSERT_NE(at, std::string::npos) << r.out;
        const std::string line = r.out.substr(at + 1, r.out.find('\n', at + 1) - at - 1);
        EXPECT_EQ(line.find("; its stderr is unstable (") != std::string::npos, says) << line;
      }
    }
  }
}

TEST(ReportContent, BiasReportShowsTheMissedLightWithTheCheckersReasons) {
  const fs::path dir = scratch_dir() / "bias";
  const CliRun r = run_pathex_args({"bias", "samples/scenes/point-mirror-caustic.json", "--renderer", "pt-nee", "--spp", "4",
                                    "--resolution", "16x16", "--quiet", "--out", dir.string(), "--report"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + dir.string() + "/report.html (open it in a browser)\n"), std::string::npos);
  const std::string html = read_file(dir / "report.html");
  const auto bias = nlohmann::json::parse(read_file(dir / "bias.json"));
  EXPECT_NE(html.find("<section id=\"missed\"><h2>The light pt-nee misses</h2>"), std::string::npos);
  EXPECT_NE(html.find("alt=\"the missed light alone, on the render&apos;s exposure\""), std::string::npos);
  for (const auto& c : bias["classes"]) {
    const std::string name = c["name"];
    EXPECT_NE(html.find("<tr data-class=\"" + name + "\"><td>" + name + "</td>"), std::string::npos) << name;
    // the tiles carry pt-nee's verdicts, from bias.json
    EXPECT_NE(html.find("data-class=\"" + name + "\" data-rendered=\"true\""), std::string::npos) << name;
  }
  EXPECT_NE(html.find("the checker's verdict for pt-nee"), std::string::npos);
  EXPECT_NE(html.find("<pre class=\"cmd\" id=\"command\">pathex bias samples/scenes/point-mirror-caustic.json --renderer pt-nee "),
            std::string::npos);
  EXPECT_NE(read_file(dir / ".pathex-manifest").find("\nreport.html\n"), std::string::npos);
}

TEST(ReportContent, ConvergeReportShowsThePlotAndTheTable) {
  const fs::path dir = scratch_dir() / "converge";
  const CliRun r = run_pathex_args({"converge", "samples/scenes/closed-sphere-point.json", "--renderer", "pt-nee", "--spp", "2,4",
                                    "--resolution", "8x8", "--quiet", "--out", dir.string(), "--report"});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string html = read_file(dir / "report.html");
  const auto conv = nlohmann::json::parse(read_file(dir / "converge.json"));
  EXPECT_NE(html.find("<table id=\"converge-table\">"), std::string::npos);
  EXPECT_NE(html.find("alt=\"log-log plot of each renderer's error"), std::string::npos);
  std::size_t rows = 0;
  for (const auto& k : conv["renderers"])
    for (const auto& c : k["classes"]) rows += c["rungs"].size() + 1;
  const std::size_t table = html.find("<table id=\"converge-table\">");
  EXPECT_EQ(count(html.substr(table, html.find("</table>", table) - table), "<tr><td>pt-nee</td>"), rows);
  EXPECT_NE(html.find("pathex converge samples/scenes/closed-sphere-point.json --renderer pt-nee --spp 2,4 --seed 1"), std::string::npos);
}

TEST(ReportContent, ConnectorStatisticsAreHistogramJsons) {
  const fs::path dir = scratch_dir() / "connectors";
  const CliRun r = run_pathex_args({"trace", "samples/scenes/point-mirror-caustic.json", "--renderer", "bdpt+mirror", "--spp", "2",
                                    "--resolution", "16x16", "--quiet", "--out", dir.string(), "--report"});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string html = read_file(dir / "report.html");
  const auto doc = nlohmann::json::parse(read_file(dir / "histogram.json"));
  ASSERT_EQ(doc["connectors"].size(), 1u);
  const auto& c = doc["connectors"][0];
  ASSERT_GT(c["attempts"].get<std::uint64_t>(), 0u);
  // columns: attempts, successes, then the failure reasons by name (no_transport, occluded, outside)
  EXPECT_NE(html.find("<tr><td>" + c["strategy"].get<std::string>() + "</td><td>mirror</td><td class=\"n\">" + c["attempts"].dump() +
                      "</td><td class=\"n\">" + c["successes"].dump() + "</td><td class=\"n\">" + c["failures"]["no_transport"].dump() +
                      "</td><td class=\"n\">" + c["failures"]["occluded"].dump() + "</td><td class=\"n\">" +
                      c["failures"]["outside"].dump() + "</td></tr>"),
            std::string::npos);
  // and pathex report, reading histogram.json, makes the same page
  const std::string made = html;
  ASSERT_EQ(run_pathex_args({"report", dir.string()}).code, 0);
  EXPECT_EQ(read_file(dir / "report.html"), made);
}

TEST(ReportContent, EscapesWhatItShows) {
  pathex::ReportData d;
  d.folder = "a<b";
  d.kind = "trace";
  pathex::HistogramReport h;
  h.run.scene = "x&y";
  h.run.renderer = "r\"q";
  h.classes.push_back({"c", "L.*&~(LDDE)E", {}, 0.5, {}, true});
  d.histogram = h;
  const std::string html = pathex::report_html(d, {});
  EXPECT_NE(html.find("<title>pathex report: x&amp;y, r&quot;q</title>"), std::string::npos);
  EXPECT_NE(html.find("<code>L.*&amp;~(LDDE)E</code>"), std::string::npos);
  EXPECT_NE(html.find("<code>a&lt;b</code>"), std::string::npos);
  EXPECT_EQ(html.find("hover-data"), std::string::npos);  // no images, no hover data
}

// --- bad input: one located message, exit 2, nothing written ---

TEST(ReportErrors, NotAFolderMissingOrCorruptHistogram) {
  const fs::path base = scratch_dir() / "bad";
  fs::create_directories(base / "empty");
  fs::create_directories(base / "corrupt");
  fs::create_directories(base / "wrong");
  std::ofstream(base / "file.txt") << "x";
  std::ofstream(base / "corrupt" / "histogram.json") << "{\n  \"scene\": \"s\",\n  \"spp\": [1,\n";
  std::ofstream(base / "wrong" / "histogram.json") << "{\n  \"scene\": \"s\",\n  \"renderer\": 5\n}\n";
  const std::string b = base.string();
  struct Case {
    std::string dir, message;
  } cases[] = {
      {b + "/none", b + "/none: no such folder; expected the output folder of pathex trace, bias or converge"},
      {b + "/file.txt", b + "/file.txt: is not a folder; expected the output folder of pathex trace, bias or converge"},
      {b + "/empty", b + "/empty/histogram.json: no such file; expected the histogram.json that pathex trace or pathex bias "
                         "writes into its output folder"},
      {b + "/corrupt", b + "/corrupt/histogram.json:/spp/1: not valid JSON: parse error at line 4, column 1: syntax error while "
                           "parsing value - unexpected end of input; expected '[', '{', or a literal"},
      {b + "/wrong", b + "/wrong/histogram.json:/renderer: expected a string"},
  };
  for (const Case& c : cases) {
    const CliRun r = run_pathex_args({"report", c.dir});
    EXPECT_EQ(r.code, 2) << c.dir;
    EXPECT_EQ(r.out, "") << c.dir;
    EXPECT_EQ(r.err, "pathex: error: " + c.message + "\n") << c.dir;
    EXPECT_FALSE(fs::exists(fs::path(c.dir) / "report.html")) << c.dir;
  }
}

TEST(ReportErrors, TheFolderOtherFilesAreCheckedToo) {
  // a trace folder whose run.json, missed.json or classes.exr is damaged: one message naming it
  const fs::path dir = default_render();
  struct Case {
    std::string file, bytes, message;
  } cases[] = {
      {"run.json", "{\"time_s\": \"x\"}", "/run.json:/time_s: found a string, expected a number or null"},
      {"run.json", "{\"pruned\": 3}", "/run.json:/pruned: found a number, expected an array"},
      {"missed.json", "{\"renderer\": 1}", "/missed.json:/renderer: expected a string, found a number"},
      {"classes.exr", "not an exr", "/classes.exr: cannot read the EXR file: "},
  };
  int i = 0;
  for (const Case& c : cases) {
    const fs::path copy = scratch_dir() / ("damaged-" + std::to_string(i++));
    fs::copy(dir, copy);
    fs::remove(copy / "report.html");
    std::ofstream(copy / c.file, std::ios::binary | std::ios::trunc) << c.bytes;
    const CliRun r = run_pathex_args({"report", copy.string()});
    EXPECT_EQ(r.code, 2) << c.file;
    EXPECT_EQ(r.err.rfind("pathex: error: " + copy.string() + c.message, 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(copy / "report.html")) << c.file;
  }
}

}  // namespace
