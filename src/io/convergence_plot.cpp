// Log-log convergence panels drawn with cairo (see convergence_plot.h). The same drawing routine
// paints an SVG surface and an image surface; both stream into strings.
#include "io/convergence_plot.h"

#include <cairo-svg.h>
#include <cairo.h>
#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <variant>

namespace pathex {
namespace {

// libcairo is loaded when a plot is drawn, not linked: its library and the seventeen it pulls in
// (X11, fontconfig, freetype, ...) cost every pathex process about 8 ms of start-up CPU
// (`pathex --version` 32 -> 24 ms on the loaded 2-core VM, bench/README.md), and only
// `pathex converge` draws.
struct CairoApi {
  decltype(&::cairo_arc) arc;
  decltype(&::cairo_clip) clip;
  decltype(&::cairo_create) create;
  decltype(&::cairo_destroy) destroy;
  decltype(&::cairo_fill) fill;
  decltype(&::cairo_image_surface_create) image_surface_create;
  decltype(&::cairo_line_to) line_to;
  decltype(&::cairo_move_to) move_to;
  decltype(&::cairo_paint) paint;
  decltype(&::cairo_rectangle) rectangle;
  decltype(&::cairo_restore) restore;
  decltype(&::cairo_rotate) rotate;
  decltype(&::cairo_save) save;
  decltype(&::cairo_select_font_face) select_font_face;
  decltype(&::cairo_set_dash) set_dash;
  decltype(&::cairo_set_font_size) set_font_size;
  decltype(&::cairo_set_line_width) set_line_width;
  decltype(&::cairo_set_source_rgb) set_source_rgb;
  decltype(&::cairo_show_text) show_text;
  decltype(&::cairo_status_to_string) status_to_string;
  decltype(&::cairo_stroke) stroke;
  decltype(&::cairo_surface_destroy) surface_destroy;
  decltype(&::cairo_surface_finish) surface_finish;
  decltype(&::cairo_surface_flush) surface_flush;
  decltype(&::cairo_surface_status) surface_status;
  decltype(&::cairo_surface_write_to_png_stream) surface_write_to_png_stream;
  decltype(&::cairo_svg_surface_create_for_stream) svg_surface_create_for_stream;
  decltype(&::cairo_text_extents) text_extents;
  decltype(&::cairo_translate) translate;
};

// The loaded library's functions, or the reason it could not be loaded.
const std::variant<CairoApi, std::string>& cairo_library() {
  static const std::variant<CairoApi, std::string> api = []() -> std::variant<CairoApi, std::string> {
    void* lib = ::dlopen("libcairo.so.2", RTLD_NOW | RTLD_LOCAL);  // never closed: the process keeps it
    if (lib == nullptr) return std::string("cannot load libcairo.so.2 (") + ::dlerror() + ")";
    CairoApi a{};
    const auto get = [&](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(::dlsym(lib, name));
      return fn != nullptr;
    };
    const bool ok =get(a.arc, "cairo_arc") &&
                    get(a.clip, "cairo_clip") &&
                    get(a.create, "cairo_create") &&
                    get(a.destroy, "cairo_destroy") &&
                    get(a.fill, "cairo_fill") &&
                    get(a.image_surface_create, "cairo_image_surface_create") &&
                    get(a.line_to, "cairo_line_to") &&
                    get(a.move_to, "cairo_move_to") &&
                    get(a.paint, "cairo_paint") &&
                    get(a.rectangle, "cairo_rectangle") &&
                    get(a.restore, "cairo_restore") &&
                    get(a.rotate, "cairo_rotate") &&
                    get(a.save, "cairo_save") &&
                    get(a.select_font_face, "cairo_select_font_face") &&
                    get(a.set_dash, "cairo_set_dash") &&
                    get(a.set_font_size, "cairo_set_font_size") &&
                    get(a.set_line_width, "cairo_set_line_width") &&
                    get(a.set_source_rgb, "cairo_set_source_rgb") &&
                    get(a.show_text, "cairo_show_text") &&
                    get(a.status_to_string, "cairo_status_to_string") &&
                    get(a.stroke, "cairo_stroke") &&
                    get(a.surface_destroy, "cairo_surface_destroy") &&
                    get(a.surface_finish, "cairo_surface_finish") &&
                    get(a.surface_flush, "cairo_surface_flush") &&
                    get(a.surface_status, "cairo_surface_status") &&
                    get(a.surface_write_to_png_stream, "cairo_surface_write_to_png_stream") &&
                    get(a.svg_surface_create_for_stream, "cairo_svg_surface_create_for_stream") &&
                    get(a.text_extents, "cairo_text_extents") &&
                    get(a.translate, "cairo_translate");
    if (!ok) return std::string("libcairo.so.2 lacks a function the plot needs");
    return a;
  }();
  return api;
}

// Only after draw_convergence_plot has checked that the library loaded.
const CairoApi& cairo() { return std::get<CairoApi>(cairo_library()); }


constexpr double kPanelW = 460, kPanelH = 340;
constexpr double kLeft = 72, kRight = 16, kTop = 34, kBottom = 74;  // margins inside a panel

// Colour-blind-safe palette (Okabe & Ito), one colour per renderer in order.
constexpr double kPalette[][3] = {{0.000, 0.447, 0.698}, {0.835, 0.369, 0.000}, {0.000, 0.620, 0.451},
                                  {0.800, 0.475, 0.655}, {0.902, 0.624, 0.000}, {0.337, 0.706, 0.914},
                                  {0.941, 0.894, 0.259}, {0.000, 0.000, 0.000}};

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!(v > 0.0) || !std::isfinite(v)) return;
    lo = std::min(lo, std::log10(v));
    hi = std::max(hi, std::log10(v));
  }
  bool empty() const { return !(lo <= hi); }
  // Whole decades around the data, at least one wide.
  void widen() {
    if (empty()) lo = -1, hi = 0;
    lo = std::floor(lo);
    hi = std::ceil(hi);
    if (hi - lo < 1) hi = lo + 1;
  }
};

std::string decade_label(int e) {
  char buf[32];
  if (e >= -2 && e <= 3) std::snprintf(buf, sizeof buf, "%g", std::pow(10.0, e));
  else std::snprintf(buf, sizeof buf, "1e%d", e);
  return buf;
}

void text(cairo_t* cr, double x, double y, const std::string& s, double align_x, double align_y) {
  cairo_text_extents_t ext;
  cairo().text_extents(cr, s.c_str(), &ext);
  cairo().move_to(cr, x - align_x * ext.width - ext.x_bearing, y - align_y * ext.height - ext.y_bearing);
  cairo().show_text(cr, s.c_str());
}

void draw_panel(cairo_t* cr, const PlotPanel& p, double ox, double oy) {
  Range rx, ry;
  for (const PlotSeries& s : p.series) {
    for (double t : s.time) rx.add(t);
    for (double e : s.error) ry.add(e);
    for (double e : s.std_error) ry.add(e);
  }
  rx.widen();
  ry.widen();
  const double x0 = ox + kLeft, x1 = ox + kPanelW - kRight, y0 = oy + kPanelH - kBottom, y1 = oy + kTop;
  auto px = [&](double v) { return x0 + (std::log10(v) - rx.lo) / (rx.hi - rx.lo) * (x1 - x0); };
  auto py = [&](double v) { return y0 - (std::log10(v) - ry.lo) / (ry.hi - ry.lo) * (y0 - y1); };

  cairo().select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  // --- grid and ticks at every decade (and 2, 5 within them) ---
  cairo().set_line_width(cr, 0.5);
  cairo().set_font_size(cr, 10);
  for (int e = static_cast<int>(rx.lo); e <= static_cast<int>(rx.hi); ++e)
    for (double m : {1.0, 2.0, 5.0}) {
      const double v = m * std::pow(10.0, e);
      if (std::log10(v) > rx.hi + 1e-9) break;
      cairo().set_source_rgb(cr, m == 1.0 ? 0.8 : 0.92, m == 1.0 ? 0.8 : 0.92, m == 1.0 ? 0.8 : 0.92);
      cairo().move_to(cr, px(v), y0);
      cairo().line_to(cr, px(v), y1);
      cairo().stroke(cr);
      if (m == 1.0) {
        cairo().set_source_rgb(cr, 0.1, 0.1, 0.1);
        text(cr, px(v), y0 + 6, decade_label(e), 0.5, 0.0);
      }
    }
  for (int e = static_cast<int>(ry.lo); e <= static_cast<int>(ry.hi); ++e)
    for (double m : {1.0, 2.0, 5.0}) {
      const double v = m * std::pow(10.0, e);
      if (std::log10(v) > ry.hi + 1e-9) break;
      cairo().set_source_rgb(cr, m == 1.0 ? 0.8 : 0.92, m == 1.0 ? 0.8 : 0.92, m == 1.0 ? 0.8 : 0.92);
      cairo().move_to(cr, x0, py(v));
      cairo().line_to(cr, x1, py(v));
      cairo().stroke(cr);
      if (m == 1.0) {
        cairo().set_source_rgb(cr, 0.1, 0.1, 0.1);
        text(cr, x0 - 6, py(v), decade_label(e), 1.0, 0.5);
      }
    }
  // --- frame, title, axis labels ---
  cairo().set_source_rgb(cr, 0.1, 0.1, 0.1);
  cairo().set_line_width(cr, 1.0);
  cairo().rectangle(cr, x0, y1, x1 - x0, y0 - y1);
  cairo().stroke(cr);
  cairo().set_font_size(cr, 13);
  text(cr, (x0 + x1) / 2, oy + 10, p.title, 0.5, 0.0);
  cairo().set_font_size(cr, 11);
  text(cr, (x0 + x1) / 2, y0 + 22, "CPU time (s)", 0.5, 0.0);
  cairo().save(cr);
  cairo().translate(cr, ox + 16, (y0 + y1) / 2);
  cairo().rotate(cr, -M_PI / 2);
  text(cr, 0, 0, "error (luminance)", 0.5, 0.5);
  cairo().restore(cr);

  cairo().save(cr);
  cairo().rectangle(cr, x0, y1, x1 - x0, y0 - y1);
  cairo().clip(cr);
  // --- the 1/sqrt(t) guide through the middle of the first renderer's true errors ---
  double gx = 0, gy = 0;
  int gn = 0;
  for (const PlotSeries& s : p.series)
    for (std::size_t i = 0; i < s.time.size() && i < s.error.size(); ++i)
      if (s.time[i] > 0 && s.error[i] > 0 && std::isfinite(s.error[i])) {
        gx += std::log10(s.time[i]);
        gy += std::log10(s.error[i]);
        ++gn;
      }
  if (gn > 0) {
    gx /= gn;
    gy /= gn;
    const double lx0 = rx.lo, lx1 = rx.hi;
    cairo().set_source_rgb(cr, 0.55, 0.55, 0.55);
    cairo().set_line_width(cr, 1.2);
    const double dash[] = {6.0, 4.0};
    cairo().set_dash(cr, dash, 2, 0);
    cairo().move_to(cr, px(std::pow(10.0, lx0)), py(std::pow(10.0, gy - 0.5 * (lx0 - gx))));
    cairo().line_to(cr, px(std::pow(10.0, lx1)), py(std::pow(10.0, gy - 0.5 * (lx1 - gx))));
    cairo().stroke(cr);
    cairo().set_dash(cr, nullptr, 0, 0);
  }
  // --- one colour per renderer: true error solid with markers, reported stderr dotted ---
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    const PlotSeries& s = p.series[k];
    const double* c = kPalette[k % (sizeof kPalette / sizeof kPalette[0])];
    cairo().set_source_rgb(cr, c[0], c[1], c[2]);
    for (int pass = 0; pass < 2; ++pass) {
      const std::vector<double>& ys = pass == 0 ? s.error : s.std_error;
      cairo().set_line_width(cr, pass == 0 ? 2.0 : 1.4);
      const double dots[] = {1.5, 3.0};
      if (pass == 1) cairo().set_dash(cr, dots, 2, 0);
      bool open = false;
      for (std::size_t i = 0; i < s.time.size() && i < ys.size(); ++i) {
        if (!(s.time[i] > 0) || !(ys[i] > 0) || !std::isfinite(ys[i])) {
          open = false;
          continue;
        }
        if (open) cairo().line_to(cr, px(s.time[i]), py(ys[i]));
        else cairo().move_to(cr, px(s.time[i]), py(ys[i]));
        open = true;
      }
      cairo().stroke(cr);
      cairo().set_dash(cr, nullptr, 0, 0);
      if (pass == 0)
        for (std::size_t i = 0; i < s.time.size() && i < ys.size(); ++i)
          if (s.time[i] > 0 && ys[i] > 0 && std::isfinite(ys[i])) {
            cairo().arc(cr, px(s.time[i]), py(ys[i]), 3.2, 0, 2 * M_PI);
            cairo().fill(cr);
          }
    }
  }
  cairo().restore(cr);
  // --- legend below the axis label ---
  cairo().set_font_size(cr, 10.5);
  double lx = x0;
  const double ly = y0 + 46;
  for (std::size_t k = 0; k <= p.series.size(); ++k) {
    const bool guide = k == p.series.size();
    const std::string label = guide ? "1/\u221At" : p.series[k].name;
    if (guide) {
      cairo().set_source_rgb(cr, 0.55, 0.55, 0.55);
      const double dash[] = {6.0, 4.0};
      cairo().set_dash(cr, dash, 2, 0);
    } else {
      const double* c = kPalette[k % (sizeof kPalette / sizeof kPalette[0])];
      cairo().set_source_rgb(cr, c[0], c[1], c[2]);
    }
    cairo().set_line_width(cr, 2.0);
    cairo().move_to(cr, lx, ly);
    cairo().line_to(cr, lx + 18, ly);
    cairo().stroke(cr);
    cairo().set_dash(cr, nullptr, 0, 0);
    cairo().set_source_rgb(cr, 0.1, 0.1, 0.1);
    text(cr, lx + 22, ly, label, 0.0, 0.5);
    cairo_text_extents_t ext;
    cairo().text_extents(cr, label.c_str(), &ext);
    lx += 34 + ext.x_advance;
  }
  cairo().set_font_size(cr, 9.5);
  cairo().set_source_rgb(cr, 0.35, 0.35, 0.35);
  text(cr, x0, ly + 14, "solid: true error against the reference; dotted: reported standard error", 0.0, 0.5);
}

void draw(cairo_t* cr, const std::vector<PlotPanel>& panels, int columns) {
  cairo().set_source_rgb(cr, 1, 1, 1);
  cairo().paint(cr);
  for (std::size_t i = 0; i < panels.size(); ++i)
    draw_panel(cr, panels[i], static_cast<double>(i % static_cast<std::size_t>(columns)) * kPanelW,
               static_cast<double>(i / static_cast<std::size_t>(columns)) * kPanelH);
}

cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo().surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo().destroy(c); }
};

Error cairo_error(cairo_status_t st, const char* what) {
  return make_error(ErrorCode::kBadFile, std::string("cannot draw the convergence plot (") + what + "): " + cairo().status_to_string(st));
}

}  // namespace

Result<PlotFiles> draw_convergence_plot(const std::vector<PlotPanel>& panels) {
  if (const std::string* why = std::get_if<std::string>(&cairo_library()))
    return make_error(ErrorCode::kBadFile, "cannot draw the convergence plot: " + *why);
  const int columns = panels.size() > 1 ? 2 : 1;
  const int rows = static_cast<int>((std::max<std::size_t>(panels.size(), 1) + static_cast<std::size_t>(columns) - 1) /
                                    static_cast<std::size_t>(columns));
  const double w = columns * kPanelW, h = rows * kPanelH;
  PlotFiles files;
  {
    std::unique_ptr<cairo_surface_t, SurfaceDeleter> svg(cairo().svg_surface_create_for_stream(append, &files.svg, w, h));
    std::unique_ptr<cairo_t, ContextDeleter> cr(cairo().create(svg.get()));
    draw(cr.get(), panels, columns);
    cairo().surface_finish(svg.get());
    if (cairo_status_t st = cairo().surface_status(svg.get()); st != CAIRO_STATUS_SUCCESS) return cairo_error(st, "SVG");
  }
  {
    std::unique_ptr<cairo_surface_t, SurfaceDeleter> img(
        cairo().image_surface_create(CAIRO_FORMAT_RGB24, static_cast<int>(w), static_cast<int>(h)));
    std::unique_ptr<cairo_t, ContextDeleter> cr(cairo().create(img.get()));
    draw(cr.get(), panels, columns);
    cairo().surface_flush(img.get());
    if (cairo_status_t st = cairo().surface_write_to_png_stream(img.get(), append, &files.png); st != CAIRO_STATUS_SUCCESS)
      return cairo_error(st, "PNG");
  }
  return files;
}

}  // namespace pathex
