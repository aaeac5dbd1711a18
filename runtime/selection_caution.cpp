#include "dgtex/selection_caution.h"

#include <algorithm>
#include <cmath>

#include "api_argument_checks.h"
#include "dgtex/boundary_selection.h"

namespace dgtex {

std::string selection_tolerance_caution(const Scene& scene, const Mesh& mesh) {
  if (mesh.num_nodes() == 0) return "";
  double lo[3], hi[3];
  for (int d = 0; d < 3; ++d) lo[d] = hi[d] = mesh.node(0)[d];
  for (int n = 1; n < mesh.num_nodes(); ++n)
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], mesh.node(n)[d]);
      hi[d] = std::max(hi[d], mesh.node(n)[d]);
    }
  const double diagonal = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  for (size_t i = 0; i < scene.boundary.size(); ++i) {
    const double tolerance = scene.boundary[i].select.tolerance;
    if (!(tolerance >= kSelectionToleranceCautionAbove * diagonal)) continue;
    const size_t selected = select_nodes(mesh, scene.boundary[i].select).size();
    return "boundary[" + std::to_string(i) + "].select.tolerance " + detail::short_number(tolerance) + " is " +
           detail::short_number(std::round(100 * tolerance / diagonal)) + " % of the mesh's size (the diagonal of " +
           "its bounding box, " + detail::short_number(diagonal) + ") and selects " + std::to_string(selected) +
           " of its " + std::to_string(mesh.num_nodes()) +
           " nodes; the tolerance is a length in the mesh's units (default 1e-6): give one well below the node "
           "spacing";
  }
  return "";
}

}  // namespace dgtex
