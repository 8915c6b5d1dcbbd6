// io/image_read.h: a scene's images through OpenImageIO, decoded to linear RGB with the encoding
// asked for, and every refusal with its exact message.
#include "io/image_read.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "support/scratch_files.h"
#include "support/test_images.h"

namespace pathex {
namespace {

using test::relative;
using test::scratch;
using test::write_image;

std::string message_of(const Result<LinearImage>& r) { return r.ok() ? "(read)" : relative(r.error().render()); }

TEST(ImageRead, EightBitCodesAreDecodedByTheEncodingAskedFor) {
  const std::string path = write_image<unsigned char>("codes.png", 3, 1, 3, {0, 128, 255, 10, 20, 30, 255, 255, 255});
  Result<LinearImage> srgb = read_image(path);
  ASSERT_TRUE(srgb.ok()) << message_of(srgb);
  ASSERT_EQ(srgb.value().width, 3);
  ASSERT_EQ(srgb.value().height, 1);
  EXPECT_TRUE(srgb.value().alpha.empty());
  const std::vector<float>& v = srgb.value().rgb;
  EXPECT_FLOAT_EQ(v[0], 0.0f);
  EXPECT_NEAR(v[1], 0.2158605f, 1e-6);  // sRGB code 128: ((128/255 + 0.055)/1.055)^2.4
  EXPECT_FLOAT_EQ(v[2], 1.0f);
  EXPECT_NEAR(v[3], 10.0 / 255 / 12.92, 1e-7);  // the linear segment below 0.04045
  EXPECT_FLOAT_EQ(v[8], 1.0f);

  Result<LinearImage> linear = read_image(path, {.encoding = ImageEncoding::kLinear});
  ASSERT_TRUE(linear.ok());
  EXPECT_FLOAT_EQ(linear.value().rgb[1], 128.0f / 255);
  Result<LinearImage> gamma = read_image(path, {.encoding = ImageEncoding::kGamma, .gamma = 2.2f});
  ASSERT_TRUE(gamma.ok());
  EXPECT_NEAR(gamma.value().rgb[1], std::pow(128.0 / 255, 2.2), 1e-6);
}

TEST(ImageRead, FloatDataIsLinearWhateverTheEncoding) {
  const std::string path = write_image<float>("values.exr", 2, 1, 3, {3.5f, 0.001f, 0.0f, 100.0f, 0.25f, 7.0f});
  Result<LinearImage> r = read_image(path, {.encoding = ImageEncoding::kSrgb});
  ASSERT_TRUE(r.ok()) << message_of(r);
  EXPECT_EQ(r.value().rgb, (std::vector<float>{3.5f, 0.001f, 0.0f, 100.0f, 0.25f, 7.0f}));
}

TEST(ImageRead, GreyIsCopiedToEveryChannelAndAlphaIsNotDecoded) {
  const std::string path = write_image<unsigned char>("grey-alpha.png", 1, 2, 2, {255, 128, 0, 255});
  Result<LinearImage> r = read_image(path);
  ASSERT_TRUE(r.ok()) << message_of(r);
  EXPECT_EQ(r.value().rgb, (std::vector<float>{1, 1, 1, 0, 0, 0}));  // rows from the top
  ASSERT_EQ(r.value().alpha.size(), 2u);
  EXPECT_FLOAT_EQ(r.value().alpha[0], 128.0f / 255);
  EXPECT_FLOAT_EQ(r.value().alpha[1], 1.0f);

  const std::string rgba = write_image<unsigned char>("rgba.png", 1, 1, 4, {255, 0, 0, 51});
  Result<LinearImage> four = read_image(rgba);
  ASSERT_TRUE(four.ok()) << message_of(four);
  EXPECT_EQ(four.value().rgb, (std::vector<float>{1, 0, 0}));
  EXPECT_FLOAT_EQ(four.value().alpha[0], 0.2f);
}

TEST(ImageRead, TexelsAreCountedOverTheScenesImagesAgainstTheLimit) {
  const std::string path = write_image<unsigned char>("four.png", 2, 2, 3, std::vector<unsigned char>(12, 7));
  std::size_t so_far = 0;
  Result<LinearImage> first = read_image(path, {.max_texels = 6, .texels_so_far = &so_far});
  ASSERT_TRUE(first.ok()) << message_of(first);
  EXPECT_EQ(so_far, 4u);
  Result<LinearImage> second = read_image(path, {.max_texels = 6, .texels_so_far = &so_far});
  EXPECT_EQ(message_of(second), "four.png: the size of the scene's images exceeds the limit of 6 texels (raise it with --max-texels)");
  EXPECT_EQ(so_far, 4u);
}

TEST(ImageRead, RefusalsSayWhatAndWhere) {
  EXPECT_EQ(message_of(read_image(scratch() + "/missing.png")),
            "missing.png: cannot read the image: No such file or directory");
  const std::string text = test::write("notes.png", "not an image at all\n");
  EXPECT_EQ(message_of(read_image(text)).rfind("notes.png: is not an image OpenImageIO reads: ", 0), 0u) << message_of(read_image(text));
  const std::string big = write_image<unsigned char>("big.png", 4, 4, 3, std::vector<unsigned char>(48, 1));
  EXPECT_EQ(message_of(read_image(big, {.max_file_bytes = 10})),
            "big.png: the image file exceeds the limit of 10 bytes (raise it with --max-file-size)");
  const float inf = std::numeric_limits<float>::infinity();
  const std::string nonfinite = write_image<float>("inf.exr", 2, 1, 3, {0, 0, 0, 1, inf, 1});
  EXPECT_EQ(message_of(read_image(nonfinite)),
            "inf.exr: has a value that is not finite at pixel (1, 0) (expected finite values)");
  const std::string five = write_image<float>("five.exr", 1, 1, 5, {1, 2, 3, 4, 5});
  EXPECT_EQ(message_of(read_image(five)),
            "five.exr: has 5 channels (expected 1 grey, 2 grey and alpha, 3 RGB or 4 RGBA)");
}

}  // namespace
}  // namespace pathex
