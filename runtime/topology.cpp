#include "dgtex/topology.h"

#include <algorithm>
#include <string>

namespace dgtex {
namespace {

// One element's traversal of one of its local edges.
struct HalfEdge {
  int low, high;  // corner node indices, sorted: the key shared by both sides of an edge
  int element, local_edge;
  int nodes[3];   // start, mid, end in this element's local direction
};

std::string describe(const HalfEdge& h) {
  return "element " + std::to_string(h.element) + " (local edge " + std::to_string(h.local_edge) + ": nodes " +
         std::to_string(h.nodes[0]) + " -> " + std::to_string(h.nodes[1]) + " -> " + std::to_string(h.nodes[2]) + ")";
}

MeshEdge make_edge(const HalfEdge& plus, const HalfEdge* minus) {
  MeshEdge edge;
  edge.plus_element = plus.element;
  edge.plus_local_edge = plus.local_edge;
  if (minus) {
    edge.minus_element = minus->element;
    edge.minus_local_edge = minus->local_edge;
  }
  std::copy(plus.nodes, plus.nodes + 3, edge.nodes);
  return edge;
}

bool by_plus_side(const MeshEdge& a, const MeshEdge& b) {
  return a.plus_element != b.plus_element ? a.plus_element < b.plus_element : a.plus_local_edge < b.plus_local_edge;
}

}  // namespace

Topology build_topology(const Mesh& mesh) {
  const int corners = kernels::corners_per_element(mesh.type);
  const int elements = mesh.num_elements();
  std::vector<HalfEdge> half_edges;
  half_edges.reserve(static_cast<size_t>(elements) * corners);
  for (int e = 0; e < elements; ++e) {
    const int* en = mesh.element_nodes(e);
    for (int k = 0; k < corners; ++k) {
      int local[3];
      kernels::local_edge_nodes(mesh.type, k, local);
      HalfEdge h;
      h.element = e;
      h.local_edge = k;
      for (int i = 0; i < 3; ++i) h.nodes[i] = en[local[i]];
      if (h.nodes[0] == h.nodes[2])
        throw MeshError("degenerate edge: " + describe(h) + " starts and ends at the same node", {e});
      h.low = std::min(h.nodes[0], h.nodes[2]);
      h.high = std::max(h.nodes[0], h.nodes[2]);
      half_edges.push_back(h);
    }
  }
  // Sorting by (corner pair, element, local edge) groups the sides of each edge in a fixed order.
  std::sort(half_edges.begin(), half_edges.end(), [](const HalfEdge& a, const HalfEdge& b) {
    if (a.low != b.low) return a.low < b.low;
    if (a.high != b.high) return a.high < b.high;
    if (a.element != b.element) return a.element < b.element;
    return a.local_edge < b.local_edge;
  });

  Topology topology;
  for (size_t begin = 0; begin < half_edges.size();) {
    size_t end = begin + 1;
    while (end < half_edges.size() && half_edges[end].low == half_edges[begin].low &&
           half_edges[end].high == half_edges[begin].high)
      ++end;
    const HalfEdge& first = half_edges[begin];
    const std::string corner_pair = "edge between nodes " + std::to_string(first.low) + " and " +
                                    std::to_string(first.high);
    if (end - begin == 1) {
      topology.boundary_edges.push_back(make_edge(first, nullptr));
    } else if (end - begin == 2) {
      const HalfEdge& second = half_edges[begin + 1];
      if (first.element == second.element)
        throw MeshError("element " + std::to_string(first.element) + " uses the " + corner_pair +
                            " twice (local edges " + std::to_string(first.local_edge) + " and " +
                            std::to_string(second.local_edge) + ")",
                        {first.element});
      if (first.nodes[0] == second.nodes[0])
        throw MeshError("inconsistent orientation: " + describe(first) + " and " + describe(second) +
                            " traverse their shared edge in the same direction; one of elements " +
                            std::to_string(first.element) + " and " + std::to_string(second.element) +
                            " is flipped (its normal points the other way)",
                        {first.element, second.element});
      if (first.nodes[1] != second.nodes[1])
        throw MeshError("midside nodes disagree on the " + corner_pair + ": " + describe(first) + " vs " +
                            describe(second) + "; neighbours must share all three edge nodes",
                        {first.element, second.element});
      topology.interior_edges.push_back(make_edge(first, &second));  // lower element index is plus
    } else {
      std::string list;
      std::vector<int> involved;
      for (size_t i = begin; i < end; ++i) {
        list += (i == begin ? "" : ", ") + describe(half_edges[i]);
        involved.push_back(half_edges[i].element);
      }
      throw MeshError("non-manifold " + corner_pair + ": used by " + std::to_string(end - begin) +
                          " elements (at most 2 allowed): " + list,
                      involved);
    }
    begin = end;
  }
  std::sort(topology.interior_edges.begin(), topology.interior_edges.end(), by_plus_side);
  std::sort(topology.boundary_edges.begin(), topology.boundary_edges.end(), by_plus_side);
  return topology;
}

}  // namespace dgtex
