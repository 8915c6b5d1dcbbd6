// A scene file loaded for a test: a file that does not load fails the test with its located
// message and gives an empty scene, so that the test goes on to report what else is wrong.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "scene/scene.h"

namespace pathex::test {

inline Scene load(const std::string& path) {
  Result<Scene> s = load_scene_file(path);
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().render());
  return s.ok() ? std::move(*s) : Scene{};
}

}  // namespace pathex::test
