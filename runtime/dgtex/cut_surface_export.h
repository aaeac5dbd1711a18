#pragma once
// The deformed, cut surface of a ShellState as a polygon mesh, split along the cuts at
// texel resolution:
//  - an element with enrichments becomes one quad per texel (tri6: the texels with
//    i + j <= T - 1; those on the diagonal become their lower-left triangle) of the
//    finest of its textures. Texel corners are shared by the texels around them that are
//    not separated by a cut (some enrichment's values differ by more than cut_threshold
//    and change sign, the renderer's criterion); each group gets its own vertex,
//    displaced with the group's mean enrichment values, so the pieces come apart.
//  - an element without enrichment becomes a tessellation x tessellation grid of quads
//    (tri6: triangles).
// Vertices on element boundaries are welded across elements where their rest positions
// coincide (within 1e-9 of the rest bounding-box size) and each element meets there with
// one vertex only; the welded vertex takes the mean deformed position, which closes the
// small cracks per-element texel sampling of H leaves. Where a cut reaches an element
// boundary (an element has several vertices there) nothing is welded, so the sides stay
// apart. Texel grids and tessellations of neighbouring elements meet only where their
// vertices coincide (T-junctions elsewhere).
// Pure function: reads the state, returns a CutSurfaceMesh that owns its vertices and
// faces (keeps nothing; thread-safe). Positions in the mesh's length unit (SI: m).
#include <string>
#include <vector>

#include "dgtex/shell_state.h"

namespace dgtex {

struct CutSurfaceMesh {
  std::vector<double> vertices;    // #vertices x 3
  std::vector<int> face_sizes;     // 3 or 4 per face
  std::vector<int> face_vertices;  // concatenated, counter-clockwise seen from the normal side
  std::vector<int> face_elements;  // the element each face belongs to
  int num_vertices() const { return static_cast<int>(vertices.size() / 3); }
  int num_faces() const { return static_cast<int>(face_sizes.size()); }
};

CutSurfaceMesh build_cut_surface(const ShellState& state, int tessellation = 8, float cut_threshold = 0.5f);

// Wavefront OBJ: "v x y z" lines, then "f a b c [d]" (1-based), one "g element_E" group
// per element. Throws std::runtime_error naming the file on I/O failure.
void write_obj(const std::string& path, const CutSurfaceMesh& mesh);

// build_cut_surface + write_obj.
void export_cut_surface_obj(const std::string& path, const ShellState& state, int tessellation = 8,
                            float cut_threshold = 0.5f);

}  // namespace dgtex
