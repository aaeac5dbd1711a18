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

// A PNG file opened through libpng's simplified API, its header read and its size checked
// against kMaxPngSide. The destructor frees libpng's state and closes the file: an
// exception between opening and decoding (the pixels' allocation) left both open until
// session 72, a file descriptor per failed read.
class OpenPng {
 public:
  explicit OpenPng(const std::string& path) : path_(path) {
    std::memset(&png_, 0, sizeof(png_));
    png_.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png_, path.c_str()))
      throw std::runtime_error("cannot read PNG '" + path + "': " + message_and_free());
    // A header may claim any size up to 2^31 per side; refuse what no texture needs rather
    // than fail to allocate it (or allocate gigabytes).
    if (png_.width > kMaxPngSide || png_.height > kMaxPngSide) {
      const std::string size = std::to_string(png_.width) + " x " + std::to_string(png_.height);
      png_image_free(&png_);
      throw std::runtime_error("cannot read PNG '" + path + "': " + size + " pixels; at most " +
                               std::to_string(kMaxPngSide) + " x " + std::to_string(kMaxPngSide) + " are read");
    }
  }
  ~OpenPng() { png_image_free(&png_); }  // frees nothing a second time
  OpenPng(const OpenPng&) = delete;
  OpenPng& operator=(const OpenPng&) = delete;

  int width() const { return static_cast<int>(png_.width); }
  int height() const { return static_cast<int>(png_.height); }
  bool sixteen_bit() const { return (png_.format & PNG_FORMAT_FLAG_LINEAR) != 0; }
  // Decodes into `pixels` in `format`.
  void finish_read(png_uint_32 format, void* pixels) {
    png_.format = format;
    if (!png_image_finish_read(&png_, nullptr, pixels, 0, nullptr))
      throw std::runtime_error("cannot decode PNG '" + path_ + "': " + message_and_free());
  }

 private:
  std::string message_and_free() {
    const std::string message = png_.message;
    png_image_free(&png_);
    return message;
  }
  std::string path_;
  png_image png_;
};

}  // namespace

Image read_png(const std::string& path) {
  OpenPng png(path);
  Image image(png.width(), png.height());
  png.finish_read(PNG_FORMAT_RGBA, image.rgba.data());
  return image;
}

PngSize read_png_size(const std::string& path) {
  const OpenPng png(path);
  return {png.width(), png.height()};
}

GrayLevels read_png_gray_levels(const std::string& path) {
  OpenPng png(path);
  GrayLevels out;
  out.width = png.width();
  out.height = png.height();
  const std::size_t pixels = static_cast<std::size_t>(out.width) * out.height;
  out.gray.resize(pixels);
  if (png.sixteen_bit()) {
    // A 16-bit file: libpng takes its samples as linear, so a linear output format passes
    // them through. Its linear formats premultiply by alpha: divided out again.
    std::vector<png_uint_16> rgba(4 * pixels);
    png.finish_read(PNG_FORMAT_LINEAR_RGB_ALPHA, rgba.data());
    for (std::size_t i = 0; i < pixels; ++i) {
      const png_uint_16* p = rgba.data() + 4 * i;
      out.gray[i] = p[3] == 0 ? 0.0 : (p[0] + p[1] + p[2]) / (3.0 * p[3]);
    }
  } else {
    // An 8-bit file (or palette): its samples as stored, alpha left aside (as read_png).
    std::vector<std::uint8_t> rgba(4 * pixels);
    png.finish_read(PNG_FORMAT_RGBA, rgba.data());
    for (std::size_t i = 0; i < pixels; ++i) {
      const std::uint8_t* p = rgba.data() + 4 * i;
      out.gray[i] = (p[0] + p[1] + p[2]) / (3.0 * 255.0);
    }
  }
  return out;
}

}  // namespace dgtex
