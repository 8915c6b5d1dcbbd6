#include "scene/scene_hash.h"

#include <type_traits>

#include "core/hash.h"

namespace pathex {
namespace {

// Each alternative of a variant is preceded by its index, so that two kinds with the same fields
// hash differently.
void hash_basic(Fnv64& h, const BasicMaterial& m) {
  h.add(static_cast<std::uint32_t>(m.index()));
  std::visit([&](const auto& k) { h.add(k); }, m);
}

void hash_material(Fnv64& h, const Material& m) {
  h.add(static_cast<std::uint32_t>(m.index()));
  std::visit(
      [&](const auto& k) {
        if constexpr (std::is_same_v<std::decay_t<decltype(k)>, Mixture>) {
          h.add(static_cast<std::uint64_t>(k.components.size()));
          for (const Mixture::Component& c : k.components) {
            h.add(c.weight);
            hash_basic(h, c.material);
          }
        } else {
          h.add(k);
        }
      },
      m);
}

void hash_geometry(Fnv64& h, const ShapeGeometry& g) {
  h.add(static_cast<std::uint32_t>(g.index()));
  std::visit(
      [&](const auto& k) {
        if constexpr (std::is_same_v<std::decay_t<decltype(k)>, MeshShape>) {
          h.add(static_cast<std::uint64_t>(k.positions.size()));
          h.bytes(k.positions.data(), k.positions.size() * sizeof(glm::vec3));
          h.add(static_cast<std::uint64_t>(k.triangles.size()));
          h.bytes(k.triangles.data(), k.triangles.size() * sizeof(glm::uvec3));
          if (!k.normals.empty()) {  // only then, so that the hashes of meshes without normals stay as they were
            h.add(static_cast<std::uint64_t>(k.normals.size()));
            h.bytes(k.normals.data(), k.normals.size() * sizeof(glm::vec3));
          }
        } else {
          h.add(k);
        }
      },
      g);
}

}  // namespace

std::string scene_content_hash(const Scene& scene) {
  Fnv64 h;
  h.add(static_cast<std::uint64_t>(scene.materials.size()));
  for (const Material& m : scene.materials) hash_material(h, m);
  h.add(static_cast<std::uint64_t>(scene.shapes.size()));
  for (const Shape& s : scene.shapes) {
    hash_geometry(h, s.geometry);
    h.add(s.material);
    h.add(s.emission);
    h.add(s.two_sided);
    if (s.absorption != glm::vec3(0.0f)) h.add(s.absorption);  // only then: the hashes of scenes without media stay as they were
    if (s.alpha >= 0) h.add(s.alpha);                            // likewise without cut-outs
    if (s.group >= 0) h.add(s.group);                            // likewise for instancing
  }
  if (!scene.textures.empty()) {  // likewise without textures
    h.add(static_cast<std::uint64_t>(scene.textures.size()));
    for (const Texture& t : scene.textures) h.add(t);
    h.add(static_cast<std::uint64_t>(scene.images.size()));
    for (const LinearImage& im : scene.images) {
      h.add(im.width);
      h.add(im.height);
      h.bytes(im.rgb.data(), im.rgb.size() * sizeof(float));
      h.add(static_cast<std::uint64_t>(im.alpha.size()));
      h.bytes(im.alpha.data(), im.alpha.size() * sizeof(float));
    }
    h.add(static_cast<std::uint64_t>(scene.material_textures.size()));
    for (const MaterialTextures& m : scene.material_textures) {
      h.add(static_cast<std::uint64_t>(m.bindings.size()));
      for (const TextureBinding& b : m.bindings) h.add(b);
      h.add(m.amount);
      h.bytes(m.weight0.data(), m.weight0.size() * sizeof(float));
      h.bytes(m.weight1.data(), m.weight1.size() * sizeof(float));
      if (m.perturb != NormalPerturbation::kNone) {  // only then: hashes of scenes without bump or normal maps stay as they were
        h.add(static_cast<std::uint32_t>(m.perturb));
        h.add(m.perturb_texture);
        h.add(m.bump_scale);
      }
    }
  }
  if (!scene.instances.empty()) {
    h.add(static_cast<std::uint64_t>(scene.instances.size()));
    for (const ShapeInstance& i : scene.instances) {
      h.add(i.group);
      for (int c = 0; c < 4; ++c) h.add(glm::vec4(i.to_world[c]));
    }
  }
  h.add(static_cast<std::uint64_t>(scene.lights.size()));
  for (const Light& l : scene.lights) {
    h.add(static_cast<std::uint32_t>(l.index()));
    std::visit([&](const auto& k) { h.add(k); }, l);
  }
  const Camera& c = scene.camera;
  h.add(static_cast<std::uint32_t>(c.type));
  h.add(c.position);
  h.add(c.look_at);
  h.add(c.up);
  h.add(c.fov_degrees);
  h.add(c.aperture_radius);
  h.add(c.focus_distance);
  h.add(c.film_width);
  h.add(c.film_height);
  h.add(c.width);
  h.add(c.height);
  if (const auto& e = scene.environment_image) {  // only then: the hashes of scenes without one stay as they were
    h.add(static_cast<std::uint64_t>(e->texels.size()));
    for (const glm::vec3& t : e->texels) h.add(t);
    h.add(e->equal_area);
    h.add(e->width);
    for (int i = 0; i < 3; ++i) h.add(e->to_world[i]);
    h.add(e->uniform_sampling);
  }
  return h.hex();
}

}  // namespace pathex
