// The two ways an environment image covers the sphere of directions: pbrt-v4's equal-area square
// and Mitsuba 3's latitude-longitude rectangle. The scene reads images in either (its
// illuminance is integrated over the sphere when it is loaded) and the tracer looks them up and
// samples them (trace/environment.h): both use these, so they sit below both.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace pathex {

// pbrt-v4's equal-area mapping of the square [0,1]² onto the unit sphere (Clarberg's octahedral
// construction: the square's centre is +z, its corners −z) and its inverse.
glm::vec3 equal_area_square_to_sphere(glm::vec2 p);
glm::vec2 equal_area_sphere_to_square(const glm::vec3& d);
// Mitsuba 3's latitude-longitude mapping: u = φ / 2π, v = θ / π, with the direction
// (sin φ sin θ, cos θ, −cos φ sin θ): v = 0 is +Y (the image's top row), u = 0 is −Z.
glm::vec3 latlong_to_direction(glm::vec2 uv);
glm::vec2 direction_to_latlong(const glm::vec3& d);

}  // namespace pathex
