#include "dgtex/cut_manager.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>

#include <omp.h>

#include "api_argument_checks.h"
#include "cut_sides_meet.h"
#include "dgtex/enrichment_span.h"
#include "dgtex/kernels/forall.h"
#include "dgtex/stage_timer.h"
#include "dgtex/surface_point.h"
#include "dgtex/texel_storage.h"
#include "shell_model_inputs.h"

namespace dgtex {
namespace {

using kernels::CutLatticeEdge;
using kernels::CutRaster;
using kernels::TexelTile;

// H on element e at the function's last solve (its elements are sorted), or nullptr where
// e was not in its Omega.
const std::vector<double>* solved_values(const EnrichmentFunction& f, int e) {
  const auto before = [](const ElementTexture& texture, int element) { return texture.element < element; };
  const auto it = std::lower_bound(f.elements.begin(), f.elements.end(), e, before);
  return it != f.elements.end() && it->element == e ? &it->tile.values : nullptr;
}

// A lattice edge of a raster on the element's border (one side outside the element).
struct BorderEdge {
  int edge = -1, s = -1;
  int inside_texel = -1;
  int side = 0;  // +1: the inside texel is left of the cut's direction
};

bool classify_border(ElementType type, int t, const CutLatticeEdge& e, BorderEdge& out) {
  if ((e.left_texel >= 0) == (e.right_texel >= 0)) return false;  // interior, or outside the element
  out.inside_texel = e.left_texel >= 0 ? e.left_texel : e.right_texel;
  out.side = e.left_texel >= 0 ? +1 : -1;
  const int i = out.inside_texel % t, j = out.inside_texel / t;
  if (e.dy == 0) {  // horizontal lattice edge at height e.y
    if (e.y == 0) return out.edge = 0, out.s = i, true;
    if (type == ElementType::quad8 && e.y == t) return out.edge = 2, out.s = t - 1 - i, true;
  } else {  // vertical at e.x
    if (e.x == 0) return out.edge = type == ElementType::quad8 ? 3 : 2, out.s = t - 1 - j, true;
    if (type == ElementType::quad8 && e.x == t) return out.edge = 1, out.s = j, true;
  }
  if (type == ElementType::tri6 && i + j == t - 1) return out.edge = 1, out.s = j, true;  // hypotenuse staircase
  return false;
}

// A segment's Dirichlet data: element -> (texel, value) in texel order.
using TexelData = std::map<int, std::vector<std::pair<int, double>>>;

// Every traversal of a texel edge adds its side (+1 left, -1 right) to the two texels it
// separates (across a mesh edge: the texel on each side), summed per (texel, physical edge).
// A retrace (the path stepping past a snapped corner and back, inside an element or along
// a mesh edge from both elements) sums to 0 and is ignored; a texel's value is the mean of
// the signs of its remaining edges (so a texel left of one pass and right of another gets
// 0, as in set_cut_dirichlet). The sides are sorted, not inserted into a map (fracture's
// six segments: 1.0 -> 0.4 ms).
TexelData dirichlet_data(const std::vector<std::pair<int, CutRaster>>& pieces, ElementType type, int t,
                         const ElementAdjacency& adjacency) {
  struct Side {
    long long texel, edge;  // texel: element * T^2 + index; edge: the physical edge's id
    int side;
    bool operator<(const Side& o) const { return texel != o.texel ? texel < o.texel : edge < o.edge; }
  };
  std::vector<Side> sides;
  const long long tt = static_cast<long long>(t) * t;
  for (const auto& [e, raster] : pieces) {
    // The previous lattice edge's pass along a mesh edge (id 0: none). A tri6 hypotenuse
    // texel's top and east edges, one after the other, pass the same stretch s of it: one
    // pass, as the neighbour's leg makes with its one lattice edge there. Counted twice, a
    // retrace of a stretch from both elements (a loop's corner where a side along the
    // hypotenuse meets one along a leg) summed to +-1 instead of 0: a texel outside the
    // loop got 0 instead of -1, and the loop's function was harmonic, not a step (the
    // piece stayed held: -0.016 instead of -0.505; session 74).
    long long previous_id = 0;
    int previous_side = 0;
    for (const CutLatticeEdge& edge : raster.edges) {
      if (edge.left_texel >= 0 && edge.right_texel >= 0) {
        const long long id = ((static_cast<long long>(e) * (t + 1) + std::min(edge.x, edge.x + edge.dx)) * (t + 1) +
                              std::min(edge.y, edge.y + edge.dy)) * 2 + (edge.dy == 0);
        sides.push_back({e * tt + edge.left_texel, id, +1});
        sides.push_back({e * tt + edge.right_texel, id, -1});
        previous_id = 0;
        continue;
      }
      BorderEdge b;
      const bool border = classify_border(type, t, edge, b);
      const auto nb = border ? adjacency.neighbour(e, b.edge) : std::array<int, 2>{-1, -1};
      if (nb[0] < 0) {  // not on a mesh edge, or along the free boundary: separates nothing
        previous_id = 0;
        continue;
      }
      const long long here = (static_cast<long long>(e) * 4 + b.edge) * t + b.s;
      const long long there = (static_cast<long long>(nb[0]) * 4 + nb[1]) * t + (t - 1 - b.s);
      const long long id = -1 - std::min(here, there);
      if (id == previous_id && b.side == previous_side) continue;
      previous_id = id, previous_side = b.side;
      sides.push_back({e * tt + b.inside_texel, id, b.side});
      sides.push_back({nb[0] * tt + edge_texel_index(type, t, nb[1], t - 1 - b.s), id, -b.side});
    }
  }
  std::sort(sides.begin(), sides.end());
  TexelData data;
  for (std::size_t k = 0; k < sides.size();) {
    const long long texel = sides[k].texel;
    double signs = 0;
    int count = 0;
    while (k < sides.size() && sides[k].texel == texel) {  // each edge of this texel
      const long long edge = sides[k].edge;
      int sum = 0;
      for (; k < sides.size() && sides[k].texel == texel && sides[k].edge == edge; ++k) sum += sides[k].side;
      if (sum != 0) signs += sum > 0 ? 1.0 : -1.0, count += 1;
    }
    if (count > 0) data[static_cast<int>(texel / tt)].emplace_back(static_cast<int>(texel % tt), signs / count);
  }
  return data;
}

std::uint64_t fnv(std::uint64_t h, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t k = 0; k < bytes; ++k) h = (h ^ p[k]) * 1099511628211ull;
  return h;
}
constexpr std::uint64_t kFnvSeed = 1469598103934665603ull;


// Two segments that share an end point P (a cut starting where another ends, a V, the
// next segment of one cut) can both reach P's lattice point over the same lattice edge:
// P snaps to the nearest lattice point, and each staircase walks to it from its own side
// (in one element, or from the two sides of a mesh edge along it). The union of the two
// paths then has a spur, a wall with a free end, whose texels get the left/right data of
// both segments, which contradicts the sides of the crack (at a V's tip the texel beside
// the spur gets +1 of one arm though it lies outside the wedge, so the wedge stays
// attached there). Within one segment such a retrace cancels in the data; across
// segments the shared edges are dropped from both, at most kMaxSpurEdges per pair
// (snapping moves P by at most half a texel per axis; a longer overlap is a crack drawn
// twice and stays).
constexpr int kMaxSpurEdges = 2;

using RasterPieces = std::vector<std::pair<int, CutRaster>>;

// Drops the first or last lattice edge of a segment's raster (and its piece, left empty).
void pop_terminal_edge(RasterPieces& pieces, bool at_end) {
  auto& edges = (at_end ? pieces.back() : pieces.front()).second.edges;
  if (at_end) edges.pop_back();
  else edges.erase(edges.begin());
  if (!edges.empty()) return;
  if (at_end) pieces.pop_back();
  else pieces.erase(pieces.begin());
}

// Lattice coordinate along a border edge of a lattice point on it, in the numbering of
// classify_border's s (texel s spans [q, q + 1]); -1 on the tri6 hypotenuse staircase.
int border_coordinate(ElementType type, int t, int edge, int x, int y) {
  if (edge == 0) return x;
  if (type == ElementType::quad8) {
    if (edge == 1) return y;
    if (edge == 2) return t - x;
    return t - y;
  }
  return edge == 2 ? t - y : -1;
}

}  // namespace

// Physical identity of a raster edge of element e: the same from both sides of a mesh
// edge; false where it has none (a free-boundary edge, the tri6 hypotenuse). `from_lower`:
// whether e is the side the border numbering is counted from.
bool CutManager::edge_identity(int e, const CutLatticeEdge& edge, long long& id, bool& from_lower) const {
  const int t = resolution_;
  from_lower = true;
  if (edge.left_texel >= 0 && edge.right_texel >= 0) {
    id = ((static_cast<long long>(e) * (t + 1) + std::min(edge.x, edge.x + edge.dx)) * (t + 1) +
          std::min(edge.y, edge.y + edge.dy)) * 2 + (edge.dy == 0);
    return true;
  }
  BorderEdge b;
  if (!classify_border(mesh_.type, t, edge, b)) return false;
  const auto nb = adjacency_.neighbour(e, b.edge);
  if (nb[0] < 0) return false;
  const long long here = (static_cast<long long>(e) * 4 + b.edge) * t + b.s;
  const long long there = (static_cast<long long>(nb[0]) * 4 + nb[1]) * t + (t - 1 - b.s);
  from_lower = here <= there;
  id = -1 - std::min(here, there);
  return true;
}

// Physical identity of a segment's terminal: (edge id, terminal point).
bool CutManager::terminal_key(const std::vector<std::pair<int, CutRaster>>& pieces, bool at_end,
                              std::pair<long long, long long>& key) const {
  const int t = resolution_;
  const int e = at_end ? pieces.back().first : pieces.front().first;
  const CutLatticeEdge& edge = at_end ? pieces.back().second.edges.back() : pieces.front().second.edges.front();
  const int px = at_end ? edge.x + edge.dx : edge.x, py = at_end ? edge.y + edge.dy : edge.y;
  bool from_lower = true;
  if (!edge_identity(e, edge, key.first, from_lower)) return false;
  if (key.first >= 0) {
    key.second = static_cast<long long>(px) * (t + 1) + py;
    return true;
  }
  BorderEdge b;
  classify_border(mesh_.type, t, edge, b);
  const int q = border_coordinate(mesh_.type, t, b.edge, px, py);
  if (q < 0) return false;
  key.second = from_lower ? q : t - q;
  return true;
}

void CutManager::trim_shared_end_spurs(std::vector<std::vector<std::pair<int, CutRaster>>>& rasters) const {
  // A segment whose path ends by stepping one lattice edge into an element and straight
  // back (its end point snapped onto the border it had crossed) cancels that retrace in its
  // own data, but the retrace hid the edge before it, which the next segment shares, from
  // the matching below: that edge's +-1 then reached a texel outside the loop they close,
  // and the segment's function was no step (a tri6 triangle at T = 32; session 74).
  const auto walked_back = [](const CutLatticeEdge& first, const CutLatticeEdge& second) {
    return second.x == first.x + first.dx && second.y == first.y + first.dy && second.dx == -first.dx &&
           second.dy == -first.dy;
  };
  for (RasterPieces& pieces : rasters)
    for (const bool at_end : {false, true})
      while (!pieces.empty()) {
        const std::vector<CutLatticeEdge>& edges = (at_end ? pieces.back() : pieces.front()).second.edges;
        if (edges.size() < 2) break;
        if (at_end ? !walked_back(edges[edges.size() - 2], edges.back()) : !walked_back(edges[0], edges[1])) break;
        pop_terminal_edge(pieces, at_end);
        pop_terminal_edge(pieces, at_end);
      }
  struct SegmentEnd {
    std::size_t segment;
    bool at_end;  // the end of the segment's path (else its start)
  };
  std::vector<SegmentEnd> ends;
  for (std::size_t v = 0; v < rasters.size(); ++v)
    if (!rasters[v].empty()) ends.push_back({v, false}), ends.push_back({v, true});
  for (std::size_t i = 0; i < ends.size(); ++i)
    for (std::size_t j = i + 1; j < ends.size(); ++j) {
      const SegmentEnd a = ends[i], b = ends[j];
      if (a.segment == b.segment) continue;  // a closed loop: its retrace cancels in the data
      RasterPieces &pa = rasters[a.segment], &pb = rasters[b.segment];
      for (int trimmed = 0; trimmed < kMaxSpurEdges && !pa.empty() && !pb.empty(); ++trimmed) {
        std::pair<long long, long long> ka, kb;
        if (!terminal_key(pa, a.at_end, ka) || !terminal_key(pb, b.at_end, kb) || ka != kb) break;
        pop_terminal_edge(pa, a.at_end);
        pop_terminal_edge(pb, b.at_end);
      }
    }
}

bool CutManager::both_values_reach_open_edges(const EnrichmentFunction& function) const {
  std::set<int> omega;
  for (const ElementTexture& texture : function.elements) omega.insert(texture.element);
  bool plus = false, minus = false;
  for (const ElementTexture& texture : function.elements)
    for (int k = 0; k < adjacency_.edges_per_element(); ++k) {
      const int beyond = adjacency_.neighbour(texture.element, k)[0];
      if (beyond < 0 || omega.count(beyond)) continue;  // the mesh's boundary, or inside Omega_i
      for (int s = 0; s < resolution_; ++s) {
        const double value = texture.tile.values[edge_texel_index(mesh_.type, resolution_, k, s)];
        plus = plus || value == 1;
        minus = minus || value == -1;
      }
    }
  return plus && minus;
}

void CutManager::trim_ends_along_other_segments(std::vector<RasterPieces>& rasters) const {
  if (rasters.size() < 2) return;
  struct Holder {
    long long edge;
    std::size_t segment;
    int traversals;
    bool operator<(const Holder& o) const { return edge != o.edge ? edge < o.edge : segment < o.segment; }
  };
  std::vector<Holder> holders;  // sorted by (edge id, segment), one entry per pair
  long long id = 0;
  bool from_lower = true;
  for (std::size_t v = 0; v < rasters.size(); ++v)
    for (const auto& [e, raster] : rasters[v])
      for (const CutLatticeEdge& edge : raster.edges)
        if (edge_identity(e, edge, id, from_lower)) holders.push_back({id, v, 1});
  std::sort(holders.begin(), holders.end());
  std::size_t unique = 0;
  for (std::size_t i = 0; i < holders.size(); ++i) {
    if (unique > 0 && holders[unique - 1].edge == holders[i].edge && holders[unique - 1].segment == holders[i].segment)
      ++holders[unique - 1].traversals;
    else holders[unique++] = holders[i];
  }
  holders.resize(unique);
  for (std::size_t v = 0; v < rasters.size(); ++v)
    for (const bool at_end : {false, true})
      while (!rasters[v].empty()) {
        const auto& [e, raster] = at_end ? rasters[v].back() : rasters[v].front();
        if (!edge_identity(e, at_end ? raster.edges.back() : raster.edges.front(), id, from_lower)) break;
        const auto first = std::lower_bound(holders.begin(), holders.end(), Holder{id, 0, 0});
        Holder* own = nullptr;
        bool held_by_another = false;
        for (auto h = first; h != holders.end() && h->edge == id; ++h) {
          if (h->segment == v) own = &*h;
          else if (h->traversals > 0) held_by_another = true;
        }
        if (!held_by_another || own == nullptr) break;
        pop_terminal_edge(rasters[v], at_end);
        --own->traversals;
      }
}


namespace {

// What validate_scene takes of the cuts' schedules and the options the manager reads, for
// a caller that builds them in code: a NaN speed or angle was taken silently (the cut never
// appeared, or split nowhere), and a resolution of 65536 allocated a 32 GiB tile.
void check_cut_options(const std::vector<Cut>& cuts, const EnrichmentOptions& options) {
  auto refuse = [](const std::string& what, double value, const std::string& valid) {
    throw std::invalid_argument("CutManager: " + what + " is " + detail::short_number(value) + "; expected " + valid);
  };
  const int T = options.texture_resolution;
  if (T < 2 || T > kMaxTextureResolution)
    refuse("enrichment.texture_resolution", T,
           "2.." + std::to_string(kMaxTextureResolution) + " (a scene file: a power of two in " +
               std::to_string(kMinTextureResolution) + "..)");
  if (options.new_cut_length && !(std::isfinite(*options.new_cut_length) && *options.new_cut_length > 0))
    refuse("enrichment.new_cut_length", *options.new_cut_length, "a finite number > 0");
  if (options.new_cut_angle_deg && !(std::isfinite(*options.new_cut_angle_deg) && *options.new_cut_angle_deg > 0))
    refuse("enrichment.new_cut_angle_deg", *options.new_cut_angle_deg, "a finite number > 0");
  for (size_t c = 0; c < cuts.size(); ++c) {
    const std::string path = "cuts[" + std::to_string(c) + "]";
    if (!(std::isfinite(cuts[c].start_time) && cuts[c].start_time >= 0))
      refuse(path + ".start_time", cuts[c].start_time, "a finite number >= 0");
    if (cuts[c].speed && !(std::isfinite(*cuts[c].speed) && *cuts[c].speed > 0))
      refuse(path + ".speed", *cuts[c].speed, "a finite number > 0");
  }
}

}  // namespace

CutManager::CutManager(const Mesh& mesh, const Topology& topology, const std::vector<Cut>& cuts,
                       const EnrichmentOptions& options, CutManagerOptions manager_options)
    // Checked before the adjacency reads them: a topology of another (finer) mesh wrote
    // out of bounds there, and a bad node index read out of bounds in the point search.
    : mesh_((detail::check_mesh_and_topology("CutManager", mesh, topology), mesh)),
      adjacency_(mesh, topology),
      cuts_(cuts),
      options_(options),
      manager_options_(manager_options),
      resolution_(options.texture_resolution),
      edge_walls_(options.texture_resolution) {
  check_cut_options(cuts, options);
  // The cuts trace independently (each reads only the mesh and the one search), one per
  // thread: fracture's six took 9.7 ms in a row. The first failing cut's error is the one
  // reported, as in a loop.
  const int count = static_cast<int>(cuts_.size());
  paths_.resize(cuts_.size());
  std::vector<std::exception_ptr> failures(cuts_.size());
  const SurfacePointSearch search(mesh);
  kernels::forall_dynamic(
      count,
      [&](std::int64_t c) {
        try {
          const std::string where = "cuts[" + std::to_string(c) + "]";
          paths_[c] = trace_cut_path(mesh, search, adjacency_, cuts_[c], resolution_, where);
        } catch (...) {
          failures[c] = std::current_exception();
        }
      },
      count > 1 && !omp_in_parallel() ? kernels::Execution::parallel : kernels::Execution::serial);
  for (const std::exception_ptr& failure : failures)
    if (failure) std::rethrow_exception(failure);
  // Boundaries closer than half a texel (of a mean-sized element) are merged.
  const double texel = cut_point_tolerance(mesh) * 4.0 / resolution_;
  // A segment shorter than a texel would have no texels of its own, and a length below the
  // spacing of doubles at the cut's arc length would never advance the segmentation.
  if (options_.new_cut_length && *options_.new_cut_length < texel) {
    std::ostringstream message;
    message << std::setprecision(6) << "enrichment.new_cut_length: a cut segment cannot be shorter than a texel, got "
            << *options_.new_cut_length << "; expected " << texel << " or more (the mean element edge / "
            << "texture_resolution " << resolution_ << ")";
    throw std::invalid_argument(message.str());
  }
  boundaries_ = segment_cut_paths(paths_, cuts_, options_, 0.5 * texel);
  node_elements_.assign(mesh.num_nodes(), {});
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int a = 0; a < mesh.nodes_per_element(); ++a) node_elements_[mesh.element_nodes(e)[a]].push_back(e);
}

int CutManager::total_segments() const {
  int n = 0;
  for (const auto& b : boundaries_) n += static_cast<int>(b.size()) - 1;
  return n;
}

TexelFootprint CutManager::full_footprint() const {
  TexelFootprint footprint;
  for (std::size_t c = 0; c < boundaries_.size(); ++c)
    for (std::size_t k = 0; k + 1 < boundaries_[c].size(); ++k) {
      std::set<int> omega;
      for (int e : elements_passed_through(sub_path(paths_[c], boundaries_[c][k], boundaries_[c][k + 1])))
        for (int a = 0; a < mesh_.nodes_per_element(); ++a)
          for (int f : node_elements_[mesh_.element_nodes(e)[a]]) omega.insert(f);
      footprint.region_elements += static_cast<std::int64_t>(omega.size());
      ++footprint.fields;
    }
  return footprint;
}

bool CutManager::complete() const {
  if (!updated_once_) return false;
  for (std::size_t c = 0; c < boundaries_.size(); ++c)
    if (visible_cut_length(cuts_[c], boundaries_[c].back(), time_) < boundaries_[c].back()) return false;
  return true;
}

void CutManager::rasterize_visible(const std::vector<VisibleCutSegment>& visible,
                                   std::vector<std::vector<std::pair<int, CutRaster>>>& rasters) {
  walls_.clear();
  edge_walls_ = MeshEdgeWalls(resolution_);
  rasters.assign(visible.size(), {});
  const TexelTile blank = kernels::make_element_tile(mesh_.type, resolution_);
  for (std::size_t v = 0; v < visible.size(); ++v) {
    const std::vector<CutPathVertex> sub = sub_path(paths_[visible[v].cut], visible[v].begin, visible[v].end);
    std::size_t run = 0;
    while (run < sub.size()) {
      std::size_t stop = run + 1;
      while (stop < sub.size() && sub[stop].element == sub[run].element) ++stop;
      if (stop - run >= 2) {
        const int e = sub[run].element;
        std::vector<kernels::TexelPoint> line;
        for (std::size_t k = run; k < stop; ++k)
          line.push_back(kernels::texel_point_from_parametric(mesh_.type, resolution_, sub[k].xi[0], sub[k].xi[1]));
        if (walls_.find(e) == walls_.end()) walls_.emplace(e, blank);
        TexelTile scratch = blank;  // walls are marked below, after the spurs are trimmed
        CutRaster raster = kernels::rasterize_cut(line, scratch);
        if (!raster.edges.empty()) rasters[v].emplace_back(e, std::move(raster));
      }
      run = stop;
    }
  }
  trim_shared_end_spurs(rasters);
  trim_ends_along_other_segments(rasters);
  for (const auto& pieces : rasters)
    for (const auto& [e, raster] : pieces) kernels::mark_cut_walls(raster, walls_.at(e));
  // Whether a segment's end touches a wall other than its own edge there and the adjacent
  // segment's of the same cut, or lies on its element's border (not looked at closer): only
  // where an end does can this update have closed a region; where both do, the segment has
  // no free tip.
  tip_touches_a_wall_ = false;
  ends_touch_walls_.assign(rasters.size(), 0);
  const int t = resolution_;
  auto touches_a_wall = [&](int e, int x, int y, bool continued) {
    if (x <= 0 || y <= 0 || x >= t || y >= t || (mesh_.type == ElementType::tri6 && x + y >= t - 1)) return true;
    const TexelTile& walls = walls_.at(e);
    const int walls_at_point = walls.is_wall_north(x - 1, y - 1) + walls.is_wall_north(x, y - 1) +
                               walls.is_wall_east(x - 1, y - 1) + walls.is_wall_east(x - 1, y);
    return walls_at_point >= (continued ? 3 : 2);
  };
  auto continues = [&](std::size_t a, std::size_t b) {  // segment b follows segment a along one cut
    return visible[b].cut == visible[a].cut && visible[b].segment == visible[a].segment + 1 && !rasters[a].empty() &&
           !rasters[b].empty();
  };
  for (std::size_t v = 0; v < rasters.size(); ++v) {
    const auto& pieces = rasters[v];
    if (pieces.empty()) continue;
    const CutLatticeEdge& first = pieces.front().second.edges.front();
    const CutLatticeEdge& last = pieces.back().second.edges.back();
    // A loop ends where it started. Its last lattice edge can retrace its first (the end
    // point snapped back across the start's first edge, the retrace cancelling in the data):
    // then only that edge touches the end point, and the loop was not seen to close: its
    // settled tiles kept their harmonic values and the piece stayed attached (a triangle cut
    // progressively on tri6 fell 0.21 instead of 0.505; 16 of 90 such loops, until session
    // 81).
    const bool closed = pieces.back().first == pieces.front().first && last.x + last.dx == first.x &&
                        last.y + last.dy == first.y;
    const bool end = closed || touches_a_wall(pieces.back().first, last.x + last.dx, last.y + last.dy,
                                              v + 1 < rasters.size() && continues(v, v + 1));
    const bool start =
        closed || touches_a_wall(pieces.front().first, first.x, first.y, v > 0 && continues(v - 1, v));
    tip_touches_a_wall_ = tip_touches_a_wall_ || end;
    ends_touch_walls_[v] = start && end;
  }
  // Cuts along mesh edges cut the couplings between the two elements' boundary texels.
  for (const auto& pieces : rasters)
    for (const auto& [e, raster] : pieces)
      for (const CutLatticeEdge& edge : raster.edges) {
        BorderEdge b;
        if (classify_border(mesh_.type, resolution_, edge, b) && adjacency_.neighbour(e, b.edge)[0] >= 0)
          edge_walls_.block(e, b.edge, b.s, adjacency_);
      }
}

bool CutManager::update(double time) {
  if (!std::isfinite(time)) throw std::invalid_argument("CutManager::update: time " + std::to_string(time) + " is not finite");
  if (half_updated_)
    throw std::logic_error("CutManager::update: an earlier update failed and left this manager half updated (its "
                           "walls, textures and functions partly of that update's time); build a new one");
  half_updated_ = true;  // until the update completes: an exception leaves it set
  const bool changed = update_functions(time);
  half_updated_ = false;
  return changed;
}

bool CutManager::update_functions(double time) {
  const auto start = std::chrono::steady_clock::now();
  last_ = CutUpdateStats{};
  time_ = time;
  std::vector<VisibleCutSegment> visible = visible_cut_segments(boundaries_, cuts_, time);
  const auto same = [](const VisibleCutSegment& a, const VisibleCutSegment& b) {
    return a.cut == b.cut && a.segment == b.segment && a.begin == b.begin && a.end == b.end;
  };
  if (updated_once_ && visible.size() == visible_.size() && std::equal(visible.begin(), visible.end(), visible_.begin(), same)) {
    last_.ms = ms_since(start);
    return false;
  }
  updated_once_ = true;
  visible_ = visible;
  std::vector<std::vector<std::pair<int, CutRaster>>> rasters;
  rasterize_visible(visible, rasters);

  const int t = resolution_;
  const TexelTile blank = kernels::make_element_tile(mesh_.type, t);  // an element without cut walls
  std::map<int, std::uint64_t> wall_hash_cache;
  auto wall_hash = [&](int e) {
    auto it = wall_hash_cache.find(e);
    if (it != wall_hash_cache.end()) return it->second;
    std::uint64_t h = kFnvSeed;
    const auto w = walls_.find(e);
    if (w != walls_.end()) h = fnv(h, w->second.flags.data(), w->second.flags.size());
    if (const char* blocked = edge_walls_.of_element(e)) h = fnv(h, blocked, 4 * static_cast<std::size_t>(t));
    return wall_hash_cache[e] = h;
  };

  // Per segment whose H must be (re)solved: its region and what to store with the result.
  struct SolveJob {
    std::pair<int, int> key;
    std::vector<RegionTile> region;
    std::map<int, std::uint64_t> data_hash;
    std::vector<int> enriched_nodes;  // N_i: the nodes of E_i, sorted
  };
  bool changed_any = false;
  std::set<std::pair<int, int>> alive;
  std::map<std::pair<int, int>, std::size_t> visible_index;
  std::vector<TexelData> segment_data(visible.size());
  std::vector<std::size_t> to_solve;  // visible segments with data
  for (std::size_t v = 0; v < visible.size(); ++v) {
    const std::pair<int, int> key{visible[v].cut, visible[v].segment};
    visible_index[key] = v;
    segment_data[v] = dirichlet_data(rasters[v], mesh_.type, t, adjacency_);
    if (segment_data[v].empty()) continue;  // no texel edge: no enrichment
    alive.insert(key);
    to_solve.push_back(v);
  }
  // Rounds: a step function that takes both +1 and -1 in an element outside E_i (a region
  // it closes with other cuts reaches into an element where only the others' walls bound
  // it) adds that element to E_i and is solved again on the grown Omega_i. Without its
  // enrichment at that element's nodes, the region's part there stayed attached (a bar
  // across a U on tri6 whose bar lies in one triangle: -0.072 instead of -0.505; session 73).
  std::map<std::pair<int, int>, SegmentState> before_growth;
  std::map<std::pair<int, int>, bool> sides_meet;  // per segment: detail::every_side_meets_the_other
  for (;;) {
    std::vector<SolveJob> jobs;
    for (const std::size_t v : to_solve) {
      const std::pair<int, int> key{visible[v].cut, visible[v].segment};
      const TexelData& data = segment_data[v];
      auto state_it = states_.find(key);
      const bool fresh = state_it == states_.end();
      if (fresh) {
        state_it = states_.emplace(key, SegmentState{}).first;
        order_.push_back(key);
      }
      SegmentState& state = state_it->second;

      // E_i, N_i, Omega_i.
      std::set<int> e_i = state.stepping_elements;
      for (const auto& [e, texels] : data) e_i.insert(e);
      std::set<int> nodes, omega;
      for (int e : e_i)
        for (int a = 0; a < mesh_.nodes_per_element(); ++a) nodes.insert(mesh_.element_nodes(e)[a]);
      for (int n : nodes)
        for (int e : node_elements_[n]) omega.insert(e);
      std::map<int, std::uint64_t> data_hash;
      for (int e : omega) {
        std::uint64_t h = kFnvSeed;
        const auto it = data.find(e);
        if (it != data.end())
          for (const auto& [texel, value] : it->second) {
            h = fnv(h, &texel, sizeof texel);
            h = fnv(h, &value, sizeof value);
          }
        data_hash[e] = h;
      }

      std::set<int> changed;
      for (int e : omega) {
        const bool known = solved_values(state.function, e) != nullptr;
        if (!known || state.wall_hash[e] != wall_hash(e) || state.data_hash[e] != data_hash[e]) changed.insert(e);
      }
      bool omega_same = state.function.elements.size() == omega.size();
      if (omega_same)
        for (const ElementTexture& texture : state.function.elements)
          omega_same = omega_same && omega.count(texture.element) > 0;
      if (changed.empty() && omega_same) {  // settled: keep H_i
        // A round that adds an element whose nodes' elements were all in Omega_i already
        // gives the same H_i, but N_i gains the element's nodes: without them the region's
        // part there stayed attached (a square cut as a U and a bar on a 2 x 2 tri6 plate:
        // -0.176 instead of -0.505, swinging sideways; session 74).
        std::vector<int> grown_nodes(nodes.begin(), nodes.end());
        if (state.function.enriched_nodes != grown_nodes) {
          state.function.enriched_nodes = std::move(grown_nodes);
          changed_any = true;
        }
        continue;
      }

      std::set<int> solve;
      if (fresh || !manager_options_.freeze_settled_elements) {
        solve = omega;
      } else {
        for (int e : changed)
          for (int a = 0; a < mesh_.nodes_per_element(); ++a)
            for (int f : node_elements_[mesh_.element_nodes(e)[a]])
              if (omega.count(f)) solve.insert(f);
      }
      SolveJob job;
      job.key = key;
      job.data_hash = std::move(data_hash);
      job.enriched_nodes.assign(nodes.begin(), nodes.end());
      for (int e : omega) {
        RegionTile r;
        r.element = e;
        r.frozen = solve.count(e) == 0;  // then e is known: unknown elements are changed ones
        // The element's walls, and its previous H where it has one: a frozen tile's data, else
        // the initial guess (used by the multigrid; CHOLMOD ignores it). Copied once each.
        const auto w = walls_.find(e);
        const TexelTile& walled = w != walls_.end() ? w->second : blank;
        const std::vector<double>* previous = solved_values(state.function, e);
        r.tile.width = walled.width, r.tile.height = walled.height;
        r.tile.flags = walled.flags;
        r.tile.values = previous ? *previous : walled.values;
        const auto it = data.find(e);
        if (it != data.end())  // a frozen tile's data texels hold their values already
          for (const auto& [texel, value] : it->second) {
            r.tile.flags[texel] |= kernels::dirichlet;
            r.tile.values[texel] = value;
          }
        job.region.push_back(std::move(r));
      }
      // A cut that closes a region (a loop's last texel edge) changes H beyond the one-ring
      // it touches: the region's component is now constant. Its settled tiles are solved
      // again, else they kept their harmonic values (a progressive loop on tri6 whose region
      // spans two triangles: 0.033 off a fresh solve, the piece held; session 73).
      if (tip_touches_a_wall_)
        for (const int l : stale_frozen_tiles(job.region, mesh_.type, adjacency_, edge_walls_))
          job.region[l].frozen = false;
      jobs.push_back(std::move(job));
    }

    // The solves of different segments are independent (each reads only the walls and its
    // own settled values): one per thread when there are several (fewer synchronisations
    // than a parallel multigrid per tile). Each solve runs the same operations whatever
    // thread takes it, the regions that need CHOLMOD included (solve_mesh_texel_laplace's
    // direct solve is lock-free), so the results do not depend on the thread count.
    const LaplaceSolver solver =
        options_.solver == EnrichmentOptions::Solver::multigrid ? LaplaceSolver::multigrid : LaplaceSolver::cholmod;
    std::vector<MeshLaplaceStats> job_stats(jobs.size());
    std::vector<std::exception_ptr> failures(jobs.size());
    const auto solve_start = std::chrono::steady_clock::now();
    // Inside the concurrent loop each multigrid runs its serial kernels (the same results
    // as the parallel forms): nested parallel regions would cost a team per kernel call.
    const bool concurrent = jobs.size() > 1 && omp_get_max_threads() > 1 && !omp_in_parallel();
    LaplaceMultigridOptions multigrid_options;
    if (concurrent) multigrid_options.execution = kernels::Execution::serial;
    auto solve_job = [&](std::size_t k) {
      try {
        job_stats[k] = solve_mesh_texel_laplace(jobs[k].region, mesh_.type, adjacency_, edge_walls_, solver,
                                                multigrid_options);
      } catch (...) {
        failures[k] = std::current_exception();
      }
    };
    kernels::forall_dynamic(
        static_cast<std::int64_t>(jobs.size()), [&](std::int64_t k) { solve_job(static_cast<std::size_t>(k)); },
        concurrent ? kernels::Execution::parallel : kernels::Execution::serial);
    for (const std::exception_ptr& failure : failures)
      if (failure) std::rethrow_exception(failure);
    last_.solve_ms += ms_since(solve_start);

    for (std::size_t k = 0; k < jobs.size(); ++k) {
      SolveJob& job = jobs[k];
      const MeshLaplaceStats& stats = job_stats[k];
      last_.solves += 1;
      last_.unknowns += stats.unknowns;
      last_.solved_tiles += stats.solved_tiles;
      last_.frozen_tiles += stats.frozen_tiles;
      last_.algebraic_multigrid_solves += stats.algebraic_multigrid;

      SegmentState& state = states_.at(job.key);
      state.wall_hash.clear();
      state.data_hash = std::move(job.data_hash);
      EnrichmentFunction& f = state.function;
      f.enriched_nodes = std::move(job.enriched_nodes);
      f.elements.clear();
      for (RegionTile& r : job.region) {  // region is sorted by element (omega is a set)
        state.wall_hash[r.element] = wall_hash(r.element);
        ElementTexture texture;
        texture.element = r.element;
        texture.tile = std::move(r.tile);
        for (auto& flag : texture.tile.flags) flag &= static_cast<std::uint8_t>(~kernels::dirichlet);
        f.elements.push_back(std::move(texture));
      }
      changed_any = true;
    }
    to_solve.clear();
    for (const SolveJob& job : jobs) {
      SegmentState& state = states_.at(job.key);
      // A step whose two values both reach Omega_i's open edges may be one only there (they
      // meet beyond a free tip, around a crack tip closed at texel level): no rounds for it.
      // A segment without a free tip closes a region that reaches beyond Omega_i instead (a
      // bar across a U on a sheared tri6 plate, the U's corners in the row below the bar:
      // -0.019 instead of -0.505, until session 75), unless its sides meet all the same (an
      // end on an element's border counts as touching a wall: fracture's T-junction segment,
      // continued by a segment with a free tip, grew for three rounds at set-up and was
      // undone, 8 ms of a 50 ms step until session 76).
      if (!is_step_function(state.function)) continue;
      const std::size_t v = visible_index.at(job.key);
      const bool may_meet_beyond = both_values_reach_open_edges(state.function);
      if (may_meet_beyond && !ends_touch_walls_[v]) continue;
      std::set<int> stepping = state.stepping_elements;
      for (const ElementTexture& texture : state.function.elements) {
        if (segment_data[v].count(texture.element)) continue;
        const auto& values = texture.tile.values;
        if (std::find(values.begin(), values.end(), 1.0) != values.end() &&
            std::find(values.begin(), values.end(), -1.0) != values.end())
          stepping.insert(texture.element);
      }
      if (stepping.size() == state.stepping_elements.size()) continue;
      if (may_meet_beyond) {
        auto met = sides_meet.find(job.key);
        if (met == sides_meet.end())
          met = sides_meet
                    .emplace(job.key, detail::every_side_meets_the_other(segment_data, v, walls_, blank, mesh_.type,
                                                                         adjacency_, edge_walls_))
                    .first;
        if (met->second) continue;
      }
      before_growth.try_emplace(job.key, state);  // the first time only
      state.stepping_elements = std::move(stepping);
      to_solve.push_back(v);
    }
    if (to_solve.empty()) break;
  }
  // A function that was a step only within its first Omega_i (its two sides meet beyond
  // it, as around a crack tip closed at texel level) is not one on the grown region: it
  // keeps its first region and values.
  for (auto& [key, state] : before_growth)
    if (!is_step_function(states_.at(key).function)) states_.at(key) = std::move(state);
  // Segments no longer visible (time went back) lose their functions.
  for (auto it = order_.begin(); it != order_.end();) {
    if (alive.count(*it)) {
      ++it;
      continue;
    }
    states_.erase(*it);
    it = order_.erase(it);
    changed_any = true;
  }
  // Nodes where a function repeats the earlier ones (a crack continued by the next
  // segment or cut crosses the node's support completely: both are the same Heaviside)
  // keep only the earlier enrichment (enrichment_span.h); without it M and K are singular.
  // (Copied one function per thread: fracture's 281 tiles are 2.6 MB of fresh pages.)
  std::vector<const SegmentState*> in_order;
  for (const auto& key : order_) in_order.push_back(&states_.at(key));
  std::vector<EnrichmentFunction> all(in_order.size());
  kernels::forall_dynamic(static_cast<std::int64_t>(all.size()),
                          [&](std::int64_t k) { all[k] = in_order[k]->function; });
  const std::vector<std::vector<int>> independent = independent_enriched_nodes(node_elements_, all);
  functions_.clear();
  function_segments_.clear();
  function_rasters_.clear();
  dependent_nodes_ = 0;
  for (std::size_t k = 0; k < order_.size(); ++k) {
    dependent_nodes_ += static_cast<int>(all[k].enriched_nodes.size() - independent[k].size());
    if (independent[k].empty()) continue;  // the whole function repeats earlier ones
    if (independent[k].size() == all[k].enriched_nodes.size()) functions_.push_back(std::move(all[k]));
    else functions_.push_back(restrict_enriched_nodes(mesh_, all[k], independent[k]));
    const VisibleCutSegment& v = visible[visible_index.at(order_[k])];
    function_segments_.push_back({v.cut, v.segment, v.begin, v.end});
    function_rasters_.push_back(rasters[visible_index.at(order_[k])]);
  }
  last_.ms = ms_since(start);
  return changed_any;
}

void CutManager::save_textures(const std::string& dir) const {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw std::runtime_error("save textures: cannot create folder " + dir + ": " + error.message());
  TexelStorage storage(resolution_);
  for (std::size_t f = 0; f < functions_.size(); ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "enrichment_%03zu", f);
    for (const ElementTexture& texture : functions_[f].elements) storage.copy_tile_in(name, texture.element, texture.tile);
  }
  for (const auto& [e, tile] : walls_) storage.copy_flags_in("cut_walls", e, tile);
  storage.write_vdb((std::filesystem::path(dir) / "enrichment.vdb").string());
}

}  // namespace dgtex
