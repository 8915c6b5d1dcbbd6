// Scene JSON: load and validate; a scene that loads is built for Embree and rendered tiny
// (fuzz_support.h). Relative mesh paths resolve in tests/scene/bad, beside the seed corpus.
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pathex;
  Result<Scene> scene = load_scene_json(fuzz::as_text(data, size), PATHEX_SOURCE_DIR "/tests/scene/bad", "fuzz.json",
                                         fuzz::small_scene_options());
  if (!scene) {
    if (scene.error().message.empty()) fuzz::finding("an error without a message");
    return 0;
  }
  fuzz::render_tiny(std::move(*scene), 6);
  return 0;
}
