// The cheaper incremental enrichment update (cut_manager.h, mesh_texel_laplace.h,
// enrichment_span.h) gives the same answers as the direct paths:
//  - a region whose solved tiles lie flat but close up only through frozen (settled)
//    tiles (a cylinder ring with one settled element) is solved by the tile multigrid
//    with the frozen texels as Dirichlet ghost texels, to CHOLMOD's solution;
//  - where the ring closes through solved tiles, it is cut open into a seamed patch
//    (seamed_patch_laplace.h: CG preconditioned by the open patch's multigrid), same answer;
//  - the single-function test of independent_enriched_nodes (pooled per-tile moments)
//    keeps exactly the nodes whose H deviates from its mean by an RMS above tolerance;
//  - a progressive cut around a cylinder gives the same textures with the multigrid as
//    with CHOLMOD, step by step, while settled elements are frozen.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cut_test_support.h"
#include "dgtex/cut_manager.h"
#include "dgtex/enrichment_span.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/mesh_texel_laplace.h"
#include "dgtex/topology.h"
#include "region_test_support.h"

using namespace dgtex;
using namespace dgtex::testing_support;

namespace {

constexpr int T = 32;

void expect_multigrid_equals_cholmod(const Mesh& mesh, const std::vector<int>& elements, const std::vector<int>& frozen,
                                     const MeshEdgeWalls& walls, bool on_patch) {
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  std::vector<RegionTile> direct = make_test_region(mesh, elements, T, frozen);
  std::vector<RegionTile> multigrid = direct;
  const MeshLaplaceStats d = solve_mesh_texel_laplace(direct, mesh.type, adjacency, walls, LaplaceSolver::cholmod);
  LaplaceMultigridOptions options;
  options.tolerance = 1e-12;
  const MeshLaplaceStats m =
      solve_mesh_texel_laplace(multigrid, mesh.type, adjacency, walls, LaplaceSolver::multigrid, options);
  EXPECT_GT(d.unknowns, 1000);
  EXPECT_EQ(m.unknowns, d.unknowns);
  EXPECT_EQ(m.frozen_tiles, static_cast<int>(frozen.size()));
  EXPECT_FALSE(d.multigrid);
  EXPECT_TRUE(m.multigrid);
  EXPECT_EQ(m.algebraic_multigrid, !on_patch);
  double worst = 0, spread = 0;
  for (std::size_t l = 0; l < direct.size(); ++l)
    for (std::size_t k = 0; k < direct[l].tile.values.size(); ++k) {
      worst = std::max(worst, std::abs(direct[l].tile.values[k] - multigrid[l].tile.values[k]));
      if (!direct[l].frozen) spread = std::max(spread, std::abs(direct[l].tile.values[k] - 0.5));
    }
  EXPECT_LT(worst, 1e-8);
  EXPECT_GT(spread, 0.5);  // the solution is not the warm start
  // Frozen tiles are data: untouched.
  for (int l : frozen)
    for (std::size_t k = 0; k < direct[l].tile.values.size(); ++k)
      ASSERT_EQ(multigrid[l].tile.values[k], 0.25 * std::sin(0.1 * k));
}

}  // namespace

TEST(EnrichmentIncrementalUpdate, CylinderRingClosedByAFrozenTileSolvesOnThePatch) {
  const Mesh mesh = make_cylinder(1, 1, 0, 360, 4, 1, ElementType::quad8);
  for (int f = 0; f < 4; ++f) {
    SCOPED_TRACE(f);
    expect_multigrid_equals_cholmod(mesh, {0, 1, 2, 3}, {f}, MeshEdgeWalls(T), true);
  }
}

TEST(EnrichmentIncrementalUpdate, FrozenColumnOfATwoRowRingWithBlockedGhosts) {
  const Mesh mesh = make_cylinder(1, 2, 0, 360, 4, 2, ElementType::quad8);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  // Cut half of the couplings between each frozen element and one solved neighbour (a cut
  // along the mesh edges): those ghosts must not couple.
  MeshEdgeWalls walls(T);
  for (int k = 0; k < adjacency.edges_per_element(); ++k)
    for (int frozen : {3, 7}) {
      const auto nb = adjacency.neighbour(frozen, k);
      if (nb[0] < 0 || nb[0] == 3 || nb[0] == 7) continue;
      for (int s = 0; s < T / 2; ++s) walls.block(frozen, k, s, adjacency);
      break;
    }
  ASSERT_FALSE(walls.empty());
  expect_multigrid_equals_cholmod(mesh, {0, 1, 2, 3, 4, 5, 6, 7}, {3, 7}, walls, true);
}

TEST(EnrichmentIncrementalUpdate, GhostBesideATileItMustNotCoupleTo) {
  // 2 x 2 block, element 2 (top left) frozen, its whole east edge cut (a cut along the
  // mesh edge): the ghost of element 0's north edge at the corner sits west of element
  // 3's first texel and must not couple to it.
  const Mesh mesh = make_rectangle(2, 2, 2, 2, ElementType::quad8);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  MeshEdgeWalls walls(T);
  for (int s = 0; s < T; ++s) walls.block(2, 1, s, adjacency);
  expect_multigrid_equals_cholmod(mesh, {0, 1, 2, 3}, {2}, walls, true);
}

TEST(EnrichmentIncrementalUpdate, EdgeWallsKeepEachBlockedTexelOnBothSides) {
  const Mesh mesh = make_rectangle(2, 1, 2, 1, ElementType::quad8);  // elements 0 | 1
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  const auto across = adjacency.neighbour(0, 1);  // element 0's east edge
  ASSERT_EQ(across[0], 1);
  MeshEdgeWalls walls(T);
  walls.block(0, 1, 3, adjacency);
  walls.block(0, 1, 3, adjacency);  // twice: still one wall
  EXPECT_TRUE(walls.blocked(0, 1, 3));
  EXPECT_TRUE(walls.blocked(1, across[1], T - 1 - 3));
  EXPECT_FALSE(walls.blocked(0, 1, 4));
  EXPECT_FALSE(walls.blocked(0, 0, 3));
  EXPECT_EQ(walls.keys_of_element(0), (std::vector<long long>{(0 * 4 + 1) * T + 3}));
  EXPECT_EQ(walls.keys_of_element(1), (std::vector<long long>{(1 * 4 + across[1]) * T + T - 1 - 3}));
  const std::vector<char> flags = walls.flags(mesh.num_elements());
  ASSERT_EQ(flags.size(), static_cast<std::size_t>(mesh.num_elements()) * 4 * T);
  EXPECT_EQ(std::count(flags.begin(), flags.end(), 1), 2);
  EXPECT_EQ(flags[(0 * 4 + 1) * T + 3], 1);
  EXPECT_EQ(flags[(1 * 4 + across[1]) * T + T - 1 - 3], 1);
}

TEST(EnrichmentIncrementalUpdate, EdgeWallsOfAnotherResolutionAreRefused) {
  const Mesh mesh = make_rectangle(2, 1, 2, 1, ElementType::quad8);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  MeshEdgeWalls walls(2 * T);
  walls.block(0, 1, 3, adjacency);
  std::vector<RegionTile> region(2);
  for (int e = 0; e < 2; ++e) region[e].element = e, region[e].tile = kernels::make_element_tile(mesh.type, T);
  region[0].tile.flags[0] |= kernels::dirichlet;
  try {
    solve_mesh_texel_laplace(region, mesh.type, adjacency, walls, LaplaceSolver::multigrid, {});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), ("mesh texel Laplace: the edge walls are at resolution " + std::to_string(2 * T) +
                            ", the tiles at " + std::to_string(T)).c_str());
  }
}

TEST(EnrichmentIncrementalUpdate, RingClosedThroughSolvedTilesSolvesOnASeamedPatch) {
  // Row 1 is solved all around: the solved tiles close up, so the patch is cut open at a
  // seam that the seamed solve couples again.
  const Mesh mesh = make_cylinder(1, 2, 0, 360, 4, 2, ElementType::quad8);
  expect_multigrid_equals_cholmod(mesh, {0, 1, 2, 3, 4, 5, 6, 7}, {3}, MeshEdgeWalls(T), true);
}

TEST(EnrichmentIncrementalUpdate, SingleFunctionNodesKeepExactlyTheNonConstantOnes) {
  const Mesh mesh = make_rectangle(3, 1, 3, 1, ElementType::quad8);  // elements 0 | 1 | 2
  const int t = 8;
  std::vector<std::vector<int>> node_elements(mesh.num_nodes());
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int a = 0; a < mesh.nodes_per_element(); ++a) node_elements[mesh.element_nodes(e)[a]].push_back(e);
  // Element 0: exactly +1. Element 1: +1 with wiggles of RMS ~3e-7 (below the 1e-6
  // tolerance). Element 2: wiggles of RMS ~3e-5 (above it).
  EnrichmentFunction f;
  for (int e = 0; e < mesh.num_nodes(); ++e) f.enriched_nodes.push_back(e);
  const double amplitude[3] = {0.0, 3e-7, 3e-5};
  for (int e = 0; e < 3; ++e) {
    ElementTexture texture;
    texture.element = e;
    texture.tile = kernels::make_element_tile(mesh.type, t);
    for (int k = 0; k < t * t; ++k) texture.tile.values[k] = 1.0 + amplitude[e] * std::sqrt(2.0) * std::sin(0.7 * k + e);
    f.elements.push_back(texture);
  }
  const std::vector<std::vector<int>> kept = independent_enriched_nodes(node_elements, {f});
  ASSERT_EQ(kept.size(), 1u);
  // Reference: RMS of H minus its mean over each node's support texels, in one pass.
  std::vector<int> expected;
  for (int a = 0; a < mesh.num_nodes(); ++a) {
    std::vector<double> column;
    for (int e : node_elements[a])
      for (double v : f.elements[e].tile.values) column.push_back(v);
    double mean = 0;
    for (double v : column) mean += v;
    mean /= column.size();
    double m2 = 0;
    for (double v : column) m2 += (v - mean) * (v - mean);
    if (std::sqrt(m2 / column.size()) > 1e-6) expected.push_back(a);
  }
  EXPECT_EQ(kept[0], expected);
  // Not vacuous: the nodes touching element 2 are kept, those only on 0 and 1 are not.
  EXPECT_FALSE(expected.empty());
  EXPECT_LT(expected.size(), static_cast<std::size_t>(mesh.num_nodes()));
  for (int a : expected) EXPECT_TRUE(std::count(node_elements[a].begin(), node_elements[a].end(), 2));
}

// Two functions on one element: A a ramp, B = A + delta g with g orthogonal to 1 and A
// (a checkerboard) of RMS 1, so B adds a residual of RMS exactly delta to the span of 1 and A.
// B must keep its nodes exactly when delta exceeds the 1e-6 tolerance, both where the Gram
// matrix certifies independence at once and where Gram-Schmidt decides near the threshold.
TEST(EnrichmentIncrementalUpdate, SharedNodesKeepALaterFunctionExactlyAboveTheTolerance) {
  const Mesh mesh = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  const int t = 16;
  std::vector<std::vector<int>> node_elements(mesh.num_nodes(), std::vector<int>{0});
  std::vector<int> all_nodes(mesh.num_nodes());
  for (int a = 0; a < mesh.num_nodes(); ++a) all_nodes[a] = a;
  const auto function = [&](auto value) {
    EnrichmentFunction f;
    f.enriched_nodes = all_nodes;
    ElementTexture texture;
    texture.element = 0;
    texture.tile = kernels::make_element_tile(mesh.type, t);
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) texture.tile.values[j * t + i] = value(i, j);
    f.elements.push_back(texture);
    return f;
  };
  const auto ramp = [&](int i, int) { return (i - 0.5 * (t - 1)) / t; };
  const EnrichmentFunction a = function(ramp);
  for (const double delta : {1e-2, 1e-5, 1.1e-6, 0.9e-6, 1e-8, 0.0}) {
    const EnrichmentFunction b = function([&](int i, int j) { return ramp(i, j) + delta * ((i + j) % 2 ? -1.0 : 1.0); });
    const std::vector<std::vector<int>> kept = independent_enriched_nodes(node_elements, {a, b}, 1e-6);
    ASSERT_EQ(kept.size(), 2u);
    EXPECT_EQ(kept[0], all_nodes) << "delta " << delta;
    EXPECT_EQ(kept[1], delta > 1e-6 ? all_nodes : std::vector<int>{}) << "delta " << delta;
  }
}

TEST(EnrichmentIncrementalUpdate, ProgressiveCutAroundACylinderMultigridMatchesCholmod) {
  const Mesh mesh = make_cylinder(1.0, 1.0, 0, 360, 4, 1, ElementType::quad8);
  const Topology topology = build_topology(mesh);
  std::vector<Vec3> arc;  // three quarters around at mid-length, starting mid-element
  for (int k = 0; k <= 27; ++k) {
    const double a = 2 * M_PI * (0.125 + 0.75 * k / 27.0);
    arc.push_back({std::sin(a), 0.5 + 0.1 * std::sin(3 * a), std::cos(a)});
  }
  Cut cut = points_cut(arc);
  cut.has_schedule = true;
  cut.speed = 1.0;  // length 3/4 * 2 pi ~ 4.7: about 0.5 per step below
  EnrichmentOptions direct_options = cholmod_enrichment(T);
  EnrichmentOptions multigrid_options = direct_options;
  multigrid_options.solver = EnrichmentOptions::Solver::multigrid;
  CutManager direct(mesh, topology, {cut}, direct_options);
  CutManager multigrid(mesh, topology, {cut}, multigrid_options);
  int frozen = 0;
  for (int step = 1; step <= 10; ++step) {
    const double time = 0.5 * step;
    EXPECT_EQ(direct.update(time), multigrid.update(time));
    frozen += multigrid.last_update().frozen_tiles;
    ASSERT_EQ(direct.functions().size(), multigrid.functions().size());
    for (std::size_t i = 0; i < direct.functions().size(); ++i) {
      const EnrichmentFunction &a = direct.functions()[i], &b = multigrid.functions()[i];
      EXPECT_EQ(a.enriched_nodes, b.enriched_nodes);
      ASSERT_EQ(a.elements.size(), b.elements.size());
      double worst = 0;
      for (std::size_t e = 0; e < a.elements.size(); ++e) {
        EXPECT_EQ(a.elements[e].tile.flags, b.elements[e].tile.flags);
        for (std::size_t k = 0; k < a.elements[e].tile.values.size(); ++k)
          worst = std::max(worst, std::abs(a.elements[e].tile.values[k] - b.elements[e].tile.values[k]));
      }
      // Relative residual 1e-6 of the multigrid: H (O(1)) agrees to about that (measured
      // at most 1e-6 here); a coupling wrong anywhere would show as O(0.01..1).
      EXPECT_LT(worst, 1e-5) << "step " << step << " function " << i;
    }
  }
  EXPECT_GT(frozen, 0);  // settled elements were frozen on some step (the ghost path ran)
}
