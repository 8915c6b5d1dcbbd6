// A smooth coat's mean internal reflectance: what the importers need to turn Mitsuba's plastic
// into the tracer's coated diffuse material (scene/mitsuba_import.cpp), below both.
#pragma once

namespace pathex {

// R̄ = ∫ 2μ F(−μ) dμ: the share of cosine-distributed light from inside that a smooth coat of
// index eta reflects back (total internal reflection included), by the midpoint rule on 4,096
// intervals (error below 1e-6). A thin smooth coat over a base of reflectance ρ has the diffuse
// albedo T(θo) ρ (1 − R̄) / (1 − ρ R̄) (tests/trace/bsdf_test.cpp).
float mean_internal_reflectance(float eta);

}  // namespace pathex
