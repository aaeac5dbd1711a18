#include "dgtex/png_io.h"

#include <png.h>

#include <cstring>
#include <stdexcept>

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

Image read_png(const std::string& path) {
  png_image png;
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
  png.format = PNG_FORMAT_RGBA;
  Image image(static_cast<int>(png.width), static_cast<int>(png.height));
  if (!png_image_finish_read(&png, nullptr, image.rgba.data(), 0, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    throw std::runtime_error("cannot decode PNG '" + path + "': " + message);
  }
  return image;
}

}  // namespace dgtex
