// Loop subdivision (scene/loop_subdivision.h) and pbrt-v4's "loopsubdiv" shape: exact counts per
// level (V' = V + E, F' = 4 F), closed meshes stay closed, limit points on their closed forms
// (a regular icosahedron's, a quadratic height field's, pbrt's boundary rule), a vertex's limit
// the same at every level, normals on pbrt's side; and every refusal located with an exact message.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "scene/loop_subdivision.h"
#include "scene/scene.h"
#include "support/cli_run.h"
#include "support/load_scene.h"
#include "support/scratch_files.h"

namespace pathex {
namespace {

using glm::uvec3;
using glm::vec3;
using import::loop_check;
using import::loop_counts;
using import::loop_subdivide;
using test::relative;
using test::scratch;
using test::write;

MeshShape tetrahedron() {
  MeshShape m;
  m.positions = {vec3(1, 1, 1), vec3(1, -1, -1), vec3(-1, 1, -1), vec3(-1, -1, 1)};
  m.triangles = {uvec3(0, 1, 2), uvec3(0, 3, 1), uvec3(0, 2, 3), uvec3(1, 3, 2)};  // wound outwards
  return m;
}

// The regular icosahedron of circumradius 1, wound outwards.
MeshShape icosahedron() {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  MeshShape m;
  m.positions = {vec3(-1, t, 0), vec3(1, t, 0), vec3(-1, -t, 0), vec3(1, -t, 0), vec3(0, -1, t), vec3(0, 1, t),
                 vec3(0, -1, -t), vec3(0, 1, -t), vec3(t, 0, -1), vec3(t, 0, 1), vec3(-t, 0, -1), vec3(-t, 0, 1)};
  for (vec3& p : m.positions) p = glm::normalize(p);
  m.triangles = {uvec3(0, 11, 5), uvec3(0, 5, 1),  uvec3(0, 1, 7),   uvec3(0, 7, 10), uvec3(0, 10, 11), uvec3(1, 5, 9), uvec3(5, 11, 4),
                 uvec3(11, 10, 2), uvec3(10, 7, 6), uvec3(7, 1, 8),   uvec3(3, 9, 4),  uvec3(3, 4, 2),   uvec3(3, 2, 6), uvec3(3, 6, 8),
                 uvec3(3, 8, 9),   uvec3(4, 9, 5),  uvec3(2, 4, 11),  uvec3(6, 2, 10), uvec3(8, 6, 7),   uvec3(9, 8, 1)};
  return m;
}

// Every directed edge's reverse is an edge of another triangle: the surface has no boundary.
bool closed(const MeshShape& m) {
  std::set<std::pair<unsigned, unsigned>> directed;
  for (const uvec3& t : m.triangles)
    for (int k = 0; k < 3; ++k) directed.insert({t[k], t[(k + 1) % 3]});
  for (const auto& [a, b] : directed)
    if (!directed.count({b, a})) return false;
  return directed.size() == 3 * m.triangles.size();
}

TEST(LoopSubdivision, ClosedMeshesStayClosedWithExactCountsPerLevel) {
  struct Case {
    const char* name;
    MeshShape mesh;
    std::size_t edges;
    std::vector<std::pair<std::size_t, std::size_t>> counts;  // vertices and triangles at levels 0, 1, 2, 3
  };
  // Tetrahedron: V 4, E 6, F 4 -> 10, 24, 16 -> 34, 96, 64 -> 130, 384, 256.
  // Icosahedron: V 12, E 30, F 20 -> 42, 120, 80 -> 162, 480, 320 -> 642, 1920, 1280.
  const std::vector<Case> cases = {{"tetrahedron", tetrahedron(), 6, {{4, 4}, {10, 16}, {34, 64}, {130, 256}}},
                                   {"icosahedron", icosahedron(), 30, {{12, 20}, {42, 80}, {162, 320}, {642, 1280}}}};
  for (const Case& c : cases) {
    std::size_t edges = 0;
    ASSERT_EQ(loop_check(c.mesh, &edges), std::nullopt) << c.name;
    EXPECT_EQ(edges, c.edges) << c.name;
    for (int level = 0; level <= 3; ++level) {
      const MeshShape m = loop_subdivide(c.mesh, level);
      EXPECT_EQ(m.positions.size(), c.counts[level].first) << c.name << " level " << level;
      EXPECT_EQ(m.triangles.size(), c.counts[level].second) << c.name << " level " << level;
      EXPECT_EQ(m.normals.size(), m.positions.size()) << c.name;
      const import::LoopCounts n = loop_counts(c.mesh.positions.size(), c.edges, c.mesh.triangles.size(), level);
      EXPECT_EQ(n.vertices, c.counts[level].first) << c.name << " level " << level;
      EXPECT_EQ(n.triangles, c.counts[level].second) << c.name << " level " << level;
      EXPECT_TRUE(closed(m)) << c.name << " level " << level;
      std::size_t e = 0;
      EXPECT_EQ(loop_check(m, &e), std::nullopt) << c.name << " level " << level;  // still a manifold, every point used
      EXPECT_EQ(e, 3 * m.triangles.size() / 2) << c.name << " level " << level;
    }
  }
  EXPECT_EQ(loop_counts(4, 6, 4, 64).triangles, ~std::uint64_t{0});  // saturates
}

// A valence-5 vertex p of the unit icosahedron: its neighbours sum to sqrt(5) p, and Loop's
// limit weight for valence 5 is g = 1 / (5 + 3 / (8 * 3/40)) = 1/10, so its limit is
// (1 - 5/10) p + (1/10) sqrt(5) p: radius 1/2 + sqrt(5)/10. The limit of a vertex is the same at
// every level (the limit rule is the subdivision's left eigenvector), and by symmetry its normal is
// along p: pbrt's S x T points against the winding, inwards here.
TEST(LoopSubdivision, IcosahedronLimitPointsAndNormalsOnTheirClosedForm) {
  const MeshShape ico = icosahedron();
  const float radius = 0.5f + std::sqrt(5.0f) / 10.0f;  // 0.7236068
  for (int level = 0; level <= 3; ++level) {
    const MeshShape m = loop_subdivide(ico, level);
    for (std::size_t v = 0; v < 12; ++v) {  // the control points keep their indices
      EXPECT_NEAR(glm::length(m.positions[v]), radius, 2e-6f) << "vertex " << v << " level " << level;
      EXPECT_NEAR(glm::dot(glm::normalize(m.positions[v]), glm::normalize(ico.positions[v])), 1.0f, 1e-6f) << "vertex " << v;
      EXPECT_NEAR(glm::dot(glm::normalize(m.normals[v]), glm::normalize(ico.positions[v])), -1.0f, 1e-5f) << "vertex " << v << " level " << level;
    }
  }
  // Every vertex of the closed surface is inside the control polyhedron's circumsphere and its
  // normal points inwards (pbrt's side).
  const MeshShape m = loop_subdivide(ico, 2);
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    EXPECT_LT(glm::length(m.positions[v]), 1.0f) << v;
    EXPECT_LT(glm::dot(m.normals[v], m.positions[v]), 0.0f) << v;
  }
}

// A regular (valence 6) vertex at the origin of a unit triangular lattice sampled from z = x^2:
// limit weight g = 1/12, the six neighbours' heights cos^2(k pi/3) sum to 3, so the limit height is
// 3/12 = 1/4 at every level; a plane is reproduced exactly.
TEST(LoopSubdivision, RegularVertexLimitOnAQuadraticAndAPlane) {
  MeshShape lattice;
  const int n = 4;  // points (i, j), i, j in [-n, n], at i a + j b with a = (1, 0), b = (1/2, sqrt(3)/2)
  auto index = [&](int i, int j) { return static_cast<unsigned>((i + n) * (2 * n + 1) + (j + n)); };
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j) lattice.positions.emplace_back(static_cast<float>(i) + 0.5f * static_cast<float>(j), std::sqrt(3.0f) / 2.0f * static_cast<float>(j), 0.0f);
  for (int i = -n; i < n; ++i)
    for (int j = -n; j < n; ++j) {
      lattice.triangles.emplace_back(index(i, j), index(i + 1, j), index(i, j + 1));
      lattice.triangles.emplace_back(index(i + 1, j), index(i + 1, j + 1), index(i, j + 1));
    }
  const unsigned origin = index(0, 0);
  MeshShape quadratic = lattice, plane = lattice;
  for (vec3& p : quadratic.positions) p.z = p.x * p.x;
  for (vec3& p : plane.positions) p.z = 0.25f * p.x - 0.5f * p.y + 2.0f;
  std::size_t edges = 0;
  ASSERT_EQ(loop_check(lattice, &edges), std::nullopt);
  for (int level = 0; level <= 2; ++level) {
    const MeshShape q = loop_subdivide(quadratic, level);
    EXPECT_NEAR(q.positions[origin].x, 0.0f, 1e-6f) << level;
    EXPECT_NEAR(q.positions[origin].y, 0.0f, 1e-6f) << level;
    EXPECT_NEAR(q.positions[origin].z, 0.25f, 1e-6f) << level;
    EXPECT_NEAR(std::fabs(glm::normalize(q.normals[origin]).z), 1.0f, 1e-6f) << level;  // the bottom of the trough
    const MeshShape p = loop_subdivide(plane, level);
    for (std::size_t v = 0; v < p.positions.size(); ++v) {
      const vec3 x = p.positions[v];
      ASSERT_NEAR(x.z, 0.25f * x.x - 0.5f * x.y + 2.0f, 2e-5f) << "vertex " << v << " level " << level;
    }
  }
}

// pbrt-v4's boundary limit rule is 3/5 p + 1/5 (its two boundary neighbours) (not the cubic
// B-spline's 2/3, 1/6): one triangle at level 0 moves each corner to 3/5 of itself plus 1/5 of the
// others; its normals are S x T of pbrt's boundary rule for valence 2 (S = last - first, T = first +
// last - 2 p), against the winding.
TEST(LoopSubdivision, BoundaryLimitIsPbrts) {
  MeshShape tri;
  tri.positions = {vec3(0, 0, 0), vec3(5, 0, 0), vec3(0, 5, 0)};
  tri.triangles = {uvec3(0, 1, 2)};
  const MeshShape m = loop_subdivide(tri, 0);
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_NEAR(glm::length(m.positions[0] - vec3(1, 1, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(m.positions[1] - vec3(3, 1, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(m.positions[2] - vec3(1, 3, 0)), 0.0f, 1e-6f);
  for (const vec3& n : m.normals) EXPECT_NEAR(glm::normalize(n).z, -1.0f, 1e-6f);
  const MeshShape one = loop_subdivide(tri, 1);
  ASSERT_EQ(one.positions.size(), 6u);
  ASSERT_EQ(one.triangles.size(), 4u);
  // One level: corner 0 by the even boundary rule 3/4 (0, 0) + 1/8 ((5, 0) + (0, 5)) = (5/8, 5/8),
  // its new neighbours the midpoints (2.5, 0) and (0, 2.5) of the boundary edges; its limit
  // 3/5 (5/8, 5/8) + 1/5 (2.5, 2.5) = (7/8, 7/8).
  EXPECT_NEAR(glm::length(one.positions[0] - vec3(0.875f, 0.875f, 0)), 0.0f, 1e-6f);
}

const std::string kHead = "Scale -1 1 1\nLookAt 0 0 9  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nLightSource \"point\" \"point3 from\" [0 0 5]\n";

std::string tetra_shape(const std::string& extra) {
  return "Shape \"loopsubdiv\" \"point3 P\" [1 1 1  1 -1 -1  -1 1 -1  -1 -1 1]\n  \"integer indices\" [0 1 2  0 3 1  0 2 3  1 3 2]" + extra + "\n";
}

TEST(LoopSubdivision, PbrtShapeImportsAsASmoothMesh) {
  // pbrt-v4's default is 3 levels: 130 points, 256 triangles; "scheme" is read and ignored, as pbrt-v4 does.
  const Scene s = test::load(write("loop.pbrt", kHead + "Translate 0 0 1\n" + tetra_shape(" \"string scheme\" \"loop\"")));
  ASSERT_EQ(s.shapes.size(), 1u);
  const MeshShape& m = std::get<MeshShape>(s.shapes[0].geometry);
  EXPECT_EQ(m.positions.size(), 130u);
  EXPECT_EQ(m.triangles.size(), 256u);
  ASSERT_EQ(m.normals.size(), 130u);
  const MeshShape direct = loop_subdivide(tetrahedron(), 3);
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    ASSERT_NEAR(glm::length(m.positions[v] - (direct.positions[v] + vec3(0, 0, 1))), 0.0f, 1e-5f) << v;  // placed by the CTM
    ASSERT_NEAR(glm::length(m.normals[v]), 1.0f, 1e-5f) << v;                                             // normalised
  }
  const Scene one = test::load(write("loop1.pbrt", kHead + tetra_shape(" \"integer levels\" [1]")));
  EXPECT_EQ(std::get<MeshShape>(one.shapes[0].geometry).triangles.size(), 16u);
}

struct Refusal {
  std::string file, text, where, message;
};

std::vector<Refusal> refusals() {
  return {
      {"loop-levels.pbrt", kHead + tetra_shape(" \"integer levels\" [-1]"), "loop-levels.pbrt:7:50", "levels must be 0 or more"},
      {"loop-repeat.pbrt", kHead + "Shape \"loopsubdiv\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 1]\n", "loop-repeat.pbrt:6:51",
       "triangle 0 repeats a point (0 1 1): Loop subdivision needs three distinct points per triangle"},
      {"loop-winding.pbrt", kHead + "Shape \"loopsubdiv\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0] \"integer indices\" [0 1 2 1 2 3]\n",
       "loop-winding.pbrt:6:57",
       "the edge from point 1 to point 2 is used twice in the same direction (by triangle 1 and an earlier one): Loop subdivision needs "
       "consistently wound triangles, at most two per edge"},
      {"loop-bowtie.pbrt", kHead + "Shape \"loopsubdiv\" \"point3 P\" [0 0 0 1 0 0 0 1 0 -1 0 0 0 -1 0] \"integer indices\" [0 1 2 0 3 4]\n",
       "loop-bowtie.pbrt:6:65",
       "point 0 is where separate fans of triangles meet (a non-manifold vertex): Loop subdivision needs one fan around each point"},
      {"loop-lonely.pbrt", kHead + "Shape \"loopsubdiv\" \"point3 P\" [0 0 0 1 0 0 0 1 0 5 5 5] \"integer indices\" [0 1 2]\n", "loop-lonely.pbrt:6:57",
       "point 3 is used by no triangle: Loop subdivision needs every point on the surface"},
      {"loop-range.pbrt", kHead + "Shape \"loopsubdiv\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 3]\n", "loop-range.pbrt:6:51",
       "index 3 is out of range, expected 0..2"},
      {"loop-no-indices.pbrt", kHead + "Shape \"loopsubdiv\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n", "loop-no-indices.pbrt:6:1",
       "loopsubdiv needs \"point3 P\" and \"integer indices\" (3 per triangle)"},
      {"loop-uv.pbrt", kHead + tetra_shape(" \"point2 uv\" [0 0 1 0 0 1 1 1]"), "loop-uv.pbrt:7:50",
       "parameter \"point2 uv\" of Shape \"loopsubdiv\" is not supported"},
  };
}

TEST(LoopSubdivision, RefusalsNameFileLineColumnAndWhat) {
  for (const Refusal& r : refusals()) {
    const Result<Scene> s = load_scene_file(write(r.file, r.text));
    ASSERT_FALSE(s.ok()) << r.file;
    EXPECT_EQ(relative(s.error().where), r.where) << r.file;
    EXPECT_EQ(relative(s.error().message), r.message) << r.file;
  }
  const test::CliRun run = test::run_pathex("trace " + write(refusals()[3].file, refusals()[3].text) + " --quiet --out " + scratch() + "/out");
  EXPECT_EQ(run.code, 2);
  EXPECT_EQ(relative(run.err), "pathex: error: " + refusals()[3].where + ": " + refusals()[3].message + "\n");
}

// The element limit is checked on the counts before anything is subdivided: 12 levels of a
// tetrahedron would be 4^12 * 4 = 67,108,864 triangles.
TEST(LoopSubdivision, TheElementLimitHoldsBeforeSubdividing) {
  SceneLoadOptions options;
  options.max_mesh_elements = 1000;
  const Result<Scene> fits = load_scene_file(write("loop-fits.pbrt", kHead + tetra_shape(" \"integer levels\" [3]")), options);
  EXPECT_TRUE(fits.ok());  // 130 + 256
  const Result<Scene> s = load_scene_file(write("loop-big.pbrt", kHead + tetra_shape(" \"integer levels\" [12]")), options);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kLimit);
  EXPECT_EQ(relative(s.error().where), "loop-big.pbrt:6:1");
  // A billion levels: the counts saturate after 32 and the refusal is as quick.
  const Result<Scene> huge = load_scene_file(write("loop-huge.pbrt", kHead + tetra_shape(" \"integer levels\" [1000000000]")), options);
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.error().code, ErrorCode::kLimit);
}

}  // namespace
}  // namespace pathex
