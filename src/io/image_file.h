// One image file open for reading: the interface between io/image_read.cpp and the module that
// decodes images (io/image_file_oiio.cpp, built as libpathex_image.so and linked to OpenImageIO).
//
// Why a module: Debian's OpenImageIO links about 250 shared libraries (OpenCV, GDAL, Poppler,
// codecs). Linked into pathex they cost every command 0.4 s of dynamic loading before main() —
// `pathex explain` as much as a render. io/image_read.cpp loads the module with dlopen the first
// time a scene reads an image, so only scenes with images pay (bench/README.md "Start-up").
// The module is built by the same build as the library (one compiler, one C++ ABI), so the
// interface is C++; only its entry point has C linkage, to be found by name.
#pragma once

#include <string>

namespace pathex {

struct ImageFileInfo {
  int width = 0;
  int height = 0;
  int depth = 1;           // 1 for a two-dimensional image
  int channels = 0;
  bool floating = false;   // float or half data (linear); otherwise integer (display-encoded)
};

class ImageFile {
 public:
  virtual ~ImageFile() = default;
  virtual const ImageFileInfo& info() const = 0;
  // The whole image as floats, info().channels per texel, row-major from the top row; `data` holds
  // width * height * channels. False with a message when the file cannot be decoded.
  virtual bool read(float* data, std::string* error) = 0;
};

}  // namespace pathex

// The module's entry point: the file at `path` open, or null with *error set (OpenImageIO's message).
// The caller owns the result.
extern "C" pathex::ImageFile* pathex_open_image_file(const char* path, std::string* error);
using PathexOpenImageFileFn = pathex::ImageFile* (*)(const char*, std::string*);
