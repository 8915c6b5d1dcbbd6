#include "scene/universe.h"

#include "automata/ops.h"
#include "classify/pathclass.h"

namespace pathex {

Dfa scene_universe(const SceneTypes& types) {
  EndTypes ends;
  ends.lights.assign(types.lights.begin(), types.lights.end());
  ends.sensors = {types.sensor};
  // Classic L [interior]* E, mapped to full paths by the ends, then the universe.
  std::string interior = "[";
  if (types.interior & (1u << kS)) interior += 'S';
  if (types.interior & (1u << kD)) interior += 'D';
  interior += "]";
  ClassOptions o;
  o.notation = Notation::kHeckbert;
  o.ends = ends;
  const std::string expr = interior == "[]" ? "LE" : "L" + interior + "*E";
  Result<PathClass> c = compile_class(expr, o);
  return c ? c->dfa : dfa_empty();
}

}  // namespace pathex
