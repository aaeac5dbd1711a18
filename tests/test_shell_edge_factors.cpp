// The factored edge stiffness (shell_edge_rest_rows + shell_edge_factors) and its gather
// (BlockAssembly::assemble_symmetric_matrix): the factors' products are the merged edge
// kernel's blocks bitwise; the parallel kernel equals its serial reference bitwise; the
// model's stiffness assembled this way equals the block-by-block assembly of the merged
// kernel (upper triangle bitwise, the lower one mirrored, so exactly symmetric) and
// does not depend on the thread count. Also the element kernel over cached rest rows.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "dgtex/kernels/low_rank_block.h"
#include "dgtex/kernels/polar_decomposition.h"
#include "dgtex/kernels/shell_edge_kernel.h"
#include "dgtex/kernels/shell_element_kernel.h"
#include "dgtex/mesh_validation.h"
#include "shell_test_support.h"
#include "thread_count_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;
using kernels::ElementType;
using kernels::Execution;

namespace {

class EdgeFactors : public ::testing::TestWithParam<ElementType> {};

TEST_P(EdgeFactors, ProductsAreTheMergedKernelsBlocksAndParallelIsTheReference) {
  const test::ThreadCountGuard set_threads(3);  // the parallel forms on several threads, even on a 1-core runner
  const Mesh mesh = make_cylinder(0.5, 1.0, 0, 360, 8, 4, GetParam());
  const std::vector<kernels::ShellSection> sections(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
  const Topology topology = build_topology(mesh);
  std::vector<int> edges;
  std::vector<double> edge_size;
  for (const MeshEdge& e : topology.interior_edges) {
    edges.insert(edges.end(), {e.plus_element, e.plus_local_edge, e.minus_element, e.minus_local_edge});
    edge_size.push_back(0.1 + 0.001 * static_cast<double>(edge_size.size() % 7));
  }
  for (size_t k = 0; k < 6; ++k) {  // clamped boundary edges
    const MeshEdge& e = topology.boundary_edges.at(k);
    edges.insert(edges.end(), {e.plus_element, e.plus_local_edge, -1, -1});
    edge_size.push_back(0.1);
  }
  for (int points : {2, 3}) {
    const kernels::EdgeBatch batch{mesh.type, static_cast<std::int64_t>(edge_size.size()), edges.data(),
                                   edge_size.data(), 10.0, points, mesh.elements.data(), mesh.positions.data(),
                                   sections.data(), false};
    const int nb = 2 * mesh.nodes_per_element();
    const std::vector<double> R = random_rotations(batch.count * points, 5);
    for (const double* rotations : {static_cast<const double*>(nullptr), R.data()}) {
      const size_t factor_size = batch.count * kernels::shell_edge_factor_stride(batch);
      const size_t force_size = batch.count * nb * 3;
      std::vector<double> rows(batch.count * points * kernels::shell_edge_rest_row_stride(batch));
      kernels::shell_edge_rest_rows(batch, rows.data());
      // NaN in the unwritten slots: the comparisons below read only the merged ones.
      std::vector<double> reference(factor_size, NAN), fref(force_size, 1.0);
      kernels::shell_edge_factors_reference(batch, rotations, reference.data(), rotations ? fref.data() : nullptr);
      for (Execution execution : {Execution::serial, Execution::parallel}) {
        std::vector<double> factors(factor_size, NAN), f(force_size, 2.0);
        kernels::shell_edge_factors(batch, rows.data(), rotations, factors.data(), rotations ? f.data() : nullptr,
                                    execution);
        if (rotations) {
          EXPECT_EQ(f, fref);
        }
        for (std::int64_t e = 0; e < batch.count; ++e) {
          int nodes[2 * kernels::max_element_nodes];
          const int n = kernels::shell_edge_merged_nodes(batch, e, nodes);
          const double* a = factors.data() + e * kernels::shell_edge_factor_stride(batch);
          const double* b = reference.data() + e * kernels::shell_edge_factor_stride(batch);
          ASSERT_TRUE(std::equal(a, a + n * 4 * points * 3, b)) << "edge " << e;
        }
      }
      // The products against the merged kernel's blocks and forces.
      std::vector<double> merged(batch.count * nb * nb * 9, NAN), fmerged(force_size, 3.0);
      kernels::shell_edge_stiffness_merged(batch, rotations, merged.data(), rotations ? fmerged.data() : nullptr);
      std::vector<double> expanded(merged.size(), NAN);
      kernels::shell_edge_blocks_from_factors(batch, reference.data(), expanded.data());
      if (rotations) {
        EXPECT_EQ(fmerged, fref);
      }
      int compared = 0;
      for (std::int64_t e = 0; e < batch.count; ++e) {
        int nodes[2 * kernels::max_element_nodes];
        const int n = kernels::shell_edge_merged_nodes(batch, e, nodes);
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j) {
            const size_t at = ((e * nb + i) * nb + j) * 9;
            ASSERT_TRUE(std::equal(&merged[at], &merged[at] + 9, &expanded[at])) << e << " " << i << " " << j;
            ++compared;
          }
      }
      EXPECT_GT(compared, 0);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Shell, EdgeFactors, ::testing::Values(ElementType::quad8, ElementType::tri6));

// The element kernel over cached rest rows is shell_element_stiffness bitwise, serial and
// parallel, with and without rotations.
TEST_P(EdgeFactors, CachedElementKernelIsTheElementKernel) {
  const test::ThreadCountGuard set_threads(3);  // the parallel forms on several threads, even on a 1-core runner
  const Mesh mesh = make_cylinder(0.5, 1.0, 0, 360, 8, 4, GetParam());
  const std::vector<kernels::ShellSection> sections(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
  const kernels::ElementBatch batch{mesh.type, mesh.num_elements(), mesh.elements.data(), mesh.positions.data(),
                                    sections.data()};
  const int npe = mesh.nodes_per_element(), nq = kernels::element_quadrature(mesh.type).count;
  const std::vector<double> R = random_rotations(batch.count * nq, 7);
  std::vector<double> rows(batch.count * nq * kernels::shell_element_rest_row_stride(batch));
  kernels::shell_element_rest_rows(batch, rows.data());
  for (const double* rotations : {static_cast<const double*>(nullptr), R.data()}) {
    std::vector<double> K(batch.count * npe * npe * 9), f(batch.count * npe * 3);
    kernels::shell_element_stiffness(batch, rotations, K.data(), rotations ? f.data() : nullptr, Execution::serial);
    for (Execution execution : {Execution::serial, Execution::parallel}) {
      std::vector<double> K2(K.size(), NAN), f2(f.size(), 0.0);
      kernels::shell_element_stiffness_cached(batch, rows.data(), rotations, K2.data(), rotations ? f2.data() : nullptr,
                                              execution);
      EXPECT_EQ(K2, K);
      EXPECT_EQ(f2, f);
    }
  }
}

// The model's assembly against the merged kernel's blocks assembled by assemble_matrix
// (the assembly before the factored form), built here from the public kernels.
TEST(EdgeFactorsAssembly, ModelStiffnessEqualsTheBlockAssemblyAndIsThreadIndependent) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Mesh mesh = make_cylinder(0.5, 1.0, 0, 360, 8, 4, type);
    const Topology topology = build_topology(mesh);
    const Material m;
    std::vector<int> clamped;
    for (size_t k = 0; k < topology.boundary_edges.size(); ++k)
      if (mesh.node(topology.boundary_edges[k].nodes[0])[1] < 1e-9) clamped.push_back(static_cast<int>(k));
    ASSERT_FALSE(clamped.empty());
    auto model = make_model(mesh, m, 1.0, [](const double* x) { return x[1] < 1e-9; });
    ASSERT_EQ(model->num_clamped_edges(), static_cast<int>(clamped.size()));
    // The model's edge batch, as its constructor builds it.
    std::vector<double> size_of_element(mesh.num_elements());
    for (int e = 0; e < mesh.num_elements(); ++e) size_of_element[e] = element_area(mesh, e) / element_perimeter(mesh, e);
    std::vector<int> edges;
    std::vector<double> edge_size;
    for (const MeshEdge& e : topology.interior_edges) {
      edges.insert(edges.end(), {e.plus_element, e.plus_local_edge, e.minus_element, e.minus_local_edge});
      edge_size.push_back(std::min(size_of_element[e.plus_element], size_of_element[e.minus_element]));
    }
    for (int k : clamped) {
      const MeshEdge& e = topology.boundary_edges[k];
      edges.insert(edges.end(), {e.plus_element, e.plus_local_edge, -1, -1});
      edge_size.push_back(size_of_element[e.plus_element]);
    }
    const std::vector<kernels::ShellSection> sections(mesh.num_elements(), {m.E, m.nu, m.h, m.rho});
    const ShellModelOptions& options = model->options();
    const kernels::EdgeBatch gb{mesh.type, static_cast<std::int64_t>(edge_size.size()), edges.data(),
                                edge_size.data(), options.penalty, options.edge_quadrature_points,
                                mesh.elements.data(), mesh.positions.data(), sections.data(), false};
    const kernels::ElementBatch eb{mesh.type, mesh.num_elements(), mesh.elements.data(), mesh.positions.data(),
                                   sections.data()};
    // A deformed state (twist and noise), corotated per point.
    std::vector<double> current = model->rest_state();
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> noise(-0.02, 0.02);
    for (int n = 0; n < mesh.num_nodes(); ++n) {
      double* x = &current[3 * n];
      const double t = 0.8 * x[1], c = std::cos(t), s = std::sin(t);
      const double x0 = x[0], z0 = x[2];
      x[0] = c * x0 + s * z0 + noise(rng);
      x[2] = -s * x0 + c * z0 + noise(rng);
    }
    const int npe = mesh.nodes_per_element(), nq = kernels::element_quadrature(type).count;
    for (bool corotated : {false, true}) {
      const double* state = corotated ? current.data() : nullptr;
      std::vector<double> element_rotations, edge_rotations;
      if (corotated) {
        std::vector<double> F(static_cast<size_t>(eb.count) * nq * 9);
        kernels::shell_element_deformation_gradients(eb, state, F.data());
        element_rotations.resize(F.size());
        kernels::polar_decomposition_batch(eb.count * nq, F.data(), element_rotations.data());
        edge_rotations.resize(gb.count * gb.quadrature_points * 9);
        kernels::shell_edge_rotations(gb, state, edge_rotations.data());
      }
      std::vector<double> element_blocks(eb.count * npe * npe * 9), edge_blocks(gb.count * 4 * npe * npe * 9);
      kernels::shell_element_stiffness(eb, corotated ? element_rotations.data() : nullptr, element_blocks.data(),
                                       nullptr);
      kernels::shell_edge_stiffness_merged(gb, corotated ? edge_rotations.data() : nullptr, edge_blocks.data(),
                                           nullptr);
      const BlockAssembly& p = model->pattern();
      std::vector<double> expected(p.num_blocks() * 9);
      p.assemble_matrix({element_blocks.data(), edge_blocks.data()}, expected.data());

      std::vector<double> K, f;
      model->assemble_stiffness(state, K, &f, Execution::serial);
      ASSERT_EQ(K.size(), expected.size());
      double scale = 0, error = 0, asymmetry_before = 0;
      for (int r = 0; r < p.num_nodes(); ++r)
        for (std::int64_t k = p.row_start()[r]; k < p.row_start()[r + 1]; ++k) {
          const std::int64_t t = p.find(p.column()[k], r);
          ASSERT_GE(t, 0);
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
              const double v = K[k * 9 + i * 3 + j];
              scale = std::max(scale, std::abs(expected[k * 9 + i * 3 + j]));
              error = std::max(error, std::abs(v - expected[k * 9 + i * 3 + j]));
              asymmetry_before = std::max(asymmetry_before,
                                          std::abs(expected[k * 9 + i * 3 + j] - expected[t * 9 + j * 3 + i]));
              ASSERT_EQ(v, K[t * 9 + j * 3 + i]) << "exactly symmetric";
              if (p.column()[k] > r || (p.column()[k] == r && j >= i)) {
                ASSERT_EQ(v, expected[k * 9 + i * 3 + j]) << "upper triangle bitwise";
              }
            }
        }
      EXPECT_GT(scale, 0);
      EXPECT_LE(error, 1e-13 * scale);
      std::printf("%s%s: max |K - K_blocks| %.2e, asymmetry of K_blocks %.2e (max |K| %.2e)\n",
                  type == ElementType::quad8 ? "quad8" : "tri6", corotated ? " corotated" : "", error,
                  asymmetry_before, scale);
      for (int threads : {1, 2, 4}) {
        const test::ThreadCountGuard set_threads(threads);
        const ShellModel fresh = *model;  // without the cached rest rows: built on `threads`
        std::vector<double> K2, f2;
        fresh.assemble_stiffness(state, K2, &f2);
        EXPECT_EQ(K2, K) << threads << " threads";
        EXPECT_EQ(f2, f) << threads << " threads";
      }
    }
  }
}

}  // namespace
