// Eye subpaths' starts made ahead of their samples (trace/accel/eye_packets.h): for up to 16
// samples, the sensor's first ray of each, all traced as one coherent packet (RayPacket,
// trace/embree_scene.h), each handed to the one sample whose walk asks for exactly it.
//
// primary_ray() gives the selected sample's prepared ray when it is asked with the sampler state
// and pixel it was drawn with (moving the sampler on as drawing it did); intersect() gives the
// packet's hit when its query is, bit for bit, the ray that was traced. Anything else is computed
// as it would be without them, so that a start prepared for another sample is never taken. Each
// is given once.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <optional>

#include <glm/vec3.hpp>

#include "trace/embree_scene.h"
#include "trace/emitters.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex::tracer {

class EyeAhead {
 public:
  static constexpr int kCapacity = RayPacket::kCapacity;
  // One sample's start, made in place (the ray straight into its slot).
  struct Start {
    // The ray RenderSensor::primary_ray() draws for pixel (x, y) with `start`, the sample's numbers
    // at the eye's first dimension (`after`: as drawing leaves them).
    Start(const RenderSensor& sensor, const Sampler& start, int x_, int y_, std::uint64_t pass_)
        : before(start), after(start), x(x_), y(y_), pass(pass_), ray(sensor.primary_ray(after, x_, y_)) {
      if (ray) normal = sensor.origin_normal(*ray);
    }
    Sampler before, after;
    int x, y;
    std::uint64_t pass;
    std::optional<EndpointRay> ray;  // none: the sensor made no ray (and no lane)
    glm::vec3 normal{0.0f};          // the sensor vertex's
    int lane = -1;
  };

  int size() const { return size_; }
  bool full() const { return size_ == kCapacity; }
  const Start& start(int i) const { return *starts_[static_cast<std::size_t>(i)]; }
  // Queues the start of the sample with numbers `start` at pixel (x, y), pass `pass`.
  void add(const RenderSensor& sensor, const Sampler& start, int x, int y, std::uint64_t pass) {
    Start& s = starts_[static_cast<std::size_t>(size_++)].emplace(sensor, start, x, y, pass);
    // The ray EmbreeScene::intersect() casts from the sensor vertex (no error bound: offset() moves nothing).
    if (s.ray) s.lane = packet_.add(EmbreeScene::offset(s.ray->origin, s.normal, glm::vec3(0.0f), s.ray->direction), s.ray->direction);
  }
  void trace(const EmbreeScene& scene, HitDetail detail) {
    packet_.trace(scene);
    detail_ = detail;
  }
  // The start that primary_ray() and intersect() may hand out (-1: none), until the next select().
  void select(int i) {
    current_ = i;
    ray_armed_ = hit_armed_ = i >= 0;
  }
  void clear() {
    select(-1);
    size_ = 0;
    packet_.clear();
  }

  // RenderSensor::primary_ray(rng, px, py), or the selected start's ray.
  std::optional<EndpointRay> primary_ray(const RenderSensor& sensor, Sampler& rng, int px, int py) {
    if (ray_armed_) {
      ray_armed_ = false;
      const Start& s = start(current_);
      if (px == s.x && py == s.y && rng == s.before) {
        rng = s.after;
        return s.ray;
      }
    }
    return sensor.primary_ray(rng, px, py);
  }
  // EmbreeScene::intersect(o, d, n, e, detail), or the packet's hit of that very query.
  std::optional<Hit> intersect(const EmbreeScene& scene, const glm::vec3& o, const glm::vec3& d, const glm::vec3& n,
                               const glm::vec3& e, HitDetail detail) {
    if (hit_armed_) {
      hit_armed_ = false;
      const Start& s = start(current_);
      if (s.lane >= 0 && detail == detail_ && same(o, s.ray->origin) && same(d, s.ray->direction) && same(n, s.normal) &&
          same(e, glm::vec3(0.0f)))
        return packet_.hit(scene, s.lane, detail);
    }
    return scene.intersect(o, d, n, e, detail);
  }

 private:
  static bool same(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof(glm::vec3)) == 0; }

  RayPacket packet_;
  std::array<std::optional<Start>, kCapacity> starts_;
  int size_ = 0;
  int current_ = -1;
  HitDetail detail_ = HitDetail::kFull;
  bool ray_armed_ = false, hit_armed_ = false;
};

}  // namespace pathex::tracer
