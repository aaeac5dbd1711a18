#include "dgtex/deformed_shell.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "api_argument_checks.h"

namespace dgtex {
namespace {

// xi reaches a cast to int in the texel lookup (NaN is undefined there); points outside the
// reference element are evaluated as the shape functions extrapolate them.
void check_finite_point(const char* function, double xi1, double xi2) {
  const double xi[2] = {xi1, xi2};
  detail::check_finite(function, "xi", xi, 2);
}

}  // namespace

void enrichment_texel(ElementType type, int resolution, double xi1, double xi2, int& i, int& j) {
  if (resolution < 1)
    throw std::invalid_argument("enrichment_texel: resolution " + std::to_string(resolution) + "; expected 1 or more");
  check_finite_point("enrichment_texel", xi1, xi2);
  const int T = resolution;
  const double u = type == ElementType::quad8 ? 0.5 * (xi1 + 1) : xi1;
  const double v = type == ElementType::quad8 ? 0.5 * (xi2 + 1) : xi2;
  i = std::clamp(static_cast<int>(std::floor(u * T)), 0, T - 1);
  j = std::clamp(static_cast<int>(std::floor(v * T)), 0, T - 1);
  if (type == ElementType::tri6 && i + j > T - 1) {
    // Outside the triangle's texels (only on the diagonal or beyond): step back inside.
    const int excess = i + j - (T - 1);
    const int back_i = std::min(i, (excess + 1) / 2);
    i -= back_i;
    j -= excess - back_i;
  }
}

float sample_enrichment(ElementType type, const ElementEnrichment& e, double xi1, double xi2) {
  if (e.resolution < 1 || e.values.size() != static_cast<size_t>(e.resolution) * e.resolution)
    throw std::invalid_argument("sample_enrichment: " + std::to_string(e.values.size()) + " values for resolution " +
                                std::to_string(e.resolution) + "; expected resolution^2, resolution 1 or more");
  int i, j;
  enrichment_texel(type, e.resolution, xi1, xi2, i, j);
  return e.values[static_cast<size_t>(j) * e.resolution + i];
}

DeformedShell::DeformedShell(const ShellState& state) : state_(state) {
  validate_state(state);
  by_element_.assign(state.mesh.num_elements(), {});
  for (int k = 0; k < static_cast<int>(state.enrichments.size()); ++k)
    by_element_[state.enrichments[k].element].push_back(k);
  for (const auto& list : by_element_) max_per_element_ = std::max(max_per_element_, static_cast<int>(list.size()));
}

const std::vector<int>& DeformedShell::enrichments_of(int element) const {
  detail::check_index("DeformedShell::enrichments_of", "element", element, "elements", state_.mesh.num_elements());
  return by_element_[element];
}

void DeformedShell::decompose(int element, double xi1, double xi2, double base[3],
                              std::vector<std::array<double, 3>>& A) const {
  const Mesh& m = state_.mesh;
  detail::check_index("DeformedShell::decompose", "element", element, "elements", m.num_elements());
  check_finite_point("DeformedShell::decompose", xi1, xi2);
  const int npe = m.nodes_per_element();
  kernels::ShapeValues sv;
  kernels::evaluate_shape(m.type, xi1, xi2, sv);
  const int* nodes = m.element_nodes(element);
  base[0] = base[1] = base[2] = 0;
  for (int a = 0; a < npe; ++a)
    for (int d = 0; d < 3; ++d) {
      const double u = state_.displacement.empty() ? 0.0 : state_.displacement[3 * nodes[a] + d];
      base[d] += sv.N[a] * (m.positions[3 * nodes[a] + d] + u);
    }
  const auto& list = by_element_[element];
  A.assign(list.size(), {0, 0, 0});
  for (size_t k = 0; k < list.size(); ++k) {
    const ElementEnrichment& e = state_.enrichments[list[k]];
    for (int a = 0; a < npe; ++a)
      for (int d = 0; d < 3; ++d) {
        const double q = sv.N[a] * e.dofs[3 * a + d];
        A[k][d] += q;
        base[d] -= e.node_values[a] * q;
      }
  }
}

void DeformedShell::position(int element, double xi1, double xi2, const double* h, double x[3]) const {
  std::vector<std::array<double, 3>> A;
  decompose(element, xi1, xi2, x, A);
  for (size_t k = 0; k < A.size(); ++k)
    for (int d = 0; d < 3; ++d) x[d] += h[k] * A[k][d];
}

void DeformedShell::position(int element, double xi1, double xi2, double x[3]) const {
  const auto& list = enrichments_of(element);
  std::vector<double> h(list.size());
  for (size_t k = 0; k < list.size(); ++k)
    h[k] = sample_enrichment(state_.mesh.type, state_.enrichments[list[k]], xi1, xi2);
  position(element, xi1, xi2, h.data(), x);
}

std::vector<double> DeformedShell::averaged_node_normals() const {
  const Mesh& m = state_.mesh;
  const int npe = m.nodes_per_element();
  std::vector<double> normals(m.positions.size(), 0.0);
  kernels::ShapeValues sv;
  for (int e = 0; e < m.num_elements(); ++e) {
    const int* nodes = m.element_nodes(e);
    const auto& list = by_element_[e];
    for (int a = 0; a < npe; ++a) {
      double xi[2];
      kernels::node_parametric_position(m.type, a, xi);
      kernels::evaluate_shape(m.type, xi[0], xi[1], sv);
      double t[2][3] = {{0, 0, 0}, {0, 0, 0}};
      for (int b = 0; b < npe; ++b)
        for (int d = 0; d < 3; ++d) {
          double p = m.positions[3 * nodes[b] + d] + (state_.displacement.empty() ? 0.0 : state_.displacement[3 * nodes[b] + d]);
          for (int k : list) {
            const ElementEnrichment& en = state_.enrichments[k];
            p += (en.node_values[a] - en.node_values[b]) * en.dofs[3 * b + d];
          }
          t[0][d] += sv.dN[b][0] * p;
          t[1][d] += sv.dN[b][1] * p;
        }
      // Unnormalised cross product: weights each element by its area element at the node.
      double* n = &normals[3 * nodes[a]];
      n[0] += t[0][1] * t[1][2] - t[0][2] * t[1][1];
      n[1] += t[0][2] * t[1][0] - t[0][0] * t[1][2];
      n[2] += t[0][0] * t[1][1] - t[0][1] * t[1][0];
    }
  }
  for (size_t i = 0; i < normals.size(); i += 3) {
    const double length = std::sqrt(normals[i] * normals[i] + normals[i + 1] * normals[i + 1] + normals[i + 2] * normals[i + 2]);
    for (int d = 0; d < 3; ++d) normals[i + d] = length > 0 ? normals[i + d] / length : 0.0;
  }
  return normals;
}

void DeformedShell::bounding_box(double lo[3], double hi[3]) const {
  const Mesh& m = state_.mesh;
  for (int d = 0; d < 3; ++d) {
    lo[d] = std::numeric_limits<double>::infinity();
    hi[d] = -std::numeric_limits<double>::infinity();
  }
  auto include = [&](const double* p) {
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], p[d]);
      hi[d] = std::max(hi[d], p[d]);
    }
  };
  for (int n = 0; n < m.num_nodes(); ++n) {
    double p[3];
    for (int d = 0; d < 3; ++d) p[d] = m.positions[3 * n + d] + (state_.displacement.empty() ? 0.0 : state_.displacement[3 * n + d]);
    include(p);
  }
  const int samples = 9;
  for (int e = 0; e < m.num_elements(); ++e) {
    if (by_element_[e].empty()) continue;
    for (int j = 0; j < samples; ++j)
      for (int i = 0; i < samples; ++i) {
        double xi1 = double(i) / (samples - 1), xi2 = double(j) / (samples - 1);
        if (m.type == ElementType::quad8) {
          xi1 = 2 * xi1 - 1;
          xi2 = 2 * xi2 - 1;
        } else if (i + j > samples - 1) {
          continue;
        }
        double p[3];
        position(e, xi1, xi2, p);
        include(p);
      }
  }
  if (m.num_nodes() == 0)
    for (int d = 0; d < 3; ++d) lo[d] = hi[d] = 0;
}

}  // namespace dgtex
