#include "optics/internal_reflectance.h"

#include "optics/fresnel.h"

namespace pathex {

float mean_internal_reflectance(float eta) {
  constexpr int kSteps = 4096;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const double mu = (i + 0.5) / kSteps;
    sum += 2.0 * mu * fresnel_dielectric(static_cast<float>(-mu), eta);
  }
  return static_cast<float>(sum / kSteps);
}

}  // namespace pathex
