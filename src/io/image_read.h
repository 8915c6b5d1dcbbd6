// Reading a scene's images — textures and environment maps — through OpenImageIO (PNG, JPEG, EXR,
// HDR, PFM, TGA, TIFF, ... whatever the installed OpenImageIO reads), as linear RGB floats with an
// optional alpha channel, row-major from the top row.
//
// Encoding: float and half data are linear radiometric values and are taken as they are. Integer
// data (8- or 16-bit) is a display encoding, decoded by `encoding`: sRGB by default (pbrt-v4's
// "encoding" default and Mitsuba 3's for LDR bitmaps), linear (pbrt "linear", Mitsuba raw="true"),
// or a power law (pbrt "gamma g"). Alpha is never decoded (it is a coverage, not a colour).
// One channel is grey (copied to R, G and B), two are grey and alpha, three RGB, four RGBA; more
// are refused, as are images of no pixels and values that are not finite.
//
// Errors are values naming the file: a file that does not exist or is not an image, a file larger
// than `max_file_bytes` (kLimit, --max-file-size), more texels than `max_texels` counted with the
// scene's images read before (kLimit, --max-texels).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/limits.h"

namespace pathex {

enum class ImageEncoding { kSrgb, kLinear, kGamma };

struct ImageReadOptions {
  ImageEncoding encoding = ImageEncoding::kSrgb;  // of integer data only
  float gamma = 2.2f;                              // with kGamma: value = code^gamma
  std::size_t max_file_bytes = Limits{}.max_file_bytes;
  std::size_t max_texels = Limits{}.max_texels;
  // The texels of the scene's images read before, on entry; with this image's on return.
  std::size_t* texels_so_far = nullptr;
};

struct LinearImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;    // width * height * 3, linear, row-major from the top row
  std::vector<float> alpha;  // width * height, or empty when the file has no alpha channel
};

Result<LinearImage> read_image(const std::string& path, const ImageReadOptions& options = {});

// The sRGB transfer curve's inverse (IEC 61966-2-1): an encoded value in [0, 1] to linear.
float srgb_to_linear(float encoded);

}  // namespace pathex
