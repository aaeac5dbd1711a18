#include "dgtex/kernels/flood_fill.h"

#include <atomic>
#include <deque>
#include <stdexcept>

#include "dgtex/kernels/multigrid_unknowns.h"

namespace dgtex::kernels {
namespace {

void validate_tile(const TexelTile& tile) {
  if (tile.width <= 0 || tile.height <= 0 || tile.flags.size() != static_cast<std::size_t>(tile.width) * tile.height)
    throw std::invalid_argument("flood fill: the tile must be non-empty with width * height flags");
}

bool is_active(const TexelTile& tile, int t) { return !(tile.flags[t] & inactive); }

// Root of x with path halving; parent[x] <= x always holds, so this terminates.
int find_root(std::vector<std::atomic<int>>& parent, int x) {
  for (;;) {
    int p = parent[x].load(std::memory_order_relaxed);
    if (p == x) return x;
    const int gp = parent[p].load(std::memory_order_relaxed);
    if (gp != p) parent[x].compare_exchange_weak(p, gp, std::memory_order_relaxed);  // halving; failure is harmless
    x = gp;
  }
}

void unite(std::vector<std::atomic<int>>& parent, int a, int b) {
  for (;;) {
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a == b) return;
    if (a < b) std::swap(a, b);  // hang the larger root below the smaller one
    int expected = a;
    if (parent[a].compare_exchange_strong(expected, b, std::memory_order_relaxed)) return;
  }
}

}  // namespace

int label_components_reference(const TexelTile& tile, std::vector<int>& labels) {
  validate_tile(tile);
  const int w = tile.width, n = w * tile.height;
  labels.assign(n, -1);
  int count = 0;
  std::deque<int> queue;
  for (int seed = 0; seed < n; ++seed) {
    if (labels[seed] >= 0 || !is_active(tile, seed)) continue;
    labels[seed] = count;
    queue.push_back(seed);
    while (!queue.empty()) {
      const int t = queue.front(), i = t % w, j = t / w;
      queue.pop_front();
      auto visit = [&](bool coupled, int nb) {
        if (coupled && labels[nb] < 0) {
          labels[nb] = count;
          queue.push_back(nb);
        }
      };
      visit(i > 0 && texels_coupled_east(tile, i - 1, j), t - 1);
      visit(texels_coupled_east(tile, i, j), t + 1);
      visit(j > 0 && texels_coupled_north(tile, i, j - 1), t - w);
      visit(texels_coupled_north(tile, i, j), t + w);
    }
    ++count;
  }
  return count;
}

int label_components(const TexelTile& tile, std::vector<int>& labels, Execution execution) {
  validate_tile(tile);
  const int w = tile.width, h = tile.height, n = w * h;
  std::vector<std::atomic<int>> parent(n);
  // Rows: each texel points to the first texel of its run of east-connected texels.
  forall(
      h,
      [&](std::int64_t jj) {
        const int j = static_cast<int>(jj);
        int run_start = j * w;
        for (int i = 0; i < w; ++i) {
          const int t = j * w + i;
          if (i == 0 || !texels_coupled_east(tile, i - 1, j)) run_start = t;
          parent[t].store(run_start, std::memory_order_relaxed);
        }
      },
      execution);
  // Columns: merge runs across uncut north links.
  forall(
      h - 1,
      [&](std::int64_t jj) {
        const int j = static_cast<int>(jj);
        for (int i = 0; i < w; ++i)
          if (texels_coupled_north(tile, i, j)) unite(parent, j * w + i, (j + 1) * w + i);
      },
      execution);
  // Each component's root is now its smallest texel; number roots in index order.
  std::vector<int> roots(n);
  std::vector<int> roots_per_row(h, 0);
  forall(
      h,
      [&](std::int64_t jj) {
        const int j = static_cast<int>(jj);
        int count = 0;
        for (int t = j * w; t < (j + 1) * w; ++t) {
          roots[t] = is_active(tile, t) ? find_root(parent, t) : -1;
          count += (roots[t] == t);
        }
        roots_per_row[j] = count;
      },
      execution);
  std::vector<int> first_label_of_row(h + 1, 0);
  for (int j = 0; j < h; ++j) first_label_of_row[j + 1] = first_label_of_row[j] + roots_per_row[j];
  labels.assign(n, -1);
  forall(
      h,
      [&](std::int64_t jj) {
        const int j = static_cast<int>(jj);
        int next = first_label_of_row[j];
        for (int t = j * w; t < (j + 1) * w; ++t)
          if (roots[t] == t) labels[t] = next++;
      },
      execution);
  // Non-roots copy their root's label (roots lie at smaller indices, already labelled).
  forall(
      n,
      [&](std::int64_t t) {
        if (roots[t] >= 0 && roots[t] != t) labels[t] = labels[roots[t]];
      },
      execution);
  return first_label_of_row[h];
}

}  // namespace dgtex::kernels
