// Embree 3 geometry for a Scene: ray queries, visibility, and uniform sampling of shapes.
//
// Meshes and quads are Embree triangles and quads; spheres and disks are Embree user geometry
// with exact analytic intersection (a numerically stable quadratic for spheres), so the closed
// forms of DESIGN §9 are not blurred by tessellation. The device and scene are RAII handles; one
// error callback collects Embree's own errors, which build() returns as an Error value. All
// queries are const and thread-safe (TBB calls them concurrently).
//
// Self-intersection (pbrt-v4's method, Pharr, Jakob and Humphreys, "Physically Based Rendering",
// 4th ed., sec. 6.8; Wächter and Binder, Ray Tracing Gems ch. 6): every hit and every sampled
// surface point carries `error`, a per-component bound on the rounding error of its position
// relative to the surface as Embree and the analytic tests see it (from the magnitudes that went
// into computing it: gamma(n) * (|b0 p0| + |b1 p1| + |b2 p2|) for a triangle, and so on). A ray
// leaving the surface starts at the point moved along the geometric normal, to the side the ray
// goes, by the error bound's extent along the normal, dot(|n|, error), and then rounded one float
// further away: the new origin is provably on the ray's side of the surface. The offset depends
// on the point and its own primitive only, never on the scene's size: a ground plane 1e6 away, or
// a far sphere, leaves the rest of the scene untouched (tests/scene/embree_test.cpp,
// tests/trace/render_test.cpp). The raw queries (intersect/occluded with tmin, tmax) take the ray
// as given; the robust ones (intersect with an origin normal and error, visible, OcclusionBatch)
// offset. Points in free space (lights, pinholes: normal zero) are not moved. Hit positions are
// put back onto the exact surface, so the bounds only cover rounding. The price of float
// coordinates stays: the error (and so the offset) is about 1e-6 of the magnitudes involved, so
// features (radii, gaps, contacts) should be larger than that.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include "core/error.h"
#include "scene/scene.h"
#include "trace/differential.h"

namespace pathex {

struct Hit {
  float t = 0.0f;                  // along the query's direction as given (not normalised)
  glm::vec3 position{0.0f};        // on the surface
  glm::vec3 normal{0.0f};          // geometric, unit, the shape's outward side (whichever side was hit)
  glm::vec3 shading_normal{0.0f};  // unit: a mesh's interpolated vertex normals where it has them, else `normal`
  glm::vec3 error{0.0f};           // bound on |position - the exact surface point|, per component
  int shape = -1;                  // index into Scene::shapes (an instance's hit: the group member's)
  int primitive = -1;              // triangle index for meshes, 0 otherwise
  int instance = -1;               // index into Scene::instances, -1 for shapes placed in the world
  // Surface parameters (HitDetail::kFull only; zero otherwise), the textures' coordinates: mesh,
  // its per-vertex uv interpolated, or without them pbrt-v4's default (0, 0), (1, 0), (1, 1) at the
  // triangle's corners, (w1 + w2, w2) for Embree's barycentrics w1, w2; quad, position = corner + u edge1 + v edge2; sphere, u = phi / 2pi with
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
  glm::vec3 error{0.0f};   // as Hit::error
};

// |v| per component. Not glm::abs, whose x >= 0 ? x : -x (which keeps -0) compiles to a branch per
// component; here the sign bits are cleared (the bounds below and the offsets add such terms, where
// -0 and +0 are the same).
inline glm::vec3 abs3(const glm::vec3& v) { return {std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}; }

// gamma(n) = n u / (1 - n u) with u = 2^-24, the unit roundoff of float: the bound on the
// relative error of n successive float operations (pbrt-v4's gamma()).
constexpr float error_gamma(int n) {
  constexpr float u = 0x1p-24f;
  return static_cast<float>(n) * u / (1.0f - static_cast<float>(n) * u);
}

// A ray that leaves a triangle or quad is tested against it again by Embree, whose rounding in
// that test grows with the distance from the ray's origin to the primitive's vertices: the
// primitive's size `extent`, in every direction (an exact point on the plane y = 0 has no error
// of its own, yet a ray leaving it exactly there can hit the plane again at a tiny t). Bounds of
// points on triangles and quads include this term.
inline glm::vec3 primitive_test_error(float extent) { return glm::vec3(error_gamma(12) * extent); }

// The error bound of a point corner + u edge1 + v edge2 (u, v in [0, 1]) on a parallelogram whose
// corners are float: a quad shape's hits and samples, a distant light's aperture points.
inline glm::vec3 parallelogram_error(const glm::vec3& corner, const glm::vec3& edge1, const glm::vec3& edge2) {
  const glm::vec3 span = glm::abs(edge1) + glm::abs(edge2);
  return error_gamma(8) * (glm::abs(corner) + span) + primitive_test_error(std::max(span.x, std::max(span.y, span.z)));
}

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
  // Queues the segment between a and b (normals and error bounds as for EmbreeScene::visible();
  // zero for points in free space) and returns its lane. The batch must not be full.
  int add(const EmbreeScene& scene, const glm::vec3& a, const glm::vec3& na, const glm::vec3& ea, const glm::vec3& b,
          const glm::vec3& nb, const glm::vec3& eb);
  // Tests every queued segment; visible(lane) then holds until clear().
  void trace(const EmbreeScene& scene);
  bool visible(int lane) const { return rays_.tfar[lane] >= 0.0f; }
  void clear() { size_ = 0; }

 private:
  alignas(64) RTCRay16 rays_;
  alignas(64) int valid_[kCapacity];
  int size_ = 0;
};

// Closest hits of up to 16 rays traced together, as one coherent packet (rtcIntersect16 with
// Embree's coherent flag): the eye subpaths' first rays, which leave one point (a pinhole) or a
// small lens for neighbouring pixels and passes, cost about a third of what they cost one by one
// (bench/trace_bench BM_EyeRayPackets, which also checks that every hit is the one
// EmbreeScene::intersect() finds: the same test of the same ray, and the same Hit made from it).
// Raw queries (no offset: a sensor point has no rounding error to move off). One writer.
class RayPacket {
 public:
  static constexpr int kCapacity = 16;
  int size() const { return size_; }
  bool full() const { return size_ == kCapacity; }
  // Queues the ray o + t d, t > 0 (as EmbreeScene::intersect(o, d, 0, inf)) and returns its lane.
  int add(const glm::vec3& o, const glm::vec3& d);
  // Traces every queued ray; hit(lane) then holds until clear().
  void trace(const EmbreeScene& scene);
  // The closest hit of lane's ray, as EmbreeScene::intersect(o, d, 0, inf, detail) returns it.
  std::optional<Hit> hit(const EmbreeScene& scene, int lane, HitDetail detail) const;
  void clear() { size_ = 0; }

 private:
  alignas(64) RTCRayHit16 rays_;
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
  // The closest hit along o + t d, t > 0, from a point with normal `origin_normal` and error bound
  // `origin_error` (both zero for points in free space), moved off its surface first.
  std::optional<Hit> intersect(const glm::vec3& o, const glm::vec3& d, const glm::vec3& origin_normal,
                               const glm::vec3& origin_error, HitDetail detail = HitDetail::kFull) const;
  // Whether the segment between two surface points (normal n, error bound e; both zero for a
  // point in free space) is unobstructed.
  bool visible(const glm::vec3& a, const glm::vec3& na, const glm::vec3& ea, const glm::vec3& b, const glm::vec3& nb,
               const glm::vec3& eb) const;
  bool visible(const glm::vec3& a, const glm::vec3& b) const {
    const glm::vec3 zero(0.0f);
    return visible(a, zero, zero, b, zero, zero);
  }
  // p (normal n, error bound e) moved off its surface towards the side of direction d: by
  // dot(|n|, e) along n, then one float further in each component that moved. Inline: every ray
  // the tracer casts takes one or two.
  static glm::vec3 offset(const glm::vec3& p, const glm::vec3& n, const glm::vec3& e, const glm::vec3& d) {
    // A zero normal or error (a point: lights, pinholes) offsets by exactly zero, without a branch
    // whose outcome would follow which ends of a connection are points. No branches on signs
    // either (glm::abs and a choice of ±dist compiled to four, mispredicted as often as the
    // scene's normals and the rays' directions change sign): abs3(), and the side's sign put into
    // dist's sign bit (dist >= 0, so this is -dist exactly when d points below the surface).
    const float dist = glm::dot(abs3(n), e);
    const std::uint32_t below = glm::dot(n, d) >= 0.0f ? 0u : 0x80000000u;
    const glm::vec3 off = std::bit_cast<float>(std::bit_cast<std::uint32_t>(dist) ^ below) * n;
    return away(p + off, off);
  }
  // Each component of x moved to the next float towards the sign of dir's (kept when dir's is
  // zero or x's is not finite): std::nextafter(x, ±inf), on the bits, where adding one moves a
  // float one step away from zero. Four lanes at once (GCC vector extensions): every ray the
  // tracer casts takes one or two, and the signs follow the scene's orientation, which no branch
  // predictor guesses.
  static glm::vec3 away(const glm::vec3& x, const glm::vec3& dir) {
    using F4 = float __attribute__((vector_size(16)));
    using U4 = std::uint32_t __attribute__((vector_size(16)));
    using I4 = std::int32_t __attribute__((vector_size(16)));
    const F4 xf{x.x, x.y, x.z, 0.0f}, df{dir.x, dir.y, dir.z, 0.0f};
    const U4 b = std::bit_cast<U4>(xf);
    const U4 neg = std::bit_cast<U4>(I4(df < 0.0f));             // all ones: step down
    const U4 same = ~(neg ^ std::bit_cast<U4>(I4(std::bit_cast<I4>(b) < 0)));  // x lies on that side
    const U4 stepped = b + 1u - (~same & 2u);                     // |x| one float larger, or smaller
    const U4 zero = std::bit_cast<U4>(I4((b & 0x7FFFFFFFu) == 0u));  // ±0: the least subnormal of dir's sign
    const U4 moved = (zero & ((neg & 0x80000000u) | 1u)) | (~zero & stepped);
    const U4 keep = std::bit_cast<U4>(I4(df == 0.0f)) | std::bit_cast<U4>(I4((b & 0x7F800000u) == 0x7F800000u));
    const F4 r = std::bit_cast<F4>((keep & b) | (~keep & moved));
    return {r[0], r[1], r[2]};
  }
  // The shadow ray between a and b as visible() casts it (o + t d, 0 < t < 1): from a moved off
  // its surface to b moved off its own. OcclusionBatch casts the same ray.
  static void shadow_ray(const glm::vec3& a, const glm::vec3& na, const glm::vec3& ea, const glm::vec3& b,
                         const glm::vec3& nb, const glm::vec3& eb, glm::vec3* o, glm::vec3* d) {
    *o = offset(a, na, ea, b - a);
    *d = offset(b, nb, eb, a - b) - *o;
  }

  // --- shapes ---
  float shape_area(int shape) const { return areas_[static_cast<std::size_t>(shape)]; }
  // The density of sample_shape() per unit area: 1 / area (0 for a zero-area shape).
  float area_pdf(int shape) const;
  // A point uniformly distributed by area on the shape; meshes pick a triangle by area.
  SurfaceSample sample_shape(int shape, glm::vec2 u) const;
  // The unit geometric normal of a shape at a point on it (`primitive`: the triangle of a mesh).
  glm::vec3 normal_at(int shape, int primitive, const glm::vec3& p) const;
  // dp/du and dp/dv at a hit (HitDetail::kFull), the tangents of Hit::uv in the world, from which
  // bump and normal maps build their frame (trace/texture_eval.h perturbed_normal): a triangle's
  // from its corners and their uv (pbrt-v4's Triangle), a quad's edges, a sphere's and a disk's
  // from their (u, v) maps. Zero (or parallel) where the uv are degenerate, a sphere's poles.
  void uv_tangents(const Hit& h, glm::vec3* dpdu, glm::vec3* dpdv) const;
  // The surface parameters (Hit::uv) of a point p on a shape (`primitive`: the triangle of a mesh),
  // as a hit there computes them; for points found otherwise than by a ray (the manifold's chains).
  glm::vec2 uv_at(int shape, int primitive, const glm::vec3& p) const;
  // A shape's geometry as the scene gives it.
  const ShapeGeometry& shape_geometry(int shape) const { return source_->shapes[static_cast<std::size_t>(shape)].geometry; }
  // A hit's position and normal derivatives (trace/differential.h), computed only when asked: the
  // manifold connector's walk along surfaces needs them, the hot loop's hits do not.
  SurfaceDerivatives derivatives(const Hit& h) const {
    return surface_derivatives(shape_geometry(h.shape), h.primitive, glm::dvec3(h.position));
  }

  // An instance's transform as the hits use it (EmbreeScene::intersect): the member's triangle
  // corners are moved to the world by `to_world` (as flattening would place them) and the hit is
  // computed from them; shading normals by `normal_matrix` (the inverse transpose). `flips`: the
  // transform mirrors (negative determinant), so the front side is the other one. `error_scale`
  // bounds the rounding of Embree's ray transform to the group's space and back: a per-component
  // multiple of (|x| + |translation|) (see intersect()).
  struct InstanceTransform {
    glm::mat4 to_world{1.0f};
    glm::mat3 normal_matrix{1.0f};
    glm::mat3 error_scale{0.0f};
    glm::vec3 abs_translation{0.0f};
    bool flips = false;
  };
  const InstanceTransform& instance_transform(int instance) const { return instances_[static_cast<std::size_t>(instance)]; }

  RTCScene handle() const { return scene_.get(); }
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
  std::vector<std::unique_ptr<RTCSceneTy, SceneRelease>> groups_;  // one Embree scene per ShapeGroup
  std::unique_ptr<RTCSceneTy, SceneRelease> scene_;

  void instance_hit(unsigned inst_geom, unsigned geom, float u, float v, const glm::vec3& d, HitDetail detail, Hit* h) const;
  // What Embree reported of a ray's closest hit, and the Hit made from it (the ray o + t d).
  struct RawHit {
    float t, u, v;
    unsigned geom, prim, inst;
  };
  void finish_hit(const glm::vec3& o, const glm::vec3& d, const RawHit& raw, HitDetail detail, Hit& h) const;
  friend class RayPacket;

  const Scene* source_ = nullptr;
  std::vector<float> areas_;
  std::vector<glm::vec3> quad_normals_;  // unit, per shape (zero for other kinds)
  // The error bound of every point of a quad or disk (parallelogram_error(), disk_error()), per
  // shape, once per scene: it depends on the shape alone (zero for other kinds).
  std::vector<glm::vec3> shape_errors_;
  std::vector<std::vector<double>> triangle_cdf_;  // meshes: cumulative triangle areas
  std::vector<unsigned> geom_to_shape_;
  std::vector<std::vector<unsigned>> group_geom_to_shape_;  // per group: its scene's geomID -> shape
  std::vector<InstanceTransform> instances_;                // per Scene::instances
  std::vector<unsigned> geom_to_instance_;                  // the top scene's geomID -> instance
  std::size_t triangles_ = 0;
};

}  // namespace pathex
