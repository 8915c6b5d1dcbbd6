#include "cli/bias_common.h"

#include "io/estimate_text.h"
#include "cli/witness_text.h"
#include "io/histogram_json.h"
#include "io/reach_json.h"

namespace pathex::cli {

std::string missed_line(const BiasReport& r) {
  if (r.covered)
    return r.renderer + " cannot sample 0 % of what " + r.reference + " finds: it samples every path of the scene up to " +
           std::to_string(r.reference_bounces) + " interior vertices (exact, by the checker)";
  return r.renderer + " cannot sample " + percent(r.share) + " ± " + percent(r.share_std_error, 2) + " of what " +
         r.reference + " finds (luminance " + absolute(r.missed) + " of " + absolute(r.total) + ")";
}

std::vector<std::string> undersampled_lines(const BiasReport& r, int top) {
  std::vector<std::string> lines;
  if (!r.undersampled) return lines;
  const UnderSampling& u = *r.undersampled;
  char each[32];
  std::snprintf(each, sizeof each, "%.2g", u.each);
  lines.push_back("under-sampled: light " + r.renderer + " can sample where its estimate at " + std::to_string(u.spp) +
                  " spp and " + r.reference + "'s differ beyond their combined stderr (two-sided p < " + each + ": " +
                  percent(u.rate, 0) + " false alarms over " + std::to_string(u.comparisons) +
                  " comparisons, Šidák; Student's t, Welch's dof) by at least " + percent(u.min_share) +
                  " of the light it can sample:");
  if (u.flagged.empty())
    lines.push_back("  none: its estimates of the image, each class and each listed path it can sample agree with the reference's");
  for (std::size_t i = 0; i < u.flagged.size() && static_cast<int>(i) < top; ++i) {
    const UnderSampled& f = u.flagged[i];
    char z[32];
    std::snprintf(z, sizeof z, "%.1f", f.z);
    lines.push_back("  " + std::string(f.path ? "path " : "") + f.name + ": reachable, under-sampled at " +
                    std::to_string(u.spp) + " spp: estimate " + absolute(f.renderer) + ", reference " +
                    absolute(f.reference) + " (z " + z + ")");
  }
  if (u.flagged.size() > static_cast<std::size_t>(std::max(top, 0)))
    lines.push_back("  … " + std::to_string(u.flagged.size() - static_cast<std::size_t>(top)) + " more (\"undersampled\" in the JSON)");
  return lines;
}

std::string witness_line(const Witness& w) {
  return w.path + ", chains " + chains_text(w.chains) + "; " + w.reason;
}

}  // namespace pathex::cli
