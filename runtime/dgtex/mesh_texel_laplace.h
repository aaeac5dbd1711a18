#pragma once
// The harmonic texel problem over several element tiles (thesis §5.5.3), as one texel
// graph: inside a tile the 5-point couplings of dgtex/kernels/multigrid_unknowns.h (walls
// and inactive texels cut them), and across every mesh edge shared by two tiles of the
// region, boundary texel s of local edge k of element e couples (weight 1) to boundary
// texel T-1-s of the neighbour's local edge (the neighbour runs the edge backwards).
// Boundary texels of an edge: quad8 edge 0 (s, 0), 1 (T-1, s), 2 (T-1-s, T-1),
// 3 (0, T-1-s); tri6 edge 0 (s, 0), 1 (T-1-s, s) (the half-covered diagonal texels of
// the hypotenuse), 2 (0, T-1-s). Unlike a planar block of tiles this handles unstructured
// meshes, closed cylinders and spheres, and any mix of edge pairings. The cross-edge
// couplings give C0 continuity of H to the order of one texel, like inside a tile.
//
// Tiles marked frozen are data: every active texel is a Dirichlet value for the texels of
// solved tiles coupled to it (the C0 constraints from settled neighbouring enrichments of
// §5.5.3). Elements outside the region leave zero Neumann. Free texels in a component
// (connected through free-free couplings) with no data get the value that every texel
// beyond its walls holds (after the solve), where there is one, else 0; components without
// data that walls join count as one there (mesh_texel_laplace.cpp,
// untouched_component_values). A component whose data are all one value v gets exactly v
// without a solve; the rest are the unknowns of one SPD system. With
// LaplaceSolver::multigrid (the enrichment's default) a single tile, or a quad8 region
// whose solved (non-frozen) tiles lie side by side in the plane without turning or closing
// up (e.g. blocks of a rectangle mesh: chad's 2x2; a cylinder ring closed only through
// frozen tiles: slinky after its first cut settles), is solved by the tile multigrid on one
// patch tile holding the same couplings (options: tolerance, warm start from the
// tiles' values); frozen texels coupled to solved ones enter that patch as Dirichlet ghost
// texels beside the edge they couple across, walled off from everything else; a ring closed
// through solved tiles, on a patch cut open at a seam. Other regions whose texels still lie on
// one square lattice with every coupling between lattice neighbours (quad8 neighbours turned
// against each other; tri6 cells split with the diagonal as both hypotenuses,
// TriangleSplit::square: each hypotenuse texel's partner sits beside it) are solved by the
// tile multigrid on a lattice patch, texel by texel, walled wherever lattice neighbours are
// not coupled. Regions no lattice holds (a tri6 hypotenuse meeting a leg: the sheared
// split's 5-cycles; rings of such cells) are solved by algebraic multigrid on the texel
// graph. With LaplaceSolver::cholmod, or where a multigrid misses its tolerance, CHOLMOD
// solves.
// Value types that own their data (MeshEdgeWalls its flag rows, RegionTile its tile) and
// functions that keep nothing; a solve may use all OpenMP threads. Values dimensionless.
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "dgtex/cut_path.h"
#include "dgtex/kernels/texel_grid.h"
#include "dgtex/laplace_solver.h"

namespace dgtex {

// Texel index (j * T + i) of boundary texel s of local edge k.
int edge_texel_index(ElementType type, int resolution, int edge, int s);
// The local edges (and positions s on them) a texel lies on; returns how many (0..2).
int texel_edges(ElementType type, int resolution, int i, int j, int edges[2], int positions[2]);

// Cross-edge couplings cut by a cut running along a mesh edge.
class MeshEdgeWalls {
 public:
  explicit MeshEdgeWalls(int resolution = 0) : resolution_(resolution) {}
  // Blocks boundary texel s of (element, edge) and its partner across the edge.
  void block(int element, int edge, int s, const ElementAdjacency& adjacency);
  bool blocked(int element, int edge, int s) const {
    const char* row = of_element(element);
    return row && row[edge * resolution_ + s];
  }
  bool empty() const { return rows_.empty(); }
  // The element's flags, index edge * resolution + s (4 edges, also for tri6), or nullptr
  // where none of its edges is blocked: one look-up per element instead of one per texel.
  const char* of_element(int element) const {
    if (rows_.empty()) return nullptr;
    const auto it = rows_.find(element);
    return it != rows_.end() ? it->second.data() : nullptr;
  }
  // Blocked (element, edge, s) of one element as keys (element * 4 + edge) * resolution + s, sorted.
  std::vector<long long> keys_of_element(int element) const;
  int resolution() const { return resolution_; }
  // Every (element, edge, s) as one flag, index (element * 4 + edge) * resolution + s.
  std::vector<char> flags(int num_elements) const;

 private:
  void set(int element, int edge, int s);
  int resolution_;
  std::unordered_map<int, std::vector<char>> rows_;  // element -> 4 * resolution flags
};

struct RegionTile {
  int element = -1;
  kernels::TexelTile tile;  // T x T: walls, inactive, dirichlet bits with values as data
  bool frozen = false;      // every active texel is data (a settled neighbour)
};

struct MeshLaplaceStats {
  int unknowns = 0;
  int solved_components = 0;    // components that needed the linear solve
  int constant_components = 0;  // components set to their single data value
  int solved_tiles = 0, frozen_tiles = 0;
  double relative_residual = 0;
  bool multigrid = false;  // solved by a multigrid (else CHOLMOD, or nothing to solve) ...
  bool algebraic_multigrid = false;  // ... the algebraic one on the texel graph (no planar patch)
  double ms = 0;  // wall time of the whole call
};

// The frozen tiles (indices into `tiles`) holding texels of a component whose data are one
// value, or none, while their stored H is not that constant (for none: the value beyond
// its walls, as solve_mesh_texel_laplace gives it): components of every active texel that
// is not data, across mesh edges and frozen tiles alike, data being the texels with the
// dirichlet bit (set it on frozen tiles' data texels too). A cut that
// closes a region after those tiles settled leaves their harmonic values stale, where the
// solution is now a constant. Reads the tiles only (non-const for TexelGraph).
std::vector<int> stale_frozen_tiles(std::vector<RegionTile>& tiles, ElementType type, const ElementAdjacency& adjacency,
                                    const MeshEdgeWalls& edge_walls);

// Solves in place: free texels of non-frozen tiles get H; data texels keep their values.
// All tiles must be T x T of the same T, elements distinct (std::invalid_argument
// otherwise); std::runtime_error if CHOLMOD fails. With LaplaceSolver::multigrid, regions
// that lie flat (as blocks of tiles or texel by texel) are solved by the tile multigrid on
// one patch tile, the others by algebraic multigrid on the texel graph (graph_laplacian_amg.h),
// both to options.tolerance. CHOLMOD solves the region with LaplaceSolver::cholmod and
// where a multigrid does not converge: simplicial with the AMD ordering. None calls BLAS or
// METIS, so concurrent calls (one segment per thread in CutManager) need no lock and give
// the bits of a serial call.
MeshLaplaceStats solve_mesh_texel_laplace(std::vector<RegionTile>& tiles, ElementType type,
                                          const ElementAdjacency& adjacency, const MeshEdgeWalls& edge_walls,
                                          LaplaceSolver solver = LaplaceSolver::cholmod,
                                          const LaplaceMultigridOptions& options = {});

}  // namespace dgtex
