// What `bias`, `trace --missed` and the check file's `missed` requirement share: the classes a
// render labels, the reference render and its report as JSON and as text.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bias/bias.h"
#include "cli/render_job.h"
#include "classify/pathclass.h"
#include "core/error.h"
#include "output/bias_json.h"
#include "scene/scene.h"

namespace pathex::cli {

// The classes of a render of `scene`, as trace compiles them (cli/render_job.h): the class file's
// or, without one, the built-ins but $all; Heckbert and LPE entries get the scene's light and
// sensor types. A class file entry named "missed" (bias's layer) is refused at its JSON pointer.
Result<std::unique_ptr<RenderClasses>> bias_classes(const std::string& classes_file, const Scene& scene,
                                                    const Limits& limits);

// "pt-nee cannot sample 6.3 % ± 0.08 % of what bdpt finds (luminance 0.04064 ± 0.00049 of 0.64123)".
std::string missed_line(const BiasReport& r);

// The under-sampled light (BiasReport::undersampled), a heading and a line per flagged class or
// path, at most `top` of them: "caustic: reachable, under-sampled at 4 spp: estimate 0.00000 ±
// 0.00000, reference 0.02560 ± 0.00040 (z -64.0)". Empty without a comparison.
std::vector<std::string> undersampled_lines(const BiasReport& r, int top);

// "LSDSDDSE, chains SD(0..1) DSD(1..3)[mirror] DD(3..4) DS(4..5); no DD join: …"
std::string witness_line(const Witness& w);

}  // namespace pathex::cli
