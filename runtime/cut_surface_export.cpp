#include "dgtex/cut_surface_export.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

#include "dgtex/deformed_shell.h"
#include "dgtex/kernels/flood_fill.h"

namespace dgtex {
namespace {

struct Builder {
  const DeformedShell& shell;
  CutSurfaceMesh mesh;
  std::vector<int> vertex_element;  // element of each vertex
  std::vector<char> on_boundary;    // whether the vertex lies on its element's boundary
  std::vector<double> rest;         // rest position of each vertex (#vertices x 3)

  int add_vertex(int element, double xi1, double xi2, const double* h, bool boundary) {
    double x[3];
    shell.position(element, xi1, xi2, h, x);
    mesh.vertices.insert(mesh.vertices.end(), {x[0], x[1], x[2]});
    const ShellState& state = shell.state();
    kernels::ShapeValues sv;
    kernels::evaluate_shape(state.mesh.type, xi1, xi2, sv);
    const int* nodes = state.mesh.element_nodes(element);
    double r[3] = {0, 0, 0};
    for (int a = 0; a < state.mesh.nodes_per_element(); ++a)
      for (int d = 0; d < 3; ++d) r[d] += sv.N[a] * state.mesh.positions[3 * nodes[a] + d];
    rest.insert(rest.end(), {r[0], r[1], r[2]});
    vertex_element.push_back(element);
    on_boundary.push_back(boundary);
    return mesh.num_vertices() - 1;
  }
  void add_face(int element, std::initializer_list<int> v) {
    mesh.face_sizes.push_back(static_cast<int>(v.size()));
    mesh.face_vertices.insert(mesh.face_vertices.end(), v);
    mesh.face_elements.push_back(element);
  }
};

// Parameter point of grid point (ci, cj) of an n x n grid over the element's domain.
void grid_xi(ElementType type, int n, int ci, int cj, double& xi1, double& xi2) {
  if (type == ElementType::quad8) {
    xi1 = -1.0 + 2.0 * ci / n;
    xi2 = -1.0 + 2.0 * cj / n;
  } else {
    xi1 = double(ci) / n;
    xi2 = double(cj) / n;
  }
}

bool grid_boundary(ElementType type, int n, int ci, int cj) {
  if (ci == 0 || cj == 0) return true;
  return type == ElementType::quad8 ? (ci == n || cj == n) : ci + cj == n;
}

void tessellate_plain(Builder& b, int e, int n) {
  const ElementType type = b.shell.state().mesh.type;
  const bool quad = type == ElementType::quad8;
  std::vector<int> id((n + 1) * (n + 1), -1);
  for (int cj = 0; cj <= n; ++cj)
    for (int ci = 0; ci <= n; ++ci) {
      if (!quad && ci + cj > n) continue;
      double xi1, xi2;
      grid_xi(type, n, ci, cj, xi1, xi2);
      id[cj * (n + 1) + ci] = b.add_vertex(e, xi1, xi2, nullptr, grid_boundary(type, n, ci, cj));
    }
  auto v = [&](int ci, int cj) { return id[cj * (n + 1) + ci]; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (quad) {
        b.add_face(e, {v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)});
      } else if (i + j < n) {
        b.add_face(e, {v(i, j), v(i + 1, j), v(i, j + 1)});
        if (i + j < n - 1) b.add_face(e, {v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)});
      }
    }
}

void texelate_enriched(Builder& b, int e, float cut_threshold) {
  const ShellState& state = b.shell.state();
  const ElementType type = state.mesh.type;
  const bool quad = type == ElementType::quad8;
  const auto& list = b.shell.enrichments_of(e);
  const int K = static_cast<int>(list.size());
  int T = 1;
  for (int k : list) T = std::max(T, state.enrichments[k].resolution);
  auto valid = [&](int i, int j) { return i >= 0 && j >= 0 && i < T && j < T && (quad || i + j <= T - 1); };
  // Enrichment values on the T x T grid (coarser textures resampled by nearest texel).
  std::vector<float> h(static_cast<size_t>(T) * T * K, 0.0f);
  for (int j = 0; j < T; ++j)
    for (int i = 0; i < T; ++i) {
      if (!valid(i, j)) continue;
      double xi1, xi2;
      grid_xi(type, T, i, j, xi1, xi2);
      const double half = (quad ? 1.0 : 0.5) / T;
      for (int k = 0; k < K; ++k)
        h[(static_cast<size_t>(j) * T + i) * K + k] =
            sample_enrichment(type, state.enrichments[list[k]], xi1 + half, xi2 + half);
    }
  auto value = [&](int i, int j, int k) { return h[(static_cast<size_t>(j) * T + i) * K + k]; };
  auto separated = [&](int i1, int j1, int i2, int j2) {
    for (int k = 0; k < K; ++k) {
      const float a = value(i1, j1, k), c = value(i2, j2, k);
      if (std::abs(a - c) > cut_threshold && (a >= 0) != (c >= 0)) return true;
    }
    return false;
  };
  // corner_vertex[(cj * (T+1) + ci) * 4 + s]: the vertex of corner (ci, cj) used by its
  // incident texel s (0: (ci-1,cj-1), 1: (ci,cj-1), 2: (ci-1,cj), 3: (ci,cj)).
  std::vector<int> corner_vertex(static_cast<size_t>(T + 1) * (T + 1) * 4, -1);
  std::vector<double> mean(K);
  for (int cj = 0; cj <= T; ++cj)
    for (int ci = 0; ci <= T; ++ci) {
      if (!quad && ci + cj > T) continue;
      const int ti[4] = {ci - 1, ci, ci - 1, ci}, tj[4] = {cj - 1, cj - 1, cj, cj};
      bool present[4];
      std::vector<int> parent = {0, 1, 2, 3};
      for (int s = 0; s < 4; ++s) present[s] = valid(ti[s], tj[s]);
      for (auto [s, t] : {std::pair{0, 1}, std::pair{2, 3}, std::pair{0, 2}, std::pair{1, 3}})
        if (present[s] && present[t] && !separated(ti[s], tj[s], ti[t], tj[t]))
          parent[kernels::find_root_halving(parent, s)] = kernels::find_root_halving(parent, t);
      double xi1, xi2;
      grid_xi(type, T, ci, cj, xi1, xi2);
      const bool boundary = grid_boundary(type, T, ci, cj);
      for (int s = 0; s < 4; ++s) {
        if (!present[s] || kernels::find_root_halving(parent, s) != s) continue;
        std::fill(mean.begin(), mean.end(), 0.0);
        int members = 0;
        for (int t = 0; t < 4; ++t)
          if (present[t] && kernels::find_root_halving(parent, t) == s) {
            for (int k = 0; k < K; ++k) mean[k] += value(ti[t], tj[t], k);
            ++members;
          }
        for (double& m : mean) m /= members;
        const int vertex = b.add_vertex(e, xi1, xi2, mean.data(), boundary);
        for (int t = 0; t < 4; ++t)
          if (present[t] && kernels::find_root_halving(parent, t) == s) corner_vertex[(static_cast<size_t>(cj) * (T + 1) + ci) * 4 + t] = vertex;
      }
    }
  auto v = [&](int ci, int cj, int s) { return corner_vertex[(static_cast<size_t>(cj) * (T + 1) + ci) * 4 + s]; };
  for (int j = 0; j < T; ++j)
    for (int i = 0; i < T; ++i) {
      if (!valid(i, j)) continue;
      if (quad || i + j < T - 1)
        b.add_face(e, {v(i, j, 3), v(i + 1, j, 2), v(i + 1, j + 1, 0), v(i, j + 1, 1)});
      else
        b.add_face(e, {v(i, j, 3), v(i + 1, j, 2), v(i, j + 1, 1)});
    }
}

// Welds element-boundary vertices of different elements at the same rest position (see
// the header).
void weld(Builder& b) {
  CutSurfaceMesh& m = b.mesh;
  const int n = m.num_vertices();
  if (n == 0) return;
  const std::vector<double>& p = b.rest;
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (int v = 0; v < n; ++v)
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], p[3 * v + d]);
      hi[d] = std::max(hi[d], p[3 * v + d]);
    }
  const double size = std::max(std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                         (hi[2] - lo[2]) * (hi[2] - lo[2])),
                               1e-300);
  const double tolerance = 1e-9 * size, cell = 1e-7 * size;
  struct KeyHash {
    size_t operator()(const std::array<long long, 3>& k) const {
      return std::hash<long long>()(k[0] * 73856093LL ^ k[1] * 19349663LL ^ k[2] * 83492791LL);
    }
  };
  std::unordered_map<std::array<long long, 3>, std::vector<int>, KeyHash> grid;
  auto key_of = [&](int v) {
    std::array<long long, 3> k;
    for (int d = 0; d < 3; ++d) k[d] = static_cast<long long>(std::floor((p[3 * v + d] - lo[d]) / cell));
    return k;
  };
  for (int v = 0; v < n; ++v)
    if (b.on_boundary[v]) grid[key_of(v)].push_back(v);
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  for (int v = 0; v < n; ++v) {
    if (!b.on_boundary[v]) continue;
    const auto k = key_of(v);
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          auto it = grid.find({k[0] + dx, k[1] + dy, k[2] + dz});
          if (it == grid.end()) continue;
          for (int w : it->second) {
            if (w <= v || b.vertex_element[w] == b.vertex_element[v]) continue;
            double d2 = 0;
            for (int d = 0; d < 3; ++d) d2 += std::pow(p[3 * v + d] - p[3 * w + d], 2);
            if (d2 <= tolerance * tolerance) parent[kernels::find_root_halving(parent, w)] = kernels::find_root_halving(parent, v);
          }
        }
  }
  // A cluster is welded only if each element meets it at most once.
  std::unordered_map<int, std::vector<int>> clusters;
  for (int v = 0; v < n; ++v)
    if (b.on_boundary[v]) clusters[kernels::find_root_halving(parent, v)].push_back(v);
  std::vector<int> target(n);
  std::iota(target.begin(), target.end(), 0);
  for (auto& [root, members] : clusters) {
    if (members.size() < 2) continue;
    std::vector<int> elements;
    for (int v : members) elements.push_back(b.vertex_element[v]);
    std::sort(elements.begin(), elements.end());
    if (std::adjacent_find(elements.begin(), elements.end()) != elements.end()) continue;
    // The welded vertex sits at the mean of the deformed positions: this closes the
    // small cracks that per-element texel sampling of H leaves between elements.
    const int keep = *std::min_element(members.begin(), members.end());
    double mean[3] = {0, 0, 0};
    for (int v : members)
      for (int d = 0; d < 3; ++d) mean[d] += m.vertices[3 * v + d] / members.size();
    for (int d = 0; d < 3; ++d) m.vertices[3 * keep + d] = mean[d];
    for (int v : members) target[v] = keep;
  }
  // Compact: drop welded-away vertices, renumber faces.
  std::vector<int> new_index(n, -1);
  std::vector<double> vertices;
  for (int v = 0; v < n; ++v)
    if (target[v] == v) {
      new_index[v] = static_cast<int>(vertices.size() / 3);
      vertices.insert(vertices.end(), m.vertices.begin() + 3 * v, m.vertices.begin() + 3 * v + 3);
    }
  for (int& f : m.face_vertices) f = new_index[target[f]];
  m.vertices = std::move(vertices);
}

}  // namespace

CutSurfaceMesh build_cut_surface(const ShellState& state, int tessellation, float cut_threshold) {
  if (tessellation < 1 || tessellation > 1024)
    throw std::invalid_argument("cut surface tessellation = " + std::to_string(tessellation) + " (valid: 1..1024)");
  if (!(cut_threshold >= 0))
    throw std::invalid_argument("cut surface cut_threshold = " + std::to_string(cut_threshold) + " (valid: >= 0)");
  const DeformedShell shell(state);
  Builder b{shell, {}, {}, {}, {}};
  for (int e = 0; e < state.mesh.num_elements(); ++e) {
    if (shell.enrichments_of(e).empty())
      tessellate_plain(b, e, tessellation);
    else
      texelate_enriched(b, e, cut_threshold);
  }
  weld(b);
  return std::move(b.mesh);
}

void write_obj(const std::string& path, const CutSurfaceMesh& mesh) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error("cannot open '" + path + "' for writing the cut surface");
  std::fprintf(f, "# dgtex cut surface: %d vertices, %d faces\n", mesh.num_vertices(), mesh.num_faces());
  for (int v = 0; v < mesh.num_vertices(); ++v)
    std::fprintf(f, "v %.9g %.9g %.9g\n", mesh.vertices[3 * v], mesh.vertices[3 * v + 1], mesh.vertices[3 * v + 2]);
  size_t offset = 0;
  int group = -1;
  for (int i = 0; i < mesh.num_faces(); ++i) {
    if (mesh.face_elements[i] != group) {
      group = mesh.face_elements[i];
      std::fprintf(f, "g element_%d\n", group);
    }
    std::fputc('f', f);
    for (int k = 0; k < mesh.face_sizes[i]; ++k) std::fprintf(f, " %d", mesh.face_vertices[offset + k] + 1);
    std::fputc('\n', f);
    offset += mesh.face_sizes[i];
  }
  const bool failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || failed) throw std::runtime_error("writing the cut surface '" + path + "' failed");
}

void export_cut_surface_obj(const std::string& path, const ShellState& state, int tessellation, float cut_threshold) {
  write_obj(path, build_cut_surface(state, tessellation, cut_threshold));
}

}  // namespace dgtex
