// Lights and sensors (trace/emitters.h): letters and delta flags agree with alphabet.h, sampling
// densities integrate to 1, sampled rays agree with pdf_ray(), starting throughputs average to the
// emitted power, joins invert ray sampling, and the measurement equation gives the same closed
// form from the eye side and from the light side for every sensor. Also the DESIGN §9 closed
// forms (point light irradiance, distant light through a window) and grazing configurations.
//
// Tolerances: each test's Monte Carlo means (standard errors estimated from the same samples)
// within the standard errors that its number of checks gives at a family-wise false-failure rate
// of 0.1 % (test::family_sigmas); seeds from test::stat_seed_from (fixed, or others under
// PATHEX_STAT_SEED: bench/stat_sweep.py).
#include "trace/emitters.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "support/stat_seed.h"
#include "trace/frame.h"
#include "trace/rng.h"
#include "trace/spherical_rect.h"

namespace pathex {
namespace {

constexpr double kPiD = std::numbers::pi;

struct Accumulator {
  double sum = 0.0, sum2 = 0.0;
  std::uint64_t n = 0;
  void add(double x) {
    sum += x;
    sum2 += x * x;
    ++n;
  }
  double mean() const { return sum / static_cast<double>(n); }
  double se() const {
    const double m = mean();
    return std::sqrt(std::max(0.0, sum2 / static_cast<double>(n) - m * m) / static_cast<double>(n));
  }
};

// The tolerance, in standard errors, of a test that makes `checks` such checks: 0.1 % together.
double sigmas_for(int checks) { return test::family_sigmas(checks, 1e-3, test::kNormalDof); }

// Within k standard errors, plus float rounding (some estimators here are exact per sample).
#define EXPECT_MC_NEAR(acc, expected, k)                                                                        \
  test::stat_log(#acc, (acc).se() > 0.0 ? ((acc).mean() - (expected)) / (acc).se() : 0.0, k);                  \
  EXPECT_NEAR((acc).mean(), (expected), (k) * (acc).se() + 1e-5 * std::abs(expected)) << "standard error " \
                                                                                      << (acc).se()

std::string letters(Letter first, Letter second) {
  return {letter_char(first), letter_char(second)};
}

// Every sampled ray: letters are the struct's, delta flags say S exactly where the letter is S, a
// Dirac part's density is 0 (the tracer's one delta convention, trace/emitters.h), the weight is
// value · |cos| / (pdf.pos · pdf.dir) with a Dirac part's factor 1, and pdf_ray() would give the
// same densities.
template <class P>
void expect_consistent(const EndpointRay& r, const RayPdf& again) {
  EXPECT_EQ(r.pos_letter, P::kPosLetter);
  EXPECT_EQ(r.dir_letter, P::kDirLetter);
  EXPECT_EQ(r.pdf.delta_pos, P::kPosLetter == kS);
  EXPECT_EQ(r.pdf.delta_dir, P::kDirLetter == kS);
  if (r.pdf.delta_pos) {
    EXPECT_EQ(r.pdf.pos, 0.0f);
  } else {
    EXPECT_GT(r.pdf.pos, 0.0f);
  }
  if (r.pdf.delta_dir) {
    EXPECT_EQ(r.pdf.dir, 0.0f);
  } else {
    EXPECT_GT(r.pdf.dir, 0.0f);
  }
  const bool has_surface = glm::dot(r.normal, r.normal) > 0.0f;
  const float cos_theta = has_surface ? std::abs(glm::dot(r.normal, r.direction)) : 1.0f;
  const float pos = r.pdf.delta_pos ? 1.0f : r.pdf.pos, dir = r.pdf.delta_dir ? 1.0f : r.pdf.dir;
  const glm::vec3 w = r.value * (cos_theta / (pos * dir));
  EXPECT_NEAR(r.weight.x, w.x, 1e-4f * std::abs(w.x));
  EXPECT_NEAR(glm::length(r.direction), 1.0f, 1e-5f);
  EXPECT_NEAR(again.pos, r.pdf.pos, 1e-5f * r.pdf.pos);
  EXPECT_NEAR(again.dir, r.pdf.dir, 1e-4f * r.pdf.dir);
  EXPECT_EQ(again.delta_pos, r.pdf.delta_pos);
  EXPECT_EQ(again.delta_dir, r.pdf.delta_dir);
}

// A parallelogram corner + a e1 + b e2 (a, b ∈ [0,1)) hit by a ray, in the test's own code.
std::optional<glm::vec3> hit_parallelogram(const glm::vec3& corner, const glm::vec3& e1,
                                           const glm::vec3& e2, const glm::vec3& o,
                                           const glm::vec3& d) {
  const glm::vec3 n = glm::cross(e1, e2);
  const float denom = glm::dot(d, n);
  if (denom == 0.0f) return std::nullopt;
  const float t = glm::dot(corner - o, n) / denom;
  if (t <= 0.0f) return std::nullopt;
  const glm::vec3 x = o + t * d;
  const glm::vec3 rel = x - corner;
  const float a = glm::dot(glm::cross(rel, e2), n) / glm::dot(n, n);
  const float b = glm::dot(glm::cross(e1, rel), n) / glm::dot(n, n);
  if (a < 0.0f || a >= 1.0f || b < 0.0f || b >= 1.0f) return std::nullopt;
  return x;
}

// --- letters ---

TEST(EmitterLetters, MatchTheAlphabet) {
  EXPECT_EQ(letters(AreaLightParams::kPosLetter, AreaLightParams::kDirLetter),
            light_letters(LightType::kArea));
  EXPECT_EQ(letters(PointLightParams::kPosLetter, PointLightParams::kDirLetter),
            light_letters(LightType::kPoint));
  EXPECT_EQ(letters(SpotLightParams::kPosLetter, SpotLightParams::kDirLetter),
            light_letters(LightType::kPoint));
  EXPECT_EQ(letters(DistantLightParams::kPosLetter, DistantLightParams::kDirLetter),
            light_letters(LightType::kDistant));
  EXPECT_EQ(letters(LaserParams::kPosLetter, LaserParams::kDirLetter),
            light_letters(LightType::kLaser));
  // Sensors contribute c(k+1) (direction) then c(k+2) (position).
  EXPECT_EQ(letters(ThinLensParams::kDirLetter, ThinLensParams::kPosLetter),
            sensor_letters(SensorType::kLens));
  EXPECT_EQ(letters(PinholeParams::kDirLetter, PinholeParams::kPosLetter),
            sensor_letters(SensorType::kPinhole));
  EXPECT_EQ(letters(OrthographicParams::kDirLetter, OrthographicParams::kPosLetter),
            sensor_letters(SensorType::kOrthographic));
  EXPECT_EQ(letters(SpotMeterParams::kDirLetter, SpotMeterParams::kPosLetter),
            sensor_letters(SensorType::kSpotmeter));
}

// --- lights ---

TEST(AreaLight, CosineEmissionWithDensitiesThatIntegrateToOne) {
  const double k = sigmas_for(6);  // 6 Monte Carlo means, 0.1 % together
  for (bool two_sided : {false, true}) {
    const AreaLightParams light{glm::vec3(2.0f, 1.0f, 0.5f), two_sided};
    const SurfacePoint x{glm::vec3(1.0f, 2.0f, 3.0f), glm::normalize(glm::vec3(0.2f, -0.3f, 1.0f)),
                         0.25f};
    Accumulator cos_mean, below, integral;
    for (int i = 0; i < 100'000; ++i) {
      Sampler s(test::stat_seed_from(1), two_sided, static_cast<std::uint64_t>(i));
      const glm::vec2 u = s.get2d();
      const auto r = sample_ray(light, x, u);
      // A u with a coordinate exactly 0 (or u.x exactly 1/2 when two-sided: 0 once stretched)
      // maps onto the hemisphere's rim, where the cosine density is 0: no ray, rightly. Each has
      // probability 2^-24 a draw: 2 seeds in 100 of bench/stat_sweep.py drew one.
      if (!r) {
        ASSERT_TRUE(u.x == 0.0f || u.y == 0.0f || (two_sided && u.x == 0.5f)) << "u " << std::hexfloat << u.x << ", " << u.y;
        continue;
      }
      if (i < 2000) expect_consistent<AreaLightParams>(*r, pdf_ray(light, x, r->direction));
      const float c = glm::dot(r->direction, x.normal);
      cos_mean.add(std::abs(c));
      below.add(c < 0.0f);
      EXPECT_EQ(r->weight, light.radiance * (kPi * (two_sided ? 2.0f : 1.0f) / 0.25f));
      EXPECT_EQ(r->weight, power(light, 4.0f)) << "area 4 sampled uniformly: p_A = 1/4";
      // ∫ pdf_dir dσ over the sphere, by uniform directions.
      const glm::vec3 w = sample_uniform_sphere(s.get2d());
      integral.add(pdf_ray(light, x, w).dir * 4.0 * kPiD);
    }
    EXPECT_MC_NEAR(cos_mean, 2.0 / 3.0, k);
    EXPECT_MC_NEAR(below, two_sided ? 0.5 : 0.0, k);
    EXPECT_MC_NEAR(integral, 1.0, k);
    EXPECT_EQ(emitted_radiance(light, x.normal, -x.normal),
              two_sided ? light.radiance : glm::vec3(0.0f));
  }
  EXPECT_FALSE(sample_ray(AreaLightParams{}, SurfacePoint{glm::vec3(0.0f), glm::vec3(0, 0, 1), 0.0f},
                          {0.5f, 0.5f}))
      << "a zero-area light emits nothing";
}

TEST(AreaLight, IrradianceFromADiskMatchesTheClosedForm) {
  const double k = sigmas_for(2);  // 2 Monte Carlo means, 0.1 % together
  // A disk of radius R and radiance Le facing a point on its axis at height h gives the point an
  // irradiance of π Le R² / (h² + R²). Uniform area sampling of the disk, joined by connect().
  const float R = 0.5f, h = 1.5f, Le = 3.0f;
  const AreaLightParams light{glm::vec3(Le), false};
  const glm::vec3 ref(0.0f), n_ref(0.0f, 0.0f, 1.0f);
  const float kCosCone = std::cos(0.35f);
  Accumulator e, solid_angle_integral;
  for (int i = 0; i < 200'000; ++i) {
    Sampler s(test::stat_seed_from(2), 0, static_cast<std::uint64_t>(i));
    const glm::vec2 d = sample_concentric_disk(s.get2d()) * R;
    const SurfacePoint x{glm::vec3(d.x, d.y, h), glm::vec3(0.0f, 0.0f, -1.0f),
                         1.0f / (kPi * R * R)};
    const auto c = connect(light, x, ref);
    ASSERT_TRUE(c);
    EXPECT_FALSE(c->delta);
    e.add(c->weight.x * std::abs(glm::dot(c->wi, n_ref)));
    // pdf_dir integrates to 1 over the directions that reach the disk: directions drawn
    // uniformly in a cone just wider than the disk (half-angle 0.35 > atan(1/3)).
    const glm::vec3 w = sample_uniform_cone(s.get2d(), kCosCone);
    const auto hit = hit_parallelogram(glm::vec3(-R, -R, h), glm::vec3(2 * R, 0, 0),
                                       glm::vec3(0, 2 * R, 0), ref, w);
    double p = 0.0;
    if (hit && glm::length(glm::vec2(hit->x, hit->y)) < R) {
      const auto ch = connect(light, SurfacePoint{*hit, glm::vec3(0, 0, -1), 1.0f / (kPi * R * R)}, ref);
      p = ch ? ch->pdf_dir : 0.0;
    }
    solid_angle_integral.add(p / uniform_cone_pdf(kCosCone));
  }
  EXPECT_MC_NEAR(e, kPiD * Le * R * R / (h * h + R * R), k);
  EXPECT_MC_NEAR(solid_angle_integral, 1.0, k);
  // Seen from behind a one-sided light: nothing.
  EXPECT_FALSE(connect(light, SurfacePoint{glm::vec3(0, 0, h), glm::vec3(0, 0, 1), 1.0f}, ref));
}

TEST(AreaLight, IrradianceIsScaleInvariantFromTinyToHugeScenes) {
  const double k = sigmas_for(2);  // 2 Monte Carlo means, 0.1 % together
  // DESIGN §10: the disk configuration above scaled by 1e-4 and 1e+4 (the latter also moved 1e+5
  // from the origin) gives the same irradiance, π Le R² / (h² + R²), and finite join densities.
  const float Le = 1.0f;
  const AreaLightParams light{glm::vec3(Le), false};
  for (const auto& [scale, offset] : {std::pair{1e-4f, 0.0f}, std::pair{1e4f, 1e5f}}) {
    const float R = 0.5f * scale, h = 1.5f * scale;
    const glm::vec3 ref(offset, -offset, offset);
    Accumulator e;
    for (int i = 0; i < 50'000; ++i) {
      Sampler s(test::stat_seed_from(20), 0, static_cast<std::uint64_t>(i));
      const glm::vec2 d = sample_concentric_disk(s.get2d()) * R;
      const SurfacePoint x{ref + glm::vec3(d.x, d.y, h), glm::vec3(0.0f, 0.0f, -1.0f),
                           1.0f / (kPi * R * R)};
      const auto c = connect(light, x, ref);
      ASSERT_TRUE(c);
      ASSERT_TRUE(std::isfinite(c->pdf_dir) && c->pdf_dir > 0.0f);
      e.add(c->weight.x * std::abs(c->wi.z));
    }
    EXPECT_MC_NEAR(e, kPiD * 0.25 / (2.25 + 0.25), k) << "scale " << scale;
  }
}

TEST(PointLight, IsotropicPowerAndInverseSquareIrradiance) {
  const double k = sigmas_for(1);  // 1 Monte Carlo mean, 0.1 % together
  const PointLightParams light{glm::vec3(0.0f, 0.0f, 2.0f), glm::vec3(5.0f, 4.0f, 3.0f)};
  Accumulator z;
  for (int i = 0; i < 50'000; ++i) {
    Sampler s(test::stat_seed_from(3), 0, static_cast<std::uint64_t>(i));
    const auto r = sample_ray(light, s.get2d());
    ASSERT_TRUE(r);
    if (i < 1000) expect_consistent<PointLightParams>(*r, pdf_ray(light, r->direction));
    EXPECT_EQ(r->weight, power(light));
    z.add(r->direction.z);
  }
  EXPECT_MC_NEAR(z, 0.0, k);
  EXPECT_NEAR(power(light).x, 4.0 * kPiD * 5.0, 1e-4);
  // DESIGN §9: a point light at height h over a plane; at horizontal offset x the irradiance is
  // I cos θ / d² with cos θ = h / d.
  const glm::vec3 ref(1.5f, 0.0f, 0.0f);
  const auto c = connect(light, ref);
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->delta);
  EXPECT_EQ(c->pdf_dir, 0.0f);
  EXPECT_FLOAT_EQ(c->distance, 2.5f);
  EXPECT_NEAR(glm::length(c->wi - glm::vec3(-0.6f, 0.0f, 0.8f)), 0.0f, 1e-6f);
  EXPECT_FLOAT_EQ(c->weight.x * c->wi.z, 5.0f * 0.8f / 6.25f);
  EXPECT_FALSE(connect(light, light.position)) << "a point at the light itself";
}

TEST(SpotLight, FalloffPowerAndConeDensity) {
  const double k = sigmas_for(4);  // 4 Monte Carlo means, 0.1 % together
  SpotLightParams spot;
  spot.position = glm::vec3(0.0f, 0.0f, 3.0f);
  spot.axis = glm::normalize(glm::vec3(0.3f, 0.0f, -1.0f));
  spot.intensity = glm::vec3(10.0f);
  spot.cos_total = std::cos(0.6f);
  spot.cos_falloff_start = std::cos(0.4f);
  // smoothstep falloff: 1 inside, 0 outside, 1/2 halfway (in cosine) through the transition.
  EXPECT_EQ(spot_falloff(spot, 1.0f), 1.0f);
  EXPECT_EQ(spot_falloff(spot, spot.cos_falloff_start), 1.0f);
  EXPECT_EQ(spot_falloff(spot, spot.cos_total), 0.0f);
  EXPECT_NEAR(spot_falloff(spot, 0.5f * (spot.cos_total + spot.cos_falloff_start)), 0.5f, 1e-5f);
  SpotLightParams hard = spot;
  hard.cos_falloff_start = hard.cos_total;
  EXPECT_EQ(spot_falloff(hard, std::nextafter(hard.cos_total, 1.0f)), 1.0f);
  EXPECT_EQ(spot_falloff(hard, hard.cos_total), 0.0f);

  for (const SpotLightParams& p : {spot, hard}) {
    Accumulator weight, integral;
    for (int i = 0; i < 200'000; ++i) {
      Sampler s(test::stat_seed_from(4), 0, static_cast<std::uint64_t>(i));
      const auto r = sample_ray(p, s.get2d());
      if (r) {
        if (i < 1000) expect_consistent<SpotLightParams>(*r, pdf_ray(p, r->direction));
        // Inside the cone, but for the rounding of the rotation to world space: a direction
        // sampled a hair inside the rim can come out on it (seed 36 of bench/stat_sweep.py, both
        // lights, 0.825336 each), within a few ulps of cos_total (4e-7 at 0.83).
        EXPECT_GT(glm::dot(r->direction, p.axis), p.cos_total - 4e-7f);
      }
      weight.add(r ? r->weight.x : 0.0);
      integral.add(pdf_ray(p, sample_uniform_sphere(s.get2d())).dir * 4.0 * kPiD);
    }
    // Power 2π I (1 − (cos_start + cos_total)/2): the mean starting throughput.
    EXPECT_MC_NEAR(weight, power(p).x, k);
    EXPECT_NEAR(power(p).x,
                2.0 * kPiD * 10.0 * (1.0 - 0.5 * (p.cos_falloff_start + p.cos_total)), 1e-3);
    EXPECT_MC_NEAR(integral, 1.0, k);
  }
  // Joins: inside the cone the inverse-square law with the falloff, outside nothing.
  const glm::vec3 on_axis = spot.position + 2.0f * spot.axis;
  const auto c = connect(spot, on_axis);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->weight.x, 10.0f / 4.0f, 1e-5f);
  EXPECT_FALSE(connect(spot, spot.position + glm::vec3(0.0f, 0.0f, 1.0f)));
}

TEST(DistantLight, ThroughAWindowIsECosThetaInsideTheProjection) {
  const double k = sigmas_for(1);  // 1 Monte Carlo mean, 0.1 % together
  // A 2 × 1 window in the plane z = 2, light travelling down and sideways (DESIGN §9).
  DistantLightParams sun;
  sun.direction = glm::normalize(glm::vec3(0.6f, 0.0f, -0.8f));
  sun.irradiance = glm::vec3(7.0f);
  sun.corner = glm::vec3(0.0f, 0.0f, 2.0f);
  sun.edge1 = glm::vec3(2.0f, 0.0f, 0.0f);
  sun.edge2 = glm::vec3(0.0f, 1.0f, 0.0f);
  const glm::vec3 n_floor(0.0f, 0.0f, 1.0f);
  // The window's projection onto the floor z = 0 is shifted by 2 · 0.6/0.8 = 1.5 along x.
  const auto inside = connect(sun, glm::vec3(2.0f, 0.5f, 0.0f));
  ASSERT_TRUE(inside);
  EXPECT_TRUE(inside->delta);
  EXPECT_EQ(inside->wi, -sun.direction);
  EXPECT_NEAR(inside->distance, 2.5f, 1e-5f);
  EXPECT_NEAR(glm::length(inside->position - glm::vec3(0.5f, 0.5f, 2.0f)), 0.0f, 1e-5f);
  EXPECT_FLOAT_EQ(inside->weight.x * glm::dot(inside->wi, n_floor), 7.0f * 0.8f);
  EXPECT_FALSE(connect(sun, glm::vec3(1.2f, 0.5f, 0.0f))) << "left of the projection";
  EXPECT_FALSE(connect(sun, glm::vec3(3.6f, 0.5f, 0.0f))) << "right of the projection";
  EXPECT_FALSE(connect(sun, glm::vec3(2.0f, 1.2f, 0.0f)));
  EXPECT_FALSE(connect(sun, glm::vec3(0.5f, 0.5f, 3.0f))) << "above the window";
  EXPECT_NEAR(power(sun).x, 7.0f * 2.0f * 0.8f, 1e-5f);

  // Rays leave the window uniformly; where they land on the floor, the projection join finds the
  // same window point. The aperture density integrates to 1 over a box around the window.
  Accumulator integral;
  for (int i = 0; i < 20'000; ++i) {
    Sampler s(test::stat_seed_from(5), 0, static_cast<std::uint64_t>(i));
    const glm::vec2 u_window = s.get2d();
    const auto r = sample_ray(sun, u_window);
    ASSERT_TRUE(r);
    if (i < 1000) expect_consistent<DistantLightParams>(*r, pdf_ray(sun, r->origin));
    EXPECT_EQ(r->weight, power(sun));
    const glm::vec3 floor = r->origin + (r->origin.z / 0.8f) * r->direction;
    const auto c = connect(sun, floor);
    // A window point on the far edge of its half-open [0, 1)² (u of 1 − 2^-24) can round onto
    // the edge itself on the way to the floor and back, and the join then misses the window
    // (seed 94 of bench/stat_sweep.py): allowed within 1e-6 of an edge, nowhere else.
    const auto near_edge = [](float v) { return v < 1e-6f || v > 1.0f - 1e-6f; };
    if (!c && (near_edge(u_window.x) || near_edge(u_window.y))) continue;
    ASSERT_TRUE(c) << i << ": u " << std::hexfloat << u_window.x << ", " << u_window.y;
    EXPECT_NEAR(glm::length(c->position - r->origin), 0.0f, 1e-5f);
    const glm::vec2 u = s.get2d();
    integral.add(pdf_ray(sun, glm::vec3(-1.0f + 4.0f * u.x, -1.0f + 3.0f * u.y, 2.0f)).pos * 12.0);
  }
  EXPECT_MC_NEAR(integral, 1.0, k);
}

TEST(DistantLight, NearlyParallelToTheApertureStaysFinite) {
  DistantLightParams sun;
  sun.direction = glm::normalize(glm::vec3(1.0f, 0.0f, -1e-6f));
  sun.corner = glm::vec3(0.0f, 0.0f, 1.0f);
  const auto r = sample_ray(sun, {0.3f, 0.7f});
  ASSERT_TRUE(r);
  EXPECT_TRUE(std::isfinite(r->weight.x));
  EXPECT_NEAR(r->weight.x, 1e-6f, 1e-7f);
  const auto c = connect(sun, glm::vec3(1e6f + 0.5f, 0.5f, 0.0f));  // a million units downstream
  ASSERT_TRUE(c);
  EXPECT_TRUE(std::isfinite(c->distance));
  DistantLightParams degenerate;
  degenerate.edge2 = degenerate.edge1;
  EXPECT_FALSE(sample_ray(degenerate, {0.5f, 0.5f})) << "zero-area aperture";
  EXPECT_EQ(power(degenerate), glm::vec3(0.0f));
}

TEST(Laser, OneRayAndNoJoin) {
  const LaserParams laser{glm::vec3(1.0f), glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.25f)};
  const auto r = sample_ray(laser);
  ASSERT_TRUE(r);
  expect_consistent<LaserParams>(*r, pdf_ray(laser));
  EXPECT_EQ(r->origin, laser.position);
  EXPECT_EQ(r->direction, laser.direction);
  EXPECT_EQ(r->weight, glm::vec3(0.25f));
  EXPECT_FALSE(connect(laser, glm::vec3(1.0f, 5.0f, 1.0f))) << "even on the beam: probability 0";
}

// --- sensors ---

// A unit-radiance square light of side 2 centred on the camera axis at distance 4, facing the
// camera: with a 90° field of view (tan_half = 1) it covers (0.5 / 2)^2 = 1/16 of the image, so
// the image-mean measurement is Le / 16. The eye side gets it geometrically; the light side joins
// uniformly sampled light points to the sensor (strategy t = 1): Le |cos_l| weight / p_A.
constexpr float kLightDistance = 4.0f;
SurfacePoint light_point(glm::vec2 u) {
  return {glm::vec3(-1.0f + 2.0f * u.x, -1.0f + 2.0f * u.y, -kLightDistance),
          glm::vec3(0.0f, 0.0f, 1.0f), 0.25f};
}

TEST(Pinhole, ImportanceIsNormalisedAndJoinsInvertRays) {
  const double k = sigmas_for(2);  // 2 Monte Carlo means, 0.1 % together
  PinholeParams cam;  // at the origin looking down −z, 90° × 90°
  Accumulator normalisation, integral;
  for (int i = 0; i < 400'000; ++i) {
    Sampler s(test::stat_seed_from(6), 0, static_cast<std::uint64_t>(i));
    const glm::vec3 w = sample_uniform_sphere(s.get2d());
    glm::vec2 raster;
    const float we = importance(cam, w, &raster).x;
    normalisation.add(we * std::max(0.0f, glm::dot(w, cam.forward)) * 4.0 * kPiD);
    integral.add(pdf_ray(cam, w).dir * 4.0 * kPiD);
  }
  EXPECT_MC_NEAR(normalisation, 1.0, k);
  EXPECT_MC_NEAR(integral, 1.0, k);
  for (int i = 0; i < 1000; ++i) {
    Sampler s(test::stat_seed_from(7), 0, static_cast<std::uint64_t>(i));
    const glm::vec2 raster = s.get2d();
    const auto r = sample_ray(cam, raster);
    ASSERT_TRUE(r);
    expect_consistent<PinholeParams>(*r, pdf_ray(cam, r->direction));
    EXPECT_EQ(r->weight, glm::vec3(1.0f));
    const auto c = connect(cam, r->origin + 3.0f * r->direction);
    ASSERT_TRUE(c);
    EXPECT_TRUE(c->delta);
    EXPECT_NEAR(glm::length(c->raster - raster), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(c->wi + r->direction), 0.0f, 1e-5f);
    EXPECT_NEAR(c->value.x, r->value.x, 1e-5f * r->value.x);
  }
  EXPECT_FALSE(connect(cam, glm::vec3(0.0f, 0.0f, 1.0f))) << "behind the camera";
  EXPECT_FALSE(connect(cam, glm::vec3(2.0f, 0.0f, -1.0f))) << "outside the field of view";
}

TEST(Pinhole, MeasurementFromEitherEndIsTheClosedForm) {
  const double k = sigmas_for(1);  // 1 Monte Carlo mean, 0.1 % together
  PinholeParams cam;
  // Eye side: the fraction of a 512 × 512 raster grid whose rays hit the square, exactly 1/16.
  int hits = 0;
  constexpr int kGrid = 512;
  for (int y = 0; y < kGrid; ++y)
    for (int x = 0; x < kGrid; ++x) {
      const auto r = sample_ray(cam, glm::vec2(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f) /
                                         static_cast<float>(kGrid));
      hits += hit_parallelogram(glm::vec3(-1, -1, -kLightDistance), glm::vec3(2, 0, 0),
                                glm::vec3(0, 2, 0), r->origin, r->direction)
                  .has_value();
    }
  EXPECT_EQ(hits * 16, kGrid * kGrid);
  // Light side.
  Accumulator m;
  for (int i = 0; i < 100'000; ++i) {
    Sampler s(test::stat_seed_from(8), 0, static_cast<std::uint64_t>(i));
    const SurfacePoint x = light_point(s.get2d());
    const auto c = connect(cam, x.position);
    m.add(c ? std::abs(glm::dot(x.normal, c->wi)) * c->weight.x / x.pdf_area : 0.0);
  }
  EXPECT_MC_NEAR(m, 1.0 / 16.0, k);
}

TEST(ThinLens, NormalisedFocusedAndMeasuresTheClosedForm) {
  const double k = sigmas_for(5);  // 5 Monte Carlo means, 0.1 % together
  ThinLensParams cam;
  cam.lens_radius = 0.2f;
  cam.focus_distance = kLightDistance;
  // ∫∫ We cos dσ dA = 1 over lens points and directions; pdf_ray integrates to 1 in both parts.
  Accumulator normalisation, pos_integral, dir_integral;
  for (int i = 0; i < 400'000; ++i) {
    Sampler s(test::stat_seed_from(9), 0, static_cast<std::uint64_t>(i));
    const glm::vec3 x = lens_point(cam, s.get2d());
    const glm::vec3 w = sample_uniform_sphere(s.get2d());
    glm::vec2 raster;
    const double a_lens = kPiD * cam.lens_radius * cam.lens_radius;
    normalisation.add(importance(cam, x, w, &raster).x * std::max(0.0f, glm::dot(w, cam.forward)) *
                      4.0 * kPiD * a_lens);
    dir_integral.add(pdf_ray(cam, x, w).dir * 4.0 * kPiD);
    const glm::vec2 u = s.get2d();
    const glm::vec3 y(-0.25f + 0.5f * u.x, -0.25f + 0.5f * u.y, 0.0f);  // 0.5 × 0.5 square
    pos_integral.add(pdf_ray(cam, y, cam.forward).pos * 0.25);
  }
  EXPECT_MC_NEAR(normalisation, 1.0, k);
  EXPECT_MC_NEAR(dir_integral, 1.0, k);
  EXPECT_MC_NEAR(pos_integral, 1.0, k);
  // Rays of one raster position meet on the plane of focus; importance() recovers the raster.
  const glm::vec2 raster(0.3f, 0.8f);
  std::optional<glm::vec3> meet;
  for (int i = 0; i < 200; ++i) {
    Sampler s(test::stat_seed_from(10), 0, static_cast<std::uint64_t>(i));
    const auto r = sample_ray(cam, raster, s.get2d());
    ASSERT_TRUE(r);
    expect_consistent<ThinLensParams>(*r, pdf_ray(cam, r->origin, r->direction));
    EXPECT_EQ(r->weight, glm::vec3(1.0f));
    const glm::vec3 at_focus =
        r->origin + r->direction * (kLightDistance / glm::dot(r->direction, cam.forward));
    if (!meet) meet = at_focus;
    EXPECT_NEAR(glm::length(at_focus - *meet), 0.0f, 2e-5f);
    glm::vec2 back{-1.0f};  // importance() sets it where it returns nonzero importance
    EXPECT_GT(importance(cam, r->origin, r->direction, &back).x, 0.0f);
    EXPECT_NEAR(glm::length(back - raster), 0.0f, 1e-5f);
    // A light subpath arriving along the reversed ray hits the lens where the ray left it.
    const auto h = hit_lens(cam, r->origin + 2.0f * r->direction, -r->direction);
    ASSERT_TRUE(h);
    EXPECT_NEAR(glm::length(h->position - r->origin), 0.0f, 1e-5f);
  }
  // Light side of the measurement (the square at the plane of focus: a sharp image, 1/16), and
  // the join density integrating to 1 over the directions that reach the lens.
  Accumulator m, join_integral;
  const glm::vec3 axis_point = cam.position + kLightDistance * cam.forward;
  const float kCosCone = std::cos(0.06f);
  for (int i = 0; i < 200'000; ++i) {
    Sampler s(test::stat_seed_from(11), 0, static_cast<std::uint64_t>(i));
    const SurfacePoint x = light_point(s.get2d());
    const auto c = connect(cam, s.get2d(), x.position);
    m.add(c ? std::abs(glm::dot(x.normal, c->wi)) * c->weight.x / x.pdf_area : 0.0);
    // Directions uniform in a cone about the axis just wider than the lens (0.06 > atan(0.05)).
    const glm::vec3 w = Frame::from_normal(-cam.forward).to_world(sample_uniform_cone(s.get2d(), kCosCone));
    const auto h = hit_lens(cam, axis_point, w);
    join_integral.add(h ? h->pdf_dir / uniform_cone_pdf(kCosCone) : 0.0);
  }
  EXPECT_MC_NEAR(m, 1.0 / 16.0, k);
  EXPECT_MC_NEAR(join_integral, 1.0, k);
}

TEST(Orthographic, MeasurementProjectionAndDensities) {
  const double k = sigmas_for(1);  // 1 Monte Carlo mean, 0.1 % together
  OrthographicParams cam;  // 4 × 4 film at the origin looking down −z
  cam.half_width = 2.0f;
  cam.half_height = 2.0f;
  Accumulator pos_integral;
  for (int i = 0; i < 2000; ++i) {
    Sampler s(test::stat_seed_from(12), 0, static_cast<std::uint64_t>(i));
    const glm::vec2 raster = s.get2d();
    const auto r = sample_ray(cam, raster);
    ASSERT_TRUE(r);
    expect_consistent<OrthographicParams>(*r, pdf_ray(cam, r->origin));
    EXPECT_EQ(r->direction, cam.forward);
    const auto c = connect(cam, r->origin + 5.0f * r->direction);
    ASSERT_TRUE(c);
    EXPECT_TRUE(c->delta);
    EXPECT_EQ(c->wi, -cam.forward);
    EXPECT_NEAR(c->distance, 5.0f, 1e-5f);
    EXPECT_NEAR(glm::length(c->raster - raster), 0.0f, 1e-5f);
    const glm::vec2 u = s.get2d();
    pos_integral.add(pdf_ray(cam, glm::vec3(-3.0f + 6.0f * u.x, -3.0f + 6.0f * u.y, 0.0f)).pos * 36.0);
  }
  EXPECT_MC_NEAR(pos_integral, 1.0, k);
  // The 2 × 2 unit-radiance square covers 1/4 of the film: every light-side sample says so.
  for (int i = 0; i < 100; ++i) {
    Sampler s(test::stat_seed_from(13), 0, static_cast<std::uint64_t>(i));
    const SurfacePoint x = light_point(s.get2d());
    const auto c = connect(cam, x.position);
    ASSERT_TRUE(c);
    EXPECT_FLOAT_EQ(std::abs(glm::dot(x.normal, c->wi)) * c->weight.x / x.pdf_area, 0.25f);
  }
  EXPECT_FALSE(connect(cam, glm::vec3(0.0f, 0.0f, 1.0f))) << "behind the film";
  EXPECT_FALSE(connect(cam, glm::vec3(2.5f, 0.0f, -1.0f))) << "beside the film";
}

TEST(SpotMeter, OneRayAndNoJoin) {
  const SpotMeterParams meter{glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(1.0f, 0.0f, 0.0f)};
  const auto r = sample_ray(meter);
  ASSERT_TRUE(r);
  expect_consistent<SpotMeterParams>(*r, pdf_ray(meter));
  EXPECT_EQ(r->weight, glm::vec3(1.0f));
  EXPECT_FALSE(connect(meter, glm::vec3(5.0f, 1.0f, 0.0f)));
}

// --- numerically hard cases (DESIGN §10) ---

TEST(Grazing, JoinsStayFiniteAtCosOneInAMillion) {
  // An area light seen edge-on (cos = 1e-6 at the light) and a pinhole ray at the image corner.
  const AreaLightParams light{glm::vec3(1.0f), false};
  const glm::vec3 n = glm::normalize(glm::vec3(0.0f, 1e-6f, 1.0f));
  const SurfacePoint x{glm::vec3(0.0f), n, 1.0f};
  const auto c = connect(light, x, glm::vec3(0.0f, 10.0f, 0.0f));
  ASSERT_TRUE(c);
  EXPECT_TRUE(std::isfinite(c->pdf_dir) && std::isfinite(c->weight.x));
  EXPECT_NEAR(c->weight.x, 1e-6f / 100.0f, 1e-9f);
  EXPECT_NEAR(c->pdf_dir, 100.0f / 1e-6f, 1e6f);
  // A camera ray through the image corner and a join from just inside it.
  const PinholeParams cam;
  const auto r = sample_ray(cam, {0.0f, 0.0f});
  ASSERT_TRUE(r);
  EXPECT_TRUE(std::isfinite(r->value.x) && std::isfinite(r->pdf.dir));
  EXPECT_TRUE(connect(cam, glm::vec3(-0.999999f, 0.999999f, -1.0f)));
  // A spot light joined at its rim carries nothing rather than something non-finite.
  SpotLightParams spot;
  spot.axis = glm::vec3(0.0f, 0.0f, -1.0f);
  EXPECT_FALSE(connect(spot, glm::vec3(1.8f, 0.0f, -1.0f))) << "61° off the axis, cone of 60°";
  EXPECT_TRUE(connect(spot, glm::vec3(1.7f, 0.0f, -1.0f))) << "59.5° off the axis";
}

// The tracer computes a sensor's lens numbers only where reads_lens_numbers() says they are read
// (Sampler::get2d_if): a pinhole's rays and joins are the same for any, a thin lens's are not.
TEST(Sensors, LensNumbersAreReadByTheThinLensOnly) {
  ThinLensParams lens;
  lens.lens_radius = 0.2f;
  lens.focus_distance = kLightDistance;
  const std::vector<SensorParams> sensors = {PinholeParams{}, lens, OrthographicParams{}};
  for (const SensorParams& cam : sensors) {
    int differs = 0;
    for (int i = 0; i < 200; ++i) {
      Sampler s(23, static_cast<std::uint64_t>(cam.index()), static_cast<std::uint64_t>(i));
      const glm::vec2 raster = s.get2d(), u = s.get2d(), u2 = s.get2d();
      const glm::vec3 ref(0.3f * (raster.x - 0.5f), 0.3f * (raster.y - 0.5f), -2.0f);  // in front of the sensors
      const auto a = sample_ray(cam, raster, u), b = sample_ray(cam, raster, u2);
      ASSERT_EQ(a.has_value(), b.has_value());
      if (a) differs += a->origin != b->origin || a->direction != b->direction || a->weight != b->weight;
      const auto c = connect_finite(cam, u, ref), d = connect_finite(cam, u2, ref);
      ASSERT_EQ(c.has_value(), d.has_value());
      if (c) differs += c->position != d->position || c->wi != d->wi || c->weight != d->weight;
    }
    EXPECT_EQ(differs > 0, reads_lens_numbers(cam)) << "sensor " << cam.index();
  }
}

// --- a rectangle sampled by the solid angle it subtends (Ureña et al. 2013; trace/spherical_rect.h) ---

// A rectangle light of sides a × b in a tilted frame, and points placed in that frame: the tests'
// closed forms are written in its coordinates.
struct TiltedRect {
  glm::dvec3 ex, ey, ez;  // orthonormal
  glm::dvec3 corner;
  double a, b;
  TiltedRect(double a_, double b_) : a(a_), b(b_) {
    ex = glm::normalize(glm::dvec3(0.8, 0.36, -0.48));
    ez = glm::normalize(glm::cross(ex, glm::dvec3(0.1, 1.0, 0.3)));
    ey = glm::cross(ez, ex);
    corner = glm::dvec3(0.3, 1.9, -0.7);
  }
  AreaLightParams light(bool two_sided) const {
    AreaLightParams p{glm::vec3(3.0f, 2.0f, 1.0f), two_sided};
    p.towards = AreaLightParams::Towards::kRectangle;
    p.corner = glm::vec3(corner);
    p.edge1 = glm::vec3(ex * a);
    p.edge2 = glm::vec3(ey * b);
    p.normal = glm::normalize(glm::cross(p.edge1, p.edge2));
    p.pdf_area = 1.0f / glm::length(glm::cross(p.edge1, p.edge2));
    return p;
  }
  // The point at (u, v, h) in the rectangle's coordinates (u along edge1, v along edge2, h along
  // the normal from the corner).
  glm::vec3 at(double u, double v, double h) const { return glm::vec3(corner + u * ex + v * ey + h * ez); }
  // The solid angle at `ref` of the part [u0, u1] × [v0, v1] of the rectangle's plane, in closed form:
  // Σ ± atan(x y / (h √(x² + y² + h²))) over its corners, x, y, h relative to ref's foot.
  double solid_angle(const glm::vec3& ref, double u0, double u1, double v0, double v1) const {
    const glm::dvec3 d = glm::dvec3(ref) - corner;
    const double pu = glm::dot(d, ex), pv = glm::dot(d, ey), h = std::abs(glm::dot(d, ez));
    const auto f = [h](double x, double y) { return std::atan(x * y / (h * std::sqrt(x * x + y * y + h * h))); };
    return f(u1 - pu, v1 - pv) - f(u0 - pu, v1 - pv) - f(u1 - pu, v0 - pv) + f(u0 - pu, v0 - pv);
  }
  double solid_angle(const glm::vec3& ref) const { return solid_angle(ref, 0.0, a, 0.0, b); }
  // A point of the plane back in the rectangle's coordinates (u, v).
  glm::dvec2 coords(const glm::vec3& x) const {
    const glm::dvec3 d = glm::dvec3(x) - corner;
    return {glm::dot(d, ex), glm::dot(d, ey)};
  }
};

// Points from which the rectangle (0.6 × 0.4) is seen: in front, off to a side, close above a
// corner, at a grazing angle, from behind.
std::vector<glm::vec3> rect_viewpoints(const TiltedRect& r) {
  return {r.at(0.3, 0.2, 1.5), r.at(1.4, -0.6, 0.7), r.at(0.02, 0.03, 0.05), r.at(2.5, 0.2, 0.12), r.at(0.4, 0.1, -0.9)};
}

TEST(AreaLight, RectangleSolidAngleIsTheClosedForm) {
  const TiltedRect r(0.6, 0.4);
  const AreaLightParams p = r.light(false);
  for (const glm::vec3& ref : rect_viewpoints(r)) {
    const SphericalRect s = SphericalRect::at(p.corner, p.edge1, p.edge2, ref);
    const double expected = r.solid_angle(ref);
    EXPECT_NEAR(s.solid_angle, expected, 2e-6 * expected) << "at " << ref.x << " " << ref.y << " " << ref.z;
    EXPECT_TRUE(s.usable());
  }
  // A cube's face seen from its centre: a sixth of the sphere.
  const TiltedRect cube(2.0, 2.0);
  const AreaLightParams face = cube.light(false);
  EXPECT_NEAR(SphericalRect::at(face.corner, face.edge1, face.edge2, cube.at(1.0, 1.0, 1.0)).solid_angle, 4.0 * kPiD / 6.0, 1e-6);
  // In the plane (to float rounding of the tilted point): no solid angle, and none of it sampled;
  // exactly in it: 0; far away: too small, sampled by area.
  EXPECT_LT(SphericalRect::at(p.corner, p.edge1, p.edge2, r.at(1.5, 0.2, 0.0)).solid_angle, 1e-7);
  EXPECT_EQ(SphericalRect::at(glm::vec3(0.0f), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(2, 0.5f, 0)).solid_angle, 0.0);
  EXPECT_FALSE(SphericalRect::at(p.corner, p.edge1, p.edge2, r.at(1.5, 0.2, 0.0)).usable());
  const SphericalRect far = SphericalRect::at(p.corner, p.edge1, p.edge2, r.at(0.3, 0.2, 300.0));
  EXPECT_NEAR(far.solid_angle, 0.24 / (300.0 * 300.0), 1e-3 * 0.24 / (300.0 * 300.0));
  EXPECT_FALSE(far.usable());
  EXPECT_TRUE(is_rectangle(p.edge1, p.edge2));
  EXPECT_FALSE(is_rectangle(p.edge1, p.edge2 + 0.1f * p.edge1)) << "a parallelogram that is not a rectangle";
  EXPECT_FALSE(is_rectangle(p.edge1, glm::vec3(0.0f)));
}

// The directions drawn are uniform over the solid angle: a chi-square over an 8 × 8 grid of the
// rectangle, each cell expected with its own solid angle's share (closed form), at each viewpoint.
TEST(AreaLight, RectangleSamplesAreUniformInItsSolidAngle) {
  constexpr int kGrid = 8, kSamples = 200'000;
  const TiltedRect r(0.6, 0.4);
  const AreaLightParams p = r.light(true);
  const std::vector<glm::vec3> refs = rect_viewpoints(r);
  const double critical = test::family_chi2_critical(kGrid * kGrid - 1, static_cast<int>(refs.size()));
  for (std::size_t k = 0; k < refs.size(); ++k) {
    const glm::vec3 ref = refs[k];
    const SphericalRect s = SphericalRect::at(p.corner, p.edge1, p.edge2, ref);
    ASSERT_TRUE(s.usable());
    std::vector<double> count(kGrid * kGrid, 0.0);
    for (int i = 0; i < kSamples; ++i) {
      Sampler rng(test::stat_seed_from(31), k, static_cast<std::uint64_t>(i));
      const glm::vec3 x = s.sample(rng.get2d());
      ASSERT_TRUE(std::isfinite(x.x + x.y + x.z));
      const glm::dvec2 uv = r.coords(x);
      const int cu = std::clamp(static_cast<int>(uv.x / r.a * kGrid), 0, kGrid - 1);
      const int cv = std::clamp(static_cast<int>(uv.y / r.b * kGrid), 0, kGrid - 1);
      // On the rectangle, to float rounding.
      EXPECT_NEAR(glm::dot(glm::dvec3(x) - r.corner, r.ez), 0.0, 1e-5);
      ASSERT_TRUE(uv.x > -1e-5 && uv.x < r.a + 1e-5 && uv.y > -1e-5 && uv.y < r.b + 1e-5);
      count[static_cast<std::size_t>(cu * kGrid + cv)] += 1.0;
    }
    const double total = r.solid_angle(ref);
    double chi2 = 0.0;
    for (int cu = 0; cu < kGrid; ++cu)
      for (int cv = 0; cv < kGrid; ++cv) {
        const double share = r.solid_angle(ref, r.a * cu / kGrid, r.a * (cu + 1) / kGrid, r.b * cv / kGrid, r.b * (cv + 1) / kGrid) / total;
        const double expected = share * kSamples;
        const double d = count[static_cast<std::size_t>(cu * kGrid + cv)] - expected;
        chi2 += d * d / expected;
      }
    test::stat_log("rectangle solid-angle chi2, viewpoint " + std::to_string(k), chi2, critical);
    EXPECT_LE(chi2, critical) << "viewpoint " << k;
  }
}

// Next-event estimation towards a rectangle by solid angle: the join reports the density 1 / Ω of
// the closed form and the weight Le Ω; towards_area_density() is that density per area and
// integrates to 1 over the rectangle; with towards_step_density() it makes up the emission's joint
// density; and its irradiance agrees with area sampling's.
TEST(AreaLight, RectangleJoinsBySolidAngleHaveTheDensityTheyReport) {
  const double k = sigmas_for(2 * 5);  // 2 Monte Carlo checks at 5 viewpoints, 0.1 % together
  const TiltedRect r(0.6, 0.4);
  for (bool two_sided : {false, true}) {
    const AreaLightParams p = r.light(two_sided);
    const std::vector<glm::vec3> refs = rect_viewpoints(r);
    for (std::size_t v = 0; v < refs.size(); ++v) {
      const glm::vec3 ref = refs[v];
      const double omega = r.solid_angle(ref);
      const bool behind = glm::dot(glm::dvec3(ref) - r.corner, r.ez) < 0.0;
      Accumulator integral, difference;
      for (int i = 0; i < 40'000; ++i) {
        Sampler s(test::stat_seed_from(32), v + 8 * two_sided, static_cast<std::uint64_t>(i));
        const std::optional<EndpointConnection> c = connect(p, s.get2d(), ref);
        // The one-sided light seen from behind: no join (and no emission).
        if (behind && !two_sided) {
          ASSERT_FALSE(c);
          continue;
        }
        ASSERT_TRUE(c);
        EXPECT_NEAR(c->pdf_dir, 1.0 / omega, 2e-5 / omega);
        EXPECT_NEAR(c->weight.x, 3.0 * omega, 2e-5 * omega);
        const float d2 = c->distance * c->distance;
        const float cos_l = std::abs(glm::dot(c->normal, c->wi));
        const float dens = towards_area_density(p, c->position, c->normal, ref);
        EXPECT_NEAR(dens * d2 / cos_l, 1.0 / omega, 2e-4 / omega);
        // The emission's joint density of (x0, x1 = ref) split as x0's from ref and x1's after it.
        const float cos1 = 0.37f;
        const float joint = p.pdf_area * cos_l * kInvPi / (two_sided ? 2.0f : 1.0f) * cos1 / d2;
        EXPECT_NEAR(dens * towards_step_density(p, c->position, c->normal, ref, cos1), joint, 2e-4 * joint);
        // ∫ density dA = 1 over the rectangle, by uniform points of it.
        const glm::vec2 ua = s.get2d();
        const glm::vec3 xa = r.at(ua.x * r.a, ua.y * r.b, 0.0);
        integral.add(towards_area_density(p, xa, p.normal, ref) / p.pdf_area);
        // Irradiance at ref (normal towards the rectangle's centre): solid angle against area sampling.
        const glm::vec3 n_ref = glm::normalize(r.at(0.3, 0.2, 0.0) - ref);
        const SurfacePoint xp{xa, p.normal, p.pdf_area};
        const std::optional<EndpointConnection> by_area = connect(p, xp, ref);
        const double e_sa = c->weight.x * std::max(0.0f, glm::dot(c->wi, n_ref));
        const double e_area = by_area ? by_area->weight.x * std::max(0.0f, glm::dot(by_area->wi, n_ref)) : 0.0;
        difference.add(e_sa - e_area);
      }
      if (behind && !two_sided) continue;
      EXPECT_MC_NEAR(integral, 1.0, k);
      EXPECT_MC_NEAR(difference, 0.0, k);
    }
  }
  // Far away the solid angle is too small to sample: area sampling, its density 1 / area, the
  // join's as connect() by area gives it.
  const AreaLightParams p = r.light(false);
  const glm::vec3 far = r.at(0.3, 0.2, 300.0);
  const std::optional<EndpointConnection> c = connect(p, glm::vec2(0.25f, 0.75f), far);
  ASSERT_TRUE(c);
  EXPECT_EQ(towards_area_density(p, c->position, c->normal, far), p.pdf_area);
  const std::optional<EndpointConnection> by_area = connect(p, SurfacePoint{c->position, p.normal, p.pdf_area}, far);
  ASSERT_TRUE(by_area);
  EXPECT_EQ(c->weight, by_area->weight);
  EXPECT_EQ(c->pdf_dir, by_area->pdf_dir);
}

// A sphere sampled by the cone it subtends (pbrt-v4's Sphere::Sample), from near, mid and far
// (a cone of 0.7°): every point on the sphere and facing ref, the cone's directions uniform (a
// chi-square over an 8 × 8 grid of (1 − cos θ) / (1 − cos θ_max) and φ), the join's density the
// closed form 1 / (2π (1 − cos θ_max)) and its weight Le Ω, the area density integrating to 1 over
// the sphere, its irradiance as area sampling's. From inside the sphere: by area.
TEST(AreaLight, SphereSamplesAreUniformInItsCone) {
  constexpr int kGrid = 8, kSamples = 100'000;
  const glm::vec3 center(0.4f, 1.1f, -0.3f);
  const float radius = 0.5f;
  AreaLightParams p{glm::vec3(2.0f, 1.5f, 1.0f), false};
  p.towards = AreaLightParams::Towards::kSphere;
  p.center = center;
  p.radius = radius;
  p.pdf_area = 1.0f / (4.0f * kPi * radius * radius);
  const std::vector<glm::vec3> refs = {center + glm::vec3(0.3f, 0.5f, 0.4f), center + glm::vec3(-2.0f, 1.0f, 2.0f),
                                       center + glm::vec3(10.0f, -35.0f, 20.0f)};
  const double critical = test::family_chi2_critical(kGrid * kGrid - 1, static_cast<int>(refs.size()));
  const double k = sigmas_for(2 * static_cast<int>(refs.size()));
  for (std::size_t v = 0; v < refs.size(); ++v) {
    const glm::vec3 ref = refs[v];
    const glm::dvec3 to_c = glm::dvec3(center) - glm::dvec3(ref);
    const double d = glm::length(to_c);
    const glm::dvec3 axis = to_c / d;
    const glm::dvec3 bx = glm::normalize(glm::cross(axis, glm::dvec3(0.3, 0.9, 0.2))), by = glm::cross(axis, bx);
    const double one_minus_cos_max = 1.0 - std::sqrt(1.0 - static_cast<double>(radius) * radius / (d * d));
    const double omega = 2.0 * kPiD * one_minus_cos_max;
    std::vector<double> count(kGrid * kGrid, 0.0);
    Accumulator integral, difference;
    for (int i = 0; i < kSamples; ++i) {
      Sampler s(test::stat_seed_from(33), v, static_cast<std::uint64_t>(i));
      const std::optional<EndpointConnection> c = connect(p, s.get2d(), ref);
      ASSERT_TRUE(c);
      EXPECT_NEAR(glm::length(c->position - center), radius, 2e-6f * (1.0f + glm::length(center)));
      EXPECT_GT(glm::dot(c->normal, -c->wi), 0.0f) << "a point of the cap facing ref";
      EXPECT_NEAR(c->pdf_dir, 1.0 / omega, 1e-5 / omega);
      EXPECT_NEAR(c->weight.x, 2.0 * omega, 1e-5 * omega);
      const glm::dvec3 w(c->wi);
      const double t = (1.0 - glm::dot(w, axis)) / one_minus_cos_max;
      const double phi = std::atan2(glm::dot(w, by), glm::dot(w, bx)) / (2.0 * kPiD) + 0.5;
      const int ct = std::clamp(static_cast<int>(t * kGrid), 0, kGrid - 1), cp = std::clamp(static_cast<int>(phi * kGrid), 0, kGrid - 1);
      // Inside the cone, to the float rounding of wi (its cosine to ~2.4e-7, against a 0.7° cone's
      // 1 − cos θ_max of 7.3e-5).
      ASSERT_LT(t, 1.0 + 2.4e-7 / one_minus_cos_max) << "inside the cone";
      count[static_cast<std::size_t>(ct * kGrid + cp)] += 1.0;
      // ∫ density dA = 1 over the sphere (0 off the cap), by uniform points of it.
      const glm::vec3 n_a = sample_uniform_sphere(s.get2d());
      const glm::vec3 xa = center + radius * n_a;
      integral.add(towards_area_density(p, xa, n_a, ref) / p.pdf_area);
      // Irradiance at ref facing the sphere: cone against area sampling.
      const glm::vec3 n_ref = glm::vec3(axis);
      const std::optional<EndpointConnection> by_area = connect(p, SurfacePoint{xa, n_a, p.pdf_area}, ref);
      const double e_cone = c->weight.x * std::max(0.0f, glm::dot(c->wi, n_ref));
      const double e_area = by_area ? by_area->weight.x * std::max(0.0f, glm::dot(by_area->wi, n_ref)) : 0.0;
      difference.add(e_cone - e_area);
    }
    double chi2 = 0.0;
    for (double n : count) chi2 += (n - kSamples / double(kGrid * kGrid)) * (n - kSamples / double(kGrid * kGrid)) / (kSamples / double(kGrid * kGrid));
    test::stat_log("sphere cone chi2, viewpoint " + std::to_string(v), chi2, critical);
    EXPECT_LE(chi2, critical) << "viewpoint " << v;
    EXPECT_MC_NEAR(integral, 1.0, k);
    EXPECT_MC_NEAR(difference, 0.0, k);
  }
  // From inside (or on) the sphere: by area, density 1 / area.
  const glm::vec3 inside = center + glm::vec3(0.1f, 0.0f, 0.2f);
  EXPECT_EQ(towards_area_density(p, center + radius * glm::vec3(0, 1, 0), glm::vec3(0, 1, 0), inside), p.pdf_area);
  EXPECT_EQ(towards_area_density(p, center + radius * glm::vec3(0, 1, 0), glm::vec3(0, 1, 0), center + radius * glm::vec3(1, 0, 0)),
            p.pdf_area);
}

}  // namespace
}  // namespace pathex
