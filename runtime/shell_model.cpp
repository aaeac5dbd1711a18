#include "dgtex/shell_model.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/polar_decomposition.h"
#include "dgtex/mesh_validation.h"

namespace dgtex {

using kernels::Execution;

ShellModel::ShellModel(Mesh mesh, const Topology& topology, std::vector<kernels::ShellSection> sections,
                       const std::vector<int>& clamped_edges, ShellModelOptions options)
    : mesh_(std::move(mesh)), sections_(std::move(sections)), options_(options) {
  const int ne = mesh_.num_elements();
  const int npe = mesh_.nodes_per_element();
  if (static_cast<int>(sections_.size()) != ne)
    throw std::invalid_argument("ShellModel: " + std::to_string(sections_.size()) + " sections for " +
                                std::to_string(ne) + " elements");
  // h^e = min over adjacent elements of area / perimeter (report eq. 16).
  std::vector<double> size_of_element(ne);
  for (int e = 0; e < ne; ++e) size_of_element[e] = element_area(mesh_, e) / element_perimeter(mesh_, e);
  for (const MeshEdge& edge : topology.interior_edges) {
    edges_.insert(edges_.end(), {edge.plus_element, edge.plus_local_edge, edge.minus_element, edge.minus_local_edge});
    edge_size_.push_back(std::min(size_of_element[edge.plus_element], size_of_element[edge.minus_element]));
  }
  num_interior_edges_ = static_cast<int>(topology.interior_edges.size());
  for (int index : clamped_edges) {
    const MeshEdge& edge = topology.boundary_edges.at(index);
    edges_.insert(edges_.end(), {edge.plus_element, edge.plus_local_edge, -1, -1});
    edge_size_.push_back(size_of_element[edge.plus_element]);
  }

  BlockSourceFamily elements{ne, npe, mesh_.elements};
  BlockSourceFamily edges{num_edges(), 2 * npe, std::vector<int>(static_cast<size_t>(num_edges()) * 2 * npe, -1)};
  for (int k = 0; k < num_edges(); ++k)
    for (int side = 0; side < 2; ++side) {
      const int element = edges_[4 * k + 2 * side];
      if (element < 0) continue;
      std::copy_n(mesh_.element_nodes(element), npe, edges.global_nodes.begin() + (static_cast<size_t>(k) * 2 + side) * npe);
    }
  assembly_ = BlockAssembly(mesh_.num_nodes(), {elements, edges});

  // Mass and load weights depend on the rest geometry only.
  std::vector<double> element_mass(static_cast<size_t>(ne) * npe * npe);
  kernels::shell_element_mass(element_batch(), element_mass.data());
  std::vector<double> mass_local(static_cast<size_t>(ne) * npe * npe * 9, 0.0);
  for (size_t i = 0; i < element_mass.size(); ++i)
    for (int d = 0; d < 3; ++d) mass_local[i * 9 + d * 4] = element_mass[i];
  mass_blocks_.resize(assembly_.num_blocks() * 9);
  assembly_.assemble_matrix({mass_local.data(), nullptr}, mass_blocks_.data());
  area_weights_.resize(static_cast<size_t>(ne) * npe);
  mass_weights_.resize(static_cast<size_t>(ne) * npe);
  kernels::shell_element_load_weights(element_batch(), area_weights_.data(), mass_weights_.data());
}

kernels::ElementBatch ShellModel::element_batch() const {
  return {mesh_.type, mesh_.num_elements(), mesh_.elements.data(), mesh_.positions.data(), sections_.data()};
}

kernels::EdgeBatch ShellModel::edge_batch() const {
  return {mesh_.type,        num_edges(),          edges_.data(),           edge_size_.data(),
          options_.penalty,  options_.edge_quadrature_points, mesh_.elements.data(), mesh_.positions.data(),
          sections_.data()};
}

std::int64_t ShellModel::num_quadrature_points() const {
  return static_cast<std::int64_t>(mesh_.num_elements()) * kernels::element_quadrature(mesh_.type).count +
         static_cast<std::int64_t>(num_edges()) * options_.edge_quadrature_points;
}

void ShellModel::assemble_stiffness(const double* current, std::vector<double>& blocks, std::vector<double>* corrective,
                                    Execution execution) const {
  const int ne = mesh_.num_elements();
  const int npe = mesh_.nodes_per_element();
  const int nq = kernels::element_quadrature(mesh_.type).count;
  const kernels::ElementBatch eb = element_batch();
  const kernels::EdgeBatch gb = edge_batch();
  std::vector<double> element_rotations, edge_rotations;
  if (current) {
    std::vector<double> gradients(static_cast<size_t>(ne) * nq * 9);
    element_rotations.resize(gradients.size());
    kernels::shell_element_deformation_gradients(eb, current, gradients.data(), execution);
    kernels::polar_decomposition_batch(static_cast<std::int64_t>(ne) * nq, gradients.data(), element_rotations.data(), execution);
    edge_rotations.resize(static_cast<size_t>(num_edges()) * gb.quadrature_points * 9);
    kernels::shell_edge_rotations(gb, current, edge_rotations.data(), execution);
  }
  std::vector<double> element_blocks(static_cast<size_t>(ne) * npe * npe * 9);
  std::vector<double> edge_blocks(static_cast<size_t>(num_edges()) * 4 * npe * npe * 9);
  std::vector<double> element_forces, edge_forces;
  if (current && corrective) {
    element_forces.resize(static_cast<size_t>(ne) * npe * 3);
    edge_forces.resize(static_cast<size_t>(num_edges()) * 2 * npe * 3);
  }
  kernels::shell_element_stiffness(eb, current ? element_rotations.data() : nullptr, element_blocks.data(),
                                   element_forces.empty() ? nullptr : element_forces.data(), execution);
  kernels::shell_edge_stiffness(gb, current ? edge_rotations.data() : nullptr, edge_blocks.data(),
                                edge_forces.empty() ? nullptr : edge_forces.data(), execution);
  blocks.resize(assembly_.num_blocks() * 9);
  const bool parallel = execution == Execution::parallel;
  assembly_.assemble_matrix({element_blocks.data(), edge_blocks.data()}, blocks.data(), parallel);
  if (corrective) {
    corrective->assign(num_dofs(), 0.0);
    if (current) assembly_.assemble_vector({element_forces.data(), edge_forces.data()}, corrective->data(), parallel);
  }
}

void ShellModel::add_gravity(const double g[3], std::vector<double>& f) const {
  const int npe = mesh_.nodes_per_element();
  for (int e = 0; e < mesh_.num_elements(); ++e)
    for (int a = 0; a < npe; ++a)
      for (int c = 0; c < 3; ++c) f[3 * mesh_.element_nodes(e)[a] + c] += mass_weights_[e * npe + a] * g[c];
}

void ShellModel::add_area_force(const double q[3], std::vector<double>& f) const {
  const int npe = mesh_.nodes_per_element();
  for (int e = 0; e < mesh_.num_elements(); ++e)
    for (int a = 0; a < npe; ++a)
      for (int c = 0; c < 3; ++c) f[3 * mesh_.element_nodes(e)[a] + c] += area_weights_[e * npe + a] * q[c];
}

void ShellModel::add_point_force(int element, const double xi[2], const double force[3], std::vector<double>& f) const {
  kernels::ShapeValues s;
  kernels::evaluate_shape(mesh_.type, xi[0], xi[1], s);
  for (int a = 0; a < s.count; ++a)
    for (int c = 0; c < 3; ++c) f[3 * mesh_.element_nodes(element)[a] + c] += s.N[a] * force[c];
}

void ShellModel::interpolate(const std::vector<double>& u, int element, const double xi[2], double out[3]) const {
  kernels::ShapeValues s;
  kernels::evaluate_shape(mesh_.type, xi[0], xi[1], s);
  out[0] = out[1] = out[2] = 0;
  for (int a = 0; a < s.count; ++a)
    for (int c = 0; c < 3; ++c) out[c] += s.N[a] * u[3 * mesh_.element_nodes(element)[a] + c];
}

void block_multiply(const BlockAssembly& pattern, const double* blocks, const double* x, double* y) {
  const auto& start = pattern.row_start();
  const auto& col = pattern.column();
  kernels::forall(pattern.num_nodes(), [&](std::int64_t r) {
    double sum[3] = {0, 0, 0};
    for (std::int64_t k = start[r]; k < start[r + 1]; ++k) {
      const double* b = blocks + k * 9;
      const double* xv = x + 3 * static_cast<std::int64_t>(col[k]);
      for (int i = 0; i < 3; ++i) sum[i] += b[i * 3] * xv[0] + b[i * 3 + 1] * xv[1] + b[i * 3 + 2] * xv[2];
    }
    for (int i = 0; i < 3; ++i) y[3 * r + i] = sum[i];
  });
}

}  // namespace dgtex
