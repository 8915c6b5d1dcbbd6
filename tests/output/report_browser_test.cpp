// report.html in a real browser (issue 41): headless Chromium (Debian's `chromium`, which setup.sh
// installs) loads the default render's report from disk, and the test checks the DOM its script
// built (--dump-dom: every tile, the tables, the hover data read, a pixel's values per class equal
// to the EXR's) and that a screenshot is not blank (decoded with libpng: its pixels vary).
// Skipped, saying so, only where Chromium cannot start; a browser that hangs fails (timeout).
#include <gtest/gtest.h>

#include <png.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "stats/histogram.h"
#include "io/image_io.h"
#include "support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using pathex::test::CliRun;
using pathex::test::read_file;
using pathex::test::run_pathex_args;
using pathex::test::run_shell;
using pathex::test::scratch_dir;
using pathex::test::shell_quote;

constexpr int kBrowserSeconds = 90;  // per Chromium run: a hang fails the test instead of stalling CI

// Chromium headless with `args` on the file `url`; stdout in out, stderr discarded into a file.
// Its profile and HOME are a fresh folder of this test (containers have no writable HOME).
CliRun chromium(const std::string& args, const std::string& url) {
  const fs::path home = scratch_dir() / "chromium-home";
  fs::create_directories(home);
  return run_shell("HOME=" + shell_quote(home.string()) + " timeout " + std::to_string(kBrowserSeconds) +
                   " chromium --headless=new --no-sandbox --disable-gpu --disable-dev-shm-usage --no-first-run "
                   "--user-data-dir=" + shell_quote((home / "profile").string()) + " " + args + " " + shell_quote(url) +
                   " 2> " + shell_quote((scratch_dir() / "chromium-stderr.txt").string()));
}

// Skips the test when Chromium is not installed or cannot start at all.
#define SKIP_WITHOUT_CHROMIUM()                                                                                        \
  do {                                                                                                                 \
    if (run_shell("command -v chromium >/dev/null 2>&1").code != 0)                                                    \
      GTEST_SKIP() << "chromium is not installed (setup.sh installs Debian's chromium package)";                       \
    const CliRun v = run_shell("timeout 30 chromium --headless=new --no-sandbox --disable-gpu --version 2>&1");       \
    if (v.code != 0) GTEST_SKIP() << "chromium cannot start here (exit " << v.code << "): " << v.out;                  \
  } while (false)

const fs::path& default_report() {
  static const fs::path dir = [] {
    const fs::path d = scratch_dir() / "default";
    const CliRun r = run_pathex_args({"trace", "--out", d.string(), "--quiet", "--report"});
    EXPECT_EQ(r.code, 0) << r.err;
    return d;
  }();
  return dir;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + what.size())) ++n;
  return n;
}

TEST(ReportBrowser, ChromiumBuildsTheTilesTablesAndHoverData) {
  SKIP_WITHOUT_CHROMIUM();
  const fs::path dir = default_report();
  const auto doc = nlohmann::json::parse(read_file(dir / "histogram.json"));
  // #pixel=X,Y shows that pixel's values as hovering it does
  const CliRun r = chromium("--dump-dom", "file://" + fs::absolute(dir / "report.html").string() + "#pixel=32,40");
  ASSERT_NE(r.code, 124) << "chromium did not finish within " << kBrowserSeconds << " s";
  if (r.out.empty()) GTEST_SKIP() << "chromium started but printed no DOM (exit " << r.code << "): "
                                  << read_file(scratch_dir() / "chromium-stderr.txt").substr(0, 2000);
  ASSERT_EQ(r.code, 0);
  const std::string& dom = r.out;
  // the script ran and read every layer's data
  EXPECT_NE(dom.find("data-hover=\"ready\""), std::string::npos);
  EXPECT_NE(dom.find("data-hover-layers=\"6\""), std::string::npos);  // total and the five classes
  // every tile, its image, and the tables
  EXPECT_EQ(count(dom, "<div class=\"tile\""), doc["classes"].size());
  for (const auto& c : doc["classes"])
    EXPECT_NE(dom.find("data-class=\"" + c["name"].get<std::string>() + "\""), std::string::npos) << c["name"];
  EXPECT_EQ(count(dom, "<img class=\"px\" data-layer="), 6u);
  EXPECT_NE(dom.find("<table id=\"run\">"), std::string::npos);
  EXPECT_NE(dom.find("<table id=\"paths-table\">"), std::string::npos);
  EXPECT_EQ(count(dom, "<tr data-path="), 20u);
  // the hover box, built by the script for pixel (32, 40): each layer's luminance as the EXR has it
  const std::size_t box = dom.find("<div id=\"hover\"");
  ASSERT_NE(box, std::string::npos);
  const std::string panel = dom.substr(box, dom.find("</div>", box) - box);
  EXPECT_NE(panel.find("<b>pixel (32, 40)</b>"), std::string::npos) << panel;
  pathex::Result<std::vector<pathex::ImageLayer>> layers = pathex::read_exr_layers((dir / "classes.exr").string());
  ASSERT_TRUE(layers.ok());
  for (const pathex::ImageLayer& l : *layers) {
    const std::string row = "<tr data-layer=\"" + l.name + "\"><td>" + l.name + "</td><td class=\"n\">";
    const std::size_t at = panel.find(row);
    ASSERT_NE(at, std::string::npos) << l.name << " in " << panel;
    const double shown = std::stod(panel.substr(at + row.size()));
    const double exr = pathex::luminance({l.image.at(32, 40, 0), l.image.at(32, 40, 1), l.image.at(32, 40, 2)});
    EXPECT_NEAR(shown, exr, 5e-4 * std::fabs(exr) + 1e-12) << l.name;  // shown with 4 significant digits
  }
}

// The PNG's 8-bit RGB(A) pixels, read with libpng.
struct Decoded {
  int width = 0, height = 0, channels = 0;
  std::vector<unsigned char> pixels;
};
Decoded decode_png(const std::string& path) {
  Decoded d;
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return d;
  image.format = PNG_FORMAT_RGB;
  d.width = static_cast<int>(image.width);
  d.height = static_cast<int>(image.height);
  d.channels = 3;
  d.pixels.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, d.pixels.data(), 0, nullptr)) d.pixels.clear();
  png_image_free(&image);
  return d;
}

TEST(ReportBrowser, ScreenshotIsNotBlank) {
  SKIP_WITHOUT_CHROMIUM();
  const fs::path dir = default_report();
  const fs::path shot = scratch_dir() / "report.png";
  const CliRun r = chromium("--window-size=1200,1600 --hide-scrollbars --screenshot=" + shell_quote(shot.string()),
                            "file://" + fs::absolute(dir / "report.html").string());
  ASSERT_NE(r.code, 124) << "chromium did not finish within " << kBrowserSeconds << " s";
  if (!fs::exists(shot)) GTEST_SKIP() << "chromium started but wrote no screenshot (exit " << r.code << "): "
                                      << read_file(scratch_dir() / "chromium-stderr.txt").substr(0, 2000);
  const Decoded png = decode_png(shot.string());
  ASSERT_EQ(png.width, 1200);
  ASSERT_EQ(png.height, 1600);
  ASSERT_EQ(png.pixels.size(), 1200u * 1600u * 3u);
  // Not blank: the pixels' grey levels vary (a white page has variance 0), and the render's dark
  // box and the coloured walls are there: many dark pixels, and red-dominant and green-dominant ones.
  double sum = 0, sum2 = 0;
  std::size_t dark = 0, red = 0, green = 0;
  for (std::size_t i = 0; i < png.pixels.size(); i += 3) {
    const int R = png.pixels[i], G = png.pixels[i + 1], B = png.pixels[i + 2];
    const double grey = (R + G + B) / 3.0;
    sum += grey;
    sum2 += grey * grey;
    dark += grey < 40 ? 1 : 0;
    red += R > G + 25 && R > B + 25 ? 1 : 0;
    green += G > R + 25 && G > B + 25 ? 1 : 0;
  }
  const double n = static_cast<double>(png.pixels.size() / 3);
  const double variance = sum2 / n - (sum / n) * (sum / n);
  EXPECT_GT(variance, 500.0);
  EXPECT_GT(dark, 20000u);  // the render alone is 384 x 384 pixels on the page
  EXPECT_GT(red, 1000u) << "dark " << dark << " green " << green << " variance " << variance;
  EXPECT_GT(green, 1000u);
}

}  // namespace
