// The multi-element harmonic problem (mesh_texel_laplace.h) solved by the tile multigrid on
// one patch tile must give CHOLMOD's solution on the texel graph: same couplings across
// element edges, walls (inside tiles and along mesh edges), frozen neighbours as data; a
// closed cylinder ring is cut open into a seamed patch (seamed_patch_laplace.h); regions whose
// tiles lie on one texel lattice only texel by texel (turned quad8 neighbours, tri6 cells
// split into square texels) are solved on a lattice patch, and those that cannot lie flat
// (a tri6 hypotenuse meeting a leg) by algebraic multigrid on the texel graph
// (graph_laplacian_amg.h), all to the same answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/mesh_generators.h"
#include "dgtex/mesh_texel_laplace.h"
#include "dgtex/topology.h"
#include "region_test_support.h"

using namespace dgtex;
using testing_support::make_test_region;

namespace {

constexpr int T = 32;

double max_difference(const std::vector<RegionTile>& a, const std::vector<RegionTile>& b) {
  double worst = 0;
  for (std::size_t l = 0; l < a.size(); ++l)
    for (std::size_t k = 0; k < a[l].tile.values.size(); ++k)
      worst = std::max(worst, std::abs(a[l].tile.values[k] - b[l].tile.values[k]));
  return worst;
}

struct Case {
  Mesh mesh;
  std::vector<int> elements;
};

void expect_multigrid_equals_cholmod(const Case& c, const MeshEdgeWalls& walls, bool on_patch,
                                     const std::vector<int>& frozen = {}) {
  const Topology topology = build_topology(c.mesh);
  const ElementAdjacency adjacency(c.mesh, topology);
  std::vector<RegionTile> direct = make_test_region(c.mesh, c.elements, T);
  for (int l : frozen) {
    direct[l].frozen = true;
    for (std::size_t k = 0; k < direct[l].tile.values.size(); ++k) direct[l].tile.values[k] = 0.25 * std::sin(0.1 * k);
  }
  std::vector<RegionTile> multigrid = direct;
  const MeshLaplaceStats d = solve_mesh_texel_laplace(direct, c.mesh.type, adjacency, walls, LaplaceSolver::cholmod);
  LaplaceMultigridOptions options;
  options.tolerance = 1e-12;
  const MeshLaplaceStats m =
      solve_mesh_texel_laplace(multigrid, c.mesh.type, adjacency, walls, LaplaceSolver::multigrid, options);
  EXPECT_GT(d.unknowns, 1000);
  EXPECT_EQ(m.unknowns, d.unknowns);
  EXPECT_FALSE(d.multigrid);
  EXPECT_TRUE(m.multigrid);
  EXPECT_EQ(m.algebraic_multigrid, !on_patch);
  EXPECT_LE(m.relative_residual, 1e-12);
  EXPECT_LT(max_difference(direct, multigrid), 1e-8);
  // The solution is not the warm start (the comparison is not vacuous).
  double spread = 0;
  for (const RegionTile& r : direct)
    for (double v : r.tile.values) spread = std::max(spread, std::abs(v - 0.5));
  EXPECT_GT(spread, 0.5);
}

}  // namespace

TEST(LaplaceMeshMultigrid, RectangleBlockMatchesCholmod) {
  expect_multigrid_equals_cholmod({make_rectangle(2, 2, 2, 2, ElementType::quad8), {0, 1, 2, 3}}, MeshEdgeWalls(T),
                                  true);
}

TEST(LaplaceMeshMultigrid, LShapedRegionWithEdgeWallsAndFrozenTile) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::quad8);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  MeshEdgeWalls walls(T);
  // Block half of element 0's east edge (a cut along the mesh edge).
  for (int s = 0; s < T / 2; ++s) walls.block(0, 1, s, adjacency);
  expect_multigrid_equals_cholmod({mesh, {0, 1, 4, 2, 5}}, walls, true, {3});
}

TEST(LaplaceMeshMultigrid, ClosedCylinderRingSolvesOnASeamedPatch) {
  expect_multigrid_equals_cholmod({make_cylinder(1, 1, 0, 360, 4, 1, ElementType::quad8), {0, 1, 2, 3}},
                                  MeshEdgeWalls(T), true);
}

// The sheared split's hypotenuses meet legs across the cell sides: a staircase of texels
// coupled to a straight row closes 5-cycles, which no square lattice holds.
TEST(LaplaceMeshMultigrid, ShearedTri6BlockSolvesByAlgebraicMultigridToTheSameAnswer) {
  expect_multigrid_equals_cholmod({make_rectangle(2, 2, 2, 2, ElementType::tri6), {0, 1, 2, 3, 4, 5, 6, 7}},
                                  MeshEdgeWalls(T), false);
}

// One sheared cell: its two triangles meet leg to leg along the diagonal, which the lattice holds.
TEST(LaplaceMeshMultigrid, ShearedTri6CellLiesOnTheLattice) {
  expect_multigrid_equals_cholmod({make_rectangle(1, 1, 1, 1, ElementType::tri6), {0, 1}}, MeshEdgeWalls(T), true);
}

// A 2 x 2 block of square-split cells (eight triangles, hypotenuse to hypotenuse on the
// diagonals, legs across the cell sides), one triangle settled, half of a diagonal and half
// of a cell side walled: the lattice patch with ghost texels gives CHOLMOD's answer.
TEST(LaplaceMeshMultigrid, SquareSplitTri6BlockWithEdgeWallsAndFrozenTileSolvesOnTheLattice) {
  const Mesh mesh = make_rectangle(3, 3, 3, 3, ElementType::tri6, TriangleSplit::square);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  MeshEdgeWalls walls(T);
  for (int s = 0; s < T / 2; ++s) walls.block(0, 1, s, adjacency), walls.block(1, 2, s, adjacency);
  expect_multigrid_equals_cholmod({mesh, {0, 1, 2, 3, 6, 7, 8, 9}}, walls, true, {5});
}

// Element 1 numbered from another corner: its edge toward element 0 is not the one opposite
// element 0's, so the blocks of tiles do not fit, but the texels still lie on one lattice.
TEST(LaplaceMeshMultigrid, TurnedQuad8NeighbourSolvesOnTheLattice) {
  Mesh mesh = make_rectangle(2, 2, 2, 2, ElementType::quad8);
  int* nodes = mesh.elements.data() + 8;  // element 1: corners then midside nodes
  std::rotate(nodes, nodes + 1, nodes + 4);
  std::rotate(nodes + 4, nodes + 5, nodes + 8);
  expect_multigrid_equals_cholmod({mesh, {0, 1, 2, 3}}, MeshEdgeWalls(T), true, {2});
}

// The eight triangles of a 2 x 2 block, one of them settled, half of an element edge walled
// (a cut along it).
TEST(LaplaceMeshMultigrid, Tri6RegionWithEdgeWallsAndFrozenTileSolvesByAlgebraicMultigrid) {
  const Mesh mesh = make_rectangle(2, 2, 2, 2, ElementType::tri6);
  const ElementAdjacency adjacency(mesh, build_topology(mesh));
  MeshEdgeWalls walls(T);
  for (int s = 0; s < T / 2; ++s) walls.block(0, 1, s, adjacency);
  expect_multigrid_equals_cholmod({mesh, {0, 1, 2, 3, 4, 5, 6, 7}}, walls, false, {3});
}
