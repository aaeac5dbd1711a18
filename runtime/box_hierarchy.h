#pragma once
// Exact range queries by box distance over a fixed set of axis-aligned boxes: the whole-mesh
// closest-point search (SurfacePointSearch::closest) visits only the elements near the
// point instead of every element's box, and finds the same ones.

#include <vector>

namespace dgtex::detail {

// Distance from p to the box [lo, hi] (0 inside).
double box_distance(const double* lo, const double* hi, const double p[3]);

// A bounding-volume hierarchy: each node's box holds its items' boxes, so its box_distance
// is never larger than any of theirs, in floating point too (the bounds are exact minima
// and maxima, and the clamped gaps, their squares, sum and root only grow with the box's
// distance along each axis). A query prunes a node only where that lower bound exceeds the
// radius, so it returns exactly the items a scan over all of them would.
class BoxHierarchy {
 public:
  // boxes: lo[3], hi[3] per item.
  explicit BoxHierarchy(const std::vector<double>& boxes);

  // The items whose box_distance to p is at most r, ascending.
  void within(const double p[3], double r, std::vector<int>& out) const;
  // The least box_distance from p to any item (infinity without items).
  double nearest_distance(const double p[3]) const;

 private:
  struct Node {
    double lo[3], hi[3];
    int begin = 0, end = 0;     // items order_[begin, end)
    int left = -1, right = -1;  // children (-1: a leaf)
  };
  int build(int begin, int end);
  void collect(int node, const double p[3], double r, std::vector<int>& out) const;
  void descend(int node, const double p[3], double& best) const;

  std::vector<double> item_boxes_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

}  // namespace dgtex::detail
