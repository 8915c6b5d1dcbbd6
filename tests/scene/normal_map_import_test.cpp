// Bump and normal maps in the scene formats (issue 35, docs/textures.md "Bump and normal maps"):
// pbrt-v4's "texture displacement" and "string normalmap" on a material, Mitsuba 3's bumpmap and
// normalmap bsdfs; each mapped with its exact texture, and what stays refused, located, with its
// exact message. A bump or normal map leaves the material (kind, letters) as it was.
#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

#include "scene/scene.h"
#include "support/cli_run.h"
#include "support/load_scene.h"
#include "support/scene_snippets.h"
#include "support/scratch_files.h"
#include "support/test_images.h"
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

// A 2 x 1 PNG of 8-bit codes: (255, 128, 0) and (0, 128, 255).
void write_normals() { write_image<unsigned char>("nm.png", 2, 1, 3, {255, 128, 0, 0, 128, 255}); }

const MaterialTextures& textures_of(const Scene& s, std::size_t shape) {
  return s.material_textures.at(static_cast<std::size_t>(s.shapes.at(shape).material));
}

TEST(ImportNormalMapsPbrt, DisplacementAndNormalmap) {
  write_normals();
  const Scene s = load(write("nm.pbrt", kPbrtHead +
                                            "Texture \"bumps\" \"float\" \"scale\" \"float tex\" 2 \"float scale\" 0.25\n"
                                            "Material \"diffuse\" \"texture displacement\" \"bumps\"\nShape \"sphere\"\n"
                                            "Material \"coateddiffuse\" \"string normalmap\" \"nm.png\"\nShape \"sphere\"\n"
                                            "MakeNamedMaterial \"n\" \"string type\" \"conductor\" \"float displacement\" 0.5\n"
                                            "NamedMaterial \"n\"\nShape \"sphere\"\n"));
  ASSERT_EQ(s.shapes.size(), 3u);
  EXPECT_TRUE(std::holds_alternative<Diffuse>(s.materials.at(static_cast<std::size_t>(s.shapes[0].material))));  // the kind stays
  const MaterialTextures& bump = textures_of(s, 0);
  EXPECT_EQ(bump.perturb, NormalPerturbation::kBumpPbrt);
  EXPECT_TRUE(bump.bindings.empty());
  EXPECT_EQ(eval_texture(s, bump.perturb_texture, vec2(0.3f, 0.7f)), vec3(0.5f));
  const MaterialTextures& normal = textures_of(s, 1);
  EXPECT_EQ(normal.perturb, NormalPerturbation::kNormalMap);
  const Texture& t = s.textures.at(static_cast<std::size_t>(normal.perturb_texture));
  EXPECT_EQ(t.kind, TextureKind::kImage);
  EXPECT_TRUE(t.flip_t);  // pbrt-v4's NormalMap() looks up (u, 1 − v)
  EXPECT_EQ(t.wrap, TextureWrap::kRepeat);
  // Read linear (pbrt-v4 reads normal maps with ColorEncoding::Linear): code 128 is 128/255.
  EXPECT_EQ(eval_texture(s, normal.perturb_texture, vec2(0.25f, 0.5f)), vec3(1.0f, 128.0f / 255.0f, 0.0f));
  EXPECT_EQ(eval_texture(s, normal.perturb_texture, vec2(0.75f, 0.5f)), vec3(0.0f, 128.0f / 255.0f, 1.0f));
  const MaterialTextures& named = textures_of(s, 2);
  EXPECT_EQ(named.perturb, NormalPerturbation::kBumpPbrt);
  EXPECT_EQ(eval_texture(s, named.perturb_texture, vec2(0.0f)), vec3(0.5f));
}

TEST(ImportNormalMapsMitsuba, NormalmapAndBumpmap) {
  write_normals();
  const Scene s = load(write(
      "nm.xml", kXmlHead +
                    "<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><transform name=\"to_world\"><lookat origin=\"0, 0, 5\" "
                    "target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>\n"
                    "<texture type=\"bitmap\" id=\"nmap\"><string name=\"filename\" value=\"nm.png\"/><boolean name=\"raw\" value=\"true\"/></texture>\n"
                    "<shape type=\"sphere\"><bsdf type=\"normalmap\"><ref name=\"normalmap\" id=\"nmap\"/>"
                    "<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.25\"/></bsdf></bsdf></shape>\n"
                    "<shape type=\"sphere\"><bsdf type=\"twosided\"><bsdf type=\"bumpmap\"><float name=\"scale\" value=\"0.5\"/>"
                    "<texture type=\"bitmap\" name=\"arbitrary\"><string name=\"filename\" value=\"nm.png\"/><boolean name=\"raw\" value=\"true\"/>"
                    "</texture><bsdf type=\"roughplastic\"/></bsdf></bsdf></shape>\n</scene>\n"));
  ASSERT_EQ(s.shapes.size(), 2u);
  const Material& m0 = s.materials.at(static_cast<std::size_t>(s.shapes[0].material));
  ASSERT_TRUE(std::holds_alternative<Diffuse>(m0));
  EXPECT_EQ(std::get<Diffuse>(m0).albedo, vec3(0.25f));
  const MaterialTextures& normal = textures_of(s, 0);
  EXPECT_EQ(normal.perturb, NormalPerturbation::kNormalMap);
  const Texture& t = s.textures.at(static_cast<std::size_t>(normal.perturb_texture));
  EXPECT_FALSE(t.flip_t);  // Mitsuba looks up t as it is
  EXPECT_EQ(eval_texture(s, normal.perturb_texture, vec2(0.25f, 0.5f)), vec3(1.0f, 128.0f / 255.0f, 0.0f));
  const MaterialTextures& bump = textures_of(s, 1);
  EXPECT_EQ(bump.perturb, NormalPerturbation::kBumpMitsuba);
  EXPECT_EQ(bump.bump_scale, 0.5f);
  // As a float, a bitmap reads the luminance of R, G and B (Mitsuba 3).
  const float lum = 0.212671f * 1.0f + 0.715160f * (128.0f / 255.0f);
  EXPECT_FLOAT_EQ(eval_texture(s, bump.perturb_texture, vec2(0.25f, 0.5f)).x, lum);
}

struct Refusal {
  const char* file;
  std::string text;
  const char* where;
  const char* message;
};

TEST(ImportNormalMapsRefusals, LocatedWithExactMessages) {
  write_normals();
  const std::string diffuse = "<bsdf type=\"diffuse\"/>";
  const std::vector<Refusal> refusals = {
      {"both.pbrt", kPbrtHead + "Material \"diffuse\" \"float displacement\" 1 \"string normalmap\" \"nm.png\"\n", "both.pbrt:5:43",
       "a material with both displacement and normalmap is not supported: pbrt-v4 applies one of them"},
      {"nofile.pbrt", kPbrtHead + "Material \"diffuse\" \"string normalmap\" \"none.png\"\n", "nofile.pbrt:5:20",
       "image \"none.png\" cannot read the image: No such file or directory"},
      {"empty.pbrt", kPbrtHead + "Material \"diffuse\" \"string normalmap\" \"\"\n", "empty.pbrt:5:20", "normalmap needs an image file name"},
      {"kind.pbrt", kPbrtHead + "Texture \"c\" \"spectrum\" \"constant\"\nMaterial \"diffuse\" \"texture displacement\" \"c\"\n", "kind.pbrt:6:20",
       "texture \"c\" is a spectrum texture, parameter 'displacement' expects a float one"},
      {"mix.pbrt",
       kPbrtHead + "MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"float displacement\" 1\nMakeNamedMaterial \"b\" \"string type\" \"diffuse\"\n"
                   "Material \"mix\" \"string materials\" [\"a\" \"b\"]\n",
       "mix.pbrt:7:16", "a mix of \"a\", which has a bump or normal map, is not supported"},
      {"nomap.xml", kXmlHead + "<bsdf type=\"normalmap\" id=\"x\">" + diffuse + "</bsdf>\n</scene>\n", "nomap.xml:3:1",
       "normalmap needs a <texture name=\"normalmap\">"},
      {"notex.xml", kXmlHead + "<bsdf type=\"bumpmap\" id=\"x\">" + diffuse + "</bsdf>\n</scene>\n", "notex.xml:3:1",
       "bumpmap needs one nested <texture>, found 0"},
      {"nobsdf.xml",
       kXmlHead + "<bsdf type=\"bumpmap\" id=\"x\"><texture type=\"checkerboard\"/></bsdf>\n</scene>\n", "nobsdf.xml:3:1",
       "bumpmap with 0 nested BSDFs is not supported, expected one"},
      {"twice.xml",
       kXmlHead + "<bsdf type=\"bumpmap\" id=\"x\"><texture type=\"checkerboard\"/><bsdf type=\"bumpmap\"><texture type=\"checkerboard\"/>" +
           diffuse + "</bsdf></bsdf>\n</scene>\n",
       "twice.xml:3:59", "a bumpmap or normalmap inside a bumpmap or normalmap is not supported"},
      {"blend.xml",
       kXmlHead + "<bsdf type=\"blendbsdf\" id=\"x\"><bsdf type=\"bumpmap\"><texture type=\"checkerboard\"/>" + diffuse + "</bsdf>" + diffuse +
           "</bsdf>\n</scene>\n",
       "blend.xml:3:31", "a bumpmap or normalmap inside a blendbsdf is not supported"},
  };
  for (const Refusal& r : refusals) {
    const Result<Scene> s = load_scene_file(write(r.file, r.text));
    ASSERT_FALSE(s.ok()) << r.file;
    EXPECT_EQ(relative(s.error().where), r.where) << r.file << ": " << s.error().message;
    EXPECT_EQ(relative(s.error().message), r.message) << r.file;
  }
}

TEST(ImportNormalMapsRefusals, TheCommandLineSaysWhereAndExitsWith2) {
  const std::string path = write("both-cli.pbrt", kPbrtHead + "Material \"diffuse\" \"float displacement\" 1 \"string normalmap\" \"nm.png\"\n"
                                                              "Shape \"sphere\"\n");
  const test::CliRun r = test::run_pathex_args({"trace", path, "--spp", "1", "--out", (test::scratch_dir() / "out").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(relative(r.err), "pathex: error: both-cli.pbrt:5:43: a material with both displacement and normalmap is not supported: pbrt-v4 "
                             "applies one of them\n");
}

}  // namespace
}  // namespace pathex
