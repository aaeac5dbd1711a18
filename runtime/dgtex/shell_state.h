#pragma once
// The state of a (cut) shell at one instant: what the simulation produces and the
// renderer, the cut-surface export and `dgtex render` consume.
//
// Deformed position at parameter xi of element e:
//   x(xi) = sum_a N^a(xi) (X^a + u^a) + sum_{enrichments k of e} sum_a N^a(xi) (H_k(xi) - H_k(xi^a)) q_k^a
// with N^a the basis of dgtex/kernels/shape_functions.h, X^a the rest positions
// (mesh.positions), u^a the displacement, H_k the enrichment texture and q_k^a its DOFs.
// Plain value types that own their arrays (a copy of the mesh included). Positions and
// displacements in the mesh's length unit (SI: m), time in s; H dimensionless.
#include <string>
#include <vector>

#include "dgtex/mesh.h"

namespace dgtex {

// One enrichment function on one element: H sampled on a T x T texel grid over the
// element's parameter square.
//   quad8: texel (i, j) covers xi in [-1+2i/T, -1+2(i+1)/T] x [-1+2j/T, -1+2(j+1)/T];
//   tri6:  texel (i, j) covers xi in [i/T, (i+1)/T] x [j/T, (j+1)/T]; texels with
//          i + j <= T - 1 are read (those on the diagonal are cut in half by it), the
//          others are unused.
struct ElementEnrichment {
  int element = -1;
  int resolution = 0;
  std::vector<float> values;       // T*T, texel (i,j) at j*T+i: the enrichment function H
  std::vector<float> node_values;  // H at the element's local nodes (shifted enrichment H - H(xi^a))
  std::vector<double> dofs;        // nodes_per_element x 3: enrichment displacement q^a of each local node
};

struct ShellState {
  Mesh mesh;
  std::vector<double> displacement;  // #nodes x 3 (empty means zero)
  std::vector<ElementEnrichment> enrichments;
  double time = 0;
};

// These functions share no state (thread-safe; two saves to one path race on the file).
// Checks sizes and indices, and that time, positions, displacements (and their sums) and
// enrichments are finite; throws std::invalid_argument naming the offending field.
void validate_state(const ShellState& state);

// Binary format, little-endian, version 2 ("dgtex state"):
//   char[8]  magic "DGTEXST\0"      u32 version = 2
//   i32 element type (0 quad8, 1 tri6)  u64 #nodes  u64 #elements  f64 time
//   f64 positions[#nodes*3]   i32 elements[#elements*npe]
//   u8  has_displacement      f64 displacement[#nodes*3] if has_displacement
//   u64 #enrichments, then per enrichment:
//     i32 element  i32 T  f32 values[T*T]  f32 node_values[npe]  f64 dofs[npe*3]
//   u32 CRC-32 (IEEE, as zlib's crc32) of every byte before it
// Version 1 is the same without the checksum; load_state reads both, save_state writes 2.
// Errors (cannot open, not a regular file, truncated, bad magic/version, a checksum that
// does not match, inconsistent sizes, a state validate_state refuses) throw
// std::runtime_error naming the file.
void save_state(const std::string& path, const ShellState& state);
ShellState load_state(const std::string& path);

}  // namespace dgtex
