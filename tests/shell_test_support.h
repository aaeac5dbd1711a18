#pragma once
// Small builders shared by the shell mechanics tests.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "dgtex/block_assembly.h"
#include "dgtex/dependent_node.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/shell_model.h"
#include "dgtex/topology.h"

namespace dgtex::testing_support {

// Largest |v_i|, and largest |a_i - b_i| (a and b of one size).
inline double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}
inline double max_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

// A block matrix of the pattern (9 doubles a block) written out densely, 3 rows and
// columns a node.
inline Eigen::MatrixXd dense_from_blocks(const BlockAssembly& pattern, const std::vector<double>& blocks) {
  const int n = 3 * pattern.num_nodes();
  Eigen::MatrixXd matrix = Eigen::MatrixXd::Zero(n, n);
  for (int r = 0; r < pattern.num_nodes(); ++r)
    for (std::int64_t k = pattern.row_start()[r]; k < pattern.row_start()[r + 1]; ++k)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) matrix(3 * r + i, 3 * pattern.column()[k] + j) = blocks[9 * k + 3 * i + j];
  return matrix;
}

// T of x = T x_free, written out densely (#dofs x #unknowns): a DOF that is neither fixed
// nor of a dependent node is an unknown (numbered in DOF order); a dependent node's DOF that
// is not fixed follows its sources' unknown DOFs with their coefficients (dependent_node.h).
inline Eigen::MatrixXd dense_elimination_matrix(const std::vector<char>& fixed,
                                                const std::vector<DependentNode>& dependents) {
  const int n = static_cast<int>(fixed.size());
  std::vector<char> dependent(n, 0);
  for (const DependentNode& d : dependents) dependent[3 * d.node] = dependent[3 * d.node + 1] = dependent[3 * d.node + 2] = 1;
  std::vector<int> unknown(n, -1);
  int count = 0;
  for (int d = 0; d < n; ++d)
    if (!fixed[d] && !dependent[d]) unknown[d] = count++;
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(n, count);
  for (int d = 0; d < n; ++d)
    if (unknown[d] >= 0) T(d, unknown[d]) = 1;
  for (const DependentNode& d : dependents)
    for (int c = 0; c < 3; ++c)
      if (!fixed[3 * d.node + c])
        for (const auto& [source, coefficient] : d.sources)
          if (unknown[3 * source + c] >= 0) T(3 * d.node + c, unknown[3 * source + c]) = coefficient;
  return T;
}

using NodePredicate = std::function<bool(const double* x)>;

struct Material {
  double E = 1e6, nu = 0.3, h = 0.01, rho = 1000;
};

inline std::unique_ptr<ShellModel> make_model(const Mesh& mesh, const Material& m, double penalty,
                                               const NodePredicate& clamp = nullptr) {
  const Topology topology = build_topology(mesh);
  std::vector<kernels::ShellSection> sections(mesh.num_elements(), {m.E, m.nu, m.h, m.rho});
  std::vector<int> clamped;
  if (clamp)
    for (size_t k = 0; k < topology.boundary_edges.size(); ++k) {
      const MeshEdge& e = topology.boundary_edges[k];
      if (clamp(mesh.node(e.nodes[0])) && clamp(mesh.node(e.nodes[1])) && clamp(mesh.node(e.nodes[2])))
        clamped.push_back(static_cast<int>(k));
    }
  ShellModelOptions options;
  options.penalty = penalty;
  return std::make_unique<ShellModel>(mesh, topology, sections, clamped, options);
}

// A model of the default material (penalty 1) with these enrichment functions; enriched
// nodes below min_mass_ratio (ShellModelOptions::min_enrichment_mass_ratio) are dropped.
inline std::unique_ptr<ShellModel> enriched_model(const Mesh& mesh, std::vector<EnrichmentFunction> functions,
                                                  double min_mass_ratio) {
  const Topology topology = build_topology(mesh);
  const Material m;
  std::vector<kernels::ShellSection> sections(mesh.num_elements(), {m.E, m.nu, m.h, m.rho});
  ShellModelOptions options;
  options.penalty = 1.0;
  options.min_enrichment_mass_ratio = min_mass_ratio;
  auto model = std::make_unique<ShellModel>(mesh, topology, sections, std::vector<int>{}, options);
  model->set_enrichments(std::move(functions));
  return model;
}

// Fixed-DOF flags: components (x, y, z) held on nodes matching the predicate.
inline void fix_nodes(const Mesh& mesh, const NodePredicate& where, bool x, bool y, bool z, std::vector<char>& fixed) {
  if (fixed.empty()) fixed.assign(3 * mesh.num_nodes(), 0);
  const bool comp[3] = {x, y, z};
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (where(mesh.node(n)))
      for (int c = 0; c < 3; ++c)
        if (comp[c]) fixed[3 * n + c] = 1;
}

// count values uniformly in [-1, 1], reproducible from the seed.
inline std::vector<double> random_values(std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<double> values(count);
  for (double& v : values) v = uniform(rng);
  return values;
}

// count proper rotations (3x3, row-major), uniformly random (normalised Gaussian quaternions),
// reproducible from the seed: the kernels take any R per point.
inline std::vector<double> random_rotations(std::int64_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<double> R(static_cast<std::size_t>(count) * 9);
  for (std::int64_t i = 0; i < count; ++i) {
    double q[4], n2 = 0;
    for (double& c : q) c = normal(rng), n2 += c * c;
    for (double& c : q) c /= std::sqrt(n2);
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                         2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    std::copy(m, m + 9, R.begin() + 9 * i);
  }
  return R;
}

// A rotation of up to max_angle rad about a random axis per point (row-major 3x3 each).
inline std::vector<double> small_random_rotations(std::int64_t count, double max_angle, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> R(static_cast<std::size_t>(count) * 9);
  for (std::int64_t q = 0; q < count; ++q) {
    double w[3] = {u(rng), u(rng), u(rng)};
    const double norm = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    const double angle = max_angle * std::abs(u(rng));
    for (double& x : w) x /= norm;
    const double c = std::cos(angle), s = std::sin(angle);
    double* r = &R[9 * q];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r[i * 3 + j] = (i == j ? c : 0) + (1 - c) * w[i] * w[j];
    r[1] -= s * w[2], r[2] += s * w[1], r[3] += s * w[2], r[5] -= s * w[0], r[6] -= s * w[1], r[7] += s * w[0];
  }
  return R;
}

}  // namespace dgtex::testing_support
