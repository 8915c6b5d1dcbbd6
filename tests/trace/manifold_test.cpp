// The manifold connector (issue 12, trace/joins/manifold.h): the Newton walk against closed forms,
// every failure reason it reports, and the glass-sphere caustic rendered by pt-nee+manifold
// against light tracing and bdpt (fixed seeds; tolerances in standard errors).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "support/compare_estimates.h"
#include "support/stat_seed.h"
#include "io/profile_json.h"
#include "scene/scene.h"
#include "trace/differential.h"
#include "trace/joins/manifold.h"
#include "trace/render.h"
#include "trace/render_scene.h"

namespace pathex {
namespace {

using glm::dvec3;

// A chain vertex on `g`: `entering` when the light side is outside the glass (index 1) and the
// eye side inside (index ior), else the reverse.
ChainVertex on(const ShapeGeometry& g, dvec3 p, bool entering, double ior = 1.5) {
  return ChainVertex{&g, 0, 0, ior, entering ? 1.0 : ior, entering ? ior : 1.0, false, p};
}

// Snell's law at every vertex of a solved chain: η_i sin θ_i = η_o sin θ_o, sides opposite.
void expect_snell(const std::vector<ChainVertex>& x, dvec3 a, dvec3 b) {
  for (std::size_t i = 0; i < x.size(); ++i) {
    const dvec3 n = surface_derivatives(*x[i].shape, 0, x[i].p).n;
    const dvec3 wi = glm::normalize((i == 0 ? a : x[i - 1].p) - x[i].p);
    const dvec3 wo = glm::normalize((i + 1 == x.size() ? b : x[i + 1].p) - x[i].p);
    const double ci = glm::dot(wi, n), co = glm::dot(wo, n);
    EXPECT_LT(ci * co, 0.0) << "vertex " << i;
    const double ei = ci < 0 ? x[i].ior : 1.0, eo = co < 0 ? x[i].ior : 1.0;
    EXPECT_NEAR(ei * std::sqrt(1 - ci * ci), eo * std::sqrt(1 - co * co), 1e-5) << "vertex " << i;
  }
}

// One flat interface (glass below the plane y = 0): on the axis through a and b, a ray leaving a
// at angle θ meets the plane at h1 tan θ and b's plane at θ (h1 + h2 / η) paraxially, so the
// solid angle at a per unit area at b is 1 / (h1 + h2 / η)².
TEST(ManifoldWalk, FlatInterfaceMatchesTheParaxialClosedForm) {
  const ShapeGeometry quad = QuadShape{{-5.0f, 0.0f, 5.0f}, {10.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -10.0f}};
  const double h1 = 1.3, h2 = 0.7, eta = 1.5;
  const dvec3 a(0, h1, 0), b(0, -h2, 0);
  std::vector<ChainVertex> x{on(quad, dvec3(0.2, 0.0, -0.1), true, eta)};
  const ManifoldWalk w = solve_chain(x, a, b, dvec3(0, 1, 0), 10.0, ManifoldOptions{});
  ASSERT_EQ(w.failure, ManifoldFailure::kNone);
  EXPECT_NEAR(x[0].p.x, 0.0, 1e-6);
  EXPECT_NEAR(x[0].p.z, 0.0, 1e-6);
  EXPECT_NEAR(w.dw_db, 1.0 / ((h1 + h2 / eta) * (h1 + h2 / eta)), 1e-6 * w.dw_db);
}

// A smooth-shaded triangle (trace/differential.h): its shading normal is the vertex normals'
// interpolation, and dn/du, dn/dv are that normal's derivatives along the triangle (checked here
// against central differences of mesh_shading_normal, the function the tracer shades with).
TEST(ManifoldWalk, SmoothShadedTrianglesNormalAndItsDerivatives) {
  MeshShape m;
  m.positions = {{-1, 0, 1}, {1, 0, 1}, {0, 0, -1}};
  m.triangles = {{0, 1, 2}};
  m.normals = {glm::normalize(glm::vec3(-0.4f, 1, 0.1f)), glm::normalize(glm::vec3(0.5f, 1, 0.2f)), glm::normalize(glm::vec3(0, 1, -0.6f))};
  const ShapeGeometry g = m;
  const dvec3 p(0.1, 0.0, 0.2);
  const SurfaceDerivatives d = surface_derivatives(g, 0, p);
  EXPECT_NEAR(glm::length(d.n - dvec3(0, 1, 0)), 0.0, 1e-12);  // wound (0 1 2): (e1 × e2) points up
  // The barycentrics of p: w1 = 0.35, w2 = 0.4 (p = 0.25 p0 + 0.35 p1 + 0.4 p2).
  const glm::vec3 ns = mesh_shading_normal(m, m.triangles[0], 0.35f, 0.4f, glm::vec3(d.n));
  EXPECT_NEAR(glm::length(d.ns - dvec3(ns)), 0.0, 1e-6);
  const auto shade_at = [&](const dvec3& q) { return surface_derivatives(g, 0, q).ns; };
  const double h = 1e-5;
  const dvec3 fd_u = (shade_at(p + h * d.dpdu) - shade_at(p - h * d.dpdu)) / (2 * h);
  const dvec3 fd_v = (shade_at(p + h * d.dpdv) - shade_at(p - h * d.dpdv)) / (2 * h);
  EXPECT_GT(glm::length(fd_u), 0.05);  // the normal does turn
  EXPECT_NEAR(glm::length(d.dndu - fd_u), 0.0, 1e-7);
  EXPECT_NEAR(glm::length(d.dndv - fd_v), 0.0, 1e-7);
}

// A flat triangle whose vertex normals all lean the same way refracts as a tilted interface: the
// walk solves Snell's law about the shading normal (the tracer's), not the geometric one.
TEST(ManifoldWalk, SmoothShadedInterfaceRefractsAboutItsShadingNormal) {
  MeshShape m;
  m.positions = {{-5, 0, 5}, {5, 0, 5}, {0, 0, -10}};
  m.triangles = {{0, 1, 2}};
  const glm::vec3 lean = glm::normalize(glm::vec3(0.3f, 1, 0));
  m.normals = {lean, lean, lean};
  const ShapeGeometry g = m;
  const dvec3 a(0.2, 1.3, 0.1), b(-0.1, -0.7, 0.0);
  std::vector<ChainVertex> x{on(g, dvec3(0.0, 0.0, 0.0), true, 1.5)};
  const ManifoldWalk w = solve_chain(x, a, b, dvec3(0, 1, 0), 10.0, ManifoldOptions{});
  ASSERT_EQ(w.failure, ManifoldFailure::kNone);
  const dvec3 n = surface_derivatives(g, 0, x[0].p).ns;
  EXPECT_NEAR(glm::length(n - dvec3(lean)), 0.0, 1e-6);
  const dvec3 wi = glm::normalize(a - x[0].p), wo = glm::normalize(b - x[0].p);
  const double ci = glm::dot(wi, n), co = glm::dot(wo, n);
  EXPECT_NEAR(std::sqrt(1 - ci * ci), 1.5 * std::sqrt(1 - co * co), 1e-6);  // Snell about ns
  EXPECT_NEAR(glm::dot(glm::cross(wi, n), wo), 0.0, 1e-6);                  // in the plane of incidence
  const dvec3 ng(0, 1, 0);
  const double gi = glm::dot(wi, ng), go = glm::dot(wo, ng);
  EXPECT_GT(std::fabs(std::sqrt(1 - gi * gi) - 1.5 * std::sqrt(1 - go * go)), 1e-2);  // and not about ng
}

// Off the axis the flat interface's term is still closed-form: with the refraction point r along the
// plane, θ1 and θ2 its angles, dA_b / dω_a = (h1 / cos θ1 ... ) — checked here against the
// definition instead: moving b by δ and re-solving moves the direction leaving a by dω.
TEST(ManifoldWalk, SphereChainObeysSnellAndItsTermIsTheDirectionMapsJacobian) {
  const ShapeGeometry sphere = SphereShape{{0.0f, 0.9f, 0.0f}, 0.5f};
  const dvec3 a(0.05, 2.4, 0.02), b(0.12, 0.0, -0.07);
  std::vector<ChainVertex> seed{on(sphere, dvec3(0.1, 1.39, 0.0), true), on(sphere, dvec3(0.1, 0.41, 0.0), false)};
  std::vector<ChainVertex> x = seed;
  const ManifoldWalk w = solve_chain(x, a, b, dvec3(0, 1, 0), 6.0, ManifoldOptions{});
  ASSERT_EQ(w.failure, ManifoldFailure::kNone);
  expect_snell(x, a, b);
  EXPECT_GT(w.iterations, 0);
  // The definition: directions leaving a for b moved along x and z by ±δ, re-solved from x.
  const double d = 1e-4;
  dvec3 dirs[2][2];
  for (int axis = 0; axis < 2; ++axis)
    for (int sign = 0; sign < 2; ++sign) {
      std::vector<ChainVertex> y = x;
      const dvec3 bb = b + (sign ? d : -d) * (axis == 0 ? dvec3(1, 0, 0) : dvec3(0, 0, 1));
      ManifoldOptions tight;
      tight.threshold = 1e-12;
      ASSERT_EQ(solve_chain(y, a, bb, dvec3(0, 1, 0), 6.0, tight).failure, ManifoldFailure::kNone);
      dirs[axis][sign] = glm::normalize(y[0].p - a);
    }
  const dvec3 du = (dirs[0][1] - dirs[0][0]) / (2 * d), dv = (dirs[1][1] - dirs[1][0]) / (2 * d);
  const double expected = glm::length(glm::cross(du, dv));  // the solid angle swept per unit area at b
  EXPECT_NEAR(w.dw_db, expected, 1e-3 * expected);
}

TEST(ManifoldWalk, EveryFailureReasonIsReported) {
  const ShapeGeometry sphere = SphereShape{{0.0f, 0.0f, 0.0f}, 1.0f};
  const ShapeGeometry disk = DiskShape{{0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 0.2f};
  ManifoldOptions o;
  // Iteration limit: an off-axis seed given one iteration.
  {
    std::vector<ChainVertex> x{on(sphere, dvec3(0.3, 0.953939, 0.0), true), on(sphere, dvec3(0.3, -0.953939, 0.0), false)};
    ManifoldOptions one = o;
    one.max_iterations = 1;
    EXPECT_EQ(solve_chain(x, dvec3(0.1, 3, 0), dvec3(-0.2, -3, 0.1), dvec3(0, 1, 0), 6.0, one).failure,
              ManifoldFailure::kIterationLimit);
  }
  // Wrong type: a and b on one side of the disk; the half vector then asks for a reflection.
  {
    std::vector<ChainVertex> x{on(disk, dvec3(0.05, 0.0, 0.0), true)};
    EXPECT_EQ(solve_chain(x, dvec3(-0.1, 1, 0), dvec3(0.1, 1, 0), dvec3(0, 1, 0), 2.0, o).failure, ManifoldFailure::kWrongType);
  }
  // No solution: the refraction point lies off the small disk.
  {
    std::vector<ChainVertex> x{on(disk, dvec3(0.19, 0.0, 0.0), true)};
    EXPECT_EQ(solve_chain(x, dvec3(2.0, 1, 0), dvec3(2.0, -1, 0), dvec3(0, 1, 0), 4.0, o).failure, ManifoldFailure::kNoSolution);
  }
  // Too short: b within 1e-3 of the scene's size of the interface.
  {
    std::vector<ChainVertex> x{on(disk, dvec3(0.0, 0.0, 0.0), true)};
    EXPECT_EQ(solve_chain(x, dvec3(0, 1, 0), dvec3(0, -1e-4, 0), dvec3(0, 1, 0), 2.0, o).failure, ManifoldFailure::kTooShort);
  }
  // Singular: b at the paraxial focus of a ball lens lit from a on its axis. There every chain
  // near the axis joins a and b (a caustic), so the constraints do not fix the chain.
  {
    const double n = 1.5, r = 1.0, u0 = 3.0;  // a at 3 before the first vertex
    const double v1 = n / ((n - 1) / r - 1 / u0);
    const double v2 = 1 / ((n - 1) / r + n / (v1 - 2 * r));
    std::vector<ChainVertex> x{on(sphere, dvec3(0, 1, 0), true), on(sphere, dvec3(0, -1, 0), false)};
    EXPECT_EQ(solve_chain(x, dvec3(0, r + u0, 0), dvec3(0, -r - v2, 0), dvec3(0, 1, 0), 10.0, o).failure,
              ManifoldFailure::kSingular);
  }
}

// The seeds leave a hollow sphere where the sphere alone says, without a ray (SpecularSurfaces::
// hollow): point-glass.json's sphere is one (the floor, the pyramid and the plate stay outside it),
// also resting on the floor; not once the floor cuts it or a small sphere sits inside it.
// A chain past a fold has no solution, however small the constraints' least value there (issue 40,
// twelfth session). Light from a point 20 radii from a glass ball (index 1.5), refracted, reflected
// once inside and refracted out (the rainbow's chain), reaches a circle of radius 10 about the ball
// only up to a largest angle from the axis, a fold of the chains: the two chains there merge. The
// fold is found here by tracing rays (a scan of their directions, then golden-section search); an
// eye end just beyond it, seeded with the fold's ray, must not solve (the walk once accepted such a
// near miss whenever its constraints came within the threshold, with |dω_a/dA_b| near the fold's
// divergence: a bias at every caustic's edge), and one just inside it must.
TEST(ManifoldWalk, NoChainIsFoundPastAFold) {
  const ShapeGeometry sphere = SphereShape{{0.0f, 0.0f, 0.0f}, 1.0f};
  const double n = 1.5, far = 10.0;
  const dvec3 a(0.0, 0.0, 20.0);
  struct Traced {
    dvec3 p1, p2, p3;
    double angle = 0.0;  // of the exit ray's crossing of the circle of radius `far`, from +z
    bool ok = false;
  };
  const auto second_hit = [](dvec3 o, dvec3 d) { return o - 2.0 * glm::dot(o, d) * d; };  // inside the unit sphere
  const auto trace = [&](double alpha) {
    Traced r;
    const dvec3 d(std::sin(alpha), 0.0, -std::cos(alpha));
    const double bq = glm::dot(a, d), disc = bq * bq - (glm::dot(a, a) - 1.0);
    if (disc <= 0.0) return r;
    r.p1 = a + (-bq - std::sqrt(disc)) * d;
    const dvec3 in = glm::refract(d, r.p1, 1.0 / n);
    r.p2 = second_hit(r.p1, in);
    const dvec3 back = glm::reflect(in, -r.p2);
    r.p3 = second_hit(r.p2, back);
    const dvec3 out = glm::refract(back, -r.p3, n);
    if (glm::dot(out, out) == 0.0) return r;  // total internal reflection
    const double bo = glm::dot(r.p3, out), t = -bo + std::sqrt(bo * bo - (glm::dot(r.p3, r.p3) - far * far));
    const dvec3 hit = r.p3 + t * out;
    r.angle = std::atan2(hit.x, hit.z);
    r.ok = true;
    return r;
  };
  // The fold: the extreme angle over the rays that hit the ball (the rays' angles reach it from one side).
  const double alpha_max = std::asin(1.0 / 20.0);
  double best = 0.0, best_angle = 0.0;
  for (int i = 1; i < 2000; ++i) {
    const Traced r = trace(alpha_max * i / 2000.0);
    if (r.ok && std::fabs(r.angle) > std::fabs(best_angle)) best = alpha_max * i / 2000.0, best_angle = r.angle;
  }
  double lo = best - alpha_max / 2000.0, hi = best + alpha_max / 2000.0;
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int i = 0; i < 200; ++i) {
    const double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
    if (std::fabs(trace(m1).angle) > std::fabs(trace(m2).angle)) hi = m2;
    else lo = m1;
  }
  const Traced fold = trace(0.5 * (lo + hi));
  ASSERT_TRUE(fold.ok);
  const double side = fold.angle > 0.0 ? 1.0 : -1.0;
  const auto seeded = [&](const Traced& r) {
    ChainVertex inside{&sphere, 0, 0, n, n, n, true, r.p2};
    return std::vector<ChainVertex>{on(sphere, r.p1, true), inside, on(sphere, r.p3, false)};
  };
  const auto eye_end = [&](double angle) { return dvec3(far * std::sin(angle), 0.0, far * std::cos(angle)); };
  for (const double delta : {1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3}) {
    std::vector<ChainVertex> x = seeded(fold);
    const dvec3 b = eye_end(fold.angle + side * delta);
    const ManifoldWalk past = solve_chain(x, a, b, glm::normalize(b), 10.0, ManifoldOptions{});
    EXPECT_NE(past.failure, ManifoldFailure::kNone) << "δ " << delta << " past the fold: |dω_a/dA_b| " << past.dw_db;
  }
  for (const double delta : {1e-3, 1e-2}) {
    std::vector<ChainVertex> x = seeded(fold);
    const dvec3 b = eye_end(fold.angle - side * delta);
    const ManifoldWalk inside = solve_chain(x, a, b, glm::normalize(b), 10.0, ManifoldOptions{});
    EXPECT_EQ(inside.failure, ManifoldFailure::kNone) << "δ " << delta << " inside the fold";
    EXPECT_GT(inside.dw_db, 0.0);
  }
}

TEST(ManifoldWalk, ASphereIsHollowUntilAnotherSurfaceEntersIt) {
  const Scene scene = load_scene_file(std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/point-glass.json").expect("the sample");
  const auto hollow = [](const Scene& s) { return make_render_scene(s).expect("a scene the tracer renders").specular.hollow; };
  const auto moved = [&](float y, float inner) {
    Scene s = scene;
    std::get<SphereShape>(s.shapes[1].geometry).center.y = y;
    if (inner > 0.0f) s.shapes.push_back(s.shapes[1]), std::get<SphereShape>(s.shapes.back().geometry).radius = inner;
    return hollow(s);
  };
  EXPECT_EQ(hollow(scene), (std::vector<std::uint8_t>{0, 1, 0, 0}));
  EXPECT_EQ(moved(0.5f, 0.0f)[1], 1);  // touching the floor
  EXPECT_EQ(moved(0.45f, 0.0f)[1], 0);  // cut by it
  EXPECT_EQ(moved(0.9f, 0.1f)[1], 0);
}

// Ten glass interfaces: five slabs' worth of parallel disks, alternately entering and leaving.
TEST(ManifoldWalk, TenInterfacesSolveAndStayFinite) {
  std::vector<ShapeGeometry> disks;
  for (int i = 0; i < 10; ++i) disks.push_back(DiskShape{{0.0f, -0.1f * static_cast<float>(i), 0.0f}, {0.0f, i % 2 ? -1.0f : 1.0f, 0.0f}, 2.0f});
  std::vector<ChainVertex> x;
  for (int i = 0; i < 10; ++i) x.push_back(on(disks[static_cast<std::size_t>(i)], dvec3(0.01 * i, -0.1 * i, 0.0), i % 2 == 0));
  const dvec3 a(0.3, 1.0, 0.1), b(-0.4, -2.0, 0.2);
  const ManifoldWalk w = solve_chain(x, a, b, dvec3(0, 1, 0), 4.0, ManifoldOptions{});
  ASSERT_EQ(w.failure, ManifoldFailure::kNone);
  expect_snell(x, a, b);
  EXPECT_TRUE(std::isfinite(w.dw_db));
  EXPECT_GT(w.dw_db, 0.0);
}

// The walk against brute force: the irradiance a point light at height 2.4 casts through a glass
// sphere (centre height 0.9, radius 0.5, index 1.5) onto the floor at radius r, per unit intensity.
// Brute force: rays uniform in the cone of the sphere, refracted twice with their Fresnel
// transmittance, binned in an annulus around r. The walk: every distinct chain found from 3000
// seeds (straight rays from the floor point into the sphere, refracted through it), summed, each
// |dω_a/dA_b| times its transmittance. Near the axis three chains reach a point (rays from the far
// side cross it), further out one.
TEST(ManifoldWalk, SumOverChainsIsTheBruteForceIrradiance) {
  const dvec3 a(0, 2.4, 0), c(0, 0.9, 0);
  const double r = 0.5, n = 1.5;
  const ShapeGeometry sphere = SphereShape{{0.0f, 0.9f, 0.0f}, 0.5f};
  const auto fresnel = [](double cos_i, double eta) {  // eta = η_t / η_i, cos_i > 0
    const double s2 = (1 - cos_i * cos_i) / (eta * eta);
    if (s2 >= 1) return 1.0;
    const double ct = std::sqrt(1 - s2), rs = (cos_i - eta * ct) / (cos_i + eta * ct), rp = (eta * cos_i - ct) / (eta * cos_i + ct);
    return 0.5 * (rs * rs + rp * rp);
  };
  const auto refract = [](dvec3 d, dvec3 nrm, double eta, dvec3* out) {  // nrm against d, eta = η_i / η_t
    const double ci = -glm::dot(d, nrm), s2 = eta * eta * (1 - ci * ci);
    if (s2 >= 1) return false;
    *out = glm::normalize(eta * d + (eta * ci - std::sqrt(1 - s2)) * nrm);
    return true;
  };
  const auto hit = [&](dvec3 o, dvec3 d, bool inside) {
    const dvec3 oc = o - c;
    const double b = glm::dot(oc, d), disc = std::max(b * b - (glm::dot(oc, oc) - r * r), 0.0);
    return inside ? -b + std::sqrt(disc) : -b - std::sqrt(disc);
  };
  std::mt19937_64 rng(test::stat_seed(1));
  std::uniform_real_distribution<double> uni(0, 1);
  // A direction uniform in the cone from `from` around the sphere.
  const auto cone = [&](dvec3 from) {
    const dvec3 axis = glm::normalize(c - from);
    const double cos_max = std::sqrt(1 - r * r / glm::dot(c - from, c - from));
    const double z = 1 - uni(rng) * (1 - cos_max), phi = 2 * M_PI * uni(rng), s = std::sqrt(1 - z * z);
    dvec3 t1, t2;
    tangent_frame(axis, &t1, &t2);
    return glm::normalize(s * std::cos(phi) * t1 + s * std::sin(phi) * t2 + z * axis);
  };
  const double radii[] = {0.05, 0.2};
  // The annulus' half-width: its average of the irradiance differs from the value at its radius
  // by a bias ∝ dr² (near the axis, where three chains meet, 2.8σ at dr = 0.005 over 30 seeds:
  // the fixed seed passed, 16 % of others failed); at 0.0025 with twice the rays, about 0.7σ.
  const double dr = 0.0025;
  double sums[2] = {0, 0};
  long counts[2] = {0, 0};
  const long rays = 4000000;
  const double cos_max = std::sqrt(1 - r * r / glm::dot(c - a, c - a)), omega = 2 * M_PI * (1 - cos_max);
  for (long i = 0; i < rays; ++i) {
    const dvec3 d = cone(a);
    const dvec3 p1 = a + hit(a, d, false) * d, n1 = (p1 - c) / r;
    dvec3 d2, d3;
    if (!refract(d, n1, 1 / n, &d2)) continue;
    const dvec3 p2 = p1 + hit(p1, d2, true) * d2, n2 = (p2 - c) / r;
    if (!refract(d2, -n2, n, &d3) || d3.y >= 0) continue;
    const dvec3 floor = p2 + (-p2.y / d3.y) * d3;
    const double at = std::hypot(floor.x, floor.z);
    for (int k = 0; k < 2; ++k)
      if (std::fabs(at - radii[k]) < dr) {
        sums[k] += (1 - fresnel(-glm::dot(d, n1), n)) * (1 - fresnel(glm::dot(d2, n2), 1 / n));
        ++counts[k];
      }
  }
  for (int k = 0; k < 2; ++k) {
    const double area = M_PI * (std::pow(radii[k] + dr, 2) - std::pow(radii[k] - dr, 2));
    const double brute = sums[k] * omega / static_cast<double>(rays) / area;
    const dvec3 b(radii[k], 0, 0);
    std::vector<std::vector<ChainVertex>> found;
    double walk = 0.0;
    for (int seed = 0; seed < 3000; ++seed) {
      const dvec3 d = cone(b);
      const dvec3 q1 = b + hit(b, d, false) * d;
      dvec3 e;
      if (!refract(d, (q1 - c) / r, 1 / n, &e)) continue;
      const dvec3 q2 = q1 + hit(q1, e, true) * e;
      std::vector<ChainVertex> x{on(sphere, q2, true), on(sphere, q1, false)};
      const ManifoldWalk w = solve_chain(x, a, b, dvec3(0, 1, 0), 8.5, ManifoldOptions{});
      if (w.failure != ManifoldFailure::kNone) continue;
      bool seen = false;
      for (const auto& y : found) seen = seen || glm::length(y[0].p - x[0].p) < 1e-4;
      if (seen) continue;
      found.push_back(x);
      const double c0 = glm::dot(glm::normalize(a - x[0].p), (x[0].p - c) / r);
      const double c1 = glm::dot(glm::normalize(x[0].p - x[1].p), (x[1].p - c) / r);
      walk += w.dw_db * (1 - fresnel(c0, n)) * (1 - fresnel(std::fabs(c1), 1 / n));
    }
    EXPECT_EQ(found.size(), k == 0 ? 3u : 1u) << "radius " << radii[k];
    // The brute force's error: a count's relative σ is 1 / √count (the weights vary little); two
    // radii, 0.1 % family-wise, and 0.1 % of the value for what is left of the annulus' bias.
    const double sigma = brute / std::sqrt(static_cast<double>(counts[k]));
    test::stat_log("manifold walk against brute force, radius " + std::to_string(radii[k]), (walk - brute) / sigma, test::family_sigmas(2, 1e-3, 1 << 20));
    EXPECT_NEAR(walk, brute, test::family_sigmas(2, 1e-3, 1 << 20) * sigma + 1e-3 * brute) << "radius " << radii[k];
  }
}

const PathEstimate* find(const HistogramReport& r, const std::string& path) {
  for (const PathEstimate& p : r.paths)
    if (p.path == path) return &p;
  return nullptr;
}

// A point light's image in a convex mirror sphere, computed without the walk: the reflection point
// P by bisection on the angles to L and b in the plane through the light L, the centre C and the
// floor point b; the reflected ray tube by Coddington's equations. A convex mirror of radius R,
// met at incidence θ by a point source at distance s, sends the reflected rays as if from two
// focal lines behind it, at v_t (in the plane of incidence) and v_s (across it):
//   1 / v_t = 1 / s + 2 / (R cos θ),   1 / v_s = 1 / s + 2 cos θ / R.
// A solid angle dω leaving L covers s² dω across the ray at P and, d further on, s² dω (v_t + d)
// (v_s + d) / (v_t v_s); on the floor it covers that over cos θ_b. So
//   dω / dA_b = cos θ_b v_t v_s / (s² (v_t + d) (v_s + d)),
// which for R → ∞ is the plane mirror's image light cos θ_b / (s + d)².
struct MirrorSphereImage {
  dvec3 p;
  double dw_db;
};
MirrorSphereImage mirror_sphere_image(dvec3 light, dvec3 centre, double radius, dvec3 b, dvec3 nb) {
  const dvec3 u = glm::normalize(light - centre);
  const dvec3 v = glm::normalize((b - centre) - glm::dot(b - centre, u) * u);
  const double phi_b = std::atan2(glm::dot(b - centre, v), glm::dot(b - centre, u));
  const auto at = [&](double phi) { return centre + radius * (std::cos(phi) * u + std::sin(phi) * v); };
  // cos of the angle to L minus cos of the angle to b: positive at P = towards L, negative towards b.
  const auto g = [&](double phi) {
    const dvec3 q = at(phi), n = (q - centre) / radius;
    return glm::dot(glm::normalize(light - q), n) - glm::dot(glm::normalize(b - q), n);
  };
  // Between the horizon of b (where P starts to see b) and that of L, both are in view and g falls
  // from positive to negative; outside it g has roots where P sees neither.
  double lo = phi_b - std::acos(radius / glm::length(b - centre)), hi = std::acos(radius / glm::length(light - centre));
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0.0 ? lo : hi) = mid;
  }
  const dvec3 p = at(0.5 * (lo + hi)), n = (p - centre) / radius;
  const double s = glm::length(light - p), d = glm::length(b - p);
  const double cos_t = glm::dot(glm::normalize(light - p), n);
  const double v_t = 1.0 / (1.0 / s + 2.0 / (radius * cos_t)), v_s = 1.0 / (1.0 / s + 2.0 * cos_t / radius);
  const double cos_b = glm::dot(glm::normalize(p - b), nb);
  return {p, cos_b * v_t * v_s / (s * s * (v_t + d) * (v_s + d))};
}

// The walk reflects on a curved mirror: from a seed a quarter radius off, it solves to the
// bisection's reflection point and its |dω_a/dA_b| is Coddington's ray tube, to 1e-6 relative
// (the Jacobian's central differences step 1e-7 of the scene's size).
TEST(ManifoldWalk, MirrorSphereReflectionIsCoddingtonsRayTube) {
  const dvec3 centre(0.0, 0.8, 0.0), light(-1.2, 1.5, 0.4);
  const double radius = 0.5;
  const ShapeGeometry sphere = SphereShape{glm::vec3(centre), static_cast<float>(radius)};
  for (const dvec3 b : {dvec3(-0.2, 0.0, 1.1), dvec3(-1.0, 0.0, -0.5), dvec3(0.5, 0.0, 1.2)}) {
    const MirrorSphereImage expected = mirror_sphere_image(light, centre, radius, b, dvec3(0, 1, 0));
    const dvec3 off = glm::normalize(expected.p - centre + dvec3(0.1, 0.1, -0.1));
    std::vector<ChainVertex> x{ChainVertex{&sphere, 0, 0, 1.0, 1.0, 1.0, true, centre + radius * off, 1}};
    const ManifoldWalk w = solve_chain(x, light, b, dvec3(0, 1, 0), 6.0, ManifoldOptions{});
    ASSERT_EQ(w.failure, ManifoldFailure::kNone) << "b " << b.x << " " << b.z;
    EXPECT_LT(glm::length(x[0].p - expected.p), 1e-7) << "b " << b.x << " " << b.z;
    EXPECT_NEAR(w.dw_db, expected.dw_db, 1e-6 * expected.dw_db) << "b " << b.x << " " << b.z;
  }
}

// The same image rendered: a spot meter reads the floor at b, lit by a point light (intensity I)
// through a mirror sphere (reflectance R), so the class LSDSDSSE reads ρ / π · I · R · dω/dA_b.
// pt-nee cannot sample it (no DD join); pt-nee+manifold finds the one reflection point, and the
// walk's unbiased trial-count weight makes each sample's estimate a whole multiple of the closed
// form (0, 1, 2 … times it), so its estimate is within 4σ (Student's, 31 degrees of freedom).
// The spot meter has one pixel: 16 pixel groups of two replicates gave its stderr one degree of
// freedom, and at 16 spp issue 36's sweep read 12/16 and 14/16 of the closed form with a stderr of
// 0 (seeds 2 and 4). The default design now follows the pixel count: one group of 32 replicates.
TEST(ManifoldRender, MirrorSphereImageOnTheFloorIsTheClosedForm) {
  const double rho = 0.7, intensity = 3.0, refl = 0.9;
  const dvec3 centre(0.0, 0.8, 0.0), light(-1.2, 1.5, 0.4), b(-0.2, 0.0, 1.1);
  const std::string json = R"({"camera": {"type": "spotmeter", "position": [0.3, 1.0, 1.8], "look_at": [-0.2, 0, 1.1]},
    "materials": {"floor": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}, "mirror": {"type": "mirror", "reflectance": [0.9, 0.9, 0.9]}},
    "shapes": [{"type": "quad", "corner": [-4, 0, 4], "edge1": [8, 0, 0], "edge2": [0, 0, -8], "material": "floor"},
               {"type": "sphere", "center": [0, 0.8, 0], "radius": 0.5, "material": "mirror"}],
    "lights": [{"type": "point", "position": [-1.2, 1.5, 0.4], "intensity": [3, 3, 3]}]})";
  const Scene scene = load_scene_json(json, ".", "mirror-sphere.json").expect("a valid scene");
  const double expected = rho / M_PI * intensity * refl * mirror_sphere_image(light, centre, 0.5, b, dvec3(0, 1, 0)).dw_db;
  RenderOptions o;
  o.spp = 256;
  o.seed = test::stat_seed(5);
  o.max_bounces = 4;
  o.images = false;
  RunInfo info;
  info.spp = o.spp;
  for (const char* renderer : {"pt-nee+manifold", "pt-nee"}) {
    Result<RenderOutput> out = render(scene, resolve_profile(renderer, Limits{}).expect("built in"), nullptr, o);
    ASSERT_TRUE(out.ok()) << out.error().render();
    EXPECT_EQ(out->histogram.nonfinite(), 0u);
    const HistogramReport r = make_report(out->histogram, info, nullptr, {}).expect("a report");
    const PathEstimate* image = find(r, "LSDSDSSE");
    if (std::string(renderer) == "pt-nee") {
      EXPECT_EQ(image, nullptr);
      continue;
    }
    ASSERT_NE(image, nullptr);
    EXPECT_EQ(image->estimate.dof, 31);
    EXPECT_NEAR(image->estimate.luminance, expected, 4.0 * image->estimate.std_error);
    ASSERT_EQ(out->connectors.size(), 1u);
    EXPECT_EQ(out->connectors[0].truncated, 0u);
  }
}

// point-glass.json rendered at 24 x 24 pixels, or (`window`) through a 0.4° window of 8 x 8
// pixels onto the floor at 0.02-0.06 from the sphere's axis: inside the caustic, between the
// axis (where the irradiance grows as 1 / r) and the fold near 0.072 (as 1 / √distance), where
// three chains reach every point.
HistogramReport render_point_glass(const std::string& renderer, std::uint64_t spp, bool window,
                                   std::vector<ConnectorStats>* stats = nullptr) {
  Scene scene = load_scene_file(std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/point-glass.json").expect("the sample");
  scene.camera.width = scene.camera.height = window ? 8 : 24;
  if (window) {
    scene.camera.look_at = glm::vec3(0.035f, 0.0f, 0.0f);
    scene.camera.fov_degrees = 0.4f;
  }
  RenderOptions o;
  o.spp = spp;
  o.seed = test::stat_seed(7);
  o.max_bounces = 6;
  o.images = false;
  Result<RenderOutput> out = render(scene, resolve_profile(renderer, Limits{}).expect("built in"), nullptr, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().render());
  if (stats) *stats = out->connectors;
  RunInfo info;
  info.spp = spp;
  return make_report(out->histogram, info, nullptr, {}).expect("a report");
}

// The caustic under the sphere, seen directly: light tracing and bdpt sample it by splatting
// (their light-splat strategy), pt-nee+manifold by the walk. In the window the manifold's estimate
// is within 1.8 % (its samples have no heavy tail there: no fold, no axis), light tracing's at 512
// times the samples per pixel too, bdpt's within 3.1 %: a ~4σ test that fails for a bias of ~10 %
// or more (one of the three chains missed is ~30 %).
TEST(ManifoldRender, PointGlassCausticAgreesWithLightTracingAndBdpt) {
  const std::string caustic = "LSDSSDDSE";
  const HistogramReport mf = render_point_glass("pt-nee+manifold", 64, true);
  const HistogramReport lt = render_point_glass("lt", 32768, true);
  const HistogramReport bd = render_point_glass("bdpt", 8192, true);
  EXPECT_EQ(mf.nonfinite_samples, 0u);
  const PathEstimate* m = find(mf, caustic);
  ASSERT_NE(m, nullptr);
  EXPECT_LT(m->estimate.std_error, 0.03 * m->estimate.luminance);
  std::vector<test::Comparison> comparisons;
  for (const HistogramReport* ref : {&lt, &bd}) {
    const PathEstimate* r = find(*ref, caustic);
    ASSERT_NE(r, nullptr);
    comparisons.push_back(test::compare(std::string("manifold against ") + (ref == &lt ? "lt" : "bdpt"), m->estimate, r->estimate));
  }
  // The shared rule (tests/support/compare_estimates.h) at 0.2 % for the two: about the 4σ this
  // test has always used at 16 degrees of freedom.
  for (const std::string& failure : test::family_failures(comparisons, 2e-3)) ADD_FAILURE() << failure;
}

// The whole view: the caustic seen through the sphere only the walk reaches; every attempt is
// accounted for.
TEST(ManifoldRender, PointGlassSeenThroughIsFoundAndEveryAttemptCounted) {
  std::vector<ConnectorStats> stats;
  const HistogramReport mf = render_point_glass("pt-nee+manifold", 16, false, &stats);
  const HistogramReport lt = render_point_glass("lt", 16, false);
  EXPECT_EQ(mf.nonfinite_samples, 0u);
  const PathEstimate* through = find(mf, "LSDSSDSSDSE");
  ASSERT_NE(through, nullptr);
  EXPECT_GT(through->estimate.luminance, 0.0);
  EXPECT_TRUE(std::isfinite(through->estimate.luminance));
  EXPECT_EQ(find(lt, "LSDSSDSSDSE"), nullptr);
  ASSERT_EQ(stats.size(), 1u);
  const ConnectorStats& c = stats[0];
  EXPECT_EQ(c.connector, "manifold");
  EXPECT_GT(c.successes, 0u);
  EXPECT_GT(c.repeats, 0u);
  EXPECT_GT(c.walks, 0u);
  EXPECT_GT(c.iterations, 0u);
  // Every seed of a first batch succeeds, repeats a chain found before it, or fails for one reason.
  EXPECT_EQ(c.attempts, c.successes + c.no_solution + c.occluded + c.singular + c.wrong_type + c.too_short + c.iteration_limit +
                            c.repeats + c.no_transport);
}

// Stress: a point light above five glass slabs (ten interfaces, as pairs of disks facing apart)
// over a floor, seen at a grazing angle: long chains, total internal reflection in the seeds,
// grazing refractions. No non-finite sample, no hang, and chains of all ten interfaces found.
TEST(ManifoldRender, TenInterfacesStayFiniteAndAreFound) {
  std::string shapes = R"({"type": "quad", "corner": [-4, 0, 4], "edge1": [8, 0, 0], "edge2": [0, 0, -8], "material": "floor"})";
  for (int i = 0; i < 10; ++i) {
    const double y = 0.4 + 0.1 * i + (i / 2) * 0.05;  // slab i/2: its bottom (normal down) and top (normal up)
    shapes += R"(, {"type": "disk", "center": [0, )" + std::to_string(y) + R"(, 0], "normal": [0, )" + (i % 2 ? "1" : "-1") +
              R"(, 0], "radius": 1.5, "material": "glass"})";
  }
  const std::string json = R"({"camera": {"type": "pinhole", "position": [0, 0.6, 5], "look_at": [0, 0.2, 0], "up": [0, 1, 0],
      "fov": 50, "width": 16, "height": 16},
    "materials": {"floor": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}, "glass": {"type": "dielectric", "ior": 1.5}},
    "shapes": [)" + shapes + R"(],
    "lights": [{"type": "point", "position": [0.3, 2.6, 0.2], "intensity": [5, 5, 5]}]})";
  const Scene scene = load_scene_json(json, ".", "stack.json").expect("a valid scene");
  RenderOptions o;
  o.spp = 8;
  o.seed = test::stat_seed(3);
  o.max_bounces = 14;
  o.images = false;
  Result<RenderOutput> out = render(scene, resolve_profile("pt-nee+manifold", Limits{}).expect("built in"), nullptr, o);
  ASSERT_TRUE(out.ok()) << out.error().render();
  EXPECT_EQ(out->histogram.nonfinite(), 0u);
  RunInfo info;
  info.spp = o.spp;
  const HistogramReport r = make_report(out->histogram, info, nullptr, {}).expect("a report");
  const PathEstimate* ten = find(r, "LSD" + std::string(10, 'S') + "DDSE");
  ASSERT_NE(ten, nullptr);
  EXPECT_GT(ten->estimate.luminance, 0.0);
  EXPECT_TRUE(std::isfinite(ten->estimate.luminance));
  ASSERT_EQ(out->connectors.size(), 1u);
  EXPECT_GT(out->connectors[0].successes, 0u);
}

}  // namespace
}  // namespace pathex
