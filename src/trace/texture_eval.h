// Evaluating a scene's textures (scene/texture.h) at a hit's surface parameters, and a material
// with its textured parameters put in (docs/textures.md).
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "scene/scene.h"
#include "scene/texture.h"

namespace pathex {

// An image's value at texture coordinates (s, t): bilinear between the four nearest texel centres
// (pbrt-v4's Image::Bilerp, x = s·width − ½, y = t·height − ½, row 0 the top), texels outside the
// image wrapped by `wrap` (kBlack: zero). `channel` kNone: RGB; else the float of
// FloatChannel copied to the three channels.
glm::vec3 image_bilerp(const LinearImage& image, glm::vec2 st, TextureWrap wrap, FloatChannel channel);

// Texture `index` of `scene` at surface parameters `uv`.
glm::vec3 eval_texture(const Scene& scene, int index, glm::vec2 uv);

// `out` = `base` with the parameters `textures` binds evaluated at `uv`. `out` may hold another
// material before (a Mixture's storage is reused).
void textured_material(const Scene& scene, const Material& base, const MaterialTextures& textures, glm::vec2 uv, Material* out);

// The shading normal `ns` (unit) turned by the normal or bump map of `textures` (NormalPerturbation)
// at `uv`, with the hit's tangents `dpdu`, `dpdv` (EmbreeScene::uv_tangents) and its unit
// geometric normal `ng`; `ns` itself without one. Where dp/du and dp/dv span no plane (degenerate
// uv, a sphere's pole) an arbitrary frame around ns stands in, as pbrt-v4 does. Bump maps take
// finite differences of step kBumpDelta in u and v: pbrt-v4's step without ray differentials
// (pathex has none). The result is unit and on ns's side. Only the normal changes: never a letter.
inline constexpr float kBumpDelta = 0.0005f;
glm::vec3 perturbed_normal(const Scene& scene, const MaterialTextures& textures, glm::vec2 uv, const glm::vec3& ng, const glm::vec3& ns,
                           glm::vec3 dpdu, glm::vec3 dpdv);

// The coverage of shape `shape` at `uv` in [0, 1] (Shape::alpha; 1 without one).
float shape_alpha(const Scene& scene, int shape, glm::vec2 uv);

// pbrt-v4's stochastic alpha test: a ray meets a surface of coverage a in (0, 1) when a hash of the
// ray in [0, 1) is below a (so a fraction a of the rays meet it); coverage 0 is always passed, 1
// always met.
bool alpha_passes(float alpha, const glm::vec3& origin, const glm::vec3& direction);

}  // namespace pathex
