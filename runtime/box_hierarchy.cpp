#include "box_hierarchy.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dgtex::detail {

double box_distance(const double* lo, const double* hi, const double p[3]) {
  double s = 0;
  for (int d = 0; d < 3; ++d) {
    const double gap = p[d] - std::clamp(p[d], lo[d], hi[d]);
    s += gap * gap;
  }
  return std::sqrt(s);
}

namespace {
constexpr int kLeafItems = 4;
}

BoxHierarchy::BoxHierarchy(const std::vector<double>& boxes) : item_boxes_(boxes) {
  const int count = static_cast<int>(boxes.size() / 6);
  order_.resize(count);
  for (int k = 0; k < count; ++k) order_[k] = k;
  if (count > 0) build(0, count);
}

// Splits the items at the median of their box centres along the node box's longest axis.
int BoxHierarchy::build(int begin, int end) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.begin = begin, node.end = end;
  for (int d = 0; d < 3; ++d) node.lo[d] = std::numeric_limits<double>::infinity(), node.hi[d] = -node.lo[d];
  for (int k = begin; k < end; ++k) {
    const double* box = &item_boxes_[6 * static_cast<std::size_t>(order_[k])];
    for (int d = 0; d < 3; ++d) node.lo[d] = std::min(node.lo[d], box[d]), node.hi[d] = std::max(node.hi[d], box[3 + d]);
  }
  if (end - begin > kLeafItems) {
    int axis = 0;
    for (int d = 1; d < 3; ++d)
      if (node.hi[d] - node.lo[d] > node.hi[axis] - node.lo[axis]) axis = d;
    auto centre = [&](int item) {
      const double* box = &item_boxes_[6 * static_cast<std::size_t>(item)];
      return box[axis] + box[3 + axis];
    };
    const int middle = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end, [&](int a, int b) {
      const double ca = centre(a), cb = centre(b);
      return ca != cb ? ca < cb : a < b;
    });
    node.left = build(begin, middle);
    node.right = build(middle, end);
  }
  nodes_[index] = node;
  return index;
}

void BoxHierarchy::within(const double p[3], double r, std::vector<int>& out) const {
  out.clear();
  if (!nodes_.empty()) collect(0, p, r, out);
  std::sort(out.begin(), out.end());
}

void BoxHierarchy::collect(int index, const double p[3], double r, std::vector<int>& out) const {
  const Node& node = nodes_[index];
  if (box_distance(node.lo, node.hi, p) > r) return;
  if (node.left < 0) {
    for (int k = node.begin; k < node.end; ++k) {
      const double* box = &item_boxes_[6 * static_cast<std::size_t>(order_[k])];
      if (box_distance(box, box + 3, p) <= r) out.push_back(order_[k]);
    }
    return;
  }
  collect(node.left, p, r, out);
  collect(node.right, p, r, out);
}

double BoxHierarchy::nearest_distance(const double p[3]) const {
  double best = std::numeric_limits<double>::infinity();
  if (!nodes_.empty()) descend(0, p, best);
  return best;
}

// Depth first, the nearer child first, pruning nodes farther than the best item so far.
void BoxHierarchy::descend(int index, const double p[3], double& best) const {
  const Node& node = nodes_[index];
  if (node.left < 0) {
    for (int k = node.begin; k < node.end; ++k) {
      const double* box = &item_boxes_[6 * static_cast<std::size_t>(order_[k])];
      best = std::min(best, box_distance(box, box + 3, p));
    }
    return;
  }
  const Node& a = nodes_[node.left];
  const Node& b = nodes_[node.right];
  const double da = box_distance(a.lo, a.hi, p), db = box_distance(b.lo, b.hi, p);
  const int near = da <= db ? node.left : node.right, far = da <= db ? node.right : node.left;
  if (std::min(da, db) <= best) descend(near, p, best);
  if (std::max(da, db) <= best) descend(far, p, best);
}

}  // namespace dgtex::detail
