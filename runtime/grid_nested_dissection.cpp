#include "grid_nested_dissection.h"

namespace dgtex::detail {
namespace {

// Boxes of at most this many nodes are numbered row by row (their factor is dense anyway).
constexpr long leaf_nodes = 16;

struct Dissection {
  const kernels::GridShape& g;
  const std::uint8_t* active;
  std::vector<std::int64_t>& order;

  void emit(int i0, int i1, int j0, int j1) {
    for (int j = j0; j < j1; ++j)
      for (int i = i0; i < i1; ++i)
        if (active[g.at(i, j)]) order.push_back(g.at(i, j));
  }

  // Box [i0, i1) x [j0, j1).
  void box(int i0, int i1, int j0, int j1) {
    const int w = i1 - i0, h = j1 - j0;
    if (w <= 0 || h <= 0) return;
    if (static_cast<long>(w) * h <= leaf_nodes) {
      emit(i0, i1, j0, j1);
      return;
    }
    if (w >= h) {
      const int m = i0 + w / 2;
      box(i0, m, j0, j1);
      box(m + 1, i1, j0, j1);
      emit(m, m + 1, j0, j1);
    } else {
      const int m = j0 + h / 2;
      box(i0, i1, j0, m);
      box(i0, i1, m + 1, j1);
      emit(i0, i1, m, m + 1);
    }
  }
};

}  // namespace

std::vector<std::int64_t> grid_nested_dissection_order(const kernels::GridShape& g, const std::uint8_t* active) {
  std::vector<std::int64_t> order;
  Dissection{g, active, order}.box(0, g.nx, 0, g.ny);
  return order;
}

}  // namespace dgtex::detail
