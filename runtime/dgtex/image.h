#pragma once
// An 8-bit RGBA image, rows top to bottom, 4 bytes per pixel: rgba[4 * (y * width + x) + c].
// A value type that owns its pixels (width x height x 4 bytes).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace dgtex {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgba(static_cast<size_t>(w) * h * 4, 0) {}
  std::uint8_t* pixel(int x, int y) { return rgba.data() + 4 * (static_cast<size_t>(y) * width + x); }
  const std::uint8_t* pixel(int x, int y) const { return rgba.data() + 4 * (static_cast<size_t>(y) * width + x); }
};

}  // namespace dgtex
