// Textures in the scene formats (docs/textures.md): pbrt-v4's Texture directive (imagemap,
// checkerboard, scale, mix, constant) and textured material parameters and alpha, Mitsuba 3's
// bitmap and checkerboard (nested or by id), blendbsdf weights and mask; each mapped with exact
// values, images read once per file and decoding; and what stays refused, located, with its
// exact message.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "optics/internal_reflectance.h"
#include "scene/scene.h"
#include "support/load_scene.h"
#include "support/scene_snippets.h"
#include "support/scratch_files.h"
#include "support/test_images.h"
#include "trace/bsdf_layered.h"
#include "trace/texture_eval.h"

namespace pathex {
namespace {

using glm::vec2;
using glm::vec3;
using test::relative;
using test::write;
using test::write_image;

using test::kPbrtHead;
using test::kXmlHead;

using test::load;

// A 2 x 1 PNG: a black texel and a white one (8-bit codes 0 and 255, the same in every decoding).
void write_black_white() { write_image<unsigned char>("bw.png", 2, 1, 3, {0, 0, 0, 255, 255, 255}); }

const MaterialTextures& textures_of(const Scene& s, std::size_t shape) {
  return s.material_textures.at(static_cast<std::size_t>(s.shapes.at(shape).material));
}

TEST(ImportTexturesPbrt, ImagemapCheckerboardScaleMixAndTheirBindings) {
  write_black_white();
  const Scene s = load(write("tex.pbrt", kPbrtHead +
                                             "Texture \"img\" \"spectrum\" \"imagemap\" \"string filename\" \"bw.png\" \"float uscale\" 2 "
                                             "\"float vscale\" 3 \"float udelta\" 0.25 \"float vdelta\" -1 \"string wrap\" \"clamp\" "
                                             "\"float scale\" 0.5 \"bool invert\" true \"string filter\" \"ewa\"\n"
                                             "Texture \"again\" \"spectrum\" \"imagemap\" \"string filename\" \"bw.png\"\n"
                                             "Texture \"lin\" \"spectrum\" \"imagemap\" \"string filename\" \"bw.png\" \"string encoding\" \"linear\"\n"
                                             "Texture \"checks\" \"spectrum\" \"checkerboard\" \"rgb tex1\" [1 0 0] \"texture tex2\" \"again\" "
                                             "\"float uscale\" 4 \"float vscale\" 4\n"
                                             "Texture \"amt\" \"float\" \"checkerboard\"\n"
                                             "Texture \"half\" \"spectrum\" \"scale\" \"texture tex\" \"checks\" \"float scale\" 0.5\n"
                                             "Material \"diffuse\" \"texture reflectance\" \"img\"\nShape \"sphere\"\n"
                                             "Material \"coateddiffuse\" \"texture reflectance\" \"half\"\nShape \"sphere\"\n"
                                             "Material \"diffusetransmission\" \"texture transmittance\" \"lin\" \"float scale\" 0.5\nShape \"sphere\"\n"
                                             "MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"texture reflectance\" \"checks\"\n"
                                             "MakeNamedMaterial \"b\" \"string type\" \"conductor\"\n"
                                             "Material \"mix\" \"string materials\" [\"a\" \"b\"] \"texture amount\" \"amt\"\nShape \"sphere\"\n"
                                             "Material \"diffuse\"\nShape \"sphere\"\n"));
  ASSERT_EQ(s.shapes.size(), 5u);
  ASSERT_EQ(s.images.size(), 2u);  // bw.png once as sRGB (twice named), once as linear
  const Texture& img = s.textures.at(static_cast<std::size_t>(textures_of(s, 0).bindings.at(0).texture));
  EXPECT_EQ(img.kind, TextureKind::kImage);
  EXPECT_EQ(img.wrap, TextureWrap::kClamp);
  EXPECT_TRUE(img.flip_t);
  EXPECT_TRUE(img.invert);
  EXPECT_FLOAT_EQ(img.scale, 0.5f);
  EXPECT_EQ(std::vector<float>(img.uv.m, img.uv.m + 6), (std::vector<float>{2, 0, 0.25f, 0, 3, -1}));
  // (u, v) = (0.25, 0.5): s = 0.75 (the white texel's centre), t = 1 − 0.5 = 0.5; ½ · 1 inverted is ½.
  EXPECT_EQ(eval_texture(s, textures_of(s, 0).bindings[0].texture, {0.25f, 0.5f}), vec3(0.5f));
  EXPECT_EQ(std::get<Diffuse>(s.materials[0]).albedo, vec3(0.5f));  // the placeholder: pbrt's default
  // The coated reflectance: ½ × checks; checks is red on even cells and the plain image on odd ones.
  const int half = textures_of(s, 1).bindings.at(0).texture;
  EXPECT_EQ(eval_texture(s, half, {0.1f, 0.1f}), vec3(0.5f, 0, 0));
  EXPECT_EQ(eval_texture(s, half, {0.375f, 0.1f}), vec3(0.125f));  // odd: the image at s = 0.375, ¾ black + ¼ white, × ½
  // Diffuse transmission: the binding keeps pbrt's scale.
  const TextureBinding& t = textures_of(s, 2).bindings.at(0);
  EXPECT_EQ(t.param, TexturedParam::kTransmittance);
  EXPECT_FLOAT_EQ(t.scale, 0.5f);
  // The mix: diffuse (checks) weighs 1 − amount, the conductor amount; amount is a float checkerboard (1, 0).
  const MaterialTextures& mt = textures_of(s, 3);
  EXPECT_GE(mt.amount, 0);
  EXPECT_EQ(mt.weight0, (std::vector<float>{1, 0}));
  EXPECT_EQ(mt.weight1, (std::vector<float>{0, 1}));
  ASSERT_EQ(mt.bindings.size(), 1u);
  EXPECT_EQ(mt.bindings[0].component, 0);
  Material at;
  textured_material(s, s.materials[static_cast<std::size_t>(s.shapes[3].material)], mt, {0.5f, 0.5f}, &at);  // even: amount 1
  EXPECT_FLOAT_EQ(std::get<Mixture>(at).components[0].weight, 0.0f);
  EXPECT_FLOAT_EQ(std::get<Mixture>(at).components[1].weight, 1.0f);
  EXPECT_EQ(letters_of(s.materials[static_cast<std::size_t>(s.shapes[3].material)]), static_cast<LetterMask>((1u << kD) | (1u << kS)));
  EXPECT_TRUE(textures_of(s, 4).empty());
}

TEST(ImportTexturesPbrt, AlphaValuesAndTextures) {
  write_black_white();
  const Scene s = load(write("alpha.pbrt", kPbrtHead +
                                               "Texture \"cut\" \"float\" \"imagemap\" \"string filename\" \"bw.png\"\n"
                                               "Shape \"sphere\" \"float alpha\" 0.25\nShape \"sphere\" \"texture alpha\" \"cut\"\n"
                                               "Shape \"sphere\" \"float alpha\" 1\nShape \"sphere\"\n"));
  ASSERT_EQ(s.shapes.size(), 4u);
  ASSERT_GE(s.shapes[0].alpha, 0);
  EXPECT_EQ(s.textures[static_cast<std::size_t>(s.shapes[0].alpha)].value, vec3(0.25f));
  EXPECT_FLOAT_EQ(shape_alpha(s, 1, {0.75f, 0.5f}), 1.0f);  // the white texel: opaque
  EXPECT_FLOAT_EQ(shape_alpha(s, 1, {0.25f, 0.5f}), 0.0f);  // the black one: cut out
  EXPECT_EQ(s.textures[static_cast<std::size_t>(s.shapes[1].alpha)].channel, FloatChannel::kPbrt);
  EXPECT_EQ(s.shapes[2].alpha, -1);  // alpha 1 is no cut-out
  EXPECT_EQ(s.shapes[3].alpha, -1);
}

TEST(ImportTexturesMitsuba, BitmapCheckerboardBlendWeightAndMask) {
  write_black_white();
  const std::string xml =
      kXmlHead +
      "<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><transform name=\"to_world\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>\n"
      "<texture type=\"bitmap\" id=\"shared\"><string name=\"filename\" value=\"bw.png\"/><boolean name=\"raw\" value=\"true\"/></texture>\n"
      "<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"bw.png\"/>"
      "<string name=\"wrap_mode\" value=\"clamp\"/><transform name=\"to_uv\"><scale x=\"2\" y=\"4\"/><translate x=\"0.5\"/></transform>"
      "</texture></bsdf></shape>\n"
      "<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"checkerboard\" name=\"reflectance\">"
      "<rgb name=\"color0\" value=\"1, 0, 0\"/></texture></bsdf></shape>\n"
      "<shape type=\"sphere\"><bsdf type=\"blendbsdf\"><ref name=\"weight\" id=\"shared\"/><bsdf type=\"diffuse\"/><bsdf type=\"conductor\"/>"
      "</bsdf></shape>\n"
      "<shape type=\"sphere\"><bsdf type=\"mask\"><ref name=\"opacity\" id=\"shared\"/><bsdf type=\"twosided\"><bsdf type=\"diffuse\">"
      "<ref name=\"reflectance\" id=\"shared\"/></bsdf></bsdf></bsdf></shape>\n"
      "</scene>\n";
  const Scene s = load(write("tex.xml", xml));
  ASSERT_EQ(s.shapes.size(), 4u);
  EXPECT_EQ(s.images.size(), 2u);  // sRGB and raw
  const Texture& bitmap = s.textures.at(static_cast<std::size_t>(textures_of(s, 0).bindings.at(0).texture));
  EXPECT_FALSE(bitmap.flip_t);
  EXPECT_EQ(bitmap.wrap, TextureWrap::kClamp);
  EXPECT_EQ(std::vector<float>(bitmap.uv.m, bitmap.uv.m + 6), (std::vector<float>{2, 0, 0.5f, 0, 4, 0}));
  // Mitsuba's checkerboard: color0 where the fractional parts of u and v are on the same side of ½.
  const int checks = textures_of(s, 1).bindings.at(0).texture;
  EXPECT_EQ(eval_texture(s, checks, {0.2f, 0.3f}), vec3(1, 0, 0));
  EXPECT_EQ(eval_texture(s, checks, {0.7f, 0.3f}), vec3(0.2f));
  EXPECT_EQ(eval_texture(s, checks, {0.7f, 0.8f}), vec3(1, 0, 0));
  // blendbsdf with a texture weight: the diffuse weighs 1 − w, the conductor w.
  const MaterialTextures& blend = textures_of(s, 2);
  EXPECT_EQ(blend.weight0, (std::vector<float>{1, 0}));
  EXPECT_EQ(blend.weight1, (std::vector<float>{0, 1}));
  EXPECT_EQ(s.textures[static_cast<std::size_t>(blend.amount)].channel, FloatChannel::kLuminance);
  // The mask: the shape's alpha, the shared bitmap read as a float (a texture node of its own).
  ASSERT_GE(s.shapes[3].alpha, 0);
  EXPECT_FLOAT_EQ(shape_alpha(s, 3, {0.25f, 0.5f}), 0.0f);
  EXPECT_FLOAT_EQ(shape_alpha(s, 3, {0.75f, 0.5f}), 1.0f);
  EXPECT_EQ(s.shapes[3].alpha, blend.amount);  // one node per texture id and float-ness
  EXPECT_EQ(textures_of(s, 3).bindings.size(), 1u);
}

// Issue 35: roughness textures (pbrt-v4 roughness / uroughness / vroughness on conductor,
// dielectric, coateddiffuse, remapped per hit), pbrt-v4's conductor reflectance texture, Mitsuba
// 3's alpha textures and specular_reflectance, and plastic's textured diffuse_reflectance. A
// textured roughness makes the material the rough kind (letter D), placeholder alpha 1.
TEST(ImportTexturesPbrt, RoughnessAndConductorReflectance) {
  write_black_white();
  const Scene s = load(write("rough.pbrt", kPbrtHead +
                                               "Texture \"r\" \"float\" \"imagemap\" \"string filename\" \"bw.png\"\n"
                                               "Texture \"c\" \"spectrum\" \"checkerboard\" \"rgb tex1\" [0.64 0.64 0.64] \"rgb tex2\" [0 0 0]\n"
                                               "Material \"conductor\" \"texture roughness\" \"r\" \"texture reflectance\" \"c\"\nShape \"sphere\"\n"
                                               "Material \"conductor\" \"texture uroughness\" \"r\" \"float vroughness\" 0.25 \"bool remaproughness\" false\n"
                                               "Shape \"sphere\"\n"
                                               "Material \"dielectric\" \"texture roughness\" \"r\"\nShape \"sphere\"\n"
                                               "Material \"coateddiffuse\" \"texture roughness\" \"r\"\nShape \"sphere\"\n"));
  ASSERT_EQ(s.shapes.size(), 4u);
  const auto material = [&](std::size_t shape) { return s.materials.at(static_cast<std::size_t>(s.shapes[shape].material)); };
  const LetterMask only_d = static_cast<LetterMask>(1u << kD);
  // The conductor: u and v from "roughness" (√, remapped), k from the reflectance texture.
  const MaterialTextures& t0 = textures_of(s, 0);
  ASSERT_EQ(t0.bindings.size(), 3u);
  EXPECT_EQ(t0.bindings[0].param, TexturedParam::kConductorReflectance);
  EXPECT_EQ(t0.bindings[1].param, TexturedParam::kAlphaU);
  EXPECT_EQ(t0.bindings[2].param, TexturedParam::kAlphaV);
  EXPECT_EQ(t0.bindings[1].map, TextureMap::kSqrt);
  EXPECT_EQ(t0.bindings[1].texture, t0.bindings[2].texture);
  EXPECT_EQ(std::get<Conductor>(material(0)).alpha_u, 1.0f);  // the placeholder: rough
  EXPECT_EQ(letters_of(material(0)), only_d);
  Material at;
  textured_material(s, material(0), t0, {0.75f, 0.5f}, &at);  // white texel: roughness 1; even cell: r = 0.64
  EXPECT_EQ(std::get<Conductor>(at).alpha_u, 1.0f);
  EXPECT_EQ(std::get<Conductor>(at).eta, vec3(1.0f));
  EXPECT_NEAR(std::get<Conductor>(at).k.y, 8.0 / 3.0, 1e-5);
  textured_material(s, material(0), t0, {0.25f, 0.5f}, &at);  // black texel: roughness 0, kept rough at 1e-3
  EXPECT_EQ(std::get<Conductor>(at).alpha_v, kSmoothAlpha);
  // uroughness a texture, vroughness 0.25 unmapped.
  const MaterialTextures& t1 = textures_of(s, 1);
  ASSERT_EQ(t1.bindings.size(), 1u);
  EXPECT_EQ(t1.bindings[0].map, TextureMap::kLinear);
  EXPECT_EQ(std::get<Conductor>(material(1)).alpha_v, 0.25f);
  // The dielectric is the rough one; the coat rough (D only).
  EXPECT_TRUE(std::holds_alternative<RoughDielectric>(material(2)));
  EXPECT_EQ(textures_of(s, 2).bindings.size(), 2u);
  EXPECT_EQ(std::get<CoatedDiffuse>(material(3)).roughness, 1.0f);
  EXPECT_EQ(letters_of(material(3)), only_d);
}

TEST(ImportTexturesMitsuba, AlphaSpecularReflectanceAndPlastic) {
  write_black_white();
  const auto tex = [&](const std::string& name) { return "<texture type=\"bitmap\" name=\"" + name + "\"><string name=\"filename\" value=\"bw.png\"/></texture>"; };
  const std::string xml =
      kXmlHead +
      "<sensor type=\"perspective\"><transform name=\"to_world\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>\n"
      "<shape type=\"sphere\"><bsdf type=\"roughconductor\">" + tex("alpha") + tex("specular_reflectance") + "</bsdf></shape>\n" +
      "<shape type=\"sphere\"><bsdf type=\"roughdielectric\"><float name=\"alpha_u\" value=\"0.3\"/>" + tex("alpha_v") + "</bsdf></shape>\n" +
      "<shape type=\"sphere\"><bsdf type=\"conductor\">" + tex("specular_reflectance") + "</bsdf></shape>\n" +
      "<shape type=\"sphere\"><bsdf type=\"plastic\">" + tex("diffuse_reflectance") + "</bsdf></shape>\n" +
      "<shape type=\"sphere\"><bsdf type=\"roughplastic\"><boolean name=\"nonlinear\" value=\"true\"/>" + tex("diffuse_reflectance") +
      "</bsdf></shape>\n</scene>\n";
  const Scene s = load(write("rough.xml", xml));
  ASSERT_EQ(s.shapes.size(), 5u);
  const auto material = [&](std::size_t shape) { return s.materials.at(static_cast<std::size_t>(s.shapes[shape].material)); };
  // roughconductor: the tint and both alphas (unmapped: Mitsuba's alphas are the distribution's).
  const MaterialTextures& t0 = textures_of(s, 0);
  ASSERT_EQ(t0.bindings.size(), 3u);
  EXPECT_EQ(t0.bindings[0].param, TexturedParam::kSpecularReflectance);
  EXPECT_EQ(t0.bindings[1].param, TexturedParam::kAlphaU);
  EXPECT_EQ(t0.bindings[2].param, TexturedParam::kAlphaV);
  EXPECT_EQ(t0.bindings[1].map, TextureMap::kLinear);
  EXPECT_EQ(s.textures.at(static_cast<std::size_t>(t0.bindings[1].texture)).channel, FloatChannel::kLuminance);
  EXPECT_EQ(letters_of(material(0)), static_cast<LetterMask>(1u << kD));
  // roughdielectric: alpha_u 0.3, alpha_v a texture.
  ASSERT_TRUE(std::holds_alternative<RoughDielectric>(material(1)));
  EXPECT_FLOAT_EQ(std::get<RoughDielectric>(material(1)).alpha_u, 0.3f);
  EXPECT_EQ(textures_of(s, 1).bindings.at(0).param, TexturedParam::kAlphaV);
  // A smooth conductor of material none with a textured tint stays a conductor (S), not a mirror.
  ASSERT_TRUE(std::holds_alternative<Conductor>(material(2)));
  EXPECT_EQ(letters_of(material(2)), static_cast<LetterMask>(1u << kS));
  // plastic: the base ρ / (1 − R̄ + ρ R̄) per hit (R̄ of eta 1.49 / 1.000277); nonlinear: ρ itself.
  const TextureBinding& p = textures_of(s, 3).bindings.at(0);
  EXPECT_EQ(p.map, TextureMap::kPlastic);
  EXPECT_FLOAT_EQ(p.r_bar, mean_internal_reflectance(std::get<CoatedDiffuse>(material(3)).eta));
  Material at;
  textured_material(s, material(3), textures_of(s, 3), {0.75f, 0.5f}, &at);  // white: ρ = 1 gives the base 1
  EXPECT_FLOAT_EQ(std::get<CoatedDiffuse>(at).reflectance.x, 1.0f);
  EXPECT_EQ(textures_of(s, 4).bindings.at(0).map, TextureMap::kLinear);
}

TEST(ImportTexturesJson, TextureObjectsForColours) {
  write_black_white();
  const std::string json =
      R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40, "width": 4, "height": 4},
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}],
    "materials": {"img": {"type": "diffuse", "albedo": {"image": "bw.png", "wrap": "clamp", "uv_scale": [2, 1], "uv_offset": [0.25, 0]}},
                  "mix": {"type": "mixture", "components": [{"weight": 0.5, "material": {"type": "diffuse"}},
                    {"weight": 0.5, "material": {"type": "diffuse_transmission", "transmittance": {"checkerboard": [[0.5, 0, 0], [0, 0, 0.5]]}}}]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "img"},
               {"type": "sphere", "center": [0, 3, 0], "radius": 1, "material": "mix"}]})";
  const Scene s = load(write("tex.json", json));
  ASSERT_EQ(s.shapes.size(), 3u);  // and the environment's box
  ASSERT_EQ(s.images.size(), 1u);
  const TextureBinding& b = textures_of(s, 0).bindings.at(0);
  const Texture& t = s.textures.at(static_cast<std::size_t>(b.texture));
  EXPECT_EQ(t.wrap, TextureWrap::kClamp);
  EXPECT_TRUE(t.flip_t);
  EXPECT_EQ(std::vector<float>(t.uv.m, t.uv.m + 6), (std::vector<float>{2, 0, 0.25f, 0, 1, 0}));
  EXPECT_EQ(eval_texture(s, b.texture, {0.25f, 0.5f}), vec3(1.0f));  // s = 0.75: the white texel
  const TextureBinding& c = textures_of(s, 1).bindings.at(0);
  EXPECT_EQ(c.component, 1);
  EXPECT_EQ(c.param, TexturedParam::kTransmittance);
  EXPECT_EQ(eval_texture(s, c.texture, {0.5f, 0.5f}), vec3(0.5f, 0, 0));
  EXPECT_EQ(eval_texture(s, c.texture, {1.5f, 0.5f}), vec3(0, 0, 0.5f));
}

// OBJ texture coordinates: vertices split per (position, uv) pair, so one position with two uvs
// becomes two vertices.
TEST(ImportTexturesObj, VtCoordinatesSplitVertices) {
  const std::string path = write("uv.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
                                           "f 1/1 2/2 3/3\nf 1/5 3/3 4/4\n");
  std::size_t elements = 0;
  Result<MeshShape> m = load_obj_mesh(path, {}, &elements);
  ASSERT_TRUE(m.ok()) << m.error().render();
  EXPECT_EQ(m->positions, (std::vector<vec3>{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}, {0, 1, 0}}));
  EXPECT_EQ(m->uvs, (std::vector<vec2>{{0, 0}, {1, 0}, {1, 1}, {0.5f, 0.5f}, {0, 1}}));
  EXPECT_EQ(m->triangles, (std::vector<glm::uvec3>{{0, 1, 2}, {3, 2, 4}}));
  // Without a uv at every corner, none is kept.
  Result<MeshShape> partial = load_obj_mesh(write("part.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/1 2 3\n"));
  ASSERT_TRUE(partial.ok());
  EXPECT_TRUE(partial->uvs.empty());
  EXPECT_EQ(partial->positions.size(), 3u);
}

struct Refusal {
  const char* file;
  std::string text;
  const char* where;
  const char* message;
};

TEST(ImportTexturesRefusals, LocatedWithExactMessages) {
  write_black_white();
  const std::string json_head =
      R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40, "width": 4, "height": 4},
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}], "shapes": [], "materials": {"m": )";
  const std::string bitmap = "<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\">"
                             "<string name=\"filename\" value=\"bw.png\"/>";
  const std::vector<Refusal> refusals = {
      {"fbm.pbrt", kPbrtHead + "Texture \"t\" \"float\" \"fbm\"\n", "fbm.pbrt:5:1",
       "texture \"fbm\" is not supported, expected imagemap, checkerboard, scale, mix or constant"},
      {"ptex.pbrt", kPbrtHead + "Texture \"t\" \"spectrum\" \"ptex\" \"string filename\" \"a.ptx\"\n", "ptex.pbrt:5:1",
       "texture \"ptex\" is not supported, expected imagemap, checkerboard, scale, mix or constant"},
      {"bump.pbrt", kPbrtHead + "Texture \"t\" \"normal\" \"imagemap\"\n", "bump.pbrt:5:1",
       "texture type \"normal\" is not supported, expected \"spectrum\" or \"float\""},
      {"spherical.pbrt", kPbrtHead + "Texture \"t\" \"float\" \"checkerboard\" \"string mapping\" \"spherical\"\n", "spherical.pbrt:5:36",
       "texture mapping \"spherical\" is not supported: pathex's textures use the surface's (u, v) (mapping \"uv\")"},
      {"solid.pbrt", kPbrtHead + "Texture \"t\" \"float\" \"checkerboard\" \"integer dimension\" 3\n", "solid.pbrt:5:36",
       "checkerboard dimension 3 is not supported: pathex's textures use the surface's (u, v) (dimension 2)"},
      {"encoding.pbrt", kPbrtHead + "Texture \"t\" \"float\" \"imagemap\" \"string filename\" \"bw.png\" \"string encoding\" \"gamma x\"\n",
       "encoding.pbrt:5:59", "imagemap encoding \"gamma x\" is not supported, expected \"sRGB\", \"linear\" or \"gamma g\" with g in (0, 10]"},
      {"octa.pbrt", kPbrtHead + "Texture \"t\" \"float\" \"imagemap\" \"string filename\" \"bw.png\" \"string wrap\" \"octahedralsphere\"\n",
       "octa.pbrt:5:59", "imagemap wrap \"octahedralsphere\" is not supported, expected repeat, clamp or black"},
      {"missing.pbrt", kPbrtHead + "Texture \"t\" \"float\" \"imagemap\" \"string filename\" \"none.png\"\n", "missing.pbrt:5:32",
       "image \"none.png\" cannot read the image: No such file or directory"},
      {"unknown.pbrt", kPbrtHead + "Material \"diffuse\" \"texture reflectance\" \"nope\"\n", "unknown.pbrt:5:20", "unknown texture \"nope\""},
      {"kind.pbrt", kPbrtHead + "Texture \"f\" \"float\" \"constant\"\nMaterial \"diffuse\" \"texture reflectance\" \"f\"\n", "kind.pbrt:6:20",
       "texture \"f\" is a float texture, parameter 'reflectance' expects a spectrum one"},
      {"g.pbrt", kPbrtHead + "Texture \"f\" \"float\" \"constant\"\nMaterial \"coateddiffuse\" \"texture g\" \"f\"\n", "g.pbrt:6:26",
       "a texture for parameter 'g' is not supported (pathex reads textures for reflectance, transmittance, roughness, a mix's amount and "
       "a shape's alpha), give \"float g\" value"},
      {"metal.pbrt", kPbrtHead + "Texture \"c\" \"spectrum\" \"constant\"\nMaterial \"conductor\" \"texture eta\" \"c\"\n",
       "metal.pbrt:6:22",
       "a texture for parameter \"eta\" is not supported here (pathex reads textures for reflectance, transmittance, roughness, a mix's "
       "amount and a shape's alpha), give \"rgb eta\" [r g b]"},
      {"aniso.pbrt", kPbrtHead + "Texture \"f\" \"float\" \"constant\"\nMaterial \"coateddiffuse\" \"texture uroughness\" \"f\"\n",
       "aniso.pbrt:6:1", "anisotropic roughness (uroughness != vroughness) is not supported"},
      {"lit.pbrt", kPbrtHead + "AreaLightSource \"diffuse\"\nShape \"sphere\" \"float alpha\" 0.5\n", "lit.pbrt:6:16",
       "an alpha cut-out on an area light is not supported"},
      {"alpha2.pbrt", kPbrtHead + "Shape \"sphere\" \"float alpha\" 2\n", "alpha2.pbrt:5:16", "alpha must be within [0, 1]"},
      {"perlin.xml", kXmlHead + bitmap.substr(0, bitmap.find("<texture")) + "<texture type=\"perlin\" name=\"reflectance\"/></bsdf></shape>\n</scene>\n",
       "perlin.xml:3:43", "texture \"perlin\" is not supported, expected bitmap or checkerboard"},
      {"mirror.xml", kXmlHead + bitmap + "<string name=\"wrap_mode\" value=\"mirror\"/></texture></bsdf></shape>\n</scene>\n", "mirror.xml:3:125",
       "wrap_mode \"mirror\" is not supported, expected repeat or clamp"},
      {"lit.xml",
       kXmlHead + "<shape type=\"sphere\"><bsdf type=\"mask\"><bsdf type=\"diffuse\"/></bsdf><emitter type=\"area\"/></shape>\n</scene>\n",
       "lit.xml:3:1", "a mask (an opacity cut-out) on an area light is not supported"},
      {"eta.xml",
       kXmlHead + "<bsdf type=\"roughdielectric\" id=\"x\"><texture type=\"bitmap\" name=\"specular_reflectance\"><string name=\"filename\" "
                  "value=\"bw.png\"/></texture></bsdf>\n</scene>\n",
       "eta.xml:3:37",
       "a texture for 'specular_reflectance' is not supported here (pathex reads textures for reflectances, alphas, a blendbsdf's weight "
       "and a mask's opacity), give an <rgb>"},
      {"plastic.xml",
       kXmlHead + "<bsdf type=\"roughplastic\" id=\"x\"><texture type=\"bitmap\" name=\"alpha\"><string name=\"filename\" "
                  "value=\"bw.png\"/></texture></bsdf>\n</scene>\n",
       "plastic.xml:3:34",
       "a texture for 'alpha' of roughplastic is not supported: Mitsuba 3's roughplastic takes one <float> alpha"},
      {"both.json", json_head + R"({"type": "diffuse", "albedo": {"image": "bw.png", "checkerboard": [[1, 1, 1], [0, 0, 0]]}}}})",
       "both.json:/materials/m/albedo", "expected a texture with either \"image\" or \"checkerboard\""},
      {"wrap.json", json_head + R"({"type": "diffuse", "albedo": {"image": "bw.png", "wrap": "mirror"}}}})", "wrap.json:/materials/m/albedo/wrap",
       "unknown wrap 'mirror', expected repeat, clamp or black"},
      {"nofile.json", json_head + R"({"type": "diffuse", "albedo": {"image": "none.png"}}}})", "nofile.json:/materials/m/albedo/image",
       "image 'none.png' cannot read the image: No such file or directory"},
  };
  for (const Refusal& r : refusals) {
    const Result<Scene> s = load_scene_file(write(r.file, r.text));
    ASSERT_FALSE(s.ok()) << r.file;
    EXPECT_EQ(relative(s.error().where), r.where) << r.file << ": " << s.error().message;
    EXPECT_EQ(relative(s.error().message), r.message) << r.file;
  }
}

}  // namespace
}  // namespace pathex
