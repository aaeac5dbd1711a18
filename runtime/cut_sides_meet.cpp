#include "cut_sides_meet.h"

#include <unordered_map>

#include "dgtex/kernels/multigrid_unknowns.h"

namespace dgtex::detail {

namespace {

using kernels::TexelTile;

struct Texel {
  int element, index;
};

// Sets of texels reached from one seed each, joined where their searches touch, with the
// sides they hold and how many of their texels still wait in the search's queue.
class SeedSets {
 public:
  int add(unsigned side) {
    parent_.push_back(static_cast<int>(parent_.size()));
    sides_.push_back(side);
    waiting_.push_back(1);
    one_sided_ += one_sided_value(side);
    return parent_.back();
  }
  int find(int s) {
    while (parent_[s] != s) s = parent_[s] = parent_[parent_[s]];
    return s;
  }
  int unite(int a, int b) {  // roots
    if (a == b) return a;
    one_sided_ -= one_sided_value(sides_[a]) + one_sided_value(sides_[b]);
    parent_[b] = a;
    sides_[a] |= sides_[b];
    waiting_[a] += waiting_[b];
    one_sided_ += one_sided_value(sides_[a]);
    return a;
  }
  long long& waiting(int root) { return waiting_[root]; }
  bool one_sided(int root) const { return one_sided_value(sides_[root]); }
  int one_sided_roots() const { return one_sided_; }

  static constexpr unsigned neither = 0, plus = 1, minus = 2, both = 3;

 private:
  static bool one_sided_value(unsigned sides) { return sides == plus || sides == minus; }

  std::vector<int> parent_;
  std::vector<unsigned> sides_;
  std::vector<long long> waiting_;
  int one_sided_ = 0;
};

}  // namespace

bool every_side_meets_the_other(const std::vector<SideTexels>& segments, std::size_t segment,
                                const std::map<int, TexelTile>& walls, const TexelTile& blank, ElementType type,
                                const ElementAdjacency& adjacency, const MeshEdgeWalls& edge_walls) {
  const int t = blank.width, tt = t * t;
  std::unordered_map<int, std::vector<int>> set_of;  // element -> per texel: the set that reached it, or -1
  auto sets_in = [&](int e) -> std::vector<int>& {
    auto [it, fresh] = set_of.try_emplace(e);
    if (fresh) it->second.assign(tt, -1);
    return it->second;
  };
  auto tile_of = [&](int e) -> const TexelTile& {
    const auto it = walls.find(e);
    return it != walls.end() ? it->second : blank;
  };

  SeedSets sets;
  std::vector<Texel> layer, next;
  auto seed = [&](const SideTexels& sides, bool signed_sides) {
    for (const auto& [e, texels] : sides) {
      std::vector<int>& reached = sets_in(e);
      for (const auto& [index, value] : texels) {
        if (reached[index] >= 0) continue;
        const unsigned side = !signed_sides ? SeedSets::neither
                              : value == 1  ? SeedSets::plus
                              : value == -1 ? SeedSets::minus
                                            : SeedSets::neither;
        reached[index] = sets.add(side);
        layer.push_back({e, index});
      }
    }
  };
  seed(segments[segment], true);
  for (std::size_t k = 0; k < segments.size(); ++k)
    if (k != segment) seed(segments[k], false);
  if (sets.one_sided_roots() == 0) return true;

  while (!layer.empty()) {
    next.clear();
    int element = -1;  // the last texel's element, whose look-ups most texels share
    std::vector<int>* here = nullptr;
    const TexelTile* tile_here = nullptr;
    for (const Texel& x : layer) {
      if (x.element != element) {
        element = x.element;
        here = &sets_in(element);
        tile_here = &tile_of(element);
      }
      int root = sets.find((*here)[x.index]);
      --sets.waiting(root);
      auto reach = [&](std::vector<int>& reached, int e, int index) {
        if (reached[index] < 0) {
          reached[index] = root;
          ++sets.waiting(root);
          next.push_back({e, index});
        } else {
          root = sets.unite(root, sets.find(reached[index]));
        }
      };
      const TexelTile& tile = *tile_here;
      const int i = x.index % t, j = x.index / t;
      if (kernels::texels_coupled_east(tile, i, j)) reach(*here, x.element, x.index + 1);
      if (i > 0 && kernels::texels_coupled_east(tile, i - 1, j)) reach(*here, x.element, x.index - 1);
      if (kernels::texels_coupled_north(tile, i, j)) reach(*here, x.element, x.index + t);
      if (j > 0 && kernels::texels_coupled_north(tile, i, j - 1)) reach(*here, x.element, x.index - t);
      int edges[2], positions[2];
      const int on_edges = (tile.flags[x.index] & kernels::inactive) ? 0 : texel_edges(type, t, i, j, edges, positions);
      for (int k = 0; k < on_edges; ++k) {
        const auto beyond = adjacency.neighbour(x.element, edges[k]);
        const int s = t - 1 - positions[k];
        if (beyond[0] < 0 || edge_walls.blocked(x.element, edges[k], positions[k]) ||
            edge_walls.blocked(beyond[0], beyond[1], s))
          continue;
        const int partner = edge_texel_index(type, t, beyond[1], s);
        if (!(tile_of(beyond[0]).flags[partner] & kernels::inactive)) reach(sets_in(beyond[0]), beyond[0], partner);
      }
      if (sets.one_sided_roots() == 0) return true;
      if (sets.waiting(root) == 0 && sets.one_sided(root)) return false;  // a region that holds one side only
    }
    layer.swap(next);
  }
  return sets.one_sided_roots() == 0;
}

}  // namespace dgtex::detail
