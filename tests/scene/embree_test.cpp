// The Embree layer: the two-ray smoke test, exact analytic intersections (t to 1e-6 relative),
// raw tmin/tmax queries, surface parameters, area sampling integrating known integrals with
// pdf = 1/area, robustness of the self-intersection offset for scenes scaled by 1e-4 and 1e+4 and
// far from the origin, and concurrent queries.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <fstream>
#include <random>
#include <thread>

#include "scene/scene.h"
#include "trace/accel/eye_ahead.h"
#include "trace/embree_scene.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex {
namespace {

using glm::vec3;
constexpr double kPiD = 3.14159265358979323846;

Scene one_shape(const std::string& shapes_json) {
  const std::string text = R"({"camera": {"type": "pinhole", "position": [0, 0, 5], "look_at": [0, 0, 0]},
    "materials": {"m": {"type": "diffuse"}}, "shapes": [)" + shapes_json +
                           R"(], "lights": [{"type": "point", "position": [0, 0, 3], "intensity": [1, 1, 1]}]})";
  Result<Scene> s = load_scene_json(text, "/tmp", "inline");
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().render());
  return s.ok() ? *s : Scene{};
}

// Uniform numbers in [0, 1) from a fixed-seed engine.
struct Uniform {
  std::mt19937 engine{12345};
  float next() { return static_cast<float>(engine() >> 8) * 0x1p-24f; }
  glm::vec2 next2() {
    const float a = next();
    return {a, next()};
  }
};

TEST(Embree, TwoRaySmokeTest) {
  // A triangle in the plane z = 0; one ray hits it at t = 1, one misses.
  std::ofstream("/tmp/pathex-smoke.obj") << "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n";
  const Scene s = one_shape(R"({"type": "mesh", "file": "pathex-smoke.obj", "material": "m"})");
  auto es = EmbreeScene::build(s);
  ASSERT_TRUE(es.ok()) << es.error().render();
  const std::optional<Hit> hit = (*es)->intersect({0, 0, 1}, {0, 0, -1}, 0.0f, INFINITY);
  ASSERT_TRUE(hit.has_value());
  EXPECT_FLOAT_EQ(hit->t, 1.0f);
  EXPECT_EQ(hit->shape, 0);
  EXPECT_EQ(hit->primitive, 0);
  EXPECT_EQ(hit->normal, vec3(0, 0, 1));
  EXPECT_EQ(hit->shading_normal, vec3(0, 0, 1));
  // (0, 0) = 1/4 p0 + 1/4 p1 + 1/2 p2; without uv pbrt-v4's (0, 0), (1, 0), (1, 1) at the corners.
  EXPECT_NEAR(hit->uv.x, 0.75f, 1e-6f);
  EXPECT_NEAR(hit->uv.y, 0.5f, 1e-6f);
  EXPECT_FALSE((*es)->intersect({5, 5, 1}, {0, 0, -1}, 0.0f, INFINITY).has_value());
  // With the file's uv: interpolated with the same weights.
  std::ofstream("/tmp/pathex-smoke-uv.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                               "property float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\n"
                                               "end_header\n-1 -1 0 0.2 0.1\n1 -1 0 0.6 0.1\n0 1 0 0.4 0.9\n3 0 1 2\n";
  const Scene t = one_shape(R"({"type": "mesh", "file": "pathex-smoke-uv.ply", "material": "m"})");
  auto et = EmbreeScene::build(t);
  ASSERT_TRUE(et.ok()) << et.error().render();
  const std::optional<Hit> uv_hit = (*et)->intersect({0, 0, 1}, {0, 0, -1}, 0.0f, INFINITY);
  ASSERT_TRUE(uv_hit.has_value());
  EXPECT_NEAR(uv_hit->uv.x, 0.25f * 0.2f + 0.25f * 0.6f + 0.5f * 0.4f, 1e-6f);
  EXPECT_NEAR(uv_hit->uv.y, 0.25f * 0.1f + 0.25f * 0.1f + 0.5f * 0.9f, 1e-6f);
}

// Debian's Embree aborts the process on a non-finite ray (an assertion); the queries must keep
// such a ray from it: no hit, and blocked, so it carries no light.
TEST(Embree, NonFiniteRaysNeverReachEmbree) {
  const Scene s = one_shape(R"({"type": "quad", "corner": [-1, -1, 0], "edge1": [2, 0, 0], "edge2": [0, 2, 0], "material": "m"})");
  auto es = EmbreeScene::build(s);
  ASSERT_TRUE(es.ok()) << es.error().render();
  const float nan = std::nanf(""), inf = INFINITY;
  for (const auto& [o, d] : std::vector<std::pair<vec3, vec3>>{
           {{0, 0, 1}, {nan, 0, -1}}, {{nan, 0, 1}, {0, 0, -1}}, {{0, 0, 1}, {0, inf, -1}}, {{0, -inf, 1}, {0, 0, -1}}}) {
    EXPECT_FALSE((*es)->intersect(o, d, 0.0f, INFINITY).has_value());
    EXPECT_TRUE((*es)->occluded(o, d, 0.0f, 1.0f));
    EXPECT_FALSE((*es)->visible(o, o + d));
  }
  EXPECT_TRUE((*es)->intersect({0, 0, 1}, {0, 0, -1}, 0.0f, INFINITY).has_value()) << "a finite ray still hits";
}

TEST(Embree, ExactAnalyticIntersections) {
  const Scene s = one_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "m"},
                              {"type": "disk", "center": [0, 0, -2], "normal": [0, 0, 1], "radius": 1, "material": "m"},
                              {"type": "quad", "corner": [-1, -1, -3], "edge1": [2, 0, 0], "edge2": [0, 2, 0], "material": "m"})");
  auto es = EmbreeScene::build(s);
  ASSERT_TRUE(es.ok());
  const vec3 none(0.0f);
  const auto sphere = (*es)->intersect({0, 0, 3}, {0, 0, -1}, none, none);
  ASSERT_TRUE(sphere);
  EXPECT_NEAR(sphere->t, 2.5f, 2.5e-6f);
  EXPECT_EQ(sphere->shape, 0);
  EXPECT_EQ(sphere->normal, vec3(0, 0, 1));
  // Off-centre: the chord at height 0.3 enters at z = sqrt(0.25 - 0.09) = 0.4.
  const auto chord = (*es)->intersect({0.3f, 0, 3}, {0, 0, -1}, none, none);
  ASSERT_TRUE(chord);
  EXPECT_NEAR(chord->t, 2.6f, 2.6e-6f);
  EXPECT_NEAR(glm::distance(chord->normal, vec3(0.6f, 0, 0.8f)), 0.0f, 1e-6f);
  // A direction that is not unit: t scales with it.
  const auto scaled = (*es)->intersect({0.3f, 0, 3}, {0, 0, -4}, none, none);
  ASSERT_TRUE(scaled);
  EXPECT_NEAR(scaled->t, 0.65f, 0.65e-6f);
  // From inside the sphere outwards (the closed-sphere scenes).
  const auto inside = (*es)->intersect({0, 0, 0}, {0, 1, 0}, none, none);
  ASSERT_TRUE(inside);
  EXPECT_NEAR(inside->t, 0.5f, 1e-6f);
  // A ray far from the sphere, nearly tangent: the stable quadratic still finds t exactly. The
  // ray x = 0.49, starting 1e4 away along z, meets the sphere at z = sqrt(0.25 - 0.49^2).
  const auto far = (*es)->intersect({0.49f, 0, 1e4f}, {0, 0, -1}, none, none);
  ASSERT_TRUE(far);
  EXPECT_NEAR(far->t, 1e4 - std::sqrt(0.25 - 0.49 * 0.49), 1e4 * 1e-6);
  const auto disk = (*es)->intersect({0.7f, 0, 3}, {0, 0, -1}, none, none);
  ASSERT_TRUE(disk);
  EXPECT_EQ(disk->shape, 1);
  EXPECT_NEAR(disk->t, 5.0f, 5e-6f);
  EXPECT_FALSE((*es)->intersect({0.7f, 0.72f, 3}, {0, 0, -1}, 0.0f, 5.5f));  // outside the disk (r > 1), before the quad
  const auto quad = (*es)->intersect({0.95f, 0.95f, 3}, {0, 0, -1}, none, none);
  ASSERT_TRUE(quad);
  EXPECT_EQ(quad->shape, 2);
  EXPECT_NEAR(quad->t, 6.0f, 6e-6f);
  EXPECT_NEAR(quad->uv.x, 0.975f, 1e-6f);
  EXPECT_NEAR(quad->uv.y, 0.975f, 1e-6f);
  // Visibility between the sphere's top and a point above it, and through it.
  EXPECT_TRUE((*es)->visible({0, 0.5f, 0}, {0, 1, 0}, vec3(1e-7f), {0, 2, 0}, none, none));
  EXPECT_FALSE((*es)->visible({0, 0, 2}, {0, 0, -1.5f}));
  EXPECT_TRUE((*es)->visible({0, 0, 2}, {0, 0, 0.6f}));
}

TEST(Embree, RawQueriesHonourTminAndTmax) {
  const Scene s = one_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"},
                              {"type": "quad", "corner": [-1, -1, -3], "edge1": [2, 0, 0], "edge2": [0, 2, 0], "material": "m"})");
  auto es = EmbreeScene::build(s);
  ASSERT_TRUE(es.ok());
  const vec3 o(0, 0, 3), d(0, 0, -1);
  ASSERT_TRUE((*es)->intersect(o, d, 0.0f, INFINITY));
  EXPECT_NEAR((*es)->intersect(o, d, 0.0f, INFINITY)->t, 2.0f, 2e-6f);   // sphere, entering
  EXPECT_NEAR((*es)->intersect(o, d, 2.5f, INFINITY)->t, 4.0f, 4e-6f);   // sphere, leaving
  EXPECT_EQ((*es)->intersect(o, d, 4.5f, INFINITY)->shape, 1);           // then the quad at 6
  EXPECT_NEAR((*es)->intersect(o, d, 4.5f, INFINITY)->t, 6.0f, 6e-6f);
  EXPECT_FALSE((*es)->intersect(o, d, 0.0f, 1.9f));
  EXPECT_FALSE((*es)->intersect(o, d, 6.1f, INFINITY));
  EXPECT_TRUE((*es)->occluded(o, d, 0.0f, 2.1f));
  EXPECT_FALSE((*es)->occluded(o, d, 0.0f, 1.9f));
  EXPECT_TRUE((*es)->occluded(o, d, 4.5f, 6.1f));
  EXPECT_FALSE((*es)->occluded(o, d, 4.1f, 5.9f));
}

TEST(Embree, SurfaceParametersOfSpheresAndDisks) {
  const Scene s = one_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 2, "material": "m"},
                              {"type": "disk", "center": [10, 0, 0], "normal": [0, 0, 1], "radius": 2, "material": "m"})");
  auto es = EmbreeScene::build(s);
  ASSERT_TRUE(es.ok());
  // The sphere's equator at phi = 90 degrees: u = 1/4, v = 1/2; its +z pole: v = 0.
  const auto eq = (*es)->intersect({0, 5, 0}, {0, -1, 0}, 0.0f, INFINITY);
  ASSERT_TRUE(eq);
  EXPECT_NEAR(eq->uv.x, 0.25f, 1e-6f);
  EXPECT_NEAR(eq->uv.y, 0.5f, 1e-6f);
  const auto pole = (*es)->intersect({0, 0, 5}, {0, 0, -1}, 0.0f, INFINITY);
  ASSERT_TRUE(pole);
  EXPECT_NEAR(pole->uv.y, 0.0f, 1e-3f);
  // The disk: v is the distance from the centre over the radius.
  const auto d = (*es)->intersect({11, 0, 5}, {0, 0, -1}, 0.0f, INFINITY);
  ASSERT_TRUE(d);
  EXPECT_NEAR(d->uv.y, 0.5f, 1e-6f);
  EXPECT_EQ(d->position, vec3(11, 0, 0));
  EXPECT_EQ((*es)->normal_at(1, 0, d->position), vec3(0, 0, 1));
  EXPECT_NEAR(glm::distance((*es)->normal_at(0, 0, vec3(0, 2, 0)), vec3(0, 1, 0)), 0.0f, 1e-7f);
}

// uv_at (for points found otherwise than by a ray: the manifold's solved chains) gives what a hit
// at that point gives, on every kind of shape: a sphere, a disk, a quad and a mesh with uv.
TEST(Embree, UvAtAPointIsTheHitsUv) {
  Scene s = one_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 2, "material": "m"},
                        {"type": "disk", "center": [10, 0, 0], "normal": [0, 0, 1], "radius": 2, "material": "m"},
                        {"type": "quad", "corner": [20, -1, 0], "edge1": [2, 0, 0], "edge2": [0, 3, 0], "material": "m"})");
  ASSERT_EQ(s.shapes.size(), 3u);
  Shape mesh = s.shapes[2];
  MeshShape m;
  m.positions = {{30, -1, 0}, {32, -1, 0}, {30, 2, 0}};
  m.triangles = {{0u, 1u, 2u}};
  m.uvs = {{0.1f, 0.2f}, {0.9f, 0.3f}, {0.4f, 0.8f}};
  mesh.geometry = m;
  s.shapes.push_back(mesh);
  auto es = EmbreeScene::build(s);
  ASSERT_TRUE(es.ok());
  Uniform rng;
  int hits[4] = {0, 0, 0, 0};
  for (int i = 0; i < 200; ++i) {
    const glm::vec2 u = rng.next2();
    const float x0[4] = {0.0f, 10.0f, 20.0f, 30.0f};
    const int shape = i % 4;
    const vec3 origin(x0[shape] + 3.0f * u.x - 1.0f, 2.5f * u.y - 1.0f, 5.0f);
    const auto hit = (*es)->intersect(origin, {0, 0, -1}, 0.0f, INFINITY);
    if (!hit || hit->shape != shape) continue;
    ++hits[shape];
    const glm::vec2 at = (*es)->uv_at(hit->shape, hit->primitive, hit->position);
    EXPECT_NEAR(at.x, hit->uv.x, 2e-5f) << "shape " << shape;
    EXPECT_NEAR(at.y, hit->uv.y, 2e-5f) << "shape " << shape;
  }
  for (int n : hits) EXPECT_GE(n, 10);
}

// --- sampling: E[f(X) / pdf] is the integral of f over the shape ---
TEST(Embree, AreaSamplingIntegratesKnownIntegrals) {
  std::ofstream("/tmp/pathex-two.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 10 0 0\nv 13 0 0\nv 10 1 0\nf 1 2 3\nf 4 5 6\n";
  const Scene s = one_shape(R"({"type": "sphere", "center": [1, 2, 3], "radius": 2, "material": "m"},
                              {"type": "disk", "center": [0, 0, 0], "normal": [0, 1, 0], "radius": 1.5, "material": "m"},
                              {"type": "mesh", "file": "pathex-two.obj", "material": "m"},
                              {"type": "quad", "corner": [0, 0, -4], "edge1": [2, 0, 0], "edge2": [1, 3, 0], "material": "m"})");
  auto es = EmbreeScene::build(s);
  ASSERT_TRUE(es.ok());
  EXPECT_NEAR((*es)->shape_area(0), 4 * kPiD * 4, 1e-4);
  EXPECT_NEAR((*es)->shape_area(1), kPiD * 2.25, 1e-5);
  EXPECT_NEAR((*es)->shape_area(2), 0.5 + 1.5, 1e-6);
  EXPECT_NEAR((*es)->shape_area(3), 6.0, 1e-6);
  EXPECT_FLOAT_EQ((*es)->area_pdf(3), 1.0f / 6.0f);
  // Integrals in closed form: sphere of radius R about c, (z - c_z)^2 dA = 4 pi R^4 / 3; disk,
  // r^2 dA = pi R^4 / 2; the two triangles, x dA = 0.5 * 1/3 + 1.5 * 11; the parallelogram,
  // x dA = area * x of its centre (1.5).
  struct Case {
    int shape;
    double exact;
    double (*f)(vec3);
  };
  const Case cases[] = {
      {0, 4 * kPiD * 16 / 3, [](vec3 p) { return double(p.z - 3) * double(p.z - 3); }},
      {1, kPiD * std::pow(1.5, 4) / 2, [](vec3 p) { return double(glm::dot(p, p)); }},
      {2, 0.5 / 3 + 1.5 * 11, [](vec3 p) { return double(p.x); }},
      {3, 6.0 * 1.5, [](vec3 p) { return double(p.x); }},
  };
  for (const Case& c : cases) {
    Uniform u;
    const int n = 20000;
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
      const SurfaceSample x = (*es)->sample_shape(c.shape, u.next2());
      // Each sample carries the shape's normal there (both triangles of the mesh face +z).
      EXPECT_NEAR(glm::distance(x.normal, (*es)->normal_at(c.shape, 0, x.position)), 0.0f, 1e-5f);
      const double v = c.f(x.position) / double((*es)->area_pdf(c.shape));
      sum += v;
      sum2 += v * v;
    }
    const double mean = sum / n, sd = std::sqrt((sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, c.exact, 4 * sd + 1e-9) << "shape " << c.shape;
  }
  // The sphere's samples are on the sphere, the disk's on the disk.
  Uniform u;
  for (int i = 0; i < 2000; ++i) {
    EXPECT_NEAR(glm::length((*es)->sample_shape(0, u.next2()).position - vec3(1, 2, 3)), 2.0f, 2e-6f);
    const SurfaceSample b = (*es)->sample_shape(1, u.next2());
    EXPECT_NEAR(b.position.y, 0.0f, 1e-6f);
    EXPECT_LE(glm::length(b.position), 1.5f + 1e-5f);
  }
}

// --- robustness: random walks inside a closed box and inside a closed sphere ---
// The box [-1, 1]^3 of six quads holds a sphere, a pyramid mesh and a disk; the whole scene is
// scaled by s and moved by T. From a point inside, each walk bounces 6 times, leaving each surface
// on the side it arrived from, in a uniform direction or a grazing one (cos = 1e-3). Every ray
// must hit something (the box is closed), never the convex or flat shape it leaves, and the
// segment it traced must be visible between its two surface points: never blocked by its own
// ends, and by a third shape's silhouette (the shadow ray runs between the offset points, not
// quite along the traced line) at most once in a thousand rays. A unit box 1e5 from the
// origin is not among the cases: its float coordinates step by 0.0078 (0.4 % of the box), and
// the sphere resting on the floor then has no well-defined contact; a box of size 200 there
// (DESIGN §10 asks for 2e4) is.
// With `far`, the scene also holds far-off, large shapes outside the box: a ground mesh of two
// triangles 1e6 below spanning 2e7, a sphere of radius 1e5 at 1e6 and a quad 1e19 away. Offsets
// come from each point's own error bound, so they must change nothing inside the box.
Scene box_scene(float s, vec3 t, bool far = false) {
  Scene scene;
  scene.materials = {Diffuse{}};
  scene.material_names = {"m"};
  auto add = [&](ShapeGeometry g) {
    Shape shape;
    shape.geometry = std::move(g);
    scene.shapes.push_back(std::move(shape));
  };
  auto P = [&](vec3 p) { return t + s * p; };
  auto V = [&](vec3 v) { return s * v; };
  // Six walls, normals pointing inwards.
  add(QuadShape{P({-1, -1, -1}), V({0, 0, 2}), V({2, 0, 0})});  // floor y = -1
  add(QuadShape{P({-1, 1, -1}), V({2, 0, 0}), V({0, 0, 2})});   // ceiling
  add(QuadShape{P({-1, -1, -1}), V({2, 0, 0}), V({0, 2, 0})});  // back z = -1
  add(QuadShape{P({-1, -1, 1}), V({0, 2, 0}), V({2, 0, 0})});   // front
  add(QuadShape{P({-1, -1, -1}), V({0, 2, 0}), V({0, 0, 2})});  // left x = -1
  add(QuadShape{P({1, -1, -1}), V({0, 0, 2}), V({0, 2, 0})});   // right
  add(SphereShape{P({0.4f, -0.6f, 0}), 0.4f * s});
  MeshShape pyramid;
  for (vec3 p : {vec3(-0.8f, -1, -0.8f), vec3(-0.2f, -1, -0.8f), vec3(-0.2f, -1, -0.2f), vec3(-0.8f, -1, -0.2f), vec3(-0.5f, -0.4f, -0.5f)})
    pyramid.positions.push_back(P(p));
  pyramid.triangles = {{0, 2, 1}, {0, 3, 2}, {3, 2, 4}, {2, 1, 4}, {1, 0, 4}, {0, 3, 4}};
  add(std::move(pyramid));
  add(DiskShape{P({0, 0.2f, -0.9f}), vec3(0, 0, 1), 0.3f * s});
  if (far) {
    MeshShape ground;
    ground.positions = {vec3(-1e7f, -1e6f, -1e7f), vec3(1e7f, -1e6f, -1e7f), vec3(1e7f, -1e6f, 1e7f), vec3(-1e7f, -1e6f, 1e7f)};
    ground.triangles = {{0, 2, 1}, {0, 3, 2}};
    add(std::move(ground));
    add(SphereShape{vec3(1e6f, 0, 0), 1e5f});
    add(QuadShape{vec3(-1e19f, 1e19f, -1e19f), vec3(2e19f, 0, 0), vec3(0, 0, 2e19f)});
  }
  return scene;
}

vec3 walk_direction(Uniform& u, vec3 n, bool grazing) {
  const vec3 a = std::fabs(n.x) > 0.5f ? vec3(0, 1, 0) : vec3(1, 0, 0);
  const vec3 t1 = glm::normalize(glm::cross(n, a)), t2 = glm::cross(n, t1);
  const float phi = 2 * 3.14159265f * u.next();
  const float c = grazing ? 1e-3f : std::sqrt(u.next());  // cosine-distributed otherwise
  const float sn = std::sqrt(1 - c * c);
  return glm::normalize(c * n + sn * (std::cos(phi) * t1 + std::sin(phi) * t2));
}

struct WalkStats {
  int rays = 0, escaped = 0, self_hits = 0, invisible = 0, grazing = 0, outside = 0;
};

WalkStats walk_box(float s, vec3 t, bool far = false) {
  const Scene scene = box_scene(s, t, far);
  auto es = EmbreeScene::build(scene);
  EXPECT_TRUE(es.ok());
  WalkStats st;
  Uniform u;
  for (int path = 0; path < 1500; ++path) {
    vec3 p = t + s * vec3(0.3f, 0.5f, 0.6f), n(0.0f), e(0.0f);
    int shape = -1;
    vec3 d = walk_direction(u, glm::normalize(vec3(u.next() - 0.5f, u.next() - 0.5f, u.next() - 0.5f)), false);
    for (int bounce = 0; bounce < 6; ++bounce) {
      ++st.rays;
      const std::optional<Hit> h = (*es)->intersect(p, d, n, e);
      if (!h) {
        ++st.escaped;
        break;
      }
      if (h->shape == shape) ++st.self_hits;
      // Inside the box, up to 1e-3 of its size and the rounding of coordinates as large as t.
      const vec3 local = (h->position - t) / s;
      const float slack = 1e-3f + 4e-7f * std::max(std::fabs(t.x), std::max(std::fabs(t.y), std::fabs(t.z))) / s;
      if (glm::any(glm::greaterThan(glm::abs(local), vec3(1.0f + slack)))) ++st.outside;
      if (!(*es)->visible(p, n, e, h->position, h->normal, h->error)) {
        // Blocked by one of its own ends is an offset failure; by a third shape, the shadow ray
        // (between the two offset points, not quite the traced line) grazed its silhouette.
        vec3 o, to;
        EmbreeScene::shadow_ray(p, n, e, h->position, h->normal, h->error, &o, &to);
        const std::optional<Hit> b = (*es)->intersect(o, to, 0.0f, 1.0f);
        ++(b && b->shape != shape && b->shape != h->shape ? st.grazing : st.invisible);
      }
      const vec3 side = glm::dot(h->normal, d) < 0 ? h->normal : -h->normal;
      p = h->position;
      n = h->normal;
      e = h->error;
      shape = h->shape;
      d = walk_direction(u, side, bounce % 3 == 2);
    }
  }
  return st;
}

void expect_robust(const WalkStats& st) {
  EXPECT_GT(st.rays, 5000);
  EXPECT_EQ(st.escaped, 0);
  EXPECT_EQ(st.self_hits, 0);
  EXPECT_EQ(st.invisible, 0);
  EXPECT_LE(st.grazing, st.rays / 1000);
  EXPECT_EQ(st.outside, 0);
}

TEST(EmbreeRobustness, BoxWalksAtEveryScaleAndOffset) {
  struct Config {
    float scale;
    vec3 offset;
  };
  const Config configs[] = {
      {1.0f, vec3(0.0f)}, {1e-4f, vec3(0.0f)}, {1e4f, vec3(0.0f)}, {1.0f, vec3(1e3f, -1e3f, 1e3f)}, {1e2f, vec3(1e5f, -1e5f, 1e5f)}, {1e4f, vec3(1e5f, 1e5f, -1e5f)},
  };
  for (const Config& c : configs) {
    const WalkStats st = walk_box(c.scale, c.offset);
    SCOPED_TRACE(testing::Message() << "scale " << c.scale << " offset " << c.offset.x);
    expect_robust(st);
  }
}

TEST(EmbreeRobustness, FarLargeShapesChangeNothingInsideTheBox) {
  expect_robust(walk_box(1.0f, vec3(0.0f), /*far=*/true));
}

TEST(EmbreeRobustness, ClosedSphereChordsAtEveryScale) {
  // Inside a sphere of radius R, a ray leaving a wall point at angle theta to the inward normal
  // meets the wall again after the chord 2 R cos(theta). The origin moves inwards by the offset
  // eps, which lengthens the chord by about eps / cos(theta): the check allows that plus 1e-4 R
  // for cos(theta) >= 0.1; grazing rays (cos = 1e-3) must at least not hit their own origin.
  for (const auto& [scale, offset] : {std::pair{1.0f, vec3(0.0f)}, std::pair{1e-4f, vec3(0.0f)}, std::pair{1e4f, vec3(0.0f)},
                                      std::pair{1e4f, vec3(-1e5f, 1e5f, 1e5f)}}) {
    Scene scene;
    scene.materials = {Diffuse{}};
    scene.material_names = {"m"};
    Shape sphere;
    sphere.geometry = SphereShape{offset, scale};
    scene.shapes.push_back(sphere);
    auto es = EmbreeScene::build(scene);
    ASSERT_TRUE(es.ok());
    Uniform u;
    int bad = 0;
    for (int path = 0; path < 500; ++path) {
      vec3 p = offset, n(0.0f), e(0.0f);
      vec3 d = walk_direction(u, vec3(0, 1, 0), false);
      for (int bounce = 0; bounce < 6; ++bounce) {
        const std::optional<Hit> h = (*es)->intersect(p, d, n, e);
        if (!h) {
          ++bad;
          break;
        }
        if (bounce > 0) {
          const float cos_theta = glm::dot(d, -n), chord = 2.0f * scale * cos_theta;
          const float found = glm::distance(h->position, p);
          if (cos_theta >= 0.1f ? std::fabs(found - chord) > 1e-4f * scale + 2.0f * glm::dot(glm::abs(n), e) / cos_theta
                                : !(found > 0.5f * chord))
            ++bad;
        }
        if (std::fabs(glm::distance(h->position, offset) - scale) > 1e-5f * scale) ++bad;
        p = h->position;
        n = h->normal;
        e = h->error;
        d = walk_direction(u, -n, bounce % 3 == 2);
      }
    }
    EXPECT_EQ(bad, 0) << "scale " << scale << " offset " << offset.x;
  }
}

// Watertightness: rays from inside a closed surface aimed exactly at the seams its primitives
// share (a box's edges and corners between its six quads, each quad's own diagonal, where Embree
// splits it into two triangles; a closed octahedron mesh's edges and vertices) must hit it. A
// ray that slips between two primitives would leave a closed room (light leaks through its
// corners) and, inside glass, a closed object. RTC_SCENE_FLAG_ROBUST selects Embree's
// watertight intersectors (Plücker coordinates); its default Möller tests are not watertight
// and fail this test (bench/README.md, "Issue 39, twenty-second session").
TEST(EmbreeRobustness, RaysAimedAtSharedEdgesAndCornersNeverSlipThrough) {
  for (const auto& [scale, offset] : {std::pair{1.0f, vec3(0.0f)}, std::pair{1e-3f, vec3(0.0f)}, std::pair{1e3f, vec3(0.0f)},
                                      std::pair{1.0f, vec3(300.0f, -200.0f, 100.0f)}}) {
    Scene scene;
    scene.materials = {Diffuse{}};
    scene.material_names = {"m"};
    const auto P = [&](vec3 p) { return offset + scale * p; };
    const auto V = [&](vec3 v) { return scale * v; };
    for (ShapeGeometry g : {ShapeGeometry{QuadShape{P({-1, -1, -1}), V({0, 0, 2}), V({2, 0, 0})}},
                            ShapeGeometry{QuadShape{P({-1, 1, -1}), V({2, 0, 0}), V({0, 0, 2})}},
                            ShapeGeometry{QuadShape{P({-1, -1, -1}), V({2, 0, 0}), V({0, 2, 0})}},
                            ShapeGeometry{QuadShape{P({-1, -1, 1}), V({0, 2, 0}), V({2, 0, 0})}},
                            ShapeGeometry{QuadShape{P({-1, -1, -1}), V({0, 2, 0}), V({0, 0, 2})}},
                            ShapeGeometry{QuadShape{P({1, -1, -1}), V({0, 0, 2}), V({0, 2, 0})}}}) {
      Shape shape;
      shape.geometry = g;
      scene.shapes.push_back(shape);
    }
    auto es = EmbreeScene::build(scene);
    ASSERT_TRUE(es.ok());
    // The octahedron |x| + |y| + |z| = 0.5, alone in a scene of its own.
    Scene octa_scene;
    octa_scene.materials = {Diffuse{}};
    octa_scene.material_names = {"m"};
    MeshShape octa;
    for (vec3 p : {vec3(0.5f, 0, 0), vec3(-0.5f, 0, 0), vec3(0, 0.5f, 0), vec3(0, -0.5f, 0), vec3(0, 0, 0.5f), vec3(0, 0, -0.5f)})
      octa.positions.push_back(P(p));
    octa.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    Shape octa_shape;
    octa_shape.geometry = std::move(octa);
    octa_scene.shapes.push_back(std::move(octa_shape));
    auto eo = EmbreeScene::build(octa_scene);
    ASSERT_TRUE(eo.ok());
    // Seams as segments (a, b) of the unit shapes; a target is a float point on one of them.
    std::vector<std::pair<vec3, vec3>> box_seams, octa_seams;
    const vec3 c[8] = {{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {-1, 1, 1}, {1, 1, 1}};
    for (int i = 0; i < 8; ++i)
      for (int j = i + 1; j < 8; ++j) {
        const int differ = (c[i].x != c[j].x) + (c[i].y != c[j].y) + (c[i].z != c[j].z);
        if (differ <= 2) box_seams.push_back({c[i], c[j]});  // the 12 edges and the 12 face diagonals (both of each face)
      }
    const vec3 o[6] = {{0.5f, 0, 0}, {-0.5f, 0, 0}, {0, 0.5f, 0}, {0, -0.5f, 0}, {0, 0, 0.5f}, {0, 0, -0.5f}};
    for (int i = 0; i < 6; ++i)
      for (int j = i + 1; j < 6; ++j)
        if (glm::dot(o[i], o[j]) == 0.0f) octa_seams.push_back({o[i], o[j]});  // its 12 edges
    Uniform u;
    int box_slipped = 0, octa_slipped = 0, rays = 0;
    for (int r = 0; r < 20000; ++r) {
      for (int which = 0; which < 2; ++which) {
        const auto& seams = which == 0 ? box_seams : octa_seams;
        const auto& [a, b] = seams[static_cast<std::size_t>(u.next() * static_cast<float>(seams.size()))];
        // Every 8th target a corner (a seam's end), the rest along the seam.
        const float f = r % 8 == 0 ? 0.0f : u.next();
        const vec3 target = P(a + f * (b - a));
        const float reach = which == 0 ? 0.9f : 0.3f;  // origins inside either shape
        const vec3 origin = P(reach * (2.0f * vec3(u.next(), u.next(), u.next()) - 1.0f) / (which == 0 ? 1.0f : 3.0f));
        const vec3 d = glm::normalize(target - origin);
        ++rays;
        const std::optional<Hit> h = (which == 0 ? *es : *eo)->intersect(origin, d, 0.0f, INFINITY);
        if (!h) ++(which == 0 ? box_slipped : octa_slipped);
      }
    }
    EXPECT_EQ(box_slipped, 0) << "scale " << scale << " offset " << offset.x << ", " << rays << " rays";
    EXPECT_EQ(octa_slipped, 0) << "scale " << scale << " offset " << offset.x << ", " << rays << " rays";
  }
}

TEST(Embree, ConcurrentQueriesAgreeWithSerialOnes) {
  const Scene scene = box_scene(1.0f, vec3(0.0f));
  auto es = EmbreeScene::build(scene);
  ASSERT_TRUE(es.ok());
  std::vector<vec3> dirs;
  Uniform u;
  for (int i = 0; i < 20000; ++i) dirs.push_back(walk_direction(u, vec3(0, 1, 0), false) * (u.next() < 0.5f ? 1.0f : -1.0f));
  auto run = [&](std::size_t begin, std::size_t end, std::vector<float>* out) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto h = (*es)->intersect(vec3(0.1f, 0.2f, 0.3f), dirs[i], vec3(0.0f), vec3(0.0f));
      (*out)[i] = h ? h->t + 100.0f * static_cast<float>(h->shape) : -1.0f;
    }
  };
  std::vector<float> serial(dirs.size()), parallel(dirs.size());
  run(0, dirs.size(), &serial);
  std::thread a(run, 0, dirs.size() / 2, &parallel), b(run, dirs.size() / 2, dirs.size(), &parallel);
  a.join();
  b.join();
  EXPECT_EQ(serial, parallel);
  EXPECT_EQ(std::count(serial.begin(), serial.end(), -1.0f), 0);  // the box is closed
}

// Shadow rays traced together (an Embree packet, or one by one for a small batch) give the
// answers visible() gives for each alone: segments between points sampled on the Cornell box's
// quads and spheres (user geometry), points in free space, coincident points and non-finite ones,
// at every batch size from 1 to full.
TEST(Embree, OcclusionBatchAgreesWithVisibleAtEveryBatchSize) {
  Result<Scene> scene = load_scene_json(default_scene_json(), ".", "default");
  ASSERT_TRUE(scene.ok());
  auto es = EmbreeScene::build(*scene);
  ASSERT_TRUE(es.ok());
  struct Point {
    vec3 p, n, e;
  };
  std::vector<Point> points;
  Uniform u;
  for (int i = 0; i < 400; ++i) {
    const int shape = i % static_cast<int>(scene->shapes.size());
    const SurfaceSample ss = (*es)->sample_shape(shape, u.next2());
    points.push_back({ss.position, ss.normal, ss.error});
  }
  for (int i = 0; i < 20; ++i) points.push_back({vec3(u.next(), u.next(), u.next()) * 2.0f - 1.0f, vec3(0.0f), vec3(0.0f)});
  points.push_back({vec3(std::nanf(""), 0, 0), vec3(0.0f), vec3(0.0f)});
  points.push_back({vec3(0, INFINITY, 0), vec3(0, 1, 0), vec3(1e-7f)});
  std::mt19937 pick(7);
  int agree = 0, blocked = 0, open = 0;
  OcclusionBatch batch;
  for (int round = 0; round < 400; ++round) {
    const int size = 1 + round % OcclusionBatch::kCapacity;
    std::vector<std::pair<Point, Point>> segments;
    for (int i = 0; i < size; ++i) {
      const Point& a = points[pick() % points.size()];
      const Point& b = i == 0 && round % 7 == 0 ? a : points[pick() % points.size()];  // sometimes coincident
      segments.push_back({a, b});
      EXPECT_EQ(batch.add(**es, a.p, a.n, a.e, b.p, b.n, b.e), i);
    }
    EXPECT_EQ(batch.full(), size == OcclusionBatch::kCapacity);
    batch.trace(**es);
    for (int i = 0; i < size; ++i) {
      const auto& [a, b] = segments[static_cast<std::size_t>(i)];
      const bool alone = (*es)->visible(a.p, a.n, a.e, b.p, b.n, b.e);
      EXPECT_EQ(batch.visible(i), alone) << "round " << round << " lane " << i;
      agree += batch.visible(i) == alone;
      (alone ? open : blocked) += 1;
    }
    batch.clear();
    EXPECT_EQ(batch.size(), 0);
  }
  EXPECT_EQ(agree, open + blocked);
  EXPECT_GT(blocked, 500) << "the test needs segments that something blocks";
  EXPECT_GT(open, 500) << "and segments that nothing blocks";
}

// A packet's closest hits (RayPacket, which traces the render's first eye rays: issue 39) are the
// ones intersect() finds, field by field: camera-like rays from one point into the box and past
// it (hits and misses), rays from random points inside it in every direction, and non-finite
// rays; for every packet size.
TEST(Embree, RayPacketHitsAreIntersectsHits) {
  Result<Scene> scene = load_scene_json(default_scene_json(), ".", "default");
  ASSERT_TRUE(scene.ok());
  auto es = EmbreeScene::build(*scene);
  ASSERT_TRUE(es.ok());
  std::vector<std::pair<vec3, vec3>> rays;
  Uniform u;
  const vec3 eye(0.0f, 1.0f, 3.0f);  // before the box's open side, as its camera
  for (int i = 0; i < 600; ++i) rays.push_back({eye, glm::normalize(vec3(u.next(), u.next(), u.next()) * 2.6f - vec3(1.3f, 0.3f, 1.3f) - eye)});
  for (int i = 0; i < 600; ++i) rays.push_back({vec3(u.next() * 1.8f - 0.9f, u.next() * 1.8f + 0.1f, u.next() * 1.8f - 0.9f), sample_uniform_sphere(u.next2())});
  rays.push_back({vec3(std::nanf(""), 0, 0), vec3(0, 0, -1)});
  rays.push_back({vec3(0, 1, 3), vec3(0, INFINITY, -1)});
  int hits = 0, misses = 0, packets = 0;
  RayPacket packet;
  for (std::size_t i = 0; i < rays.size();) {
    const int size = 1 + packets++ % RayPacket::kCapacity;
    const std::size_t n = std::min<std::size_t>(static_cast<std::size_t>(size), rays.size() - i);
    for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(packet.add(rays[i + k].first, rays[i + k].second), static_cast<int>(k));
    EXPECT_EQ(packet.full(), n == RayPacket::kCapacity);
    packet.trace(**es);
    for (std::size_t k = 0; k < n; ++k)
      for (const HitDetail detail : {HitDetail::kFull, HitDetail::kNoUv}) {
        const auto& [o, d] = rays[i + k];
        const std::optional<Hit> alone = (*es)->intersect(o, d, 0.0f, std::numeric_limits<float>::infinity(), detail);
        const std::optional<Hit> batched = packet.hit(**es, static_cast<int>(k), detail);
        ASSERT_EQ(batched.has_value(), alone.has_value()) << "ray " << i + k;
        if (!alone) {
          misses += detail == HitDetail::kFull;
          continue;
        }
        hits += detail == HitDetail::kFull;
        EXPECT_EQ(std::memcmp(&*batched, &*alone, sizeof(Hit)), 0) << "ray " << i + k;
      }
    packet.clear();
    EXPECT_EQ(packet.size(), 0);
    i += n;
  }
  EXPECT_GT(hits, 600);
  EXPECT_GT(misses, 100);
}

// The eye's starts made ahead (trace/accel/eye_ahead.h) give exactly what the sample would have
// computed: the selected start's ray and hit to its own sample and query, and to any other one
// (another pixel, other numbers, another ray, an origin with an error bound) what computing gives.
TEST(EyeAhead, GivesAStartOnlyToItsOwnSampleAndQuery) {
  Result<Scene> scene = load_scene_json(default_scene_json(), ".", "default");
  ASSERT_TRUE(scene.ok());
  Result<RenderScene> rs = make_render_scene(*scene);
  ASSERT_TRUE(rs.ok());
  const RenderSensor& cam = rs->camera;
  const EmbreeScene& es = *rs->geometry;
  const auto sampler = [](int pixel) { return Sampler(1, static_cast<std::uint64_t>(pixel), 3, SamplerKind::kSobol, 2); };
  const auto same_ray = [](const std::optional<EndpointRay>& a, const std::optional<EndpointRay>& b) {
    return a.has_value() == b.has_value() && (!a || (a->origin == b->origin && a->direction == b->direction && a->weight == b->weight));
  };
  const auto same_hit = [](const std::optional<Hit>& a, const std::optional<Hit>& b) {
    return a.has_value() == b.has_value() && (!a || std::memcmp(&*a, &*b, sizeof(Hit)) == 0);
  };
  tracer::EyeAhead ahead;
  for (int x = 0; x < 16; ++x) ahead.add(cam, sampler(x), x, 0, 3);
  EXPECT_TRUE(ahead.full());
  ahead.trace(es, HitDetail::kNoUv);
  for (int x = 0; x < 16; ++x) {
    Sampler fresh = sampler(x);
    const std::optional<EndpointRay> want = cam.primary_ray(fresh, x, 0);
    ASSERT_TRUE(want.has_value());
    const std::optional<Hit> want_hit = es.intersect(want->origin, want->direction, vec3(0.0f), vec3(0.0f), HitDetail::kNoUv);
    // Its own sample and query: the prepared ones, the sampler moved on as drawing moves it.
    ahead.select(x);
    Sampler mine = sampler(x);
    EXPECT_TRUE(same_ray(ahead.primary_ray(cam, mine, x, 0), want));
    EXPECT_TRUE(mine == fresh);
    EXPECT_TRUE(same_hit(ahead.intersect(es, want->origin, want->direction, vec3(0.0f), vec3(0.0f), HitDetail::kNoUv), want_hit));
    // Another pixel, other numbers, another query: computed.
    const int other = (x + 1) % 16;
    for (const auto& [px, pixel] : {std::pair{other, x}, std::pair{x, other}}) {
      ahead.select(x);
      Sampler rng = sampler(pixel), ref = sampler(pixel);
      EXPECT_TRUE(same_ray(ahead.primary_ray(cam, rng, px, 0), cam.primary_ray(ref, px, 0)));
      EXPECT_TRUE(rng == ref);
    }
    ahead.select(x);
    const vec3 d = glm::normalize(want->direction + vec3(0.01f, 0.0f, 0.0f)), e(1e-7f);
    EXPECT_TRUE(same_hit(ahead.intersect(es, want->origin, d, vec3(0.0f), vec3(0.0f), HitDetail::kNoUv),
                         es.intersect(want->origin, d, vec3(0.0f), vec3(0.0f), HitDetail::kNoUv)));
    ahead.select(x);
    EXPECT_TRUE(same_hit(ahead.intersect(es, want->origin, want->direction, vec3(0, 0, -1), e, HitDetail::kNoUv),
                         es.intersect(want->origin, want->direction, vec3(0, 0, -1), e, HitDetail::kNoUv)));
    // Given once: a second ask computes (the same answers).
    ahead.select(x);
    Sampler twice = sampler(x);
    (void)ahead.primary_ray(cam, twice, x, 0);
    twice = sampler(x);
    EXPECT_TRUE(same_ray(ahead.primary_ray(cam, twice, x, 0), want));
  }
  ahead.clear();
  EXPECT_EQ(ahead.size(), 0);
}

}  // namespace
}  // namespace pathex

// The offset's last step, on four lanes of bits, against its definition std::nextafter(x, ±inf):
// every sign of x and dir, zeros of both signs, subnormals, the largest float, infinities, NaN.
TEST(Embree, AwayIsNextafterTowardsTheSignOfDir) {
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> xs = {0.0f, -0.0f, 1.0f, -1.0f, 1e-45f, -1e-45f, 1e-38f, 3.5f, -1e30f,
                                 std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(), inf, -inf,
                                 std::numeric_limits<float>::quiet_NaN(), 0.1f, -123.456f};
  const std::vector<float> dirs = {0.0f, -0.0f, 1e-30f, -1e-30f, 2.0f, -2.0f};
  const auto expected = [](float x, float dir) {
    if (dir == 0.0f || !std::isfinite(x)) return x;
    return std::nextafter(x, dir > 0.0f ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity());
  };
  const auto same_bits = [](float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  for (float x : xs)
    for (float dx : dirs)
      for (float dy : dirs) {
        const glm::vec3 r = pathex::EmbreeScene::away(glm::vec3(x, -x, x), glm::vec3(dx, dy, -dx));
        EXPECT_TRUE(same_bits(r.x, expected(x, dx))) << x << " towards " << dx << ": " << r.x;
        EXPECT_TRUE(same_bits(r.y, expected(-x, dy))) << -x << " towards " << dy << ": " << r.y;
        EXPECT_TRUE(same_bits(r.z, expected(x, -dx))) << x << " towards " << -dx << ": " << r.z;
      }
}

// RenderSensor::below() (to_pixels()' bound on the bits) is std::nextafter(x, 0) for every pixel
// count a sensor can have, up to and past 2^24, where floats stop being every integer.
TEST(Embree, SensorBelowIsNextafterTowardsZero) {
  for (std::uint32_t n = 1; n <= (1u << 25); n = n < 4096 ? n + 1 : n * 3 / 2 + 1) {
    const float x = static_cast<float>(n);
    EXPECT_EQ(pathex::RenderSensor::below(x), std::nextafter(x, 0.0f)) << n;
  }
}
