#pragma once
// Small builders shared by the shell mechanics tests.
#include <functional>
#include <memory>
#include <vector>

#include "dgtex/mesh_generators.h"
#include "dgtex/shell_model.h"
#include "dgtex/topology.h"

namespace dgtex::testing_support {

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

// Fixed-DOF flags: components (x, y, z) held on nodes matching the predicate.
inline void fix_nodes(const Mesh& mesh, const NodePredicate& where, bool x, bool y, bool z, std::vector<char>& fixed) {
  if (fixed.empty()) fixed.assign(3 * mesh.num_nodes(), 0);
  const bool comp[3] = {x, y, z};
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (where(mesh.node(n)))
      for (int c = 0; c < 3; ++c)
        if (comp[c]) fixed[3 * n + c] = 1;
}

}  // namespace dgtex::testing_support
