// The scene importers under hostile input (issue 42): every reproducer of the mutation run is
// refused with one located message and exit code 2 by `trace` and `query --scene` alike, or loads
// within the stated limits (--max-file-size for each file, --max-scene-size for a scene's text
// with its includes, --max-scene-depth, --max-material-nodes, --max-mesh-elements). Times are
// not asserted: bench/hangs.py measures them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "scene/scene.h"
#include "support/cli_run.h"
#include "support/scratch_files.h"

namespace pathex {
namespace {

const std::string kDir = PATHEX_SOURCE_DIR;

using test::relative;
using test::scratch;
using test::write;

const std::string kPbrtHead = "LookAt 0 1 3  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\nWorldBegin\n";
const std::string kXmlHead = "<scene version=\"3.0.0\">\n";
const std::string kXmlCamera =
    "<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/>"
    "<transform name=\"to_world\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>"
    "<emitter type=\"point\"><point name=\"position\" x=\"0\" y=\"3\" z=\"3\"/></emitter>\n";

std::string repeat(const std::string& s, int n) {
  std::string out;
  out.reserve(s.size() * static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) out += s;
  return out;
}

struct Case {
  std::string file, text, where, message;
};

// Each is refused with exactly this location and message under the default limits.
std::vector<Case> refusals() {
  const std::string a64(64, 'A');
  return {
      // 1. A Mitsuba bsdf that refers to itself (the file, byte for byte): it recursed until the stack overflowed.
      {"self-ref.xml",
       "<scene version=\"3.0.0\"><bsdf type=\"twosided\" id=\"a\"><ref id=\"a\"/></bsdf><shape type=\"sphere\"><ref id=\"a\"/></shape></scene>",
       "self-ref.xml:1:53", "<ref id=\"a\"> inside the bsdf it names: a bsdf cannot contain itself"},
      // 2. 50,000 nested twosided overflowed the stack; the 65th level is refused.
      {"deep.xml",
       kXmlHead + "  <shape type=\"sphere\">" + repeat("<bsdf type=\"twosided\">", 50000) + "<bsdf type=\"diffuse\"/>" +
           repeat("</bsdf>", 50000) + "</shape>\n</scene>\n",
       "deep.xml:2:1432", "the nesting of materials exceeds the limit of 64 levels (raise it with --max-scene-depth)"},
      // 3. 16 Mi '[' after WorldBegin became 16 Mi tokens and a bad_alloc before the first was read.
      {"brackets.pbrt", kPbrtHead + std::string(std::size_t{16} << 20, '['), "brackets.pbrt:4:1", "expected a directive, found '['"},
      // 8. An Include of a directory or of "" included nothing.
      {"include-dot.pbrt", kPbrtHead + "Include \".\"\n", "include-dot.pbrt:4:1", "the included file '.' is a directory, expected a file"},
      {"include-dir.pbrt", kPbrtHead + "Import \"sub\"\n", "include-dir.pbrt:4:1", "the included file 'sub' is a directory, expected a file"},
      {"include-empty.pbrt", kPbrtHead + "Include \"\"\n", "include-empty.pbrt:4:1", "Include needs a file name, found \"\""},
      {"include-empty.xml", kXmlHead + "  <include filename=\"\"/>\n</scene>\n", "include-empty.xml:2:3", "<include> needs a file name, found \"\""},
      // 11. Projective and singular matrices were applied as if affine.
      {"projective.pbrt", kPbrtHead + "Transform [1 0 0 0  0 1 0 0  0 0 1 1  0 0 0 1]\nShape \"sphere\"\n", "projective.pbrt:4:1",
       "Transform's matrix is projective (its last row is 0 0 1 1, expected 0 0 0 1): pathex applies affine transforms only"},
      {"singular.pbrt", kPbrtHead + "ConcatTransform [0 0 0 0  0 0 0 0  0 0 0 0  0 0 0 1]\nShape \"sphere\"\n", "singular.pbrt:4:1",
       "ConcatTransform's matrix is singular: it flattens space onto a plane, a line or a point"},
      {"projective.xml",
       kXmlHead + "  <shape type=\"sphere\">\n    <transform name=\"to_world\">\n      <matrix value=\"1 0 0 0  0 1 0 0  0 0 1 0  0 0 1 1\"/>\n"
                  "    </transform>\n  </shape>\n</scene>\n",
       "projective.xml:4:7", "the matrix is projective (its last row is 0 0 1 1, expected 0 0 0 1): pathex applies affine transforms only"},
      {"singular.xml",
       kXmlHead + "  <shape type=\"sphere\">\n    <transform name=\"to_world\">\n      <matrix value=\"1 0 0 0  0 1 0 0  0 0 0 0  0 0 0 1\"/>\n"
                  "    </transform>\n  </shape>\n</scene>\n",
       "singular.xml:4:7", "the matrix is singular: it flattens space onto a plane, a line or a point"},
      // 12. What pugixml accepts and XML or Mitsuba do not.
      {"duplicate-attribute.xml", kXmlHead + "  <shape type=\"sphere\" type=\"cylinder\"/>\n</scene>\n", "duplicate-attribute.xml:2:3",
       "<shape> has the attribute \"type\" twice"},
      {"duplicate-id.xml", kXmlHead + "  <bsdf type=\"diffuse\" id=\"a\"/>\n  <shape type=\"sphere\" id=\"a\"/>\n</scene>\n", "duplicate-id.xml:3:3",
       "a second object with id \"a\" (the first is at duplicate-id.xml:2:3)"},
      {"two-roots.xml", kXmlHead + "  <shape type=\"sphere\"/>\n</scene>\n<scene version=\"3.0.0\"/>\n", "two-roots.xml:4:1",
       "a second root element <scene> (a scene file has one root, <scene>)"},
      // 13. A conductor with a negative k; two cameras (pbrt's last one silently won).
      {"negative-k.pbrt", kPbrtHead + "Material \"conductor\" \"rgb eta\" [0.2 0.9 1.1] \"rgb k\" [3.9 -2.4 2.3]\nShape \"sphere\"\n",
       "negative-k.pbrt:4:46", "conductor k must be non-negative"},
      {"negative-k.xml",
       kXmlHead + "  <shape type=\"sphere\">\n    <bsdf type=\"conductor\">\n      <rgb name=\"eta\" value=\"0.2, 0.9, 1.1\"/>\n"
                  "      <rgb name=\"k\" value=\"3.9, -2.4, 2.3\"/>\n    </bsdf>\n  </shape>\n</scene>\n",
       "negative-k.xml:5:7", "conductor k must be non-negative"},
      {"two-cameras.pbrt", "LookAt 0 1 3  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\nCamera \"orthographic\"\nWorldBegin\n",
       "two-cameras.pbrt:3:1", "a second Camera (the first is at two-cameras.pbrt:2:1): pathex renders one camera"},
      // Messages: a long token is cut with an ellipsis; whole-scene errors say where the scene was read from.
      {"long-directive.pbrt", kPbrtHead + std::string(std::size_t{1} << 20, 'A') + "\n", "long-directive.pbrt:4:1",
       "directive '" + a64 + "…' is not supported (pathex imports shapes, materials, lights, a camera, transforms and Include/Import)"},
      {"long-tag.xml", kXmlHead + "<" + std::string(std::size_t{1} << 20, 'A') + "/>\n</scene>\n", "long-tag.xml:2:1",
       "<" + a64 + "…> is not supported (pathex imports shapes, bsdfs, emitters, a sensor, includes and paths)"},
      {"no-light.pbrt", kPbrtHead + "Include \"parts.pbrt\"\n", "no-light.pbrt",
       "the scene has no light: expected a light source or an emitting shape (read from no-light.pbrt and the files it includes: parts.pbrt)"},
      {"no-sensor.xml", kXmlHead + "  <emitter type=\"point\"/>\n  <shape type=\"sphere\"/>\n</scene>\n", "no-sensor.xml", "the scene has no camera"},
      // 14. One OBJ verdict for every command: the face corners `1/`, `2//` and `3///` (here through Mitsuba).
      {"corners.xml",
       kXmlHead + "  <shape type=\"obj\">\n    <string name=\"filename\" value=\"corners.obj\"/>\n"
                  "    <boolean name=\"face_normals\" value=\"true\"/>\n  </shape>\n</scene>\n",
       "corners.obj:4:3", "bad face corner '1/', expected v, v/vt, v//vn or v/vt/vn"},
  };
}

void write_fixtures() {
  std::filesystem::create_directories(scratch() + "/sub");
  write("parts.pbrt", "Shape \"sphere\"\n");
  write("corners.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ 2// 3///\n");
}

TEST(HostileScenes, LibraryRefusesEachWithItsLocationAndMessage) {
  write_fixtures();
  for (const Case& c : refusals()) {
    const Result<Scene> s = load_scene_file(write(c.file, c.text));
    ASSERT_FALSE(s.ok()) << c.file;
    EXPECT_EQ(relative(s.error().where), c.where) << c.file;
    EXPECT_EQ(relative(s.error().message), c.message) << c.file;
  }
}

TEST(HostileScenes, TraceAndQueryGiveTheSameLineAndExit2) {
  write_fixtures();
  for (const Case& c : refusals()) {
    const std::string path = write(c.file, c.text);
    const std::string line = "pathex: error: " + c.where + ": " + c.message + "\n";
    const pathex::test::CliRun trace = pathex::test::run_pathex("trace " + path + " --quiet --out " + scratch() + "/out");
    EXPECT_EQ(trace.code, 2) << c.file;
    EXPECT_EQ(relative(trace.err), line) << c.file;
    const pathex::test::CliRun query = pathex::test::run_pathex("query --scene " + path + " 'L.*E'");
    EXPECT_EQ(query.code, 2) << c.file;
    EXPECT_EQ(relative(query.err), line) << c.file;
  }
  // 14. The OBJ in a JSON scene: `query --scene` reads only the OBJ's scan, `trace` the whole mesh.
  const std::string json = kDir + "/tests/scene/bad/obj-corner-forms.json";
  const std::string line = "pathex: error: tests/scene/bad/obj-corner-forms.obj:4:3: bad face corner '1/', expected v, v/vt, v//vn or v/vt/vn\n";
  const pathex::test::CliRun trace = pathex::test::run_pathex("trace " + json + " --quiet --out " + scratch() + "/out");
  const pathex::test::CliRun query = pathex::test::run_pathex("query --scene " + json + " 'L.*E'");
  EXPECT_EQ(trace.code, 2);
  EXPECT_EQ(query.code, 2);
  EXPECT_EQ(relative(trace.err), line);
  EXPECT_EQ(relative(query.err), line);
}

// --- the limits: each an option, each refused with the option's name ---

TEST(HostileScenes, IncludedFilesAreReadWithTheFileSizeCap) {
  SceneLoadOptions o;
  o.max_file_bytes = 100000;
  for (const auto& [file, text, where] :
       {std::tuple{"include-zero.pbrt", kPbrtHead + "Include \"/dev/zero\"\n", "include-zero.pbrt:4:1"},
        std::tuple{"include-zero.xml", kXmlHead + "  <include filename=\"/dev/zero\"/>\n</scene>\n", "include-zero.xml:2:3"}}) {
    const std::string message = "the included file '/dev/zero' exceeds the limit of 100000 bytes (raise it with --max-file-size)";
    const Result<Scene> s = load_scene_file(write(file, text), o);
    ASSERT_FALSE(s.ok()) << file;
    EXPECT_EQ(s.error().code, ErrorCode::kLimit);
    EXPECT_EQ(relative(s.error().where), where);
    EXPECT_EQ(s.error().message, message);
    // The default cap, 64 MiB, through the command line (the issue: 2 GB and 14 s before).
    const pathex::test::CliRun run = pathex::test::run_pathex("query --scene " + scratch() + "/" + file + " 'L.*E'");
    EXPECT_EQ(run.code, 2);
    EXPECT_EQ(relative(run.err), std::string("pathex: error: ") + where +
                                     ": the included file '/dev/zero' exceeds the limit of 67108864 bytes (raise it with --max-file-size)\n");
  }
}

TEST(HostileScenes, TheSceneSizeCountsEveryIncludedFile) {
  write("six-hundred.pbrt", "# " + std::string(597, '-') + "\n");  // 600 bytes
  const std::string main = write("scene-size.pbrt", kPbrtHead + "Include \"six-hundred.pbrt\"\nInclude \"six-hundred.pbrt\"\n");
  SceneLoadOptions o;
  o.max_scene_bytes = 1000;  // the main file (128 bytes) and one include fit, not two
  const Result<Scene> s = load_scene_file(main, o);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kLimit);
  EXPECT_EQ(relative(s.error().where), "scene-size.pbrt:5:1");
  EXPECT_EQ(s.error().message, "the scene's text with its included files exceeds the limit of 1000 bytes (raise it with --max-scene-size)");
  const pathex::test::CliRun run = pathex::test::run_pathex("query --max-scene-size 1000 --scene " + main + " 'L.*E'");
  EXPECT_EQ(run.code, 2);
  EXPECT_EQ(relative(run.err), "pathex: error: scene-size.pbrt:5:1: the scene's text with its included files exceeds the limit of 1000 bytes "
                               "(raise it with --max-scene-size)\n");
}

// 64 nested levels load (the JSON reader's bound too); the 65th is refused, and the option moves it.
TEST(HostileScenes, MaterialNestingStopsAtMaxSceneDepth) {
  auto nested = [](int levels) {
    return kXmlHead + kXmlCamera + "<shape type=\"sphere\">" + repeat("<bsdf type=\"twosided\">", levels - 1) + "<bsdf type=\"diffuse\"/>" +
           repeat("</bsdf>", levels - 1) + "</shape>\n</scene>\n";
  };
  EXPECT_TRUE(load_scene_file(write("nested-64.xml", nested(64))).ok());
  const Result<Scene> deeper = load_scene_file(write("nested-65.xml", nested(65)));
  ASSERT_FALSE(deeper.ok());
  EXPECT_EQ(deeper.error().code, ErrorCode::kLimit);
  SceneLoadOptions o;
  o.max_scene_depth = 65;
  EXPECT_TRUE(load_scene_file(scratch() + "/nested-65.xml", o).ok());
  const pathex::test::CliRun run = pathex::test::run_pathex("query --max-scene-depth 65 --scene " + scratch() + "/nested-65.xml 'L.*E'");
  EXPECT_EQ(run.code, 0) << run.err;
}

// 4. A graph of materials that share parts was expanded as a tree: 40 levels of "mix m_{i+1}
// m_{i+1}" doubled the time and memory per level. Equal components now merge, so each level is
// one diffuse component of weight exactly 1 (sums of powers of two).
TEST(HostileScenes, SharedMaterialsDoNotExpandExponentially) {
  const int levels = 10000;
  std::string pbrt = kPbrtHead + "LightSource \"point\" \"point3 from\" [0 2 2]\n";
  pbrt += "MakeNamedMaterial \"m" + std::to_string(levels) + "\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.25 0.5 0.75]\n";
  for (int i = levels - 1; i >= 0; --i)
    pbrt += "MakeNamedMaterial \"m" + std::to_string(i) + "\" \"string type\" \"mix\" \"string materials\" [\"m" + std::to_string(i + 1) +
            "\" \"m" + std::to_string(i + 1) + "\"]\n";
  pbrt += "NamedMaterial \"m0\"\nShape \"sphere\"\n";
  std::string xml = kXmlHead + kXmlCamera + "<bsdf type=\"diffuse\" id=\"b40\"><rgb name=\"reflectance\" value=\"0.25, 0.5, 0.75\"/></bsdf>\n";
  for (int i = 39; i >= 0; --i)
    xml += "<bsdf type=\"blendbsdf\" id=\"b" + std::to_string(i) + "\"><ref id=\"b" + std::to_string(i + 1) + "\"/><ref id=\"b" +
           std::to_string(i + 1) + "\"/></bsdf>\n";
  xml += "<shape type=\"sphere\"><ref id=\"b0\"/></shape>\n</scene>\n";
  for (const auto& [file, text] : {std::pair{"shared.pbrt", pbrt}, std::pair{"shared.xml", xml}}) {
    const Result<Scene> s = load_scene_file(write(file, text));
    ASSERT_TRUE(s.ok()) << s.error().render();
    const auto& mix = std::get<Mixture>(s->materials[static_cast<std::size_t>(s->shapes[0].material)]);
    ASSERT_EQ(mix.components.size(), 1u) << file;
    EXPECT_EQ(mix.components[0].weight, 1.0f) << file;
    EXPECT_EQ(std::get<Diffuse>(mix.components[0].material).albedo, glm::vec3(0.25f, 0.5f, 0.75f)) << file;
  }
}

// Distinct materials still add up: d1..d4 (1 component each, 4 in all), c1 = d1 + d2 (2, 6 in
// all), c2 = c1 + d3 (3, 9), c3 = c2 + d4 (4, 13 > 10: refused at c3).
TEST(HostileScenes, ExpandedMaterialsStopAtMaxMaterialNodes) {
  std::string text = kPbrtHead;
  for (int i = 1; i <= 4; ++i)
    text += "MakeNamedMaterial \"d" + std::to_string(i) + "\" \"string type\" \"diffuse\" \"rgb reflectance\" [0." + std::to_string(i) + " 0 0]\n";
  text += "MakeNamedMaterial \"c1\" \"string type\" \"mix\" \"string materials\" [\"d1\" \"d2\"]\n"
          "MakeNamedMaterial \"c2\" \"string type\" \"mix\" \"string materials\" [\"c1\" \"d3\"]\n"
          "MakeNamedMaterial \"c3\" \"string type\" \"mix\" \"string materials\" [\"c2\" \"d4\"]\n";
  const std::string path = write("material-nodes.pbrt", text);
  SceneLoadOptions o;
  o.max_material_nodes = 10;
  const Result<Scene> s = load_scene_file(path, o);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kLimit);
  EXPECT_EQ(relative(s.error().where), "material-nodes.pbrt:10:1");
  EXPECT_EQ(s.error().message, "the expansion of the scene's materials exceeds the limit of 10 components (raise it with --max-material-nodes)");
  const pathex::test::CliRun run = pathex::test::run_pathex("trace --max-material-nodes 10 " + path + " --quiet --out " + scratch() + "/out");
  EXPECT_EQ(run.code, 2);
  EXPECT_EQ(relative(run.err), "pathex: error: material-nodes.pbrt:10:1: the expansion of the scene's materials exceeds the limit of 10 "
                               "components (raise it with --max-material-nodes)\n");
}

// Vertices plus triangles of all the scene's meshes, in every format: a trianglemesh of 4 + 2,
// an OBJ of 3 + 1 (refused at its face line, before it is kept).
TEST(HostileScenes, MeshesStopAtMaxMeshElements) {
  SceneLoadOptions o;
  o.max_mesh_elements = 5;
  const Result<Scene> pbrt = load_scene_file(
      write("mesh-elements.pbrt", kPbrtHead + "Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  1 1 0  0 1 0] \"integer indices\" [0 1 2  0 2 3]\n"), o);
  ASSERT_FALSE(pbrt.ok());
  EXPECT_EQ(pbrt.error().code, ErrorCode::kLimit);
  EXPECT_EQ(relative(pbrt.error().where), "mesh-elements.pbrt:4:1");
  EXPECT_EQ(pbrt.error().message, "the scene's mesh size exceeds the limit of 5 vertices and triangles (raise it with --max-mesh-elements)");
  o.max_mesh_elements = 3;
  write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n");
  std::ifstream in(kDir + "/tests/scene/bad/obj-texture-index.json");
  std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  json.replace(json.find("obj-texture-index.obj"), std::string("obj-texture-index.obj").size(), "tri.obj");
  const std::string path = write("mesh-elements.json", json);
  const Result<Scene> three = load_scene_file(path, o);
  ASSERT_FALSE(three.ok());
  EXPECT_EQ(three.error().code, ErrorCode::kLimit);
  EXPECT_EQ(relative(three.error().where), "tri.obj:4:1");
  EXPECT_EQ(three.error().message, "the scene's mesh size exceeds the limit of 3 vertices and triangles (raise it with --max-mesh-elements)");
  o.max_mesh_elements = 4;
  EXPECT_TRUE(load_scene_file(path, o).ok());
  const pathex::test::CliRun run = pathex::test::run_pathex("query --max-mesh-elements 3 --scene " + path + " 'L.*E'");
  EXPECT_EQ(run.code, 2);
}

// A JSON "mesh" naming a .ply is read as PLY (it was read as OBJ): the sample floor, one planar
// quad, is two triangles.
TEST(HostileScenes, JsonMeshNamingAPlyIsReadAsPly) {
  std::ifstream in(kDir + "/tests/scene/bad/obj-texture-index.json");
  std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string ply = kDir + "/samples/scenes/meshes/cornell-floor.ply";
  json.replace(json.find("obj-texture-index.obj"), std::string("obj-texture-index.obj").size(), ply);
  const Result<Scene> s = load_scene_file(write("ply-mesh.json", json));
  ASSERT_TRUE(s.ok()) << s.error().render();
  const auto& mesh = std::get<MeshShape>(s->shapes[1].geometry);
  EXPECT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.positions.size(), 4u);
  EXPECT_EQ(mesh.file, ply);
}

TEST(HostileScenes, TheLimitsAreOptionsWithTheirDefaults) {
  const pathex::test::CliRun help = pathex::test::run_pathex("query --help");
  for (const char* option : {"--max-scene-size UINT:UINT in [1 - 68719476736]=268435456", "--max-scene-depth INT:INT in [1 - 1000]=64",
                             "--max-material-nodes UINT:UINT in [1 - 100000000]=1000000",
                             "--max-mesh-elements UINT:UINT in [1 - 4000000000]=50000000"})
    EXPECT_NE(help.out.find(option), std::string::npos) << option << "\n" << help.out;
}

TEST(HostileScenes, ExcerptCutsAtACharacterBoundary) {
  EXPECT_EQ(excerpt("short"), "short");
  EXPECT_EQ(excerpt(std::string(64, 'x')), std::string(64, 'x'));
  EXPECT_EQ(excerpt(std::string(65, 'x')), std::string(64, 'x') + "…");
  // "é" is two bytes: a cut after 4 bytes of "aéé" would split the second; it is cut before it.
  EXPECT_EQ(excerpt("a\xC3\xA9\xC3\xA9", 5), "a\xC3\xA9\xC3\xA9");
  EXPECT_EQ(excerpt("a\xC3\xA9\xC3\xA9", 4), "a\xC3\xA9…");
}

}  // namespace
}  // namespace pathex
