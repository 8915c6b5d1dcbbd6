// Hard cases (DESIGN §10, issue 13): every sampling routine the tracer calls, driven by the random
// generator's extreme values. The generator returns k / 2^24 for k = 0 … 2^24 − 1 (trace/rng.h),
// so 0.0 and kOneMinusEpsilon (the largest float below 1) do occur — once in 2^24 draws, i.e.
// several times in a 128 spp render of a 512 × 512 image. A sample drawn there must either carry
// nothing (nullopt) or have finite, nonzero densities wherever the integrator divides by them
// (issue 13's known bug: u = 0.0 mapped to a direction in the light's own plane, cos θ = 0,
// density 0, and a light subpath divided 0 by 0).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "trace/bsdf.h"
#include "trace/emitters.h"
#include "trace/rng.h"

namespace pathex {
namespace {

// The extremes and their neighbours: 0, the smallest nonzero value, ½, and the two largest.
const std::vector<float> kExtremes = {0.0f, 0x1p-24f, 0.5f, 1.0f - 0x1p-23f, kOneMinusEpsilon};

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// A sampled ray that carries light has finite, positive densities (unless Dirac) and a finite weight.
void expect_usable(const EndpointRay& r, const std::string& what) {
  EXPECT_TRUE(finite3(r.weight)) << what;
  EXPECT_TRUE(finite3(r.direction)) << what;
  if (!r.pdf.delta_dir) {
    EXPECT_GT(r.pdf.dir, 0.0f) << what << ": a sampled direction of density 0";
    EXPECT_TRUE(std::isfinite(r.pdf.dir)) << what;
  }
  if (!r.pdf.delta_pos) {
    EXPECT_GT(r.pdf.pos, 0.0f) << what;
    EXPECT_TRUE(std::isfinite(r.pdf.pos)) << what;
  }
}

std::string at(float a, float b) { return "u = (" + std::to_string(a) + ", " + std::to_string(b) + ")"; }

TEST(Extremes, AreaLightRaysLeaveTheLightsPlaneWithPositiveDensity) {
  for (bool two_sided : {false, true}) {
    const AreaLightParams light{glm::vec3(1.0f), two_sided};
    // Normals along the axes and a tilted one: the frame's rounding differs.
    for (const glm::vec3& n : {glm::vec3(0, 0, 1), glm::vec3(0, -1, 0), glm::normalize(glm::vec3(0.3f, -0.9f, 0.1f))}) {
      const SurfacePoint x{glm::vec3(0.1f, 1.98f, -0.2f), n, 1.0f / 0.0125f};
      for (float a : kExtremes)
        for (float b : kExtremes) {
          const std::optional<EndpointRay> r = sample_ray(light, x, {a, b});
          if (!r) continue;
          const std::string what = std::string(two_sided ? "two-sided" : "one-sided") + " area light, " + at(a, b);
          expect_usable(*r, what);
          // The density pdf_ray() gives for the same direction (what MIS divides by) agrees and is positive.
          const RayPdf again = pdf_ray(light, x, r->direction);
          EXPECT_GT(again.dir, 0.0f) << what << ": cos θ = " << glm::dot(n, r->direction);
          EXPECT_GT(std::abs(glm::dot(n, r->direction)), 0.0f) << what;
        }
    }
  }
}

TEST(Extremes, PointSpotAndDistantLightRaysAreUsable) {
  const PointLightParams point{glm::vec3(0.0f), glm::vec3(1.0f)};
  SpotLightParams spot;
  spot.position = glm::vec3(0.0f);
  spot.axis = glm::vec3(0, -1, 0);
  spot.intensity = glm::vec3(1.0f);
  spot.cos_total = std::cos(0.5f);
  spot.cos_falloff_start = std::cos(0.5f);
  for (float a : kExtremes)
    for (float b : kExtremes) {
      if (auto r = sample_ray(point, {a, b})) expect_usable(*r, "point light, " + at(a, b));
      if (auto r = sample_ray(spot, {a, b})) expect_usable(*r, "spot light, " + at(a, b));
    }
}

TEST(Extremes, PinholeRaysAtTheImageCornersAreUsable) {
  const PinholeParams cam;
  for (float a : kExtremes)
    for (float b : kExtremes)
      if (auto r = sample_ray(cam, {a, b})) expect_usable(*r, "pinhole, raster " + at(a, b));
}

// Every material kind, lit from several directions (normal, oblique, grazing at cos θ = 1e-6),
// sampled with extreme numbers: a sample has a finite weight and, when finite, positive densities.
TEST(Extremes, BsdfSamplesAreUsable) {
  const std::vector<std::pair<std::string, Material>> materials = {
      {"diffuse", Diffuse{glm::vec3(0.8f)}},
      {"mirror", Mirror{glm::vec3(0.9f)}},
      {"glass", Dielectric{1.5f, glm::vec3(1.0f)}},
      {"glossy 0.3", Glossy{glm::vec3(0.9f), 0.3f}},
      {"glossy 1e-4", Glossy{glm::vec3(0.9f), 1e-4f}},
      {"mixture", Mixture{{{0.5f, Diffuse{glm::vec3(0.8f)}}, {0.1f, Mirror{glm::vec3(1.0f)}}, {0.3f, Glossy{glm::vec3(0.9f), 0.01f}}}}},
  };
  const glm::vec3 n(0, 0, 1);
  const float grazing = 1e-6f;
  const std::vector<glm::vec3> wos = {glm::vec3(0, 0, 1), glm::normalize(glm::vec3(0.6f, 0.2f, 0.7f)),
                                      glm::normalize(glm::vec3(1.0f, 0.0f, grazing)), glm::vec3(0, 0, -1)};
  for (const auto& [name, m] : materials)
    for (const glm::vec3& wo : wos)
      for (TransportMode mode : {TransportMode::kRadiance, TransportMode::kImportance})
        for (float c : kExtremes)
          for (float a : kExtremes)
            for (float b : kExtremes) {
              const std::optional<BsdfSample> s = bsdf::sample(m, wo, n, n, c, {a, b}, mode);
              if (!s) continue;
              const std::string what = name + ", wo.z = " + std::to_string(wo.z) + ", u_c = " + std::to_string(c) + ", " + at(a, b);
              EXPECT_TRUE(finite3(s->weight)) << what;
              EXPECT_TRUE(finite3(s->wi)) << what;
              EXPECT_TRUE(std::isfinite(s->pdf)) << what;
              if (!s->is_delta) {
                EXPECT_GT(s->pdf, 0.0f) << what;
                EXPECT_TRUE(std::isfinite(s->pdf_rev)) << what;
              }
            }
}

}  // namespace
}  // namespace pathex
