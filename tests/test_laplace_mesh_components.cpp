// The component search of solve_mesh_texel_laplace (mesh_texel_laplace.cpp): free texels
// walled off from everything else form their own components. At T = 128 over two tiles, a
// walled box with no data gets 0, a box touching one data value gets exactly that value
// (neither is solved), and the rest (+1 and -1 data in the two tiles) is the one solved
// component; the answer is bitwise the same for 1, 2 and 4 threads, with the multigrid and
// with CHOLMOD, and the two solvers agree on the solved component. The same boxes in a
// region of one tile (the tile multigrid on the tile itself) leave its flags as they were.
// Components that join late (a comb's teeth above their band, a box across the element
// edge) are found whole.
#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "dgtex/kernels/texel_grid.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/mesh_texel_laplace.h"
#include "dgtex/topology.h"
#include "region_test_support.h"
#include "thread_count_support.h"

using namespace dgtex;

namespace {

constexpr int T = 128;

struct Box {
  int x0, x1, y0, y1;  // texels [x0, x1] x [y0, y1]
  bool contains(int i, int j) const { return i >= x0 && i <= x1 && j >= y0 && j <= y1; }
};
constexpr Box empty_box{10, 30, 20, 50};       // tile 0
constexpr Box constant_box{40, 100, 25, 100};  // tile 1
constexpr double constant_value = 0.75;

// Walls below and above the box (texel flags hold the walls on their east and north sides).
void wall_below_and_above(kernels::TexelTile& tile, const Box& b) {
  for (int i = b.x0; i <= b.x1; ++i) {
    tile.flags[(b.y0 - 1) * T + i] |= kernels::wall_north;
    tile.flags[b.y1 * T + i] |= kernels::wall_north;
  }
}

// Walls all around the box.
void wall_in(kernels::TexelTile& tile, const Box& b) {
  for (int j = b.y0; j <= b.y1; ++j) {
    tile.flags[j * T + b.x0 - 1] |= kernels::wall_east;
    tile.flags[j * T + b.x1] |= kernels::wall_east;
  }
  wall_below_and_above(tile, b);
}

std::vector<RegionTile> boxed_region(const Mesh& mesh) {
  std::vector<RegionTile> region = testing_support::make_test_region(mesh, {0, 1}, T);
  wall_in(region[0].tile, empty_box);
  wall_in(region[1].tile, constant_box);
  const int k = 40 * T + 50;  // one data texel inside the constant box
  region[1].tile.flags[k] |= kernels::dirichlet;
  region[1].tile.values[k] = constant_value;
  return region;
}

struct Solved {
  std::vector<RegionTile> region;
  MeshLaplaceStats stats;
};

Solved solve(LaplaceSolver solver, int threads) {
  const Mesh mesh = make_rectangle(2, 1, 2, 1, ElementType::quad8);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  Solved out{boxed_region(mesh), {}};
  LaplaceMultigridOptions options;
  options.tolerance = 1e-12;
  out.stats = test::with_threads(threads, [&] {
    return solve_mesh_texel_laplace(out.region, mesh.type, adjacency, MeshEdgeWalls(T), solver, options);
  });
  return out;
}

void expect_boxes_settled_without_a_solve(const Solved& s) {
  EXPECT_EQ(s.stats.solved_components, 1);
  EXPECT_EQ(s.stats.constant_components, 1);
  // Every texel of the region is free except the +-1 runs (6 each) and the box's data texel.
  const int boxed = (empty_box.x1 - empty_box.x0 + 1) * (empty_box.y1 - empty_box.y0 + 1) +
                    (constant_box.x1 - constant_box.x0 + 1) * (constant_box.y1 - constant_box.y0 + 1) - 1;
  EXPECT_EQ(s.stats.unknowns, 2 * T * T - 2 * 6 - 1 - boxed);
  for (int j = 0; j < T; ++j)
    for (int i = 0; i < T; ++i) {
      if (empty_box.contains(i, j)) {
        EXPECT_EQ(s.region[0].tile.values[j * T + i], 0.0) << i << ", " << j;
      }
      if (constant_box.contains(i, j)) {
        EXPECT_EQ(s.region[1].tile.values[j * T + i], constant_value) << i << ", " << j;
      }
    }
}

void expect_bitwise_equal(const Solved& a, const Solved& b) {
  EXPECT_EQ(a.stats.unknowns, b.stats.unknowns);
  EXPECT_EQ(a.stats.solved_components, b.stats.solved_components);
  EXPECT_EQ(a.stats.constant_components, b.stats.constant_components);
  std::size_t differ = 0;
  for (std::size_t l = 0; l < a.region.size(); ++l)
    for (std::size_t k = 0; k < a.region[l].tile.values.size(); ++k)
      differ += a.region[l].tile.values[k] != b.region[l].tile.values[k];
  EXPECT_EQ(differ, 0u);
}

}  // namespace

TEST(LaplaceMeshComponents, BoxesAcrossRowBandsAreSettledAlikeForAnyThreadCount) {
  for (LaplaceSolver solver : {LaplaceSolver::multigrid, LaplaceSolver::cholmod}) {
    SCOPED_TRACE(solver == LaplaceSolver::multigrid ? "multigrid" : "cholmod");
    const Solved one = solve(solver, 1);
    expect_boxes_settled_without_a_solve(one);
    EXPECT_EQ(one.stats.multigrid, solver == LaplaceSolver::multigrid);
    expect_bitwise_equal(one, solve(solver, 2));
    expect_bitwise_equal(one, solve(solver, 4));
  }
}

TEST(LaplaceMeshComponents, TheSolvedComponentMatchesAcrossSolvers) {
  const Solved multigrid = solve(LaplaceSolver::multigrid, 2), direct = solve(LaplaceSolver::cholmod, 2);
  double worst = 0, spread = 0;
  for (std::size_t l = 0; l < direct.region.size(); ++l)
    for (std::size_t k = 0; k < direct.region[l].tile.values.size(); ++k) {
      worst = std::max(worst, std::abs(direct.region[l].tile.values[k] - multigrid.region[l].tile.values[k]));
      spread = std::max(spread, std::abs(direct.region[l].tile.values[k] - 0.5));
    }
  EXPECT_LT(worst, 1e-8);
  EXPECT_GT(spread, 0.4);  // not the warm start: the comparison is not vacuous
}

// A region of one tile takes the tile multigrid on the tile itself: the boxes are settled
// as above, the solved component agrees with CHOLMOD, and the tile's flags come back as
// they were (the settled texels are data only while the multigrid runs).
TEST(LaplaceMeshComponents, OneTileSettlesItsBoxesAndReturnsItsFlags) {
  const Mesh mesh = make_rectangle(1, 1, 1, 1, ElementType::quad8);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  std::vector<RegionTile> start = testing_support::make_test_region(mesh, {0}, T);
  wall_in(start[0].tile, empty_box);
  wall_in(start[0].tile, constant_box);
  start[0].tile.flags[40 * T + 50] |= kernels::dirichlet;
  start[0].tile.values[40 * T + 50] = constant_value;
  LaplaceMultigridOptions options;
  options.tolerance = 1e-12;
  std::vector<RegionTile> multigrid = start, direct = start;
  const MeshLaplaceStats mg =
      solve_mesh_texel_laplace(multigrid, mesh.type, adjacency, MeshEdgeWalls(T), LaplaceSolver::multigrid, options);
  const MeshLaplaceStats chol =
      solve_mesh_texel_laplace(direct, mesh.type, adjacency, MeshEdgeWalls(T), LaplaceSolver::cholmod, options);
  EXPECT_TRUE(mg.multigrid);
  EXPECT_FALSE(chol.multigrid);
  for (const MeshLaplaceStats& stats : {mg, chol}) {
    EXPECT_EQ(stats.solved_components, 1);
    EXPECT_EQ(stats.constant_components, 1);
  }
  EXPECT_EQ(multigrid[0].tile.flags, start[0].tile.flags);
  EXPECT_EQ(direct[0].tile.flags, start[0].tile.flags);
  double worst = 0, spread = 0;
  for (int j = 0; j < T; ++j)
    for (int i = 0; i < T; ++i) {
      const int k = j * T + i;
      if (empty_box.contains(i, j)) {
        EXPECT_EQ(multigrid[0].tile.values[k], 0.0) << i << ", " << j;
      }
      if (constant_box.contains(i, j)) {
        EXPECT_EQ(multigrid[0].tile.values[k], constant_value) << i << ", " << j;
      }
      worst = std::max(worst, std::abs(multigrid[0].tile.values[k] - direct[0].tile.values[k]));
      spread = std::max(spread, std::abs(direct[0].tile.values[k] - 0.5));
    }
  EXPECT_LT(worst, 1e-8);
  EXPECT_GT(spread, 0.4);  // not the warm start
}

// Components that join late. The teeth of a comb meet only in a band above them: the
// component search meets each tooth as a set of its own and unites them in the band. A box
// cut by the shared element edge is one component across the two tiles. With data in one
// tooth, and on one side of the edge, every texel of the comb and of the box gets that value.
TEST(LaplaceMeshComponents, CombTeethAndABoxAcrossTheElementEdgeJoin) {
  const Mesh mesh = make_rectangle(2, 1, 2, 1, ElementType::quad8);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  std::vector<RegionTile> start = testing_support::make_test_region(mesh, {0, 1}, T);
  constexpr Box comb{10, 59, 10, 60};
  constexpr int teeth_top = 54;  // the teeth's walls end here; rows 55-60 are the band
  constexpr double comb_value = 0.75, bridge_value = -0.25;
  kernels::TexelTile& left = start[0].tile;
  kernels::TexelTile& right = start[1].tile;
  wall_in(left, comb);
  for (int x : {19, 29, 39, 49})
    for (int j = comb.y0; j <= teeth_top; ++j) left.flags[j * T + x] |= kernels::wall_east;
  left.flags[12 * T + 12] |= kernels::dirichlet;  // in the first tooth
  left.values[12 * T + 12] = comb_value;
  // The bridge: texels 100-127 of tile 0 and 0-20 of tile 1, rows 80-100, open across the
  // shared edge (element 0's east, element 1's west).
  constexpr Box bridge_left{100, T - 1, 80, 100}, bridge_right{0, 20, 80, 100};
  for (int j = bridge_left.y0; j <= bridge_left.y1; ++j) {
    left.flags[j * T + bridge_left.x0 - 1] |= kernels::wall_east;
    right.flags[j * T + bridge_right.x1] |= kernels::wall_east;
  }
  wall_below_and_above(left, bridge_left);
  wall_below_and_above(right, bridge_right);
  right.flags[90 * T + 10] |= kernels::dirichlet;
  right.values[90 * T + 10] = bridge_value;

  LaplaceMultigridOptions options;
  options.tolerance = 1e-12;
  std::vector<std::vector<RegionTile>> answers;
  for (LaplaceSolver solver : {LaplaceSolver::multigrid, LaplaceSolver::cholmod})
    for (int threads : {1, 2}) {
      SCOPED_TRACE(std::string(solver == LaplaceSolver::multigrid ? "multigrid" : "cholmod") + ", " +
                   std::to_string(threads) + " threads");
      std::vector<RegionTile> region = start;
      const MeshLaplaceStats stats = test::with_threads(
          threads, [&] { return solve_mesh_texel_laplace(region, mesh.type, adjacency, MeshEdgeWalls(T), solver, options); });
      EXPECT_EQ(stats.multigrid, solver == LaplaceSolver::multigrid);
      EXPECT_EQ(stats.constant_components, 2);
      EXPECT_EQ(stats.solved_components, 1);
      int wrong = 0;
      for (int j = 0; j < T; ++j)
        for (int i = 0; i < T; ++i) {
          const int k = j * T + i;
          if (comb.contains(i, j)) wrong += region[0].tile.values[k] != comb_value;
          if (bridge_left.contains(i, j)) wrong += region[0].tile.values[k] != bridge_value;
          if (bridge_right.contains(i, j)) wrong += region[1].tile.values[k] != bridge_value;
        }
      EXPECT_EQ(wrong, 0);
      answers.push_back(std::move(region));
    }
  for (std::size_t a : {1u, 3u})  // each solver: 2 threads bitwise as 1
    for (std::size_t l = 0; l < 2; ++l) EXPECT_EQ(answers[a][l].tile.values, answers[a - 1][l].tile.values);
}

// A component that no data reaches (a piece other cuts separate from this cut's texels) is
// harmonic for any constant; it takes the one value beyond its walls, the side of the cut
// it lies on, so that the enriched functions of the nodes on that side vanish on it. Walls
// joining several such components (the quadrants beyond an X's crossing) make one group;
// a group beside two values keeps 0. Two tiles: a wall splits tile 1 at column 64 into a
// left part, open to tile 0 across the element edge, with data +1 there, and a right part
// with data -1. A box walled in inside tile 0 gets +1; a box walled in across the split gets
// 0 in both halves. Tile 0 frozen with those values is not stale; with its box at 0 it is.
TEST(LaplaceMeshComponents, AWalledBoxWithoutDataTakesTheOneValueBeyondItsWalls) {
  const Mesh mesh = make_rectangle(2, 1, 2, 1, ElementType::quad8);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  std::vector<RegionTile> region(2);
  for (int l = 0; l < 2; ++l) {
    region[l].element = l;
    region[l].tile = kernels::make_element_tile(mesh.type, T);
    for (double& v : region[l].tile.values) v = 0.5;  // a warm start, not an answer
  }
  kernels::TexelTile& left = region[0].tile;
  kernels::TexelTile& right = region[1].tile;
  constexpr Box inside{20, 40, 20, 40}, across{50, 80, 60, 90};
  wall_in(left, inside);
  wall_in(right, across);
  for (int j = 0; j < T; ++j) right.flags[j * T + 63] |= kernels::wall_east;
  left.flags[100 * T + 100] |= kernels::dirichlet;
  left.values[100 * T + 100] = 1;
  right.flags[10 * T + 100] |= kernels::dirichlet;
  right.values[10 * T + 100] = -1;
  for (LaplaceSolver solver : {LaplaceSolver::multigrid, LaplaceSolver::cholmod}) {
    SCOPED_TRACE(solver == LaplaceSolver::multigrid ? "multigrid" : "cholmod");
    std::vector<RegionTile> solved = region;
    const MeshLaplaceStats stats =
        solve_mesh_texel_laplace(solved, mesh.type, adjacency, MeshEdgeWalls(T), solver, LaplaceMultigridOptions{});
    EXPECT_EQ(stats.constant_components, 2);
    EXPECT_EQ(stats.unknowns, 0);
    int wrong = 0;
    for (int j = 0; j < T; ++j)
      for (int i = 0; i < T; ++i) {
        const int k = j * T + i;
        wrong += solved[0].tile.values[k] != 1.0;  // the box as all around it
        const double expected = across.contains(i, j) ? 0.0 : i < 64 ? 1.0 : -1.0;
        wrong += solved[1].tile.values[k] != expected;
      }
    EXPECT_EQ(wrong, 0);
    // Settled, tile 0 is data for a solve of tile 1 (its data texel marked as such): with
    // its box at the value beyond the walls it is not stale; with the box at 0 it is.
    solved[0].frozen = true;
    EXPECT_TRUE(stale_frozen_tiles(solved, mesh.type, adjacency, MeshEdgeWalls(T)).empty());
    for (int j = inside.y0; j <= inside.y1; ++j)
      for (int i = inside.x0; i <= inside.x1; ++i) solved[0].tile.values[j * T + i] = 0;
    EXPECT_EQ(stale_frozen_tiles(solved, mesh.type, adjacency, MeshEdgeWalls(T)), std::vector<int>{0});
  }
}
