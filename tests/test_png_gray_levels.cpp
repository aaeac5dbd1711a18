// Data textures read as stored (dgtex/png_io.h, read_png_gray_levels): 8- and 16-bit grey,
// grey + alpha and RGB PNGs of the same levels give the same values, and so do the material
// textures made from them. Through read_png (8-bit RGBA) libpng takes 16-bit samples as
// linear light and encodes them to sRGB: 0x8080 (0.502) became 0.73 of a texture's range.
#include <gtest/gtest.h>
#include <png.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <new>
#include <string>
#include <unistd.h>
#include <vector>

#include "dgtex/material_texture.h"
#include "dgtex/png_io.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "address_space_support.h"

namespace {

using namespace dgtex;

// Writes width x 1 pixels of `format` (libpng's simplified API) from raw samples.
void write_samples(const std::string& path, int width, png_uint_32 format, const void* samples) {
  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(width);
  png.height = 1;
  png.format = format;
  ASSERT_TRUE(png_image_write_to_file(&png, path.c_str(), 0, samples, 0, nullptr)) << png.message;
}

// The PNG chunk checksum (CRC-32, ISO 3309 polynomial), bit by bit.
std::uint32_t png_crc(const std::uint8_t* bytes, std::size_t n) {
  std::uint32_t c = 0xffffffffu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= bytes[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

void put_big_endian(std::vector<std::uint8_t>& bytes, std::size_t at, std::uint32_t value) {
  for (int k = 0; k < 4; ++k) bytes[at + k] = static_cast<std::uint8_t>(value >> (24 - 8 * k));
}

// A one-element quad8 strip, clamped at x = 0, whose thickness texture is `image`.
Scene textured_strip(const std::string& image, const std::string& scene_path) {
  return parse_scene(
      R"({"mesh": {"generator": "rectangle", "size": [1, 0.1], "divisions": [1, 1], "element": "quad8"},
          "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01},
          "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true}],
          "material_textures": [{"field": "thickness", "image": ")" +
          image + R"(", "range": [0.002, 0.012]}]})",
      scene_path);
}

class PngGrayLevels : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("dgtex_png_gray_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // A small gray PNG whose header claims kMaxPngSide x kMaxPngSide pixels (its CRC redone):
  // 4 GiB to decode, the pixels themselves missing.
  std::string write_huge_header_png() const {
    const std::uint8_t grey8[2] = {128, 64};
    write_samples(path("small.png"), 2, PNG_FORMAT_GRAY, grey8);
    std::ifstream in(path("small.png"), std::ios::binary);
    std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_GT(bytes.size(), 33u);
    EXPECT_EQ(std::string(bytes.begin() + 12, bytes.begin() + 16), "IHDR");
    put_big_endian(bytes, 16, kMaxPngSide);  // width
    put_big_endian(bytes, 20, kMaxPngSide);  // height
    put_big_endian(bytes, 29, png_crc(bytes.data() + 12, 17));  // over the chunk's type and data
    std::ofstream(path("huge.png"), std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                            static_cast<std::streamsize>(bytes.size()));
    return path("huge.png");
  }
  std::filesystem::path dir_;
};

// Levels 0, 128, 255 of 255 (16-bit: 257 times those, the same fractions exactly).
TEST_F(PngGrayLevels, EightAndSixteenBitFilesGiveTheSameLevels) {
  const std::uint8_t grey8[3] = {0, 128, 255};
  const png_uint_16 grey16[3] = {0, 128 * 257, 65535};
  const png_uint_16 grey_alpha16[6] = {0, 65535, 128 * 257, 65535, 65535, 65535};
  const std::uint8_t rgb8[9] = {0, 0, 0, 100, 128, 156, 255, 255, 255};  // mean 128 in the middle
  write_samples(path("grey8.png"), 3, PNG_FORMAT_GRAY, grey8);
  write_samples(path("grey16.png"), 3, PNG_FORMAT_LINEAR_Y, grey16);
  write_samples(path("grey_alpha16.png"), 3, PNG_FORMAT_LINEAR_Y_ALPHA, grey_alpha16);
  write_samples(path("rgb8.png"), 3, PNG_FORMAT_RGB, rgb8);
  for (const char* name : {"grey8.png", "grey16.png", "grey_alpha16.png", "rgb8.png"}) {
    const GrayLevels levels = read_png_gray_levels(path(name));
    ASSERT_EQ(levels.width, 3) << name;
    ASSERT_EQ(levels.height, 1) << name;
    ASSERT_EQ(levels.gray.size(), 3u) << name;
    EXPECT_EQ(levels.gray[0], 0.0) << name;
    EXPECT_NEAR(levels.gray[1], 128.0 / 255, 1e-15) << name;
    EXPECT_EQ(levels.gray[2], 1.0) << name;
  }
  // What read_png makes of the 16-bit file: sRGB-encoded, far from 128.
  const Image encoded = read_png(path("grey16.png"));
  EXPECT_GT(encoded.pixel(1, 0)[0], 180);
  EXPECT_THROW(read_png_gray_levels(path("missing.png")), std::runtime_error);
}

// A thickness texture from a 16-bit grey image equals the one from the 8-bit image.
TEST_F(PngGrayLevels, MaterialTexturesFromSixteenBitImagesAreTheStoredLevels) {
  const std::uint8_t grey8[2] = {128, 64};
  const png_uint_16 grey16[2] = {128 * 257, 64 * 257};
  write_samples(path("t8.png"), 2, PNG_FORMAT_GRAY, grey8);
  write_samples(path("t16.png"), 2, PNG_FORMAT_LINEAR_Y, grey16);
  std::vector<double> thickness[2];
  for (int k = 0; k < 2; ++k) {
    const std::string image = k == 0 ? "t8.png" : "t16.png";
    const Scene scene = textured_strip(image, path("scene.json"));
    const std::vector<ElementMaterialTexture> textures = scene_material_textures(scene, build_scene_mesh(scene));
    ASSERT_EQ(textures.size(), 1u);
    thickness[k] = textures[0].thickness;
  }
  ASSERT_EQ(thickness[0].size(), 2u);
  EXPECT_EQ(thickness[0], thickness[1]);
  EXPECT_NEAR(thickness[1][0], 0.002 + 0.01 * 128 / 255, 1e-15);
  EXPECT_NEAR(thickness[1][1], 0.002 + 0.01 * 64 / 255, 1e-15);
}

// A header claiming 16384 x 16384 pixels is weighed against the memory available before
// anything is decoded.
TEST_F(PngGrayLevels, ImagesBeyondTheMemoryAvailableAreRefusedFromTheirHeader) {
  const PngSize size = read_png_size(write_huge_header_png());
  EXPECT_EQ(size.width, static_cast<int>(kMaxPngSide));
  EXPECT_EQ(size.height, static_cast<int>(kMaxPngSide));

  const Scene scene = textured_strip("huge.png", path("scene.json"));
  const std::int64_t one_gib = std::int64_t{1} << 30;
  try {
    scene_material_textures(scene, build_scene_mesh(scene), one_gib);
    FAIL() << "a 16384 x 16384 image was read with 1 GiB available";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.json_path(), "material_textures[0].image");
    const std::string what = e.what();
    for (const char* part : {"reading its 16384x16384 pixels", "16 bytes a pixel", "a smaller image"})
      EXPECT_NE(what.find(part), std::string::npos) << part << " not in: " << what;
  }
}

// A read whose pixels cannot be allocated (the library's readers weigh nothing) closes its
// file: until session 72 each such read left a file descriptor and libpng's state behind.
TEST_F(PngGrayLevels, AReadThatCannotAllocateItsPixelsClosesItsFile) {
  const std::string huge = write_huge_header_png();
  const auto open_files = [] {
    return std::distance(std::filesystem::directory_iterator("/proc/self/fd"), std::filesystem::directory_iterator());
  };
  test::ScopedAddressSpaceLimit limit(std::int64_t{512} << 20);  // below read_png's 1 GiB of pixels
  if (!limit.why_not().empty()) GTEST_SKIP() << limit.why_not();
  const auto before = open_files();
  for (int k = 0; k < 3; ++k) {
    EXPECT_THROW(read_png(huge), std::bad_alloc);
    EXPECT_THROW(read_png_gray_levels(huge), std::bad_alloc);
  }
  limit.restore();
  EXPECT_EQ(open_files(), before);
}

// The read's weighing at its line: a 2 x 1 image takes 2 x 16 bytes to read (and as many for
// the element's copies of E and h afterwards).
TEST_F(PngGrayLevels, AnImageIsReadWhenItsDecodingFits) {
  const std::uint8_t grey8[2] = {128, 64};
  write_samples(path("small.png"), 2, PNG_FORMAT_GRAY, grey8);
  const Scene scene = textured_strip("small.png", path("scene.json"));
  const Mesh mesh = build_scene_mesh(scene);
  EXPECT_EQ(scene_material_textures(scene, mesh, 2 * kGrayLevelsReadBytesPerPixel).size(), 1u);
  try {
    scene_material_textures(scene, mesh, 2 * kGrayLevelsReadBytesPerPixel - 1);
    FAIL() << "read with one byte too few";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.json_path(), "material_textures[0].image");
    EXPECT_NE(std::string(e.what()).find("reading its 2x1 pixels"), std::string::npos) << e.what();
  }
}

}  // namespace
