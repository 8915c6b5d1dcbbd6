#include "trace/embree_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "trace/frame.h"
#include "trace/rng.h"

namespace pathex {

struct EmbreeScene::AnalyticRecord {
  const Shape* shape;
  bool sphere;
};

namespace {

void on_embree_error(void*, RTCError code, const char* message) {
  // Embree reports misuse and out-of-memory here; build() checks rtcGetDeviceError afterwards.
  std::fprintf(stderr, "pathex: embree error %d: %s\n", static_cast<int>(code), message ? message : "");
}

using Analytic = EmbreeScene::AnalyticRecord;

// --- spheres: a numerically stable quadratic (Haines et al., Ray Tracing Gems ch. 7) ---
bool sphere_t(const SphereShape& s, const glm::vec3& o, const glm::vec3& d, float tmin, float tmax, float* t_out) {
  const glm::vec3 f = o - s.center;
  const float a = glm::dot(d, d);
  const float b = glm::dot(f, d);
  const glm::vec3 perp = f - (b / a) * d;
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

bool disk_t(const DiskShape& s, const glm::vec3& o, const glm::vec3& d, float tmin, float tmax, float* t_out) {
  const float dn = glm::dot(d, s.normal);
  if (dn == 0.0f) return false;
  const float t = glm::dot(s.center - o, s.normal) / dn;
  if (!(t > tmin && t < tmax)) return false;
  const glm::vec3 p = o + t * d - s.center;
  if (glm::dot(p, p) > s.radius * s.radius) return false;
  *t_out = t;
  return true;
}

void analytic_bounds(const RTCBoundsFunctionArguments* args) {
  const Analytic* a = static_cast<const Analytic*>(args->geometryUserPtr);
  glm::vec3 lo, hi;
  if (a->sphere) {
    const SphereShape& s = std::get<SphereShape>(a->shape->geometry);
    lo = s.center - glm::vec3(s.radius);
    hi = s.center + glm::vec3(s.radius);
  } else {
    const DiskShape& s = std::get<DiskShape>(a->shape->geometry);
    lo = s.center - glm::vec3(s.radius);
    hi = s.center + glm::vec3(s.radius);
  }
  args->bounds_o->lower_x = lo.x;
  args->bounds_o->lower_y = lo.y;
  args->bounds_o->lower_z = lo.z;
  args->bounds_o->upper_x = hi.x;
  args->bounds_o->upper_y = hi.y;
  args->bounds_o->upper_z = hi.z;
}

bool analytic_t(const Analytic* a, const glm::vec3& o, const glm::vec3& d, float tmin, float tmax, float* t) {
  return a->sphere ? sphere_t(std::get<SphereShape>(a->shape->geometry), o, d, tmin, tmax, t)
                   : disk_t(std::get<DiskShape>(a->shape->geometry), o, d, tmin, tmax, t);
}

void analytic_intersect(const RTCIntersectFunctionNArguments* args) {
  const Analytic* a = static_cast<const Analytic*>(args->geometryUserPtr);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const glm::vec3 o(RTCRayN_org_x(ray, args->N, i), RTCRayN_org_y(ray, args->N, i), RTCRayN_org_z(ray, args->N, i));
    const glm::vec3 d(RTCRayN_dir_x(ray, args->N, i), RTCRayN_dir_y(ray, args->N, i), RTCRayN_dir_z(ray, args->N, i));
    float t;
    if (!analytic_t(a, o, d, RTCRayN_tnear(ray, args->N, i), RTCRayN_tfar(ray, args->N, i), &t)) continue;
    RTCRayN_tfar(ray, args->N, i) = t;
    RTCHitN_geomID(hit, args->N, i) = args->geomID;
    RTCHitN_primID(hit, args->N, i) = args->primID;
    RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
    RTCHitN_u(hit, args->N, i) = 0.0f;
    RTCHitN_v(hit, args->N, i) = 0.0f;
    RTCHitN_Ng_x(hit, args->N, i) = 0.0f;  // recomputed exactly by intersect()
    RTCHitN_Ng_y(hit, args->N, i) = 0.0f;
    RTCHitN_Ng_z(hit, args->N, i) = 1.0f;
  }
}

void analytic_occluded(const RTCOccludedFunctionNArguments* args) {
  const Analytic* a = static_cast<const Analytic*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const glm::vec3 o(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i), RTCRayN_org_z(args->ray, args->N, i));
    const glm::vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i), RTCRayN_dir_z(args->ray, args->N, i));
    float t;
    if (analytic_t(a, o, d, RTCRayN_tnear(args->ray, args->N, i), RTCRayN_tfar(args->ray, args->N, i), &t))
      RTCRayN_tfar(args->ray, args->N, i) = -std::numeric_limits<float>::infinity();
  }
}


float max_abs(const glm::vec3& p) { return std::max(std::fabs(p.x), std::max(std::fabs(p.y), std::fabs(p.z))); }

}  // namespace

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

glm::vec3 EmbreeScene::offset(const glm::vec3& p, const glm::vec3& n, const glm::vec3& d) const {
  if (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f) return p;
  const float eps = epsilon_ + 1e-6f * max_abs(p);
  return p + (glm::dot(n, d) >= 0.0f ? eps : -eps) * n;
}

Result<std::unique_ptr<EmbreeScene>> EmbreeScene::build(const Scene& scene) {
  std::unique_ptr<EmbreeScene> es(new EmbreeScene());
  es->source_ = &scene;
  es->device_ = rtcNewDevice("verbose=0");
  if (!es->device_) return make_error(ErrorCode::kBadValue, "cannot create the Embree device");
  rtcSetDeviceErrorFunction(es->device_, on_embree_error, nullptr);
  es->scene_ = rtcNewScene(es->device_);
  rtcSetSceneFlags(es->scene_, RTC_SCENE_FLAG_ROBUST);
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  es->areas_.assign(scene.shapes.size(), 0.0f);
  es->triangle_cdf_.resize(scene.shapes.size());
  for (std::size_t si = 0; si < scene.shapes.size(); ++si) {
    const Shape& shape = scene.shapes[si];
    RTCGeometry g = nullptr;
    if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {
      g = rtcNewGeometry(es->device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m->positions.size()));
      for (std::size_t i = 0; i < m->positions.size(); ++i) {
        v[3 * i] = m->positions[i].x;
        v[3 * i + 1] = m->positions[i].y;
        v[3 * i + 2] = m->positions[i].z;
        lo = glm::min(lo, m->positions[i]);
        hi = glm::max(hi, m->positions[i]);
      }
      auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), m->triangles.size()));
      std::vector<float>& cdf = es->triangle_cdf_[si];
      cdf.reserve(m->triangles.size());
      float total = 0.0f;
      for (std::size_t i = 0; i < m->triangles.size(); ++i) {
        const glm::uvec3 t = m->triangles[i];
        idx[3 * i] = t.x;
        idx[3 * i + 1] = t.y;
        idx[3 * i + 2] = t.z;
        total += 0.5f * glm::length(glm::cross(m->positions[t.y] - m->positions[t.x], m->positions[t.z] - m->positions[t.x]));
        cdf.push_back(total);
      }
      es->areas_[si] = total;
      es->triangles_ += m->triangles.size();
    } else if (const auto* q = std::get_if<QuadShape>(&shape.geometry)) {
      g = rtcNewGeometry(es->device_, RTC_GEOMETRY_TYPE_QUAD);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 4));
      const glm::vec3 corners[4] = {q->corner, q->corner + q->edge1, q->corner + q->edge1 + q->edge2, q->corner + q->edge2};
      for (int i = 0; i < 4; ++i) {
        v[3 * i] = corners[i].x;
        v[3 * i + 1] = corners[i].y;
        v[3 * i + 2] = corners[i].z;
        lo = glm::min(lo, corners[i]);
        hi = glm::max(hi, corners[i]);
      }
      auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 4 * sizeof(unsigned), 1));
      for (unsigned i = 0; i < 4; ++i) idx[i] = i;
      es->areas_[si] = glm::length(glm::cross(q->edge1, q->edge2));
    } else {
      const bool sphere = std::holds_alternative<SphereShape>(shape.geometry);
      es->analytic_.push_back(std::make_unique<Analytic>(Analytic{&shape, sphere}));
      g = rtcNewGeometry(es->device_, RTC_GEOMETRY_TYPE_USER);
      rtcSetGeometryUserPrimitiveCount(g, 1);
      rtcSetGeometryUserData(g, es->analytic_.back().get());
      rtcSetGeometryBoundsFunction(g, analytic_bounds, nullptr);
      rtcSetGeometryIntersectFunction(g, analytic_intersect);
      rtcSetGeometryOccludedFunction(g, analytic_occluded);
      constexpr float kPiF = 3.14159265358979f;
      if (sphere) {
        const SphereShape& s = std::get<SphereShape>(shape.geometry);
        es->areas_[si] = 4.0f * kPiF * s.radius * s.radius;
        lo = glm::min(lo, s.center - glm::vec3(s.radius));
        hi = glm::max(hi, s.center + glm::vec3(s.radius));
      } else {
        const DiskShape& s = std::get<DiskShape>(shape.geometry);
        es->areas_[si] = kPiF * s.radius * s.radius;
        lo = glm::min(lo, s.center - glm::vec3(s.radius));
        hi = glm::max(hi, s.center + glm::vec3(s.radius));
      }
    }
    rtcCommitGeometry(g);
    const unsigned id = rtcAttachGeometry(es->scene_, g);
    rtcReleaseGeometry(g);
    if (es->geom_to_shape_.size() <= id) es->geom_to_shape_.resize(id + 1, 0);
    es->geom_to_shape_[id] = static_cast<unsigned>(si);
  }
  rtcCommitScene(es->scene_);
  if (rtcGetDeviceError(es->device_) != RTC_ERROR_NONE) return make_error(ErrorCode::kBadValue, "Embree could not build the scene");
  es->extent_ = std::max(glm::length(hi - lo), 1e-30f);
  es->epsilon_ = 1e-5f * es->extent_;
  return es;
}

std::optional<Hit> EmbreeScene::intersect(const glm::vec3& o_in, const glm::vec3& d, const glm::vec3& origin_normal) const {
  const glm::vec3 o = offset(o_in, origin_normal, d);
  RTCRayHit rh{};
  rh.ray.org_x = o.x;
  rh.ray.org_y = o.y;
  rh.ray.org_z = o.z;
  rh.ray.dir_x = d.x;
  rh.ray.dir_y = d.y;
  rh.ray.dir_z = d.z;
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcIntersect1(scene_, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  Hit h;
  h.t = rh.ray.tfar;
  h.shape = static_cast<int>(geom_to_shape_[rh.hit.geomID]);
  h.primitive = static_cast<int>(rh.hit.primID);
  h.position = o + h.t * d;
  const Shape& shape = source_->shapes[static_cast<std::size_t>(h.shape)];
  if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {
    const glm::uvec3 t = m->triangles[rh.hit.primID];
    const glm::vec3 n = glm::cross(m->positions[t.y] - m->positions[t.x], m->positions[t.z] - m->positions[t.x]);
    const float len = glm::length(n);
    h.normal = len > 0.0f ? n / len : -glm::normalize(d);  // degenerate triangles face the ray
  } else if (const auto* q = std::get_if<QuadShape>(&shape.geometry)) {
    h.normal = glm::normalize(glm::cross(q->edge1, q->edge2));
  } else if (const auto* s = std::get_if<SphereShape>(&shape.geometry)) {
    h.normal = glm::normalize(h.position - s->center);
    h.position = s->center + s->radius * h.normal;  // back onto the surface
  } else {
    h.normal = std::get<DiskShape>(shape.geometry).normal;
  }
  h.shading_normal = h.normal;
  return h;
}

bool EmbreeScene::visible(const glm::vec3& a, const glm::vec3& na, const glm::vec3& b, const glm::vec3& nb) const {
  const glm::vec3 o = offset(a, na, b - a);
  const glm::vec3 e = offset(b, nb, a - b);
  const glm::vec3 d = e - o;
  RTCRay ray{};
  ray.org_x = o.x;
  ray.org_y = o.y;
  ray.org_z = o.z;
  ray.dir_x = d.x;
  ray.dir_y = d.y;
  ray.dir_z = d.z;
  ray.tnear = 0.0f;
  ray.tfar = 1.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.flags = 0;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  rtcOccluded1(scene_, &ctx, &ray);
  return ray.tfar >= 0.0f;
}

SurfaceSample EmbreeScene::sample_shape(int shape_index, glm::vec2 u) const {
  const Shape& shape = source_->shapes[static_cast<std::size_t>(shape_index)];
  SurfaceSample s;
  if (const auto* m = std::get_if<MeshShape>(&shape.geometry)) {
    const std::vector<float>& cdf = triangle_cdf_[static_cast<std::size_t>(shape_index)];
    const float target = u.x * cdf.back();
    const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), target) - cdf.begin()), cdf.size() - 1);
    const float lo = i ? cdf[i - 1] : 0.0f;
    const float width = cdf[i] - lo;
    const float ux = width > 0.0f ? std::clamp((target - lo) / width, 0.0f, kOneMinusEpsilon) : 0.5f;  // reuse the remainder
    const glm::uvec3 t = m->triangles[i];
    const glm::vec2 b = sample_uniform_triangle(glm::vec2(ux, u.y));
    const glm::vec3 p0 = m->positions[t.x], p1 = m->positions[t.y], p2 = m->positions[t.z];
    s.position = b.x * p0 + b.y * p1 + (1.0f - b.x - b.y) * p2;
    const glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
    s.normal = glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0.0f, 0.0f, 1.0f);
  } else if (const auto* q = std::get_if<QuadShape>(&shape.geometry)) {
    s.position = q->corner + u.x * q->edge1 + u.y * q->edge2;
    s.normal = glm::normalize(glm::cross(q->edge1, q->edge2));
  } else if (const auto* sp = std::get_if<SphereShape>(&shape.geometry)) {
    s.normal = sample_uniform_sphere(u);
    s.position = sp->center + sp->radius * s.normal;
  } else {
    const DiskShape& d = std::get<DiskShape>(shape.geometry);
    const glm::vec2 p = sample_concentric_disk(u) * d.radius;
    const Frame f = Frame::from_normal(d.normal);
    s.position = d.center + f.to_world(glm::vec3(p.x, p.y, 0.0f));
    s.normal = d.normal;
  }
  return s;
}

}  // namespace pathex
