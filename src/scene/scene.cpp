// JSON scene loading with validation. A small reader walks the document and turns every
// violation into one Error whose `where` is "file:/json/pointer" and whose message says what was
// expected; unknown keys are errors, so a typo never silently does nothing.
#include "scene/scene.h"

#include "scene/mitsuba_import.h"
#include "scene/pbrt_import.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>
#include <tiny_obj_loader.h>

#include "io/input_file.h"
#include "io/json_reader.h"
#include "scene/import_common.h"
#include "scene/metal_spectra.h"

namespace pathex {
namespace {

using nlohmann::json;
using glm::vec3;

float max_component(vec3 v) { return std::max(v.x, std::max(v.y, v.z)); }

// The shared JSON reader (io/json_reader.h) plus the scene's own kind of value, the 3-vector.
class Reader : public JsonReader {
 public:
  using JsonReader::JsonReader;

  // A 3-vector; `nonneg` for colours, `unit` requires a non-zero length (normalised by callers).
  Result<vec3> vector3(const json& j, const std::string& key, const std::string& ptr, bool required,
                       vec3 fallback = vec3(0.0f), bool nonneg = false, bool nonzero = false) const {
    const std::string p = ptr + "/" + key;
    if (!j.contains(key)) {
      if (!required) return fallback;
      return fail(p, "missing " + key + ", expected [x, y, z]");
    }
    const json& v = j.at(key);
    if (!v.is_array() || v.size() != 3)
      return fail(p, "expected an array of 3 numbers, found " + (v.is_array() ? "an array of " + std::to_string(v.size()) : kind(v)));
    vec3 out;
    for (int i = 0; i < 3; ++i) {
      const json& e = v[static_cast<std::size_t>(i)];
      if (!e.is_number()) return fail(p + "/" + std::to_string(i), "expected a number, found " + kind(e));
      const double x = e.get<double>();
      if (!std::isfinite(x) || std::fabs(x) > 1e30) return fail(p + "/" + std::to_string(i), "expected a finite number");
      if (nonneg && x < 0) return fail(p + "/" + std::to_string(i), "expected a non-negative number, found " + fmt(x));
      out[i] = static_cast<float>(x);
    }
    if (nonzero && glm::dot(out, out) == 0.0f) return fail(p, "expected a non-zero vector");
    return out;
  }

  // An emission, intensity, irradiance or power: a non-negative 3-vector of at most kMaxLightValue
  // whose nonzero components are at least kMinLightValue.
  Result<vec3> light_value(const json& j, const std::string& key, const std::string& ptr, bool required) const {
    Result<vec3> v = vector3(j, key, ptr, required, vec3(0.0f), /*nonneg=*/true);
    if (!v) return v;
    for (int i = 0; i < 3; ++i)
      if ((*v)[i] > kMaxLightValue)
        return fail(ptr + "/" + key + "/" + std::to_string(i),
                    "expected at most 1e9, found " + fmt((*v)[i]) +
                        ": the tracer sums contributions exactly below 2^50 (about 1.1e15) and drops larger ones, so "
                        "brighter lights would lose samples; scale the scene's lights down (the image scales with them)");
      else if ((*v)[i] > 0.0f && (*v)[i] < kMinLightValue)
        return fail(ptr + "/" + key + "/" + std::to_string(i),
                    "expected 0 or at least 1e-6, found " + fmt((*v)[i]) +
                        ": the tracer sums contributions exactly on a grid of 2^-64 (about 5.4e-20), so dimmer lights "
                        "would round to nothing; scale the scene's lights up (the image scales with them)");
    return v;
  }

};

#define PATHEX_TRY(var, expr)      \
  auto var##_r = (expr);           \
  if (!var##_r) return var##_r.error(); \
  auto var = std::move(*var##_r)

// Microfacet alphas of a conductor or dielectric (of the "distribution" read_distribution() reads): "roughness" for both tangents, "roughness_u" and
// "roughness_v" for each (default: "roughness"), each in [0, 1]; below 1e-3 in both is smooth.
Result<glm::vec2> read_alphas(const Reader& r, const json& j, const std::string& ptr) {
  PATHEX_TRY(both, r.number(j, "roughness", ptr, 0.0, 1.0, 0.0));
  PATHEX_TRY(u, r.number(j, "roughness_u", ptr, 0.0, 1.0, both));
  PATHEX_TRY(v, r.number(j, "roughness_v", ptr, 0.0, 1.0, both));
  return glm::vec2(static_cast<float>(u), static_cast<float>(v));
}

// The microfacet distribution of a rough material: "distribution" "ggx" (the default) or "beckmann".
Result<MicrofacetKind> read_distribution(const Reader& r, const json& j, const std::string& ptr) {
  if (!j.contains("distribution")) return MicrofacetKind::kGgx;
  PATHEX_TRY(name, r.string(j, "distribution", ptr));
  if (name == "ggx") return MicrofacetKind::kGgx;
  if (name == "beckmann") return MicrofacetKind::kBeckmann;
  return r.fail(ptr + "/distribution", "unknown microfacet distribution '" + name + "', expected ggx or beckmann");
}

// What the JSON reader needs to make textures (scene/texture.h, docs/textures.md): the scene
// that receives them, where image files are, the images read so far (once per file and
// encoding), and the bindings of the material being read (`component`: its index in a mixture).
struct JsonTextures {
  Scene* scene = nullptr;
  std::string base_dir;
  SceneLoadOptions options;
  std::size_t texels = 0;
  std::map<std::pair<std::string, int>, int> images;
  MaterialTextures current;
  int component = -1;
};

// A texture object: {"image": "file.png", "encoding": "srgb" | "linear", "wrap": "repeat" |
// "clamp" | "black", "uv_scale": [su, sv], "uv_offset": [du, dv]} (pbrt-v4's lookup: v runs up the
// image) or {"checkerboard": [even, odd], "uv_scale", "uv_offset"} (colours in [0, 1]).
Result<int> read_texture(const Reader& r, const json& j, const std::string& ptr, JsonTextures* tx) {
  if (auto k = r.keys(j, ptr, {"image", "encoding", "wrap", "uv_scale", "uv_offset", "checkerboard"}); !k) return k.error();
  Texture t;
  float m[4] = {1, 1, 0, 0};
  for (int i = 0; i < 2; ++i) {
    const char* key = i == 0 ? "uv_scale" : "uv_offset";
    if (!j.contains(key)) continue;
    const json& v = j[key];
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number() || !std::isfinite(v[0].get<double>()) ||
        !std::isfinite(v[1].get<double>()) || std::fabs(v[0].get<double>()) > 1e30 || std::fabs(v[1].get<double>()) > 1e30)
      return r.fail(ptr + "/" + key, "expected an array of 2 finite numbers");
    m[2 * i] = v[0].get<float>();
    m[2 * i + 1] = v[1].get<float>();
  }
  t.uv = UvTransform{{m[0], 0.0f, m[2], 0.0f, m[1], m[3]}};
  if (j.contains("checkerboard") == j.contains("image")) return r.fail(ptr, "expected a texture with either \"image\" or \"checkerboard\"");
  if (j.contains("checkerboard")) {
    for (const char* key : {"encoding", "wrap"})
      if (j.contains(key)) return r.fail(ptr + "/" + key, std::string(key) + " is a key of an image texture, not of a checkerboard");
    const json& c = j["checkerboard"];
    if (!c.is_array() || c.size() != 2) return r.fail(ptr + "/checkerboard", "expected [even colour, odd colour]");
    const json pair = {{"0", c[0]}, {"1", c[1]}};
    int cells[2];
    for (int i = 0; i < 2; ++i) {
      PATHEX_TRY(v, r.vector3(pair, std::to_string(i), ptr + "/checkerboard", true, vec3(0.0f), true));
      tx->scene->textures.push_back(constant(v));
      cells[i] = static_cast<int>(tx->scene->textures.size()) - 1;
    }
    t.kind = TextureKind::kCheckerboard;
    t.a = cells[0];
    t.b = cells[1];
  } else {
    PATHEX_TRY(file, r.string(j, "image", ptr));
    ImageReadOptions o;
    o.max_file_bytes = tx->options.max_file_bytes;
    o.max_texels = tx->options.max_texels;
    o.texels_so_far = &tx->texels;
    if (j.contains("encoding")) {
      PATHEX_TRY(e, r.string(j, "encoding", ptr));
      if (e != "srgb" && e != "linear") return r.fail(ptr + "/encoding", "unknown encoding '" + e + "', expected srgb or linear");
      o.encoding = e == "srgb" ? ImageEncoding::kSrgb : ImageEncoding::kLinear;
    }
    if (j.contains("wrap")) {
      PATHEX_TRY(w, r.string(j, "wrap", ptr));
      if (w != "repeat" && w != "clamp" && w != "black") return r.fail(ptr + "/wrap", "unknown wrap '" + w + "', expected repeat, clamp or black");
      t.wrap = w == "repeat" ? TextureWrap::kRepeat : w == "clamp" ? TextureWrap::kClamp : TextureWrap::kBlack;
    }
    const std::string path = (std::filesystem::path(tx->base_dir) / file).string();
    const auto key = std::make_pair(path, static_cast<int>(o.encoding));
    auto it = tx->images.find(key);
    if (it == tx->images.end()) {
      Result<LinearImage> image = read_image(path, o);
      if (!image) {
        Error e = r.fail(ptr + "/image", "image '" + file + "' " + image.error().message);
        e.code = image.error().code;
        return e;
      }
      tx->scene->images.push_back(std::move(*image));
      it = tx->images.emplace(key, static_cast<int>(tx->scene->images.size()) - 1).first;
    }
    t.kind = TextureKind::kImage;
    t.image = it->second;
    t.flip_t = true;
  }
  tx->scene->textures.push_back(t);
  return static_cast<int>(tx->scene->textures.size()) - 1;
}

// A colour parameter that may be a texture object: its value, or for a texture `fallback` as the
// material's placeholder and a binding in tx->current.
Result<vec3> read_colour(const Reader& r, const json& j, const std::string& key, const std::string& ptr, vec3 fallback, TexturedParam param,
                         JsonTextures* tx) {
  if (!tx || !j.contains(key) || !j[key].is_object()) return r.vector3(j, key, ptr, false, fallback, true);
  PATHEX_TRY(index, read_texture(r, j[key], ptr + "/" + key, tx));
  tx->current.bindings.push_back(TextureBinding{tx->component, param, index, 1.0f});
  return fallback;
}

// `component`: inside a mixture, where only basic materials are allowed.
const std::string kBasicTypes = "diffuse, mirror, dielectric, glossy, conductor, thin_dielectric, diffuse_transmission, coateddiffuse";

Result<BasicMaterial> read_basic(const Reader& r, const json& j, const std::string& ptr, bool component, JsonTextures* tx) {
  PATHEX_TRY(type, r.string(j, "type", ptr));
  if (type == "diffuse") {
    if (auto k = r.keys(j, ptr, {"type", "albedo"}); !k) return k.error();
    PATHEX_TRY(albedo, read_colour(r, j, "albedo", ptr, vec3(0.8f), TexturedParam::kReflectance, tx));
    if (const float hi = max_component(albedo); hi > 1.0f) return r.fail(ptr + "/albedo", "expected values in [0, 1], found " + Reader::fmt(hi));
    return BasicMaterial{Diffuse{albedo}};
  }
  if (type == "mirror") {
    if (auto k = r.keys(j, ptr, {"type", "reflectance"}); !k) return k.error();
    PATHEX_TRY(refl, r.vector3(j, "reflectance", ptr, false, vec3(1.0f), true));
    if (const float hi = max_component(refl); hi > 1.0f) return r.fail(ptr + "/reflectance", "expected values in [0, 1], found " + Reader::fmt(hi));
    return BasicMaterial{Mirror{refl}};
  }
  if (type == "dielectric" || type == "thin_dielectric") {
    const bool thin = type == "thin_dielectric";
    if (auto k = thin ? r.keys(j, ptr, {"type", "ior", "tint"})
                      : r.keys(j, ptr, {"type", "ior", "tint", "roughness", "roughness_u", "roughness_v", "distribution"});
        !k)
      return k.error();
    PATHEX_TRY(ior, r.number(j, "ior", ptr, -1e30, 1e30, 1.5));
    if (!valid_ior(ior)) return r.fail(ptr + "/ior", std::string("expected an index of refraction ") + kValidIor + ", found " + Reader::fmt(ior));
    PATHEX_TRY(tint, r.vector3(j, "tint", ptr, false, vec3(1.0f), true));
    if (thin) return BasicMaterial{ThinDielectric{static_cast<float>(ior), tint}};
    PATHEX_TRY(alpha, read_alphas(r, j, ptr));
    PATHEX_TRY(dist, read_distribution(r, j, ptr));
    if (std::max(alpha.x, alpha.y) >= kSmoothAlpha)
      return BasicMaterial{RoughDielectric{static_cast<float>(ior), tint, alpha.x, alpha.y, dist}};
    return BasicMaterial{Dielectric{static_cast<float>(ior), tint}};
  }
  if (type == "conductor") {
    if (auto k = r.keys(j, ptr, {"type", "metal", "eta", "k", "roughness", "roughness_u", "roughness_v", "distribution"}); !k) return k.error();
    Conductor c;  // pbrt-v4's default: copper
    if (j.contains("metal")) {
      if (j.contains("eta") || j.contains("k")) return r.fail(ptr + "/metal", "expected either metal or eta and k, found both");
      PATHEX_TRY(name, r.string(j, "metal", ptr));
      const MetalSpectrum* metal = find_metal(name);
      if (!metal) return r.fail(ptr + "/metal", "unknown metal '" + name + "', expected one of " + kMetalNames);
      c.eta = vec3(metal->eta[0], metal->eta[1], metal->eta[2]);
      c.k = vec3(metal->k[0], metal->k[1], metal->k[2]);
    } else if (j.contains("eta") || j.contains("k")) {
      PATHEX_TRY(eta, r.vector3(j, "eta", ptr, true, vec3(1.0f), true));
      PATHEX_TRY(k, r.vector3(j, "k", ptr, true, vec3(0.0f), true));
      c.eta = eta;
      c.k = k;
    }
    PATHEX_TRY(alpha, read_alphas(r, j, ptr));
    PATHEX_TRY(dist, read_distribution(r, j, ptr));
    c.alpha_u = alpha.x;
    c.alpha_v = alpha.y;
    c.distribution = dist;
    return BasicMaterial{c};
  }
  if (type == "diffuse_transmission") {
    if (auto k = r.keys(j, ptr, {"type", "reflectance", "transmittance"}); !k) return k.error();
    PATHEX_TRY(refl, read_colour(r, j, "reflectance", ptr, vec3(0.25f), TexturedParam::kReflectance, tx));
    PATHEX_TRY(trans, read_colour(r, j, "transmittance", ptr, vec3(0.25f), TexturedParam::kTransmittance, tx));
    if (const float hi = max_component(refl + trans); hi > 1.0f)
      return r.fail(ptr + "/transmittance", "expected reflectance + transmittance within [0, 1], found " + Reader::fmt(hi));
    return BasicMaterial{DiffuseTransmission{refl, trans}};
  }
  if (type == "glossy") {
    if (auto k = r.keys(j, ptr, {"type", "reflectance", "roughness", "distribution"}); !k) return k.error();
    PATHEX_TRY(refl, r.vector3(j, "reflectance", ptr, false, vec3(0.8f), true));
    if (const float hi = max_component(refl); hi > 1.0f) return r.fail(ptr + "/reflectance", "expected values in [0, 1], found " + Reader::fmt(hi));
    PATHEX_TRY(rough, r.number(j, "roughness", ptr, 1e-4, 1.0, 0.2));
    PATHEX_TRY(dist, read_distribution(r, j, ptr));
    return BasicMaterial{Glossy{refl, static_cast<float>(rough), dist}};
  }
  if (type == "coateddiffuse") {  // pbrt-v4's layered coateddiffuse (scene/material.h CoatedDiffuse)
    if (auto k = r.keys(j, ptr, {"type", "reflectance", "roughness", "distribution", "eta", "thickness", "albedo", "g", "max_depth", "samples", "base"}); !k)
      return k.error();
    CoatedDiffuse c;
    if (j.contains("base")) {  // pbrt-v4's coatedconductor: a conductor under the coat, its eta and k divided by the coat's
      if (j.contains("reflectance")) return r.fail(ptr + "/base", "expected either reflectance (a Lambertian base) or base (a conductor), found both");
      const json& b = j["base"];
      if (!b.is_object() || !b.contains("type") || !b["type"].is_string() || b["type"].get<std::string>() != "conductor")
        return r.fail(ptr + "/base", "expected a conductor material object ({\"type\": \"conductor\", …})");
      PATHEX_TRY(metal, read_basic(r, b, ptr + "/base", /*component=*/true, nullptr));
      c.base = CoatBase::kConductor;
      c.conductor = std::get<Conductor>(metal);
    }
    PATHEX_TRY(refl, read_colour(r, j, "reflectance", ptr, vec3(0.5f), TexturedParam::kReflectance, tx));
    if (const float hi = max_component(refl); hi > 1.0f) return r.fail(ptr + "/reflectance", "expected values in [0, 1], found " + Reader::fmt(hi));
    PATHEX_TRY(albedo, r.vector3(j, "albedo", ptr, false, vec3(0.0f), true));
    if (const float hi = max_component(albedo); hi > 1.0f) return r.fail(ptr + "/albedo", "expected values in [0, 1], found " + Reader::fmt(hi));
    PATHEX_TRY(rough, r.number(j, "roughness", ptr, 0.0, 1.0, 0.0));
    PATHEX_TRY(eta, r.number(j, "eta", ptr, -1e30, 1e30, 1.5));
    if (!valid_ior(eta)) return r.fail(ptr + "/eta", std::string("expected an index of refraction ") + kValidIor + ", found " + Reader::fmt(eta));
    PATHEX_TRY(thickness, r.number(j, "thickness", ptr, 0.0, 1e6, 0.01));
    PATHEX_TRY(g, r.number(j, "g", ptr, -0.999, 0.999, 0.0));
    PATHEX_TRY(depth, r.integer(j, "max_depth", ptr, 1, kMaxCoatDepth, 10));
    PATHEX_TRY(samples, r.integer(j, "samples", ptr, 1, kMaxCoatSamples, 1));
    PATHEX_TRY(dist, read_distribution(r, j, ptr));
    c.distribution = dist;
    c.reflectance = refl;
    c.albedo = albedo;
    c.roughness = static_cast<float>(rough);
    c.eta = static_cast<float>(eta);
    c.thickness = static_cast<float>(thickness);
    c.g = static_cast<float>(g);
    c.max_depth = static_cast<int>(depth);
    c.samples = static_cast<int>(samples);
    if (c.base == CoatBase::kConductor) {
      c.conductor.eta /= c.eta;
      c.conductor.k /= c.eta;
      if (c.smooth() && c.conductor.smooth() && albedo != vec3(0.0f))
        return r.fail(ptr + "/albedo", "a smooth coat over a smooth conductor with a scattering layer (albedo > 0) is not supported: pathex "
                                       "samples it as one delta reflection, which needs albedo 0");
    }
    return BasicMaterial{c};
  }
  if (component)
    return r.fail(ptr + "/type", "material type '" + type + "' cannot be a mixture's component, expected " + kBasicTypes);
  return r.fail(ptr + "/type", "unknown material type '" + type + "', expected " + kBasicTypes + " or mixture");
}

Result<Material> read_material(const Reader& r, const json& j, const std::string& ptr, JsonTextures* tx) {
  if (!j.is_object()) return r.fail(ptr, "expected a material object, found " + Reader::kind(j));
  PATHEX_TRY(type, r.string(j, "type", ptr));
  if (type != "mixture") {
    PATHEX_TRY(basic, read_basic(r, j, ptr, /*component=*/false, tx));
    return std::visit([](const auto& b) { return Material{b}; }, basic);
  }
  if (auto k = r.keys(j, ptr, {"type", "components"}); !k) return k.error();
  if (!j.contains("components") || !j["components"].is_array() || j["components"].empty())
    return r.fail(ptr + "/components", "expected a non-empty array of {weight, material}");
  Mixture mix;
  double total = 0;
  for (std::size_t i = 0; i < j["components"].size(); ++i) {
    const std::string cp = ptr + "/components/" + std::to_string(i);
    const json& c = j["components"][i];
    if (auto k = r.keys(c, cp, {"weight", "material"}); !k) return k.error();
    PATHEX_TRY(weight, r.number(c, "weight", cp, 0.0, 1.0));
    if (!c.contains("material")) return r.fail(cp + "/material", "missing material, expected a basic material object");
    if (!c["material"].is_object()) return r.fail(cp + "/material", "expected a basic material object");
    tx->component = static_cast<int>(i);
    PATHEX_TRY(basic, read_basic(r, c["material"], cp + "/material", /*component=*/true, tx));
    mix.components.push_back({static_cast<float>(weight), basic});
    total += weight;
  }
  if (total > 1.0 + 1e-6) return r.fail(ptr + "/components", "the weights sum to " + Reader::fmt(total) + ", expected at most 1");
  return Material{mix};
}

// A transform: {"translate": [..], "rotate": {"axis": [..], "degrees": a}, "scale": s or [..]}.
Result<glm::mat4> read_transform(const Reader& r, const json& j, const std::string& ptr, bool* uniform, float* scale) {
  if (auto k = r.keys(j, ptr, {"translate", "rotate", "scale"}); !k) return k.error();
  glm::mat4 m(1.0f);
  *uniform = true;
  *scale = 1.0f;
  PATHEX_TRY(t, r.vector3(j, "translate", ptr, false));
  m = glm::translate(m, t);
  if (j.contains("rotate")) {
    const std::string rp = ptr + "/rotate";
    if (auto k = r.keys(j["rotate"], rp, {"axis", "degrees"}); !k) return k.error();
    PATHEX_TRY(axis, r.vector3(j["rotate"], "axis", rp, true, vec3(0.0f), false, true));
    PATHEX_TRY(deg, r.number(j["rotate"], "degrees", rp, -3600, 3600));
    m = glm::rotate(m, glm::radians(static_cast<float>(deg)), glm::normalize(axis));
  }
  if (j.contains("scale")) {
    const json& s = j["scale"];
    if (s.is_number()) {
      PATHEX_TRY(sc, r.number(j, "scale", ptr, 1e-12, 1e12));
      *scale = static_cast<float>(sc);
      m = glm::scale(m, vec3(*scale));
    } else {
      PATHEX_TRY(sv, r.vector3(j, "scale", ptr, true));
      if (sv.x <= 0 || sv.y <= 0 || sv.z <= 0) return r.fail(ptr + "/scale", "expected positive scale factors");
      *uniform = sv.x == sv.y && sv.y == sv.z;
      *scale = sv.x;
      m = glm::scale(m, sv);
    }
  }
  return m;
}


// OBJ meshes. tinyobjloader does the loading, but it only warns about out-of-range indices and
// reads a malformed number as 0, so a first pass over the text checks every `v` and `f` line and
// names the offending line and column: "mesh.obj:LINE:COLUMN: what was expected".
Error obj_error(const std::string& path, int line, int column, std::string message) {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = path + ":" + std::to_string(line) + ":" + std::to_string(column);
  return e;
}

// Parses the whole of `s` as a number; false for trailing junk.
bool parse_double(std::string_view s, double* out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const char* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, *out);
  return ec == std::errc() && p == end;
}
bool parse_long(std::string_view s, long long* out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const char* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, *out);
  return ec == std::errc() && p == end;
}

// Splits a line into whitespace-separated words (no allocation beyond the vector).
void split_words(std::string_view line, std::vector<std::string_view>* words) {
  words->clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) words->push_back(line.substr(i, j - i));
    i = j;
  }
}

// One face corner "v", "v/vt", "v//vn" or "v/vt/vn": each index 1..count, or negative (relative).
// Any other form ("1/", "2//", "3///") is refused here, so that the scan alone decides whether a
// mesh is valid: `query --scene` reads only this scan, `trace` tinyobjloader after it, and both
// must give one verdict.
std::optional<std::string> check_corner(std::string_view item, const long long counts[3]) {
  static const char* const kWhat[3] = {"vertex", "texture coordinate", "normal"};
  std::string_view fields[3];
  std::size_t n = 0;
  for (std::string_view rest = item;; ++n) {
    const std::size_t slash = rest.find('/');
    if (n == 3) return "bad face corner '" + excerpt(item) + "', expected v, v/vt, v//vn or v/vt/vn";
    fields[n] = rest.substr(0, slash);
    if (slash == std::string_view::npos) {
      ++n;
      break;
    }
    rest = rest.substr(slash + 1);
  }
  if (fields[n - 1].empty() || (n == 2 && fields[1].empty()))
    return "bad face corner '" + excerpt(item) + "', expected v, v/vt, v//vn or v/vt/vn";
  for (std::size_t part = 0; part < n; ++part) {
    const std::string_view field = fields[part];
    if (field.empty() && part == 1) continue;  // "v//vn"
    long long idx = 0;
    if (!parse_long(field, &idx))
      return "bad face corner '" + excerpt(field) + "', expected a " + kWhat[part] + " number";
    const long long resolved = idx < 0 ? counts[part] + idx + 1 : idx;
    if (idx == 0 || resolved < 1 || resolved > counts[part])
      return std::string("face ") + kWhat[part] + " index " + std::to_string(idx) + " is out of range, expected " +
             (counts[part] == 0 ? std::string("none: no ") + kWhat[part] + " is defined above this line"
                                : "1.." + std::to_string(counts[part]) + " (or a negative relative index)");
  }
  return std::nullopt;
}

// Checks every `v` and `f` line, keeps the vertex positions and counts the faces. `elements`: the
// vertices and triangles of the scene's meshes before this one, on entry; with this one's, on return.
std::optional<Error> scan_obj(const std::string& path, std::string_view text, std::vector<vec3>* positions,
                              std::size_t* faces, std::size_t* elements, const SceneLoadOptions& options) {
  long long counts[3] = {0, 0, 0};  // v, vt, vn defined so far
  std::vector<std::string_view> words;
  int line_no = 0;
  std::size_t pos = 0;
  *faces = 0;
  while (pos < text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) eol = text.size();
    std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    split_words(line, &words);
    if (words.empty()) continue;
    auto column = [&](std::size_t i) { return static_cast<int>(words[i].data() - line.data()) + 1; };
    const std::string_view tag = words[0];
    if (tag == "v") {
      if (words.size() < 4)
        return obj_error(path, line_no, column(0), "a vertex needs 3 coordinates, found " + std::to_string(words.size() - 1));
      vec3 p;
      for (std::size_t i = 1; i < 4; ++i) {
        double x = 0;
        if (!parse_double(words[i], &x))
          return obj_error(path, line_no, column(i), "bad vertex coordinate '" + excerpt(words[i]) + "', expected a number");
        if (!std::isfinite(x) || std::fabs(x) > 1e30)
          return obj_error(path, line_no, column(i), "vertex coordinate " + excerpt(words[i]) + " is not finite (or beyond 1e30)");
        p[static_cast<int>(i - 1)] = static_cast<float>(x);
      }
      if (auto e = check_mesh_elements(++*elements, options, path + ":" + std::to_string(line_no) + ":" + std::to_string(column(0))))
        return e;
      positions->push_back(p);
      ++counts[0];
    } else if (tag == "vt") {
      ++counts[1];
    } else if (tag == "vn") {
      ++counts[2];
    } else if (tag == "f") {
      if (words.size() < 4)
        return obj_error(path, line_no, column(0), "a face needs at least 3 vertices, found " + std::to_string(words.size() - 1));
      if (words.size() - 1 > kMaxFaceCorners)
        return obj_error(path, line_no, column(0), "a face of " + std::to_string(words.size() - 1) + " corners exceeds the limit of " +
                                            std::to_string(kMaxFaceCorners) + " (split or triangulate it in the modeller)");
      for (std::size_t i = 1; i < words.size(); ++i)
        if (std::optional<std::string> m = check_corner(words[i], counts)) return obj_error(path, line_no, column(i), *m);
      *elements += words.size() - 3;  // its triangles
      if (auto e = check_mesh_elements(*elements, options, path + ":" + std::to_string(line_no) + ":" + std::to_string(column(0))))
        return e;
      ++*faces;
    }
  }
  return std::nullopt;
}

// The OBJ at `path`: checked and scanned for its vertices and faces, then (if asked) triangulated.
Result<MeshShape> read_obj(const std::string& path, const SceneLoadOptions& options, std::size_t* faces, std::size_t* elements) {
  MeshShape mesh;
  mesh.file = path;
  {  // the text is released before tinyobjloader reads the file again, to keep peak memory low
    Result<std::string> text = read_input_file(path, options.max_file_bytes);
    if (!text) {
      if (text.error().code == ErrorCode::kLimit) return text.error();
      Error e = make_error(ErrorCode::kBadFile, "cannot open the mesh");
      e.where = excerpt(path, kMaxPathBytes);
      return e;
    }
    if (std::optional<Error> e = scan_obj(path, *text, &mesh.positions, faces, elements, options)) return *e;
  }
  if (!options.triangles) return mesh;  // the positions alone: bounds and types, no triangulation
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    Error e = make_error(ErrorCode::kBadFile, "cannot read the mesh: " + reader.Error());
    e.where = path;
    return e;
  }
  const auto& v = reader.GetAttrib().vertices;
  mesh.positions.clear();
  mesh.positions.reserve(v.size() / 3);
  for (std::size_t i = 0; i + 2 < v.size(); i += 3) mesh.positions.emplace_back(v[i], v[i + 1], v[i + 2]);
  for (const auto& shape : reader.GetShapes())
    for (std::size_t i = 0; i + 2 < shape.mesh.indices.size(); i += 3)
      mesh.triangles.emplace_back(static_cast<unsigned>(shape.mesh.indices[i].vertex_index),
                                  static_cast<unsigned>(shape.mesh.indices[i + 1].vertex_index),
                                  static_cast<unsigned>(shape.mesh.indices[i + 2].vertex_index));
  // check_obj and tinyobjloader split some bytes differently (a NUL, a lone carriage return): a
  // face tinyobjloader kept may then name a vertex it did not read (found by fuzz/obj_fuzz.cpp).
  for (const glm::uvec3& t : mesh.triangles)
    if (std::max(t.x, std::max(t.y, t.z)) >= mesh.positions.size()) {
      Error e = make_error(ErrorCode::kBadFile, "a face refers to a vertex that was not read; expected plain text lines "
                                                "(no NUL bytes or lone carriage returns)");
      e.where = excerpt(path, kMaxPathBytes);
      return e;
    }
  // Texture coordinates (`vt`, scene/texture.h): an OBJ corner names its position and its uv
  // separately, so the vertices are split per (position, uv) pair, when every corner has a uv
  // (else none is kept). The split vertices count towards --max-mesh-elements.
  const auto& tc = reader.GetAttrib().texcoords;
  bool every = !tc.empty();
  for (const auto& shape : reader.GetShapes())
    for (const auto& idx : shape.mesh.indices)
      every = every && idx.texcoord_index >= 0 && 2 * static_cast<std::size_t>(idx.texcoord_index) + 1 < tc.size();
  if (every) {
    std::map<std::pair<int, int>, unsigned> split;
    std::vector<vec3> positions;
    std::vector<glm::vec2> uvs;
    std::vector<glm::uvec3> triangles;
    for (const auto& shape : reader.GetShapes())
      for (std::size_t i = 0; i + 2 < shape.mesh.indices.size(); i += 3) {
        unsigned corner[3];
        for (std::size_t k = 0; k < 3; ++k) {
          const tinyobj::index_t& idx = shape.mesh.indices[i + k];
          const auto [it, fresh] = split.emplace(std::make_pair(idx.vertex_index, idx.texcoord_index), static_cast<unsigned>(positions.size()));
          if (fresh) {
            positions.push_back(mesh.positions[static_cast<std::size_t>(idx.vertex_index)]);
            const std::size_t t = 2 * static_cast<std::size_t>(idx.texcoord_index);
            uvs.emplace_back(tc[t], tc[t + 1]);
          }
          corner[k] = it->second;
        }
        triangles.emplace_back(corner[0], corner[1], corner[2]);
      }
    if (positions.size() > mesh.positions.size()) {
      *elements += positions.size() - mesh.positions.size();
      if (auto e = check_mesh_elements(*elements, options, excerpt(path, kMaxPathBytes))) return *e;
    }
    mesh.positions = std::move(positions);
    mesh.uvs = std::move(uvs);
    mesh.triangles = std::move(triangles);
  }
  return mesh;
}

// A JSON scene's "mesh": an OBJ file, or a PLY file when its name ends in .ply (read as the
// importers read PLY meshes: its per-vertex normals, if any, shade it; an OBJ's are not read). `elements`: as scan_obj.
Result<MeshShape> load_obj(const Reader& r, const std::string& ptr, const std::string& base_dir, const std::string& file,
                           const SceneLoadOptions& options, std::size_t* elements) {
  const std::string path = (std::filesystem::path(base_dir) / file).string();
  if (!std::ifstream(path, std::ios::binary)) return r.fail(ptr + "/file", "cannot open the mesh '" + excerpt(path, kMaxPathBytes) + "'");
  std::string lower = file;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  auto ends_with = [&](std::string_view tail) { return lower.size() >= tail.size() && lower.compare(lower.size() - tail.size(), tail.size(), tail) == 0; };
  if (ends_with(".ply") || ends_with(".ply.gz")) {
    Result<MeshShape> ply = import::load_ply_mesh(path, import::Location{r.file() + ":" + ptr + "/file"}, options);
    if (!ply) return ply.error();
    *elements += ply->positions.size() + ply->triangles.size();
    if (auto e = check_mesh_elements(*elements, options, r.file() + ":" + ptr + "/file")) return *e;
    ply->file = file;
    return ply;
  }
  std::size_t faces = 0;
  Result<MeshShape> mesh = read_obj(path, options, &faces, elements);
  if (!mesh) return mesh.error();
  if (faces == 0 || (options.triangles && mesh->triangles.empty()))
    return r.fail(ptr + "/file", "the mesh '" + path + "' has no faces, expected at least one 'f' line");
  mesh->file = file;
  return mesh;
}

}  // namespace

Result<MeshShape> load_obj_mesh(const std::string& path, const SceneLoadOptions& options, std::size_t* mesh_elements) {
  std::size_t faces = 0, none = 0;
  return read_obj(path, options, &faces, mesh_elements != nullptr ? mesh_elements : &none);
}

std::optional<Error> check_mesh_elements(std::size_t elements, const SceneLoadOptions& options, const std::string& where) {
  if (elements <= options.max_mesh_elements) return std::nullopt;
  Error e = make_error(ErrorCode::kLimit, limit_message("the scene's mesh size", options.max_mesh_elements, "vertices and triangles",
                                                        "--max-mesh-elements"));
  e.where = where;
  return e;
}

SceneLoadOptions scene_load_options(const Limits& limits, bool triangles) {
  SceneLoadOptions o;
  o.max_file_bytes = limits.max_file_bytes;
  o.triangles = triangles;
  o.max_scene_bytes = limits.max_scene_bytes;
  o.max_scene_depth = limits.max_scene_depth;
  o.max_material_nodes = limits.max_material_nodes;
  o.max_mesh_elements = limits.max_mesh_elements;
  o.max_texels = limits.max_texels;
  return o;
}

namespace {

// --- "the camera sees no geometry" ---
// Defined exactly: no shape's axis-aligned bounding box meets the camera's viewing region, which
// is the field-of-view pyramid of a pinhole; for a thin lens the pyramid widened by the aperture
// (a superset of every lens ray: slopes tan + aperture / focus distance, apex moved behind the
// lens so the pyramid contains the lens disk); for an orthographic camera the half-infinite prism
// over its film; for a spot meter its one ray. Each region is a convex set (base points plus a
// cone of directions), so the separating-axis test below decides the question exactly; it errs
// only towards "sees", so a scene is never refused for a geometry it does see.

float max_abs(vec3 p) { return std::max(std::fabs(p.x), std::max(std::fabs(p.y), std::fabs(p.z))); }

struct Box {
  vec3 lo{std::numeric_limits<float>::max()}, hi{-std::numeric_limits<float>::max()};
  void add(vec3 p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
};

Box shape_bounds(const Shape& s) {
  Box b;
  std::visit(
      [&](const auto& g) {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, MeshShape>) {
          for (const vec3& p : g.positions) b.add(p);
        } else if constexpr (std::is_same_v<T, SphereShape>) {
          b.add(g.center - vec3(g.radius));
          b.add(g.center + vec3(g.radius));
        } else if constexpr (std::is_same_v<T, QuadShape>) {
          b.add(g.corner);
          b.add(g.corner + g.edge1);
          b.add(g.corner + g.edge2);
          b.add(g.corner + g.edge1 + g.edge2);
        } else {  // a disk's extent along axis i is radius * sqrt(1 - n_i^2)
          const vec3 half = g.radius * glm::sqrt(glm::max(vec3(0.0f), vec3(1.0f) - g.normal * g.normal));
          b.add(g.center - half);
          b.add(g.center + half);
        }
      },
      s.geometry);
  return b;
}

// base points + the cone of non-negative combinations of `rays`; `edges` are its edge directions.
struct ViewRegion {
  std::vector<vec3> base, rays, edges;
};

ViewRegion view_region(const Camera& c) {
  const vec3 fwd = glm::normalize(c.look_at - c.position);
  const vec3 right = glm::normalize(glm::cross(fwd, c.up));
  const vec3 up = glm::cross(right, fwd);
  ViewRegion v;
  const float ty = std::tan(glm::radians(c.fov_degrees) * 0.5f);
  const float tx = ty * static_cast<float>(c.width) / static_cast<float>(c.height);
  auto pyramid = [&](vec3 apex, float sx, float sy) {
    v.base = {apex};
    for (float a : {-1.0f, 1.0f})
      for (float b : {-1.0f, 1.0f}) v.rays.push_back(fwd + a * sx * right + b * sy * up);
    v.edges = v.rays;
  };
  switch (c.type) {
    case SensorType::kPinhole: pyramid(c.position, tx, ty); break;
    case SensorType::kLens: {
      const float widen = c.aperture_radius / c.focus_distance;
      const float sx = tx + widen, sy = ty + widen;
      pyramid(c.position - fwd * (c.aperture_radius / std::min(sx, sy)), sx, sy);
      break;
    }
    case SensorType::kOrthographic:
      for (float a : {-0.5f, 0.5f})
        for (float b : {-0.5f, 0.5f}) v.base.push_back(c.position + a * c.film_width * right + b * c.film_height * up);
      v.rays = {fwd};
      v.edges = {fwd, right, up};
      break;
    case SensorType::kSpotmeter:
      v.base = {c.position};
      v.rays = {fwd};
      v.edges = {fwd};
      break;
  }
  return v;
}

// Separating-axis test between a convex view region and a box: candidate axes are the box's face
// normals, the region's face normals (crosses of its edges) and crosses of an edge of each.
bool region_meets_box(const ViewRegion& v, const Box& b) {
  std::vector<vec3> axes = {vec3(1, 0, 0), vec3(0, 1, 0), vec3(0, 0, 1)};
  for (std::size_t i = 0; i < v.edges.size(); ++i) {
    for (std::size_t j = i + 1; j < v.edges.size(); ++j) axes.push_back(glm::cross(v.edges[i], v.edges[j]));
    for (int k = 0; k < 3; ++k) axes.push_back(glm::cross(v.edges[i], axes[static_cast<std::size_t>(k)]));
  }
  const vec3 centre = 0.5f * (b.lo + b.hi), half = 0.5f * (b.hi - b.lo);
  for (vec3 n : axes) {
    const float len = glm::length(n);
    if (!(len > 1e-12f)) continue;
    n /= len;
    const float bc = glm::dot(centre, n), br = glm::dot(half, glm::abs(n));
    float lo = std::numeric_limits<float>::max(), hi = -lo, scale = std::fabs(bc) + br;
    for (const vec3& p : v.base) {
      lo = std::min(lo, glm::dot(p, n));
      hi = std::max(hi, glm::dot(p, n));
      scale = std::max(scale, max_abs(p));
    }
    const float slack = 1e-5f * scale;  // rounding only ever counts as overlap
    // A ray along +n makes the region's interval unbounded above, one along -n below; a ray
    // perpendicular to n (the region's own face normals; |cos| below rounding) does neither.
    bool up = false, down = false;
    for (const vec3& r : v.rays) {
      const float dr = glm::dot(glm::normalize(r), n);
      up = up || dr > 1e-6f;
      down = down || dr < -1e-6f;
    }
    if (!up && hi + slack < bc - br) return false;
    if (!down && lo - slack > bc + br) return false;
  }
  return true;
}

// --- the scene-level rules every loader checks (check_scene_rules) ---
constexpr const char* kNoLight = "the scene has no light: expected an entry in /lights or a shape with an emission";
constexpr const char* kSeesNothing = "the camera sees no geometry: no shape's bounding box meets its field of view";

bool has_light(const Scene& scene) {
  bool any = !scene.lights.empty();
  for (const Shape& s : scene.shapes) any = any || s.emissive();
  return any;
}

bool camera_sees_geometry(const Scene& scene) {
  const ViewRegion view = view_region(scene.camera);
  for (const Shape& s : scene.shapes)
    if (s.group < 0 && region_meets_box(view, shape_bounds(s))) return true;
  for (const auto& [lo, hi] : instance_boxes(scene))
    if (region_meets_box(view, Box{lo, hi})) return true;
  return false;
}

}  // namespace

std::vector<std::pair<vec3, vec3>> instance_boxes(const Scene& scene) {
  std::vector<Box> group_box(scene.groups.size());
  for (const Shape& s : scene.shapes)
    if (s.group >= 0) {
      const Box sb = shape_bounds(s);
      group_box[static_cast<std::size_t>(s.group)].add(sb.lo);
      group_box[static_cast<std::size_t>(s.group)].add(sb.hi);
    }
  std::vector<std::pair<vec3, vec3>> out;
  for (const ShapeInstance& inst : scene.instances) {
    const Box& g = group_box[static_cast<std::size_t>(inst.group)];
    if (!(g.lo.x <= g.hi.x)) continue;  // an empty group draws nothing
    Box b;
    for (int c = 0; c < 8; ++c)
      b.add(import::apply_point(inst.to_world, vec3(c & 1 ? g.hi.x : g.lo.x, c & 2 ? g.hi.y : g.lo.y, c & 4 ? g.hi.z : g.lo.z)));
    out.emplace_back(b.lo, b.hi);
  }
  return out;
}

namespace {

Result<Camera> read_camera(const Reader& r, const json& j, const std::string& ptr) {
  if (!j.is_object()) return r.fail(ptr, "expected a camera object, found " + Reader::kind(j));
  Camera c;
  PATHEX_TRY(type, r.string(j, "type", ptr));
  if (type == "pinhole") {
    c.type = SensorType::kPinhole;
    if (auto k = r.keys(j, ptr, {"type", "position", "look_at", "up", "fov", "width", "height"}); !k) return k.error();
  } else if (type == "lens") {
    c.type = SensorType::kLens;
    if (auto k = r.keys(j, ptr, {"type", "position", "look_at", "up", "fov", "width", "height", "aperture_radius", "focus_distance"}); !k)
      return k.error();
  } else if (type == "orthographic") {
    c.type = SensorType::kOrthographic;
    if (auto k = r.keys(j, ptr, {"type", "position", "look_at", "up", "film_width", "film_height", "width", "height"}); !k)
      return k.error();
  } else if (type == "spotmeter") {
    c.type = SensorType::kSpotmeter;
    if (auto k = r.keys(j, ptr, {"type", "position", "look_at", "up"}); !k) return k.error();
  } else {
    return r.fail(ptr + "/type", "unknown camera type '" + type + "', expected pinhole, lens, orthographic or spotmeter");
  }
  PATHEX_TRY(pos, r.vector3(j, "position", ptr, true));
  PATHEX_TRY(look, r.vector3(j, "look_at", ptr, true));
  PATHEX_TRY(up, r.vector3(j, "up", ptr, false, vec3(0.0f, 1.0f, 0.0f), false, true));
  c.position = pos;
  c.look_at = look;
  c.up = up;
  const vec3 fwd = look - pos;
  if (glm::dot(fwd, fwd) == 0.0f) return r.fail(ptr + "/look_at", "look_at must differ from position");
  if (glm::length(glm::cross(glm::normalize(fwd), glm::normalize(up))) < 1e-6f)
    return r.fail(ptr + "/up", "up must not be parallel to the viewing direction");
  if (c.type == SensorType::kPinhole || c.type == SensorType::kLens) {
    PATHEX_TRY(fov, r.number(j, "fov", ptr, 1e-3, 179.0, 45.0));
    c.fov_degrees = static_cast<float>(fov);
  }
  if (c.type == SensorType::kLens) {
    PATHEX_TRY(ar, r.number(j, "aperture_radius", ptr, 1e-9, 1e9));
    PATHEX_TRY(fd, r.number(j, "focus_distance", ptr, 1e-9, 1e12));
    c.aperture_radius = static_cast<float>(ar);
    c.focus_distance = static_cast<float>(fd);
  }
  if (c.type == SensorType::kOrthographic) {
    PATHEX_TRY(fw, r.number(j, "film_width", ptr, 1e-12, 1e12));
    PATHEX_TRY(fh, r.number(j, "film_height", ptr, 1e-12, 1e12));
    c.film_width = static_cast<float>(fw);
    c.film_height = static_cast<float>(fh);
  }
  if (c.type == SensorType::kSpotmeter) {
    c.width = c.height = 1;
  } else {
    PATHEX_TRY(w, r.integer(j, "width", ptr, 1, 16384, 64));
    PATHEX_TRY(h, r.integer(j, "height", ptr, 1, 16384, 64));
    c.width = static_cast<int>(w);
    c.height = static_cast<int>(h);
  }
  return c;
}

Result<Light> read_light(const Reader& r, const json& j, const std::string& ptr) {
  PATHEX_TRY(type, r.string(j, "type", ptr));
  if (type == "point") {
    if (auto k = r.keys(j, ptr, {"type", "position", "intensity"}); !k) return k.error();
    PATHEX_TRY(p, r.vector3(j, "position", ptr, true));
    PATHEX_TRY(i, r.light_value(j, "intensity", ptr, true));
    return Light{PointLight{p, i}};
  }
  if (type == "spot") {
    if (auto k = r.keys(j, ptr, {"type", "position", "direction", "intensity", "cone", "falloff_start", "falloff"}); !k) return k.error();
    PATHEX_TRY(p, r.vector3(j, "position", ptr, true));
    PATHEX_TRY(d, r.vector3(j, "direction", ptr, true, vec3(0.0f), false, true));
    PATHEX_TRY(i, r.light_value(j, "intensity", ptr, true));
    PATHEX_TRY(cone, r.number(j, "cone", ptr, 1e-3, 180.0, 30.0));
    PATHEX_TRY(start, r.number(j, "falloff_start", ptr, 0.0, cone, cone));
    SpotLight spot{p, glm::normalize(d), i, static_cast<float>(cone), static_cast<float>(start)};
    if (j.contains("falloff")) {
      const json& f = j["falloff"];
      if (f == "smoothstep") spot.falloff = SpotFalloff::kSmoothstep;
      else if (f == "linear") spot.falloff = SpotFalloff::kLinear;
      else return r.fail(ptr + "/falloff", "expected \"smoothstep\" (in cos θ, as pbrt-v4) or \"linear\" (in θ, as Mitsuba 3)");
    }
    return Light{spot};
  }
  if (type == "distant") {
    if (auto k = r.keys(j, ptr, {"type", "direction", "irradiance", "aperture"}); !k) return k.error();
    PATHEX_TRY(d, r.vector3(j, "direction", ptr, true, vec3(0.0f), false, true));
    PATHEX_TRY(e, r.light_value(j, "irradiance", ptr, true));
    if (!j.contains("aperture")) return r.fail(ptr + "/aperture", "missing aperture, expected {corner, edge1, edge2}: the window the light enters through");
    const std::string ap = ptr + "/aperture";
    if (auto k = r.keys(j["aperture"], ap, {"corner", "edge1", "edge2"}); !k) return k.error();
    PATHEX_TRY(c, r.vector3(j["aperture"], "corner", ap, true));
    PATHEX_TRY(e1, r.vector3(j["aperture"], "edge1", ap, true, vec3(0.0f), false, true));
    PATHEX_TRY(e2, r.vector3(j["aperture"], "edge2", ap, true, vec3(0.0f), false, true));
    if (glm::length(glm::cross(e1, e2)) == 0.0f) return r.fail(ap, "the aperture's edges are parallel: its area is zero");
    if (std::fabs(glm::dot(glm::normalize(glm::cross(e1, e2)), glm::normalize(d))) < 1e-6f)
      return r.fail(ap, "the light's direction lies in the aperture's plane: no light passes through it");
    return Light{DistantLight{glm::normalize(d), e, c, e1, e2}};
  }
  if (type == "laser") {
    if (auto k = r.keys(j, ptr, {"type", "position", "direction", "power"}); !k) return k.error();
    PATHEX_TRY(p, r.vector3(j, "position", ptr, true));
    PATHEX_TRY(d, r.vector3(j, "direction", ptr, true, vec3(0.0f), false, true));
    PATHEX_TRY(pw, r.light_value(j, "power", ptr, true));
    return Light{LaserLight{p, glm::normalize(d), pw}};
  }
  return r.fail(ptr + "/type", "unknown light type '" + type + "', expected point, spot, distant, laser or environment (area lights are shapes with an emission)");
}

Result<Shape> read_shape(const Reader& r, const json& j, const std::string& ptr, const Scene& scene,
                         const std::string& base_dir, const SceneLoadOptions& options, std::size_t* mesh_elements) {
  if (!j.is_object()) return r.fail(ptr, "expected a shape object, found " + Reader::kind(j));
  PATHEX_TRY(type, r.string(j, "type", ptr));
  Shape s;
  s.pointer = ptr;
  const std::initializer_list<const char*> common = {"type", "material", "emission", "two_sided", "absorption", "transform"};
  auto allowed = [&](std::initializer_list<const char*> extra) {
    std::vector<const char*> all(common);
    all.insert(all.end(), extra);
    return all;
  };
  std::vector<const char*> keys;
  if (type == "sphere") keys = allowed({"center", "radius"});
  else if (type == "quad") keys = allowed({"corner", "edge1", "edge2"});
  else if (type == "disk") keys = allowed({"center", "normal", "radius"});
  else if (type == "mesh") keys = allowed({"file"});
  else return r.fail(ptr + "/type", "unknown shape type '" + type + "', expected sphere, quad, disk or mesh");
  for (const auto& [key, value] : j.items()) {
    bool ok = key == "description";
    for (const char* k : keys) ok = ok || key == k;
    if (!ok) {
      std::string list;
      for (const char* k : keys) list += std::string(list.empty() ? "" : ", ") + k;
      return r.fail(ptr + "/" + pointer_token(key), "unknown key '" + key + "', expected one of " + list);
    }
  }
  PATHEX_TRY(mat, r.string(j, "material", ptr));
  s.material = -1;
  for (std::size_t i = 0; i < scene.material_names.size(); ++i)
    if (scene.material_names[i] == mat) s.material = static_cast<int>(i);
  if (s.material < 0) return r.fail(ptr + "/material", "unknown material '" + mat + "', expected a name defined in /materials");
  PATHEX_TRY(em, r.light_value(j, "emission", ptr, false));
  s.emission = em;
  if (j.contains("two_sided")) {
    if (!j["two_sided"].is_boolean()) return r.fail(ptr + "/two_sided", "expected true or false");
    s.two_sided = j["two_sided"].get<bool>();
  }
  PATHEX_TRY(absorption, r.vector3(j, "absorption", ptr, false, vec3(0.0f), /*nonneg=*/true));
  s.absorption = absorption;  // σa of an absorbing interior (trace/media.h)
  glm::mat4 m(1.0f);
  bool uniform = true;
  float scale = 1.0f;
  if (j.contains("transform")) {
    PATHEX_TRY(t, read_transform(r, j["transform"], ptr + "/transform", &uniform, &scale));
    m = t;
  }
  if (type == "sphere") {
    PATHEX_TRY(c, r.vector3(j, "center", ptr, true));
    PATHEX_TRY(rad, r.number(j, "radius", ptr, 1e-12, 1e12));
    if (!uniform) return r.fail(ptr + "/transform/scale", "a sphere needs a uniform scale");
    s.geometry = SphereShape{import::apply_point(m, c), static_cast<float>(rad) * scale};
  } else if (type == "quad") {
    PATHEX_TRY(c, r.vector3(j, "corner", ptr, true));
    PATHEX_TRY(e1, r.vector3(j, "edge1", ptr, true, vec3(0.0f), false, true));
    PATHEX_TRY(e2, r.vector3(j, "edge2", ptr, true, vec3(0.0f), false, true));
    if (glm::length(glm::cross(e1, e2)) == 0.0f) return r.fail(ptr, "the quad's edges are parallel: its area is zero");
    s.geometry = QuadShape{import::apply_point(m, c), import::apply_vector(m, e1), import::apply_vector(m, e2)};
  } else if (type == "disk") {
    PATHEX_TRY(c, r.vector3(j, "center", ptr, true));
    PATHEX_TRY(n, r.vector3(j, "normal", ptr, true, vec3(0.0f), false, true));
    PATHEX_TRY(rad, r.number(j, "radius", ptr, 1e-12, 1e12));
    if (!uniform) return r.fail(ptr + "/transform/scale", "a disk needs a uniform scale");
    const vec3 wn = glm::normalize(vec3(glm::transpose(glm::inverse(m)) * glm::vec4(n, 0.0f)));
    s.geometry = DiskShape{import::apply_point(m, c), wn, static_cast<float>(rad) * scale};
  } else {
    PATHEX_TRY(file, r.string(j, "file", ptr));
    PATHEX_TRY(mesh, load_obj(r, ptr, base_dir, file, options, mesh_elements));
    if (auto e = import::place_mesh(&mesh, m, false, false, import::Location{r.file() + ":" + ptr + "/file"})) return *e;
    s.geometry = std::move(mesh);
  }
  return s;
}

// "reference": the closed form the scene declares (scene.h, ClosedFormReference). The class
// expressions are compiled where they are used (pathex converge), with their pointers.
Result<ClosedFormReference> read_reference(const Reader& r, const nlohmann::json& j, const std::string& ptr) {
  if (!j.is_object()) return r.fail(ptr, "expected {\"source\": …, \"classes\": [{\"name\", \"class\", \"luminance\"}, …]}");
  if (auto k = r.keys(j, ptr, {"source", "uniform", "classes"}); !k) return k.error();
  ClosedFormReference ref;
  PATHEX_TRY(source, r.string(j, "source", ptr));
  ref.source = source;
  if (j.contains("uniform")) {
    if (!j["uniform"].is_boolean()) return r.fail(ptr + "/uniform", "expected true or false");
    ref.uniform = j["uniform"].get<bool>();
  }
  if (!j.contains("classes") || !j["classes"].is_array() || j["classes"].empty())
    return r.fail(ptr + "/classes", "expected a non-empty array of {name, class, luminance}");
  for (std::size_t i = 0; i < j["classes"].size(); ++i) {
    const std::string cp = ptr + "/classes/" + std::to_string(i);
    const nlohmann::json& c = j["classes"][i];
    if (!c.is_object()) return r.fail(cp, "expected {name, class, luminance}");
    if (auto k = r.keys(c, cp, {"name", "class", "luminance"}); !k) return k.error();
    ReferenceClass rc;
    PATHEX_TRY(name, r.string(c, "name", cp));
    PATHEX_TRY(expr, r.string(c, "class", cp));
    PATHEX_TRY(lum, r.number(c, "luminance", cp, 0.0, 1e30));
    for (const ReferenceClass& before : ref.classes)
      if (before.name == name) return r.fail(cp + "/name", "the class name '" + name + "' is used twice");
    rc.name = name;
    rc.expr = expr;
    rc.luminance = lum;
    ref.classes.push_back(std::move(rc));
  }
  return ref;
}

}  // namespace

// The name of the environment box's material; the box is the shape with this material and the
// environment's radiance.
constexpr const char* kEnvironmentMaterial = "environment (absorbs)";

namespace {

// The box of the infinite lights (scene.h): its index among the shapes.
int add_environment_box(Scene* scene, glm::vec3 emission, const std::string& pointer);

}  // namespace

void add_uniform_environment(Scene* scene, glm::vec3 radiance, const std::string& pointer) {
  if (scene->environment_image) {  // an image light's box: the radiance joins every texel
    for (glm::vec3& t : scene->environment_image->texels) t += radiance;
    scene->environment = scene->environment.value_or(vec3(0.0f)) + radiance;
    return;
  }
  if (scene->environment) {  // a second infinite light: one box emitting the sum
    for (Shape& s : scene->shapes)
      if (scene->material_names[static_cast<std::size_t>(s.material)] == kEnvironmentMaterial && s.emission == *scene->environment)
        s.emission += radiance;
    *scene->environment += radiance;
    return;
  }
  add_environment_box(scene, radiance, pointer);
  scene->environment = radiance;
}

void add_image_environment(Scene* scene, EnvironmentImage image, const std::string& pointer) {
  if (scene->environment) {  // a uniform light's box becomes the image's, its radiance in every texel
    for (glm::vec3& t : image.texels) t += *scene->environment;
    for (std::size_t i = 0; i < scene->shapes.size(); ++i)
      if (scene->material_names[static_cast<std::size_t>(scene->shapes[i].material)] == kEnvironmentMaterial) image.shape = static_cast<int>(i);
  } else {
    image.shape = add_environment_box(scene, vec3(1.0f), pointer);
  }
  // The shape's emission only marks it as a light (the radiance is the image's); the image is its pointer.
  scene->shapes[static_cast<std::size_t>(image.shape)].emission = vec3(1.0f);
  scene->shapes[static_cast<std::size_t>(image.shape)].pointer = pointer;
  scene->environment_image = std::move(image);
}

namespace {

int add_environment_box(Scene* scene, glm::vec3 emission, const std::string& pointer) {
  // --- what the box must hold ---
  Box b;
  for (const Shape& s : scene->shapes) {
    if (s.group >= 0) continue;  // instances' members: where the instances put them, below
    const Box sb = shape_bounds(s);
    b.add(sb.lo);
    b.add(sb.hi);
  }
  for (const auto& [lo, hi] : instance_boxes(*scene)) {
    b.add(lo);
    b.add(hi);
  }
  const Camera& c = scene->camera;
  const float camera_reach = c.type == SensorType::kLens          ? c.aperture_radius
                             : c.type == SensorType::kOrthographic ? 0.5f * std::hypot(c.film_width, c.film_height)
                                                                   : 0.0f;
  b.add(c.position - vec3(camera_reach));
  b.add(c.position + vec3(camera_reach));
  for (const Light& l : scene->lights) {
    if (const auto* d = std::get_if<DistantLight>(&l)) {
      b.add(d->aperture_corner);
      b.add(d->aperture_corner + d->aperture_edge1);
      b.add(d->aperture_corner + d->aperture_edge2);
      b.add(d->aperture_corner + d->aperture_edge1 + d->aperture_edge2);
    } else {
      std::visit([&](const auto& x) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(x)>, DistantLight>) b.add(x.position);
      }, l);
    }
  }
  // A tenth of the diagonal, and never less than rounding at the coordinates' magnitude.
  const float pad = 0.1f * glm::length(b.hi - b.lo) + 1e-4f * std::max(max_abs(b.lo), max_abs(b.hi)) + 1e-6f;
  const vec3 lo = b.lo - vec3(pad), hi = b.hi + vec3(pad);
  // --- six faces of two triangles, each wound so that its normal (p1 − p0) × (p2 − p0) points in ---
  MeshShape box;
  for (int x = 0; x < 8; ++x) box.positions.push_back(vec3(x & 1 ? hi.x : lo.x, x & 2 ? hi.y : lo.y, x & 4 ? hi.z : lo.z));
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3, v = (a + 2) % 3;  // e_u × e_v = e_a
    for (int side = 0; side < 2; ++side) {       // side 0: the low face, whose inward normal is +e_a
      const unsigned base = side ? (1u << a) : 0u;
      const unsigned c00 = base, c10 = base | (1u << u), c11 = base | (1u << u) | (1u << v), c01 = base | (1u << v);
      if (side == 0) {
        box.triangles.push_back({c00, c10, c11});
        box.triangles.push_back({c00, c11, c01});
      } else {
        box.triangles.push_back({c00, c11, c10});
        box.triangles.push_back({c00, c01, c11});
      }
    }
  }
  scene->material_names.push_back(kEnvironmentMaterial);
  scene->materials.push_back(Material{Mixture{}});
  Shape s;
  s.geometry = std::move(box);
  s.material = static_cast<int>(scene->materials.size()) - 1;
  s.emission = emission;
  s.pointer = pointer;
  scene->shapes.push_back(std::move(s));
  return static_cast<int>(scene->shapes.size()) - 1;
}

}  // namespace

Result<Scene> load_scene_json(std::string_view text, const std::string& base_dir, const std::string& name,
                              const SceneLoadOptions& options) {
  const Reader r(name);
  PATHEX_TRY(doc, parse_json(text, name));
  if (auto k = r.keys(doc, "", {"camera", "materials", "groups", "shapes", "lights", "reference"}); !k) return k.error();
  Scene scene;
  scene.name = name;
  // --- materials ---
  if (!doc.contains("materials") || !doc["materials"].is_object() || doc["materials"].empty())
    return r.fail("/materials", "expected an object of named materials, e.g. {\"white\": {\"type\": \"diffuse\"}}");
  JsonTextures textures;
  textures.scene = &scene;
  textures.base_dir = base_dir;
  textures.options = options;
  for (const auto& [mname, mj] : doc["materials"].items()) {
    textures.current = {};
    textures.component = -1;
    PATHEX_TRY(m, read_material(r, mj, "/materials/" + pointer_token(mname), &textures));
    scene.material_names.push_back(mname);
    scene.materials.push_back(std::move(m));
    if (!textures.current.empty() || !scene.material_textures.empty()) scene.material_textures.resize(scene.materials.size());
    if (!textures.current.empty()) scene.material_textures.back() = std::move(textures.current);
  }
  // --- shapes ---
  if (!doc.contains("shapes") || !doc["shapes"].is_array()) return r.fail("/shapes", "expected an array of shapes");
  if (doc["shapes"].empty()) return r.fail("/shapes", "the scene is empty: expected at least one shape");
  std::size_t mesh_elements = 0;  // of all the meshes so far (--max-mesh-elements)
  // --- groups (instancing, scene.h ShapeGroup): {"name": [shape, …]}, members in the group's space ---
  if (doc.contains("groups")) {
    if (!doc["groups"].is_object()) return r.fail("/groups", "expected an object of named groups, e.g. {\"tree\": [shapes]}");
    for (const auto& [gname, gj] : doc["groups"].items()) {
      const std::string gp = "/groups/" + pointer_token(gname);
      if (!gj.is_array() || gj.empty()) return r.fail(gp, "expected a non-empty array of shapes");
      const int group = static_cast<int>(scene.groups.size());
      scene.groups.push_back({gname, gp});
      for (std::size_t i = 0; i < gj.size(); ++i) {
        const std::string sp = gp + "/" + std::to_string(i);
        if (gj[i].is_object() && gj[i].contains("type") && gj[i]["type"] == "instance")
          return r.fail(sp + "/type", "an instance inside a group is not supported: groups do not nest");
        PATHEX_TRY(s, read_shape(r, gj[i], sp, scene, base_dir, options, &mesh_elements));
        if (std::optional<std::string> why = import::make_group_member(&s, group)) return r.fail(sp, *why);
        scene.shapes.push_back(std::move(s));
      }
    }
  }
  for (std::size_t i = 0; i < doc["shapes"].size(); ++i) {
    const std::string sp = "/shapes/" + std::to_string(i);
    const json& sj = doc["shapes"][i];
    if (sj.is_object() && sj.contains("type") && sj["type"] == "instance") {  // {"type": "instance", "group": name, "transform": …}
      if (auto k = r.keys(sj, sp, {"type", "group", "transform", "description"}); !k) return k.error();
      PATHEX_TRY(gname, r.string(sj, "group", sp));
      ShapeInstance inst;
      inst.group = -1;
      for (std::size_t g = 0; g < scene.groups.size(); ++g)
        if (scene.groups[g].name == gname) inst.group = static_cast<int>(g);
      if (inst.group < 0) return r.fail(sp + "/group", "unknown group '" + gname + "', expected a name defined in /groups");
      if (sj.contains("transform")) {
        bool uniform = true;
        float scale = 1.0f;
        PATHEX_TRY(t, read_transform(r, sj["transform"], sp + "/transform", &uniform, &scale));
        inst.to_world = t;
      }
      inst.pointer = sp;
      scene.instances.push_back(std::move(inst));
      continue;
    }
    PATHEX_TRY(s, read_shape(r, sj, sp, scene, base_dir, options, &mesh_elements));
    scene.shapes.push_back(std::move(s));
  }
  // --- lights ---
  std::vector<std::pair<vec3, std::string>> environments;  // uniform infinite lights
  std::optional<std::pair<EnvironmentImage, std::string>> environment_image;  // an image one
  if (doc.contains("lights")) {
    if (!doc["lights"].is_array()) return r.fail("/lights", "expected an array of lights");
    for (std::size_t i = 0; i < doc["lights"].size(); ++i) {
      const std::string ptr = "/lights/" + std::to_string(i);
      const json& lj = doc["lights"][i];
      if (!lj.is_object()) return r.fail(ptr, "expected a light object");
      if (lj.contains("type") && lj["type"] == "environment" && lj.contains("image")) {  // docs/lights.md
        if (auto k = r.keys(lj, ptr, {"type", "image", "mapping", "scale", "rotate", "sampling"}); !k) return k.error();
        if (environment_image) return r.fail(ptr, "a second image environment: a scene has at most one");
        PATHEX_TRY(file, r.string(lj, "image", ptr));
        bool equal_area = false;
        if (lj.contains("mapping")) {
          if (lj["mapping"] == "equal-area") equal_area = true;
          else if (lj["mapping"] != "latlong")
            return r.fail(ptr + "/mapping", "expected \"latlong\" (Mitsuba 3's envmap, +Y up) or \"equal-area\" (pbrt-v4's square)");
        }
        PATHEX_TRY(scale, r.vector3(lj, "scale", ptr, false, vec3(1.0f), /*nonneg=*/true));
        Result<EnvironmentImage> img = load_environment_image((std::filesystem::path(base_dir) / file).string(), file,
                                                              equal_area, scale, options, &textures.texels);  // one count with the textures'

        if (!img) {
          Error e = img.error();
          return r.fail(ptr + "/image", "the image '" + excerpt(file, kMaxPathBytes) + "': " + e.message);
        }
        if (lj.contains("rotate")) {  // {"axis": [x, y, z], "degrees": d}, as a shape's transform
          bool uniform = true;
          float sc = 1.0f;
          PATHEX_TRY(t, read_transform(r, json{{"rotate", lj["rotate"]}}, ptr, &uniform, &sc));
          img->to_world = glm::mat3(t);
        }
        if (lj.contains("sampling")) {
          if (lj["sampling"] == "uniform") img->uniform_sampling = true;
          else if (lj["sampling"] != "importance")
            return r.fail(ptr + "/sampling", "expected \"importance\" (by the image's values, the default) or \"uniform\"");
        }
        if (std::optional<std::string> bad = settle_environment_values(&*img)) return r.fail(ptr + "/image", *bad);
        environment_image.emplace(std::move(*img), ptr);
        continue;
      }
      if (lj.contains("type") && lj["type"] == "environment") {  // added once the camera is known
        if (auto k = r.keys(lj, ptr, {"type", "radiance"}); !k) return k.error();
        PATHEX_TRY(radiance, r.light_value(lj, "radiance", ptr, true));
        environments.emplace_back(radiance, ptr);
        continue;
      }
      PATHEX_TRY(l, read_light(r, lj, ptr));
      scene.lights.push_back(std::move(l));
    }
  }
  if (!has_light(scene) && environments.empty() && !environment_image) return r.fail("/lights", kNoLight);
  // --- camera ---
  if (!doc.contains("camera")) return r.fail("/camera", "missing camera, expected {type, position, look_at, …}");
  PATHEX_TRY(cam, read_camera(r, doc["camera"], "/camera"));
  scene.camera = cam;
  if (environment_image) add_image_environment(&scene, std::move(environment_image->first), environment_image->second);
  for (const auto& [radiance, ptr] : environments) add_uniform_environment(&scene, radiance, ptr);
  if (!camera_sees_geometry(scene)) return r.fail("/camera", kSeesNothing);
  if (doc.contains("reference")) {
    PATHEX_TRY(ref, read_reference(r, doc["reference"], "/reference"));
    scene.reference = std::move(ref);
  }
  return scene;
}

std::optional<SceneRuleViolation> check_scene_rules(const Scene& scene) {
  if (scene.shapes.empty()) return SceneRuleViolation{"/shapes", "the scene is empty: expected at least one shape"};
  if (!has_light(scene)) return SceneRuleViolation{"/lights", kNoLight};
  if (!camera_sees_geometry(scene)) return SceneRuleViolation{"/camera", kSeesNothing};
  return std::nullopt;
}

Result<Scene> load_scene_file(const std::string& path, const SceneLoadOptions& options) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".pbrt") return load_scene_pbrt(path, options);
  if (ext == ".xml") return load_scene_mitsuba(path, options);
  Result<std::string> text = read_input_file(path, options.max_file_bytes);
  if (!text) {
    if (text.error().code == ErrorCode::kLimit) return text.error();
    Error e = make_error(ErrorCode::kBadFile, "cannot open the scene file");
    e.where = path;
    return e;
  }
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return load_scene_json(*text, dir.empty() ? "." : dir, path, options);
}

SceneTypes scene_types(const Scene& scene) {
  SceneTypes t;
  t.sensor = scene.camera.type;
  for (const Light& l : scene.lights) {
    std::visit(
        [&](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, PointLight> || std::is_same_v<T, SpotLight>) t.lights.insert(LightType::kPoint);
          else if constexpr (std::is_same_v<T, DistantLight>) t.lights.insert(LightType::kDistant);
          else t.lights.insert(LightType::kLaser);
        },
        l);
  }
  std::vector<bool> instanced(scene.groups.size(), false);  // a group no instance places draws nothing
  for (const ShapeInstance& inst : scene.instances) instanced[static_cast<std::size_t>(inst.group)] = true;
  for (const Shape& s : scene.shapes) {
    if (s.group >= 0 && !instanced[static_cast<std::size_t>(s.group)]) continue;
    if (s.emissive()) t.lights.insert(LightType::kArea);
    t.interior = static_cast<LetterMask>(t.interior | letters_of(scene.materials[static_cast<std::size_t>(s.material)]));
  }
  return t;
}

std::string describe(const SceneTypes& t) {
  std::string s = "lights";
  for (LightType l : t.lights) s += " " + to_string(l);
  s += "; sensor " + to_string(t.sensor) + "; materials";
  if (t.interior & (1u << kD)) s += " D";
  if (t.interior & (1u << kS)) s += " S";
  return s;
}

}  // namespace pathex
