// Embree 3 geometry for a Scene: ray queries, visibility, and uniform sampling of shapes.
//
// Meshes and quads are Embree triangles and quads; spheres and disks are Embree user geometry
// with exact analytic intersection (a numerically stable quadratic for spheres), so the closed
// forms of DESIGN §9 are not blurred by tessellation. One error callback reports Embree's own
// errors; the device and scene are RAII handles. All queries are const and thread-safe.
//
// Self-intersection: rays leave a surface from a point offset along the geometric normal by an
// epsilon proportional to the scene's size and the point's magnitude (kOffset), and shadow rays
// stop short of their target by the same amount.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include "core/error.h"
#include "scene/scene.h"

namespace pathex {

struct Hit {
  float t = 0.0f;
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};          // geometric, unit, the shape's outward side
  glm::vec3 shading_normal{0.0f};  // equal to `normal` (no interpolated normals yet)
  int shape = -1;
  int primitive = -1;
};

struct SurfaceSample {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};
};

class EmbreeScene {
 public:
  static Result<std::unique_ptr<EmbreeScene>> build(const Scene& scene);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // The closest hit along o + t d, t > 0; `origin_normal` (zero for points in free space) offsets
  // the origin off the surface it leaves.
  std::optional<Hit> intersect(const glm::vec3& o, const glm::vec3& d, const glm::vec3& origin_normal) const;
  // Whether the segment between two surface (or free-space) points is unobstructed.
  bool visible(const glm::vec3& a, const glm::vec3& na, const glm::vec3& b, const glm::vec3& nb) const;

  float shape_area(int shape) const { return areas_[static_cast<std::size_t>(shape)]; }
  // A point uniformly distributed by area on the shape (density 1 / shape_area).
  SurfaceSample sample_shape(int shape, glm::vec2 u) const;

  RTCScene handle() const { return scene_; }
  struct AnalyticRecord;  // a sphere or disk as Embree user geometry
  float extent() const { return extent_; }
  std::size_t triangle_count() const { return triangles_; }

 private:
  EmbreeScene() = default;
  glm::vec3 offset(const glm::vec3& p, const glm::vec3& n, const glm::vec3& d) const;

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  const Scene* source_ = nullptr;
  std::vector<float> areas_;
  std::vector<std::vector<float>> triangle_cdf_;  // meshes: cumulative triangle areas
  std::vector<unsigned> geom_to_shape_;
  float extent_ = 1.0f;
  float epsilon_ = 1e-4f;
  std::size_t triangles_ = 0;
  std::vector<std::unique_ptr<AnalyticRecord>> analytic_;  // must outlive scene_
};

}  // namespace pathex
