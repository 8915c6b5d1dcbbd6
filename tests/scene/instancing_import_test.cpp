// Instancing in every format (scene.h ShapeGroup, ShapeInstance): pbrt-v4's ObjectBegin/ObjectEnd/
// ObjectInstance, Mitsuba 3's shapegroup/instance and JSON's groups give exact groups, members and
// transforms (pbrt-v4's CTM at the shape inside the object, then the CTM at ObjectInstance), and
// what is refused is refused with its file, line, column and an exact message, by the library and
// by the CLI (exit 2).
#include <gtest/gtest.h>

#include "scene/scene.h"
#include "support/cli_run.h"
#include "support/load_scene.h"
#include "support/scratch_files.h"

namespace pathex {
namespace {

using glm::vec3;
using test::relative;
using test::scratch;
using test::write;

using test::load;

vec3 moved(const ShapeInstance& i, vec3 p) { return vec3(i.to_world * glm::vec4(p, 1.0f)); }

void expect_near(vec3 a, vec3 b, const std::string& what) {
  EXPECT_LT(glm::length(a - b), 1e-5f) << what << ": (" << a.x << ", " << a.y << ", " << a.z << ") vs (" << b.x << ", " << b.y << ", " << b.z << ")";
}

// "Scale -1 1 1" before LookAt makes pbrt's camera space right-handed, so the world is not mirrored.
const std::string kPbrt = "Scale -1 1 1\nLookAt 0 0 9  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nLightSource \"point\" \"point3 from\" [0 0 5]\n";

TEST(InstancingImport, PbrtComposesTheCtmAtTheShapeAndAtTheInstance) {
  const Scene s = load(write("inst.pbrt", kPbrt +
                                              "AttributeBegin\nTranslate 5 0 0\nObjectInstance \"thing\"\nAttributeEnd\n"  // before the definition, as pbrt-v4 allows
                                              "Translate 0 0 1\nObjectBegin \"thing\"\nScale 2 2 2\n"
                                              "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\nObjectEnd\n"
                                              "Shape \"sphere\"\n"  // ObjectEnd restored the CTM: Translate 0 0 1 only
                                              "Rotate 90 0 0 1\nObjectInstance \"thing\"\n"));
  ASSERT_EQ(s.groups.size(), 1u);
  EXPECT_EQ(s.groups[0].name, "thing");
  EXPECT_EQ(relative(s.groups[0].pointer), "inst.pbrt:11:1");
  ASSERT_EQ(s.shapes.size(), 2u);
  EXPECT_EQ(s.shapes[0].group, 0);
  const MeshShape& m = std::get<MeshShape>(s.shapes[0].geometry);
  ASSERT_EQ(m.positions.size(), 3u);
  expect_near(m.positions[1], vec3(2, 0, 1), "the member's CTM inside the object (Translate, Scale)");
  EXPECT_EQ(s.shapes[1].group, -1);
  expect_near(std::get<SphereShape>(s.shapes[1].geometry).center, vec3(0, 0, 1), "the sphere after ObjectEnd");
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(relative(s.instances[0].pointer), "inst.pbrt:8:1");
  expect_near(moved(s.instances[0], m.positions[1]), vec3(7, 0, 1), "Translate 5 0 0 at the first instance");
  // The second instance's CTM: Translate 0 0 1, Rotate 90 about z: (2, 0, 1) -> (0, 2, 1) -> (0, 2, 2).
  expect_near(moved(s.instances[1], m.positions[1]), vec3(0, 2, 2), "the CTM at the second instance");
  EXPECT_EQ(describe(scene_types(s)), "lights point; sensor pinhole; materials D");
}

// A bare LookAt is left-handed: the builder mirrors the world through the camera's vertical plane
// (x = 0 here) and the mirror joins the instance's transform; the member stays in its space.
TEST(InstancingImport, PbrtMirrorJoinsTheInstanceTransform) {
  const Scene s = load(write("inst-mirror.pbrt", "LookAt 0 0 9  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n"
                                                 "LightSource \"point\" \"point3 from\" [0 0 5]\nObjectBegin \"t\"\n"
                                                 "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n"
                                                 "ObjectEnd\nTranslate 3 0 0\nObjectInstance \"t\"\n"));
  ASSERT_EQ(s.instances.size(), 1u);
  expect_near(std::get<MeshShape>(s.shapes[0].geometry).positions[1], vec3(1, 0, 0), "the member, unmirrored");
  expect_near(moved(s.instances[0], vec3(1, 0, 0)), vec3(-4, 0, 0), "translated by 3, then mirrored");
  EXPECT_LT(glm::determinant(glm::mat3(s.instances[0].to_world)), 0.0f);
}

TEST(InstancingImport, MitsubaShapegroupAndInstances) {
  const Scene s = load(write("inst.xml",
                             "<scene version=\"3.0.0\">\n"
                             "  <sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><transform name=\"to_world\"><lookat origin=\"0, 0, 9\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>\n"
                             "  <emitter type=\"point\"><point name=\"position\" value=\"0, 0, 5\"/></emitter>\n"
                             "  <shape type=\"shapegroup\" id=\"g\">\n"
                             "    <shape type=\"rectangle\"><transform name=\"to_world\"><translate value=\"0, 0, 1\"/></transform></shape>\n"
                             "  </shape>\n"
                             "  <shape type=\"instance\"><ref id=\"g\"/><transform name=\"to_world\"><translate value=\"3, 0, 0\"/></transform></shape>\n"
                             "  <shape type=\"instance\"><ref id=\"g\"/></shape>\n"
                             "</scene>\n"));
  ASSERT_EQ(s.groups.size(), 1u);
  EXPECT_EQ(s.groups[0].name, "g");
  ASSERT_EQ(s.shapes.size(), 1u);
  EXPECT_EQ(s.shapes[0].group, 0);
  // The rectangle [-1, 1]^2 at z = 1 as two triangles.
  const MeshShape& m = std::get<MeshShape>(s.shapes[0].geometry);
  EXPECT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.triangles.size(), 2u);
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(s.instances[0].group, 0);
  EXPECT_EQ(relative(s.instances[0].pointer), "inst.xml:7:3");
  expect_near(moved(s.instances[0], vec3(1, 1, 1)), vec3(4, 1, 1), "translated by 3");
  expect_near(moved(s.instances[1], vec3(1, 1, 1)), vec3(1, 1, 1), "in place");
}

// An instance may come before its shapegroup (made when first named), and an empty object draws nothing.
TEST(InstancingImport, InstanceBeforeItsShapegroupAndEmptyObjects) {
  const Scene x = load(write("inst-late.xml",
                             "<scene version=\"3.0.0\">\n"
                             "  <sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><transform name=\"to_world\"><lookat origin=\"0, 0, 9\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>\n"
                             "  <emitter type=\"point\"><point name=\"position\" value=\"0, 0, 5\"/></emitter>\n"
                             "  <shape type=\"instance\"><ref id=\"g\"/></shape>\n"
                             "  <shape type=\"shapegroup\" id=\"g\"><shape type=\"cube\"/></shape>\n"
                             "</scene>\n"));
  EXPECT_EQ(x.groups.size(), 1u);
  EXPECT_EQ(x.shapes.size(), 1u);
  EXPECT_EQ(x.instances.size(), 1u);
  const Scene p = load(write("inst-empty.pbrt", kPbrt + "ObjectBegin \"none\"\nObjectEnd\nObjectInstance \"none\"\nShape \"sphere\"\n"));
  EXPECT_EQ(p.groups.size(), 1u);
  EXPECT_EQ(p.instances.size(), 1u);
  EXPECT_TRUE(instance_boxes(p).empty());
}

TEST(InstancingImport, JsonGroupsAndInstances) {
  write("inst-tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const Scene s = load(write("inst.json", R"({"camera": {"type": "pinhole", "position": [0, 0, 9], "look_at": [0, 0, 0]},
    "materials": {"m": {"type": "diffuse"}}, "lights": [{"type": "point", "position": [0, 0, 5], "intensity": [1, 1, 1]}],
    "groups": {"tri": [{"type": "mesh", "file": "inst-tri.obj", "material": "m", "transform": {"translate": [0, 0, 1]}},
                       {"type": "quad", "corner": [0, 0, 0], "edge1": [1, 0, 0], "edge2": [0, 1, 0], "material": "m"}]},
    "shapes": [{"type": "instance", "group": "tri", "transform": {"translate": [1, 2, 3], "scale": [2, 1, 1]}}]})"));
  ASSERT_EQ(s.shapes.size(), 2u);
  EXPECT_EQ(std::get<MeshShape>(s.shapes[1].geometry).triangles.size(), 2u);  // the quad as two triangles
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.instances[0].pointer, "/shapes/0");
  expect_near(moved(s.instances[0], std::get<MeshShape>(s.shapes[0].geometry).positions[1]), vec3(3, 2, 4), "scale, then translate");
}

// --- refusals: located, exact ---

struct Refusal {
  const char* file;
  std::string text;
  const char* where;
  const char* message;
};

std::vector<Refusal> refusals() {
  const std::string xml = "<scene version=\"3.0.0\">\n";
  const std::string tri = "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n";
  return {
      {"unknown-object.pbrt", kPbrt + "ObjectInstance \"nope\"\n", "unknown-object.pbrt:6:1",
       "ObjectInstance of unknown object \"nope\" (no ObjectBegin defines it)"},
      {"instance-in-object.pbrt", kPbrt + "ObjectBegin \"a\"\nObjectInstance \"b\"\nObjectEnd\n", "instance-in-object.pbrt:7:1",
       "ObjectInstance inside the definition of object \"a\" (ObjectBegin at instance-in-object.pbrt:6:1): objects do not nest"},
      {"object-in-object.pbrt", kPbrt + "ObjectBegin \"a\"\nObjectBegin \"b\"\n", "object-in-object.pbrt:7:1",
       "ObjectBegin inside the definition of object \"a\" (ObjectBegin at object-in-object.pbrt:6:1): objects do not nest"},
      {"light-in-object.pbrt", kPbrt + "ObjectBegin \"a\"\nAreaLightSource \"diffuse\"\n" + tri + "ObjectEnd\n", "light-in-object.pbrt:8:1",
       "an area light in an instanced object is not supported (pbrt-v4 refuses them too): place the emitting shape in the world"},
      {"alpha-in-object.pbrt", kPbrt + "ObjectBegin \"a\"\n" + tri.substr(0, tri.size() - 1) + " \"float alpha\" 0.5\nObjectEnd\n",
       "alpha-in-object.pbrt:7:1",
       "an alpha cut-out in an instanced object is not supported: place the cut-out shape in the world"},
      {"sphere-in-object.pbrt", kPbrt + "ObjectBegin \"a\"\nShape \"sphere\"\nObjectEnd\n", "sphere-in-object.pbrt:7:1",
       "a sphere in an instanced object is not supported (an instance's transform need not keep it one): instanced objects hold meshes"},
      {"object-twice.pbrt", kPbrt + "ObjectBegin \"a\"\nObjectEnd\nObjectBegin \"a\"\n", "object-twice.pbrt:8:1",
       "object \"a\" is defined twice (first at object-twice.pbrt:6:1)"},
      {"object-open.pbrt", kPbrt + "ObjectBegin \"a\"\n" + tri, "object-open.pbrt:6:1", "ObjectBegin \"a\" has no matching ObjectEnd"},
      {"object-end.pbrt", kPbrt + "ObjectEnd\n", "object-end.pbrt:6:1", "ObjectEnd has no matching ObjectBegin"},
      {"object-attribute.pbrt", kPbrt + "ObjectBegin \"a\"\nAttributeEnd\n", "object-attribute.pbrt:7:1", "AttributeEnd has no matching AttributeBegin"},
      {"nested-group.xml", xml + "  <shape type=\"shapegroup\" id=\"g\">\n    <shape type=\"shapegroup\" id=\"h\"/>\n  </shape>\n</scene>\n",
       "nested-group.xml:3:5", "a shapegroup inside a shapegroup is not supported: shapegroups do not nest"},
      {"not-a-group.xml", xml + "  <bsdf type=\"diffuse\" id=\"b\"/>\n  <shape type=\"instance\">\n    <ref id=\"b\"/>\n  </shape>\n</scene>\n",
       "not-a-group.xml:4:5", "the instance's <ref id=\"b\"> names a <bsdf type=\"diffuse\"> (at not-a-group.xml:2:3), expected a shapegroup"},
      {"unknown-group.xml", xml + "  <shape type=\"instance\">\n    <ref id=\"zz\"/>\n  </shape>\n</scene>\n", "unknown-group.xml:3:5",
       "unknown id \"zz\""},
      {"light-in-group.xml",
       xml + "  <shape type=\"shapegroup\" id=\"g\">\n    <shape type=\"rectangle\">\n      <emitter type=\"area\"/>\n    </shape>\n  </shape>\n</scene>\n",
       "light-in-group.xml:3:5",
       "an area light in an instanced object is not supported (pbrt-v4 refuses them too): place the emitting shape in the world"},
      {"no-ref.xml", xml + "  <shape type=\"instance\"/>\n</scene>\n", "no-ref.xml:2:3", "an instance needs a <ref id=…> to a shapegroup"},
  };
}

TEST(InstancingImport, RefusalsNameFileLineColumnAndWhat) {
  for (const Refusal& r : refusals()) {
    const Result<Scene> s = load_scene_file(write(r.file, r.text));
    ASSERT_FALSE(s.ok()) << r.file;
    EXPECT_EQ(relative(s.error().where), r.where) << r.file;
    EXPECT_EQ(relative(s.error().message), r.message) << r.file;
  }
}

TEST(InstancingImport, CliPrintsTheSameLineAndExits2) {
  for (const Refusal& r : refusals()) {
    const test::CliRun run = test::run_pathex("trace " + write(r.file, r.text) + " --quiet --out " + scratch() + "/out");
    EXPECT_EQ(run.code, 2) << r.file;
    EXPECT_EQ(relative(run.err), std::string("pathex: error: ") + r.where + ": " + r.message + "\n") << r.file;
  }
}

TEST(InstancingImport, JsonRefusals) {
  const std::string head = R"({"camera": {"type": "pinhole", "position": [0, 0, 9], "look_at": [0, 0, 0]},
    "materials": {"m": {"type": "diffuse"}}, "lights": [{"type": "point", "position": [0, 0, 5], "intensity": [1, 1, 1]}],)";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"("shapes": [{"type": "instance", "group": "nope"}]})", "/shapes/0/group: unknown group 'nope', expected a name defined in /groups"},
      {R"("groups": {"g": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]}, "shapes": [{"type": "instance", "group": "g"}]})",
       "/groups/g/0: a sphere in an instanced object is not supported (an instance's transform need not keep it one): instanced objects hold meshes"},
      {R"("groups": {"g": [{"type": "quad", "corner": [0, 0, 0], "edge1": [1, 0, 0], "edge2": [0, 1, 0], "material": "m", "emission": [1, 1, 1]}]},
          "shapes": [{"type": "instance", "group": "g"}]})",
       "/groups/g/0: an area light in an instanced object is not supported (pbrt-v4 refuses them too): place the emitting shape in the world"},
      {R"("groups": {"g": [{"type": "instance", "group": "g"}]}, "shapes": [{"type": "instance", "group": "g"}]})",
       "/groups/g/0/type: an instance inside a group is not supported: groups do not nest"},
  };
  for (const auto& [body, message] : cases) {
    const Result<Scene> s = load_scene_json(head + body, scratch(), "inline");
    ASSERT_FALSE(s.ok()) << body;
    EXPECT_EQ(s.error().where + ": " + s.error().message, "inline:" + message) << body;
  }
}

}  // namespace
}  // namespace pathex
