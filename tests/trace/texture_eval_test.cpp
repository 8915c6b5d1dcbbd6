// trace/texture_eval.h: image lookups against hand-computed bilinear values, the wrap modes, the
// checkerboard's parity, uv transforms, pbrt's flip/scale/invert, the float channels, the
// composite textures, a material with textured parameters, and the alpha test's pass fraction.
#include "trace/texture_eval.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "optics/fresnel.h"
#include "support/stat_seed.h"
#include "trace/rng.h"

namespace pathex {
namespace {

using glm::vec2;
using glm::vec3;

// A 2 x 2 image, row-major from the top: t00 t10 / t01 t11 (grey values 1, 2 / 3, 4 in R, their
// tenths in G and 0 in B).
LinearImage two_by_two() {
  LinearImage im;
  im.width = 2;
  im.height = 2;
  for (float v : {1.0f, 2.0f, 3.0f, 4.0f}) im.rgb.insert(im.rgb.end(), {v, v / 10.0f, 0.0f});
  return im;
}

TEST(TextureLookup, BilinearBetweenTexelCentres) {
  const LinearImage im = two_by_two();
  // Texel centres are at (0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75).
  EXPECT_FLOAT_EQ(image_bilerp(im, {0.25f, 0.25f}, TextureWrap::kClamp, FloatChannel::kNone).x, 1.0f);
  EXPECT_FLOAT_EQ(image_bilerp(im, {0.75f, 0.75f}, TextureWrap::kClamp, FloatChannel::kNone).x, 4.0f);
  EXPECT_FLOAT_EQ(image_bilerp(im, {0.5f, 0.5f}, TextureWrap::kClamp, FloatChannel::kNone).x, 2.5f);
  // x = 0.375·2 − ½ = 0.25: ¾ of t00 and ¼ of t10; y = 0.625·2 − ½ = 0.75: ¼ of row 0, ¾ of row 1.
  const float expected = 0.25f * (0.75f * 1 + 0.25f * 2) + 0.75f * (0.75f * 3 + 0.25f * 4);
  const vec3 v = image_bilerp(im, {0.375f, 0.625f}, TextureWrap::kClamp, FloatChannel::kNone);
  EXPECT_FLOAT_EQ(v.x, expected);
  EXPECT_FLOAT_EQ(v.y, expected / 10.0f);
  EXPECT_FLOAT_EQ(v.z, 0.0f);
}

TEST(TextureLookup, WrapModesAtTheCorner) {
  const LinearImage im = two_by_two();
  // At (0, 0): x = y = −½, the texels (−1, −1), (0, −1), (−1, 0), (0, 0) a quarter each.
  EXPECT_FLOAT_EQ(image_bilerp(im, {0.0f, 0.0f}, TextureWrap::kRepeat, FloatChannel::kNone).x, 2.5f);  // all four
  EXPECT_FLOAT_EQ(image_bilerp(im, {0.0f, 0.0f}, TextureWrap::kClamp, FloatChannel::kNone).x, 1.0f);   // t00 four times
  EXPECT_FLOAT_EQ(image_bilerp(im, {0.0f, 0.0f}, TextureWrap::kBlack, FloatChannel::kNone).x, 0.25f);  // t00 once, zeros
  // Repeat is periodic, also far away and below zero.
  EXPECT_FLOAT_EQ(image_bilerp(im, {3.375f, -1.375f}, TextureWrap::kRepeat, FloatChannel::kNone).x,
                  image_bilerp(im, {0.375f, 0.625f}, TextureWrap::kRepeat, FloatChannel::kNone).x);
  // Beyond the image, clamp is its edge and black is nothing.
  EXPECT_FLOAT_EQ(image_bilerp(im, {5.0f, 0.75f}, TextureWrap::kClamp, FloatChannel::kNone).x, 4.0f);
  EXPECT_FLOAT_EQ(image_bilerp(im, {5.0f, 0.75f}, TextureWrap::kBlack, FloatChannel::kNone).x, 0.0f);
  // Coordinates beyond int range and non-finite ones do not overflow.
  EXPECT_TRUE(std::isfinite(image_bilerp(im, {3e20f, -3e20f}, TextureWrap::kRepeat, FloatChannel::kNone).x));
  EXPECT_FLOAT_EQ(image_bilerp(im, {3e20f, 0.25f}, TextureWrap::kClamp, FloatChannel::kNone).x, 2.0f);
  EXPECT_FLOAT_EQ(image_bilerp(im, {NAN, 0.25f}, TextureWrap::kClamp, FloatChannel::kNone).x, 0.0f);
}

TEST(TextureLookup, FloatChannels) {
  LinearImage im;
  im.width = im.height = 1;
  im.rgb = {0.2f, 0.4f, 0.9f};
  EXPECT_FLOAT_EQ(image_bilerp(im, {0.5f, 0.5f}, TextureWrap::kRepeat, FloatChannel::kPbrt).x, 0.5f);  // the mean
  EXPECT_NEAR(image_bilerp(im, {0.5f, 0.5f}, TextureWrap::kRepeat, FloatChannel::kLuminance).y, 0.212671 * 0.2 + 0.715160 * 0.4 + 0.072169 * 0.9,
              1e-6);
  im.alpha = {0.125f};
  EXPECT_FLOAT_EQ(image_bilerp(im, {0.5f, 0.5f}, TextureWrap::kRepeat, FloatChannel::kPbrt).z, 0.125f);  // pbrt: the alpha channel
}

// A conductor's Fresnel reflectance at normal incidence, red channel.
double fresnel_complex_at_normal(const Conductor& c) { return fresnel_complex(1.0f, c.eta.x, c.k.x); }

Scene scene_with(std::vector<Texture> textures) {
  Scene s;
  s.images.push_back(two_by_two());
  s.textures = std::move(textures);
  return s;
}

TEST(TextureEval, ImageWithUvTransformFlipScaleAndInvert) {
  Texture t;
  t.kind = TextureKind::kImage;
  t.image = 0;
  t.wrap = TextureWrap::kClamp;
  t.uv = UvTransform{{2.0f, 0.0f, 0.25f, 0.0f, 0.5f, 0.0f}};  // s = 2u + ¼, t = v/2
  Scene s = scene_with({t});
  // (u, v) = (0.25, 1.5): (s, t) = (0.75, 0.75), t11.
  EXPECT_FLOAT_EQ(eval_texture(s, 0, {0.25f, 1.5f}).x, 4.0f);
  s.textures[0].flip_t = true;  // pbrt-v4: t = 1 − 0.75 = 0.25, row 0: t10
  EXPECT_FLOAT_EQ(eval_texture(s, 0, {0.25f, 1.5f}).x, 2.0f);
  s.textures[0].scale = 0.25f;  // 0.5
  EXPECT_FLOAT_EQ(eval_texture(s, 0, {0.25f, 1.5f}).x, 0.5f);
  s.textures[0].invert = true;  // 1 − 0.5 in R, 1 − 0.05 in G, 1 in B
  EXPECT_EQ(eval_texture(s, 0, {0.25f, 1.5f}), vec3(0.5f, 0.95f, 1.0f));
  s.textures[0].scale = 1.0f;  // 1 − 2 clamps at 0
  EXPECT_FLOAT_EQ(eval_texture(s, 0, {0.25f, 1.5f}).x, 0.0f);
}

TEST(TextureEval, CheckerboardParityAndComposites) {
  const vec3 red(1, 0, 0), blue(0, 0, 1);
  const Texture a = constant(red), b = constant(blue);
  Texture checks;
  checks.kind = TextureKind::kCheckerboard;
  checks.uv = UvTransform{{4.0f, 0.0f, 0.0f, 0.0f, 4.0f, 0.0f}};
  checks.a = 0;
  checks.b = 1;
  const Texture half = constant(vec3(0.25f));
  Texture scaled;
  scaled.kind = TextureKind::kScale;
  scaled.a = 2;
  scaled.b = 3;
  Texture mixed;
  mixed.kind = TextureKind::kMix;
  mixed.a = 0;
  mixed.b = 1;
  mixed.amount = 3;
  const Scene s = scene_with({a, b, checks, half, scaled, mixed});
  EXPECT_EQ(eval_texture(s, 2, {0.1f, 0.1f}), red);    // cells (0, 0): even
  EXPECT_EQ(eval_texture(s, 2, {0.3f, 0.1f}), blue);   // (1, 0): odd
  EXPECT_EQ(eval_texture(s, 2, {0.3f, 0.3f}), red);    // (1, 1): even
  EXPECT_EQ(eval_texture(s, 2, {-0.1f, 0.1f}), blue);  // (−1, 0): odd
  EXPECT_EQ(eval_texture(s, 2, {-0.1f, -0.1f}), red);  // (−1, −1): even
  EXPECT_EQ(eval_texture(s, 4, {0.3f, 0.1f}), 0.25f * blue);
  EXPECT_EQ(eval_texture(s, 5, {0.0f, 0.0f}), 0.75f * red + 0.25f * blue);
}

TEST(TextureEval, MaterialParametersAndATexturedMixAmount) {
  Texture checks;
  checks.kind = TextureKind::kCheckerboard;
  checks.a = 0;
  checks.b = 1;
  const Scene s = scene_with({constant(vec3(0.9f)), constant(vec3(1.5f)), checks});
  Material out;
  MaterialTextures tex;
  tex.bindings.push_back({-1, TexturedParam::kReflectance, 2, 1.0f});
  textured_material(s, Material{Diffuse{vec3(0.5f)}}, tex, {0.5f, 0.5f}, &out);
  EXPECT_EQ(std::get<Diffuse>(out).albedo, vec3(0.9f));
  textured_material(s, Material{Diffuse{vec3(0.5f)}}, tex, {1.5f, 0.5f}, &out);
  EXPECT_EQ(std::get<Diffuse>(out).albedo, vec3(1.0f));  // clamped to [0, 1]
  // A mixture: the transmittance of component 1 scaled by ½, weights lerped by the amount.
  Mixture mix;
  mix.components = {{0.5f, Diffuse{vec3(0.2f)}}, {0.5f, DiffuseTransmission{vec3(0.1f), vec3(0.1f)}}};
  MaterialTextures mt;
  mt.bindings.push_back({1, TexturedParam::kTransmittance, 0, 0.5f});
  mt.amount = 0;  // 0.9
  mt.weight0 = {1.0f, 0.0f};
  mt.weight1 = {0.0f, 0.8f};
  textured_material(s, Material{mix}, mt, {0.5f, 0.5f}, &out);
  const Mixture& m = std::get<Mixture>(out);
  EXPECT_FLOAT_EQ(m.components[0].weight, 0.1f);
  EXPECT_FLOAT_EQ(m.components[1].weight, 0.9f * 0.8f);
  EXPECT_EQ(std::get<DiffuseTransmission>(m.components[1].material).transmittance, vec3(0.45f));
  EXPECT_EQ(std::get<DiffuseTransmission>(m.components[1].material).reflectance, vec3(0.1f));
  EXPECT_EQ(std::get<Diffuse>(m.components[0].material).albedo, vec3(0.2f));
}

// Roughness, conductor reflectance and Mitsuba's plastic: each value is mapped at the hit after
// the lookup (TextureMap), and a textured alpha is clamped to [1e-3, 1], so the material keeps its
// letter D (issue 35).
TEST(TextureEval, RoughnessConductorReflectanceAndPlasticMaps) {
  const Scene s = scene_with({constant(vec3(0.25f)), constant(vec3(0.0f)), constant(vec3(4.0f)), constant(vec3(0.64f)),
                              constant(vec3(0.5f))});
  Material out;
  // pbrt-v4's remaproughness: alpha = √0.25 = ½ along u; unmapped 0.25 along v.
  MaterialTextures rough;
  rough.bindings.push_back({-1, TexturedParam::kAlphaU, 0, 1.0f, TextureMap::kSqrt});
  rough.bindings.push_back({-1, TexturedParam::kAlphaV, 0, 1.0f, TextureMap::kLinear});
  Conductor metal;
  metal.alpha_u = metal.alpha_v = 1.0f;
  textured_material(s, Material{metal}, rough, {0.5f, 0.5f}, &out);
  EXPECT_EQ(std::get<Conductor>(out).alpha_u, 0.5f);
  EXPECT_EQ(std::get<Conductor>(out).alpha_v, 0.25f);
  textured_material(s, Material{RoughDielectric{1.5f, vec3(1.0f), 1.0f, 1.0f}}, rough, {0.5f, 0.5f}, &out);
  EXPECT_EQ(std::get<RoughDielectric>(out).alpha_u, 0.5f);
  EXPECT_EQ(std::get<RoughDielectric>(out).alpha_v, 0.25f);
  CoatedDiffuse coat;
  coat.roughness = 1.0f;
  textured_material(s, Material{coat}, rough, {0.5f, 0.5f}, &out);
  EXPECT_EQ(std::get<CoatedDiffuse>(out).roughness, 0.5f);  // the coat is isotropic: alpha u only
  // 0 is clamped to 1e-3: still rough, letter D, never a Dirac delta; 4 is clamped to 1.
  for (auto [texture, expected] : {std::pair{1, kSmoothAlpha}, std::pair{2, 1.0f}}) {
    MaterialTextures t;
    t.bindings.push_back({-1, TexturedParam::kAlphaU, texture, 1.0f, TextureMap::kSqrt});
    t.bindings.push_back({-1, TexturedParam::kAlphaV, texture, 1.0f, TextureMap::kSqrt});
    textured_material(s, Material{metal}, t, {0.5f, 0.5f}, &out);
    EXPECT_EQ(std::get<Conductor>(out).alpha_u, expected);
    EXPECT_FALSE(std::get<Conductor>(out).smooth());
    EXPECT_EQ(letters_of(out), static_cast<LetterMask>(1u << kD));
  }
  // pbrt-v4's conductor reflectance r = 0.64: eta 1, k = 2 √r / √(1 − r) = 8/3, which reflects
  // exactly r at normal incidence (k² / (4 + k²)).
  MaterialTextures refl;
  refl.bindings.push_back({-1, TexturedParam::kConductorReflectance, 3, 1.0f});
  textured_material(s, Material{Conductor{}}, refl, {0.5f, 0.5f}, &out);
  const Conductor& c = std::get<Conductor>(out);
  EXPECT_EQ(c.eta, vec3(1.0f));
  EXPECT_NEAR(c.k.x, 8.0 / 3.0, 1e-6);
  EXPECT_NEAR(fresnel_complex_at_normal(c), 0.64, 1e-6);
  // Mitsuba's specular_reflectance: the conductor's tint.
  MaterialTextures tint;
  tint.bindings.push_back({-1, TexturedParam::kSpecularReflectance, 4, 1.0f});
  textured_material(s, Material{Conductor{}}, tint, {0.5f, 0.5f}, &out);
  EXPECT_EQ(std::get<Conductor>(out).tint, vec3(0.5f));
  // Mitsuba's plastic: the base ρ / (1 − R̄ + ρ R̄) of the value looked up, ρ = ½, R̄ = 0.6.
  MaterialTextures plastic;
  plastic.bindings.push_back({-1, TexturedParam::kReflectance, 4, 1.0f, TextureMap::kPlastic, 0.6f});
  textured_material(s, Material{CoatedDiffuse{}}, plastic, {0.5f, 0.5f}, &out);
  EXPECT_NEAR(std::get<CoatedDiffuse>(out).reflectance.x, 0.5 / 0.7, 1e-6);
}

// pbrt-v4's stochastic alpha: a fraction 1 − a of rays pass. 200,000 rays of random origins and
// directions (a stream of mix64 keyed by test::stat_seed, 0 unless PATHEX_STAT_SEED says
// otherwise); binomial tolerance for 3 checks at a family-wise false-failure rate of 0.1 %.
TEST(AlphaTest, PassesAFractionOneMinusAlphaOfTheRays) {
  EXPECT_TRUE(alpha_passes(0.0f, vec3(0.0f), vec3(0, 0, 1)));
  EXPECT_FALSE(alpha_passes(1.0f, vec3(0.0f), vec3(0, 0, 1)));
  const std::uint64_t stream = test::stat_seed(0) << 32;  // 6 x 200,000 keys per seed, far below 2^32
  const double k = test::family_sigmas(3, 1e-3, test::kNormalDof);
  for (float a : {0.1f, 0.5f, 0.8f}) {
    const int n = 200000;
    int passed = 0;
    for (int i = 0; i < n; ++i) {
      const auto u = [&](int c) { return static_cast<float>(mix64((static_cast<std::uint64_t>(6 * i + c) + 1) | stream) >> 40) * 0x1p-24f; };
      passed += alpha_passes(a, vec3(u(0), u(1), u(2)), glm::normalize(vec3(u(3), u(4), u(5)) - 0.5f)) ? 1 : 0;
    }
    const double p = 1.0 - a, se = std::sqrt(p * (1 - p) / n);
    test::stat_log("alpha " + std::to_string(a), (static_cast<double>(passed) / n - p) / se, k);
    EXPECT_NEAR(static_cast<double>(passed) / n, p, k * se) << "alpha " << a;
  }
}

}  // namespace
}  // namespace pathex
