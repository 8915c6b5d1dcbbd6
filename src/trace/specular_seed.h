// The manifold walk's seed (trace/joins/manifold.h): a ray from one end of a join towards a
// specular shape, followed through the specular surfaces it meets as light would, its hits the
// chain that Newton's method then solves between the two ends. Scene geometry and random numbers
// only; what the estimator makes of the chain is the connector's (trace/joins/manifold_join.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "trace/joins/manifold.h"
#include "trace/render_scene.h"
#include "trace/vertex.h"

namespace pathex::tracer {

// A seed chain from end `from` (the light end a when from_light, else the eye end b): the ray
// towards a specular shape (drawn by rs.specular's seed_cdf; a point on its area, or a direction in
// the cone of a sphere), followed through every specular surface it meets (a mirror reflects; glass
// reflects with the Fresnel probability, else refracts) until it leaves them; its hits, light side
// first. Random numbers from counter-based `stream`, from number *drawn on (advanced past them).
ManifoldFailure seed_chain(const RenderScene& rs, const Vertex& from, bool from_light, std::uint64_t stream, std::uint64_t* drawn,
                           std::vector<ChainVertex>& chain);

}  // namespace pathex::tracer
