#pragma once
// From the scene's cuts to the harmonic enrichment functions of the whole mesh, over time
// (thesis §5.5-5.6). Construction traces every cut across the mesh (cut_path.h) and fixes
// its segments (cut_segments.h); update(time) then
//  1. takes the visible part of every segment and rasterises it onto texel edges, per
//     element (kernels::rasterize_cut): walls inside tiles, and cuts running along a mesh
//     edge as blocked couplings between the two elements' boundary texels;
//  2. for each visible segment c_i: Dirichlet +1 / -1 on the texels left / right of its
//     texel edges (across a mesh edge: the texel on each side), E_i = elements holding such
//     texels, N_i = their nodes, Omega_i = all elements incident to N_i;
//  3. solves H_i on Omega_i as one texel graph (mesh_texel_laplace.h): zero Neumann on the
//     walls of all other cuts and on Omega_i's outer boundary, components without data at
//     the one value beyond their walls (else 0), C0 across element edges. While a cut
//     advances only the one-ring of the elements whose data or walls changed is re-solved;
//     the other elements of Omega_i keep their values (settled, thesis §5.5.3) and act as
//     C0 Dirichlet data, except where a cut has closed a region since: a settled element
//     holding texels of a component with one data value (or none) but other values is
//     solved again (stale_frozen_tiles).
// Degenerate cases and their remedies:
//  - a cut along an element edge: the couplings across the edge are cut and the texels on
//    both sides get +-1 (the path is traced in one of the two elements);
//  - a cut through a node: the path passes from one element to the next through the corner
//    lattice point; the couplings around the node are cut by the two elements' paths;
//  - a cut ending exactly on the element (or mesh) boundary: its last lattice point lies on
//    the border, so it separates like any complete cut;
//  - a cut running along the mesh's free boundary separates nothing: those texel edges are
//    dropped (a segment made only of them gets no enrichment);
//  - a self-intersecting cut: split at both passes of its crossing, the loop between them a
//    segment of its own, where the loop is four texels long or more (cut_segments.h);
//  - a fragment shorter than half a texel has no texel edge: no enrichment for it (its
//    H would be 0 and its DOFs singular); fragments of a few texels work as any cut.
//  - segments continuing one crack (the next segment of a cut, a cut starting or ending
//    where another ends, a V of two cuts): on nodes whose support the crack crosses
//    completely both are the same +-1 Heaviside; the later one drops those nodes
//    (enrichment_span.h), else M and K are singular. Where both segments' texel paths
//    end on the same lattice edge (the shared point snaps to one lattice point and each
//    staircase walks to it from its side), that spur is dropped from both (at most 2
//    edges), else its texels get contradicting +-1 data and a V's wedge stays attached.
//  - a segment ending on another cut (the later cut at a crossing, a T-junction) can walk
//    its last edges along the other cut's staircase: they are dropped from its data (the
//    other cut's walls stay), else a texel beyond the other cut gets its +-1 and a region
//    that two cuts close stays attached;
//  - a region that a segment closes with other cuts can reach into elements where only the
//    others' walls bound it (no data of the segment there): where the segment's function
//    is a step (+-1 or 0 at every texel) and takes both +1 and -1 in such an element, the
//    element joins E_i and the function is solved again on the grown Omega_i, in rounds
//    (where both values reach Omega_i's open edges, only for a segment without a free tip).
// CutManager owns its paths, segments, wall tiles and enrichment functions; it keeps a
// reference to the mesh (which must outlive it; the topology is read by the constructor
// only). Not thread-safe; the constructor (one cut per thread) and update() use all
// OpenMP threads. Times in the scene's unit (SI: s), lengths in the mesh's (m).
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "dgtex/cut_path.h"
#include "dgtex/cut_segments.h"
#include "dgtex/enrichment_function.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/mesh.h"
#include "dgtex/mesh_texel_laplace.h"
#include "dgtex/scene.h"
#include "dgtex/texel_memory_estimate.h"
#include "dgtex/topology.h"

namespace dgtex {

struct CutManagerOptions {
  // Re-solve only the one-ring of changed elements when a segment's data change (false:
  // always the whole Omega_i).
  bool freeze_settled_elements = true;
};

// Which segment an enrichment function belongs to.
struct EnrichmentSegment {
  int cut = -1;      // index into the scene's cuts
  int segment = -1;  // segment index along that cut
  double begin = 0, end = 0;  // visible arc range (rest length)
};

struct CutUpdateStats {
  double ms = 0;        // the whole update
  double solve_ms = 0;  // Laplace solves only
  int solves = 0;       // functions (re)solved
  int unknowns = 0;     // texel unknowns over those solves
  int solved_tiles = 0, frozen_tiles = 0;
  int algebraic_multigrid_solves = 0;  // of the solves, those no patch held (mesh_texel_laplace.h)
};

class CutManager {
 public:
  // The mesh must outlive the manager. Throws MeshError for a mesh validate_mesh refuses,
  // std::invalid_argument for a topology that is not build_topology(mesh)'s, for a cut
  // the mesh cannot take (messages name cuts[i].points[j]; see trace_cut_path) and for
  // options or schedules it cannot use (texture_resolution outside 2..4096, a new_cut_length
  // or new_cut_angle_deg that is not a finite number > 0 or a new_cut_length shorter than a
  // texel, a cut's start_time not finite and >= 0, its speed not finite and > 0).
  CutManager(const Mesh& mesh, const Topology& topology, const std::vector<Cut>& cuts,
             const EnrichmentOptions& options, CutManagerOptions manager_options = {});
  // The mesh is kept by reference: a temporary one would dangle, a const one too.
  CutManager(Mesh&&, const Topology&, const std::vector<Cut>&, const EnrichmentOptions&, CutManagerOptions = {}) = delete;
  CutManager(const Mesh&&, const Topology&, const std::vector<Cut>&, const EnrichmentOptions&,
             CutManagerOptions = {}) = delete;

  // Brings the functions to `time` (finite, else std::invalid_argument); true when they
  // changed (added, removed or re-solved). A Laplace solve that fails throws
  // std::runtime_error, memory std::bad_alloc; the manager is then half updated, and every
  // later update throws std::logic_error saying so (it reported "no change" until session
  // 79): discard it, as SceneRun does. Times are
  // meant not to decrease: an update to an earlier time draws the cuts as far as that time,
  // but with CutManagerOptions::freeze_settled_elements it keeps the textures it settled
  // later (0.23 off a fresh manager's at the earlier time, in a test of session 71).
  bool update(double time);

  // The references returned below (and their contents) hold until the next update().
  // One function per visible segment with texel data, in order of first appearance (a
  // function keeps its index while its cut grows). N_i holds only the nodes where H_i adds
  // to the span of the earlier functions (enrichment_span.h); a segment that adds nowhere
  // (it only continues an earlier one's crack) has no function.
  const std::vector<EnrichmentFunction>& functions() const { return functions_; }
  // Enriched nodes dropped at the last update because their function repeated earlier ones.
  int dependent_nodes() const { return dependent_nodes_; }
  const std::vector<EnrichmentSegment>& function_segments() const { return function_segments_; }

  int texture_resolution() const { return resolution_; }
  const std::vector<MeshCutPath>& paths() const { return paths_; }
  // Per cut the segment boundaries 0 = b_0 < ... < b_n = length (all segments, visible or not).
  const std::vector<std::vector<double>>& segment_boundaries() const { return boundaries_; }
  int total_segments() const;
  // The fields of every segment at its full length (texel_memory_estimate.h), from the
  // paths alone, before any update: Omega_i from the elements the segment's path passes
  // through with positive length. The update's E_i are those holding texel data, which
  // can lack an element the path grazes (fracture at T = 32: 274 here against 261, a
  // segment without a function included).
  TexelFootprint full_footprint() const;
  // Walls of all visible cuts in every element they touch (inactive tri6 texels flagged).
  const std::map<int, kernels::TexelTile>& wall_tiles() const { return walls_; }
  const MeshEdgeWalls& edge_walls() const { return edge_walls_; }
  // Rasters of the visible segments: per function (same order) the (element, raster) pieces.
  const std::vector<std::vector<std::pair<int, kernels::CutRaster>>>& rasters() const { return function_rasters_; }
  const CutUpdateStats& last_update() const { return last_; }
  double time() const { return time_; }
  // Every cut wholly visible at time(): no later update changes anything (false before the
  // first update).
  bool complete() const;

  // Writes DIR/enrichment.vdb (DIR created if missing): field "enrichment_NNN" for function
  // NNN (texel (i, j) of element e's tile in slot of e, see texel_storage.h) and field
  // "cut_walls" with the wall flags. std::runtime_error naming the path on failure.
  void save_textures(const std::string& dir) const;

 private:
  struct SegmentState {
    std::map<int, std::uint64_t> wall_hash, data_hash;  // per element of Omega_i at the last solve
    EnrichmentFunction function;  // H_i on every element of Omega_i (sorted by element), all N_i
    // Elements without data of the segment where its step function takes both +1 and -1
    // (a piece it closes with other cuts reaches into them): in E_i as well.
    std::set<int> stepping_elements;
  };
  void rasterize_visible(const std::vector<VisibleCutSegment>& visible,
                         std::vector<std::vector<std::pair<int, kernels::CutRaster>>>& rasters);
  // Drops the lattice edges that two segments sharing an end point both end on (a spur).
  void trim_shared_end_spurs(std::vector<std::vector<std::pair<int, kernels::CutRaster>>>& rasters) const;
  // Drops a segment's first and last lattice edges while another segment's path has them
  // (a segment that ends on another cut walking its last edges along that cut's staircase):
  // they separate as the other cut's; as this segment's data they gave a texel beyond the
  // other cut this segment's +-1. The walls stay (the other segment marks them).
  void trim_ends_along_other_segments(std::vector<std::vector<std::pair<int, kernels::CutRaster>>>& rasters) const;
  // Whether H takes both +1 and -1 on Omega_i's edges toward elements outside it: its two
  // sides may meet beyond Omega_i, so a step there need not be one (fracture's first
  // segment of cut 1); a region the segment closes lies inside Omega_i, and one of its
  // values stays off those edges.
  bool both_values_reach_open_edges(const EnrichmentFunction& function) const;
  bool terminal_key(const std::vector<std::pair<int, kernels::CutRaster>>& pieces, bool at_end,
                    std::pair<long long, long long>& key) const;
  bool edge_identity(int element, const kernels::CutLatticeEdge& edge, long long& id, bool& from_lower) const;

  const Mesh& mesh_;
  ElementAdjacency adjacency_;
  std::vector<Cut> cuts_;
  EnrichmentOptions options_;
  CutManagerOptions manager_options_;
  int resolution_ = 0;
  std::vector<MeshCutPath> paths_;
  std::vector<std::vector<double>> boundaries_;
  std::vector<std::vector<int>> node_elements_;  // elements incident to each node

  // The functions brought to `time` (update's work; update guards it).
  bool update_functions(double time);

  double time_ = -1;
  bool updated_once_ = false;
  bool half_updated_ = false;  // an update threw: the state below is partly the new time's
  std::vector<VisibleCutSegment> visible_;
  std::map<int, kernels::TexelTile> walls_;
  MeshEdgeWalls edge_walls_;
  std::map<std::pair<int, int>, SegmentState> states_;
  std::vector<std::pair<int, int>> order_;  // (cut, segment) by first appearance
  std::vector<EnrichmentFunction> functions_;
  std::vector<EnrichmentSegment> function_segments_;
  std::vector<std::vector<std::pair<int, kernels::CutRaster>>> function_rasters_;
  int dependent_nodes_ = 0;
  bool tip_touches_a_wall_ = false;  // at the last rasterisation: a region may have closed
  // At the last rasterisation, per visible segment: both its ends touch a wall or lie on an
  // element's border (it has no free tip).
  std::vector<char> ends_touch_walls_;
  CutUpdateStats last_;
};

}  // namespace dgtex
