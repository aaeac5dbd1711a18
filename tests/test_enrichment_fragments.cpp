// A cut that leaves a sliver a few texels wide (thesis Table 5.1 cuts are texel-detailed,
// so such fragments happen): the enriched functions of the nodes on the far side of the
// sliver have almost no support, and the mass matrix becomes nearly singular. The remedy
// (ShellModelOptions::min_enrichment_mass_ratio) drops those enriched DOFs; this test shows
// the conditioning with and without it.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdio>
#include <utility>

#include "enrichment_test_support.h"
#include "shell_test_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

// Smallest and largest eigenvalue of the Jacobi-scaled mass matrix D^-1/2 M D^-1/2
// (scale-free; its largest is O(1)).
std::pair<double, double> scaled_mass_spectrum(const ShellModel& model) {
  const int n = model.num_dofs();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  const BlockAssembly& p = model.pattern();
  for (int r = 0; r < p.num_nodes(); ++r)
    for (std::int64_t k = p.row_start()[r]; k < p.row_start()[r + 1]; ++k)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) M(3 * r + i, 3 * p.column()[k] + j) = model.mass_blocks()[9 * k + 3 * i + j];
  const Eigen::VectorXd s = M.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = s.asDiagonal() * M * s.asDiagonal();
  const Eigen::VectorXd eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues();
  return {eig(0), eig(n - 1)};
}

std::unique_ptr<ShellModel> sliver_model(const Mesh& mesh, double min_mass_ratio) {
  const Topology topology = build_topology(mesh);
  const Material m;
  std::vector<kernels::ShellSection> sections(mesh.num_elements(), {m.E, m.nu, m.h, m.rho});
  ShellModelOptions options;
  options.penalty = 1.0;
  options.min_enrichment_mass_ratio = min_mass_ratio;
  auto model = std::make_unique<ShellModel>(mesh, topology, sections, std::vector<int>{}, options);
  // 1 texel from the left edge of a 2 x 1 plate of 0.5-wide elements at T = 64.
  model->set_enrichments({straight_cut_enrichment(mesh, 64, [](const double* x) { return x[0] - 0.5 / 64; })});
  return model;
}

TEST(EnrichmentFragments, DroppingTinySupportsKeepsTheMassMatrixWellConditioned) {
  const Mesh mesh = make_rectangle(1, 0.5, 2, 1, ElementType::quad8);
  const auto kept = sliver_model(mesh, 0.0);
  const auto pruned = sliver_model(mesh, 1e-3);
  const auto [kept_min, kept_max] = scaled_mass_spectrum(*kept);
  const auto [pruned_min, pruned_max] = scaled_mass_spectrum(*pruned);
  std::printf("sliver of 1 texel: all %d enriched nodes kept: scaled mass eigenvalues [%.3e, %.3e]; "
              "%d dropped: [%.3e, %.3e], condition %.3e\n",
              kept->num_enriched_nodes(), kept_min, kept_max, pruned->num_pruned_enriched_nodes(), pruned_min,
              pruned_max, pruned_max / pruned_min);
  EXPECT_GT(pruned->num_pruned_enriched_nodes(), 0);
  EXPECT_GT(pruned->num_enriched_nodes(), 0);  // the rest of the cut still separates
  // Keeping every enriched DOF leaves the mass matrix singular to round-off (its smallest
  // eigenvalue is at the level of rounding errors, even negative); dropping the
  // near-dependent ones leaves it well conditioned.
  EXPECT_LT(kept_min, 1e-12 * kept_max);
  EXPECT_GT(pruned_min, 0.0);
  EXPECT_LT(pruned_max / pruned_min, 1e4);
}

}  // namespace
