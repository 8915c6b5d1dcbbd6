// Embree geometry for a Scene (see embree_scene.h for the conventions): building the Embree
// scene, the user-geometry callbacks of the exact spheres and disks, ray queries with the
// self-intersection offset, and uniform area sampling of shapes. Every position computed here
// comes with its error bound (Hit::error, SurfaceSample::error), from the magnitudes it was
// computed from; the gamma(n) of each is the number of roundings on its way, rounded up.
#include "trace/embree_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include "trace/frame.h"
#include "trace/rng.h"
#include "trace/texture_eval.h"

namespace pathex {

// A sphere or disk (Embree user geometry), or a shape with an alpha cut-out (the filter's data).
struct EmbreeScene::AnalyticRecord {
  const Shape* shape;
  bool sphere;
  const Scene* scene = nullptr;  // with an alpha cut-out (Shape::alpha): the scene and the shape's index
  int index = -1;
};

// The device's one error callback writes here; build() turns the first message into an Error.
struct EmbreeScene::ErrorSink {
  std::mutex mutex;
  std::string first;
};

namespace {

using glm::vec3;
using Analytic = EmbreeScene::AnalyticRecord;

const char* error_name(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_UNKNOWN: return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
  }
  return "error";
}

void on_embree_error(void* user, RTCError code, const char* message) {
  auto* sink = static_cast<EmbreeScene::ErrorSink*>(user);
  std::lock_guard<std::mutex> lock(sink->mutex);
  if (sink->first.empty()) sink->first = std::string(error_name(code)) + (message ? std::string(": ") + message : "");
}

// --- spheres: a numerically stable quadratic (Haines et al., Ray Tracing Gems ch. 7) ---
// With f = o - c, a = d.d, b = f.d: the discriminant is computed as r^2 - |f - (b/a) d|^2, which
// does not cancel for rays far from the sphere, and the two roots as q/a and c/q, which do not
// cancel either.
bool sphere_t(const SphereShape& s, const vec3& o, const vec3& d, float tmin, float tmax, float* t_out) {
  const vec3 f = o - s.center;
  const float a = glm::dot(d, d);
  const float b = glm::dot(f, d);
  const vec3 perp = f - (b / a) * d;
  const float disc = s.radius * s.radius - glm::dot(perp, perp);
  if (disc < 0.0f) return false;
  const float c = glm::dot(f, f) - s.radius * s.radius;
  const float q = -b - std::copysign(std::sqrt(a * disc), b);
  float t0 = q / a, t1 = q != 0.0f ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > tmin && t0 < tmax) { *t_out = t0; return true; }
  if (t1 > tmin && t1 < tmax) { *t_out = t1; return true; }
  return false;
}

bool disk_t(const DiskShape& s, const vec3& o, const vec3& d, float tmin, float tmax, float* t_out) {
  const float dn = glm::dot(d, s.normal);
  if (dn == 0.0f) return false;
  const float t = glm::dot(s.center - o, s.normal) / dn;
  if (!(t > tmin && t < tmax)) return false;
  const vec3 p = o + t * d - s.center;
  if (glm::dot(p, p) > s.radius * s.radius) return false;
  *t_out = t;
  return true;
}

void analytic_bounds(const RTCBoundsFunctionArguments* args) {
  const Analytic* a = static_cast<const Analytic*>(args->geometryUserPtr);
  vec3 lo, hi;
  if (a->sphere) {
    const SphereShape& s = std::get<SphereShape>(a->shape->geometry);
    lo = s.center - vec3(s.radius);
    hi = s.center + vec3(s.radius);
  } else {
    const DiskShape& s = std::get<DiskShape>(a->shape->geometry);
    lo = s.center - vec3(s.radius);
    hi = s.center + vec3(s.radius);
  }
  args->bounds_o->lower_x = lo.x;
  args->bounds_o->lower_y = lo.y;
  args->bounds_o->lower_z = lo.z;
  args->bounds_o->upper_x = hi.x;
  args->bounds_o->upper_y = hi.y;
  args->bounds_o->upper_z = hi.z;
}

float unit_angle(float y, float x) {  // atan2 mapped to [0, 1)
  const float u = std::atan2(y, x) / (2.0f * kPi);
  return u < 0.0f ? u + 1.0f : u;
}

// (u, v) with p - corner = u e1 + v e2, for p in the parallelogram's plane.
glm::vec2 quad_uv(const QuadShape& q, const vec3& p) {
  const vec3 w = p - q.corner;
  const float e11 = glm::dot(q.edge1, q.edge1), e12 = glm::dot(q.edge1, q.edge2), e22 = glm::dot(q.edge2, q.edge2);
  const float w1 = glm::dot(w, q.edge1), w2 = glm::dot(w, q.edge2);
  const float det = e11 * e22 - e12 * e12;
  return {(w1 * e22 - w2 * e12) / det, (w2 * e11 - w1 * e12) / det};
}

// The surface parameters (Hit::uv) of the point p of `shape` that Embree reported on primitive
// `prim` at barycentrics (w1, w2) (meshes; p is used by the other kinds).
glm::vec2 shape_uv(const Shape& shape, unsigned prim, float w1, float w2, const vec3& p) {
  if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {  // the mesh's uv, or pbrt-v4's default (0, 0), (1, 0), (1, 1) per triangle
    const glm::uvec3 t = m->triangles[prim];
    return m->uvs.empty() ? glm::vec2(w1 + w2, w2) : (1.0f - w1 - w2) * m->uvs[t.x] + w1 * m->uvs[t.y] + w2 * m->uvs[t.z];
  }
  if (const auto* q = std::get_if<QuadShape>(&shape.geometry)) return glm::clamp(quad_uv(*q, p), 0.0f, 1.0f);
  if (const auto* s = std::get_if<SphereShape>(&shape.geometry)) {
    const vec3 n = glm::normalize(p - s->center);
    return {unit_angle(n.y, n.x), std::acos(std::clamp(n.z, -1.0f, 1.0f)) / kPi};
  }
  const DiskShape& k = std::get<DiskShape>(shape.geometry);
  const vec3 local = Frame::from_normal(k.normal).to_local(p - k.center);
  return {unit_angle(local.y, local.x), std::min(std::sqrt(local.x * local.x + local.y * local.y) / k.radius, 1.0f)};
}

// Whether a ray from o along d passes through the point p (at barycentrics w1, w2 of primitive
// prim) of a shape with an alpha cut-out (trace/texture_eval.h's alpha_passes).
bool passes(const Analytic* a, unsigned prim, float w1, float w2, const vec3& o, const vec3& d, const vec3& p) {
  if (!a || a->index < 0) return false;
  return alpha_passes(shape_alpha(*a->scene, a->index, shape_uv(*a->shape, prim, w1, w2, p)), o, d);
}

// Embree's filter for triangles and quads with a cut-out: a hit the cut-out lets pass is no hit.
void alpha_filter(const RTCFilterFunctionNArguments* args) {
  const Analytic* a = static_cast<const Analytic*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const vec3 o(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i), RTCRayN_org_z(args->ray, args->N, i));
    const vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i), RTCRayN_dir_z(args->ray, args->N, i));
    const vec3 p = o + RTCRayN_tfar(args->ray, args->N, i) * d;
    if (passes(a, RTCHitN_primID(args->hit, args->N, i), RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i), o, d, p))
      args->valid[i] = 0;
  }
}

// The nearest point in (tmin, tmax) of a sphere or disk that a ray meets. (`inline`: without the
// hint GCC calls it out of line from analytic_t(), 20 instructions more a ray.)
inline bool shape_t(const Analytic* a, const vec3& o, const vec3& d, float tmin, float tmax, float* t) {
  return a->sphere ? sphere_t(std::get<SphereShape>(a->shape->geometry), o, d, tmin, tmax, t)
                   : disk_t(std::get<DiskShape>(a->shape->geometry), o, d, tmin, tmax, t);
}

// shape_t() past the points a cut-out lets the ray through (a sphere has two).
bool cut_out_t(const Analytic* a, const vec3& o, const vec3& d, float tmin, float tmax, float* t) {
  for (int tries = 0; tries < 3; ++tries) {
    const bool hit = shape_t(a, o, d, tmin, tmax, t);
    if (!hit || !passes(a, 0, 0.0f, 0.0f, o, d, o + *t * d)) return hit;
    tmin = std::nextafter(*t, std::numeric_limits<float>::infinity());
  }
  return false;
}

// The ray's nearest point on a sphere or disk. Without a cut-out the test is as small as before
// cut-outs were added: it runs for every ray of a packet that meets the shape's bounds.
bool analytic_t(const Analytic* a, const vec3& o, const vec3& d, float tmin, float tmax, float* t) {
  return a->index < 0 ? shape_t(a, o, d, tmin, tmax, t) : cut_out_t(a, o, d, tmin, tmax, t);
}

void analytic_intersect(const RTCIntersectFunctionNArguments* args) {
  const Analytic* a = static_cast<const Analytic*>(args->geometryUserPtr);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const vec3 o(RTCRayN_org_x(ray, args->N, i), RTCRayN_org_y(ray, args->N, i), RTCRayN_org_z(ray, args->N, i));
    const vec3 d(RTCRayN_dir_x(ray, args->N, i), RTCRayN_dir_y(ray, args->N, i), RTCRayN_dir_z(ray, args->N, i));
    float t;
    if (!analytic_t(a, o, d, RTCRayN_tnear(ray, args->N, i), RTCRayN_tfar(ray, args->N, i), &t)) continue;
    RTCRayN_tfar(ray, args->N, i) = t;
    RTCHitN_geomID(hit, args->N, i) = args->geomID;
    RTCHitN_primID(hit, args->N, i) = args->primID;
    RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
    RTCHitN_u(hit, args->N, i) = 0.0f;  // normal and uv are recomputed exactly by intersect()
    RTCHitN_v(hit, args->N, i) = 0.0f;
    RTCHitN_Ng_x(hit, args->N, i) = 0.0f;
    RTCHitN_Ng_y(hit, args->N, i) = 0.0f;
    RTCHitN_Ng_z(hit, args->N, i) = 1.0f;
  }
}

void analytic_occluded(const RTCOccludedFunctionNArguments* args) {
  const Analytic* a = static_cast<const Analytic*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const vec3 o(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i), RTCRayN_org_z(args->ray, args->N, i));
    const vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i), RTCRayN_dir_z(args->ray, args->N, i));
    float t;
    if (analytic_t(a, o, d, RTCRayN_tnear(args->ray, args->N, i), RTCRayN_tfar(args->ray, args->N, i), &t))
      RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
  }
}



// --- positions and their error bounds ---

// b0 p0 + b1 p1 + b2 p2: three products and two sums per component, and barycentrics whose sum
// is 1 only up to rounding (pbrt-v4 bounds the same interpolation by gamma(7)); and Embree's test.
vec3 triangle_point(const vec3& p0, const vec3& p1, const vec3& p2, float b0, float b1, float b2, vec3* error) {
  const vec3 span = abs3(p1 - p0) + abs3(p2 - p0);
  *error = error_gamma(7) * (abs3(b0 * p0) + abs3(b1 * p1) + abs3(b2 * p2)) +
           primitive_test_error(std::max(span.x, std::max(span.y, span.z)));
  return b0 * p0 + b1 * p1 + b2 * p2;
}

// centre + radius n with n unit up to rounding: the reprojection and the sum (pbrt-v4: gamma(5)
// for the reprojection in object space, plus the move to world space).
vec3 sphere_error(const SphereShape& s, const vec3& n) {
  return error_gamma(8) * (abs3(s.center) + s.radius * abs3(n));
}

// A point of the disk's plane within the radius: a projection or a frame's rotation, and a sum.
vec3 disk_error(const DiskShape& d) { return error_gamma(8) * (glm::abs(d.center) + vec3(d.radius)); }

// Embree asserts that a ray's origin and direction are finite (Debian's build aborts the
// process otherwise). A non-finite ray is a bug upstream; it is treated as hitting nothing and
// as blocked, so that it carries no light, and never reaches Embree.
bool finite_ray(const vec3& o, const vec3& d) {
  // One test of the sum of products by zero: 0 * x is 0 for finite x and NaN for an infinity or
  // NaN, so the sum is 0 exactly when all six are finite (no short-circuit branches per component).
  const vec3 z = o * 0.0f + d * 0.0f;
  return z.x + z.y + z.z == 0.0f;
}

// Every field of the ray written once, in place (no zeroed temporary copied in: this runs for
// every ray the tracer casts).
void set_ray(RTCRay& ray, const vec3& o, const vec3& d, float tmin, float tmax) {
  ray.org_x = o.x;
  ray.org_y = o.y;
  ray.org_z = o.z;
  ray.tnear = tmin;
  ray.dir_x = d.x;
  ray.dir_y = d.y;
  ray.dir_z = d.z;
  ray.time = 0.0f;
  ray.tfar = tmax;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
}

}  // namespace

EmbreeScene::EmbreeScene(Key) : errors_(std::make_unique<ErrorSink>()) {}
EmbreeScene::~EmbreeScene() = default;

Result<std::unique_ptr<EmbreeScene>> EmbreeScene::build(const Scene& scene) {
  auto es = std::make_unique<EmbreeScene>(Key{});
  es->source_ = &scene;
  es->device_.reset(rtcNewDevice("verbose=0"));
  if (!es->device_)
    return make_error(ErrorCode::kBadValue, std::string("cannot create the Embree device: ") + error_name(rtcGetDeviceError(nullptr)));
  rtcSetDeviceErrorFunction(es->device_.get(), on_embree_error, es->errors_.get());
  es->scene_.reset(rtcNewScene(es->device_.get()));
  rtcSetSceneFlags(es->scene_.get(), RTC_SCENE_FLAG_ROBUST);
  RTCDevice device = es->device_.get();

  es->areas_.assign(scene.shapes.size(), 0.0f);
  es->quad_normals_.assign(scene.shapes.size(), vec3(0.0f));
  es->shape_errors_.assign(scene.shapes.size(), vec3(0.0f));
  es->triangle_cdf_.resize(scene.shapes.size());
  // Instancing: each group's members go into an Embree scene of their own, which every instance
  // of the group references with its transform (one copy of the geometry however many instances).
  es->group_geom_to_shape_.resize(scene.groups.size());
  for (std::size_t g = 0; g < scene.groups.size(); ++g) {
    es->groups_.emplace_back(rtcNewScene(device));
    rtcSetSceneFlags(es->groups_.back().get(), RTC_SCENE_FLAG_ROBUST);
  }
  for (std::size_t si = 0; si < scene.shapes.size(); ++si) {
    const Shape& shape = scene.shapes[si];
    RTCGeometry g = nullptr;
    if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {
      // --- triangle mesh; areas summed in double so a million triangles keep their share ---
      g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                            3 * sizeof(float), m->positions.size()));
      auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), m->triangles.size()));
      if (!v || !idx) {  // the error sink has the reason
        rtcReleaseGeometry(g);
        break;
      }
      for (std::size_t i = 0; i < m->positions.size(); ++i) {
        v[3 * i] = m->positions[i].x;
        v[3 * i + 1] = m->positions[i].y;
        v[3 * i + 2] = m->positions[i].z;
      }
      std::vector<double>& cdf = es->triangle_cdf_[si];
      if (shape.group < 0) cdf.reserve(m->triangles.size());  // members are never sampled (no emitters in instances)
      double total = 0.0;
      for (std::size_t i = 0; i < m->triangles.size(); ++i) {
        const glm::uvec3 t = m->triangles[i];
        idx[3 * i] = t.x;
        idx[3 * i + 1] = t.y;
        idx[3 * i + 2] = t.z;
        const glm::dvec3 p0(m->positions[t.x]), p1(m->positions[t.y]), p2(m->positions[t.z]);
        total += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
        if (shape.group < 0) cdf.push_back(total);
      }
      es->areas_[si] = static_cast<float>(total);
      es->triangles_ += m->triangles.size();
    } else if (const auto* q = std::get_if<QuadShape>(&shape.geometry)) {
      // --- quad: corner, +edge1, +edge1+edge2, +edge2 (Embree's u runs along edge1, v along edge2) ---
      g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_QUAD);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 4));
      auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 4 * sizeof(unsigned), 1));
      if (!v || !idx) {
        rtcReleaseGeometry(g);
        break;
      }
      const vec3 corners[4] = {q->corner, q->corner + q->edge1, q->corner + q->edge1 + q->edge2, q->corner + q->edge2};
      for (unsigned i = 0; i < 4; ++i) {
        v[3 * i] = corners[i].x;
        v[3 * i + 1] = corners[i].y;
        v[3 * i + 2] = corners[i].z;
        idx[i] = i;
      }
      es->areas_[si] = glm::length(glm::cross(q->edge1, q->edge2));
      es->quad_normals_[si] = glm::normalize(glm::cross(q->edge1, q->edge2));
      es->shape_errors_[si] = parallelogram_error(q->corner, q->edge1, q->edge2);
    } else {
      // --- sphere or disk: exact user geometry ---
      const bool sphere = std::holds_alternative<SphereShape>(shape.geometry);
      es->analytic_.push_back(std::make_unique<Analytic>(Analytic{&shape, sphere, &scene, shape.alpha >= 0 ? static_cast<int>(si) : -1}));
      g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
      rtcSetGeometryUserPrimitiveCount(g, 1);
      rtcSetGeometryUserData(g, es->analytic_.back().get());
      rtcSetGeometryBoundsFunction(g, analytic_bounds, nullptr);
      rtcSetGeometryIntersectFunction(g, analytic_intersect);
      rtcSetGeometryOccludedFunction(g, analytic_occluded);
      if (sphere) {
        const SphereShape& s = std::get<SphereShape>(shape.geometry);
        es->areas_[si] = 4.0f * kPi * s.radius * s.radius;
      } else {
        const DiskShape& s = std::get<DiskShape>(shape.geometry);
        es->areas_[si] = kPi * s.radius * s.radius;
        es->shape_errors_[si] = disk_error(s);
      }
    }
    if (shape.alpha >= 0 && !std::holds_alternative<SphereShape>(shape.geometry) && !std::holds_alternative<DiskShape>(shape.geometry)) {
      // a cut-out triangle mesh or quad: Embree's filter drops the hits it lets through
      es->analytic_.push_back(std::make_unique<Analytic>(Analytic{&shape, false, &scene, static_cast<int>(si)}));
      rtcSetGeometryUserData(g, es->analytic_.back().get());
      rtcSetGeometryIntersectFilterFunction(g, alpha_filter);
      rtcSetGeometryOccludedFilterFunction(g, alpha_filter);
    }
    rtcCommitGeometry(g);
    const bool member = shape.group >= 0;
    const unsigned id = rtcAttachGeometry(member ? es->groups_[static_cast<std::size_t>(shape.group)].get() : es->scene_.get(), g);
    rtcReleaseGeometry(g);
    if (id == RTC_INVALID_GEOMETRY_ID) break;
    std::vector<unsigned>& to_shape = member ? es->group_geom_to_shape_[static_cast<std::size_t>(shape.group)] : es->geom_to_shape_;
    if (to_shape.size() <= id) to_shape.resize(id + 1, 0);
    to_shape[id] = static_cast<unsigned>(si);
  }
  // --- instances: Embree instance geometry referencing the group's scene ---
  if (es->errors_->first.empty())
    for (const auto& group : es->groups_) rtcCommitScene(group.get());
  for (std::size_t ii = 0; ii < scene.instances.size() && es->errors_->first.empty(); ++ii) {
    const ShapeInstance& inst = scene.instances[ii];
    InstanceTransform x;
    x.to_world = inst.to_world;
    const glm::mat3 linear(inst.to_world);
    const glm::mat3 inverse = glm::inverse(linear);
    x.normal_matrix = glm::transpose(inverse);
    x.flips = glm::determinant(linear) < 0.0f;
    // Embree moves the ray's origin o to the group's space (inverse * (o - translation), about
    // four roundings a component) and the hit back is computed here from corners moved by
    // to_world (three more): |linear| |inverse| (|x| + |translation|) times gamma(8) bounds both.
    const glm::mat3 abs_linear(abs3(linear[0]), abs3(linear[1]), abs3(linear[2]));
    const glm::mat3 abs_inverse(abs3(inverse[0]), abs3(inverse[1]), abs3(inverse[2]));
    // The identity moves nothing and Embree's multiply by it is exact: no term (an instance in
    // place then offsets its rays exactly as the flattened mesh does).
    if (inst.to_world != glm::mat4(1.0f)) x.error_scale = error_gamma(8) * (abs_linear * abs_inverse);
    x.abs_translation = abs3(glm::vec3(inst.to_world[3]));
    es->instances_.push_back(x);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(g, es->groups_[static_cast<std::size_t>(inst.group)].get());
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &inst.to_world[0][0]);
    rtcCommitGeometry(g);
    const unsigned id = rtcAttachGeometry(es->scene_.get(), g);
    rtcReleaseGeometry(g);
    if (id == RTC_INVALID_GEOMETRY_ID) break;
    if (es->geom_to_instance_.size() <= id) es->geom_to_instance_.resize(id + 1, 0);
    es->geom_to_instance_[id] = static_cast<unsigned>(ii);
  }
  if (es->errors_->first.empty()) rtcCommitScene(es->scene_.get());
  if (!es->errors_->first.empty())
    return make_error(ErrorCode::kBadValue, "Embree could not build the scene: " + es->errors_->first);
  return es;
}

std::optional<Hit> EmbreeScene::intersect(const vec3& o, const vec3& d, float tmin, float tmax, HitDetail detail) const {
  // The hit is built in the returned object itself (every return names `out`, so it is elided):
  // a local Hit copied into the optional was read back in 16-byte words just written in 4-byte
  // ones, a store-forwarding stall on every extension ray (a third of this function's time).
  std::optional<Hit> out;
  if (!finite_ray(o, d)) return out;
  RTCRayHit rh;  // Embree reads the ray and the hit's geomID and instID[0]; it writes the rest
  set_ray(rh.ray, o, d, tmin, tmax);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcIntersect1(scene_.get(), &ctx, &rh);
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID)
    finish_hit(o, d, {rh.ray.tfar, rh.hit.u, rh.hit.v, rh.hit.geomID, rh.hit.primID, rh.hit.instID[0]}, detail, out.emplace());
  return out;
}

// Inline into both callers (intersect(), RayPacket::hit()): every ray the tracer casts ends here.
[[gnu::always_inline]] inline void EmbreeScene::finish_hit(const vec3& o, const vec3& d, const RawHit& raw, HitDetail detail,
                                                            Hit& h) const {
  h.t = raw.t;
  h.primitive = static_cast<int>(raw.prim);
  if (raw.inst != RTC_INVALID_GEOMETRY_ID) {
    instance_hit(raw.inst, raw.geom, raw.u, raw.v, d, detail, &h);
    return;
  }
  h.shape = static_cast<int>(geom_to_shape_[raw.geom]);
  const vec3 p = o + h.t * d;
  // Each branch puts the position back onto the exact surface and computes the normal and uv.
  const Shape& shape = source_->shapes[static_cast<std::size_t>(h.shape)];
  if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {
    const glm::uvec3 t = m->triangles[raw.prim];
    const vec3 p0 = m->positions[t.x], p1 = m->positions[t.y], p2 = m->positions[t.z];
    if (detail == HitDetail::kFull) h.uv = shape_uv(shape, raw.prim, raw.u, raw.v, p);
    h.position = triangle_point(p0, p1, p2, 1.0f - raw.u - raw.v, raw.u, raw.v, &h.error);
    const vec3 n = glm::cross(p1 - p0, p2 - p0);
    const float len = glm::length(n);
    h.normal = len > 0.0f ? n / len : -glm::normalize(d);  // degenerate triangles face the ray
    h.shading_normal = m->normals.empty() ? h.normal : mesh_shading_normal(*m, t, raw.u, raw.v, h.normal);
    return;
  } else if (const auto* q = std::get_if<QuadShape>(&shape.geometry)) {
    h.normal = quad_normals_[static_cast<std::size_t>(h.shape)];
    h.error = shape_errors_[static_cast<std::size_t>(h.shape)];  // the projection too: p lies within the quad
    if (detail == HitDetail::kFull) {
      h.uv = shape_uv(shape, 0, 0.0f, 0.0f, p);
      h.position = q->corner + h.uv.x * q->edge1 + h.uv.y * q->edge2;
    } else {
      h.position = p - glm::dot(p - q->corner, h.normal) * h.normal;  // onto the plane
    }
  } else if (const auto* s = std::get_if<SphereShape>(&shape.geometry)) {
    h.normal = glm::normalize(p - s->center);
    h.position = s->center + s->radius * h.normal;
    h.error = sphere_error(*s, h.normal);
    if (detail == HitDetail::kFull) h.uv = shape_uv(shape, 0, 0.0f, 0.0f, h.position);
  } else {
    const DiskShape& k = std::get<DiskShape>(shape.geometry);
    h.normal = k.normal;
    const vec3 local = Frame::from_normal(k.normal).to_local(p - k.center);
    h.position = p - local.z * k.normal;
    h.error = shape_errors_[static_cast<std::size_t>(h.shape)];
    if (detail == HitDetail::kFull) h.uv = shape_uv(shape, 0, 0.0f, 0.0f, p);
  }
  h.shading_normal = h.normal;
}

// A hit on an instance's member (a mesh: make_group_member): computed exactly as the flattened
// mesh's hit would be, from the triangle's corners moved to the world by the instance's
// transform as flattening moves them (apply_point: to_world * (p, 1)), with Embree's barycentrics
// from its test in the group's space. The normal is that of the moved corners (turned when the
// transform mirrors, as flattening swaps the winding), the shading normal the group-space one by
// the inverse transpose. The error bound adds the rounding of the way to the group's space and back.
void EmbreeScene::instance_hit(unsigned inst_geom, unsigned geom, float u, float v, const vec3& d, HitDetail detail, Hit* h) const {
  const unsigned ii = geom_to_instance_[inst_geom];
  const InstanceTransform& x = instances_[ii];
  const ShapeInstance& inst = source_->instances[ii];
  h->instance = static_cast<int>(ii);
  h->shape = static_cast<int>(group_geom_to_shape_[static_cast<std::size_t>(inst.group)][geom]);
  const MeshShape& m = std::get<MeshShape>(source_->shapes[static_cast<std::size_t>(h->shape)].geometry);
  const glm::uvec3 t = m.triangles[static_cast<std::size_t>(h->primitive)];
  const auto place = [&](const vec3& p) { return vec3(x.to_world * glm::vec4(p, 1.0f)); };
  const vec3 p0 = place(m.positions[t.x]), p1 = place(m.positions[t.y]), p2 = place(m.positions[t.z]);
  if (detail == HitDetail::kFull)
    h->uv = m.uvs.empty() ? glm::vec2(u + v, v) : (1.0f - u - v) * m.uvs[t.x] + u * m.uvs[t.y] + v * m.uvs[t.z];
  h->position = triangle_point(p0, p1, p2, 1.0f - u - v, u, v, &h->error);
  h->error += x.error_scale * (abs3(h->position) + x.abs_translation);
  const vec3 n = glm::cross(p1 - p0, p2 - p0);
  const float len = glm::length(n);
  h->normal = len > 0.0f ? (x.flips ? -n : n) / len : -glm::normalize(d);
  if (m.normals.empty()) {
    h->shading_normal = h->normal;
  } else {
    const vec3 ns = x.normal_matrix * mesh_shading_normal(m, t, u, v, vec3(0.0f));
    const float ls = glm::length(ns);
    h->shading_normal = ls > 0.0f ? ns / ls : h->normal;
  }
}

void EmbreeScene::uv_tangents(const Hit& h, vec3* dpdu, vec3* dpdv) const {
  *dpdu = *dpdv = vec3(0.0f);
  const Shape& shape = source_->shapes[static_cast<std::size_t>(h.shape)];
  if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {
    const glm::uvec3 t = m->triangles[static_cast<std::size_t>(h.primitive)];
    vec3 p0 = m->positions[t.x], p1 = m->positions[t.y], p2 = m->positions[t.z];
    if (h.instance >= 0) {
      const glm::mat4& w = instances_[static_cast<std::size_t>(h.instance)].to_world;
      p0 = vec3(w * glm::vec4(p0, 1.0f));
      p1 = vec3(w * glm::vec4(p1, 1.0f));
      p2 = vec3(w * glm::vec4(p2, 1.0f));
    }
    // pbrt-v4's default uv without per-vertex ones: (0, 0), (1, 0), (1, 1).
    const glm::vec2 uv0 = m->uvs.empty() ? glm::vec2(0.0f, 0.0f) : m->uvs[t.x];
    const glm::vec2 uv1 = m->uvs.empty() ? glm::vec2(1.0f, 0.0f) : m->uvs[t.y];
    const glm::vec2 uv2 = m->uvs.empty() ? glm::vec2(1.0f, 1.0f) : m->uvs[t.z];
    const glm::vec2 duv02 = uv0 - uv2, duv12 = uv1 - uv2;
    const vec3 dp02 = p0 - p2, dp12 = p1 - p2;
    const float det = duv02.x * duv12.y - duv02.y * duv12.x;
    if (!(std::fabs(det) >= 1e-9f)) return;  // degenerate uv: the caller's arbitrary frame
    *dpdu = (duv12.y * dp02 - duv02.y * dp12) / det;
    *dpdv = (duv02.x * dp12 - duv12.x * dp02) / det;
  } else if (const auto* q = std::get_if<QuadShape>(&shape.geometry)) {
    *dpdu = q->edge1;
    *dpdv = q->edge2;
  } else if (const auto* s = std::get_if<SphereShape>(&shape.geometry)) {
    // p = c + r (sin θ cos φ, sin θ sin φ, cos θ), φ = 2π u, θ = π v.
    const vec3 l = h.position - s->center;
    const float rxy = std::sqrt(l.x * l.x + l.y * l.y);
    *dpdu = 2.0f * kPi * vec3(-l.y, l.x, 0.0f);
    if (rxy > 0.0f) *dpdv = kPi * vec3(l.z * l.x / rxy, l.z * l.y / rxy, -rxy);
  } else {
    // u = φ / 2π, v = r / radius in the disk's Frame::from_normal.
    const DiskShape& k = std::get<DiskShape>(shape.geometry);
    const Frame f = Frame::from_normal(k.normal);
    const vec3 l = f.to_local(h.position - k.center);
    const float r = std::sqrt(l.x * l.x + l.y * l.y);
    *dpdu = 2.0f * kPi * (-l.y * f.s + l.x * f.t);
    if (r > 0.0f) *dpdv = k.radius * (l.x * f.s + l.y * f.t) / r;
  }
}

bool EmbreeScene::occluded(const vec3& o, const vec3& d, float tmin, float tmax) const {
  if (!finite_ray(o, d)) return true;
  RTCRay ray;
  set_ray(ray, o, d, tmin, tmax);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcOccluded1(scene_.get(), &ctx, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

int OcclusionBatch::add(const EmbreeScene&, const vec3& a, const vec3& na, const vec3& ea, const vec3& b, const vec3& nb,
                        const vec3& eb) {
  const int lane = size_++;
  vec3 o, d;
  EmbreeScene::shadow_ray(a, na, ea, b, nb, eb, &o, &d);
  rays_.org_x[lane] = o.x;
  rays_.org_y[lane] = o.y;
  rays_.org_z[lane] = o.z;
  rays_.tnear[lane] = 0.0f;
  rays_.dir_x[lane] = d.x;
  rays_.dir_y[lane] = d.y;
  rays_.dir_z[lane] = d.z;
  rays_.time[lane] = 0.0f;
  rays_.mask[lane] = 0xFFFFFFFFu;
  rays_.id[lane] = 0;
  rays_.flags[lane] = 0;
  // A non-finite ray never reaches Embree and counts as blocked, as in occluded().
  const bool finite = finite_ray(o, d);
  rays_.tfar[lane] = finite ? 1.0f : -std::numeric_limits<float>::infinity();
  valid_[lane] = finite ? -1 : 0;
  return lane;
}

void OcclusionBatch::trace(const EmbreeScene& scene) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  if (size_ >= kMinPacket) {
    for (int lane = size_; lane < kCapacity; ++lane) valid_[lane] = 0;
    rtcOccluded16(valid_, scene.handle(), &ctx, &rays_);
    return;
  }
  for (int lane = 0; lane < size_; ++lane) {
    if (valid_[lane] == 0) continue;
    RTCRay ray;
    set_ray(ray, vec3(rays_.org_x[lane], rays_.org_y[lane], rays_.org_z[lane]),
            vec3(rays_.dir_x[lane], rays_.dir_y[lane], rays_.dir_z[lane]), 0.0f, 1.0f);
    rtcOccluded1(scene.handle(), &ctx, &ray);
    rays_.tfar[lane] = ray.tfar;
  }
}

int RayPacket::add(const vec3& o, const vec3& d) {
  const int lane = size_++;
  rays_.ray.org_x[lane] = o.x;
  rays_.ray.org_y[lane] = o.y;
  rays_.ray.org_z[lane] = o.z;
  rays_.ray.tnear[lane] = 0.0f;
  rays_.ray.dir_x[lane] = d.x;
  rays_.ray.dir_y[lane] = d.y;
  rays_.ray.dir_z[lane] = d.z;
  rays_.ray.time[lane] = 0.0f;
  rays_.ray.tfar[lane] = std::numeric_limits<float>::infinity();
  rays_.ray.mask[lane] = 0xFFFFFFFFu;
  rays_.ray.id[lane] = 0;
  rays_.ray.flags[lane] = 0;
  rays_.hit.geomID[lane] = RTC_INVALID_GEOMETRY_ID;
  rays_.hit.instID[0][lane] = RTC_INVALID_GEOMETRY_ID;
  // A non-finite ray never reaches Embree and hits nothing, as in intersect().
  valid_[lane] = finite_ray(o, d) ? -1 : 0;
  return lane;
}

void RayPacket::trace(const EmbreeScene& scene) {
  for (int lane = size_; lane < kCapacity; ++lane) valid_[lane] = 0;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect16(valid_, scene.handle(), &ctx, &rays_);
}

std::optional<Hit> RayPacket::hit(const EmbreeScene& scene, int lane, HitDetail detail) const {
  std::optional<Hit> out;
  if (valid_[lane] == 0 || rays_.hit.geomID[lane] == RTC_INVALID_GEOMETRY_ID) return out;
  const vec3 o(rays_.ray.org_x[lane], rays_.ray.org_y[lane], rays_.ray.org_z[lane]);
  const vec3 d(rays_.ray.dir_x[lane], rays_.ray.dir_y[lane], rays_.ray.dir_z[lane]);
  scene.finish_hit(o, d,
                   {rays_.ray.tfar[lane], rays_.hit.u[lane], rays_.hit.v[lane], rays_.hit.geomID[lane], rays_.hit.primID[lane],
                    rays_.hit.instID[0][lane]},
                   detail, out.emplace());
  return out;
}

std::optional<Hit> EmbreeScene::intersect(const vec3& o, const vec3& d, const vec3& origin_normal, const vec3& origin_error,
                                          HitDetail detail) const {
  return intersect(offset(o, origin_normal, origin_error, d), d, 0.0f, std::numeric_limits<float>::infinity(), detail);
}

bool EmbreeScene::visible(const vec3& a, const vec3& na, const vec3& ea, const vec3& b, const vec3& nb,
                          const vec3& eb) const {
  vec3 o, d;
  shadow_ray(a, na, ea, b, nb, eb, &o, &d);
  return !occluded(o, d, 0.0f, 1.0f);
}

float EmbreeScene::area_pdf(int shape) const {
  const float a = shape_area(shape);
  return a > 0.0f ? 1.0f / a : 0.0f;
}

vec3 EmbreeScene::normal_at(int shape_index, int primitive, const vec3& p) const {
  const Shape& shape = source_->shapes[static_cast<std::size_t>(shape_index)];
  if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {
    const glm::uvec3 t = m->triangles[static_cast<std::size_t>(primitive)];
    const vec3 n = glm::cross(m->positions[t.y] - m->positions[t.x], m->positions[t.z] - m->positions[t.x]);
    return glm::length(n) > 0.0f ? glm::normalize(n) : vec3(0.0f, 0.0f, 1.0f);
  }
  if (const auto* q = std::get_if<QuadShape>(&shape.geometry)) return glm::normalize(glm::cross(q->edge1, q->edge2));
  if (const auto* s = std::get_if<SphereShape>(&shape.geometry)) return glm::normalize(p - s->center);
  return std::get<DiskShape>(shape.geometry).normal;
}

glm::vec2 EmbreeScene::uv_at(int shape_index, int primitive, const vec3& p) const {
  const Shape& shape = source_->shapes[static_cast<std::size_t>(shape_index)];
  float w1 = 0.0f, w2 = 0.0f;  // a mesh point's barycentrics in its triangle (p in its plane)
  if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {
    const glm::uvec3 t = m->triangles[static_cast<std::size_t>(primitive)];
    const vec3 e1 = m->positions[t.y] - m->positions[t.x], e2 = m->positions[t.z] - m->positions[t.x], w = p - m->positions[t.x];
    const float e11 = glm::dot(e1, e1), e12 = glm::dot(e1, e2), e22 = glm::dot(e2, e2);
    const float det = e11 * e22 - e12 * e12;
    if (det > 0.0f) {
      w1 = std::clamp((glm::dot(w, e1) * e22 - glm::dot(w, e2) * e12) / det, 0.0f, 1.0f);
      w2 = std::clamp((glm::dot(w, e2) * e11 - glm::dot(w, e1) * e12) / det, 0.0f, 1.0f - w1);
    }
  }
  return shape_uv(shape, static_cast<unsigned>(primitive), w1, w2, p);
}

SurfaceSample EmbreeScene::sample_shape(int shape_index, glm::vec2 u) const {
  const Shape& shape = source_->shapes[static_cast<std::size_t>(shape_index)];
  SurfaceSample s;
  if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {
    // Pick a triangle by area with u.x, then reuse the remainder of u.x inside it.
    const std::vector<double>& cdf = triangle_cdf_[static_cast<std::size_t>(shape_index)];
    const double target = static_cast<double>(u.x) * cdf.back();
    const std::size_t i =
        std::min<std::size_t>(static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), target) - cdf.begin()), cdf.size() - 1);
    const double lo = i ? cdf[i - 1] : 0.0;
    const double width = cdf[i] - lo;
    const float ux = width > 0.0 ? std::clamp(static_cast<float>((target - lo) / width), 0.0f, kOneMinusEpsilon) : 0.5f;
    const glm::uvec3 t = m->triangles[i];
    const glm::vec2 b = sample_uniform_triangle(glm::vec2(ux, u.y));
    const vec3 p0 = m->positions[t.x], p1 = m->positions[t.y], p2 = m->positions[t.z];
    s.position = triangle_point(p0, p1, p2, b.x, b.y, 1.0f - b.x - b.y, &s.error);
    const vec3 n = glm::cross(p1 - p0, p2 - p0);
    s.normal = glm::length(n) > 0.0f ? glm::normalize(n) : vec3(0.0f, 0.0f, 1.0f);
  } else if (const auto* q = std::get_if<QuadShape>(&shape.geometry)) {
    s.position = q->corner + u.x * q->edge1 + u.y * q->edge2;
    s.error = shape_errors_[static_cast<std::size_t>(shape_index)];
    s.normal = quad_normals_[static_cast<std::size_t>(shape_index)];  // normalize(e1 × e2), once per scene
  } else if (const auto* sp = std::get_if<SphereShape>(&shape.geometry)) {
    s.normal = sample_uniform_sphere(u);
    s.position = sp->center + sp->radius * s.normal;
    s.error = sphere_error(*sp, s.normal);
  } else {
    const DiskShape& d = std::get<DiskShape>(shape.geometry);
    const glm::vec2 p = sample_concentric_disk(u) * d.radius;
    const Frame f = Frame::from_normal(d.normal);
    s.position = d.center + f.to_world(vec3(p.x, p.y, 0.0f));
    s.error = shape_errors_[static_cast<std::size_t>(shape_index)];
    s.normal = d.normal;
  }
  return s;
}

}  // namespace pathex
