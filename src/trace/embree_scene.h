// Embree 3 geometry for a Scene: ray queries, visibility, and uniform sampling of shapes.
//
// Meshes and quads are Embree triangles and quads; spheres and disks are Embree user geometry
// with exact analytic intersection (a numerically stable quadratic for spheres), so the closed
// forms of DESIGN §9 are not blurred by tessellation. The device and scene are RAII handles; one
// error callback collects Embree's own errors, which build() returns as an Error value. All
// queries are const and thread-safe (TBB calls them concurrently).
//
// Self-intersection: the raw queries (intersect/occluded with tmin, tmax) take the ray as given.
// The robust ones (intersect with an origin normal, visible) move a ray's origin off the surface
// it leaves, along the geometric normal to the side the ray goes, by
//     offset_epsilon(p) = 1e-5 * extent + 1e-6 * max(|p.x|, |p.y|, |p.z|),
// where extent is the diagonal of the scene's bounds: proportional to the scene's size, and at
// least about 8 float ulps of the point's own coordinates, so scenes scaled by 1e-4 or 1e+4 and
// scenes far from the origin behave alike (tests/scene/embree_test.cpp). Hit positions are
// projected back onto the exact surface, so the offset only needs to cover rounding. The price
// of float coordinates: the offset is 1e-6 of the distance from the origin, so features (radii,
// gaps, contacts) should be larger than about 1e-4 of that distance; a unit box 1e+5 from the
// origin (coordinates step by 0.008 there) is beyond what float geometry can resolve.
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include "core/error.h"
#include "scene/scene.h"

namespace pathex {

struct Hit {
  float t = 0.0f;                  // along the query's direction as given (not normalised)
  glm::vec3 position{0.0f};        // on the surface
  glm::vec3 normal{0.0f};          // geometric, unit, the shape's outward side (whichever side was hit)
  glm::vec3 shading_normal{0.0f};  // equal to `normal` (no interpolated normals yet)
  int shape = -1;                  // index into Scene::shapes
  int primitive = -1;              // triangle index for meshes, 0 otherwise
  // Surface parameters (HitDetail::kFull only; zero otherwise): mesh, Embree's barycentrics (weights of the triangle's second and third
  // vertex); quad, position = corner + u edge1 + v edge2; sphere, u = phi / 2pi with
  // phi = atan2(y, x) about the centre in world axes, v = theta / pi with theta from +z; disk,
  // u = phi / 2pi in the disk's Frame::from_normal, v = distance from the centre / radius.
  glm::vec2 uv{0.0f};
};

// How much of a hit intersect() computes: everything, or all but the surface parameters (the
// tracer's query: uv costs a sphere an atan2 and an acos per hit, and no BSDF reads it yet).
enum class HitDetail : std::uint8_t { kFull, kNoUv };

struct SurfaceSample {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};  // geometric, unit, outward
};

class EmbreeScene;

// Shadow rays tested together. A renderer's connections are independent of each other, so a
// thread queues their segments here and has Embree trace them as one 16-wide ray packet
// (rtcOccluded16), which costs markedly less per ray than single rays (bench/trace_bench
// BM_ShadowRays). A batch with too few segments to fill much of a packet is traced ray by ray:
// a mostly empty packet costs more than its rays would alone. Same answers as
// EmbreeScene::visible() (tests/scene/embree_test.cpp): the same offsets, the same non-finite
// guard. One writer; the rays live in the batch (no allocation).
class OcclusionBatch {
 public:
  static constexpr int kCapacity = 16;
  static constexpr int kMinPacket = 9;  // fewer segments than this are traced one by one

  int size() const { return size_; }
  bool full() const { return size_ == kCapacity; }
  // Queues the segment between a and b (normals as for EmbreeScene::visible(); zero for points
  // in free space) and returns its lane. The batch must not be full.
  int add(const EmbreeScene& scene, const glm::vec3& a, const glm::vec3& na, const glm::vec3& b, const glm::vec3& nb);
  // Tests every queued segment; visible(lane) then holds until clear().
  void trace(const EmbreeScene& scene);
  bool visible(int lane) const { return rays_.tfar[lane] >= 0.0f; }
  void clear() { size_ = 0; }

 private:
  alignas(64) RTCRay16 rays_;
  alignas(64) int valid_[kCapacity];
  int size_ = 0;
};

class EmbreeScene {
  struct Key {
    explicit Key() = default;
  };

 public:
  // The Scene must outlive the EmbreeScene (shapes are read at query time).
  static Result<std::unique_ptr<EmbreeScene>> build(const Scene& scene);
  explicit EmbreeScene(Key);  // use build()
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // --- raw queries: the ray o + t d for tmin < t < tmax, no offsets ---
  std::optional<Hit> intersect(const glm::vec3& o, const glm::vec3& d, float tmin, float tmax,
                               HitDetail detail = HitDetail::kFull) const;
  bool occluded(const glm::vec3& o, const glm::vec3& d, float tmin, float tmax) const;

  // --- robust queries for rays that leave surfaces ---
  // The closest hit along o + t d, t > 0; `origin_normal` (zero for points in free space) offsets
  // the origin off the surface it leaves.
  std::optional<Hit> intersect(const glm::vec3& o, const glm::vec3& d, const glm::vec3& origin_normal,
                               HitDetail detail = HitDetail::kFull) const;
  // Whether the segment between two surface (or free-space, normal zero) points is unobstructed.
  bool visible(const glm::vec3& a, const glm::vec3& na, const glm::vec3& b, const glm::vec3& nb) const;
  bool visible(const glm::vec3& a, const glm::vec3& b) const { return visible(a, glm::vec3(0.0f), b, glm::vec3(0.0f)); }
  // p moved off its surface (normal n) towards the side of direction d; p itself when n is zero.
  // Inline: every ray the tracer casts takes one or two.
  glm::vec3 offset(const glm::vec3& p, const glm::vec3& n, const glm::vec3& d) const {
    // A zero normal (a point: lights, pinholes) offsets by exactly zero; no branch, whose outcome
    // would follow which ends of a connection are points.
    const float eps = offset_epsilon(p);
    return p + (glm::dot(n, d) >= 0.0f ? eps : -eps) * n;
  }
  // The shadow ray between a and b as visible() casts it (o + t d, 0 < t < 1): from a moved off
  // its surface to b moved off its own. OcclusionBatch casts the same ray.
  void shadow_ray(const glm::vec3& a, const glm::vec3& na, const glm::vec3& b, const glm::vec3& nb, glm::vec3* o,
                  glm::vec3* d) const {
    *o = offset(a, na, b - a);
    *d = offset(b, nb, a - b) - *o;
  }
  float offset_epsilon(const glm::vec3& p) const {
    return epsilon_ + 1e-6f * std::max(std::fabs(p.x), std::max(std::fabs(p.y), std::fabs(p.z)));
  }

  // --- shapes ---
  float shape_area(int shape) const { return areas_[static_cast<std::size_t>(shape)]; }
  // The density of sample_shape() per unit area: 1 / area (0 for a zero-area shape).
  float area_pdf(int shape) const;
  // A point uniformly distributed by area on the shape; meshes pick a triangle by area.
  SurfaceSample sample_shape(int shape, glm::vec2 u) const;
  // The unit geometric normal of a shape at a point on it (`primitive`: the triangle of a mesh).
  glm::vec3 normal_at(int shape, int primitive, const glm::vec3& p) const;

  RTCScene handle() const { return scene_.get(); }
  float extent() const { return extent_; }  // diagonal of the scene's bounding box
  std::size_t triangle_count() const { return triangles_; }

  struct AnalyticRecord;  // a sphere or disk as Embree user geometry
  struct ErrorSink;       // what the device's error callback saw

 private:
  struct DeviceRelease {
    void operator()(RTCDevice d) const { rtcReleaseDevice(d); }
  };
  struct SceneRelease {
    void operator()(RTCScene s) const { rtcReleaseScene(s); }
  };

  // Declaration order is destruction order reversed: the scene goes first, then the records
  // its user geometry points to, then the device, then the error sink the device reports to.
  std::unique_ptr<ErrorSink> errors_;
  std::unique_ptr<RTCDeviceTy, DeviceRelease> device_;
  std::vector<std::unique_ptr<AnalyticRecord>> analytic_;
  std::unique_ptr<RTCSceneTy, SceneRelease> scene_;

  const Scene* source_ = nullptr;
  std::vector<float> areas_;
  std::vector<glm::vec3> quad_normals_;  // unit, per shape (zero for other kinds)
  std::vector<std::vector<double>> triangle_cdf_;  // meshes: cumulative triangle areas
  std::vector<unsigned> geom_to_shape_;
  float extent_ = 1.0f;
  float epsilon_ = 1e-5f;
  std::size_t triangles_ = 0;
};

}  // namespace pathex
