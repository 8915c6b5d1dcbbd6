#include "measure/ladder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "io/histogram_json.h"
#include "io/image_io.h"
#include "io/input_file.h"

namespace pathex {

Result<std::vector<Budget>> parse_ladder(const std::string& text, bool time, const std::string& option) {
  std::vector<Budget> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    Budget b;
    try {
      std::size_t used = 0;
      if (time) b.seconds = std::stod(item, &used);
      else b.spp = std::stoull(item, &used);
      if (used != item.size() || item.empty() || item[0] == '-') throw std::invalid_argument(item);
    } catch (const std::exception&) {
      return make_error(ErrorCode::kUsage, option + " '" + text + "': '" + item + "' is not a " +
                                               (time ? "number of seconds" : "whole number of samples per pixel") +
                                               "; expected a comma-separated list such as " + (time ? "1,4,16" : "4,16,64,256"));
    }
    if (time ? !(b.seconds > 0.0 && b.seconds <= 86400.0) : (b.spp < 1 || b.spp > (1u << 24)))
      return make_error(ErrorCode::kUsage, option + " '" + text + "': " + item + " is out of range, expected " +
                                               (time ? "0 < seconds <= 86400" : "1 to 16777216 spp"));
    if (!out.empty() && (time ? b.seconds <= out.back().seconds : b.spp <= out.back().spp))
      return make_error(ErrorCode::kUsage, option + " '" + text + "': budgets must increase");
    out.push_back(b);
  }
  if (out.empty() || text.back() == ',') return make_error(ErrorCode::kUsage, option + " '" + text + "': expected a list such as 4,16,64");
  return out;
}

std::vector<float> luminance_image(const RgbImage& im) {
  std::vector<float> out(static_cast<std::size_t>(im.width) * static_cast<std::size_t>(im.height));
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = static_cast<float>(luminance({im.rgb[3 * i], im.rgb[3 * i + 1], im.rgb[3 * i + 2]}));
  return out;
}



Result<bool> load_reference_file(const std::string& file, int width, int height, std::vector<ClassRow>* rows,
                                 std::string* renderer) {
  namespace fs = std::filesystem;
  std::string exr;
  if (file.ends_with(".json")) {
    Result<std::string> text = read_input_file(file, std::uint64_t{1} << 30);
    if (!text) return text.error();
    Result<HistogramFile> h = parse_histogram_json(*text, file);
    if (!h) return h.error();
    *renderer = h->report.run.renderer;
    for (ClassRow& row : *rows) {
      if (row.name == "total") {
        if (!h->report.only.empty()) continue;  // an --only render's total is not the image's
        row.reference = h->report.total.luminance;
        row.reference_stderr = std::isfinite(h->report.total.std_error) ? h->report.total.std_error : 0.0;
        continue;
      }
      for (const ClassEstimate& c : h->report.classes)
        if (c.name == row.name && c.rendered) {  // a class that was not rendered has no value
          row.reference = c.estimate.luminance;
          row.reference_stderr = std::isfinite(c.estimate.std_error) ? c.estimate.std_error : 0.0;
        }
    }
    const fs::path p(file);
    for (const fs::path& beside : {fs::path(p).replace_extension(".exr"), p.parent_path() / "classes.exr"}) {
      std::error_code ec;
      if (fs::exists(beside, ec)) {
        exr = beside.string();
        break;
      }
    }
  } else if (file.ends_with(".exr")) {
    exr = file;
  } else {
    return make_error(ErrorCode::kUsage, "--reference " + file + ": expected a histogram.json or an .exr file of an earlier run");
  }
  if (!exr.empty()) {
    Result<std::vector<ImageLayer>> layers = read_exr_layers(exr);
    if (!layers) return layers.error();
    for (ClassRow& row : *rows)
      for (const ImageLayer& l : *layers)
        if (l.name == row.name) {
          if (l.image.width != width || l.image.height != height) {
            Error e = make_error(ErrorCode::kUsage, "the reference image is " + std::to_string(l.image.width) + " x " +
                                                        std::to_string(l.image.height) + " pixels, the ladder's " +
                                                        std::to_string(width) + " x " + std::to_string(height) +
                                                        "; render both at the same --resolution");
            e.where = exr;
            return e;
          }
          row.pixels = luminance_image(l.image);
          if (!file.ends_with(".json")) {  // an EXR alone: the image mean is the reference
            double s = 0.0;
            for (float v : *row.pixels) s += v;
            row.reference = row.pixels->empty() ? 0.0 : s / static_cast<double>(row.pixels->size());
          }
        }
  }
  for (const ClassRow& row : *rows)
    if (row.reference) return true;
  return make_error(ErrorCode::kUsage, "--reference " + file + " has none of the classes measured (by name: total or the class file's)");
}
Result<bool> measure_rung(const RenderOutput& out, const Classifier* classifier, const std::vector<ClassRow>& rows,
                          RungResult* r) {
  RunInfo info;
  info.spp = out.spp_done;
  std::vector<ClassInfo> infos;
  for (std::size_t i = 1; i < rows.size(); ++i) infos.push_back({rows[i].name, rows[i].expr});
  Result<HistogramReport> rep = make_report(out.histogram, info, classifier, infos, std::uint64_t{0});
  if (!rep) return rep.error();
  r->nonfinite = rep->nonfinite_samples;
  const std::vector<ImageLayer> layers = out.images.layers(1.0 / static_cast<double>(out.spp_done));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Estimate& e = i == 0 ? rep->total : rep->classes[i - 1].estimate;
    ClassMeasure c;
    c.estimate = e.luminance;
    c.std_error = e.std_error;
    c.stability = e.stability;
    c.dof = e.dof;
    if (rows[i].pixels) {
      const std::vector<float> lum = luminance_image(layers[i].image);
      double sum = 0.0;
      for (std::size_t p = 0; p < lum.size(); ++p) {
        const double d = static_cast<double>(lum[p]) - static_cast<double>((*rows[i].pixels)[p]);
        sum += d * d;
      }
      c.rms_pixel = lum.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(lum.size()));
    }
    r->classes.push_back(c);
  }
  return true;
}

std::string fmt(double v, const char* f) {
  if (!std::isfinite(v)) return "-";
  char buf[48];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

Series analyse(const std::vector<RungResult>& rungs, std::size_t row, const ClassRow& cr, bool biased) {
  Series s;
  if (!cr.reference) return s;
  std::vector<RungError> re;
  std::vector<double> times;
  double sum_e2t = 0.0;
  int n = 0;
  for (const RungResult& r : rungs) {
    const ClassMeasure& m = r.classes[row];
    const double err = std::fabs(m.estimate - *cr.reference);
    const double rounding = kRoundingFloor * std::fabs(*cr.reference);
    const double sigma =
        std::sqrt(m.std_error * m.std_error + cr.reference_stderr * cr.reference_stderr + rounding * rounding);
    s.error.push_back(err);
    s.z.push_back(sigma > 0.0 ? (m.estimate - *cr.reference) / sigma : std::numeric_limits<double>::quiet_NaN());
    s.efficiency.push_back(err > 0.0 && r.cpu_s > 0.0 ? 1.0 / (err * err * r.cpu_s) : std::numeric_limits<double>::quiet_NaN());
    times.push_back(r.cpu_s);
    re.push_back({m.estimate, m.std_error, m.stability, m.dof});
    if (r.cpu_s > 0.0) {
      sum_e2t += err * err * r.cpu_s;
      ++n;
    }
  }
  if (n > 0 && sum_e2t > 0.0) s.pooled_efficiency = static_cast<double>(n) / sum_e2t;
  s.slope = loglog_slope(times, s.error);
  s.check = check_stderr(re, *cr.reference, cr.reference_stderr);
  if (s.check.disagrees && !biased) {
    const RungResult& at = rungs[static_cast<std::size_t>(s.check.max_z_rung)];
    s.warning = "the reported stderr disagrees with the true error: chi2 " + fmt(s.check.chi2, "%.3g") + " over " +
                std::to_string(s.check.dof) + " rungs (limit " + fmt(s.check.limit, "%.3g") + " at p = 0.001), " +
                (at.classes[row].std_error > 0.0 ? fmt(s.check.max_abs_z, "%.1f") + " sigma off"
                                                  : "a stderr of 0 with an error of " + fmt(s.error[static_cast<std::size_t>(s.check.max_z_rung)], "%.3g")) +
                " at " + at.budget.text();
  }
  if (s.check.too_large && !biased)
    s.warning += std::string(s.warning.empty() ? "" : "; ") + "the reported stderr is larger than the true error: chi2 " +
                 fmt(s.check.lower_chi2, "%.3g") + " over " + std::to_string(s.check.lower_dof) + " rungs (below " +
                 fmt(s.check.lower_limit, "%.3g") + ", the lower limit at p = 0.001): the error bars overstate the error";
  if (s.check.unstable)
    s.warning += std::string(s.warning.empty() ? "" : "; ") + "the stderr is unstable: its variance estimate has a relative error of " +
                 fmt(s.check.stability, "%.2f") + " (limit " + fmt(kUnstableVariance, "%.2f") + "): a few batches carry the estimate";
  return s;
}

Rankings rank_renderers(const std::vector<ClassRow>& rows, const std::vector<std::string>& renderers,
                        const std::vector<std::vector<Series>>& series,
                        const std::vector<std::vector<std::optional<std::string>>>& cannot) {
  Rankings out;
  std::vector<Ranking>& best = out.best;
  std::vector<std::string>& best_lines = out.lines;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!rows[i].unmeasurable.empty()) {
      best_lines.push_back(rows[i].name + ": not measurable with this reference (" + rows[i].unmeasurable + "); nothing ranked");
      continue;
    }
    int top = -1, second = -1;
    for (std::size_t k = 0; k < renderers.size(); ++k) {
      const double e = series[k][i].pooled_efficiency;
      if (!std::isfinite(e) || cannot[k][i]) continue;
      if (top < 0 || e > series[static_cast<std::size_t>(top)][i].pooled_efficiency) {
        second = top;
        top = static_cast<int>(k);
      } else if (second < 0 || e > series[static_cast<std::size_t>(second)][i].pooled_efficiency) {
        second = static_cast<int>(k);
      }
    }
    std::string excluded;  // the renderers not ranked on the class: they cannot sample all of it
    for (std::size_t k = 0; k < renderers.size(); ++k)
      if (cannot[k][i]) excluded += (excluded.empty() ? "" : ", ") + renderers[k] + " cannot sample " + *cannot[k][i];
    if (top < 0) {
      if (rows[i].reference && !excluded.empty()) best_lines.push_back(rows[i].name + ": none ranked (" + excluded + ")");
      continue;
    }
    const double et = series[static_cast<std::size_t>(top)][i].pooled_efficiency;
    Ranking b{rows[i].name, renderers[static_cast<std::size_t>(top)], et, "", 0.0};
    std::string line = rows[i].name + ": " + renderers[static_cast<std::size_t>(top)] + " (efficiency " + fmt(et, "%.3g");
    if (second >= 0) {
      const double es = series[static_cast<std::size_t>(second)][i].pooled_efficiency;
      b.runner_up = renderers[static_cast<std::size_t>(second)];
      b.ratio = et / es;
      line += ", " + fmt(et / es, "%.2f") + "x " + renderers[static_cast<std::size_t>(second)] + "'s";
    }
    if (!series[static_cast<std::size_t>(top)][i].warning.empty()) line += "; its stderr is flagged";
    if (!excluded.empty()) line += "; not ranked: " + excluded;
    best.push_back(b);
    best_lines.push_back(line + ")");
  }
  return out;
}

}  // namespace pathex
