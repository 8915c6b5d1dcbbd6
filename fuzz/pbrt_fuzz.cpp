// pbrt-v4 scenes: fuzz_support.h's fuzz_scene_file with the bytes as scene.pbrt.
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return pathex::fuzz::fuzz_scene_file(data, size, "scene.pbrt");
}
