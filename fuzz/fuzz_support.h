// What the harnesses share: a private scratch folder for inputs that must be files (OBJ meshes,
// check files), and the finding of a broken invariant (an abort libFuzzer records with the input).
#pragma once

#include <unistd.h>

#include <cerrno>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>

#include "core/limits.h"
#include "io/profile_json.h"
#include "trace/render.h"

namespace pathex::fuzz {

// The limits every harness runs under: small, so that one input costs milliseconds under ASan
// rather than the second the defaults allow (with the defaults, a run in 2026-12 managed 39
// expressions in ten minutes). libFuzzer then runs hundreds of inputs a second, and a hang that
// the work budget does not bound still shows as a timeout. That the defaults themselves stop
// every known hang within 1 s is measured by bench/hangs.py (README "Limits"). --max-depth stays
// at its default: its recursion is what the fuzzer should reach.
inline Limits small_limits() {
  Limits l;
  l.max_states = 5000;
  l.max_repeat = 64;
  l.max_length = 10000;
  l.max_work = 200000;
  l.max_file_bytes = std::size_t{1} << 20;
  return l;
}

inline SceneLoadOptions small_scene_options() {
  SceneLoadOptions o;
  o.max_file_bytes = small_limits().max_file_bytes;
  o.max_scene_bytes = std::size_t{4} << 20;
  o.max_material_nodes = 100000;
  o.max_mesh_elements = 1000000;
  return o;
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// A folder of this process's own (libFuzzer's -fork and -jobs run several processes at once).
inline const std::string& scratch_dir() {
  static const std::string dir = [] {
    std::string d = "/tmp/pathex-fuzz-" + std::to_string(::getpid());
    std::string cmd = "mkdir -p " + d;
    if (std::system(cmd.c_str()) != 0) std::abort();
    return d;
  }();
  return dir;
}

inline std::string write_scratch(const std::string& name, std::string_view bytes) {
  const std::string path = scratch_dir() + "/" + name;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

[[noreturn]] inline void finding(const char* what) {
  std::fprintf(stderr, "pathex fuzz finding: %s\n", what);
  std::abort();
}

// Links in the scratch folder to the sample scenes' include/ and meshes/ folders, so that a seed's
// Include "include/cornell-materials.pbrt" or its PLY floor resolves beside the fuzzed file.
inline void link_sample_folders() {
  static const bool linked = [] {
    for (const char* folder : {"include", "meshes"}) {
      const std::string target = std::string(PATHEX_SOURCE_DIR "/samples/scenes/") + folder, link = scratch_dir() + "/" + folder;
      if (::symlink(target.c_str(), link.c_str()) != 0 && errno != EEXIST) finding("cannot link the sample folders");
    }
    return true;
  }();
  (void)linked;
}

// A scene that loaded, rendered with every plain join (bdpt) at most 4 x 4 pixels, one pass: a
// non-finite sample is a finding (DESIGN §12: numbers stay finite). Errors (e.g. from Embree) are
// values and fine.
inline void render_tiny(Scene scene, int max_bounces) {
  static const Profile bdpt = [] {
    Result<Profile> p = resolve_profile("bdpt", Limits{});
    if (!p) finding("the built-in bdpt profile does not load");
    return *p;
  }();
  scene.camera.width = std::min(scene.camera.width, 4);
  scene.camera.height = std::min(scene.camera.height, 4);
  RenderOptions o;
  o.spp = 1;
  o.threads = 1;
  o.max_bounces = max_bounces;
  Result<RenderOutput> out = render(scene, bdpt, nullptr, o);
  if (out && out->histogram.nonfinite() != 0) finding("a non-finite sample");
}

// An imported scene (pbrt-v4, Mitsuba 3): the bytes become `name` (its extension picks the
// format) in the scratch folder beside links to the sample scenes' include/ and meshes/ (so the
// seeds' includes and PLY meshes resolve), loaded under small limits; a refusal must carry a
// message of at most 16 KiB (echoed tokens are cut by excerpt(), file names past PATH_MAX too),
// and a scene that loads is rendered tiny.
inline int fuzz_scene_file(const std::uint8_t* data, std::size_t size, const std::string& name) {
  link_sample_folders();
  const std::string path = write_scratch(name, as_text(data, size));
  Result<Scene> scene = load_scene_file(path, small_scene_options());
  if (!scene) {
    if (scene.error().message.empty()) finding("an error without a message");
    if (scene.error().message.size() + scene.error().where.size() > 16384) finding("a message of more than 16 KiB");
    return 0;
  }
  render_tiny(std::move(*scene), 4);
  return 0;
}

}  // namespace pathex::fuzz
