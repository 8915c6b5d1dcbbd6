// Writing small test images with OpenImageIO (the tests that read images through io/image_read.h).
#pragma once

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "support/scratch_files.h"

namespace pathex::test {

// Writes `values` (width x height x channels, row-major from the top) to scratch()/name in the
// file's own format: 8-bit codes for PNG, floats for EXR.
template <class T>
std::string write_image(const std::string& name, int width, int height, int channels, const std::vector<T>& values) {
  const std::string path = scratch() + "/" + name;
  const OIIO::TypeDesc type = std::is_same_v<T, float> ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(path);
  EXPECT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(width, height, channels, type);
  EXPECT_TRUE(out->open(path, spec));
  EXPECT_TRUE(out->write_image(type, values.data()));
  out->close();
  return path;
}

}  // namespace pathex::test
