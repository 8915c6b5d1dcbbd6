// A scene's universe (DESIGN §6): U_s = L (light pairs) [interior letters]* (sensor pair) E,
// intersected with U. An over-approximation: geometry may still forbid a string.
#pragma once

#include "automata/dfa.h"
#include "scene/scene.h"

namespace pathex {

Dfa scene_universe(const SceneTypes& types);

}  // namespace pathex
