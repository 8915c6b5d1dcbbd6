// What the harnesses share: a private scratch folder for inputs that must be files (OBJ meshes,
// check files), and the finding of a broken invariant (an abort libFuzzer records with the input).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>

#include "io/profile_json.h"
#include "trace/render.h"

namespace pathex::fuzz {

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

}  // namespace pathex::fuzz
