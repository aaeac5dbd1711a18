#include "dgtex/png_io.h"

#include <png.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace dgtex {

// libpng's simplified API reports errors in png_image::message instead of longjmp, so no
// C++ object is ever skipped by a non-local jump.
void write_png(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgba.size() != static_cast<size_t>(image.width) * image.height * 4)
    throw std::runtime_error("write_png('" + path + "'): image of " + std::to_string(image.width) + " x " +
                             std::to_string(image.height) + " pixels holds " + std::to_string(image.rgba.size()) +
                             " bytes (expected width * height * 4, both positive)");
  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGBA;
  if (!png_image_write_to_file(&png, path.c_str(), 0, image.rgba.data(), 0, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    throw std::runtime_error("cannot write PNG '" + path + "': " + message);
  }
}

namespace {

// Opens `path` and reads its header: the size checked against kMaxPngSide.
void begin_read(png_image& png, const std::string& path) {
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    const std::string message = png.message;
    png_image_free(&png);
    throw std::runtime_error("cannot read PNG '" + path + "': " + message);
  }
  // A header may claim any size up to 2^31 per side; refuse what no texture needs rather
  // than fail to allocate it (or allocate gigabytes).
  if (png.width > kMaxPngSide || png.height > kMaxPngSide) {
    const std::string size = std::to_string(png.width) + " x " + std::to_string(png.height);
    png_image_free(&png);
    throw std::runtime_error("cannot read PNG '" + path + "': " + size + " pixels; at most " +
                             std::to_string(kMaxPngSide) + " x " + std::to_string(kMaxPngSide) + " are read");
  }
}

// Decodes the opened file into `pixels` in png.format (set by the caller).
void finish_read(png_image& png, const std::string& path, void* pixels) {
  if (!png_image_finish_read(&png, nullptr, pixels, 0, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    throw std::runtime_error("cannot decode PNG '" + path + "': " + message);
  }
}

}  // namespace

Image read_png(const std::string& path) {
  png_image png;
  begin_read(png, path);
  png.format = PNG_FORMAT_RGBA;
  Image image(static_cast<int>(png.width), static_cast<int>(png.height));
  finish_read(png, path, image.rgba.data());
  return image;
}

PngSize read_png_size(const std::string& path) {
  png_image png;
  begin_read(png, path);
  const PngSize size{static_cast<int>(png.width), static_cast<int>(png.height)};
  png_image_free(&png);
  return size;
}

GrayLevels read_png_gray_levels(const std::string& path) {
  png_image png;
  begin_read(png, path);
  GrayLevels out;
  out.width = static_cast<int>(png.width);
  out.height = static_cast<int>(png.height);
  const std::size_t pixels = static_cast<std::size_t>(out.width) * out.height;
  out.gray.resize(pixels);
  if (png.format & PNG_FORMAT_FLAG_LINEAR) {
    // A 16-bit file: libpng takes its samples as linear, so a linear output format passes
    // them through. Its linear formats premultiply by alpha: divided out again.
    png.format = PNG_FORMAT_LINEAR_RGB_ALPHA;
    std::vector<png_uint_16> rgba(4 * pixels);
    finish_read(png, path, rgba.data());
    for (std::size_t i = 0; i < pixels; ++i) {
      const png_uint_16* p = rgba.data() + 4 * i;
      out.gray[i] = p[3] == 0 ? 0.0 : (p[0] + p[1] + p[2]) / (3.0 * p[3]);
    }
  } else {
    // An 8-bit file (or palette): its samples as stored, alpha left aside (as read_png).
    png.format = PNG_FORMAT_RGBA;
    std::vector<std::uint8_t> rgba(4 * pixels);
    finish_read(png, path, rgba.data());
    for (std::size_t i = 0; i < pixels; ++i) {
      const std::uint8_t* p = rgba.data() + 4 * i;
      out.gray[i] = (p[0] + p[1] + p[2]) / (3.0 * 255.0);
    }
  }
  return out;
}

}  // namespace dgtex
