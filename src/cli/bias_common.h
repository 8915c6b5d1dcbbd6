// What `bias`, `trace --missed` and the check file's `missed` requirement print: the report as
// text (the classes bias renders: output/render_job.h's bias_classes).
#pragma once

#include <string>
#include <vector>

#include "bias/bias.h"
#include "classify/pathclass.h"
#include "core/error.h"
#include "scene/scene.h"

namespace pathex::cli {

// "pt-nee cannot sample 6.3 % ± 0.08 % of what bdpt finds (luminance 0.04064 ± 0.00049 of 0.64123)".
std::string missed_line(const BiasReport& r);

// The under-sampled light (BiasReport::undersampled), a heading and a line per flagged class or
// path, at most `top` of them: "caustic: reachable, under-sampled at 4 spp: estimate 0.00000 ±
// 0.00000, reference 0.02560 ± 0.00040 (z -64.0)". Empty without a comparison.
std::vector<std::string> undersampled_lines(const BiasReport& r, int top);

// "LSDSDDSE, chains SD(0..1) DSD(1..3)[mirror] DD(3..4) DS(4..5); no DD join: …"
std::string witness_line(const Witness& w);

}  // namespace pathex::cli
