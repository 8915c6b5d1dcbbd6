// Mitsuba's serialized meshes (scene/serialized.h): files built here byte by byte from the format's
// documentation, read back exactly; the Mitsuba importer's <shape type="serialized">; and every
// refusal with its exact message.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <zlib.h>

#include "scene/scene.h"
#include "scene/serialized.h"
#include "support/scratch_files.h"

namespace pathex {
namespace {

using test::relative;
using test::scratch;
using test::write;

template <typename T>
void put(std::string& out, T v) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &v, sizeof(T));  // this machine is little-endian, as the format
  out.append(reinterpret_cast<const char*>(raw), sizeof(T));
}

std::string deflate(const std::string& raw) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string out(size, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()), 6), Z_OK);
  out.resize(size);
  return out;
}

// One shape's inflated data.
struct Shape {
  std::uint32_t flags = 0x1000;
  std::string name = "shape";
  std::vector<double> positions, normals, uvs, colours;  // flat
  std::vector<std::uint32_t> indices;
  std::uint64_t vertices() const { return positions.size() / 3; }
  std::string data(int version) const {
    std::string d;
    put(d, flags);
    if (version == 4) d += name + '\0';
    put(d, static_cast<std::uint64_t>(vertices()));
    put(d, static_cast<std::uint64_t>(indices.size() / 3));
    for (const auto* list : {&positions, &normals, &uvs, &colours})
      for (double x : *list) (flags & 0x2000) != 0 ? put(d, x) : put(d, static_cast<float>(x));
    for (std::uint32_t i : indices) put(d, i);
    return d;
  }
};

// A file of `shapes` in `version`; `tweak` may change a shape's inflated data before it is compressed.
std::string file(const std::vector<Shape>& shapes, int version = 4, std::uint16_t identifier = 0x041C) {
  std::string out;
  std::vector<std::uint64_t> offsets;
  for (const Shape& s : shapes) {
    offsets.push_back(out.size());
    put(out, identifier);
    put(out, static_cast<std::uint16_t>(version));
    out += deflate(s.data(version));
  }
  for (std::uint64_t o : offsets) version == 4 ? put(out, o) : put(out, static_cast<std::uint32_t>(o));
  put(out, static_cast<std::uint32_t>(shapes.size()));
  return out;
}

Shape triangle() {
  Shape s;
  s.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  s.indices = {0, 1, 2};
  return s;
}

Shape smooth_quad() {
  Shape s;
  s.flags = 0x2000 | 0x0001 | 0x0002 | 0x0008;
  s.name = "quad";
  s.positions = {0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0};
  s.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  s.uvs = {0, 0, 1, 0, 1, 1, 0, 1};
  s.colours = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  s.indices = {0, 1, 2, 0, 2, 3};
  return s;
}

TEST(Serialized, EveryShapeOfAFileReadsBackExactly) {
  for (int version : {3, 4}) {
    const std::string bytes = file({triangle(), smooth_quad()}, version);
    const Result<SerializedMesh> a = parse_serialized(bytes, 0, "m.serialized");
    ASSERT_TRUE(a.ok()) << a.error().render();
    EXPECT_EQ(a->positions, (std::vector<glm::vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
    EXPECT_TRUE(a->normals.empty());
    EXPECT_EQ(a->triangles, (std::vector<glm::uvec3>{{0, 1, 2}}));
    const Result<SerializedMesh> b = parse_serialized(bytes, 1, "m.serialized");
    ASSERT_TRUE(b.ok()) << b.error().render();
    EXPECT_EQ(b->name, version == 4 ? "quad" : "");
    EXPECT_EQ(b->positions[2], glm::vec3(2, 2, 0));
    EXPECT_EQ(b->normals, std::vector<glm::vec3>(4, glm::vec3(0, 0, 1)));
    EXPECT_EQ(b->uvs[2], glm::vec2(1, 1));
    EXPECT_EQ(b->triangles, (std::vector<glm::uvec3>{{0, 1, 2}, {0, 2, 3}}));
    EXPECT_FALSE(b->face_normals);
  }
}

TEST(Serialized, MitsubaShapesPlaceTheMeshAndShadeItAsMitsubaDoes) {
  write("two.serialized", file({triangle(), smooth_quad()}));
  const std::string head = "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><transform name=\"to_world\"><lookat origin=\"0 0 5\" target=\"0 0 0\"/>"
                           "</transform></sensor>\n<emitter type=\"point\"><point name=\"position\" x=\"0\" y=\"0\" z=\"3\"/></emitter>\n";
  const std::string shape = "<shape type=\"serialized\"><string name=\"filename\" value=\"two.serialized\"/>";
  const Result<Scene> s = load_scene_file(write("serialized.xml", head +
      shape + "<integer name=\"shape_index\" value=\"1\"/><transform name=\"to_world\"><translate z=\"-1\"/></transform></shape>\n" +
      shape + "</shape>\n" + shape + "<boolean name=\"face_normals\" value=\"true\"/></shape>\n</scene>\n"));
  ASSERT_TRUE(s.ok()) << s.error().render();
  ASSERT_EQ(s->shapes.size(), 3u);
  const auto& quad = std::get<MeshShape>(s->shapes[0].geometry);
  EXPECT_EQ(quad.positions[2], glm::vec3(2, 2, -1));
  EXPECT_EQ(quad.normals, std::vector<glm::vec3>(4, glm::vec3(0, 0, 1)));  // the file's
  EXPECT_EQ(quad.uvs.size(), 4u);
  const auto& tri = std::get<MeshShape>(s->shapes[1].geometry);
  EXPECT_EQ(tri.normals, std::vector<glm::vec3>(3, glm::vec3(0, 0, 1)));  // none in the file: Mitsuba's own
  EXPECT_TRUE(std::get<MeshShape>(s->shapes[2].geometry).normals.empty());  // face_normals
}

TEST(Serialized, RefusalsNameTheFileAndWhatWasExpected) {
  Shape nan = triangle();
  nan.positions[4] = std::nan("");
  Shape out_of_range = triangle();
  out_of_range.indices[2] = 3;
  Shape both = triangle();
  both.flags = 0x3000;
  Shape unknown = triangle();
  unknown.flags = 0x1000 | 0x0100;
  std::string short_data = file({triangle()});
  const std::vector<std::pair<std::string, std::string>> cases = {
      {file({triangle()}, 4, 0x1234), "not a serialized mesh: the file does not start with the identifier 0x041C"},
      {file({triangle()}, 5), "serialized mesh version 5 is not supported, expected 3 or 4"},
      {std::string("\x1c\x04\x04\x00", 4) + "abcd" + std::string("\xff\xff\x00\x00", 4),
       "the table of shapes at the end of the file lists 65535 shapes, which the file's 12 bytes cannot hold"},
      {file({nan}), "shape 0: vertex 1 is not finite in single precision"},
      {file({out_of_range}), "shape 0: triangle 0 refers to vertex 3, expected 0..2"},
      {file({both}), "shape 0's flags give both single (0x1000) and double (0x2000) precision, expected one"},
      {file({unknown}), "shape 0 has unknown flags 0x100"},
      {std::string("\x1c\x04\x04\x00", 4) + "not zlib" + std::string(8, '\0') + std::string("\x01\x00\x00\x00", 4),
       "not a valid zlib stream: incorrect header check"},
  };
  for (const auto& [bytes, message] : cases) {
    const Result<SerializedMesh> m = parse_serialized(bytes, 0, "bad.serialized");
    ASSERT_FALSE(m.ok()) << message;
    EXPECT_EQ(m.error().where, "bad.serialized") << message;
    EXPECT_EQ(m.error().message, message);
  }
  const Result<SerializedMesh> beyond = parse_serialized(file({triangle()}), 1, "one.serialized");
  ASSERT_FALSE(beyond.ok());
  EXPECT_EQ(beyond.error().message, "shape_index 1 is beyond the file's 1 shape");
  // Counts that the data does not hold: one vertex fewer in the data than declared.
  Shape lying = triangle();
  std::string d = lying.data(4);
  d.erase(d.size() - 12 - 4, 4);  // drop the last vertex's z (single precision)
  std::string bytes;
  put(bytes, std::uint16_t{0x041C});
  put(bytes, std::uint16_t{4});
  bytes += deflate(d);
  put(bytes, std::uint64_t{0});
  put(bytes, std::uint32_t{1});
  const Result<SerializedMesh> lie = parse_serialized(bytes, 0, "lie.serialized");
  ASSERT_FALSE(lie.ok());
  EXPECT_EQ(lie.error().message, "shape 0 declares 3 vertices and 1 triangles (48 bytes of data), but holds 44 bytes after its counts");
  const Result<SerializedMesh> big = parse_serialized(file({smooth_quad()}), 0, "big.serialized", SerializedReadOptions{1 << 20, 5});
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.error().message, "the mesh's size exceeds the limit of 5 vertices and triangles (raise it with --max-mesh-elements)");
  // Through the command line: located at the file, exit 2.
  write("bad.serialized", file({nan}));
  const std::string scene = write("bad-serialized.xml",
      "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/></sensor>\n<emitter type=\"point\"/>\n"
      "<shape type=\"serialized\"><string name=\"filename\" value=\"bad.serialized\"/></shape>\n</scene>\n");
  const test::CliRun run = test::run_pathex("trace " + scene + " --quiet --out " + scratch() + "/out");
  EXPECT_EQ(run.code, 2);
  EXPECT_EQ(relative(run.err), "pathex: error: bad.serialized: shape 0: vertex 1 is not finite in single precision\n");
}

}  // namespace
}  // namespace pathex
