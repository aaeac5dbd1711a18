#pragma once
// PNG files through libpng. Errors throw std::runtime_error naming the file.
// Functions that read/write one file and keep nothing (thread-safe for distinct files).
#include <cstdint>
#include <string>
#include <vector>

#include "dgtex/image.h"

namespace dgtex {

// Writes an 8-bit RGBA PNG.
void write_png(const std::string& path, const Image& image);

// Largest width or height read_png accepts (16384 x 16384 RGBA is 1 GiB).
inline constexpr unsigned kMaxPngSide = 16384;

// Reads any PNG (grey, palette, RGB, 16-bit, ...) converted to 8-bit RGBA. Throws for a
// damaged file and for one wider or taller than kMaxPngSide. libpng takes 16-bit samples
// as linear light and encodes them to sRGB here: fine for pictures, not for data.
Image read_png(const std::string& path);

// Per pixel the mean of R, G and B in [0, 1] as stored (a grey PNG: its grey level), rows
// top to bottom: the samples of a data texture. 8-bit samples over 255, 16-bit ones over
// 65535 (8-bit RGBA through read_png turned 16-bit 0x8080, 0.502, into 0.73); alpha is
// ignored, except that a 16-bit pixel of alpha 0 reads 0. Throws as read_png.
struct GrayLevels {
  int width = 0;
  int height = 0;
  std::vector<double> gray;  // width * height, gray[y * width + x]
};
GrayLevels read_png_gray_levels(const std::string& path);

// What read_png_gray_levels holds at once for each pixel: its result and the decoded
// samples (16-bit RGBA at most). Callers weigh an image against the memory available with
// it before reading (read_png_size) rather than after.
inline constexpr std::int64_t kGrayLevelsReadBytesPerPixel = sizeof(double) + 4 * sizeof(std::uint16_t);

// The width and height in a PNG's header, checked as read_png checks them; decodes no
// pixel. Throws as read_png.
struct PngSize {
  int width = 0;
  int height = 0;
};
PngSize read_png_size(const std::string& path);

}  // namespace dgtex
