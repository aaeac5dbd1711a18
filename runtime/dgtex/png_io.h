#pragma once
// PNG files through libpng. Errors throw std::runtime_error naming the file.
#include <string>

#include "dgtex/image.h"

namespace dgtex {

// Writes an 8-bit RGBA PNG.
void write_png(const std::string& path, const Image& image);

// Reads any PNG (grey, palette, RGB, 16-bit, ...) converted to 8-bit RGBA.
Image read_png(const std::string& path);

}  // namespace dgtex
