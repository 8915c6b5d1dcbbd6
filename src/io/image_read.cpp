#include "io/image_read.h"

#include <dlfcn.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <system_error>

#include "io/image_file.h"

namespace pathex {

namespace {

Error image_error(ErrorCode code, const std::string& path, std::string message) {
  Error e = make_error(code, std::move(message));
  e.where = path;
  return e;
}

// The decoding module (io/image_file.h), loaded once per process and never closed. Where it is
// looked for: the build tree's copy (while that exists); beside the running executable as
// installed (bin/pathex with lib/pathex/libpathex_image.so, whatever prefix `cmake --install`
// was given); the install prefix configured at build time (a program linking the installed
// library).
struct ImageModule {
  PathexOpenImageFileFn open = nullptr;
  std::string error;  // why it could not be loaded, when `open` is null
};

std::vector<std::string> image_module_candidates() {
  std::vector<std::string> paths{PATHEX_IMAGE_MODULE_BUILD};
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) paths.push_back((exe.parent_path() / PATHEX_IMAGE_MODULE_FROM_BINDIR).lexically_normal().string());
  paths.push_back(PATHEX_IMAGE_MODULE_INSTALLED);
  return paths;
}

const ImageModule& image_module() {
  static const ImageModule module = [] {
    ImageModule m;
    std::string tried;
    for (const std::string& path : image_module_candidates()) {
      void* lib = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (lib == nullptr) {
        tried += std::string(tried.empty() ? "" : "; ") + ::dlerror();
        continue;
      }
      m.open = reinterpret_cast<PathexOpenImageFileFn>(::dlsym(lib, "pathex_open_image_file"));
      if (m.open != nullptr) return m;
      tried += std::string(tried.empty() ? "" : "; ") + path + ": has no pathex_open_image_file";
    }
    m.error = "cannot load pathex's image decoder libpathex_image.so (" + tried + ")";
    return m;
  }();
  return module;
}

}  // namespace

float srgb_to_linear(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

Result<LinearImage> read_image(const std::string& path, const ImageReadOptions& options) {
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec) return image_error(ErrorCode::kBadFile, path, "cannot read the image: " + ec.message());
  if (bytes > options.max_file_bytes)
    return image_error(ErrorCode::kLimit, path, limit_message("the image file", options.max_file_bytes, "bytes", "--max-file-size"));

  const ImageModule& module = image_module();
  if (module.open == nullptr) return image_error(ErrorCode::kBadFile, path, module.error);
  std::string message;
  std::unique_ptr<ImageFile> in(module.open(path.c_str(), &message));
  if (!in) return image_error(ErrorCode::kBadFile, path, "is not an image OpenImageIO reads: " + message);
  const ImageFileInfo spec = in->info();
  if (spec.width <= 0 || spec.height <= 0 || spec.depth != 1)
    return image_error(ErrorCode::kBadFile, path, "has no pixels (expected a two-dimensional image of at least 1 x 1)");
  if (spec.channels < 1 || spec.channels > 4)
    return image_error(ErrorCode::kBadFile, path,
                       "has " + std::to_string(spec.channels) + " channels (expected 1 grey, 2 grey and alpha, 3 RGB or 4 RGBA)");
  const std::size_t texels = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height);
  const std::size_t before = options.texels_so_far ? *options.texels_so_far : 0;
  if (texels > options.max_texels || before + texels > options.max_texels)
    return image_error(ErrorCode::kLimit, path, limit_message("the size of the scene's images", options.max_texels, "texels", "--max-texels"));

  const int channels = spec.channels;
  std::vector<float> data(texels * static_cast<std::size_t>(channels));
  if (!in->read(data.data(), &message)) return image_error(ErrorCode::kBadFile, path, "cannot be decoded: " + message);
  in.reset();

  const bool encoded = !spec.floating;
  auto decode = [&](float v) {
    if (!encoded || options.encoding == ImageEncoding::kLinear) return v;
    if (options.encoding == ImageEncoding::kSrgb) return srgb_to_linear(v);
    return std::pow(v, options.gamma);
  };
  LinearImage image;
  image.width = spec.width;
  image.height = spec.height;
  image.rgb.resize(texels * 3);
  const bool has_alpha = channels == 2 || channels == 4;
  if (has_alpha) image.alpha.resize(texels);
  for (std::size_t i = 0; i < texels; ++i) {
    const float* texel = &data[i * static_cast<std::size_t>(channels)];
    for (int c = 0; c < channels; ++c)
      if (!std::isfinite(texel[c]))
        return image_error(ErrorCode::kBadValue, path,
                           "has a value that is not finite at pixel (" + std::to_string(i % spec.width) + ", " +
                               std::to_string(i / spec.width) + ") (expected finite values)");
    const int colour = channels >= 3 ? 3 : 1;
    for (int c = 0; c < 3; ++c) image.rgb[3 * i + c] = decode(texel[colour == 3 ? c : 0]);
    if (has_alpha) image.alpha[i] = texel[channels - 1];
  }
  if (options.texels_so_far) *options.texels_so_far = before + texels;
  return image;
}

}  // namespace pathex
