#pragma once
// CPU evaluation of a ShellState's deformed, enriched surface: the reference twin of the
// renderer's vertex/geometry stages (shaders/shell.vert, shell.geom), used by the cut
// surface export, the renderer's camera framing and smooth normals, and tests.
//
//   x(xi) = base(xi) + sum_k h_k A_k(xi),
//   base  = sum_a N^a (X^a + u^a) - sum_k sum_a N^a H_k(xi^a) q_k^a,   A_k = sum_a N^a q_k^a,
// where h_k = H_k(xi) for the true surface, or the value of one side of a cut when a cut
// triangle is extrapolated across it.
// DeformedShell keeps a reference to the ShellState (which must outlive it) and owns only
// its per-element index lists; const functions are thread-safe. Positions in the mesh's
// length unit (SI: m).
#include <array>
#include <vector>

#include "dgtex/shell_state.h"

namespace dgtex {

// The texel (i, j) of a T x T enrichment texture that contains parameter point xi
// (nearest-texel lookup; layout in shell_state.h). Points on the border are clamped into
// the grid; on a tri6 texture points are clamped to the texels with i + j <= T - 1.
// Throws std::invalid_argument for a resolution below 1 or a non-finite xi.
void enrichment_texel(ElementType type, int resolution, double xi1, double xi2, int& i, int& j);

// H at xi (the value of the containing texel). Throws std::invalid_argument for values
// that are not resolution^2, or as enrichment_texel.
float sample_enrichment(ElementType type, const ElementEnrichment& enrichment, double xi1, double xi2);

class DeformedShell {
 public:
  // Keeps a reference to state (which must outlive this object); validates it.
  explicit DeformedShell(const ShellState& state);
  // A temporary state (DeformedShell(run.state())) would dangle, a const one too.
  explicit DeformedShell(ShellState&&) = delete;
  explicit DeformedShell(const ShellState&&) = delete;

  const ShellState& state() const { return state_; }
  // Indices into state.enrichments of the enrichments of one element, in state order.
  const std::vector<int>& enrichments_of(int element) const;
  int max_enrichments_per_element() const { return max_per_element_; }

  // base and A_k (enrichments_of(element).size() x 3) at xi. These and enrichments_of throw
  // std::invalid_argument for an element out of range or a non-finite xi.
  void decompose(int element, double xi1, double xi2, double base[3], std::vector<std::array<double, 3>>& A) const;
  // x with given enrichment values h (one per enrichments_of(element) entry).
  void position(int element, double xi1, double xi2, const double* h, double x[3]) const;
  // x with H sampled from the textures at xi.
  void position(int element, double xi1, double xi2, double x[3]) const;

  // Normals at nodes averaged over the elements sharing them (weighted by the element's
  // area element at the node), #nodes x 3, unit length (zero where undefined). An
  // element's tangents at node a include its enrichments on node a's side (h = H(xi^a)).
  std::vector<double> averaged_node_normals() const;

  // Axis-aligned bounds of the deformed surface: nodes, plus a 9 x 9 sample grid in
  // every enriched element (enrichment moves interior points, not nodes).
  void bounding_box(double lo[3], double hi[3]) const;

 private:
  const ShellState& state_;
  std::vector<std::vector<int>> by_element_;
  int max_per_element_ = 0;
};

}  // namespace dgtex
