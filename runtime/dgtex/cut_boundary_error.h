#pragma once
// How far a rendered cut boundary lies from the true one, measured on pixel coverage
// (used by `dgtex bench render` and the rendering tests).
//
// The truth is the texel-resolution cut surface (dgtex/cut_surface_export.h: one quad per
// texel, split along the cuts) rasterised on the CPU at pixel centres. For every pixel
// whose rendered coverage differs from the truth, the error is the distance (pixel centre
// to pixel centre) to the nearest pixel where the truth has the rendered value: a boundary
// rendered k pixels off gives k, a missing or extra sliver of width w gives about w/2 to
// w. Coverages are width x height bytes, row-major from the top, 1 = covered.
// Pure functions (thread-safe); errors in pixels.
#include <cstdint>
#include <vector>

#include "dgtex/image.h"
#include "dgtex/shell_renderer.h"
#include "dgtex/shell_state.h"

namespace dgtex {

// 1 where a pixel's RGB differs from the background (rounded to 8 bits).
std::vector<std::uint8_t> image_coverage(const Image& image, const float background[3]);

// Pixels whose centre (x + 0.5, y + 0.5) lies in a face of
// build_cut_surface(state, tessellation, cut_threshold) projected through camera
// (faces in front of the camera only; quads are split along their first diagonal).
std::vector<std::uint8_t> exact_cut_coverage(const ShellState& state, const Camera& camera, int tessellation = 8,
                                             float cut_threshold = 0.5f);

struct CoverageError {
  double max_pixels = 0;   // largest error (0 when the coverages agree)
  double mean_pixels = 0;  // mean error over the mismatched pixels
  long mismatched = 0;     // pixels whose coverage differs
};

// Pixels with ignored[i] != 0 (if given) are left out. Throws std::invalid_argument if
// the sizes do not match width * height.
CoverageError coverage_error(const std::vector<std::uint8_t>& rendered, const std::vector<std::uint8_t>& exact,
                             int width, int height, const std::vector<std::uint8_t>* ignored = nullptr);

// Squared Euclidean distance (in pixels) from every pixel to the nearest pixel with
// mask == value (a large number if there is none); exact two-pass transform
// (lower envelope of parabolas per row and column).
std::vector<double> squared_distance_to(const std::vector<std::uint8_t>& mask, std::uint8_t value, int width,
                                        int height);

}  // namespace dgtex
