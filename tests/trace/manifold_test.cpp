// The manifold connector (issue 12, trace/joins/manifold.h): the Newton walk against closed forms,
// every failure reason it reports, and the glass-sphere caustic rendered by pt-nee+manifold
// against light tracing and bdpt (fixed seeds; tolerances in standard errors).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "io/profile_json.h"
#include "scene/scene.h"
#include "trace/differential.h"
#include "trace/joins/manifold.h"
#include "trace/render.h"

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
  std::mt19937_64 rng(1);
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
  const double dr = 0.005;
  double sums[2] = {0, 0};
  long counts[2] = {0, 0};
  const long rays = 2000000;
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
    // The brute force's error: a count's relative σ is 1 / √count (the weights vary little).
    EXPECT_NEAR(walk, brute, 4.0 * brute / std::sqrt(static_cast<double>(counts[k])) + 1e-3 * brute) << "radius " << radii[k];
  }
}

HistogramReport render_point_glass(const std::string& renderer, std::uint64_t spp, std::vector<ConnectorStats>* stats = nullptr) {
  Scene scene = load_scene_file(std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/point-glass.json").expect("the sample");
  scene.camera.width = scene.camera.height = 24;
  RenderOptions o;
  o.spp = spp;
  o.seed = 7;
  o.max_bounces = 6;
  o.images = false;
  Result<RenderOutput> out = render(scene, resolve_profile(renderer, Limits{}).expect("built in"), nullptr, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().render());
  if (stats) *stats = out->connectors;
  RunInfo info;
  info.spp = spp;
  return make_report(out->histogram, info, nullptr, {}).expect("a report");
}

const PathEstimate* find(const HistogramReport& r, const std::string& path) {
  for (const PathEstimate& p : r.paths)
    if (p.path == path) return &p;
  return nullptr;
}

// The caustic under the sphere, seen directly: light tracing and bdpt sample it by splatting,
// pt-nee+manifold by the walk. The caustic seen through the sphere only the walk reaches.
// Known: the render's manifold estimate of the caustic has come out low in every run (README "The
// manifold connector": 0.012-0.017 against light tracing's 0.0247 at 16 spp; heavy tails or a
// bias, not settled), while the walk itself matches brute force (SumOverChainsIsTheBruteForce-
// Irradiance); its σ is large, so the 4σ check below is weak.
TEST(ManifoldRender, PointGlassCausticAgreesWithLightTracingAndBdpt) {
  std::vector<ConnectorStats> stats;
  const HistogramReport mf = render_point_glass("pt-nee+manifold", 64, &stats);
  const HistogramReport lt = render_point_glass("lt", 64);
  const HistogramReport bd = render_point_glass("bdpt", 64);
  EXPECT_EQ(mf.nonfinite_samples, 0u);
  const std::string caustic = "LSDSSDDSE";
  const PathEstimate* m = find(mf, caustic);
  ASSERT_NE(m, nullptr);
  for (const HistogramReport* ref : {&lt, &bd}) {
    const PathEstimate* r = find(*ref, caustic);
    ASSERT_NE(r, nullptr);
    const double sigma = std::hypot(m->estimate.std_error, r->estimate.std_error);
    EXPECT_LE(std::fabs(m->estimate.luminance - r->estimate.luminance), 4.0 * sigma)
        << "manifold " << m->estimate.luminance << " ± " << m->estimate.std_error << ", reference " << r->estimate.luminance
        << " ± " << r->estimate.std_error;
  }
  const PathEstimate* through = find(mf, "LSDSSDSSDSE");
  ASSERT_NE(through, nullptr);
  EXPECT_GT(through->estimate.luminance, 0.0);
  EXPECT_TRUE(std::isfinite(through->estimate.luminance));
  EXPECT_EQ(find(lt, "LSDSSDSSDSE"), nullptr);
  ASSERT_EQ(stats.size(), 1u);
  const ConnectorStats& c = stats[0];
  EXPECT_EQ(c.connector, "manifold");
  EXPECT_GT(c.successes, 0u);
  EXPECT_GT(c.walks, 0u);
  EXPECT_GT(c.iterations, 0u);
  // Every attempt succeeds or fails for one reason.
  EXPECT_EQ(c.attempts, c.successes + c.no_solution + c.occluded + c.singular + c.wrong_type + c.too_short + c.iteration_limit +
                            c.no_transport);
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
  o.seed = 3;
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
