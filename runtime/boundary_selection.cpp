#include "dgtex/boundary_selection.h"

#include <cmath>

namespace dgtex {

bool point_is_selected(const BoundarySelect& select, const double x[3]) {
  if (select.kind == BoundarySelect::Kind::plane) {
    // The parser makes the normal a unit vector; one set in code may not be.
    const Vec3& n = select.normal;
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return std::abs((n[0] * x[0] + n[1] * x[1] + n[2] * x[2]) / length - select.offset) <= select.tolerance;
  }
  for (int i = 0; i < 3; ++i)
    if (!(x[i] >= select.min[i] - select.tolerance && x[i] <= select.max[i] + select.tolerance)) return false;
  return true;
}

std::vector<int> select_nodes(const Mesh& mesh, const BoundarySelect& select) {
  // Orphan nodes (e.g. unused OBJ vertices) carry no degrees of freedom, so they must not
  // make an otherwise empty selection look non-empty.
  std::vector<char> used(mesh.num_nodes(), 0);
  for (int node : mesh.elements)
    if (node >= 0 && node < mesh.num_nodes()) used[node] = 1;
  std::vector<int> selected;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (used[n] && point_is_selected(select, mesh.node(n))) selected.push_back(n);
  return selected;
}

}  // namespace dgtex
