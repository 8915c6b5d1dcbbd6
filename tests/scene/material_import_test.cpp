// The materials of issue 35 in every scene format: pbrt-v4 (conductor with its named metal
// spectra, default copper and reflectance; rough, thin and smooth dielectrics; diffuse
// transmission; interface), Mitsuba 3 (conductor and roughconductor with named materials and
// anisotropy, roughdielectric, thindielectric) and the JSON scene, each mapped onto its kind with
// exact parameters; and what stays refused (measured, subsurface, hair, principled, unknown
// spectra) with its file, line, column and exact message.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "scene/material.h"
#include "scene/metal_spectra.h"
#include "scene/scene.h"
#include "support/load_scene.h"
#include "support/scratch_files.h"

namespace pathex {
namespace {

using test::relative;
using test::write;

const std::string kPbrtHead = "LookAt 0 1 3  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\nWorldBegin\nLightSource \"point\"\n";
const std::string kXmlHead = "<scene version=\"3.0.0\">\n<emitter type=\"point\"/>\n";
const std::string kXmlSensor =
    "<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><transform name=\"to_world\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>"
    "</transform></sensor>\n";

using test::load;

const Material& material_of(const Scene& s, std::size_t shape) {
  return s.materials[static_cast<std::size_t>(s.shapes.at(shape).material)];
}

glm::vec3 metal(const char* name, bool eta) {
  const MetalSpectrum* m = find_metal(name);
  EXPECT_NE(m, nullptr) << name;
  const float* v = eta ? m->eta : m->k;
  return glm::vec3(v[0], v[1], v[2]);
}

TEST(ImportMaterialsPbrt, ConductorsFromNamedSpectraDefaultCopperAndReflectance) {
  const Scene s = load(write("metals.pbrt", kPbrtHead +
                                                "Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" "
                                                "\"float roughness\" 0.1\nShape \"sphere\"\n"
                                                "Material \"conductor\"\nShape \"sphere\"\n"
                                                "Material \"conductor\" \"float uroughness\" 0.01 \"float vroughness\" 0.25 "
                                                "\"bool remaproughness\" false\nShape \"sphere\"\n"
                                                "Material \"conductor\" \"rgb reflectance\" [0.5 0.8 1]\nShape \"sphere\"\n"
                                                "Material \"conductor\" \"float roughness\" 0.0000009\nShape \"sphere\"\n"));
  ASSERT_EQ(s.shapes.size(), 5u);
  const auto& au = std::get<Conductor>(material_of(s, 0));
  EXPECT_EQ(au.eta, metal("Au", true));
  EXPECT_EQ(au.k, metal("Au", false));
  EXPECT_FLOAT_EQ(au.alpha_u, std::sqrt(0.1f));
  EXPECT_FLOAT_EQ(au.alpha_v, std::sqrt(0.1f));
  EXPECT_EQ(letters_of(Material{au}), static_cast<LetterMask>(1u << kD));
  const auto& cu = std::get<Conductor>(material_of(s, 1));  // pbrt-v4's default: copper, smooth
  EXPECT_EQ(cu.eta, metal("Cu", true));
  EXPECT_EQ(cu.k, metal("Cu", false));
  EXPECT_EQ(letters_of(Material{cu}), static_cast<LetterMask>(1u << kS));
  const auto& aniso = std::get<Conductor>(material_of(s, 2));
  EXPECT_FLOAT_EQ(aniso.alpha_u, 0.01f);
  EXPECT_FLOAT_EQ(aniso.alpha_v, 0.25f);
  const auto& refl = std::get<Conductor>(material_of(s, 3));  // eta 1, k = 2 sqrt(r) / sqrt(1 - r), r ≤ 0.9999
  EXPECT_EQ(refl.eta, glm::vec3(1.0f));
  EXPECT_FLOAT_EQ(refl.k.x, 2.0f);
  EXPECT_FLOAT_EQ(refl.k.y, 2.0f * std::sqrt(0.8f) / std::sqrt(0.2f));
  EXPECT_FLOAT_EQ(refl.k.z, 2.0f * std::sqrt(0.9999f) / std::sqrt(1.0f - 0.9999f));
  EXPECT_EQ(letters_of(material_of(s, 4)), 1u << kS);  // alpha = sqrt(9e-7) < 1e-3: smooth, as pbrt-v4
}

// pbrt-v4's coatedconductor: its defaults (a smooth coat of eta 1.5 over smooth copper: one delta,
// S), the metal's eta and k divided by the coat's interface.eta, both roughnesses remapped, and
// reflectance r as eta 1, k = 2 sqrt(r) / sqrt(1 - r) (then divided too); JSON's coateddiffuse
// with a conductor "base" is the same material.
TEST(ImportMaterialsPbrt, CoatedConductorDefaultsRelativeIndexAndRoughness) {
  const Scene s = load(write("coatedmetal.pbrt", kPbrtHead +
                                                     "Material \"coatedconductor\"\nShape \"sphere\"\n"
                                                     "Material \"coatedconductor\" \"float interface.eta\" 1.25 \"spectrum conductor.eta\" \"metal-Au-eta\" "
                                                     "\"spectrum conductor.k\" \"metal-Au-k\" \"float interface.roughness\" 0.04 "
                                                     "\"float conductor.uroughness\" 0.01 \"float conductor.vroughness\" 0.09 \"float thickness\" 0.2 "
                                                     "\"rgb albedo\" [0.5 0.5 0.5] \"float g\" 0.3 \"integer maxdepth\" 20 \"integer nsamples\" 2\nShape \"sphere\"\n"
                                                     "Material \"coatedconductor\" \"rgb reflectance\" [0.5 0.5 0.5] \"float conductor.roughness\" 0.25\nShape \"sphere\"\n"));
  ASSERT_EQ(s.shapes.size(), 3u);
  const auto& def = std::get<CoatedDiffuse>(material_of(s, 0));
  EXPECT_EQ(def.base, CoatBase::kConductor);
  EXPECT_EQ(def.eta, 1.5f);
  EXPECT_EQ(def.conductor.eta, metal("Cu", true) / 1.5f);
  EXPECT_EQ(def.conductor.k, metal("Cu", false) / 1.5f);
  EXPECT_EQ(def.thickness, 0.01f);
  EXPECT_EQ(def.max_depth, 10);
  EXPECT_TRUE(def.all_specular());
  EXPECT_EQ(letters_of(material_of(s, 0)), static_cast<LetterMask>(1u << kS));
  const auto& au = std::get<CoatedDiffuse>(material_of(s, 1));
  EXPECT_EQ(au.conductor.eta, metal("Au", true) / 1.25f);
  EXPECT_EQ(au.conductor.k, metal("Au", false) / 1.25f);
  EXPECT_FLOAT_EQ(au.roughness, 0.2f);
  EXPECT_FLOAT_EQ(au.conductor.alpha_u, 0.1f);
  EXPECT_FLOAT_EQ(au.conductor.alpha_v, 0.3f);
  EXPECT_EQ(au.albedo, glm::vec3(0.5f));
  EXPECT_FLOAT_EQ(au.g, 0.3f);
  EXPECT_EQ(au.samples, 2);
  EXPECT_EQ(letters_of(material_of(s, 1)), static_cast<LetterMask>(1u << kD));
  const auto& refl = std::get<CoatedDiffuse>(material_of(s, 2));
  EXPECT_EQ(refl.conductor.eta, glm::vec3(1.0f / 1.5f));
  EXPECT_FLOAT_EQ(refl.conductor.k.x, 2.0f * std::sqrt(0.5f) / std::sqrt(0.5f) / 1.5f);
  EXPECT_EQ(letters_of(material_of(s, 2)), static_cast<LetterMask>((1u << kS) | (1u << kD)));  // smooth coat, rough metal
  const Scene j = load(write("coatedmetal.json", R"({"camera": {"type": "pinhole", "position": [0, 0, 5], "look_at": [0, 0, 0]},
      "lights": [{"type": "point", "position": [0, 0, 5], "intensity": [1, 1, 1]}],
      "materials": {"m": {"type": "coateddiffuse", "eta": 1.25, "roughness": 0.2, "base": {"type": "conductor", "metal": "Au", "roughness_u": 0.1, "roughness_v": 0.3}}},
      "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})"));
  const auto& ja = std::get<CoatedDiffuse>(j.materials.at(0));
  EXPECT_EQ(ja.conductor.eta, au.conductor.eta);
  EXPECT_EQ(ja.conductor.k, au.conductor.k);
  EXPECT_EQ(ja.conductor.alpha_u, au.conductor.alpha_u);
}

TEST(ImportMaterialsPbrt, DielectricsDiffuseTransmissionAndInterface) {
  const Scene s = load(write("glass.pbrt", kPbrtHead +
                                               "Material \"dielectric\" \"float roughness\" 0.2\nShape \"sphere\"\n"
                                               "Material \"dielectric\" \"float eta\" 0.75 \"float roughness\" 0.0000001\nShape \"sphere\"\n"
                                               "Material \"thindielectric\" \"float eta\" 1.33\nShape \"sphere\"\n"
                                               "Material \"diffusetransmission\" \"rgb reflectance\" [0.2 0.4 0.6] \"rgb transmittance\" "
                                               "[0.8 0.5 0.3] \"float scale\" 1.5\nShape \"sphere\"\n"
                                               "MakeNamedMaterial \"nothing\" \"string type\" \"interface\"\n"
                                               "NamedMaterial \"nothing\"\nShape \"sphere\" \"float radius\" 3\n"
                                               "Material \"interface\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
                                               "Material \"diffusetransmission\"\nShape \"sphere\"\n"));
  ASSERT_EQ(s.shapes.size(), 5u);  // the two interface shapes are not imported
  const auto& rough = std::get<RoughDielectric>(material_of(s, 0));
  EXPECT_FLOAT_EQ(rough.ior, 1.5f);
  EXPECT_FLOAT_EQ(rough.alpha_u, std::sqrt(0.2f));
  EXPECT_EQ(letters_of(Material{rough}), static_cast<LetterMask>(1u << kD));
  const auto& smooth = std::get<Dielectric>(material_of(s, 1));
  EXPECT_FLOAT_EQ(smooth.ior, 0.75f);
  EXPECT_EQ(letters_of(Material{smooth}), static_cast<LetterMask>(1u << kS));
  const auto& thin = std::get<ThinDielectric>(material_of(s, 2));
  EXPECT_FLOAT_EQ(thin.ior, 1.33f);
  EXPECT_EQ(letters_of(Material{thin}), static_cast<LetterMask>(1u << kS));
  const auto& dt = std::get<DiffuseTransmission>(material_of(s, 3));  // scale · value, clamped to [0, 1]
  EXPECT_LT(glm::length(dt.reflectance - glm::vec3(0.3f, 0.6f, 0.9f)), 1e-6f);
  EXPECT_LT(glm::length(dt.transmittance - glm::vec3(1.0f, 0.75f, 0.45f)), 1e-6f);
  EXPECT_EQ(letters_of(Material{dt}), static_cast<LetterMask>(1u << kD));
  const auto& dflt = std::get<DiffuseTransmission>(material_of(s, 4));
  EXPECT_EQ(dflt.reflectance, glm::vec3(0.25f));
  EXPECT_EQ(dflt.transmittance, glm::vec3(0.25f));
}

TEST(ImportMaterialsMitsuba, ConductorsAndDielectrics) {
  const Scene s = load(write(
      "metals.xml",
      kXmlHead + kXmlSensor +
          "<shape type=\"sphere\"><bsdf type=\"conductor\"><string name=\"material\" value=\"Au\"/></bsdf></shape>\n"
          "<shape type=\"sphere\"><bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"ggx\"/>"
          "<float name=\"alpha_u\" value=\"0.05\"/><float name=\"alpha_v\" value=\"0.3\"/><string name=\"material\" value=\"CuZn\"/></bsdf></shape>\n"
          "<shape type=\"sphere\"><bsdf type=\"conductor\"><rgb name=\"specular_reflectance\" value=\"0.9, 0.8, 0.7\"/></bsdf></shape>\n"
          "<shape type=\"sphere\"><bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"ggx\"/>"
          "<float name=\"alpha\" value=\"0.2\"/><float name=\"int_ior\" value=\"1.5\"/><float name=\"ext_ior\" value=\"1\"/></bsdf></shape>\n"
          "<shape type=\"sphere\"><bsdf type=\"thindielectric\"><float name=\"int_ior\" value=\"1.33\"/>"
          "<float name=\"ext_ior\" value=\"1\"/></bsdf></shape>\n"
          // Mitsuba's default distribution, beckmann, and its default alpha 0.1; given explicitly.
          "<shape type=\"sphere\"><bsdf type=\"roughconductor\"/></shape>\n"
          "<shape type=\"sphere\"><bsdf type=\"roughdielectric\"/></shape>\n"
          "<shape type=\"sphere\"><bsdf type=\"roughplastic\"/></shape>\n"
          "<shape type=\"sphere\"><bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"beckmann\"/>"
          "<float name=\"alpha_u\" value=\"0.2\"/><float name=\"alpha_v\" value=\"0.05\"/></bsdf></shape>\n"
          "<shape type=\"sphere\"><bsdf type=\"roughplastic\"><string name=\"distribution\" value=\"ggx\"/>"
          "<float name=\"alpha\" value=\"0.3\"/></bsdf></shape>\n"
          "</scene>\n"));
  ASSERT_EQ(s.shapes.size(), 10u);
  const auto& au = std::get<Conductor>(material_of(s, 0));
  EXPECT_EQ(au.eta, metal("Au", true));
  EXPECT_EQ(au.k, metal("Au", false));
  EXPECT_EQ(letters_of(Material{au}), static_cast<LetterMask>(1u << kS));
  const auto& brass = std::get<Conductor>(material_of(s, 1));
  EXPECT_EQ(brass.eta, metal("CuZn", true));
  EXPECT_FLOAT_EQ(brass.alpha_u, 0.05f);
  EXPECT_FLOAT_EQ(brass.alpha_v, 0.3f);
  EXPECT_EQ(letters_of(Material{brass}), static_cast<LetterMask>(1u << kD));
  // material "none" (eta 0, k 1) reflects specular_reflectance at every angle: a mirror.
  EXPECT_EQ(std::get<Mirror>(material_of(s, 2)).reflectance, glm::vec3(0.9f, 0.8f, 0.7f));
  const auto& rough = std::get<RoughDielectric>(material_of(s, 3));
  EXPECT_FLOAT_EQ(rough.ior, 1.5f);
  EXPECT_FLOAT_EQ(rough.alpha_u, 0.2f);
  EXPECT_FLOAT_EQ(rough.alpha_v, 0.2f);
  EXPECT_FLOAT_EQ(std::get<ThinDielectric>(material_of(s, 4)).ior, 1.33f);
  EXPECT_EQ(brass.distribution, MicrofacetKind::kGgx);
  EXPECT_EQ(rough.distribution, MicrofacetKind::kGgx);
  const auto& conductor = std::get<Conductor>(material_of(s, 5));
  EXPECT_EQ(conductor.distribution, MicrofacetKind::kBeckmann);
  EXPECT_EQ(conductor.alpha_u, 0.1f);
  EXPECT_EQ(conductor.alpha_v, 0.1f);
  EXPECT_EQ(letters_of(Material{conductor}), static_cast<LetterMask>(1u << kD));
  const auto& glass = std::get<RoughDielectric>(material_of(s, 6));
  EXPECT_EQ(glass.distribution, MicrofacetKind::kBeckmann);
  EXPECT_EQ(glass.alpha_u, 0.1f);
  EXPECT_FLOAT_EQ(glass.ior, static_cast<float>(1.5046 / 1.000277));  // Mitsuba's defaults: bk7 inside, air outside
  const auto& plastic = std::get<CoatedDiffuse>(material_of(s, 7));
  EXPECT_EQ(plastic.distribution, MicrofacetKind::kBeckmann);
  EXPECT_EQ(plastic.roughness, 0.1f);
  const auto& aniso = std::get<Conductor>(material_of(s, 8));
  EXPECT_EQ(aniso.distribution, MicrofacetKind::kBeckmann);
  EXPECT_EQ(aniso.alpha_u, 0.2f);
  EXPECT_EQ(aniso.alpha_v, 0.05f);
  const auto& ggx_plastic = std::get<CoatedDiffuse>(material_of(s, 9));
  EXPECT_EQ(ggx_plastic.distribution, MicrofacetKind::kGgx);
  EXPECT_EQ(ggx_plastic.roughness, 0.3f);
}

TEST(ImportMaterialsJson, NewKindsAndTheirParameters) {
  const Scene s = load(write("materials.json", R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40, "width": 4, "height": 4},
    "materials": {"gold": {"type": "conductor", "metal": "Au", "roughness": 0.2},
                  "copper": {"type": "conductor"},
                  "custom": {"type": "conductor", "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.3], "roughness_u": 0.1, "roughness_v": 0.4},
                  "rough": {"type": "dielectric", "ior": 1.33, "roughness": 0.3},
                  "smooth": {"type": "dielectric", "ior": 1.33, "roughness": 0.0005},
                  "thin": {"type": "thin_dielectric", "ior": 1.4},
                  "leaf": {"type": "diffuse_transmission", "reflectance": [0.2, 0.3, 0.1], "transmittance": [0.3, 0.5, 0.2]},
                  "beckmann-metal": {"type": "conductor", "roughness": 0.25, "distribution": "beckmann"},
                  "beckmann-glass": {"type": "dielectric", "ior": 1.5, "roughness": 0.15, "distribution": "beckmann"},
                  "beckmann-coat": {"type": "coateddiffuse", "roughness": 0.2, "distribution": "beckmann"},
                  "ggx-glossy": {"type": "glossy", "roughness": 0.2, "distribution": "ggx"},
                  "beckmann-glossy": {"type": "glossy", "roughness": 0.2, "distribution": "beckmann"}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "gold"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "copper"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "custom"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "rough"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "smooth"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "thin"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "leaf"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "beckmann-metal"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "beckmann-glass"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "beckmann-coat"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "ggx-glossy"},
               {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "beckmann-glossy"}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}]})"));
  ASSERT_EQ(s.shapes.size(), 13u);  // and the environment's box
  const auto& gold = std::get<Conductor>(material_of(s, 0));
  EXPECT_EQ(gold.k, metal("Au", false));
  EXPECT_FLOAT_EQ(gold.alpha_u, 0.2f);
  EXPECT_EQ(std::get<Conductor>(material_of(s, 1)).eta, metal("Cu", true));
  const auto& custom = std::get<Conductor>(material_of(s, 2));
  EXPECT_EQ(custom.eta, glm::vec3(0.2f, 0.9f, 1.1f));
  EXPECT_FLOAT_EQ(custom.alpha_v, 0.4f);
  EXPECT_FLOAT_EQ(std::get<RoughDielectric>(material_of(s, 3)).alpha_v, 0.3f);
  EXPECT_FLOAT_EQ(std::get<Dielectric>(material_of(s, 4)).ior, 1.33f);
  EXPECT_FLOAT_EQ(std::get<ThinDielectric>(material_of(s, 5)).ior, 1.4f);
  EXPECT_EQ(std::get<DiffuseTransmission>(material_of(s, 6)).transmittance, glm::vec3(0.3f, 0.5f, 0.2f));
  // "distribution": ggx unless given.
  EXPECT_EQ(gold.distribution, MicrofacetKind::kGgx);
  EXPECT_EQ(std::get<RoughDielectric>(material_of(s, 3)).distribution, MicrofacetKind::kGgx);
  const auto& metal_b = std::get<Conductor>(material_of(s, 7));
  EXPECT_EQ(metal_b.distribution, MicrofacetKind::kBeckmann);
  EXPECT_EQ(metal_b.alpha_u, 0.25f);
  const auto& glass_b = std::get<RoughDielectric>(material_of(s, 8));
  EXPECT_EQ(glass_b.distribution, MicrofacetKind::kBeckmann);
  EXPECT_EQ(glass_b.alpha_v, 0.15f);
  const auto& coat_b = std::get<CoatedDiffuse>(material_of(s, 9));
  EXPECT_EQ(coat_b.distribution, MicrofacetKind::kBeckmann);
  EXPECT_EQ(coat_b.roughness, 0.2f);
  EXPECT_EQ(std::get<Glossy>(material_of(s, 10)).distribution, MicrofacetKind::kGgx);
  EXPECT_EQ(std::get<Glossy>(material_of(s, 11)).distribution, MicrofacetKind::kBeckmann);
}

struct Refusal {
  const char* file;
  std::string text;
  const char* where;
  const char* message;
};

TEST(ImportMaterialsRefusals, LocatedWithExactMessages) {
  const std::string json_head =
      R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40, "width": 4, "height": 4},
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}], "shapes": [], "materials": {"m": )";
  const std::vector<Refusal> refusals = {
      {"subsurface.pbrt", kPbrtHead + "Material \"subsurface\"\n", "subsurface.pbrt:5:1",
       "material \"subsurface\" is not supported: it needs volumetric path tracing under the surface (a medium and random walks inside "
       "it), which pathex does not have"},
      {"hair.pbrt", kPbrtHead + "Material \"hair\"\n", "hair.pbrt:5:1",
       "material \"hair\" is not supported: it needs pbrt-v4's hair BSDF on curve shapes, which pathex does not have"},
      {"spectrum.pbrt", kPbrtHead + "Material \"conductor\" \"spectrum eta\" \"metal-Pt-eta\"\n", "spectrum.pbrt:5:22",
       "unknown spectrum \"metal-Pt-eta\" for eta, expected metal-<name>-eta or metal-<name>-k with <name> one of Ag, Al, Au, Cu, CuZn, "
       "MgO, TiO2"},
      {"sampled.pbrt", kPbrtHead + "Material \"conductor\" \"spectrum k\" [300 3 800 4]\n", "sampled.pbrt:5:22",
       "parameter \"spectrum k\" with sampled values is not supported: give a named metal spectrum (\"metal-Cu-k\") or \"rgb k\" [r g b]"},
      {"both.pbrt", kPbrtHead + "Material \"conductor\" \"rgb reflectance\" [0.5 0.5 0.5] \"rgb k\" [1 1 1]\n", "both.pbrt:5:22",
       "conductor takes either reflectance or eta and k, not both"},
      {"rough-alpha.pbrt", kPbrtHead + "Material \"dielectric\" \"float roughness\" 1.5 \"bool remaproughness\" false\n",
       "rough-alpha.pbrt:5:1", "dielectric roughness gives GGX alpha 1.5, pathex accepts at most 1"},
      {"lit-interface.pbrt", kPbrtHead + "Material \"interface\"\nAreaLightSource \"diffuse\"\nShape \"sphere\"\n", "lit-interface.pbrt:7:1",
       "an area light on a shape of material \"interface\" (no surface) is not supported"},
      {"mix-interface.pbrt",
       kPbrtHead + "MakeNamedMaterial \"a\" \"string type\" \"interface\"\nMakeNamedMaterial \"b\" \"string type\" \"diffuse\"\n"
                   "Material \"mix\" \"string materials\" [\"a\" \"b\"]\n",
       "mix-interface.pbrt:7:16", "mix with the interface material \"a\" (no surface) is not supported"},
      {"cu2o.xml", kXmlHead + "<bsdf type=\"conductor\" id=\"x\"><string name=\"material\" value=\"Cu2O\"/></bsdf>\n</scene>\n", "cu2o.xml:3:31",
       "conductor material \"Cu2O\" is not supported: pathex has the measured spectra of Ag, Al, Au, Cu, CuZn, MgO, TiO2 (pbrt-v4's "
       "tables); give eta and k as rgb for another"},
      {"alphas.xml",
       kXmlHead + "<bsdf type=\"roughconductor\" id=\"x\"><string name=\"distribution\" value=\"ggx\"/><float name=\"alpha\" value=\"0.1\"/>"
                  "<float name=\"alpha_u\" value=\"0.2\"/></bsdf>\n</scene>\n",
       "alphas.xml:3:77", "give either alpha or alpha_u and alpha_v"},
      {"twosided-thin.xml",
       kXmlHead + "<bsdf type=\"twosided\" id=\"x\"><bsdf type=\"thindielectric\"/></bsdf>\n</scene>\n", "twosided-thin.xml:3:1",
       "a twosided dielectric is not supported"},
      {"metal.json", json_head + R"({"type": "conductor", "metal": "Pt"}}})", "metal.json:/materials/m/metal",
       "unknown metal 'Pt', expected one of Ag, Al, Au, Cu, CuZn, MgO, TiO2"},
      {"metal-and-eta.json", json_head + R"({"type": "conductor", "metal": "Au", "eta": [1, 1, 1]}}})", "metal-and-eta.json:/materials/m/metal",
       "expected either metal or eta and k, found both"},
      {"leaf.json", json_head + R"({"type": "diffuse_transmission", "reflectance": [0.6, 0.5, 0.5], "transmittance": [0.6, 0.5, 0.5]}}})",
       "leaf.json:/materials/m/transmittance", "expected reflectance + transmittance within [0, 1], found 1.2"},
      {"phong.xml", kXmlHead + "<bsdf type=\"roughdielectric\" id=\"x\"><string name=\"distribution\" value=\"phong\"/></bsdf>\n</scene>\n",
       "phong.xml:3:37", "microfacet distribution \"phong\" is not supported, expected beckmann or ggx"},
      {"phong.json", json_head + R"({"type": "conductor", "roughness": 0.1, "distribution": "phong"}}})", "phong.json:/materials/m/distribution",
       "unknown microfacet distribution 'phong', expected ggx or beckmann"},
      {"number.json", json_head + R"({"type": "coateddiffuse", "distribution": 2}}})", "number.json:/materials/m/distribution",
       "expected a string, found a number"},
      {"thin-distribution.json", json_head + R"({"type": "thin_dielectric", "distribution": "ggx"}}})",
       "thin-distribution.json:/materials/m/distribution", "unknown key 'distribution', expected one of type, ior, tint"},
      {"thin-rough.json", json_head + R"({"type": "thin_dielectric", "roughness": 0.1}}})", "thin-rough.json:/materials/m/roughness",
       "unknown key 'roughness', expected one of type, ior, tint"},
  };
  for (const Refusal& r : refusals) {
    const Result<Scene> s = load_scene_file(write(r.file, r.text));
    ASSERT_FALSE(s.ok()) << r.file;
    EXPECT_EQ(relative(s.error().where), r.where) << r.file;
    EXPECT_EQ(relative(s.error().message), r.message) << r.file;
  }
}

}  // namespace
}  // namespace pathex
