// The merged-basis edge kernel (shell_edge_stiffness_merged: one basis function per
// distinct node) against the plain reference with its separate plus/minus bases, summed
// over the shared nodes: equal to round-off, and its parallel form equal to the serial one
// bitwise. On a twisted closed cylinder with large rotations, quad8 and tri6.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include "dgtex/kernels/shell_edge_kernel.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/topology.h"
#include "shell_test_support.h"
#include "thread_count_support.h"

using namespace dgtex;
using testing_support::random_rotations;
using kernels::ElementType;
using kernels::Execution;

namespace {

class MergedEdges : public ::testing::TestWithParam<ElementType> {};

TEST_P(MergedEdges, MatchReferenceSummedOverSharedNodes) {
  const test::ThreadCountGuard set_threads(3);  // the parallel forms on several threads, even on a 1-core runner
  const Mesh mesh = make_cylinder(0.5, 1.0, 0, 360, 8, 4, GetParam());
  const std::vector<kernels::ShellSection> sections(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
  std::vector<int> edges;
  std::vector<double> edge_size;
  const Topology topology = build_topology(mesh);
  for (const MeshEdge& e : topology.interior_edges) {
    edges.insert(edges.end(), {e.plus_element, e.plus_local_edge, e.minus_element, e.minus_local_edge});
    edge_size.push_back(0.1);
  }
  for (size_t k = 0; k < 4; ++k) {
    const MeshEdge& e = topology.boundary_edges.at(k);
    edges.insert(edges.end(), {e.plus_element, e.plus_local_edge, -1, -1});
    edge_size.push_back(0.1);
  }
  const kernels::EdgeBatch batch{mesh.type, static_cast<std::int64_t>(edge_size.size()), edges.data(), edge_size.data(),
                                 10.0, 3, mesh.elements.data(), mesh.positions.data(), sections.data(), false};
  const int npe = mesh.nodes_per_element(), nb = 2 * npe, nq = 3;
  // Rotations: random proper rotations per edge point (the kernels take any R).
  const std::vector<double> R = random_rotations(batch.count * nq, 3);
  std::vector<double> Kref(batch.count * nb * nb * 9), fref(batch.count * nb * 3);
  kernels::shell_edge_stiffness_reference(batch, R.data(), Kref.data(), fref.data());
  std::vector<double> K(Kref.size(), 0.0), f(fref.size(), 0.0), Kpar(Kref.size(), 0.0), fpar(fref.size(), 0.0);
  kernels::shell_edge_stiffness_merged(batch, R.data(), K.data(), f.data(), Execution::serial);
  kernels::shell_edge_stiffness_merged(batch, R.data(), Kpar.data(), fpar.data(), Execution::parallel);
  EXPECT_EQ(K, Kpar);
  EXPECT_EQ(f, fpar);

  double scale_k = 0, scale_f = 0, error_k = 0, error_f = 0;
  int shared_total = 0;
  for (std::int64_t e = 0; e < batch.count; ++e) {
    int merged[2 * kernels::max_element_nodes];
    const int n = kernels::shell_edge_merged_nodes(batch, e, merged);
    const bool interior = edges[4 * e + 2] >= 0;
    std::map<int, int> slot;
    for (int i = 0; i < n; ++i) slot[merged[i]] = i;
    ASSERT_EQ(static_cast<int>(slot.size()), n) << "merged nodes are distinct";
    // The reference's separate basis, mapped onto the merged slots.
    std::vector<int> to(nb, -1);
    for (int side = 0; side < (interior ? 2 : 1); ++side)
      for (int a = 0; a < npe; ++a) to[side * npe + a] = slot.at(mesh.element_nodes(edges[4 * e + 2 * side])[a]);
    shared_total += (interior ? 2 * npe : npe) - n;
    std::vector<double> summed(static_cast<size_t>(n) * n * 9, 0.0), fsum(static_cast<size_t>(n) * 3, 0.0);
    for (int i = 0; i < nb; ++i) {
      if (to[i] < 0) continue;
      for (int c = 0; c < 3; ++c) fsum[to[i] * 3 + c] += fref[(e * nb + i) * 3 + c];
      for (int j = 0; j < nb; ++j)
        if (to[j] >= 0)
          for (int k = 0; k < 9; ++k) summed[(to[i] * n + to[j]) * 9 + k] += Kref[((e * nb + i) * nb + j) * 9 + k];
    }
    for (int i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) {
        scale_f = std::max(scale_f, std::abs(fsum[i * 3 + c]));
        error_f = std::max(error_f, std::abs(fsum[i * 3 + c] - f[(e * nb + i) * 3 + c]));
      }
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < 9; ++k) {
          const double expected = summed[(i * n + j) * 9 + k];
          scale_k = std::max(scale_k, std::abs(expected));
          error_k = std::max(error_k, std::abs(expected - K[((e * nb + i) * nb + j) * 9 + k]));
        }
    }
  }
  EXPECT_GT(shared_total, 0) << "interior edges share nodes";
  EXPECT_GT(scale_k, 0);
  EXPECT_GT(scale_f, 0);
  EXPECT_LE(error_k, 1e-13 * scale_k);
  EXPECT_LE(error_f, 1e-13 * scale_f);
}

INSTANTIATE_TEST_SUITE_P(Shell, MergedEdges, ::testing::Values(ElementType::quad8, ElementType::tri6));

}  // namespace
