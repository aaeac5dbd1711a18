#pragma once
// A shell mesh of quadratic elements (quad8 or tri6, all of one type). Shapes:
//   positions: #nodes x 3 (x, y, z), row-major, in the scene's length unit;
//   elements:  #elements x nodes_per_element(type), node indices in the local order of
//              dgtex/kernels/shape_functions.h (corners counter-clockwise seen from the
//              side the normal points to, then midsides).
// Displacements are C0: neighbouring elements share their edge's three nodes.
// A value type that owns its arrays (copying copies the mesh); const use is thread-safe.
#include <cstddef>
#include <vector>

#include "dgtex/kernels/shape_functions.h"

namespace dgtex {

using kernels::ElementType;

struct Mesh {
  ElementType type = ElementType::quad8;
  std::vector<double> positions;
  std::vector<int> elements;

  int nodes_per_element() const { return kernels::nodes_per_element(type); }
  int num_nodes() const { return static_cast<int>(positions.size() / 3); }
  int num_elements() const { return static_cast<int>(elements.size() / nodes_per_element()); }
  const int* element_nodes(int e) const { return elements.data() + static_cast<std::size_t>(e) * nodes_per_element(); }
  const double* node(int n) const { return positions.data() + 3 * static_cast<std::size_t>(n); }
};

}  // namespace dgtex
