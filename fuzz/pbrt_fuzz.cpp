// pbrt-v4 scenes: the bytes become scene.pbrt in a scratch folder beside links to the sample
// scenes' include/ and meshes/ (so the seeds' Include and plymesh resolve), loaded under small
// limits (fuzz_support.h); a scene that loads is built for Embree and rendered tiny.
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pathex;
  fuzz::link_sample_folders();
  const std::string path = fuzz::write_scratch("scene.pbrt", fuzz::as_text(data, size));
  Result<Scene> scene = load_scene_file(path, fuzz::small_scene_options());
  if (!scene) {
    if (scene.error().message.empty()) fuzz::finding("an error without a message");
    // Echoed tokens are cut (excerpt), file names past PATH_MAX too: one message stays short.
    if (scene.error().message.size() + scene.error().where.size() > 16384) fuzz::finding("a message of more than 16 KiB");
    return 0;
  }
  fuzz::render_tiny(std::move(*scene), 4);
  return 0;
}
