// The `manifold` connector's walk (DESIGN §4): a chain D S…S D through smooth glass and mirrors,
// joined by solving for the specular vertices between two fixed ends, on the half-vector
// constraints of manifold exploration (Jakob and Marschner 2012):
//
//  - the seed (trace/joins/manifold_join.cpp): a ray from either end towards a specular shape,
//    followed through the specular surfaces it meets; every hit becomes one specular vertex whose
//    type (reflection or refraction) and indices on either side stay fixed;
//  - Newton's method on the constraints: at each vertex, the generalized half vector
//    h = η_i w_i + η_o w_o (w_i, w_o unit towards the neighbours, η the index on each one's side)
//    must lie along the surface normal; its tangential part is the constraint, two numbers per
//    vertex. The Jacobian is analytic, in double precision, along each vertex's tangent frame
//    (the position and normal derivatives of trace/differential.h); steps that do not reduce the
//    largest constraint are halved;
//  - the generalized geometry term: with a and the chain's constraints fixed, b moving over its
//    tangent plane moves the first chain vertex and so the direction leaving a; the irradiance the
//    chain carries to b per unit intensity at a is |dω_a / dA_b| (implicit function theorem:
//    dX/db = -(∂C/∂X)⁻¹ ∂C/∂b). Without a chain it is |cos_b| / d², the plain geometry term.
//
// The estimator is specular manifold sampling (Zeltner, Georgiev and Jakob 2020) over batches of
// seeds: every distinct chain a first batch finds is weighed by the number of fresh batches it
// takes to find it again, whose mean is the inverse of the probability that a batch finds it;
// unbiased but for the chains still not found after max_trials seeds (counted). README "The
// manifold connector" gives the figures.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "scene/scene.h"

namespace pathex {

// Limits of the walk (pathex trace --manifold-*), defaults from the published implementations.
struct ManifoldOptions {
  int max_iterations = 64;         // Newton iterations (Cycles' MNEE: 64; SMS: 20)
  double threshold = 1e-5;         // largest |tangential half vector| accepted as solved (SMS: 1e-5), then polished to a root
  double min_segment = 1e-3;       // shortest segment, as a fraction of the scene's size (Cycles: 1e-3)
  double singular = 1e-7;          // smallest |pivot| / largest |pivot| of the constraint Jacobian
  std::optional<int> seeds;        // seeds per batch (the first's distinct chains: the contributions); unset: ditto
  int max_trials = 2000;           // seeds spent finding them again (their inverse probability), at most
  // Biased when > 0 (Zeltner et al. 2020's fixed-trials variant): a join draws this many seeds and
  // counts every distinct chain they find once, with no inverse-probability estimate (a chain a
  // join finds with probability p < 1 is underweighted by p). 0: the unbiased estimator above.
  int biased_trials = 0;
  // The share of eye subpaths whose joins run the connector (a coin per sample, its own stream; unbiased:
  // a contribution is divided by it, MIS counts it in n_i p_i). Unset: the profile's (trace/render.h).
  std::optional<double> rate;
  bool operator==(const ManifoldOptions&) const = default;
};

// Why a walk failed; kNone when it succeeded.
enum class ManifoldFailure : std::uint8_t {
  kNone,
  kNoSolution,      // a step left its surface, halving could not reduce the constraints, or polishing stalled short of a root
  kOccluded,        // the seed met a surface that is not smooth glass, or a built segment is blocked
  kSingular,        // the constraint Jacobian is (nearly) singular
  kWrongType,       // the solution reflects where the seed refracted, or the reverse
  kTooShort,        // a segment is shorter than min_segment of the scene's size
  kIterationLimit,  // not solved within max_iterations
  kUnrequested,     // (the connector's, before solving) under --only, the chain's path is in no requested class
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
  // The side of the light-side neighbour, fixed by the seed: +1 on the normal's side, -1 behind
  // it, 0 unchecked. Without it a reflection on a mirror sphere also "solves" at a point that
  // sees neither neighbour (the half vector along -n).
  int light_side = 0;
};

struct ManifoldWalk {
  ManifoldFailure failure = ManifoldFailure::kNone;
  int iterations = 0;   // Newton iterations taken
  double dw_db = 0.0;   // |dω_a / dA_b|: solid angle at a per unit area at b through the chain
};

// A distinct chain a join's first batch of seeds found, and the batch that found it again (0: none yet).
struct ManifoldSolution {
  std::vector<ChainVertex> chain;
  double dw_db = 0.0;
  int batches = 0;
};

// Solves the chain between a and b (b on a surface of unit normal nb) in place from its seed
// positions, then checks its type and segments and, with `term`, computes |dω_a / dA_b| (a
// singular term fails the walk). `scene_size` scales the shortest segment allowed. Without
// `term` (a seed that only has to say which chain it finds) dw_db stays 0.
ManifoldWalk solve_chain(std::vector<ChainVertex>& chain, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& nb,
                         double scene_size, const ManifoldOptions& o, bool term = true);

// |dω_a / dA_b| of a chain whose vertices lie on their surfaces (solved, or a path a walk traced
// through them): the solid angle at a per unit area at b (unit normal nb) as b moves and the
// chain's constraints stay fixed. 0 when the constraint Jacobian's smallest pivot over its largest
// is at or below `singular`, or the chain is undefined (coincident points). The MIS densities of a
// path through a chain use it too (Integrator::chain_densities()).
double chain_dw_db(const std::vector<ChainVertex>& chain, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& nb,
                   double singular);

}  // namespace pathex
