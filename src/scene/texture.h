// Textures: what a scene's material parameters and alpha cut-outs may be besides constants
// (docs/textures.md). Plain values like the materials; evaluation lives in trace/texture_eval.h.
//
// A texture is a node of a small expression tree over the hit's surface parameters (u, v) (Hit::uv):
// a constant, an image looked up bilinearly, a checkerboard, a product or a lerp of other textures.
// Every texture yields RGB; a float parameter (a mix amount, an alpha) reads the first channel of
// a float texture, which the importers build so that its three channels agree (FloatChannel).
// Images are read once per scene through io/image_read.h and shared by index (Scene::images).
//
// Textured material parameters do not change a material's kind, its letters or its bytes
// (scene_hash.cpp hashes them): the scene keeps, beside each material, the list of its textured
// parameters (MaterialTextures), and the tracer substitutes their values at each hit.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "io/image_read.h"

namespace pathex {

// What an image lookup does outside [0, 1)²: pbrt-v4's repeat, clamp and black (Mitsuba 3's
// repeat, clamp and zero).
enum class TextureWrap : std::uint32_t { kRepeat, kClamp, kBlack };

// How one float is read from an image (float textures): pbrt-v4's rule (the alpha channel when
// the file has one, else the mean of R, G and B, which is the grey of a one-channel file) or
// Mitsuba 3's (the luminance of R, G and B).
enum class FloatChannel : std::uint32_t { kNone, kPbrt, kLuminance };

enum class TextureKind : std::uint32_t { kConstant, kImage, kCheckerboard, kScale, kMix };

// The texture coordinates (s, t) of a hit's (u, v): s = m[0] u + m[1] v + m[2],
// t = m[3] u + m[4] v + m[5] (pbrt-v4's uscale, vscale, udelta, vdelta; Mitsuba 3's to_uv).
struct UvTransform {
  float m[6] = {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f};
  glm::vec2 apply(glm::vec2 uv) const { return {m[0] * uv.x + m[1] * uv.y + m[2], m[3] * uv.x + m[4] * uv.y + m[5]}; }
};

struct Texture {
  TextureKind kind = TextureKind::kConstant;
  glm::vec3 value{0.0f};  // kConstant
  // kImage: index into Scene::images, looked up at (s, t) bilinearly between texel centres
  // (pbrt-v4's Image::Bilerp: x = s·width − ½); row 0 is the image's top. `flip_t`: t = 1 − t
  // first (pbrt-v4, whose v runs up the image); Mitsuba 3 looks up t as it is.
  int image = -1;
  TextureWrap wrap = TextureWrap::kRepeat;
  bool flip_t = false;
  FloatChannel channel = FloatChannel::kNone;  // kNone: RGB; else the float, copied to R, G and B
  float scale = 1.0f;     // kImage: the value times scale, then
  bool invert = false;    // kImage: 1 − it (pbrt-v4), then clamped at 0 (pbrt-v4 ClampZero)
  UvTransform uv;         // kImage, kCheckerboard
  // kCheckerboard: a where ⌊s⌋ + ⌊t⌋ is even, b where it is odd; kScale: a × b;
  // kMix: (1 − amount) a + amount b. Indices into Scene::textures, each smaller than this one's.
  int a = -1, b = -1, amount = -1;
};

// A constant texture of `value`.
inline Texture constant(glm::vec3 value) {
  Texture t;
  t.value = value;
  return t;
}

// A material parameter that a texture gives (TextureBinding::param).
enum class TexturedParam : std::uint32_t {
  kReflectance,    // Diffuse::albedo, CoatedDiffuse::reflectance, DiffuseTransmission::reflectance
  kTransmittance,  // DiffuseTransmission::transmittance
  // A microfacet alpha (a float texture), clamped to [kSmoothAlpha, 1]: a textured roughness never
  // makes a rough lobe a Dirac delta, so the material keeps its letter D (docs/textures.md).
  kAlphaU,  // Conductor::alpha_u, RoughDielectric::alpha_u, CoatedDiffuse::roughness (isotropic)
  kAlphaV,  // Conductor::alpha_v, RoughDielectric::alpha_v
  kSpecularReflectance,   // Conductor::tint (Mitsuba 3's specular_reflectance), in [0, 1]
  kConductorReflectance,  // pbrt-v4's conductor "reflectance" r: eta 1, k = 2 √r / √(1 − r), r in [0, 0.9999]
};

// How a binding's texture value becomes the parameter, after the bilinear lookup: each of these
// maps is non-linear, so it is applied per hit to the filtered value, as the source renderer
// applies it (pbrt-v4 remaps the roughness it looked up; Mitsuba 3 divides the diffuse
// reflectance it looked up), never to the texels.
enum class TextureMap : std::uint32_t {
  kLinear,
  kSqrt,     // pbrt-v4's remaproughness: alpha = √roughness
  kPlastic,  // Mitsuba 3's plastic (nonlinear false): the base ρ / (1 − R̄ + ρ R̄), R̄ = TextureBinding::r_bar
};

struct TextureBinding {
  int component = -1;  // a Mixture's component index; -1: the material itself
  TexturedParam param = TexturedParam::kReflectance;
  int texture = -1;    // index into Scene::textures
  float scale = 1.0f;  // the value times this, then clamped to [0, 1] (pbrt-v4 diffusetransmission's scale)
  TextureMap map = TextureMap::kLinear;
  float r_bar = 0.0f;  // kPlastic: the coat's mean internal reflectance (optics/internal_reflectance.h)
};

// How a material turns its shading normal (docs/textures.md "Bump and normal maps"): a normal map
// (an RGB texture in the tangent frame (s, t, n) of the shading normal n and the surface's dp/du,
// RGB in [0, 1] read as 2 RGB − 1, pbrt-v4's NormalMap() and Mitsuba 3's normalmap), or a bump map
// (a float texture of displacement along n whose finite differences in uv tilt the tangents:
// pbrt-v4's BumpMap(), Mitsuba 3's bumpmap, which replaces dp/du's normal part by the gradient).
// Only the shading normal changes: the material's kind and letters stay (a bump is never a letter).
enum class NormalPerturbation : std::uint32_t { kNone, kNormalMap, kBumpPbrt, kBumpMitsuba };

// The textured parameters of one material. `amount` >= 0: a Mixture whose weights follow a float
// texture (pbrt-v4's mix with a textured amount): component i weighs
// (1 − amount) weight0[i] + amount weight1[i]; its stored weights are those at amount ½.
struct MaterialTextures {
  std::vector<TextureBinding> bindings;
  int amount = -1;
  std::vector<float> weight0, weight1;
  NormalPerturbation perturb = NormalPerturbation::kNone;
  int perturb_texture = -1;  // index into Scene::textures: the normal map (RGB) or the bump map (float)
  float bump_scale = 1.0f;   // kBumpMitsuba: the gradient times this (Mitsuba's `scale`)
  bool empty() const { return bindings.empty() && amount < 0 && perturb == NormalPerturbation::kNone; }
};

}  // namespace pathex
