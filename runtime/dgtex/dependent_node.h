#pragma once
// A node whose DOFs are no unknowns of their own but follow other nodes', component by
// component: x(node) = sum of coefficient * x(source). ShellModel makes the enriched DOFs of
// a tied node of a step function dependent so (ShellModel::dependent_nodes: the exact tie),
// and FreeDofSystem eliminates them as it eliminates fixed DOFs: a linear system over the
// free DOFs of the independent nodes, T^T A T, with x = T x_free.
#include <utility>
#include <vector>

namespace dgtex {

struct DependentNode {
  int node = -1;
  // (source node, coefficient); each source once, none of them dependent itself. A fixed
  // DOF of a source is zero, so it adds nothing; a fixed DOF of the node itself stays fixed.
  std::vector<std::pair<int, double>> sources;
};

}  // namespace dgtex
