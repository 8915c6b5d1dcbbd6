// Environment images the image-infinite-light tests write (through OpenImageIO, as EXR floats)
// into the process's scratch folder.
#pragma once

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "support/scratch_files.h"

namespace pathex::test {

// width x height RGB texels, row-major from the top row, to scratch()/name; returns the path.
inline std::string write_rgb_exr(const std::string& name, int width, int height, const std::vector<float>& rgb) {
  const std::string path = scratch() + "/" + name;
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(path);
  EXPECT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::FLOAT);
  EXPECT_TRUE(out->open(path, spec));
  EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
  out->close();
  return path;
}

// A constant image.
inline std::string write_constant_exr(const std::string& name, int width, int height, float value) {
  return write_rgb_exr(name, width, height, std::vector<float>(static_cast<std::size_t>(width * height * 3), value));
}

// `background` everywhere but texel (x, y), which is `bright`.
inline std::string write_one_texel_exr(const std::string& name, int width, int height, int x, int y, float background, float bright) {
  std::vector<float> v(static_cast<std::size_t>(width * height * 3), background);
  for (int c = 0; c < 3; ++c) v[static_cast<std::size_t>((y * width + x) * 3 + c)] = bright;
  return write_rgb_exr(name, width, height, v);
}

}  // namespace pathex::test
