// OBJ meshes: the bytes become mesh.obj in a scratch folder, loaded by a fixed scene (a pinhole
// looking at the mesh and a sphere under a point light); a mesh that loads is built for Embree and
// rendered tiny (fuzz_support.h).
#include "fuzz_support.h"

namespace {
constexpr const char* kScene = R"({
  "camera": {"type": "pinhole", "position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 60, "width": 4, "height": 4},
  "materials": {"white": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
  "shapes": [{"type": "mesh", "file": "mesh.obj", "material": "white"},
             {"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "white"}],
  "lights": [{"type": "point", "position": [0, 3, 3], "intensity": [10, 10, 10]}]
})";
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pathex;
  fuzz::write_scratch("mesh.obj", fuzz::as_text(data, size));
  Result<Scene> scene = load_scene_json(kScene, fuzz::scratch_dir(), "fuzz.json", fuzz::small_scene_options());
  if (!scene) {
    if (scene.error().message.empty()) fuzz::finding("an error without a message");
    return 0;
  }
  fuzz::render_tiny(std::move(*scene), 4);
  return 0;
}
