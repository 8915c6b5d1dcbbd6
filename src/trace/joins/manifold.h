// The `manifold` connector's walk (DESIGN §4): a chain D S…S D through smooth dielectric surfaces,
// joined by solving for the specular vertices between two fixed ends. This is manifold next-event
// estimation (Hanika, Droske and Fascione 2015, "Manifold Next Event Estimation"; Cycles' MNEE),
// on the half-vector constraints of manifold exploration (Jakob and Marschner 2012):
//
//  - the seed: a straight line from the eye end b towards the light end a; every smooth dielectric
//    surface it crosses becomes one specular vertex (a refraction), anything else blocks it;
//  - Newton's method on the constraints: at each vertex, the generalized half vector
//    h = η_i w_i + η_o w_o (w_i, w_o unit towards the neighbours, η the index on each one's side
//    as the seed crossed it)
//    must lie along the surface normal; its tangential part is the constraint, two numbers per
//    vertex. The Jacobian is by central differences in double precision along each vertex's
//    tangent frame (trace/differential.h); steps that do not reduce the largest constraint are
//    halved;
//  - the generalized geometry term: with a and the chain's constraints fixed, b moving over its
//    tangent plane moves the first chain vertex and so the direction leaving a; the irradiance the
//    chain carries to b per unit intensity at a is |dω_a / dA_b| (implicit function theorem:
//    dX/db = -(∂C/∂X)⁻¹ ∂C/∂b). Without a chain it is |cos_b| / d², the plain geometry term.
//
// The estimator is biased (Hanika et al.'s MNEE): one deterministic seed finds at most one of the
// chains joining a and b, and solutions the solver rejects (near-singular Jacobian, at the
// caustic's folds) are missed. README "The manifold connector" gives the bias measured.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "scene/scene.h"

namespace pathex {

// Limits of the walk (pathex trace --manifold-*), defaults from the published implementations.
struct ManifoldOptions {
  int max_iterations = 64;         // Newton iterations (Cycles' MNEE: 64; SMS: 20)
  double threshold = 1e-5;         // largest |tangential half vector| accepted as solved (SMS: 1e-5)
  double min_segment = 1e-3;       // shortest segment, as a fraction of the scene's size (Cycles: 1e-3)
  double singular = 1e-7;          // smallest |pivot| / largest |pivot| of the constraint Jacobian
  int max_trials = 100;            // seeds tried to find a solution again (its inverse probability)
  bool operator==(const ManifoldOptions&) const = default;
};

// Why a walk failed; kNone when it succeeded.
enum class ManifoldFailure : std::uint8_t {
  kNone,
  kNoSolution,      // a step left its surface, or halving could not reduce the constraints
  kOccluded,        // the seed met a surface that is not smooth glass, or a built segment is blocked
  kSingular,        // the constraint Jacobian is (nearly) singular
  kWrongType,       // the solution reflects where the seed refracted, or the reverse
  kTooShort,        // a segment is shorter than min_segment of the scene's size
  kIterationLimit,  // not solved within max_iterations
};

// One specular vertex of a chain: its surface and where it is.
struct ChainVertex {
  const ShapeGeometry* shape = nullptr;
  int id = -1;        // the shape's index in the scene (for the caller)
  int primitive = 0;
  double ior = 1.5;   // index inside / outside
  // The index on the light side and on the eye side of the vertex, fixed by the seed (a
  // refraction: one is ior, the other 1), so that the walk keeps each vertex's type.
  double eta_light = 1.0, eta_eye = 1.5;
  bool reflect = false;  // a reflection (both neighbours on one side; η equal), else a refraction
  glm::dvec3 p{0.0};
};

struct ManifoldWalk {
  ManifoldFailure failure = ManifoldFailure::kNone;
  int iterations = 0;   // Newton iterations taken
  double dw_db = 0.0;   // |dω_a / dA_b|: solid angle at a per unit area at b through the chain
};

// Solves the chain between a and b (b on a surface of unit normal nb) in place from its seed
// positions, then checks its type and segments and computes |dω_a / dA_b|. `scene_size` scales
// the shortest segment allowed.
ManifoldWalk solve_chain(std::vector<ChainVertex>& chain, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& nb,
                         double scene_size, const ManifoldOptions& o);

}  // namespace pathex
