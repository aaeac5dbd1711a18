#pragma once
// PNG files through libpng. Errors throw std::runtime_error naming the file.
// Functions that read/write one file and keep nothing (thread-safe for distinct files).
#include <string>

#include "dgtex/image.h"

namespace dgtex {

// Writes an 8-bit RGBA PNG.
void write_png(const std::string& path, const Image& image);

// Largest width or height read_png accepts (16384 x 16384 RGBA is 1 GiB).
inline constexpr unsigned kMaxPngSide = 16384;

// Reads any PNG (grey, palette, RGB, 16-bit, ...) converted to 8-bit RGBA. Throws for a
// damaged file and for one wider or taller than kMaxPngSide.
Image read_png(const std::string& path);

}  // namespace dgtex
