#pragma once
// The discretised DG Kirchhoff-Love shell: geometry, sections, edges and the assembly of
// stiffness (linear or corotated per quadrature point), mass and loads into 3x3 node
// blocks. Owns its mesh copy and all precomputed patterns; not thread-safe for concurrent
// calls on one instance (each call uses all OpenMP threads itself).
//
// DOFs: 3 per node (x, y, z displacement), DOF 3*n + c. Units: those of the scene.
#include <vector>

#include "dgtex/block_assembly.h"
#include "dgtex/kernels/shell_edge_kernel.h"
#include "dgtex/kernels/shell_element_kernel.h"
#include "dgtex/mesh.h"
#include "dgtex/topology.h"

namespace dgtex {

struct ShellModelOptions {
  double penalty = 10;             // eta of the interior-penalty terms (report eq. 15)
  int edge_quadrature_points = 3;  // Gauss points per edge
};

class ShellModel {
 public:
  // clamped_edges: indices into topology.boundary_edges whose normal is held (clamp).
  ShellModel(Mesh mesh, const Topology& topology, std::vector<kernels::ShellSection> sections,
             const std::vector<int>& clamped_edges, ShellModelOptions options);

  const Mesh& mesh() const { return mesh_; }
  int num_nodes() const { return mesh_.num_nodes(); }
  int num_dofs() const { return 3 * mesh_.num_nodes(); }
  int num_edges() const { return static_cast<int>(edges_.size() / 4); }
  int num_interior_edges() const { return num_interior_edges_; }
  int num_clamped_edges() const { return num_edges() - num_interior_edges_; }
  std::int64_t num_quadrature_points() const;  // element + edge points
  const BlockAssembly& pattern() const { return assembly_; }
  const ShellModelOptions& options() const { return options_; }
  const std::vector<kernels::ShellSection>& sections() const { return sections_; }

  // Global stiffness blocks (pattern().num_blocks() x 9). With current node positions
  // (#nodes x 3), the model is corotated per quadrature point and `corrective` (#dofs)
  // receives the right-hand-side term of report eq. 48; without, it is the linear model.
  void assemble_stiffness(const double* current_positions, std::vector<double>& blocks,
                          std::vector<double>* corrective, kernels::Execution execution = kernels::Execution::parallel) const;

  // Consistent mass blocks (same pattern), assembled at construction.
  const std::vector<double>& mass_blocks() const { return mass_blocks_; }

  // Load vectors (#dofs): body force per unit mass (gravity), force per unit area, and a
  // point force at a parametric point of an element (distributed by the basis functions).
  void add_gravity(const double acceleration[3], std::vector<double>& f) const;
  void add_area_force(const double force_per_area[3], std::vector<double>& f) const;
  void add_point_force(int element, const double xi[2], const double force[3], std::vector<double>& f) const;

  // Displacement at a parametric point of an element.
  void interpolate(const std::vector<double>& u, int element, const double xi[2], double out[3]) const;

 private:
  Mesh mesh_;
  std::vector<kernels::ShellSection> sections_;
  ShellModelOptions options_;
  std::vector<int> edges_;          // #edges x 4 (interior first, then clamped)
  std::vector<double> edge_size_;   // h^e
  int num_interior_edges_ = 0;
  BlockAssembly assembly_;
  std::vector<double> mass_blocks_;
  std::vector<double> area_weights_, mass_weights_;  // #elements x npe

  kernels::ElementBatch element_batch() const;
  kernels::EdgeBatch edge_batch() const;
};

// y = A x for block matrices in the pattern (deterministic, parallel over rows).
void block_multiply(const BlockAssembly& pattern, const double* blocks, const double* x, double* y);

}  // namespace dgtex
