#include "dgtex/cut_boundary_error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "dgtex/cut_surface_export.h"

namespace dgtex {

namespace {

// 1-D squared distance transform of f (n values) into d: d[q] = min_p (q - p)^2 + f[p].
void distance_1d(const double* f, int n, double* d, std::vector<int>& v, std::vector<double>& z) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  v.assign(n, 0);
  z.assign(n + 1, 0);
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (!(f[q] < inf)) continue;
    double s = -inf;
    while (k >= 0) {
      s = ((f[q] + double(q) * q) - (f[v[k]] + double(v[k]) * v[k])) / (2.0 * (q - v[k]));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -inf : s;
    z[k + 1] = inf;
  }
  if (k < 0) {
    std::fill(d, d + n, inf);
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    d[q] = double(q - v[j]) * (q - v[j]) + f[v[j]];
  }
}

}  // namespace

std::vector<std::uint8_t> image_coverage(const Image& image, const float background[3]) {
  int bg[3];
  for (int c = 0; c < 3; ++c) bg[c] = static_cast<int>(std::lround(background[c] * 255));
  std::vector<std::uint8_t> covered(static_cast<size_t>(image.width) * image.height);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      covered[static_cast<size_t>(y) * image.width + x] = p[0] != bg[0] || p[1] != bg[1] || p[2] != bg[2];
    }
  return covered;
}

std::vector<std::uint8_t> exact_cut_coverage(const ShellState& state, const Camera& camera, int tessellation,
                                             float cut_threshold) {
  const CutSurfaceMesh surface = build_cut_surface(state, tessellation, cut_threshold);
  const int width = camera.width, height = camera.height;
  std::vector<std::uint8_t> covered(static_cast<size_t>(width) * height, 0);
  // Pixel positions and whether each vertex lies in front of the camera (clip w > 0).
  std::vector<double> px(surface.num_vertices()), py(surface.num_vertices());
  std::vector<char> in_front(surface.num_vertices());
  const double* m = camera.view_projection;
  for (int v = 0; v < surface.num_vertices(); ++v) {
    const double* p = &surface.vertices[3 * v];
    in_front[v] = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15] > 0;
    camera.project(p, px[v], py[v]);
  }
  auto fill_triangle = [&](int a, int b, int c) {
    if (!in_front[a] || !in_front[b] || !in_front[c]) return;
    const double ax = px[a], ay = py[a], bx = px[b], by = py[b], cx = px[c], cy = py[c];
    const double area = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
    if (area == 0) return;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({ax, bx, cx}) - 0.5)));
    const int x1 = std::min(width - 1, static_cast<int>(std::ceil(std::max({ax, bx, cx}) - 0.5)));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({ay, by, cy}) - 0.5)));
    const int y1 = std::min(height - 1, static_cast<int>(std::ceil(std::max({ay, by, cy}) - 0.5)));
    const double sign = area > 0 ? 1 : -1;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double qx = x + 0.5, qy = y + 0.5;
        const double e0 = sign * ((bx - ax) * (qy - ay) - (qx - ax) * (by - ay));
        const double e1 = sign * ((cx - bx) * (qy - by) - (qx - bx) * (cy - by));
        const double e2 = sign * ((ax - cx) * (qy - cy) - (qx - cx) * (ay - cy));
        if (e0 >= 0 && e1 >= 0 && e2 >= 0) covered[static_cast<size_t>(y) * width + x] = 1;
      }
  };
  size_t offset = 0;
  for (int f = 0; f < surface.num_faces(); ++f) {
    const int* v = &surface.face_vertices[offset];
    fill_triangle(v[0], v[1], v[2]);
    if (surface.face_sizes[f] == 4) fill_triangle(v[0], v[2], v[3]);
    offset += surface.face_sizes[f];
  }
  return covered;
}

std::vector<double> squared_distance_to(const std::vector<std::uint8_t>& mask, std::uint8_t value, int width,
                                        int height) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::vector<double> grid(static_cast<size_t>(width) * height);
  for (size_t i = 0; i < grid.size(); ++i) grid[i] = mask[i] == value ? 0.0 : inf;
  std::vector<double> f(std::max(width, height)), d(std::max(width, height));
  std::vector<int> v;
  std::vector<double> z;
  for (int x = 0; x < width; ++x) {  // columns
    for (int y = 0; y < height; ++y) f[y] = grid[static_cast<size_t>(y) * width + x];
    distance_1d(f.data(), height, d.data(), v, z);
    for (int y = 0; y < height; ++y) grid[static_cast<size_t>(y) * width + x] = d[y];
  }
  for (int y = 0; y < height; ++y) {  // rows
    double* row = grid.data() + static_cast<size_t>(y) * width;
    std::copy(row, row + width, f.begin());
    distance_1d(f.data(), width, row, v, z);
  }
  for (double& g : grid)
    if (!(g < inf)) g = std::numeric_limits<double>::max();
  return grid;
}

CoverageError coverage_error(const std::vector<std::uint8_t>& rendered, const std::vector<std::uint8_t>& exact,
                             int width, int height, const std::vector<std::uint8_t>* ignored) {
  const size_t n = static_cast<size_t>(width) * height;
  if (width < 1 || height < 1 || rendered.size() != n || exact.size() != n || (ignored && ignored->size() != n))
    throw std::invalid_argument("coverage_error: coverages of " + std::to_string(rendered.size()) + " and " +
                                std::to_string(exact.size()) + " pixels for an image of " + std::to_string(width) +
                                " x " + std::to_string(height));
  const std::vector<double> to_covered = squared_distance_to(exact, 1, width, height);
  const std::vector<double> to_background = squared_distance_to(exact, 0, width, height);
  CoverageError e;
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    if (rendered[i] == exact[i] || (ignored && (*ignored)[i])) continue;
    const double d = std::sqrt(rendered[i] ? to_covered[i] : to_background[i]);
    e.max_pixels = std::max(e.max_pixels, d);
    sum += d;
    ++e.mismatched;
  }
  e.mean_pixels = e.mismatched ? sum / e.mismatched : 0.0;
  return e;
}

}  // namespace dgtex
