// libpathex_image.so: io/image_file.h through OpenImageIO (PNG, JPEG, EXR, HDR, PFM, TGA, TIFF,
// ... whatever the installed OpenImageIO reads). Loaded by io/image_read.cpp with dlopen.
#include <OpenImageIO/imageio.h>

#include <exception>
#include <memory>
#include <string>

#include "io/image_file.h"

namespace pathex {
namespace {

// OpenImageIO's message without its trailing newline, or `fallback` when it has none.
std::string oiio_message(std::string message, const std::string& fallback) {
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  return message.empty() ? fallback : message;
}

class OiioImageFile final : public ImageFile {
 public:
  explicit OiioImageFile(std::unique_ptr<OIIO::ImageInput> in) : in_(std::move(in)) {
    const OIIO::ImageSpec& spec = in_->spec();
    info_.width = spec.width;
    info_.height = spec.height;
    info_.depth = spec.depth;
    info_.channels = spec.nchannels;
    info_.floating = spec.format.is_floating_point();
  }
  const ImageFileInfo& info() const override { return info_; }
  bool read(float* data, std::string* error) override {
    try {
      if (in_->read_image(0, 0, 0, info_.channels, OIIO::TypeDesc::FLOAT, data)) return true;
      *error = oiio_message(in_->geterror(), "a read error");
    } catch (const std::exception& e) {  // OpenImageIO and its codecs report by value; a throw
      *error = oiio_message(e.what(), "a read error");  // (bad_alloc, a codec's own) becomes one too
    } catch (...) {
      *error = "a read error";
    }
    return false;
  }

 private:
  std::unique_ptr<OIIO::ImageInput> in_;
  ImageFileInfo info_;
};

}  // namespace
}  // namespace pathex

extern "C" pathex::ImageFile* pathex_open_image_file(const char* path, std::string* error) {
  // Colour as the file stores it: OpenImageIO would otherwise multiply a PNG's colour by its alpha
  // (associated alpha), and the colour's decoding and an alpha cut-out each need it alone.
  // No exception crosses the module's boundary: anything thrown is the caller's located error.
  try {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path, &config);
    if (!in) {
      *error = pathex::oiio_message(OIIO::geterror(), "unknown format");
      return nullptr;
    }
    return new pathex::OiioImageFile(std::move(in));
  } catch (const std::exception& e) {
    *error = pathex::oiio_message(e.what(), "unknown format");
  } catch (...) {
    *error = "unknown format";
  }
  return nullptr;
}
