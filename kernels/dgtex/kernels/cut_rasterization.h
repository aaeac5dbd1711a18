#pragma once
// Rasterises a cut polyline onto texel edges: the cut becomes a path on the corner lattice
// of a TexelTile (lattice points at integer texel coordinates, texel (i, j) covers
// [i, i+1] x [j, j+1]), and every lattice edge of that path between two texels of the
// tile sets the wall bit between them (thesis §5.4: "discontinuities are represented as an
// edge path between texels").
//
// Rules (all deterministic, independent of the thread count and of the polyline's
// direction up to reversal of the edge list):
//  - The polyline is clipped to the tile rectangle [0, width] x [0, height]; the clipped
//    end points of each segment snap to the nearest lattice point (halves round up).
//  - Each segment becomes a monotone 4-connected lattice path between its snapped ends:
//    every step moves one unit towards the end, picking the candidate lattice point
//    nearer to the segment's line. Ties pick the point with the larger x + y, then the
//    x step. A segment is always walked from its lexicographically smaller snapped end
//    and the steps reversed if needed, so both directions give the same lattice edges.
//    Segments along lattice lines map to those lines exactly; a segment through lattice
//    points passes through them (a 45° diagonal becomes a staircase).
//  - The larger-(x+y) tie rule makes a cut along a tri6 hypotenuse (x + y = T) follow the
//    boundary of the tri6 active texels (see is_tri6_texel_active below).
//  - A segment whose ends snap to the same lattice point contributes no edge (a cut
//    fragment shorter than half a texel vanishes).
//  - Lattice edges are reported in path order, repeated if the path revisits them
//    (self-intersections and retraced cuts keep every traversal).
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// CutRaster owns its edge list. Positions in texel units (texel (i, j) is [i, i+1] x [j, j+1]).
#include <array>
#include <cstdint>
#include <vector>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/shape_functions.h"
#include "dgtex/kernels/texel_grid.h"

namespace dgtex::kernels {

// A point in continuous texel coordinates (x along xi1, y along xi2, texel corners at integers).
using TexelPoint = std::array<double, 2>;

// One unit step of the cut's lattice path from lattice point (x, y) to (x + dx, y + dy),
// exactly one of dx, dy being +-1. left_texel / right_texel are the texel indices
// (j * width + i) on the left / right of the step direction (left of direction (dx, dy)
// is the side of the normal (-dy, dx)), or -1 where that side is outside the tile or an
// inactive texel (an edge on the element boundary).
struct CutLatticeEdge {
  int x = 0, y = 0;
  int dx = 0, dy = 0;
  int left_texel = -1;
  int right_texel = -1;
};

struct CutRaster {
  std::vector<CutLatticeEdge> edges;  // path order
  // Number of edges with texels on both sides (edges that separate texels; the others lie
  // on the element boundary).
  int interior_edge_count() const;
};

// Reference (serial) and parallel forms: the parallel one rasterises the segments
// concurrently (polylines of 64 segments or more; shorter ones serially) and
// concatenates them in order; both produce identical results. The
// tile's flags gain wall_east / wall_north bits for every path edge between two texels of
// the tile (inactive ones included: walls next to them are harmless). Points must be
// finite; a polyline with fewer than 2 points is an error (std::invalid_argument).
CutRaster rasterize_cut_reference(const std::vector<TexelPoint>& polyline, TexelTile& tile);
CutRaster rasterize_cut(const std::vector<TexelPoint>& polyline, TexelTile& tile,
                        Execution execution = Execution::parallel);

// Splits a rasterised cut wherever its lattice path meets an earlier cut or the domain
// boundary away from its own ends, so that every piece is a cut in the sense of thesis
// §5.4.2 (it ends at the boundary, at a junction, or at its tip). App. A.2's span
// property needs this: a cut crossing another in an X makes 4 components but
// {1, H^1, H^2} spans only 3 dimensions; {1, H^1, H^2a, H^2b} spans all 4. The same holds
// for a cut that touches an earlier cut (or the boundary) and turns back.
// earlier_walls: a tile holding only the walls of the earlier cuts (and the inactive
// texels). A contact is a maximal run of consecutive path vertices on earlier walls or on
// the boundary; the cut is split at the first vertex of every contact that does not run
// into one of the path's ends (a cut ending on another is a T-junction: no split).
// Self-intersections of the cut are not split. Pieces are returned in path order (just
// `cut` when nothing is met). A path scan, O(edges), serial only.
std::vector<CutRaster> split_cut_at_crossings(const CutRaster& cut, const TexelTile& earlier_walls);

// Sets the wall_east / wall_north bits of every edge of `cut` that lies between two texels
// of the tile (what rasterize_cut does for its own path): for rasters the caller edited,
// e.g. with a dangling end trimmed. Serial only.
void mark_cut_walls(const CutRaster& cut, TexelTile& tile);
// Element parameter coordinates -> continuous texel coordinates of a T x T tile:
// quad8: x = (xi1 + 1) T / 2, y = (xi2 + 1) T / 2; tri6: x = xi1 T, y = xi2 T (the tri6
// triangle is the lower-left half of the tile).
TexelPoint texel_point_from_parametric(ElementType type, int resolution, double xi1, double xi2);
// The inverse map, for texel centres use (i + 0.5, j + 0.5).
std::array<double, 2> parametric_from_texel_point(ElementType type, int resolution, TexelPoint point);

// tri6 tiles: texel (i, j) is active iff i + j <= T - 1, i.e. iff its centre lies in the
// closed triangle x + y <= T. The T half-covered texels on the diagonal are active; the
// hypotenuse is the lattice staircase through the points with x + y in {T, T + 1}.
inline bool is_tri6_texel_active(int i, int j, int resolution) { return i + j <= resolution - 1; }
// A fresh T x T tile for an element: all flags clear, tri6 texels outside marked inactive.
TexelTile make_element_tile(ElementType type, int resolution);

}  // namespace dgtex::kernels
