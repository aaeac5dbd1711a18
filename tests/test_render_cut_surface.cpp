// The cut surface export (OBJ split along cuts at texel resolution).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>

#include "dgtex/cut_surface_export.h"
#include "render_fixtures.h"

namespace dgtex {
namespace {

// Connected components of faces sharing a vertex.
int face_components(const CutSurfaceMesh& m, std::vector<int>* component_of_vertex = nullptr) {
  std::vector<int> parent(m.num_vertices());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  size_t offset = 0;
  for (int f = 0; f < m.num_faces(); ++f) {
    for (int k = 1; k < m.face_sizes[f]; ++k)
      parent[find(m.face_vertices[offset + k])] = find(m.face_vertices[offset]);
    offset += m.face_sizes[f];
  }
  std::vector<char> used(m.num_vertices(), 0);
  for (int v : m.face_vertices) used[v] = 1;
  int count = 0;
  for (int v = 0; v < m.num_vertices(); ++v) {
    EXPECT_TRUE(used[v]) << "vertex " << v << " belongs to no face";
    if (find(v) == v) ++count;
  }
  if (component_of_vertex) {
    component_of_vertex->resize(m.num_vertices());
    for (int v = 0; v < m.num_vertices(); ++v) (*component_of_vertex)[v] = find(v);
  }
  return count;
}

TEST(RenderCutSurface, CompleteCutSplitsThePlateIntoTwoExactPieces) {
  for (bool staircase : {false, true}) {
    const auto plate = staircase ? test::staircase_cut_plate() : test::straight_cut_plate();
    const CutSurfaceMesh m = build_cut_surface(plate.state, 4);
    std::vector<int> component;
    EXPECT_EQ(face_components(m, &component), 2) << (staircase ? "staircase" : "straight");
    // Element 0: one quad per texel; element 1: 4 x 4 quads.
    EXPECT_EQ(m.num_faces(), 16 * 16 + 4 * 4);
    // Every vertex lies where the exact deformed plate is (in z = 0, on its covered part
    // up to the boundary): check against the oracle at a point nudged into each face.
    size_t offset = 0;
    for (int f = 0; f < m.num_faces(); ++f) {
      double centre[3] = {0, 0, 0};
      for (int k = 0; k < m.face_sizes[f]; ++k)
        for (int d = 0; d < 3; ++d) centre[d] += m.vertices[3 * m.face_vertices[offset + k] + d] / m.face_sizes[f];
      EXPECT_NEAR(centre[2], 0.0, 1e-12);
      EXPECT_TRUE(plate.covers(centre[0], centre[1])) << "face " << f << " centre " << centre[0] << ", " << centre[1];
      offset += m.face_sizes[f];
    }
    // The left piece is exactly the left texels moved by -gap: its largest x.
    double left_max = -1e9, right_min = 1e9;
    const int left = component[m.face_vertices[0]];  // the first face is texel (0, 0), left of the cut
    for (int v = 0; v < m.num_vertices(); ++v) {
      if (component[v] == left)
        left_max = std::max(left_max, m.vertices[3 * v]);
      else
        right_min = std::min(right_min, m.vertices[3 * v]);
    }
    const int widest = *std::max_element(plate.cut_column.begin(), plate.cut_column.end());
    const int narrowest = *std::min_element(plate.cut_column.begin(), plate.cut_column.end());
    EXPECT_NEAR(left_max, double(widest) / plate.resolution - plate.gap, 1e-12);
    EXPECT_NEAR(right_min, double(narrowest) / plate.resolution, 1e-12);
  }
}

TEST(RenderCutSurface, UncutMeshIsOneWeldedPiece) {
  auto plate = test::straight_cut_plate();
  plate.state.enrichments.clear();
  plate.state.displacement.assign(plate.state.displacement.size(), 0.0);
  const CutSurfaceMesh m = build_cut_surface(plate.state, 3);
  EXPECT_EQ(face_components(m), 1);
  EXPECT_EQ(m.num_faces(), 2 * 9);
  EXPECT_EQ(m.num_vertices(), 7 * 4);  // two 4 x 4 grids sharing a column
}

TEST(RenderCutSurface, PartialCutOnTri6StaysOnePieceAndWritesObj) {
  const ShellState state = test::curved_partial_cut(16);
  const CutSurfaceMesh m = build_cut_surface(state, 4);
  EXPECT_EQ(face_components(m), 1);  // a partial cut does not separate the strip
  const std::string path = (std::filesystem::path(::testing::TempDir()) / "dgtex_cut_surface.obj").string();
  write_obj(path, m);
  std::ifstream in(path);
  std::string line;
  int v = 0, f = 0;
  while (std::getline(in, line)) {
    if (line.rfind("v ", 0) == 0) ++v;
    if (line.rfind("f ", 0) == 0) ++f;
  }
  EXPECT_EQ(v, m.num_vertices());
  EXPECT_EQ(f, m.num_faces());
  std::remove(path.c_str());
  EXPECT_THROW(write_obj("/nonexistent-dir/x.obj", m), std::runtime_error);
}

}  // namespace
}  // namespace dgtex
