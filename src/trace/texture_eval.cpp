// Textures at a hit (docs/textures.md): an image's bilinear look-up with its wrap mode, the procedural
// textures (checkerboard, scale, mix, constant) by recursion over the scene's texture list, and a
// material with its textured parameters evaluated and put in place, so that the BSDFs see plain
// numbers and stay unaware of textures; and the shading normal a bump or normal map turns.
#include "trace/texture_eval.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <variant>

#include "trace/frame.h"
#include "trace/rng.h"

namespace pathex {
namespace {

// Texel (x, y) of `image` after wrapping; false: outside a kBlack image.
bool wrap_texel(int* x, int* y, int width, int height, TextureWrap wrap) {
  if (wrap == TextureWrap::kRepeat) {
    *x %= width;
    *y %= height;
    if (*x < 0) *x += width;
    if (*y < 0) *y += height;
    return true;
  }
  if (wrap == TextureWrap::kClamp) {
    *x = std::clamp(*x, 0, width - 1);
    *y = std::clamp(*y, 0, height - 1);
    return true;
  }
  return *x >= 0 && *x < width && *y >= 0 && *y < height;
}

glm::vec3 texel(const LinearImage& im, int x, int y, TextureWrap wrap, FloatChannel channel) {
  if (!wrap_texel(&x, &y, im.width, im.height, wrap)) return glm::vec3(0.0f);
  const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) + static_cast<std::size_t>(x);
  const glm::vec3 rgb(im.rgb[3 * i], im.rgb[3 * i + 1], im.rgb[3 * i + 2]);
  switch (channel) {
    case FloatChannel::kNone: return rgb;
    case FloatChannel::kPbrt: return glm::vec3(im.alpha.empty() ? (rgb.x + rgb.y + rgb.z) / 3.0f : im.alpha[i]);
    case FloatChannel::kLuminance: return glm::vec3(0.212671f * rgb.x + 0.715160f * rgb.y + 0.072169f * rgb.z);
  }
  return rgb;
}

// Pixel coordinates far outside any image (a huge uscale, a far uv) are folded before the float to
// int conversion, which would overflow: repeat keeps them modulo the size (in double), clamp and
// black need only their side.
double fold(double x, int size, TextureWrap wrap) {
  if (std::fabs(x) < 1e9) return x;
  if (wrap == TextureWrap::kRepeat) return std::fmod(x, static_cast<double>(size)) + (x < 0 ? static_cast<double>(size) : 0.0);
  return x < 0 ? -2.0 : static_cast<double>(size) + 1.0;
}

float channel0(const glm::vec3& v) { return v.x; }

}  // namespace

glm::vec3 image_bilerp(const LinearImage& image, glm::vec2 st, TextureWrap wrap, FloatChannel channel) {
  if (!std::isfinite(st.x) || !std::isfinite(st.y)) return glm::vec3(0.0f);
  const double x = fold(static_cast<double>(st.x) * image.width - 0.5, image.width, wrap);
  const double y = fold(static_cast<double>(st.y) * image.height - 0.5, image.height, wrap);
  const double fx = std::floor(x), fy = std::floor(y);
  const int xi = static_cast<int>(fx), yi = static_cast<int>(fy);
  const float dx = static_cast<float>(x - fx), dy = static_cast<float>(y - fy);
  // Lerps as a + d (b − a): exact where neighbouring texels are equal (a constant image is its value).
  const glm::vec3 t00 = texel(image, xi, yi, wrap, channel), t10 = texel(image, xi + 1, yi, wrap, channel);
  const glm::vec3 t01 = texel(image, xi, yi + 1, wrap, channel), t11 = texel(image, xi + 1, yi + 1, wrap, channel);
  const glm::vec3 top = t00 + dx * (t10 - t00), bottom = t01 + dx * (t11 - t01);
  return top + dy * (bottom - top);
}

glm::vec3 eval_texture(const Scene& scene, int index, glm::vec2 uv) {
  const Texture& t = scene.textures[static_cast<std::size_t>(index)];
  switch (t.kind) {
    case TextureKind::kConstant: return t.value;
    case TextureKind::kImage: {
      glm::vec2 st = t.uv.apply(uv);
      if (t.flip_t) st.y = 1.0f - st.y;
      glm::vec3 v = t.scale * image_bilerp(scene.images[static_cast<std::size_t>(t.image)], st, t.wrap, t.channel);
      if (t.invert) v = glm::vec3(1.0f) - v;
      return glm::max(v, glm::vec3(0.0f));
    }
    case TextureKind::kCheckerboard: {
      const glm::vec2 st = t.uv.apply(uv);
      if (!std::isfinite(st.x) || !std::isfinite(st.y)) return eval_texture(scene, t.a, uv);
      const double cells = std::floor(static_cast<double>(st.x)) + std::floor(static_cast<double>(st.y));
      return eval_texture(scene, std::fmod(cells, 2.0) == 0.0 ? t.a : t.b, uv);
    }
    case TextureKind::kScale: return eval_texture(scene, t.a, uv) * eval_texture(scene, t.b, uv);
    case TextureKind::kMix: {
      const float amount = channel0(eval_texture(scene, t.amount, uv));
      return (1.0f - amount) * eval_texture(scene, t.a, uv) + amount * eval_texture(scene, t.b, uv);
    }
  }
  return glm::vec3(0.0f);
}

namespace {

// The one place where a texture's value becomes a material parameter (docs/textures.md). The
// value is clamped as the source renderers clamp it, then mapped (TextureMap: non-linear maps
// act on the filtered value at the hit, never on texels).
void bind(BasicMaterial* m, const TextureBinding& b, glm::vec3 value) {
  value *= b.scale;
  if (b.param == TexturedParam::kAlphaU || b.param == TexturedParam::kAlphaV) {
    float a = std::max(value.x, 0.0f);
    if (b.map == TextureMap::kSqrt) a = std::sqrt(a);
    a = std::isfinite(a) ? std::clamp(a, kSmoothAlpha, 1.0f) : 1.0f;  // never smooth: the letter stays D
    const bool u = b.param == TexturedParam::kAlphaU;
    if (auto* c = std::get_if<Conductor>(m)) {
      (u ? c->alpha_u : c->alpha_v) = a;
    } else if (auto* d = std::get_if<RoughDielectric>(m)) {
      (u ? d->alpha_u : d->alpha_v) = a;
    } else if (auto* coat = std::get_if<CoatedDiffuse>(m); coat && u) {
      coat->roughness = a;
    }
    return;
  }
  if (b.param == TexturedParam::kConductorReflectance) {  // pbrt-v4's ConductorMaterial, reflectance mode
    if (auto* c = std::get_if<Conductor>(m)) {
      const glm::vec3 r = glm::clamp(value, glm::vec3(0.0f), glm::vec3(0.9999f));
      c->eta = glm::vec3(1.0f);
      c->k = 2.0f * glm::sqrt(r) / glm::sqrt(glm::vec3(1.0f) - r);
    }
    return;
  }
  value = glm::clamp(value, glm::vec3(0.0f), glm::vec3(1.0f));
  if (b.map == TextureMap::kPlastic) value = value / (1.0f - b.r_bar + value * b.r_bar);
  if (auto* d = std::get_if<Diffuse>(m)) {
    d->albedo = value;
  } else if (auto* c = std::get_if<CoatedDiffuse>(m)) {
    c->reflectance = value;
  } else if (auto* t = std::get_if<DiffuseTransmission>(m)) {
    (b.param == TexturedParam::kTransmittance ? t->transmittance : t->reflectance) = value;
  } else if (auto* k = std::get_if<Conductor>(m); k && b.param == TexturedParam::kSpecularReflectance) {
    k->tint = value;
  }
}

void bind(Material* m, const TextureBinding& b, glm::vec3 value) {
  std::visit(
      [&](auto& k) {
        using K = std::decay_t<decltype(k)>;
        if constexpr (std::is_same_v<K, Mixture>) {
          if (b.component >= 0 && static_cast<std::size_t>(b.component) < k.components.size())
            bind(&k.components[static_cast<std::size_t>(b.component)].material, b, value);
        } else {
          BasicMaterial basic{k};
          bind(&basic, b, value);
          k = std::get<K>(basic);
        }
      },
      *m);
}

}  // namespace

void textured_material(const Scene& scene, const Material& base, const MaterialTextures& textures, glm::vec2 uv, Material* out) {
  *out = base;
  for (const TextureBinding& b : textures.bindings) bind(out, b, eval_texture(scene, b.texture, uv));
  if (textures.amount >= 0) {
    if (auto* mix = std::get_if<Mixture>(out)) {
      const float a = std::clamp(channel0(eval_texture(scene, textures.amount, uv)), 0.0f, 1.0f);
      for (std::size_t i = 0; i < mix->components.size() && i < textures.weight0.size(); ++i)
        mix->components[i].weight = (1.0f - a) * textures.weight0[i] + a * textures.weight1[i];
    }
  }
}

glm::vec3 perturbed_normal(const Scene& scene, const MaterialTextures& textures, glm::vec2 uv, const glm::vec3& ng, const glm::vec3& ns,
                           glm::vec3 dpdu, glm::vec3 dpdv) {
  if (textures.perturb == NormalPerturbation::kNone) return ns;
  const auto finite = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  const glm::vec3 span = glm::cross(dpdu, dpdv);
  if (!finite(dpdu) || !finite(dpdv) || !(glm::dot(span, span) > 0.0f)) {  // pbrt-v4's CoordinateSystem(n)
    const Frame f = Frame::from_normal(ns);
    dpdu = f.s;
    dpdv = f.t;
  }
  glm::vec3 n = ns;
  if (textures.perturb == NormalPerturbation::kNormalMap) {
    // The texel's 2 RGB − 1 in the frame (s, t, ns), s = dp/du made perpendicular to ns, t = ns × s
    // (pbrt-v4's Frame::FromXZ(dpdu, ns); Mitsuba 3's shading frame, Gram–Schmidt on dp_du).
    const glm::vec3 c = 2.0f * eval_texture(scene, textures.perturb_texture, uv) - glm::vec3(1.0f);
    const Frame f = Frame::from_normal_tangent(ns, dpdu);
    n = c.x * f.s + c.y * f.t + c.z * f.n;
  } else {
    const float h = kBumpDelta;
    const float d = channel0(eval_texture(scene, textures.perturb_texture, uv));
    const float gu = (channel0(eval_texture(scene, textures.perturb_texture, uv + glm::vec2(h, 0.0f))) - d) / h;
    const float gv = (channel0(eval_texture(scene, textures.perturb_texture, uv + glm::vec2(0.0f, h))) - d) / h;
    glm::vec3 su = dpdu, sv = dpdv;
    if (textures.perturb == NormalPerturbation::kBumpPbrt) {
      // pbrt-v4's shading tangents where the shading normal is not the geometric one (smooth
      // meshes): ts = ns × dp/du, ss = ts × ns. dp/du' = ss + gu ns (its BumpMap() without the
      // displace · dn/du terms, which pathex leaves out: they vanish on flat shading).
      if (ns != ng) {
        const glm::vec3 ts = glm::cross(ns, dpdu);
        if (glm::dot(ts, ts) > 0.0f) {
          su = glm::cross(ts, ns);
          sv = ts;
        }
      }
      su += gu * ns;
      sv += gv * ns;
    } else {  // Mitsuba 3's bumpmap: dp/du's part along ns replaced by the scaled gradient
      su += (textures.bump_scale * gu - glm::dot(ns, dpdu)) * ns;
      sv += (textures.bump_scale * gv - glm::dot(ns, dpdv)) * ns;
    }
    n = glm::cross(su, sv);
  }
  const float len = glm::length(n);
  if (!(len > 0.0f) || !std::isfinite(len)) return ns;
  n /= len;
  return glm::dot(n, ns) < 0.0f ? -n : n;
}

float shape_alpha(const Scene& scene, int shape, glm::vec2 uv) {
  const int t = scene.shapes[static_cast<std::size_t>(shape)].alpha;
  return t < 0 ? 1.0f : std::clamp(channel0(eval_texture(scene, t, uv)), 0.0f, 1.0f);
}

bool alpha_passes(float alpha, const glm::vec3& origin, const glm::vec3& direction) {
  if (alpha >= 1.0f) return false;
  if (alpha <= 0.0f) return true;
  std::uint64_t h = 0x243f6a8885a308d3ULL;
  for (float x : {origin.x, origin.y, origin.z, direction.x, direction.y, direction.z})
    h = mix64(h ^ (static_cast<std::uint64_t>(std::bit_cast<std::uint32_t>(x)) + 0x9e3779b97f4a7c15ULL));
  const float u = static_cast<float>(h >> 40) * 0x1p-24f;
  return u >= alpha;
}

}  // namespace pathex
