#pragma once
// Synthetic shell states for the rendering tests: small meshes with hand-made enrichment
// textures whose deformed geometry is known exactly.
#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "dgtex/deformed_shell.h"
#include "dgtex/image.h"
#include "dgtex/shell_renderer.h"
#include "dgtex/shell_state.h"

namespace dgtex::test {

// A rectangle [0, sx] x [0, sy] of nx x ny quad8 elements (or 2 nx ny tri6), z = 0.
inline Mesh rectangle_mesh(ElementType type, int nx, int ny, double sx, double sy) {
  Mesh m;
  m.type = type;
  std::map<std::pair<int, int>, int> id;
  auto node = [&](int i, int j) {
    auto [it, inserted] = id.emplace(std::make_pair(i, j), static_cast<int>(id.size()));
    if (inserted) {
      m.positions.push_back(sx * i / (2.0 * nx));
      m.positions.push_back(sy * j / (2.0 * ny));
      m.positions.push_back(0.0);
    }
    return it->second;
  };
  for (int ey = 0; ey < ny; ++ey)
    for (int ex = 0; ex < nx; ++ex) {
      const int i = 2 * ex, j = 2 * ey;
      if (type == ElementType::quad8) {
        for (int n : {node(i, j), node(i + 2, j), node(i + 2, j + 2), node(i, j + 2), node(i + 1, j),
                      node(i + 2, j + 1), node(i + 1, j + 2), node(i, j + 1)})
          m.elements.push_back(n);
      } else {
        for (int n : {node(i, j), node(i + 2, j), node(i + 2, j + 2), node(i + 1, j), node(i + 2, j + 1),
                      node(i + 1, j + 1)})
          m.elements.push_back(n);
        for (int n : {node(i, j), node(i + 2, j + 2), node(i, j + 2), node(i + 1, j + 1), node(i + 1, j + 2),
                      node(i, j + 1)})
          m.elements.push_back(n);
      }
    }
  return m;
}

// The cut plate of the tests: 2 x 1 quad8 elements of 1 x 1 on [0, 2] x [0, 1], element 0
// cut completely from bottom to top along texel edges: texel (i, j) of its T x T texture
// lies left of the cut (H = -1) when i < cut_column(j), else right (H = +1); x = i / T.
// The left piece is moved rigidly by -gap along x, the right piece (and element 1)
// stays: q^a = gap/2 e_x for all nodes, u^a = -gap e_x on nodes with H(xi^a) = -1. This is
// exact for any choice of node values in {-1, +1}; nodes shared with element 1 get +1.
struct CutPlate {
  ShellState state;
  int resolution;
  std::vector<int> cut_column;  // per texel row j
  double gap;
  double texel_size;  // world length of one texel
  // Whether the deformed plate covers world point (x, y) (all of it lies in z = 0).
  bool covers(double x, double y) const {
    if (y < 0 || y > 1) return false;
    if (x >= 1 && x <= 2) return true;                 // element 1
    auto side = [&](double rest_x, double rest_y) {    // -1 left, +1 right, 0 outside element 0
      if (rest_x < 0 || rest_x > 1) return 0;
      const int i = std::min(static_cast<int>(rest_x * resolution), resolution - 1);
      const int j = std::min(static_cast<int>(rest_y * resolution), resolution - 1);
      return i < cut_column[j] ? -1 : 1;
    };
    return side(x, y) == 1 || side(x + gap, y) == -1;
  }
};

template <class CutColumn>
CutPlate cut_plate(int resolution, CutColumn cut_column, double gap) {
  CutPlate p;
  p.resolution = resolution;
  p.gap = gap;
  p.texel_size = 1.0 / resolution;
  for (int j = 0; j < resolution; ++j) p.cut_column.push_back(cut_column(j));
  ShellState& s = p.state;
  s.mesh = rectangle_mesh(ElementType::quad8, 2, 1, 2.0, 1.0);
  s.displacement.assign(s.mesh.positions.size(), 0.0);
  ElementEnrichment e;
  e.element = 0;
  e.resolution = resolution;
  e.values.resize(static_cast<size_t>(resolution) * resolution);
  for (int j = 0; j < resolution; ++j)
    for (int i = 0; i < resolution; ++i) e.values[j * resolution + i] = i < p.cut_column[j] ? -1.0f : 1.0f;
  const int* nodes = s.mesh.element_nodes(0);
  for (int a = 0; a < 8; ++a) {
    double xi[2];
    kernels::node_parametric_position(ElementType::quad8, a, xi);
    const float h = xi[0] < 1 ? sample_enrichment(ElementType::quad8, e, xi[0], xi[1]) : 1.0f;
    e.node_values.push_back(h);
    e.dofs.insert(e.dofs.end(), {gap / 2, 0.0, 0.0});
    if (h < 0) s.displacement[3 * nodes[a]] = -gap;
  }
  s.enrichments.push_back(e);
  return p;
}

// The straight cut x = cut_texel / T (default: x = 0.5625, inside a tessellation triangle
// column for tessellation 4).
inline CutPlate straight_cut_plate(int resolution = 16, int cut_texel = 9, double gap = 0.2) {
  return cut_plate(resolution, [cut_texel](int) { return cut_texel; }, gap);
}

// A staircase cut running diagonally through element 0.
inline CutPlate staircase_cut_plate(int resolution = 16, double gap = 0.2) {
  return cut_plate(resolution, [resolution](int j) { return resolution / 4 + (j * 5) / 8; }, gap);
}

// A curved tri6 strip (part of a cylinder of radius 1.5 around the y axis, 3 x 2 cells)
// with a partial cut: H = theta / pi around a tip, jumping from -1 to +1 across the cut
// (the ray from the tip towards -x) and continuous elsewhere; every element carries it
// (so element edges stay closed up to texel sampling), and its DOFs lift the cut's two
// sides apart along z.
inline ShellState curved_partial_cut(int resolution = 32) {
  ShellState s;
  s.mesh = rectangle_mesh(ElementType::tri6, 3, 2, 1.8, 1.2);
  const double R = 1.5;
  for (size_t n = 0; n < s.mesh.positions.size(); n += 3) {
    const double x = s.mesh.positions[n] - 0.9;
    s.mesh.positions[n] = R * std::sin(x / R);
    s.mesh.positions[n + 2] = R * std::cos(x / R) - R;
  }
  s.displacement.assign(s.mesh.positions.size(), 0.0);
  // Tip at rest-parameter point (1.05, 0.65) of the flat strip; the cut runs to x = 0.
  const double tip_x = 1.05, tip_y = 0.65;
  auto H = [&](double x, double y) { return static_cast<float>(std::atan2(y - tip_y, x - tip_x) / M_PI); };
  const int nx = 3;
  for (int e = 0; e < s.mesh.num_elements(); ++e) {
    const int cell = e / 2, upper = e % 2;
    const double x0 = 0.6 * (cell % nx), y0 = 0.6 * (cell / nx);
    // Parameter xi of this triangle -> flat rest point (the same affine map as the mesh).
    auto rest_point = [&](double xi1, double xi2, double& x, double& y) {
      if (!upper) {  // corners (0,0), (1,0), (1,1) of the cell
        x = x0 + 0.6 * (xi1 + xi2);
        y = y0 + 0.6 * xi2;
      } else {  // corners (0,0), (1,1), (0,1)
        x = x0 + 0.6 * xi1;
        y = y0 + 0.6 * (xi1 + xi2);
      }
    };
    ElementEnrichment en;
    en.element = e;
    en.resolution = resolution;
    en.values.assign(static_cast<size_t>(resolution) * resolution, 0.0f);
    for (int j = 0; j < resolution; ++j)
      for (int i = 0; i + j < resolution; ++i) {
        double x, y;
        rest_point((i + 0.5) / resolution, (j + 0.5) / resolution, x, y);
        en.values[j * resolution + i] = H(x, y);
      }
    for (int a = 0; a < 6; ++a) {
      double xi[2], x, y;
      kernels::node_parametric_position(ElementType::tri6, a, xi);
      rest_point(xi[0], xi[1], x, y);
      en.node_values.push_back(H(x, y));
      en.dofs.insert(en.dofs.end(), {0.0, 0.0, 0.06});
    }
    s.enrichments.push_back(en);
  }
  return s;
}

inline bool is_background(const Image& image, int x, int y, const float background[3]) {
  const auto* p = image.pixel(x, y);
  for (int c = 0; c < 3; ++c)
    if (p[c] != static_cast<int>(std::lround(background[c] * 255))) return false;
  return true;
}

// Number of 4-connected components of non-background pixels.
inline int count_components(const Image& image, const float background[3]) {
  std::vector<int> label(static_cast<size_t>(image.width) * image.height, -1);
  int components = 0;
  std::vector<std::pair<int, int>> stack;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      if (is_background(image, x, y, background) || label[y * image.width + x] >= 0) continue;
      stack.push_back({x, y});
      label[y * image.width + x] = components;
      while (!stack.empty()) {
        auto [cx, cy] = stack.back();
        stack.pop_back();
        const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
        for (int k = 0; k < 4; ++k) {
          const int nx = cx + dx[k], ny = cy + dy[k];
          if (nx < 0 || ny < 0 || nx >= image.width || ny >= image.height) continue;
          if (label[ny * image.width + nx] >= 0 || is_background(image, nx, ny, background)) continue;
          label[ny * image.width + nx] = components;
          stack.push_back({nx, ny});
        }
      }
      ++components;
    }
  return components;
}

// Looking straight down (-z) at the cut plate from far enough to see all of it.
inline RenderSettings top_view(int width = 256, int height = 256) {
  RenderSettings s;
  s.width = width;
  s.height = height;
  s.camera_position[0] = 0.9;
  s.camera_position[1] = 0.5;
  s.camera_position[2] = 5.0;
  s.camera_target[0] = 0.9;
  s.camera_target[1] = 0.5;
  s.camera_target[2] = 0.0;
  s.camera_up[0] = 0;
  s.camera_up[1] = 1;
  s.camera_up[2] = 0;
  s.fov_deg = 30;
  s.tessellation = 4;
  return s;
}

}  // namespace dgtex::test
