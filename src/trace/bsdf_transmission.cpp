// Diffuse transmission (pbrt-v4's DiffuseTransmissionBxDF): a Lambertian lobe of `reflectance` on
// wo's side and one of `transmittance` on the other, both finite (letter D). Sampling picks the
// side with probability proportional to the channels' maxima, pr = max(R) / (max(R) + max(T)),
// then a cosine-weighted direction on it; the density is pr |cos θi| / π or (1 − pr) |cos θi| / π.
// Two-sided and symmetric: eval(wo, wi) == eval(wi, wo).
#include <algorithm>
#include <cmath>

#include "trace/bsdf_kinds.h"
#include "trace/rng.h"

namespace pathex::bsdf::kinds {
namespace {

float max3(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

// The probability of sampling the reflection lobe; 0 / 0 (a black material) gives 0.
float reflect_probability(const DiffuseTransmission& d) {
  const float pr = max3(d.reflectance), pt = max3(d.transmittance);
  return pr + pt > 0.0f ? pr / (pr + pt) : 0.0f;
}

}  // namespace

glm::vec3 diffuse_transmission_eval(const DiffuseTransmission& d, const glm::vec3&, const glm::vec3& wi) {
  if (wi.z == 0.0f) return glm::vec3(0.0f);
  return (wi.z > 0.0f ? d.reflectance : d.transmittance) * kInvPi;
}

float diffuse_transmission_pdf(const DiffuseTransmission& d, const glm::vec3&, const glm::vec3& wi) {
  if (wi.z == 0.0f) return 0.0f;
  const float pr = reflect_probability(d);
  return (wi.z > 0.0f ? pr : 1.0f - pr) * std::abs(wi.z) * kInvPi;
}

std::optional<LocalSample> diffuse_transmission_sample(const DiffuseTransmission& d, const glm::vec3&, float uc,
                                                       glm::vec2 u) {
  glm::vec3 wi = sample_cosine_hemisphere(u);
  if (uc < reflect_probability(d)) return LocalSample{wi, Lobe::kDiffuseReflection};
  wi.z = -wi.z;
  return LocalSample{wi, Lobe::kDiffuseTransmission};
}

}  // namespace pathex::bsdf::kinds
