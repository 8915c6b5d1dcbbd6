// Light path expressions (LPEs): the camera-first path notation of Open Shading Language, which
// Arnold, RenderMan and Karma use to define AOVs, read into a full-path expression tree.
//
// An LPE event is a tuple <event-type scattering-type>: the event types are C (camera), R
// (reflection), T (transmission), V (volume), L (light), O (emissive object), B (background); the
// scattering types D (diffuse), G (glossy), S (singular, i.e. specular). A path is C, its interior
// events from the camera outwards, then L or O. The result of parse_lpe() denotes, eye-first, the
// full paths E c(k+2) c(k+1) ck … c1 c0 L those events stand for:
//
//   C        -> E then a sensor's two letters, reversed   (every sensor type in `sensors`)
//   R, T     -> the interior letter: D for D and G, S for S (R and T are not told apart)
//   L        -> a light's two letters, reversed, then L    (every light type in `lights`)
//   O        -> the same for area lights only (an emissive surface is pathex's area light)
//   V, B     -> refused where written as a positive event (pathex has no media, no environment)
//
// G becomes D because a glossy BSDF, like a diffuse one, is a finite density: local sampling and
// plain joins treat it as D (DESIGN §1, §4). Camera and light events carry no scattering type
// (OSL labels them with none), so `<LD>` is no event at all while `<L.>` and `[^D]` include them.
//
// Syntax, as OSL's parser reads it (src/liboslexec/lpeparse.cpp):
//   seq      := item*                       concatenation; whitespace is ignored
//   item     := primary repeat? ('|' primary repeat?)*
//                                            '|' joins the item before it with the one after it:
//                                            `C.*L|O` is C .* (L|O), `CD|SL` is C (D|S) L
//   primary  := symbol | '.' | '<' tuple '>' | '(' seq ')' | '[' item+ ']' | '[^' symbol+ ']'
//   tuple    := component component?        event type, then scattering type ('.' when absent)
//   component:= symbol | '.' | '[' symbol+ ']' | '[^' symbol+ ']'
//   repeat   := '*' | '+' | '?' | '{n}' | '{n,}' | '{n,m}'
// A bare event type X means <X.>, a bare scattering type Y means <.Y>, and '.' any event.
// Custom labels ('key') are refused with a message: pathex paths carry no object or light names.
//
// Errors are values with the 1-based column of the offending character, like the full parser's.
#pragma once

#include <string_view>
#include <vector>

#include "alphabet/alphabet.h"
#include "core/error.h"
#include "core/limits.h"
#include "regex/ast.h"

namespace pathex {

// The eye-first full-notation tree of an LPE, with C and L standing for the given sensor and
// light types.
Result<Regex> parse_lpe(std::string_view text, const std::vector<LightType>& lights,
                        const std::vector<SensorType>& sensors, const Limits& limits);

}  // namespace pathex
